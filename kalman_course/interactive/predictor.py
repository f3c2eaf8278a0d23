r"""Curseurs du chapitre « Le filtre prédicteur–correcteur » : la boucle, demi-pas par demi-pas.

Un curseur parcourt les étapes (départ, prédiction, correction, prédiction…) des cinq premières
secondes du moteur ; l'autre change la covariance de mesure :math:`s\,\Psi` que suppose le filtre
(:func:`~kalman_course.scenarios.engine_cycle.engine_cycle`). On suit la loi de :math:`\theta_m` : la
prédiction l'élargit, la correction la resserre, d'autant moins que le filtre se méfie des mesures
(:math:`s` grand, :math:`K \to 0`). Position par défaut : :math:`s = 1`, première correction, les
nombres imprimés par la première cellule du chapitre.
"""

from __future__ import annotations

import numpy as np

from ..scenarios.engine_cycle import CYCLE_STEPS, engine_cycle
from ..scenarios.intuition import gaussian_density
from .figure import SliderSpec, number, register_sliders, subscript
from .grid import ParameterAxis
from .spec import Follow, Glyph, Panel

__all__ = ["PSI_SCALES", "THETA", "density_positions", "predictor_axes", "predictor_run", "predictor_spec"]

CHAPTER = "predicteur-correcteur"

#: Facteurs :math:`s` de :math:`\Psi` proposés (1 : le vrai bruit de mesure).
PSI_SCALES = (1e-6, 1e-4, 1e-2, 1.0, 1e2, 1e4, 1e6)
#: Échauffements du moteur (°C) où la densité de :math:`\theta_m` est tracée.
THETA = np.round(np.arange(-5.0, 25.0001, 0.15), 10)
#: Points ajoutés autour de la moyenne de chaque densité tracée (:func:`density_positions`).
PEAK_POINTS = 41


def stage_labels(n_steps: int = CYCLE_STEPS) -> tuple[str, ...]:
    """Libellés des étapes : « départ », « n = 1 : prédiction », « n = 1 : correction »…"""
    labels = ["départ : x̂₀, P₀"]
    for n in range(1, n_steps + 1):
        labels += [f"n = {n} : prédiction", f"n = {n} : correction"]
    return tuple(labels)


def predictor_axes() -> tuple[ParameterAxis, ParameterAxis]:
    """L'étape (première correction par défaut) et le facteur :math:`s` (1 par défaut)."""
    labels = stage_labels()
    return (
        ParameterAxis("stage", "n", "étape de la boucle", "", np.arange(len(labels), dtype=float), default=2,
                      scale="index", tick_labels=labels),
        ParameterAxis("psi_scale", "s", "covariance de mesure supposée s Ψ", "", np.array(PSI_SCALES),
                      default=PSI_SCALES.index(1.0), tick_labels=tuple(number(s) for s in PSI_SCALES)),
    )


def density_positions(mean: float, var: float) -> np.ndarray:
    """Les abscisses (°C) où une densité :math:`\\mathcal N(m, v)` est tracée : :data:`THETA`, plus
    :data:`PEAK_POINTS` points entre :math:`m \\pm 4\\sqrt v` (dans la fenêtre), pour qu'un pic plus étroit
    que le pas de :data:`THETA` (un filtre qui croit les mesures parfaites) soit dessiné. Forme
    ``(THETA.size + PEAK_POINTS,)``, croissante."""
    extra = np.clip(mean + np.sqrt(var) * np.linspace(-4.0, 4.0, PEAK_POINTS), THETA[0], THETA[-1])
    return np.sort(np.concatenate([THETA, extra]))


