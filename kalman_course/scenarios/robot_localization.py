r"""Localisation d'un robot plan par odométrie et GNSS : le banc d'essai de Barrau & Bonnabel (2017, § IV),
celui de ukfm (``python/benchmarks/localization.py``), pour l'EKF invariant et l'EKF standard sur SE(2).

Le robot décrit un cercle de 5 m de rayon en 40 s (:math:`v = [2\pi\cdot 5/40,\ 0]` m/s,
:math:`\omega = 2\pi/40` rad/s), odométrie à 100 Hz (:math:`dt = 0{,}01` s, 4 000 instants, bruits
:math:`[0{,}01\ \mathrm{m/s},\ 0{,}01\ \mathrm{m/s},\ 1°/\mathrm s]`), GNSS à 1 Hz (:math:`\sigma = 1` m, aux instants
100, 200, …, 3 900) ; la position de départ est connue, le cap est faux de :math:`\varepsilon \sim
\mathcal N(0, (45°)^2)`, :math:`P_0 = \mathrm{diag}(0, 0, (45°)^2)`. Les deux filtres reçoivent les mêmes données.

Erreurs : :math:`e_p = p - \hat p`, :math:`e_\theta = \mathrm{wrap}(\theta - \hat\theta)`. RMSE sur tous les
tirages et toutes les lignes ; NEES (sur les lignes :math:`k \ge 1\,999`, :math:`t \ge 20` s) par bloc, avec
:math:`\Sigma` = ``P_world`` : position :math:`e_p^T\Sigma_{pp}^{-1}e_p/2`, cap :math:`e_\theta^2/\Sigma_{\theta\theta}`
(≈ 1 pour un filtre cohérent).

Les tirages sont filtrés en lot (:func:`~kalman_course.se2_invariant_ekf_runs`), par paquets de
:data:`CHUNK` tirages (mémoire bornée) ; tous les tirages au hasard sont faits d'abord, dans un ordre fixe :
mêmes graines, mêmes nombres, quel que soit le découpage.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from ..core.angles import wrap_angle
from ..core.results import freeze_fields
from ..core.simulation import as_generator, check_positive_int
from ..core.validation import KalmanInputError
from ..filters.invariant import OdometryGnssModel, se2_invariant_ekf_runs, se2_standard_ekf_runs

__all__ = [
    "DT", "N_INSTANTS", "RADIUS", "SPEED", "TURN_RATE", "ODOMETRY_STD", "GNSS_STD", "GNSS_EVERY",
    "HEADING_STD", "NEES_FROM", "CHUNK", "UKFM_TABLE",
    "localization_model", "true_poses", "LocalizationData", "localization_data",
    "FilterScores", "LocalizationBenchmark", "LocalizationCurves", "localization_curves",
    "localization_benchmark", "heading_independence", "tiny_error_agreement", "ukfm_noise_model",
    "SliderStudy", "slider_study", "TwoHeadings", "two_headings",
]

#: Période de l'odométrie (s) et nombre d'instants (40 s).
DT = 0.01
N_INSTANTS = 4000
#: Rayon du cercle (m), vitesse d'avance (m/s) et vitesse de rotation (rad/s).
RADIUS = 5.0
SPEED = 2.0 * np.pi * RADIUS / 40.0
TURN_RATE = 2.0 * np.pi / 40.0
#: Écarts-types de l'odométrie [σ_vx, σ_vy, σ_ω] (m/s, m/s, rad/s) et du GNSS (m).
ODOMETRY_STD = np.array([0.01, 0.01, np.pi / 180.0])
GNSS_STD = 1.0
#: Une position GNSS tous les 100 instants (1 Hz), aux instants 100, 200, …, 3 900.
GNSS_EVERY = 100
#: Écart-type de l'erreur initiale de cap (rad) : 45°.
HEADING_STD = np.pi / 4.0
#: Première ligne de la NEES (instant 2 000, t = 20 s).
NEES_FROM = 1999
#: Tirages filtrés ensemble (mémoire d'un paquet : environ 40 Mo).
CHUNK = 25

#: La table imprimée par ukfm (``python/benchmarks/localization.py``, 100 tirages, documentation 2020) :
#: filtre → (RMSE de position (m), RMSE de cap (°), NEES de position, NEES de cap).
UKFM_TABLE = {"invariant": (0.45, 11.35, 2.02, 1.00), "standard": (0.76, 12.00, 275.28, 4.91)}


def localization_model(odometry_scale: float = 1.0, dt: float = DT) -> OdometryGnssModel:
    """Le modèle du banc d'essai ; ``odometry_scale`` multiplie les trois écarts-types de l'odométrie."""
    return OdometryGnssModel(dt, odometry_scale * ODOMETRY_STD, GNSS_STD)


def true_poses(n_instants: int = N_INSTANTS, dt: float = DT) -> np.ndarray:
    r"""Poses vraies (n, 3, 3) aux instants 0 … n − 1 : :math:`R_0 = I`, :math:`p_0 = 0`, odométrie sans bruit,
    :math:`\theta_k = \omega k\,dt`, :math:`p_{k+1} = p_k + R(\theta_k)v\,dt`."""
    n = check_positive_int("n_instants", n_instants, 2)
    theta = TURN_RATE * dt * np.arange(n)
    c, s = np.cos(theta), np.sin(theta)
    steps = SPEED * dt * np.stack([c[:-1], s[:-1]], axis=1)  # R(θ_k) [v, 0] dt
    T = np.zeros((n, 3, 3))
    T[:, 0, 0], T[:, 0, 1], T[:, 1, 0], T[:, 1, 1], T[:, 2, 2] = c, -s, s, c, 1.0
    T[1:, :2, 2] = np.cumsum(steps, axis=0)
    return T


@dataclass(frozen=True, eq=False)
class LocalizationData:
    r"""Données de ``N`` tirages : ``truth`` (K + 1, 3, 3) poses vraies (communes : odométrie vraie sans bruit) ;
    ``y`` (N, K, 2) positions GNSS (NaN sans position) ; ``u`` (N, K, 3) odométrie bruitée ; ``T0`` (N, 3, 3)
    poses de départ des filtres ; ``P0`` (3, 3) ; ``model``."""

    truth: np.ndarray
    y: np.ndarray
    u: np.ndarray
    T0: np.ndarray
    P0: np.ndarray
    model: OdometryGnssModel

    def __post_init__(self) -> None:
        freeze_fields(self, "truth", "y", "u", "T0", "P0")


def localization_data(n_runs: int, *, rng: Any, heading_std: float = HEADING_STD, gnss_every: int = GNSS_EVERY,
                      odometry_scale: float = 1.0, n_instants: int = N_INSTANTS, dt: float = DT) -> LocalizationData:
    r"""Tire ``n_runs`` jeux de données du banc d'essai (graine entière ou ``Generator`` ; ``None`` refusé).

    Ordre des tirages : erreurs de cap :math:`\varepsilon` (N,), bruits d'odométrie (N, K, 3), bruits GNSS
    (N, F, 2). ``heading_std`` (rad) ≥ 0 : écart-type de :math:`\varepsilon` (et :math:`P_0 =
    \mathrm{diag}(0, 0, \sigma^2)`) ; ``gnss_every`` : instants entre deux positions (aux instants ``gnss_every``,
    ``2 gnss_every``… avant ``n_instants``, comme ukfm) ; ``odometry_scale`` multiplie
    les écarts-types de l'odométrie."""
    N = check_positive_int("n_runs", n_runs)
    g = as_generator(rng)
    every = check_positive_int("gnss_every", gnss_every)
    if not (np.isfinite(heading_std) and heading_std >= 0):
        raise KalmanInputError(f"« heading_std » doit être un écart-type ≥ 0 (rad) ; reçu {heading_std!r}.")
    model = localization_model(odometry_scale, dt)
    truth = true_poses(n_instants, dt)
    K = truth.shape[0] - 1
    eps = heading_std * g.standard_normal(N)
    u_true = np.array([SPEED, 0.0, TURN_RATE])
    u = u_true + model.odometry_std * g.standard_normal((N, K, 3))
    fixes = np.arange(every, K + 1, every)  # instants 100, 200, …, 3 900 pour K + 1 = 4 000 (comme ukfm)
    y = np.full((N, K, 2), np.nan)
    y[:, fixes - 1] = truth[fixes, :2, 2] + GNSS_STD * g.standard_normal((N, fixes.size, 2))
    c, s = np.cos(eps), np.sin(eps)
    T0 = np.zeros((N, 3, 3))
    T0[:, 0, 0], T0[:, 0, 1], T0[:, 1, 0], T0[:, 1, 1], T0[:, 2, 2] = c, -s, s, c, 1.0  # T_vrai,0 Exp([0, 0, ε])
    P0 = np.diag([0.0, 0.0, heading_std**2])
    return LocalizationData(truth, y, u, T0, P0, model)


