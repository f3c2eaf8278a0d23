r"""Curseurs du chapitre « EKF itéré sur SE(3) » : le bruit des pixels et l'erreur de pose.

:func:`~kalman_course.scenarios.camera_noise.noisy_pose` : la même image, avec un bruit de pixel
d'écart-type :math:`\sigma` que le filtre connaît. Un curseur choisit :math:`\sigma`, l'autre
l'itération :math:`i` de l'EKF itéré (0 : l'a priori ; 1 : l'EKF). Position par défaut :
:math:`\sigma = 1` px, le problème du chapitre, à la dernière itération (l'EKF itéré convergé).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..geometry.camera import camera_measurement
from ..scenarios.camera_noise import noisy_pose
from ..scenarios.camera_target import CAMERA, SIGMA_PX
from .figure import SliderSpec, number, register_sliders
from .grid import ParameterAxis, log_grid
from .spec import Glyph, Panel

__all__ = ["PIXEL_STDS", "max_shown", "EDGES", "se3_axes", "se3_run", "se3_spec"]

CHAPTER = "ekf-itere-se3"

#: Écarts-types des pixels proposés (px), trois par décade de 0,1 à 10 px.
PIXEL_STDS = log_grid(SIGMA_PX, 1, 1, 3)
@lru_cache(maxsize=1)
def max_shown() -> int:
    """Nombre d'itérations affichées : le plus grand nombre d'itérations sur la grille."""
    return max(noisy_pose(s).iterates.shape[0] - 1 for s in PIXEL_STDS)
#: Arêtes du pavé (les coins 0…7 diffèrent d'un seul bit).
EDGES = [(i, j) for i in range(8) for j in range(i + 1, 8) if bin(i ^ j).count("1") == 1]


def se3_axes() -> tuple[ParameterAxis, ParameterAxis]:
    """:math:`\\sigma` (1 px par défaut) et l'itération (la dernière par défaut)."""
    labels = ("0 (a priori)", "1 (EKF)") + tuple(str(i) for i in range(2, max_shown() + 1))
    return (
        ParameterAxis("sigma_px", "σ", "bruit des pixels", "px", PIXEL_STDS, default=3),
        ParameterAxis("iteration", "i", "itération de l'EKF itéré", "", np.arange(max_shown() + 1, dtype=float),
                      default=max_shown(), scale="index", tick_labels=labels),
    )


def _wireframe(T, problem) -> tuple[np.ndarray, np.ndarray]:
    uv = camera_measurement(T, problem.points, problem.camera).reshape(-1, 2)
    xs, ys = [], []
    for i, j in EDGES:
        xs += [uv[i, 0], uv[j, 0], np.nan]
        ys += [uv[i, 1], uv[j, 1], np.nan]
    return np.array(xs), np.array(ys)


def se3_run(sigma_px: float, iteration: float) -> dict[str, np.ndarray]:
    """Le pavé reprojeté à l'itéré :math:`i` et à l'a priori, les pixels mesurés, les erreurs de pose."""
    pose = noisy_pose(sigma_px)
    p = pose.problem
    i = int(iteration)
    N = pose.iterates.shape[0] - 1
    k = min(i, N)
    pad = max_shown() - N
    angle = np.concatenate([pose.angle_error, np.full(pad, pose.angle_error[-1])])
    position = np.concatenate([pose.position_error, np.full(pad, pose.position_error[-1])])
    wx, wy = _wireframe(pose.iterates[k], p)
    px, py = _wireframe(p.T_pred, p)
    uv = p.y.reshape(-1, 2)
    return {
        "wire_u": wx, "wire_v": wy, "prior_u": px, "prior_v": py,
        "pixel_u": uv[:, 0], "pixel_v": uv[:, 1],
        "angle": angle, "position": position,
        "angle_now": angle[i:i + 1], "position_now": position[i:i + 1], "iteration_now": np.array([float(i)]),
        "n_iter": np.array([float(N)]),
    }


def _readout(series, values) -> str:
    sigma, i = values[0], int(values[1])
    N = int(series["n_iter"][0])
    done = f", convergé en {N} itérations" if i >= N else ""
    return (f"σ = {number(sigma, 'px')}, itération {i}{done} : erreur d'orientation "
            f"{number(series['angle_now'][0])}°, erreur de position {number(series['position_now'][0], 'cm')}.")


@register_sliders("se3-bruit-pixels", chapter=CHAPTER)
def se3_spec() -> SliderSpec:
    """Pose de la cible : bruit des pixels et itérations."""
    return SliderSpec(
        name="se3-bruit-pixels",
        chapter=CHAPTER,
        title="Pose d'une cible vue par une caméra (a priori à 10° et 20 cm) : bruit des pixels et itérations",
        x_label="itération i",
        axes=se3_axes(),
        run=se3_run,
        time=np.arange(max_shown() + 1, dtype=float),
        panels=(
            Panel(
                f"Plan image (détail ; image {CAMERA.width} × {CAMERA.height} px)",
                "v (px)",
                (
                    Glyph("prior_v", "line", "darkorange", "a priori T̂₋", x="prior_u", dash="dashed", width=1.2),
                    Glyph("wire_v", "line", "royalblue", "itéré choisi", x="wire_u", width=1.5),
                    Glyph("pixel_v", "scatter", "black", "pixels mesurés y", x="pixel_u", marker="cross", size=10),
                ),
                x_label="u (px)",
                x_range=(190.0, 470.0),
                y_range=(345.0, 120.0),
                equal_aspect=True,
            ),
            Panel(
                "Erreur d'orientation à chaque itération",
                "angle (°)",
                (
                    Glyph("angle", "line", "royalblue", "angle entre orientation estimée et vraie"),
                    Glyph("angle", "scatter", "royalblue", "", marker="circle", size=5),
                    Glyph("angle_now", "scatter", "crimson", "itération choisie", x="iteration_now",
                          marker="circle", size=11),
                ),
                x_label="itération i",
                x_range=(-0.5, max_shown() + 0.5),
                y_log=True,
                y_range=(1e-3, 100.0),
                height=200,
            ),
            Panel(
                "Erreur de position à chaque itération",
                "distance (cm)",
                (
                    Glyph("position", "line", "seagreen", "distance entre position estimée et vraie"),
                    Glyph("position", "scatter", "seagreen", "", marker="circle", size=5),
                    Glyph("position_now", "scatter", "crimson", "itération choisie", x="iteration_now",
                          marker="circle", size=11),
                ),
                x_label="itération i",
                x_range=(-0.5, max_shown() + 0.5),
                y_log=True,
                y_range=(0.01, 100.0),
                height=200,
            ),
        ),
        readout=_readout,
    )
