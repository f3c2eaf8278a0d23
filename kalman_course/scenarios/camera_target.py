r"""Scénario « pose relative d'une cible connue vue par une caméra » (EKF itéré sur SE(3)).

Une cible rigide de 1,0 × 0,8 × 0,5 m porte 10 points connus (ses 8 coins et 2 marques) ; elle est à
environ 3,5 m devant une caméra 640 × 480 px (:math:`f_x = 520`, :math:`f_y = 500` px, point principal au
centre). Les pixels sont bruités à :math:`\sigma = 1` px. L'a priori est décalé de 10° et de 0,2 m, avec
:math:`P_- = \mathrm{diag}(0{,}2^2 I_3,\ (10°)^2 I_3)` (m², rad²). Tous les tirages ont une graine.

La fonction :func:`camera_map_estimate` calcule le maximum a posteriori **sans** le filtre ni le module
:mod:`kalman_course.lie` : ``scipy.optimize.least_squares`` sur :math:`T = \hat T_-\,\mathrm{expm}(\xi^\wedge)`
(``scipy.linalg.expm``), jacobienne par différences finies.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg
import scipy.optimize

from ..geometry.camera import PinholeCamera, camera_measurement
from ..geometry.lie import se3_exp, se3_inverse, se3_log
from ..filters.se3 import CameraPoseModel, SE3FilterResult, se3_iekf_update, se3_iterated_filter, se3_map_cost, se3_nees
from ..core.results import freeze, freeze_fields
from ..core.simulation import as_generator
from ..tables import Table

__all__ = [
    "CAMERA",
    "TARGET_POINTS",
    "TRUE_POSE",
    "PRIOR_ERROR",
    "PRIOR_COV",
    "SIGMA_PX",
    "CAMERA_SEED",
    "CameraTargetProblem",
    "camera_target_problem",
    "pose_error",
    "camera_map_estimate",
    "reference_pixels",
    "camera_measurement_only_fit",
    "camera_iteration_table",
    "CameraMonteCarlo",
    "camera_monte_carlo",
    "camera_tracking_data",
    "camera_tracking_run",
]

#: Caméra 640 × 480 px, :math:`f_x = 520`, :math:`f_y = 500` px, point principal (320, 240) px.
CAMERA = PinholeCamera(fx=520.0, fy=500.0, cx=320.0, cy=240.0, width=640, height=480)

_HX, _HY, _HZ = 0.5, 0.4, 0.25
#: Les 10 points connus (m, repère de la cible) : 8 coins du pavé 1,0 × 0,8 × 0,5 m et 2 marques.
TARGET_POINTS = np.array(
    [[sx * _HX, sy * _HY, sz * _HZ] for sz in (-1, 1) for sy in (-1, 1) for sx in (-1, 1)]
    + [[0.0, 0.2, -_HZ], [-0.25, -_HY, 0.1]]
)
TARGET_POINTS.setflags(write=False)

#: Pose vraie de la cible dans le repère de la caméra : à 3,5 m, tournée d'environ 25°.
TRUE_POSE = se3_exp([0.10, -0.05, 3.5, 0.0, 0.0, 0.0]) @ se3_exp([0.0, 0.0, 0.0, 0.25, -0.30, 0.15])
TRUE_POSE.setflags(write=False)

_ROT_AXIS = np.array([1.0, 2.0, -2.0]) / 3.0
_TRANS_DIR = np.array([2.0, -1.0, 2.0]) / 3.0
#: Écart de l'a priori à la vérité (tangent à droite) : 0,2 m et 10° : :math:`\hat T_- = T\,\mathrm{Exp}(\delta_0)`.
PRIOR_ERROR = np.concatenate([0.2 * _TRANS_DIR, np.deg2rad(10.0) * _ROT_AXIS])
PRIOR_ERROR.setflags(write=False)
#: :math:`P_- = \mathrm{diag}(0{,}2^2 I_3,\ (10°)^2 I_3)` (m², rad²).
PRIOR_COV = np.diag([0.2**2] * 3 + [np.deg2rad(10.0) ** 2] * 3)
PRIOR_COV.setflags(write=False)
#: Écart-type du bruit de pixel (px).
SIGMA_PX = 1.0
#: Graine du bruit de l'image unique du chapitre.
CAMERA_SEED = 2024


@dataclass(frozen=True, eq=False)
class CameraTargetProblem:
    r"""Une correction : a priori ``T_pred`` (4, 4), ``P_pred`` (6, 6), pixels ``y`` (2n,),
    pose vraie ``T_true`` (4, 4), ``points`` (n, 3), ``camera``, ``sigma_px``."""

    T_pred: np.ndarray
    P_pred: np.ndarray
    y: np.ndarray
    T_true: np.ndarray
    points: np.ndarray
    camera: PinholeCamera
    sigma_px: float

    def __post_init__(self) -> None:
        freeze_fields(self, "T_pred", "P_pred", "y", "T_true", "points")

    def iekf(self, max_iter: int = 20, tol: float = 1e-10, **kwargs):
        """:func:`~kalman_course.filters.se3.se3_iekf_update` sur ce problème."""
        return se3_iekf_update(self.T_pred, self.P_pred, self.y, self.points, self.camera, self.sigma_px,
                               max_iter=max_iter, tol=tol, **kwargs)

    def cost(self, T: Any) -> float:
        """Coût MAP :math:`J(T)`."""
        return se3_map_cost(T, self.T_pred, self.P_pred, self.y, self.points, self.camera, self.sigma_px)


def camera_target_problem(rng: Any = CAMERA_SEED, prior_error: Any = None) -> CameraTargetProblem:
    r"""L'image du chapitre : :math:`y = h(T) + \sigma\varepsilon`, :math:`\varepsilon\sim\mathcal N(0, I_{20})`
    (``rng``), a priori :math:`\hat T_- = T\,\mathrm{Exp}(\delta_0)` avec ``prior_error`` :math:`\delta_0`
    (6,) (:data:`PRIOR_ERROR` par défaut)."""
    gen = as_generator(rng)
    d0 = PRIOR_ERROR if prior_error is None else np.asarray(prior_error, dtype=float)
    y = camera_measurement(TRUE_POSE, TARGET_POINTS, CAMERA) + SIGMA_PX * gen.standard_normal(2 * len(TARGET_POINTS))
    return CameraTargetProblem(T_pred=TRUE_POSE @ se3_exp(d0), P_pred=PRIOR_COV, y=y, T_true=TRUE_POSE,
                               points=TARGET_POINTS, camera=CAMERA, sigma_px=SIGMA_PX)


def pose_error(T_est: Any, T_true: Any) -> tuple[float, float]:
    r"""Erreur d'une pose : angle de :math:`R_{\mathrm{est}}^TR_{\mathrm{vrai}}` (degrés) et
    :math:`\lVert t_{\mathrm{est}} - t_{\mathrm{vrai}}\rVert` (cm)."""
    T_est = np.asarray(T_est, dtype=float)
    T_true = np.asarray(T_true, dtype=float)
    c = 0.5 * (np.trace(T_est[:3, :3].T @ T_true[:3, :3]) - 1.0)
    return float(np.degrees(np.arccos(np.clip(c, -1.0, 1.0)))), float(100 * np.linalg.norm(T_est[:3, 3] - T_true[:3, 3]))


def _expm_pose(T0: np.ndarray, xi: np.ndarray) -> np.ndarray:
    X = np.zeros((4, 4))
    X[:3, :3] = [[0.0, -xi[5], xi[4]], [xi[5], 0.0, -xi[3]], [-xi[4], xi[3], 0.0]]
    X[:3, 3] = xi[:3]
    return T0 @ scipy.linalg.expm(X)


def reference_pixels(T: np.ndarray, points: np.ndarray, camera: PinholeCamera) -> np.ndarray:
    r"""Pixels :math:`[u_1, v_1, \dots]` (2N,) de la pose ``T``, écrits ici **indépendamment** de
    :mod:`kalman_course.geometry.camera` : c'est la projection des références (MAP par ``least_squares``,
    EKF recalculé dans les tests) qui contrôlent le filtre."""
    Pc = points @ T[:3, :3].T + T[:3, 3]
    return np.column_stack([camera.fx * Pc[:, 0] / Pc[:, 2] + camera.cx,
                            camera.fy * Pc[:, 1] / Pc[:, 2] + camera.cy]).ravel()


def _pixels(T: np.ndarray, problem: CameraTargetProblem) -> np.ndarray:
    return reference_pixels(T, problem.points, problem.camera)


def _solve(residuals, problem: CameraTargetProblem) -> np.ndarray:
    sol = scipy.optimize.least_squares(residuals, np.zeros(6), jac="3-point", xtol=1e-15, ftol=1e-15, gtol=1e-15)
    return _expm_pose(problem.T_pred, sol.x)


def camera_map_estimate(problem: CameraTargetProblem) -> np.ndarray:
    r"""MAP indépendant (4, 4) : ``least_squares`` sur :math:`\xi` avec :math:`T = \hat T_-\mathrm{expm}(\xi^\wedge)`
    et les résidus blanchis :math:`[L_P^{-1}\xi;\ (y - h(T))/\sigma]` (:math:`P_- = L_PL_P^T`)."""
    LP = np.linalg.cholesky(problem.P_pred)

    def residuals(xi):
        return np.concatenate([scipy.linalg.solve_triangular(LP, xi, lower=True),
                               (problem.y - _pixels(_expm_pose(problem.T_pred, xi), problem)) / problem.sigma_px])

    return _solve(residuals, problem)


def camera_measurement_only_fit(problem: CameraTargetProblem) -> np.ndarray:
    r"""Ajustement aux seules mesures (4, 4) : ``least_squares`` sur :math:`y - h(\hat T_-\mathrm{expm}(\xi^\wedge))`,
    sans l'a priori (la limite de la boucle écrite dans les notes)."""
    return _solve(lambda xi: problem.y - _pixels(_expm_pose(problem.T_pred, xi), problem), problem)


