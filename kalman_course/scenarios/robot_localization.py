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
    "localization_benchmark", "heading_independence", "tiny_error_agreement",
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


def _run_curves(data: LocalizationData, chunk: int = CHUNK) -> LocalizationCurves:
    N, K = data.y.shape[:2]
    sums = {kind: {name: np.zeros(K) for name in ("position_mse", "heading_mse", "position_nees", "heading_nees")}
            for kind in _FILTERS}
    example = {"truth": np.array(data.truth[:, :2, 2]),
               "gnss": np.array(data.y[0][~np.isnan(data.y[0, :, 0])])}
    for start in range(0, N, chunk):
        sl = slice(start, min(N, start + chunk))
        for kind, run in _FILTERS.items():
            res = run(data.model, data.y[sl], data.T0[sl], data.P0, data.u[sl])
            e_p, e_t, nees_p, nees_t = _errors(data.truth, res)
            s = sums[kind]
            s["position_mse"] += np.sum(e_p**2, axis=(0, 2))
            s["heading_mse"] += np.sum(e_t**2, axis=0)
            s["position_nees"] += np.sum(nees_p, axis=0)
            s["heading_nees"] += np.sum(nees_t, axis=0)
            if start == 0:
                example[kind] = np.array(res.position[0])
            del res
    curves = {kind: {name: v / N for name, v in s.items()} for kind, s in sums.items()}
    return LocalizationCurves(N, data.model.dt * np.arange(1, K + 1), curves, example)


def localization_curves(n_runs: int, *, rng: Any, heading_std: float = HEADING_STD, gnss_every: int = GNSS_EVERY,
                        odometry_scale: float = 1.0, n_instants: int = N_INSTANTS) -> LocalizationCurves:
    """Les deux filtres sur ``n_runs`` tirages de :func:`localization_data` : courbes moyennes au cours du temps."""
    data = localization_data(n_runs, rng=rng, heading_std=heading_std, gnss_every=gnss_every,
                             odometry_scale=odometry_scale, n_instants=n_instants)
    return _run_curves(data)


def localization_benchmark(n_runs: int = 100, *, rng: Any) -> LocalizationBenchmark:
    r"""Le banc d'essai de ukfm sur ``n_runs`` tirages (réglages du module) : scores des deux filtres.
    ``rng`` : graine entière ou ``numpy.random.Generator`` (``None`` refusé) ; même ``rng``, mêmes nombres."""
    curves = localization_curves(n_runs, rng=rng)
    return LocalizationBenchmark(curves.n_runs, curves.scores("invariant"), curves.scores("standard"))


def heading_independence(headings_deg=(0.0, 90.0), n_instants: int = N_INSTANTS, rng: Any = 35) -> float:
    r"""Écart maximal entre les covariances :math:`P` de l'EKF invariant lancé sur les mêmes données depuis des
    caps initiaux différents (``headings_deg``) : nul à l'arrondi près, car :math:`F`, :math:`G`, :math:`H` ne
    dépendent que de l'odométrie."""
    data = localization_data(1, rng=rng, n_instants=n_instants)
    Ps = []
    for deg in headings_deg:
        a = np.radians(deg)
        T0 = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])
        Ps.append(se2_invariant_ekf_runs(data.model, data.y, T0, data.P0, data.u).P[0])
    return float(max(np.max(np.abs(P - Ps[0])) for P in Ps[1:]))


@lru_cache(maxsize=8)
def tiny_error_agreement(heading_std_deg: float = 0.01, rng: int = 35) -> float:
    """Écart maximal (m et rad) entre les poses des deux filtres quand l'erreur initiale de cap est minuscule."""
    data = localization_data(1, rng=rng, heading_std=np.radians(heading_std_deg))
    a = se2_invariant_ekf_runs(data.model, data.y, data.T0, data.P0, data.u)
    b = se2_standard_ekf_runs(data.model, data.y, data.T0, data.P0, data.u)
    return float(max(np.max(np.abs(a.position - b.position)), np.max(np.abs(wrap_angle(a.heading - b.heading)))))