@dataclass(frozen=True, eq=False)
class FilterScores:
    """Scores d'un filtre : RMSE de position (m) et de cap (°), NEES moyennes de position et de cap."""

    position_rmse: float
    heading_rmse_deg: float
    position_nees: float
    heading_nees: float


@dataclass(frozen=True, eq=False)
class LocalizationBenchmark:
    """Le banc d'essai sur ``n_runs`` tirages : scores de l'EKF invariant et de l'EKF standard."""

    n_runs: int
    invariant: FilterScores
    standard: FilterScores


@dataclass(frozen=True, eq=False)
class LocalizationCurves:
    r"""Courbes moyennes sur ``n_runs`` tirages, ligne ``k`` = instant ``k + 1`` (``t`` (K,) en s) ; pour chaque
    filtre (``"invariant"``, ``"standard"``) : ``position_mse`` (K,) :math:`\overline{|e_p|^2}` (m²),
    ``heading_mse`` (K,) (rad²), ``position_nees`` et ``heading_nees`` (K,). ``example`` : positions vraies
    (K + 1, 2), GNSS (F, 2) et estimées (K, 2) par chaque filtre, au premier tirage."""

    n_runs: int
    t: np.ndarray
    curves: dict
    example: dict

    def scores(self, kind: str, nees_from: int = NEES_FROM) -> FilterScores:
        """Les scores d'un filtre : moyennes sur toutes les lignes (RMSE), sur les lignes ≥ ``nees_from`` (NEES)."""
        c = self.curves[kind]
        return FilterScores(
            position_rmse=float(np.sqrt(np.mean(c["position_mse"]))),
            heading_rmse_deg=float(np.degrees(np.sqrt(np.mean(c["heading_mse"])))),
            position_nees=float(np.mean(c["position_nees"][nees_from:])),
            heading_nees=float(np.mean(c["heading_nees"][nees_from:])),
        )


