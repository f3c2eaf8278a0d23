r"""Curseurs du chapitre « Implémentation pratique et synthèse » : un bruit de capteur mal connu.

:func:`~kalman_course.scenarios.sensor_tuning.sensor_tuning` : le moteur simulé avec un thermocouple
d'écart-type réel :math:`\sigma_{\text{vrai}}`, filtré en supposant :math:`\sigma_{\text{supposé}}`. En haut,
ce que l'on voit (les innovations normalisées) ; en bas, ce que l'on ne voit pas (l'erreur, comparée à
l'écart-type que le filtre s'attribue). Position par défaut : les deux valent 0,5 °C, le « bon modèle »
du chapitre.
"""

from __future__ import annotations

import numpy as np

from ..scenarios.engine import ENGINE_DT
from ..scenarios.sensor_tuning import SENSOR_STD, TUNING_STEPS, sensor_tuning
from .figure import SliderSpec, number, register_sliders
from .grid import ParameterAxis, log_grid
from .spec import Follow, Glyph, Panel

__all__ = ["practice_axes", "practice_run", "practice_spec"]

CHAPTER = "pratique-synthese"


def practice_axes() -> tuple[ParameterAxis, ParameterAxis]:
    r""":math:`\sigma_{\text{vrai}}` et :math:`\sigma_{\text{supposé}}` de 0,05 à 5 °C, quatre points par décade."""
    values = log_grid(SENSOR_STD, 1, 1, 4)
    return (
        ParameterAxis("true_std", "σ vrai", "bruit réel des thermocouples", "°C", values, default=4),
        ParameterAxis("assumed_std", "σ supposé", "bruit supposé par le filtre (Ψ)", "°C", values, default=4),
    )


def practice_run(true_std: float, assumed_std: float) -> dict[str, np.ndarray]:
    """Innovations normalisées du premier capteur ; erreur sur :math:`\\theta_m` et :math:`\\pm 2\\sqrt{P_{11}}`."""
    run = sensor_tuning(true_std, assumed_std)
    return {
        "normalised": run.normalised,
        "error": run.error,
        "upper": 2.0 * run.std,
        "lower": -2.0 * run.std,
    }


def _readout(series, values) -> str:
    v = series["normalised"]
    outside = 100.0 * np.mean(np.abs(v) > 2)
    e, s = series["error"], series["upper"] / 2.0
    inside = 100.0 * np.mean(np.abs(e) <= 2.0 * s)
    return (f"Innovations normalisées : moyenne {number(v.mean())}, écart-type {number(v.std())}, "
            f"{number(outside, '%')} hors de ±2 (environ 5 % si le modèle est juste). "
            f"Erreur dans ±2√P : {number(inside, '%')} des instants.")


@register_sliders("pratique-capteur", chapter=CHAPTER)
def practice_spec() -> SliderSpec:
    """Les innovations d'un filtre dont le bruit de mesure est juste, trop petit ou trop grand."""
    return SliderSpec(
        name="pratique-capteur",
        chapter=CHAPTER,
        title=f"Moteur ({TUNING_STEPS} s) : bruit réel du capteur contre bruit supposé par le filtre",
        x_label="temps (s)",
        axes=practice_axes(),
        run=practice_run,
        time=ENGINE_DT * np.arange(1, TUNING_STEPS + 1),
        panels=(
            Panel(
                "Ce que l'on voit : innovations normalisées du thermocouple du moteur",
                "ỹₙ,₁ / √Sₙ,₁₁ (sans unité)",
                (
                    Glyph("", "hline", "gray", "± 2 (95 % si N(0, 1))", value=2.0, dash="dashed", width=1.0),
                    Glyph("", "hline", "gray", "", value=-2.0, dash="dashed", width=1.0),
                    Glyph("normalised", "line", "royalblue", "innovation normalisée", width=1.0),
                    Glyph("normalised", "scatter", "royalblue", "", marker="dot", size=6),
                ),
                y_range=Follow(columns=("normalised",), include=(-3.0, 3.0)),  # ± 2 toujours visibles
                height=220,
            ),
            Panel(
                "Ce que l'on ne voit pas : l'erreur sur θₘ et l'écart-type annoncé",
                "erreur θ̂ₘ − θₘ (°C)",
                (
                    Glyph("lower", "band", "royalblue", "± 2 √Pₙ,₁₁ annoncé par le filtre", upper="upper"),
                    Glyph("error", "line", "firebrick", "erreur vraie", width=1.2),
                ),
                # l'axe suit l'erreur : la bande (très large au départ) peut en sortir
                y_range=Follow(columns=("error",), margin=0.4),
                height=220,
            ),
        ),
        readout=_readout,
    )
