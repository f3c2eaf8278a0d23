r"""Curseurs du chapitre « Dynamique de l'erreur et gain optimal » : :math:`P_n(K)` pour un gain quelconque.

:func:`~kalman_course.scenarios.gain_trace.gain_trace` sur la tension constante : la covariance a
posteriori :math:`P_n(K) = (1 - K)^2 P^-_n + K^2\Psi` et ses deux termes, le gain de Kalman
:math:`K^\star_n` au minimum. Position par défaut : :math:`n = 10` et :math:`K = K^\star_{10}`, le point
rouge de la figure du chapitre.
"""

from __future__ import annotations

import numpy as np

from ..scenarios.gain_trace import gain_trace
from .figure import SliderSpec, number, register_sliders, subscript
from .grid import ParameterAxis
from .spec import Follow, Glyph, Panel

__all__ = ["STEPS", "CURVE_K", "gain_axes", "gain_run", "gain_spec"]

CHAPTER = "gain-optimal"

#: Pas proposés (le chapitre trace n = 10).
STEPS = (1, 2, 3, 5, 10, 20, 50)
#: Gains où les courbes sont tracées.
CURVE_K = np.linspace(0.0, 1.0, 51)


def gain_axes() -> tuple[ParameterAxis, ParameterAxis]:
    r"""Le pas :math:`n` et le gain :math:`K` (0 à 1 par pas de 0,05, plus :math:`K^\star_{10}` exactement)."""
    K_star = gain_trace(10, 0.0).K_star
    gains = np.array(sorted({k / 20 for k in range(21)} | {K_star}))
    return (
        ParameterAxis("n", "n", "numéro du relevé", "", np.array(STEPS, dtype=float), default=STEPS.index(10),
                      scale="index", tick_labels=tuple(str(n) for n in STEPS)),
        ParameterAxis("K", "K", "gain essayé", "", gains, default=int(np.flatnonzero(gains == K_star)[0]),
                      scale="linear", tick_labels=tuple(number(k) for k in gains)),
    )


def gain_run(n: float, K: float) -> dict[str, np.ndarray]:
    """Les courbes :math:`P_n(K')` et leurs termes ; le point du gain choisi et celui du gain de Kalman."""
    n = int(n)
    curve = [gain_trace(n, k) for k in CURVE_K]
    now = gain_trace(n, K)
    scale = now.P_pred  # courbes rapportées à P⁻ₙ : même échelle pour tous les pas
    return {
        "total": np.array([c.P for c in curve]) / scale,
        "prediction": np.array([c.prediction_part for c in curve]) / scale,
        "measurement": np.array([c.measurement_part for c in curve]) / scale,
        "K_now": np.array([K]),
        "P_now": np.array([now.P]),
        "ratio_now": np.array([now.P / scale]),
        "K_star": np.array([now.K_star]),
        "P_star": np.array([now.P_star]),
        "ratio_star": np.array([now.P_star / scale]),
        "P_pred": np.array([now.P_pred]),
    }


def _readout(series, values) -> str:
    n, K = int(values[0]), values[1]
    sub = subscript(n)
    P, P_star = series["P_now"][0], series["P_star"][0]
    return (f"n = {n} : P⁻{sub} = {number(series['P_pred'][0], 'V²')} ; gain de Kalman K*{sub} = "
            f"P⁻{sub}/(P⁻{sub} + Ψ) = {number(series['K_star'][0])}. Avec K = {number(K)} : "
            f"P{sub}(K) = {number(P, 'V²')}, soit {number(100 * (P / P_star - 1), '%')} de plus qu'au minimum "
            f"{number(P_star, 'V²')}.")


@register_sliders("gain-trace", chapter=CHAPTER)
def gain_spec() -> SliderSpec:
    """La covariance a posteriori en fonction du gain."""
    return SliderSpec(
        name="gain-trace",
        chapter=CHAPTER,
        title="Tension constante (Φ = 10⁻⁵ V², Ψ = 0,01 V²) : Pₙ(K) = (1 − K)² P⁻ₙ + K² Ψ",
        x_label="gain K (sans unité)",
        axes=gain_axes(),
        run=gain_run,
        time=CURVE_K,
        panels=(
            Panel(
                "Le gain de Kalman est au minimum de Pₙ(K) (courbes rapportées à P⁻ₙ)",
                "Pₙ(K) / P⁻ₙ (sans unité)",
                (
                    Glyph("prediction", "line", "darkorange", "(1 − K)² : prédiction restante", dash="dashed"),
                    Glyph("measurement", "line", "seagreen", "K² Ψ / P⁻ₙ : bruit de mesure ajouté", dash="dashed"),
                    Glyph("total", "line", "royalblue", "Pₙ(K) / P⁻ₙ (somme)"),
                    Glyph("ratio_star", "scatter", "crimson", "gain de Kalman K*ₙ", x="K_star", marker="circle",
                          size=11),
                    Glyph("ratio_now", "scatter", "black", "gain choisi", x="K_now", marker="diamond", size=11),
                ),
                x_label="gain K (sans unité)",
                x_range=(0.0, 1.0),
                # l'axe suit le point choisi (Pₙ(1)/P⁻ₙ = Ψ/P⁻ₙ ≈ 19 à n = 50) ; les courbes peuvent en sortir
                y_range=Follow(columns=("prediction", "ratio_star", "ratio_now"), include=(0.0, 1.05)),
                height=300,
            ),
        ),
        readout=_readout,
    )
