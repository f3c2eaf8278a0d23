r"""Curseurs du chapitre « Le filtre de Kalman en images » (une dimension, le chariot sur un rail).

- ``intuition-produit`` : :math:`P^-` et :math:`R` au curseur ; l'a priori, la vraisemblance, leur produit
  normalisé et la loi a posteriori du paquet ; le gain :math:`K = P^-/(P^- + R)`.
- ``intuition-cycle`` : une étape de la boucle (prédiction, correction) et le bruit d'état :math:`Q` au
  curseur ; la gaussienne s'élargit à la prédiction, se resserre à la correction.

Les calculs sont ceux de :mod:`kalman_course.scenarios.intuition` ; la position par défaut des curseurs
est l'exemple du chapitre.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..scenarios import intuition as sc
from .figure import SliderSpec, number, register_sliders, subscript
from .grid import ParameterAxis, log_grid
from .spec import Follow, Glyph, Panel

__all__ = ["product_spec", "cycle_spec", "CYCLE_POSITIONS", "GAIN_CURVE_P"]

CHAPTER = "intuition"

#: Variances a priori (m²) où la courbe du gain est tracée.
GAIN_CURVE_P = np.logspace(-1.5, 2.0, 71)
#: Positions (m) des densités de la figure du cycle.
CYCLE_POSITIONS = np.round(np.arange(-3.0, 10.0001, 0.1), 10)
#: Positions (m) des densités de la figure du produit (pas de 0,1 m).
PRODUCT_POSITIONS = np.round(np.arange(0.0, 25.0001, 0.1), 10)
#: Un point sur cinq du produit normalisé numériquement (marqueurs).
_EVERY = 5


#: Variances proposées (m²) pour :math:`P^-` et :math:`R` : des puissances de 2, pour que les deux curseurs
#: puissent prendre la même valeur ; l'exemple du chapitre est :math:`P^- = 4`, :math:`R = 1`. Aux bouts,
#: un rapport 64 entre les deux variances : le gain va de 0,06 à 0,98 (« la mesure ne déplace presque
#: plus l'estimation », « on ne croit plus que la mesure »).
VARIANCES = (0.0625, 0.125, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0)


def product_axes() -> tuple[ParameterAxis, ParameterAxis]:
    r""":math:`P^-` et :math:`R` parcourent :data:`VARIANCES` (4 m² et 1 m² par défaut)."""
    return (
        ParameterAxis("prior_var", "P⁻", "variance a priori", "m²", np.array(VARIANCES),
                      default=VARIANCES.index(sc.PRIOR_VAR)),
        ParameterAxis("meas_var", "R", "variance de la mesure", "m²", np.array(VARIANCES),
                      default=VARIANCES.index(sc.MEASUREMENT_VAR)),
    )


@lru_cache(maxsize=None)
def _gain_curve(meas_var: float) -> np.ndarray:
    """Le gain de la correction du paquet pour chaque :math:`P^-` de :data:`GAIN_CURVE_P`."""
    return np.array([sc.correction_1d(sc.PRIOR_MEAN, p, sc.MEASUREMENT, meas_var).K for p in GAIN_CURVE_P])


def product_run(prior_var: float, meas_var: float) -> dict[str, np.ndarray]:
    """Une exécution : densités (1/m) sur :data:`PRODUCT_POSITIONS`, repères verticaux, courbe du gain."""
    out = sc.product_experiment(prior_var, meas_var, positions=PRODUCT_POSITIONS)
    peak = max(out["prior"].max(), out["likelihood"].max(), out["posterior"].max())
    gains = _gain_curve(float(meas_var))
    return {
        "prior": out["prior"],
        "likelihood": out["likelihood"],
        "posterior": out["posterior"],
        "product": out["product"][::_EVERY],
        "mark_x": np.repeat(out["x_post"], 2),
        "mark_y": np.array([0.0, peak]),
        "gain_curve": gains,
        "K": out["K"],
        "P_now": out["P_prior"],
        "x_post": out["x_post"],
        "P_post": out["P_post"],
    }


def _product_readout(series, values) -> str:
    K, x, P = series["K"][0], series["x_post"][0], series["P_post"][0]
    prior_var, meas_var = values
    return (
        f"K = P⁻/(P⁻ + R) = {number(prior_var)}/({number(prior_var)} + {number(meas_var)}) = {number(K)} ; "
        f"x̂ = x̂⁻ + K (y − x̂⁻) = {number(x, 'm')} ; P = (1 − K) P⁻ = {number(P, 'm²')}"
    )


@register_sliders("intuition-produit", chapter=CHAPTER)
def product_spec() -> SliderSpec:
    """Le produit de deux gaussiennes, au curseur."""
    return SliderSpec(
        name="intuition-produit",
        chapter=CHAPTER,
        title=(f"A priori × vraisemblance = a posteriori (x̂⁻ = {number(sc.PRIOR_MEAN, 'm')}, "
               f"y = {number(sc.MEASUREMENT, 'm')})"),
        x_label="position du chariot x (m)",
        axes=product_axes(),
        run=product_run,
        time=PRODUCT_POSITIONS,
        panels=(
            Panel(
                "Ce que l'on sait : a priori, mesure, et leur produit",
                "densité de probabilité (1/m)",
                (
                    Glyph("prior", "area", "darkorange", "a priori N(x̂⁻, P⁻)"),
                    Glyph("prior", "line", "darkorange", "", width=1.5),
                    Glyph("likelihood", "area", "seagreen", "vraisemblance de la mesure N(y ; x, R)"),
                    Glyph("likelihood", "line", "seagreen", "", width=1.5),
                    Glyph("posterior", "line", "royalblue", "a posteriori N(x̂, P) (paquet)"),
                    Glyph("product", "scatter", "black", "produit normalisé (calcul numérique)", x="x_dots",
                          marker="circle", size=4),
                    Glyph("mark_y", "line", "royalblue", "", x="mark_x", dash="dashed", width=1.5),
                ),
                height=270,
                x_label="position du chariot x (m)",
                x_range=(0.0, 25.0),
                # l'axe suit les densités : un pic de 1,6 /m (R = 1/16 m²) comme une loi étalée
                y_range=Follow(columns=("prior", "likelihood", "posterior"), include=(0.0,)),
            ),
            Panel(
                "Le gain K, poids de la mesure, en fonction de P⁻ (pour le R choisi)",
                "gain K (sans unité)",
                (
                    Glyph("gain_curve", "line", "purple", "K = P⁻/(P⁻ + R)", x="P_curve"),
                    Glyph("K", "scatter", "crimson", "position des curseurs", x="P_now", marker="circle", size=10),
                    Glyph("", "hline", "gray", "", value=0.5, dash="dotted", width=1.0),
                ),
                height=200,
                x_label="variance a priori P⁻ (m²)",
                x_range=(float(GAIN_CURVE_P[0]), float(GAIN_CURVE_P[-1])),
                y_range=(0.0, 1.05),
                x_log=True,
            ),
        ),
        fixed={"x_dots": PRODUCT_POSITIONS[::_EVERY], "P_curve": GAIN_CURVE_P},
        readout=_product_readout,
    )


# --------------------------------------------------------------------------- la boucle


def cycle_axes(n_steps: int = sc.CART_STEPS) -> tuple[ParameterAxis, ParameterAxis]:
    r"""L'étape de la boucle (départ, puis prédiction et correction de chaque mesure) et :math:`Q` (m²),
    deux points par décade de :math:`5\cdot 10^{-3}` à 5 m², centré sur l'exemple (0,5 m²)."""
    labels = ["départ : x̂₀, P₀"]
    for n in range(1, n_steps + 1):
        labels += [f"n = {n} : prédiction", f"n = {n} : correction"]
    stages = np.arange(2 * n_steps + 1, dtype=float)
    return (
        ParameterAxis("stage", "n", "étape de la boucle", "", stages, default=2 * n_steps, scale="index",
                      tick_labels=tuple(labels)),
        ParameterAxis("Q", "Q", "bruit d'état (incertitude d'un déplacement)", "m²", log_grid(sc.CART_Q, 2, 1, 2),
                      default=4),
    )


