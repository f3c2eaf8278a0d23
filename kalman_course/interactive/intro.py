r"""Curseurs de l'introduction : un chariot suivi par le filtre de Kalman, avant toute formule.

:func:`~kalman_course.scenarios.intuition.cart_tracking` : le chariot du chapitre « Le filtre de Kalman
en images » simulé pendant 40 s, avec un bruit d'état :math:`Q` et un bruit de mesure :math:`R` que le
filtre connaît. Position par défaut : les valeurs de ce chapitre (:math:`Q = 0{,}5` m², :math:`R = 1` m²).
"""

from __future__ import annotations

import numpy as np

from ..scenarios.intuition import CART_DT, CART_Q, CART_R, CART_SPEED, TRACKING_STEPS, cart_tracking
from .figure import SliderSpec, number, register_sliders
from .grid import ParameterAxis, log_grid
from .spec import Glyph, Panel

__all__ = ["intro_axes", "intro_run", "intro_spec"]

CHAPTER = "intro"


def intro_axes() -> tuple[ParameterAxis, ParameterAxis]:
    """:math:`R` (0,1 à 10 m²) et :math:`Q` (5 × 10⁻³ à 5 m²), deux points par décade."""
    return (
        ParameterAxis("R", "R", "bruit du capteur (variance)", "m²", log_grid(CART_R, 1, 1, 2), default=2),
        ParameterAxis("Q", "Q", "imprévu du mouvement (variance par pas)", "m²", log_grid(CART_Q, 2, 1, 2),
                      default=4),
    )


def intro_run(R: float, Q: float) -> dict[str, np.ndarray]:
    r"""Position vraie, mesures, estimation et bande ±2√P (m), moins la position attendue :math:`v\,t`."""
    run = cart_tracking(Q, R)
    expected = CART_SPEED * CART_DT * np.arange(1, TRACKING_STEPS + 1)
    return {"truth_rel": run.truth - expected, "y_rel": run.y - expected, "x_rel": run.x - expected,
            "lower_rel": run.x - 2 * run.std - expected, "upper_rel": run.x + 2 * run.std - expected,
            "rmse_y": np.array([np.sqrt(np.mean((run.y - run.truth) ** 2))]),
            "rmse_x": np.array([np.sqrt(np.mean((run.x - run.truth) ** 2))])}


def _readout(series, values) -> str:
    return (f"Écart quadratique moyen à la position vraie : mesures {number(series['rmse_y'][0], 'm')}, "
            f"filtre de Kalman {number(series['rmse_x'][0], 'm')}.")


@register_sliders("intro-chariot", chapter=CHAPTER)
def intro_spec() -> SliderSpec:
    """Un chariot suivi par le filtre de Kalman."""
    return SliderSpec(
        name="intro-chariot",
        chapter=CHAPTER,
        title=f"Un chariot roule à 1 m/s ; un capteur bruité donne sa position chaque seconde ({TRACKING_STEPS} s)",
        x_label="temps (s)",
        axes=intro_axes(),
        run=intro_run,
        time=np.arange(1, TRACKING_STEPS + 1, dtype=float),
        panels=(
            Panel(
                "Écart à la position attendue (x − v t) : ce que le capteur voit, ce qu'estime le filtre",
                "position − v t (m)",
                (
                    Glyph("lower_rel", "band", "royalblue", "incertitude annoncée ± 2√P", upper="upper_rel"),
                    Glyph("y_rel", "scatter", "firebrick", "mesures", marker="cross", size=8),
                    Glyph("truth_rel", "line", "black", "position vraie", width=1.5, dash="dashed"),
                    Glyph("x_rel", "line", "royalblue", "estimation du filtre de Kalman"),
                ),
                height=320,
            ),
        ),
        readout=_readout,
    )
