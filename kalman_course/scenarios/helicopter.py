r"""L'hélicoptère SAMU 31 au-dessus de Toulouse : les expériences du chapitre « Plusieurs capteurs, temps
irrégulier », écrites une fois (le chapitre, ses figures, ses curseurs et ses tests les appellent).

Le modèle est la vitesse presque constante en temps continu (:func:`~kalman_course.constant_velocity`),
état :math:`[e, n, v_e, v_n]` (m, m/s), discrétisé **exactement à chaque pas** entre deux messages : les
matrices :math:`A_k, Q_k` dépendent de l'écart :math:`\Delta t_k`, le modèle varie dans le temps. Deux
capteurs :

* les **positions** ADS-B (GNSS), à leurs instants propres, irréguliers (0,4 à 8 s) ;
* les **vitesses** sol (module et route, converties en composantes), à d'autres instants.

Réunies sur un seul axe des temps, elles forment une suite de mesures :math:`[e, n, v_e, v_n]` avec
``NaN`` là où un capteur se tait : le filtre corrige avec les seules composantes présentes.

L'a priori est pris **une seconde avant** la première position : la position d'alors déduite de la
première vitesse, à 10 m près, et cette vitesse, à 5 m/s près. Les densités et écarts-types sont appris
par maximum de vraisemblance (:func:`helicopter_fit`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import NamedTuple

import numpy as np

from ..core.models import LinearGaussianModel
from ..core.motion import constant_velocity
from ..core.results import FilterResult, freeze_fields
from ..core.validation import KalmanInputError
from ..datasets.adsb import Flight, samu31
from ..filters.kalman import kalman_filter
from ..likelihood import log_likelihood

__all__ = [
    "SENSORS", "PRIOR_LEAD", "PRIOR_POSITION_STD", "PRIOR_SPEED_STD", "OUTLIER_ROWS", "OUTLIER_OFFSETS",
    "HelicopterTrack", "HelicopterFit", "helicopter_track", "helicopter_model", "helicopter_fit", "fitted_parameters",
    "helicopter_filter", "prediction_rms", "with_outliers", "GateStudy", "gate_study", "lost_track_time",
]

#: Capteurs utilisés : positions seules, ou positions et vitesses.
SENSORS = ("position", "both")
#: L'a priori est posé cette durée (s) avant la première position.
PRIOR_LEAD = 1.0
#: Écart-type de position (m) et de vitesse (m/s) de l'a priori.
PRIOR_POSITION_STD = 10.0
PRIOR_SPEED_STD = 5.0
#: Positions corrompues à la main pour l'expérience des aberrations (indices parmi les 278 positions) et
#: leurs décalages (m, est et nord) : un récepteur qui se trompe de quelques centaines de mètres.
OUTLIER_ROWS = (30, 80, 81, 150, 200, 240)
OUTLIER_OFFSETS = ((150.0, -120.0), (0.0, 200.0), (-180.0, 60.0), (120.0, 120.0), (-100.0, -150.0),
                   (200.0, 0.0))


@dataclass(frozen=True, eq=False)
class HelicopterTrack:
    r"""Les mesures de l'hélicoptère sur un axe des temps.

    ``t`` (K,) s ; ``y`` (K, m) : :math:`[e, n]` (positions seules, m = 2) ou :math:`[e, n, v_e, v_n]`
    (les deux capteurs, m = 4), NaN où un capteur se tait ; ``dt`` (K,) : écart avec l'instant précédent
    (le premier : :data:`PRIOR_LEAD`, depuis l'a priori) ; ``position_rows``, ``velocity_rows`` (K,)
    booléens ; ``x0`` (4,), ``P0`` (4, 4) : l'a priori ; ``sensors`` ; ``flight`` : le vol."""

    sensors: str
    t: np.ndarray
    y: np.ndarray
    dt: np.ndarray
    position_rows: np.ndarray
    velocity_rows: np.ndarray
    x0: np.ndarray
    P0: np.ndarray
    flight: Flight

    def __post_init__(self) -> None:
        freeze_fields(self, "t", "y", "dt", "x0", "P0")
        for name in ("position_rows", "velocity_rows"):
            a = np.array(getattr(self, name), dtype=bool)
            a.setflags(write=False)
            object.__setattr__(self, name, a)

    @property
    def C(self) -> np.ndarray:
        """Matrice d'observation : les positions (2, 4), ou tout l'état (4, 4)."""
        return np.eye(4)[:2] if self.sensors == "position" else np.eye(4)


def _check_sensors(sensors: str) -> str:
    if sensors not in SENSORS:
        raise KalmanInputError(f"« sensors » doit valoir {' ou '.join(repr(s) for s in SENSORS)} ; reçu {sensors!r}.")
    return sensors


@lru_cache(maxsize=None)
def helicopter_track(sensors: str = "position") -> HelicopterTrack:
    """Les mesures du vol SAMU 31 : positions seules (278 instants) ou positions et vitesses réunies."""
    _check_sensors(sensors)
    f = samu31()
    tp = np.round(f.t, 3)
    if sensors == "position":
        t = tp
        y = np.c_[f.east, f.north]
        pos, vel = np.ones(t.size, dtype=bool), np.zeros(t.size, dtype=bool)
    else:
        tv = np.round(f.velocity_t, 3)
        t = np.union1d(tp, tv)
        y = np.full((t.size, 4), np.nan)
        ip, iv = np.searchsorted(t, tp), np.searchsorted(t, tv)
        y[ip, 0], y[ip, 1] = f.east, f.north
        y[iv, 2], y[iv, 3] = f.velocity_east, f.velocity_north
        pos, vel = ~np.isnan(y[:, 0]), ~np.isnan(y[:, 2])
    dt = np.diff(t, prepend=t[0] - PRIOR_LEAD)
    v0 = np.array([f.velocity_east[0], f.velocity_north[0]])
    x0 = np.r_[np.array([f.east[0], f.north[0]]) - PRIOR_LEAD * v0, v0]
    P0 = np.diag([PRIOR_POSITION_STD**2] * 2 + [PRIOR_SPEED_STD**2] * 2)
    return HelicopterTrack(sensors, t, y, dt, pos, vel, x0, P0, f)


def helicopter_model(track: HelicopterTrack, accel_psd: float, position_std: float,
                     velocity_std: float | None = None) -> LinearGaussianModel:
    r"""Le modèle variable dans le temps de ``track`` : vitesse presque constante de densité ``accel_psd``
    (m²/s³), discrétisée à chaque :math:`\Delta t_k` ; positions à ``position_std`` (m) près, vitesses à
    ``velocity_std`` (m/s) près (pour les deux capteurs)."""
    A, Q1 = _unit_discretization(track.sensors)
    Q = accel_psd * Q1  # Q est proportionnelle à la densité : une discrétisation par vol suffit
    if track.sensors == "position":
        R = position_std**2 * np.eye(2)
    else:
        if velocity_std is None:
            raise KalmanInputError("« velocity_std » : donnez l'écart-type des vitesses (m/s) pour les deux capteurs.")
        R = np.diag([position_std**2] * 2 + [velocity_std**2] * 2)
    return LinearGaussianModel(A, track.C, Q, R)


@lru_cache(maxsize=None)
def _unit_discretization(sensors: str):
    """:math:`A_k` et :math:`Q_k` de densité 1 aux pas du vol (calculés une fois)."""
    return constant_velocity(helicopter_track(sensors).dt, 1.0, dim=2)


class HelicopterFit(NamedTuple):
    r"""Paramètres appris : ``params`` = :math:`(q, \sigma_p)` ou :math:`(q, \sigma_p, \sigma_v)` (m²/s³, m,
    m/s), ``log_likelihood`` au maximum, ``n_evaluations`` (filtrages), ``converged``."""

    params: tuple[float, ...]
    log_likelihood: float
    n_evaluations: int
    converged: bool


@lru_cache(maxsize=None)
def helicopter_fit(sensors: str = "position") -> HelicopterFit:
    r"""Maximum de vraisemblance de :math:`\theta = \log(q, \sigma_p)` (positions seules) ou
    :math:`\log(q, \sigma_p, \sigma_v)` (deux capteurs) : :func:`~kalman_course.log_likelihood` (a priori
    connu) maximisée par ``scipy.optimize.minimize`` (L-BFGS-B, gradient par différences finies) depuis
    :math:`q = 10` m²/s³, :math:`\sigma_p = 2` m, :math:`\sigma_v = 1` m/s. (Sans les écarts-types de
    :func:`~kalman_course.maximum_likelihood`, dont la hessienne coûterait des centaines de filtrages.)"""
    import scipy.optimize

    track = helicopter_track(sensors)
    theta0 = np.log([10.0, 2.0] if sensors == "position" else [10.0, 2.0, 1.0])

    def cost(theta):
        return -log_likelihood(helicopter_model(track, *np.exp(theta)), track.y, track.x0, track.P0)

    opt = scipy.optimize.minimize(cost, theta0, method="L-BFGS-B")
    return HelicopterFit(tuple(float(v) for v in np.exp(opt.x)), float(-opt.fun), int(opt.nfev), bool(opt.success))


def fitted_parameters(sensors: str = "position") -> tuple[float, ...]:
    """Les paramètres appris : ``(q, σ_p)`` ou ``(q, σ_p, σ_v)`` (m²/s³, m, m/s)."""
    return helicopter_fit(sensors).params


def helicopter_filter(sensors: str = "position", accel_psd: float | None = None, position_std: float | None = None,
                      velocity_std: float | None = None, *, gate: float | None = None,
                      outliers: bool = False) -> FilterResult:
    """Le filtre de Kalman sur le vol (paramètres appris par défaut), avec porte ``gate`` et, si
    ``outliers``, les positions corrompues de :func:`with_outliers`."""
    track = helicopter_track(sensors)
    fitted = fitted_parameters(sensors)
    q = fitted[0] if accel_psd is None else accel_psd
    sp = fitted[1] if position_std is None else position_std
    sv = None if sensors == "position" else (fitted[2] if velocity_std is None else velocity_std)
    y = with_outliers(track) if outliers else track.y
    return kalman_filter(helicopter_model(track, q, sp, sv), y, track.x0, track.P0, gate=gate)


def with_outliers(track: HelicopterTrack) -> np.ndarray:
    """Les mesures de ``track`` dont les positions :data:`OUTLIER_ROWS` sont décalées de
    :data:`OUTLIER_OFFSETS` (m)."""
    y = np.array(track.y)
    rows = np.flatnonzero(track.position_rows)[list(OUTLIER_ROWS)]
    y[rows, :2] += np.array(OUTLIER_OFFSETS)
    return y


def prediction_rms(result: FilterResult, track: HelicopterTrack) -> float:
    r"""Écart quadratique moyen (m) entre chaque position mesurée et sa **prédiction** juste avant,
    :math:`\hat x_{k\mid k-1}` : l'erreur du filtre sur ce qu'il ne connaît pas encore (sans vérité terrain,
    la mesure suivante est le seul juge honnête)."""
    rows = track.position_rows
    err = np.asarray(track.y)[rows, :2] - result.x_pred[rows, :2]
    return float(np.sqrt(np.mean(np.sum(err**2, axis=1))))


def lost_track_time(result: FilterResult, track: HelicopterTrack, run: int = 5) -> float | None:
    """Instant (s) à partir duquel ``run`` positions de suite sont rejetées par la porte (piste perdue),
    ``None`` si cela n'arrive pas."""
    rejected = np.asarray(result.rejected)[track.position_rows]
    times = np.asarray(track.t)[track.position_rows]
    streak = np.convolve(rejected, np.ones(run, dtype=int), "valid")
    hits = np.flatnonzero(streak == run)
    return None if hits.size == 0 else float(times[hits[0]])


@dataclass(frozen=True)
class GateStudy:
    r"""La porte sur le vol (positions seules, paramètres appris).

    ``exceed_99``, ``exceed_999`` : part des positions dont la NIS du filtre **sans porte** dépasse le
    quantile 0,99 et 0,999 de :math:`\chi^2_2` ; ``rejected_999`` : positions rejetées par la porte
    :math:`p = 0{,}999` sur les données propres ; ``outliers_rejected`` : les positions corrompues rejetées
    (sur :data:`OUTLIER_ROWS`) ; ``other_rejected`` : autres positions rejetées dans cette expérience ;
    ``deviation_plain``, ``deviation_gated`` : plus grand écart de position (m) à l'estimation sur données
    propres, sans et avec la porte ; ``lost_at_99`` : instant de perte de la piste avec :math:`p = 0{,}99`
    (ou ``None``), ``regained_99`` : instant de la première position de nouveau acceptée ;
    ``lost_at_quiet`` : avec :math:`p = 0{,}999` et une densité 100 fois trop petite, ``quiet_rejected`` :
    part des positions alors rejetées après la perte, ``quiet_final_error`` : écart (m) entre la dernière
    estimation et la dernière position."""

    exceed_99: float
    exceed_999: float
    rejected_999: int
    outliers_rejected: int
    other_rejected: int
    deviation_plain: float
    deviation_gated: float
    lost_at_99: float | None
    regained_99: float | None
    lost_at_quiet: float | None
    quiet_rejected: float
    quiet_final_error: float


@lru_cache(maxsize=1)
def gate_study() -> GateStudy:
    """Les nombres de la section « porte » du chapitre."""
    from ..diagnostics.consistency import nis
    from ..filters.gating import gate_threshold

    track = helicopter_track("position")
    clean = helicopter_filter("position")
    e = nis(clean)
    gated_clean = helicopter_filter("position", gate=0.999)
    plain_bad = helicopter_filter("position", outliers=True)
    gated_bad = helicopter_filter("position", gate=0.999, outliers=True)
    bad_rows = np.flatnonzero(track.position_rows)[list(OUTLIER_ROWS)]
    rejected = np.flatnonzero(gated_bad.rejected)
    deviation = lambda r: float(np.max(np.hypot(*(r.x[:, :2] - clean.x[:, :2]).T)))  # noqa: E731
    q, sp = fitted_parameters("position")
    t = np.asarray(track.t)
    loose = helicopter_filter("position", gate=0.99)
    lost_at = lost_track_time(loose, track)
    regained = None
    if lost_at is not None:
        after = np.flatnonzero((t > lost_at) & ~np.asarray(loose.rejected))
        regained = float(t[after[0]]) if after.size else None
    quiet = helicopter_filter("position", q / 100.0, sp, gate=0.999)
    lost_quiet = lost_track_time(quiet, track)
    return GateStudy(
        exceed_99=float(np.mean(e > gate_threshold(0.99, 2))),
        exceed_999=float(np.mean(e > gate_threshold(0.999, 2))),
        rejected_999=int(gated_clean.rejected.sum()),
        outliers_rejected=int(np.isin(bad_rows, rejected).sum()),
        other_rejected=int((~np.isin(rejected, bad_rows)).sum()),
        deviation_plain=deviation(plain_bad),
        deviation_gated=deviation(gated_bad),
        lost_at_99=lost_at,
        regained_99=regained,
        lost_at_quiet=lost_quiet,
        quiet_rejected=float(np.mean(quiet.rejected[t >= lost_quiet])) if lost_quiet is not None else 0.0,
        quiet_final_error=float(np.hypot(*(quiet.x[-1, :2] - np.asarray(track.y)[-1, :2]))),
    )