def camera_iteration_table(problem: CameraTargetProblem | None = None, T_map: Any = None) -> Table:
    r"""Tableau par itération de l'EKF itéré : coût :math:`J(T_i)`, erreur d'orientation (°) et de
    position (cm), distance au MAP :math:`\lVert\mathrm{Log}(T_{\mathrm{MAP}}^{-1}T_i)\rVert`. Ligne 0 :
    a priori ; ligne 1 : EKF."""
    p = camera_target_problem() if problem is None else problem
    T_map = camera_map_estimate(p) if T_map is None else np.asarray(T_map, dtype=float)
    out = p.iekf()
    errs = np.array([pose_error(T, p.T_true) for T in out.iterates])
    dist = [float(np.linalg.norm(se3_log(se3_inverse(T_map) @ T))) for T in out.iterates]
    labels = ["0 (a priori)", "1 (EKF)"] + [str(i) for i in range(2, out.iterates.shape[0])]
    return Table(
        ["itération $i$", "coût $J(T_i)$", "erreur d'orientation (°)", "erreur de position (cm)",
         r"$\lVert\mathrm{Log}(T_{\mathrm{MAP}}^{-1}T_i)\rVert$"],
        [labels, out.cost, errs[:, 0], errs[:, 1], dist],
        [None, "{:.6g}", "{:.3f}", "{:.3f}", "{:.1e}"],
    )