_FILTERS = {"invariant": se2_invariant_ekf_runs, "standard": se2_standard_ekf_runs}


def ukfm_noise_model(model: OdometryGnssModel) -> OdometryGnssModel:
    r"""Le modèle de bruit que voit l'EKF invariant de ukfm : sa matrice :math:`G = dt\,I` range le bruit
    :math:`[w_{v_x}, w_{v_y}, w_\omega]` sur son erreur :math:`[\theta, x, y]` dans l'ordre des indices, donc
    :math:`\sigma_{v_x}` sur le cap, :math:`\sigma_{v_y}` sur :math:`x` et :math:`\sigma_\omega` sur :math:`y`. Dans
    l'ordre du paquet :math:`[\rho_x, \rho_y, \theta]`, c'est le modèle aux écarts-types
    :math:`[\sigma_{v_y}, \sigma_\omega, \sigma_{v_x}]` (à la rotation :math:`\mathrm{Exp}(\omega\,dt)^T` près, de
    0,09° par pas)."""
    s = model.odometry_std
    return OdometryGnssModel(model.dt, [s[1], s[2], s[0]], model.gnss_std)


def _errors(truth: np.ndarray, res) -> tuple[np.ndarray, ...]:
    """Erreurs (N, K, 2) et (N, K) et NEES (N, K) de position et de cap d'un lot filtré."""
    e_p = truth[None, 1:, :2, 2] - res.position
    e_t = wrap_angle(np.arctan2(truth[None, 1:, 1, 0], truth[None, 1:, 0, 0]) - res.heading)
    W = res.P_world
    a, b, d = W[..., 0, 0], W[..., 0, 1], W[..., 1, 1]
    x, y = e_p[..., 0], e_p[..., 1]
    with np.errstate(divide="ignore", invalid="ignore"):  # Σ_pp singulière (P0 nulle en position) : inf
        nees_p = 0.5 * (d * x * x - 2.0 * b * x * y + a * y * y) / (a * d - b * b)  # e_pᵀ Σ_pp⁻¹ e_p / 2
        nees_t = e_t**2 / W[..., 2, 2]
    return e_p, e_t, nees_p, nees_t


