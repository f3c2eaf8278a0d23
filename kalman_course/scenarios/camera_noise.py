r"""La pose de la cible vue par la caméra (chapitre « EKF itéré sur SE(3) ») avec un bruit de pixel
plus ou moins fort.

Même image que le chapitre (graine :data:`~.camera_target.CAMERA_SEED`, mêmes tirages normaux
:math:`\varepsilon`), mais des pixels mesurés :math:`y = h(T) + \sigma\,\varepsilon` avec un écart-type
:math:`\sigma` (px) que le filtre connaît. Pour :math:`\sigma = 1` px, c'est le problème du chapitre.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.results import freeze_fields
from ..core.simulation import as_generator
from ..core.validation import KalmanInputError, as_float_array
from ..geometry.camera import camera_measurement
from ..geometry.lie import se3_exp
from .camera_target import (
    CAMERA,
    CAMERA_SEED,
    PRIOR_COV,
    PRIOR_ERROR,
    SIGMA_PX,
    TARGET_POINTS,
    TRUE_POSE,
    CameraTargetProblem,
    pose_error,
)

__all__ = ["camera_problem_with_noise", "NoisyPose", "noisy_pose"]


def camera_problem_with_noise(sigma_px: float = SIGMA_PX, rng: Any = CAMERA_SEED) -> CameraTargetProblem:
    r"""L'image du chapitre avec un bruit de pixel d'écart-type ``sigma_px`` (px)."""
    v = as_float_array("sigma_px", sigma_px)
    if v.ndim != 0 or not (np.isfinite(v) and v > 0):
        raise KalmanInputError(f"« sigma_px » doit être un écart-type strictement positif (px) ; reçu {sigma_px!r}.")
    sigma = float(v)
    eps = as_generator(rng).standard_normal(2 * len(TARGET_POINTS))
    y = camera_measurement(TRUE_POSE, TARGET_POINTS, CAMERA) + sigma * eps
    return CameraTargetProblem(T_pred=TRUE_POSE @ se3_exp(PRIOR_ERROR), P_pred=PRIOR_COV, y=y, T_true=TRUE_POSE,
                               points=TARGET_POINTS, camera=CAMERA, sigma_px=sigma)


@dataclass(frozen=True, eq=False)
class NoisyPose:
    r"""``problem`` ; ``iterates`` (N+1, 4, 4) poses de l'EKF itéré (:math:`T_0 = \hat T_-`, :math:`T_1` = EKF) ;
    ``angle_error`` (N+1,) (°) et ``position_error`` (N+1,) (cm) par rapport à la pose vraie ; ``converged``."""

    problem: CameraTargetProblem
    iterates: np.ndarray
    angle_error: np.ndarray
    position_error: np.ndarray
    converged: bool

    def __post_init__(self) -> None:
        freeze_fields(self, "iterates", "angle_error", "position_error")


def noisy_pose(sigma_px: float = SIGMA_PX, max_iter: int = 20, tol: float = 1e-10) -> NoisyPose:
    """L'EKF itéré sur SE(3) du problème à ``sigma_px`` et l'erreur de pose de chaque itéré."""
    p = camera_problem_with_noise(sigma_px)
    out = p.iekf(max_iter=max_iter, tol=tol)
    errors = np.array([pose_error(T, p.T_true) for T in out.iterates])
    return NoisyPose(p, out.iterates, errors[:, 0], errors[:, 1], bool(out.converged))