# --------------------------------------------------------------------------- Monte-Carlo


@dataclass(frozen=True, eq=False)
class CameraMonteCarlo:
    r"""Tirages indépendants (a priori :math:`\hat T_- = T\,\mathrm{Exp}(\delta_0)`, :math:`\delta_0\sim\mathcal N(0, P_-)`,
    nouveau bruit de pixels) : erreurs (°, cm) de l'EKF et de l'EKF itéré (R, 2), NEES (R,) et itérations (R,)."""

    ekf_error: np.ndarray
    iekf_error: np.ndarray
    ekf_nees: np.ndarray
    iekf_nees: np.ndarray
    n_iter: np.ndarray
    converged: np.ndarray

    @property
    def n_runs(self) -> int:
        """Nombre de tirages."""
        return self.ekf_nees.shape[0]


def camera_monte_carlo(n_runs: int = 200, rng: Any = 11, max_iter: int = 20) -> CameraMonteCarlo:
    """Monte-Carlo de la correction unique : EKF (une itération) contre EKF itéré."""
    gen = as_generator(rng)
    L = np.linalg.cholesky(PRIOR_COV)
    cols = {k: [] for k in ("ee", "ie", "en", "in", "n", "c")}
    for _ in range(n_runs):
        p = camera_target_problem(gen, prior_error=L @ gen.standard_normal(6))
        ekf = p.iekf(max_iter=1)
        iekf = p.iekf(max_iter=max_iter)
        cols["ee"].append(pose_error(ekf.T, p.T_true))
        cols["ie"].append(pose_error(iekf.T, p.T_true))
        cols["en"].append(se3_nees(ekf.T, ekf.P, p.T_true))
        cols["in"].append(se3_nees(iekf.T, iekf.P, p.T_true))
        cols["n"].append(iekf.n_iter)
        cols["c"].append(iekf.converged)
    return CameraMonteCarlo(
        ekf_error=freeze(cols["ee"]), iekf_error=freeze(cols["ie"]), ekf_nees=freeze(cols["en"]),
        iekf_nees=freeze(cols["in"]), n_iter=np.array(cols["n"]), converged=np.array(cols["c"]),
    )