_CURVE_NAMES = ("position_mse", "heading_mse", "position_nees", "heading_nees")


def _curve_terms(truth, res) -> dict[str, np.ndarray]:
    """Par tirage et par ligne (N, K) : erreurs quadratiques de position (m²) et de cap (rad²), NEES."""
    e_p, e_t, nees_p, nees_t = _errors(truth, res)
    return {"position_mse": np.sum(e_p**2, axis=-1), "heading_mse": e_t**2, "position_nees": nees_p,
            "heading_nees": nees_t}


def _run_curves(data: LocalizationData, chunk: int = CHUNK, filters: dict | None = None) -> LocalizationCurves:
    """Les filtres ``filters`` (nom → (filtre en lot, modèle du filtre) ; par défaut les deux filtres avec le
    modèle des données) sur toutes les données, par paquets de ``chunk`` tirages."""
    N, K = data.y.shape[:2]
    filters = filters or {kind: (run, data.model) for kind, run in _FILTERS.items()}
    sums = {kind: {name: np.zeros(K) for name in _CURVE_NAMES} for kind in filters}
    example = {"truth": np.array(data.truth[:, :2, 2]),
               "gnss": np.array(data.y[0][~np.isnan(data.y[0, :, 0])])}
    for start in range(0, N, chunk):
        sl = slice(start, min(N, start + chunk))
        for kind, (run, model) in filters.items():
            res = run(model, data.y[sl], data.T0[sl], data.P0, data.u[sl])
            for name, values in _curve_terms(data.truth, res).items():
                sums[kind][name] += values.sum(axis=0)
            if start == 0:
                example[kind] = np.array(res.position[0])
            del res
    curves = {kind: {name: v / N for name, v in s.items()} for kind, s in sums.items()}
    return LocalizationCurves(N, data.model.dt * np.arange(1, K + 1), curves, example)


def localization_curves(n_runs: int, *, rng: Any, heading_std: float = HEADING_STD, gnss_every: int = GNSS_EVERY,
                        odometry_scale: float = 1.0, n_instants: int = N_INSTANTS,
                        ukfm_g: bool = False) -> LocalizationCurves:
    """Les deux filtres sur ``n_runs`` tirages de :func:`localization_data` : courbes moyennes au cours du temps.
    ``ukfm_g=True`` ajoute l'EKF invariant avec le bruit que lui donne ukfm (:func:`ukfm_noise_model`), sous le
    nom ``"invariant_ukfm"``."""
    data = localization_data(n_runs, rng=rng, heading_std=heading_std, gnss_every=gnss_every,
                             odometry_scale=odometry_scale, n_instants=n_instants)
    filters = {kind: (run, data.model) for kind, run in _FILTERS.items()}
    if ukfm_g:
        filters["invariant_ukfm"] = (se2_invariant_ekf_runs, ukfm_noise_model(data.model))
    return _run_curves(data, filters=filters)


def localization_benchmark(n_runs: int = 100, *, rng: Any) -> LocalizationBenchmark:
    r"""Le banc d'essai de ukfm sur ``n_runs`` tirages (réglages du module) : scores des deux filtres.
    ``rng`` : graine entière ou ``numpy.random.Generator`` (``None`` refusé) ; même ``rng``, mêmes nombres."""
    curves = localization_curves(n_runs, rng=rng)
    return LocalizationBenchmark(curves.n_runs, curves.scores("invariant"), curves.scores("standard"))


