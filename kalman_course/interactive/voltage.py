r"""Curseurs du chapitre « tension constante » : :math:`\Phi` et :math:`\Psi` (statiques et interactifs).

Même scénario que les figures du chapitre (:mod:`kalman_course.figures.voltage`) : 50 relevés à graine
fixe, :math:`\hat x_0 = 0`, :math:`P_0 = 1` V². La position par défaut des curseurs,
:math:`\Phi = 10^{-5}` V² et :math:`\Psi = 0{,}01` V², redonne exactement l'exécution des figures
statiques du chapitre.
"""

from __future__ import annotations

import numpy as np

from ..filters.kalman import kalman_filter
from ..scenarios import TRUE_VOLTAGE, constant_voltage_measurements, constant_voltage_model
from ..core.validation import KalmanInputError, as_float_array
from ..numbers import format_spec
from .figure import SliderSpec, register_sliders
from .grid import ParameterAxis, ParameterGrid, log_grid, precompute_grid
from .spec import Glyph, Panel

__all__ = [
    "VOLTAGE_Q",
    "VOLTAGE_R",
    "VOLTAGE_P0",
    "voltage_axes",
    "voltage_run",
    "voltage_grid",
    "voltage_panels",
    "voltage_sliders",
    "live_voltage_explorer",
]

#: Valeurs du chapitre (figures statiques) : position par défaut des curseurs.
VOLTAGE_Q = 1e-5
VOLTAGE_R = 0.01  # littéral du chapitre (0.1**2 vaut 0.010000000000000002)
VOLTAGE_P0 = 1.0
VOLTAGE_X0 = 0.0

LIVE_HINT = "kc.interactive.live_voltage_explorer()"


def voltage_axes(per_decade: int = 2) -> tuple[ParameterAxis, ParameterAxis]:
    r"""Les deux axes de la grille : :math:`\Phi \in [10^{-9}, 10^{-2}]` V² et
    :math:`\Psi \in [10^{-5}, 10^{2}]` V², ``per_decade`` points par décade (15 × 15 par défaut),
    centrés exactement sur les valeurs du chapitre."""
    q = log_grid(VOLTAGE_Q, 4, 3, per_decade)
    r = log_grid(VOLTAGE_R, 3, 4, per_decade)
    return (
        ParameterAxis("Q", "Φ", "bruit d'état", "V²", q, default=4 * per_decade),
        ParameterAxis("R", "Ψ", "bruit de mesure", "V²", r, default=3 * per_decade),
    )


def voltage_run(Q: float, R: float, P0: float = VOLTAGE_P0, n_steps: int = 50) -> dict[str, np.ndarray]:
    r"""Une exécution du filtre sur les relevés du chapitre ; séries de forme (T,) :
    ``x`` (:math:`\hat x_n`, V), ``P`` (:math:`P_n`, V²), ``K`` (:math:`K_n`)."""
    z = constant_voltage_measurements(n_steps)
    result = kalman_filter(constant_voltage_model(Q=Q, R=R), z, x0=VOLTAGE_X0, P0=P0)
    return {"x": result.x[:, 0], "P": result.P[:, 0, 0], "K": result.K[:, 0, 0]}


def _check_n_steps(n_steps) -> int:
    if not isinstance(n_steps, (int, np.integer)) or isinstance(n_steps, bool) or n_steps < 1:
        raise KalmanInputError(f"« n_steps » doit être un entier ≥ 1 (nombre de relevés) ; reçu {n_steps!r}.")
    return int(n_steps)


def _check_positive(name: str, value) -> float:
    v = as_float_array(name, value)
    if v.ndim != 0 or not v > 0:
        raise KalmanInputError(f"« {name} » doit être un nombre strictement positif (une variance) ; reçu {value!r}.")
    return float(v)


def voltage_grid(n_steps: int = 50, P0: float = VOLTAGE_P0, per_decade: int = 2) -> ParameterGrid:
    r"""Toutes les exécutions :math:`(\Phi, \Psi)` de la grille (15 × 15 par défaut), séries ``x``,
    ``P``, ``K`` de forme ``(N_Φ, N_Ψ, T)``."""
    n_steps = _check_n_steps(n_steps)
    P0 = _check_positive("P0", P0)
    q_axis, r_axis = voltage_axes(per_decade)
    return precompute_grid(
        lambda Q, R: voltage_run(Q, R, P0=P0, n_steps=n_steps),
        q_axis,
        r_axis,
        time=np.arange(1, n_steps + 1, dtype=float),
    )