# --------------------------------------------------------------------------- suivi


#: Incrément connu par image (tangent à droite) : la cible avance de 2 cm et tourne de 1° par image.
TRACK_INCREMENT = np.array([0.02, 0.0, 0.0, 0.0, np.deg2rad(1.0), 0.0])
TRACK_INCREMENT.setflags(write=False)
#: Covariance du bruit d'incrément : 5 mm et 0,3° par image.
TRACK_Q = np.diag([0.005**2] * 3 + [np.deg2rad(0.3) ** 2] * 3)
TRACK_Q.setflags(write=False)


def camera_tracking_data(n_frames: int = 30, rng: Any = 5):
    r"""Suivi : :math:`T_{k+1} = T_k\,\mathrm{Exp}(u + w_k)`, :math:`w_k\sim\mathcal N(0, Q)`, pixels bruités.

    Renvoie ``(T_true (F, 4, 4), y (F, 2n), u (F, 6), T0 (4, 4), P0 (6, 6))`` : ``T0`` est l'a priori,
    décalé de :data:`PRIOR_ERROR` de la pose vraie avant la première image."""
    gen = as_generator(rng)
    LQ = np.linalg.cholesky(TRACK_Q)
    T = np.array(TRUE_POSE)
    T0 = T @ se3_exp(PRIOR_ERROR)
    truth, ys = [], []
    for _ in range(n_frames):
        T = T @ se3_exp(TRACK_INCREMENT + LQ @ gen.standard_normal(6))
        truth.append(T)
        ys.append(camera_measurement(T, TARGET_POINTS, CAMERA) + SIGMA_PX * gen.standard_normal(2 * len(TARGET_POINTS)))
    U = np.tile(TRACK_INCREMENT, (n_frames, 1))
    return np.array(truth), np.array(ys), U, T0, np.array(PRIOR_COV)


def camera_tracking_run(n_frames: int = 30, rng: Any = 5, max_iter: int = 20) -> tuple[np.ndarray, SE3FilterResult]:
    """Données de :func:`camera_tracking_data` filtrées ; renvoie ``(T_true, résultat)``."""
    truth, y, U, T0, P0 = camera_tracking_data(n_frames, rng)
    model = CameraPoseModel(TARGET_POINTS, CAMERA, SIGMA_PX, TRACK_Q)
    return truth, se3_iterated_filter(model, y, T0, P0, U, max_iter=max_iter)