def heading_independence(headings_deg=(0.0, 90.0), rng: int = 35) -> float:
    r"""Écart maximal entre les covariances :math:`P` de l'EKF invariant lancé sur les mêmes données (un tirage du
    banc d'essai) depuis des caps initiaux différents (``headings_deg``) : nul à l'arrondi près, car :math:`F`,
    :math:`G`, :math:`H` ne dépendent que de l'odométrie (:func:`two_headings`)."""
    return two_headings(tuple(float(h) for h in headings_deg), rng).invariant_gap


@lru_cache(maxsize=8)
def tiny_error_agreement(heading_std_deg: float = 0.01, rng: int = 35) -> float:
    """Écart maximal (m et rad) entre les poses des deux filtres quand l'erreur initiale de cap est minuscule."""
    from ..filters.invariant import se2_invariant_ekf, se2_standard_ekf

    data = localization_data(1, rng=rng, heading_std=np.radians(heading_std_deg))
    a = se2_invariant_ekf(data.model, data.y[0], data.T0[0], data.P0, data.u[0])
    b = se2_standard_ekf(data.model, data.y[0], data.T0[0], data.P0, data.u[0])
    return float(max(np.max(np.abs(a.position - b.position)), np.max(np.abs(wrap_angle(a.heading - b.heading)))))


# --------------------------------------------------------------------------- l'expérience des curseurs

#: Les curseurs du chapitre rejouent le banc d'essai en plus léger : odométrie à 5 Hz (200 instants, 40 s),
#: :data:`SLIDER_RUNS` tirages par position des curseurs, erreurs initiales de cap aux quantiles
#: :math:`(i + 1/2)/M` de la loi normale (un échantillon régulier, sans tirage chanceux ni malchanceux),
#: mêmes bruits d'odométrie et de GNSS (nombres aléatoires communs) à toutes les positions. À 5 Hz, les
#: écarts-types par mesure de l'odométrie sont ceux du banc d'essai divisés par √20 : même dérive par seconde
#: (variance :math:`\sigma^2dt` par seconde).
SLIDER_DT = 0.2
SLIDER_INSTANTS = 200
SLIDER_RUNS = 8
SLIDER_SEED = 35
SLIDER_HEADINGS_DEG = (0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 90.0)
SLIDER_GNSS_PERIODS = (0.4, 1.0, 2.0)
SLIDER_ODOMETRY_SCALES = (0.3, 1.0, 3.0)
#: Un point des courbes des curseurs toutes les SLIDER_EVERY lignes (0,4 s).
SLIDER_EVERY = 2
#: Première ligne des moyennes des curseurs (t ≥ 20 s).
SLIDER_FROM = 99


@dataclass(frozen=True, eq=False)
class SliderStudy:
    r"""L'expérience des curseurs pour un bruit d'odométrie : ``t`` (L,) instants des courbes (s) ;
    ``runs[(cap en °, période GNSS en s)]`` → séries moyennes sur les :data:`SLIDER_RUNS` tirages, pour
    ``inv`` (EKF invariant) et ``std`` (EKF standard) : ``*_nees`` (L,) NEES de position, ``*_rmse`` (L,) erreur
    quadratique moyenne de position (m), ``*_nees_mean`` et ``*_rmse_mean`` (1,) : NEES moyenne sur
    t ≥ 20 s et RMSE sur tout le trajet."""

    odometry_scale: float
    t: np.ndarray
    runs: dict


def _heading_quantiles(M: int) -> np.ndarray:
    from scipy.special import ndtri

    return ndtri((np.arange(M) + 0.5) / M)