def cycle_run(stage: float, Q: float) -> dict[str, np.ndarray]:
    """Une exécution : la gaussienne de l'étape, celle de l'étape précédente, la vraisemblance de la
    mesure (correction seulement), la position vraie, les écarts-types de toutes les étapes."""
    cycle = sc.cart_cycle(Q=Q)
    k = int(stage)
    x = CYCLE_POSITIONS
    current = sc.gaussian_density(x, cycle.mean[k], cycle.var[k])
    previous = sc.gaussian_density(x, cycle.mean[k - 1], cycle.var[k - 1]) if k > 0 else np.full(x.size, np.nan)
    n = cycle.step_of(k)
    if cycle.kind[k] == "correction":
        likelihood = sc.gaussian_density(x, cycle.y[n - 1], sc.CART_R)
    else:
        likelihood = np.full(x.size, np.nan)
    truth = cycle.truth[n - 1] if n > 0 else np.nan
    return {
        "current": current,
        "previous": previous,
        "likelihood": likelihood,
        "truth_x": np.array([truth, truth]),
        "std": np.sqrt(cycle.var),
        "std_now": np.array([np.sqrt(cycle.var[k])]),
        "stage_now": np.array([float(k)]),
        "mean_now": np.array([cycle.mean[k]]),
        "var_now": np.array([cycle.var[k]]),
        "y_now": np.array([cycle.y[n - 1] if n > 0 else np.nan]),
    }