def predictor_run(stage: float, psi_scale: float) -> dict[str, np.ndarray]:
    """La loi de :math:`\\theta_m` à l'étape choisie et à la précédente ; l'écart-type à chaque étape."""
    cycle = engine_cycle(psi_scale)
    steps = cycle.steps
    k = int(stage)
    n = steps.step_of(k)
    mean, var = steps.mean[:, 0], steps.cov[:, 0, 0]
    nan2 = np.full(2, np.nan)
    current_x = density_positions(mean[k], var[k])
    current = gaussian_density(current_x, mean[k], var[k])
    if k > 0:
        previous_x = density_positions(mean[k - 1], var[k - 1])
        previous = gaussian_density(previous_x, mean[k - 1], var[k - 1])
    else:
        previous_x = previous = np.full(current_x.size, np.nan)
    top = 1.05 * np.nanmax(np.concatenate([current, previous]))
    return {
        "current_x": current_x,
        "current": current,
        "previous_x": previous_x,
        "previous": previous,
        "bar_y": np.array([0.0, top]),
        "truth_x": np.repeat(cycle.simulation.x[n - 1, 0], 2) if n > 0 else nan2,
        "inverted_x": np.repeat(cycle.inverted[n - 1, 0], 2) if steps.kind[k] == "correction" else nan2,
        "std": np.sqrt(var),
        "std_now": np.array([np.sqrt(var[k])]),
        "stage_now": np.array([float(k)]),
        "mean_now": steps.mean[k],
        "std_both": np.sqrt(np.diag(steps.cov[k])),
        "gain_norm": np.array([np.linalg.norm(cycle.K[n - 1]) if n > 0 else np.nan]),
    }


def _pair(v, unit: str) -> str:
    return f"({number(v[0])} ; {number(v[1])}) {unit}"


def _readout(series, values) -> str:
    k = int(values[0])
    mean, std = series["mean_now"], series["std_both"]
    if k == 0:
        return f"Départ : x̂₀ = {_pair(mean, '°C')}, écarts-types {_pair(std, '°C')} (P₀ = 15² I °C²)."
    n = (k + 1) // 2
    sub = subscript(n)
    if k % 2 == 1:
        return (f"Prédiction : x̂⁻{sub} = A x̂{subscript(n - 1)} + B u{subscript(n - 1)} = {_pair(mean, '°C')}, "
                f"écarts-types {_pair(std, '°C')} : P⁻ = A P Aᵀ + Φ a grandi.")
    return (f"Correction : x̂{sub} = {_pair(mean, '°C')}, écarts-types {_pair(std, '°C')} ; "
            f"‖K{sub}‖ = {number(series['gain_norm'][0], '°C/mV')}.")


@register_sliders("predicteur-etapes", chapter=CHAPTER)
def predictor_spec() -> SliderSpec:
    """La boucle prédiction–correction du moteur, étape par étape."""
    axes = predictor_axes()
    stages = axes[0].values
    return SliderSpec(
        name="predicteur-etapes",
        chapter=CHAPTER,
        title="Moteur, cinq premières secondes : prédire élargit la loi de θₘ, corriger la resserre",
        x_label="étape de la boucle (sans unité)",
        axes=axes,
        run=predictor_run,
        time=THETA,
        panels=(
            Panel(
                "Loi de l'échauffement du moteur θₘ à l'étape choisie",
                "densité de probabilité (1/°C)",
                (
                    Glyph("previous", "line", "gray", "étape précédente", x="previous_x", dash="dashed",
                          width=1.5),
                    Glyph("current", "area", "royalblue", "étape choisie", x="current_x"),
                    Glyph("current", "line", "royalblue", "", x="current_x"),
                    Glyph("bar_y", "line", "black", "valeur vraie θₘ", x="truth_x", dash="dotted"),
                    Glyph("bar_y", "line", "seagreen", "mesure inversée (C⁻¹yₙ)₁", x="inverted_x"),
                ),
                x_label="échauffement du moteur θₘ (°C)",
                x_range=(float(THETA[0]), float(THETA[-1])),
                # l'axe suit la densité affichée : un pic de 800 /°C (s = 10⁻⁶) comme une loi presque plate
                y_range=Follow(columns=("current", "previous"), include=(0.0,)),
                height=270,
            ),
            Panel(
                "Écart-type de θₘ à chaque étape (échelle logarithmique)",
                "écart-type de θₘ (°C)",
                (
                    Glyph("std", "line", "royalblue", "√P₁₁ à chaque étape", x="stages"),
                    Glyph("std", "scatter", "royalblue", "", x="stages", marker="circle", size=5),
                    Glyph("std_now", "scatter", "crimson", "étape choisie", x="stage_now", marker="circle",
                          size=11),
                ),
                x_label="étape (0 = départ ; impaire = prédiction ; paire = correction)",
                x_range=(-0.5, float(stages[-1]) + 0.5),
                y_log=True,
                height=220,
            ),
        ),
        fixed={"stages": stages},
        readout=_readout,
    )