@lru_cache(maxsize=4)
def slider_study(odometry_scale: float) -> SliderStudy:
    """Les deux filtres, en un lot chacun, sur toutes les positions des curseurs de cap et de période GNSS
    (7 × 3 × :data:`SLIDER_RUNS` tirages) pour ce bruit d'odométrie (multiple de celui du banc d'essai,
    :data:`ODOMETRY_STD` à 100 Hz)."""
    M, dt = SLIDER_RUNS, SLIDER_DT
    g = np.random.default_rng(SLIDER_SEED)
    truth = true_poses(SLIDER_INSTANTS, dt)
    K = truth.shape[0] - 1
    z_odo = g.standard_normal((M, K, 3))
    z_gnss = g.standard_normal((M, K, 2))
    q = _heading_quantiles(M)
    model = OdometryGnssModel(dt, odometry_scale * ODOMETRY_STD * np.sqrt(DT / dt), GNSS_STD)
    keys = [(h, period) for h in SLIDER_HEADINGS_DEG for period in SLIDER_GNSS_PERIODS]
    N = len(keys) * M
    y = np.full((N, K, 2), np.nan)
    T0 = np.zeros((N, 3, 3))
    P0 = np.zeros((N, 3, 3))
    for j, (h, period) in enumerate(keys):
        sl = slice(j * M, (j + 1) * M)
        every = int(round(period / dt))
        rows = np.arange(every, K + 1, every) - 1
        y[sl, rows] = truth[rows + 1, :2, 2] + GNSS_STD * z_gnss[:, rows]
        eps = np.radians(h) * q
        T0[sl, 0, 0], T0[sl, 0, 1], T0[sl, 1, 0], T0[sl, 1, 1], T0[sl, 2, 2] = (
            np.cos(eps), -np.sin(eps), np.sin(eps), np.cos(eps), 1.0)
        P0[sl, 2, 2] = np.radians(h) ** 2
    u = np.array([SPEED, 0.0, TURN_RATE]) + model.odometry_std * np.tile(z_odo, (len(keys), 1, 1))
    pick = slice(SLIDER_EVERY - 1, None, SLIDER_EVERY)
    runs = {key: {} for key in keys}
    for prefix, run in (("inv", se2_invariant_ekf_runs), ("std", se2_standard_ekf_runs)):
        terms = _curve_terms(truth, run(model, y, T0, P0, u))
        mse = terms["position_mse"].reshape(len(keys), M, K).mean(axis=1)
        nees = terms["position_nees"].reshape(len(keys), M, K).mean(axis=1)
        for j, key in enumerate(keys):
            runs[key].update({
                f"{prefix}_nees": nees[j, pick], f"{prefix}_rmse": np.sqrt(mse[j, pick]),
                f"{prefix}_nees_mean": np.array([nees[j, SLIDER_FROM:].mean()]),
                f"{prefix}_rmse_mean": np.array([np.sqrt(mse[j].mean())]),
            })
    return SliderStudy(float(odometry_scale), dt * np.arange(1, K + 1)[pick], runs)


# --------------------------------------------------------------------------- deux caps initiaux


@dataclass(frozen=True, eq=False)
class TwoHeadings:
    r"""Un tirage du banc d'essai filtré depuis deux caps initiaux (``headings_deg``, la position de départ
    étant juste), avec la même :math:`P_0` : ``invariant[i]`` et ``standard[i]`` sont les
    :class:`~kalman_course.SE2FilterResult` du cap ``headings_deg[i]`` ; ``data`` : les données."""

    headings_deg: tuple
    data: LocalizationData
    invariant: tuple
    standard: tuple

    @property
    def invariant_gap(self) -> float:
        """Écart maximal entre les covariances :math:`P` de l'EKF invariant des différents caps."""
        return float(max(np.max(np.abs(r.P - self.invariant[0].P)) for r in self.invariant[1:]))

    @property
    def standard_gap(self) -> float:
        """Le même écart pour l'EKF standard."""
        return float(max(np.max(np.abs(r.P - self.standard[0].P)) for r in self.standard[1:]))


@lru_cache(maxsize=4)
def two_headings(headings_deg: tuple = (0.0, 60.0), rng: int = SLIDER_SEED) -> TwoHeadings:
    """Le tirage ``rng`` du banc d'essai (vérité de cap nul), filtré par les deux filtres depuis chacun des caps
    ``headings_deg`` (°), avec :math:`P_0 = \\mathrm{diag}(0, 0, (45°)^2)`."""
    from ..filters.invariant import se2_invariant_ekf, se2_standard_ekf

    data = localization_data(1, rng=rng)
    inv, std = [], []
    for deg in headings_deg:
        a = np.radians(deg)
        T0 = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])
        inv.append(se2_invariant_ekf(data.model, data.y[0], T0, data.P0, data.u[0]))
        std.append(se2_standard_ekf(data.model, data.y[0], T0, data.P0, data.u[0]))
    return TwoHeadings(tuple(headings_deg), data, tuple(inv), tuple(std))
