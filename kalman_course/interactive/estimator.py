r"""Curseurs du chapitre « Construction d'un estimateur » : un gain fixe :math:`K` sur le contre-exemple
scalaire, et la stabilité :math:`|(1 - KC)A| < 1`.

Calculs : :func:`~kalman_course.scenarios.stability.fixed_gain_experiment` (récurrence du cours et
moyenne de 400 simulations). Position par défaut : :math:`A = 2`, :math:`K = 0{,}4`, la courbe rouge de
la figure du chapitre.
"""

from __future__ import annotations

import numpy as np

from ..scenarios.stability import COUNTER_A, COUNTER_C, STABILITY_RUNS, STABILITY_STEPS, fixed_gain_experiment
from .figure import SliderSpec, number, register_sliders
from .grid import ParameterAxis
from .spec import Follow, Glyph, Panel

__all__ = ["GAINS", "CURVE_GAINS", "SYSTEMS", "estimator_axes", "estimator_run", "estimator_spec"]

CHAPTER = "estimateur"

#: Gains fixes proposés : 0 à 2 par pas de 0,2 (0,4 et 0,6 sont ceux du chapitre, au bit près).
GAINS = tuple(k / 5 for k in range(11))
#: Gains où la courbe de stabilité est tracée.
CURVE_GAINS = np.linspace(0.0, 2.0, 201)
#: Systèmes proposés (A) ; le contre-exemple du chapitre est A = 2.
SYSTEMS = (0.5, 1.0, 2.0, 3.0)
#: Plancher d'affichage de l'erreur moyenne (échelle logarithmique).
FLOOR = 1e-8


def estimator_axes() -> tuple[ParameterAxis, ParameterAxis]:
    """Le gain :math:`K` (0,4 par défaut) et le système :math:`A` (2 par défaut)."""
    return (
        ParameterAxis("K", "K", "gain fixe de l'estimateur", "", np.array(GAINS), default=GAINS.index(0.4),
                      scale="linear", tick_labels=tuple(number(k) for k in GAINS)),
        ParameterAxis("A", "A", "dynamique du système xₙ₊₁ = A xₙ + φₙ", "", np.array(SYSTEMS),
                      default=SYSTEMS.index(COUNTER_A), scale="linear",
                      tick_labels=tuple(number(a) for a in SYSTEMS)),
    )


def estimator_run(K: float, A: float) -> dict[str, np.ndarray]:
    """Erreur moyenne (récurrence et Monte-Carlo), rayons de stabilité le long des gains."""
    run = fixed_gain_experiment(K, A)
    rec = np.abs(run.recursion.e[:, 0])
    mc = np.abs(run.monte_carlo.mean_error()[:, 0])
    radius_curve = np.abs((1.0 - CURVE_GAINS * COUNTER_C) * A)
    return {
        "recursion": np.maximum(rec, FLOOR),
        "monte_carlo": np.maximum(mc, FLOOR),
        "radius_curve": radius_curve,
        "K_now": np.array([K]),
        "radius_now": np.array([run.radius]),
        "printed_now": np.array([run.printed_radius]),
    }


def _readout(series, values) -> str:
    K, A = values
    rho, printed = series["radius_now"][0], series["printed_now"][0]
    verdict = "l'erreur moyenne décroît" if rho < 1 else ("elle reste constante" if rho == 1 else "elle explose")
    lo, hi = 1 - 1 / A, 1 + 1 / A
    return (f"|(1 − KC)A| = {number(rho)} : {verdict}. Condition imprimée |1 − KC| = {number(printed)}. "
            f"Gains stables pour A = {number(A)} : {number(lo)} < K < {number(hi)}.")


@register_sliders("estimateur-gain", chapter=CHAPTER)
def estimator_spec() -> SliderSpec:
    """L'erreur moyenne d'un estimateur à gain fixe."""
    return SliderSpec(
        name="estimateur-gain",
        chapter=CHAPTER,
        title=(f"Estimateur à gain fixe sur xₙ₊₁ = A xₙ + φₙ, yₙ = xₙ + ψₙ (erreur initiale 1, "
               f"{STABILITY_RUNS} simulations)"),
        x_label="itération n (sans unité)",
        axes=estimator_axes(),
        run=estimator_run,
        time=np.arange(STABILITY_STEPS + 1, dtype=float),
        panels=(
            Panel(
                "Erreur moyenne |E[eₙ]| : multipliée par (1 − KC)A à chaque pas",
                "|E[eₙ]| (unités de x)",
                (
                    Glyph("recursion", "line", "royalblue", "récurrence du cours"),
                    Glyph("monte_carlo", "scatter", "black", f"moyenne de {STABILITY_RUNS} simulations",
                          marker="circle", size=5),
                    Glyph("", "hline", "gray", "plancher 10⁻⁸ : erreur nulle", value=FLOOR, dash="dotted", width=1.0),
                ),
                y_log=True,
                # le plancher reste une décade au-dessus du bas de l'axe ; le haut suit l'erreur affichée
                y_range=Follow(columns=("recursion", "monte_carlo"), include=(FLOOR / 10.0, 10.0)),
                height=240,
            ),
            Panel(
                "Stabilité : c'est |(1 − KC)A| qui doit être < 1, pas |1 − KC|",
                "rayon (sans unité)",
                (
                    Glyph("radius_curve", "line", "royalblue", "|(1 − KC)A|", x="gains"),
                    Glyph("printed_curve", "line", "gray", "|1 − KC| (condition imprimée)", x="gains",
                          dash="dashed"),
                    Glyph("", "hline", "firebrick", "limite 1", value=1.0, width=1.0),
                    Glyph("radius_now", "scatter", "crimson", "gain choisi", x="K_now", marker="circle", size=11),
                ),
                x_label="gain K (sans unité)",
                x_range=(-0.05, 2.05),
                y_range=(0.0, 3.2),
                height=200,
            ),
        ),
        fixed={"gains": CURVE_GAINS, "printed_curve": np.abs(1.0 - CURVE_GAINS * COUNTER_C)},
        readout=_readout,
    )
