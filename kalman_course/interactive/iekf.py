r"""Curseurs du chapitre « Filtre de Kalman étendu itéré » : les itérés de Gauss–Newton, un par un.

:func:`~kalman_course.scenarios.radar_prior.prior_iterations` : la correction du radar précis avec un
a priori d'écart-type :math:`\sigma_0`. Un curseur choisit l'itération :math:`i` (0 : l'a priori ; 1 :
l'EKF), l'autre :math:`\sigma_0`. Position par défaut : :math:`\sigma_0 = 3` m (le problème du chapitre),
:math:`i = 1` (l'EKF).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..scenarios.radar import RADAR_PRIOR, RADAR_TRUTH
from ..scenarios.radar_prior import RADAR_PRIOR_STD, prior_iterations
from .figure import SliderSpec, ellipse_outline, number, register_sliders
from .grid import ParameterAxis, log_grid
from .spec import Glyph, Panel

__all__ = ["max_shown", "iekf_axes", "iekf_run", "iekf_spec"]

CHAPTER = "ekf-itere"

#: Plancher d'affichage des distances (échelle logarithmique).
FLOOR = 1e-16


def _prior_stds() -> np.ndarray:
    return log_grid(RADAR_PRIOR_STD, 1, 1, 2)


@lru_cache(maxsize=1)
def max_shown() -> int:
    """Nombre d'itérations affichées : le plus grand nombre d'itérations sur la grille."""
    return max(prior_iterations(s).iterates.shape[0] - 1 for s in _prior_stds())


def iekf_axes() -> tuple[ParameterAxis, ParameterAxis]:
    """L'itération :math:`i` (1 par défaut) et l'écart-type a priori :math:`\\sigma_0` (3 m par défaut)."""
    labels = ("0 (a priori)", "1 (EKF)") + tuple(str(i) for i in range(2, max_shown() + 1))
    return (
        ParameterAxis("iteration", "i", "itération de Gauss–Newton", "", np.arange(max_shown() + 1, dtype=float),
                      default=1, scale="index", tick_labels=labels),
        ParameterAxis("prior_std", "σ₀", "écart-type de l'a priori", "m", _prior_stds(), default=2),
    )


def iekf_run(iteration: float, prior_std: float) -> dict[str, np.ndarray]:
    """Le chemin des itérés jusqu'à :math:`i`, l'itéré courant, l'ellipse a priori, la distance au MAP."""
    it = prior_iterations(prior_std)
    i = int(iteration)
    N = it.iterates.shape[0] - 1
    padded = np.vstack([it.iterates, np.repeat(it.iterates[-1:], max_shown() - N, axis=0)])
    dist = np.concatenate([it.distance_to_map, np.full(max_shown() - N, it.distance_to_map[-1])])
    cost = np.concatenate([it.cost, np.full(max_shown() - N, it.cost[-1])])
    path = padded.copy()
    path[i + 1:] = np.nan
    ex, ey = ellipse_outline(it.problem.x_pred, it.problem.P_pred, scale=1.0)
    return {
        "path_x": path[:, 0], "path_y": path[:, 1],
        "now_x": padded[i:i + 1, 0], "now_y": padded[i:i + 1, 1],
        "ekf_x": it.iterates[1:2, 0], "ekf_y": it.iterates[1:2, 1],
        "map_x": it.map[:1], "map_y": it.map[1:],
        "prior_x": ex, "prior_y": ey,
        "distance": np.maximum(dist, FLOOR),
        "distance_now": np.array([max(dist[i], FLOOR)]),
        "iteration_now": np.array([float(i)]),
        "cost_now": np.array([cost[i]]),
        "error_now": np.array([np.linalg.norm(padded[i] - it.problem.truth)]),
        "n_iter": np.array([float(N)]),
    }


def _readout(series, values) -> str:
    i = int(values[0])
    N = int(series["n_iter"][0])
    done = f" (convergé en {N} itérations)" if i >= N else ""
    return (f"Itération {i}{done} : coût J = {number(series['cost_now'][0], significant=6)}, distance au MAP "
            f"{number(series['distance_now'][0], 'm')}, distance à la cible vraie {number(series['error_now'][0], 'm')}.")


@register_sliders("ekf-itere-curseurs", chapter=CHAPTER)
def iekf_spec() -> SliderSpec:
    """Les itérés de l'EKF itéré marchent vers le maximum a posteriori."""
    return SliderSpec(
        name="ekf-itere-curseurs",
        chapter=CHAPTER,
        title="Radar précis (5 cm, 0,5°), a priori x̂⁻ = (10 ; 0) m : itérez, changez la confiance dans l'a priori",
        x_label="itération i",
        axes=iekf_axes(),
        run=iekf_run,
        time=np.arange(max_shown() + 1, dtype=float),
        panels=(
            Panel(
                "Les itérés x⁽ⁱ⁾ dans le plan",
                "y (m)",
                (
                    Glyph("prior_y", "line", "darkorange", "a priori x̂⁻, 1σ", x="prior_x", dash="dashed",
                          clip=True),  # l'ellipse de σ₀ = 30 m déborde du détail
                    Glyph("path_y", "line", "royalblue", "itérés de Gauss–Newton", x="path_x"),
                    Glyph("path_y", "scatter", "royalblue", "", x="path_x", marker="circle", size=6),
                    Glyph("ekf_y", "scatter", "firebrick", "EKF = x⁽¹⁾", x="ekf_x", marker="square", size=12,
                          alpha=0.7),
                    Glyph("map_y", "scatter", "black", "MAP (optimiseur indépendant)", x="map_x", marker="star", size=16),
                    Glyph("truth_y", "scatter", "seagreen", "cible vraie", x="truth_x", marker="x", size=12),
                    Glyph("now_y", "scatter", "crimson", "itéré choisi", x="now_x", marker="circle", size=12),
                ),
                x_label="x (m)",
                x_range=(7.0, 10.6),
                y_range=(-0.5, 3.9),
                equal_aspect=True,
            ),
            Panel(
                "Distance au MAP à chaque itération",
                "distance de l'itéré au MAP (m)",
                (
                    Glyph("distance", "line", "royalblue", "Gauss–Newton"),
                    Glyph("distance", "scatter", "royalblue", "", marker="circle", size=6),
                    Glyph("", "hline", "gray", "seuil d'arrêt 10⁻¹⁰ m", value=1e-10, dash="dotted", width=1.0),
                    Glyph("distance_now", "scatter", "crimson", "itéré choisi", x="iteration_now", marker="circle",
                          size=12),
                ),
                x_label="itération i",
                x_range=(-0.5, max_shown() + 0.5),
                y_log=True,
                y_range=(FLOOR, 100.0),
                height=230,
            ),
        ),
        fixed={"truth_x": RADAR_TRUTH[:1], "truth_y": RADAR_TRUTH[1:], "prior_mean_x": RADAR_PRIOR[:1]},
        readout=_readout,
    )