def voltage_panels() -> tuple[Panel, ...]:
    r"""La figure du chapitre, décrite une fois pour les deux sortes de curseurs : estimation,
    :math:`P_n` (échelle log), :math:`K_n`."""
    truth = f"valeur vraie x = {format_spec(TRUE_VOLTAGE, 'g')} V"  # comme la figure statique du chapitre
    return (
        Panel(
            "Valeur vraie, mesures et estimation",
            "tension (V)",
            (
                Glyph("", "hline", "green", truth, value=TRUE_VOLTAGE),
                Glyph("z", "scatter", "firebrick", "mesures yₙ"),
                Glyph("x", "line", "royalblue", "estimation x̂ₙ"),
            ),
            height=260,
        ),
        Panel("Covariance de l'erreur Pₙ", "Pₙ (V²)", (Glyph("P", "line", "royalblue", "Pₙ (a posteriori)"),),
              y_log=True),
        Panel("Gain de Kalman Kₙ", "Kₙ (sans unité)", (Glyph("K", "line", "darkorange", "gain Kₙ"),),
              y_range=(0.0, 1.05)),
    )


def voltage_sliders(n_steps: int = 50, per_decade: int = 2):
    r"""Figure à curseurs statiques :math:`\Phi` et :math:`\Psi` (Bokeh) : estimation, :math:`P_n`, :math:`K_n`.

    Toutes les exécutions de :func:`voltage_grid` sont embarquées dans la figure : la page publiée
    change de courbe sans noyau. Renvoie un :class:`~.static.StaticSliders` (affiché en HTML).
    """
    from .static import StaticSliders

    n_steps = _check_n_steps(n_steps)
    return StaticSliders(
        voltage_grid(n_steps=n_steps, per_decade=per_decade),
        voltage_panels(),
        x_label="itération n (sans unité)",
        fixed={"z": constant_voltage_measurements(n_steps)},
        name="tension-curseurs",
        title=f"Tension constante : déplacez Φ et Ψ (x̂₀ = 0 V, P₀ = 1 V², {n_steps} relevés)",
        live_hint=LIVE_HINT,
    )


def live_voltage_explorer(Q: float = VOLTAGE_Q, R: float = VOLTAGE_R, P0: float = VOLTAGE_P0, n_steps: int = 50):
    r"""Curseurs interactifs (ipywidgets) :math:`\Phi`, :math:`\Psi`, :math:`P_0` pour Jupyter, Binder ou Colab.

    Chaque relâchement d'un curseur relance :func:`~kalman_course.kf.kalman_filter` et redessine
    l'estimation, :math:`P_n` et :math:`K_n`. Exige un noyau Python en marche : dans le livre publié,
    utiliser :func:`voltage_sliders`. Renvoie un :class:`~.live.LiveExplorer`.
    """
    from .live import LiveExplorer, LogParameter

    n_steps = _check_n_steps(n_steps)
    return LiveExplorer(
        run=lambda Q, R, P0: voltage_run(Q, R, P0=P0, n_steps=n_steps),
        parameters=(
            LogParameter("Q", "Φ (bruit d'état)", "V²", _check_positive("Q", Q), -9.0, -2.0),
            LogParameter("R", "Ψ (bruit de mesure)", "V²", _check_positive("R", R), -5.0, 2.0),
            LogParameter("P0", "P₀ (variance initiale)", "V²", _check_positive("P0", P0), -4.0, 2.0),
        ),
        time=np.arange(1, n_steps + 1, dtype=float),
        panels=voltage_panels(),
        x_label="itération n (sans unité)",
        fixed={"z": constant_voltage_measurements(n_steps)},
    )


def voltage_readout(series, values) -> str:
    """Le texte sous les curseurs : le gain et la covariance au premier et au dernier relevé, l'erreur finale."""
    from .figure import number

    x, P, K = series["x"], series["P"], series["K"]
    return (f"Gain K₁ = {number(K[0])} au premier relevé, K₅₀ = {number(K[-1])} au dernier ; P₅₀ = "
            f"{number(P[-1], 'V²')} ; estimation finale {number(x[-1], 'V')}, à "
            f"{number(abs(x[-1] - TRUE_VOLTAGE), 'V')} de la valeur vraie.")


@register_sliders("tension-curseurs", chapter="tension-constante")
def voltage_spec(n_steps: int = 50, per_decade: int = 2) -> SliderSpec:
    r"""La figure :math:`(\Phi, \Psi)` du chapitre au registre des figures à curseurs (même grille que
    :func:`voltage_grid`, mêmes panneaux que :func:`voltage_sliders`)."""
    q_axis, r_axis = voltage_axes(per_decade)
    return SliderSpec(
        name="tension-curseurs",
        chapter="tension-constante",
        title=f"Tension constante : déplacez Φ et Ψ (x̂₀ = 0 V, P₀ = 1 V², {n_steps} relevés)",
        x_label="itération n (sans unité)",
        axes=(q_axis, r_axis),
        run=lambda Q, R: voltage_run(Q, R, n_steps=n_steps),
        time=np.arange(1, n_steps + 1, dtype=float),
        panels=voltage_panels(),
        fixed={"z": constant_voltage_measurements(n_steps)},
        readout=voltage_readout,
    )