def _cycle_readout(series, values) -> str:
    stage = int(values[0])
    m, v = series["mean_now"][0], series["var_now"][0]
    if stage == 0:
        return f"Départ : x̂₀ = {number(m, 'm')}, P₀ = {number(v, 'm²')}."
    n = (stage + 1) // 2
    sub = subscript(n)
    if stage % 2 == 1:
        return (f"Prédiction n = {n} : x̂⁻{sub} = x̂{subscript(n - 1)} + v Δt = {number(m, 'm')} ; "
                f"P⁻{sub} = P{subscript(n - 1)} + Q = {number(v, 'm²')} : la gaussienne avance et s'élargit.")
    return (f"Correction n = {n} : mesure y{sub} = {number(series['y_now'][0], 'm')} ; "
            f"x̂{sub} = {number(m, 'm')}, P{sub} = {number(v, 'm²')} : la gaussienne se resserre.")


@register_sliders("intuition-cycle", chapter=CHAPTER)
def cycle_spec() -> SliderSpec:
    """La boucle prédiction–correction du chariot, étape par étape."""
    axes = cycle_axes()
    stages = axes[0].values
    # hauteur commune : le pic de la gaussienne la plus étroite de toute la grille
    v_min = min(sc.cart_cycle(Q=q).var.min() for q in axes[1].values)
    top = 1.1 / np.sqrt(2.0 * np.pi * v_min)
    return SliderSpec(
        name="intuition-cycle",
        chapter=CHAPTER,
        title=(f"Le chariot, mesure après mesure (v = {number(sc.CART_SPEED, 'm/s')}, "
               f"R = {number(sc.CART_R, 'm²')}, P₀ = {number(sc.CART_P0, 'm²')})"),
        x_label="étape de la boucle (sans unité)",
        axes=axes,
        run=cycle_run,
        time=CYCLE_POSITIONS,
        panels=(
            Panel(
                "La loi de la position à l'étape choisie",
                "densité de probabilité (1/m)",
                (
                    Glyph("previous", "line", "gray", "étape précédente", dash="dashed", width=1.5),
                    Glyph("likelihood", "area", "seagreen", "vraisemblance de la mesure"),
                    Glyph("likelihood", "line", "seagreen", "", width=1.5),
                    Glyph("current", "area", "royalblue", "loi de l'étape choisie"),
                    Glyph("current", "line", "royalblue", ""),
                    Glyph("truth_y", "line", "black", "position vraie", x="truth_x", dash="dotted"),
                ),
                height=280,
                x_label="position du chariot x (m)",
                x_range=(float(CYCLE_POSITIONS[0]), float(CYCLE_POSITIONS[-1])),
                y_range=(0.0, float(top)),
            ),
            Panel(
                "Écart-type √P : la prédiction l'augmente, la correction le diminue",
                "écart-type √P (m)",
                (
                    Glyph("std", "line", "royalblue", "écart-type à chaque étape", x="stages"),
                    Glyph("std", "scatter", "royalblue", "", x="stages", marker="circle", size=5),
                    Glyph("std_now", "scatter", "crimson", "étape choisie", x="stage_now", marker="circle",
                          size=11),
                ),
                height=220,
                x_label="étape de la boucle (0 = départ ; impaire = prédiction ; paire = correction)",
                x_range=(-0.5, float(stages[-1]) + 0.5),
            ),
        ),
        fixed={"stages": stages, "truth_y": np.array([0.0, float(top)])},
        readout=_cycle_readout,
    )
