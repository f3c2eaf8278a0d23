r"""Curseurs de la partie « Assimilation de données » (expériences courtes de
:mod:`kalman_course.scenarios.assimilation` : 300 cycles de Lorenz-96, dont 100 de mise en route, départ sur
l'attracteur) :

* « Le filtre d'ensemble en grande dimension » — la **taille** :math:`N` et l'**inflation** :math:`\lambda`
  de l'EnKF stochastique (la carte du rmse.a et sa région de divergence) ; le **rayon de localisation** du
  LETKF à 7 membres ;
* « Méthodes variationnelles » — la **densité d'observation** (une variable observée sur :math:`k`) :
  LETKF, 3D-Var et interpolation optimale.
"""

from __future__ import annotations

import numpy as np

from ..filters.ensemble_analysis import gaspari_cohn
from ..scenarios import assimilation as assim
from .figure import SliderSpec, number, register_sliders
from .grid import ParameterAxis
from .spec import Glyph, Panel

__all__ = ["inflation_axes", "inflation_run", "inflation_spec", "localization_axes", "localization_run",
           "localization_spec", "density_axes", "density_run", "density_spec"]

ENSEMBLE_CHAPTER = "assimilation-ensemble"
VARIATIONAL_CHAPTER = "methodes-variationnelles"

#: Couleurs des courbes de la carte, une par taille d'ensemble.
_MAP_COLORS = ("crimson", "darkorange", "olivedrab", "teal", "navy")
#: Axe logarithmique des erreurs : des premiers cycles (départ à 0,03 près) à la divergence (≈ 7).
_RMSE_RANGE = (0.01, 20.0)
_CYCLES = np.arange(1, assim.SHORT_CYCLES + 1, dtype=float)


def _rmse_panel(glyphs: tuple[Glyph, ...]) -> Panel:
    return Panel(
        "Erreur de l'analyse à chaque cycle (moyenne quadratique sur les 40 variables)",
        "erreur de l'analyse (sans unité)",
        glyphs + (
            Glyph("", "hline", "black", "erreur des observations (R = I)", value=1.0, dash="dotted", width=1.5),
            Glyph("", "vline", "gray", "fin de la mise en route", value=float(assim.SHORT_BURN_IN), dash="dashed",
                  width=1.0),
        ),
        y_log=True, y_range=_RMSE_RANGE, height=260,
    )


# --------------------------------------------------------------------------- taille × inflation


def inflation_axes() -> tuple[ParameterAxis, ParameterAxis]:
    """La taille :math:`N` (10 à 40, 40 par défaut) et l'inflation :math:`\\lambda` (1 à 1,2, 1,06 par défaut :
    la ligne de DAPPER)."""
    return (
        ParameterAxis("n_members", "N", "taille de l'ensemble", "", np.array(assim.MAP_MEMBERS, dtype=float),
                      default=assim.MAP_MEMBERS.index(40), scale="index",
                      tick_labels=tuple(str(n) for n in assim.MAP_MEMBERS)),
        ParameterAxis("inflation", "λ", "inflation", "", np.array(assim.MAP_INFLATIONS),
                      default=assim.MAP_INFLATIONS.index(1.06), scale="index",
                      tick_labels=tuple(number(v, significant=3) for v in assim.MAP_INFLATIONS)),
    )


def inflation_run(n_members: float, inflation: float) -> dict[str, np.ndarray]:
    """L'erreur à chaque cycle de l'EnKF stochastique (``n_members``, ``inflation``), et toute la carte du
    rmse.a (une courbe par taille), avec le point affiché."""
    exp = assim.inflation_run(int(round(n_members)), float(inflation))
    table = assim.inflation_map()
    out = {"rmse": exp.rmse, "rmse_a": np.array([exp.rmse_a]),
           "here_x": np.array([inflation]), "here_y": np.array([exp.rmse_a])}
    for N, row in zip(assim.MAP_MEMBERS, table):
        out[f"map_{N}"] = row
    return out


def _inflation_readout(series, values) -> str:
    N, lam = values
    return (f"N = {int(round(N))}, λ = {number(lam)} : erreur moyenne de l'analyse (rmse.a, cycles "
            f"{assim.SHORT_BURN_IN + 1} à {assim.SHORT_CYCLES}) = {number(series['rmse_a'][0])} ; celle des "
            f"observations vaut 1.")


@register_sliders("assimilation-inflation", chapter=ENSEMBLE_CHAPTER)
def inflation_spec() -> SliderSpec:
    """Taille de l'ensemble et inflation de l'EnKF stochastique sur Lorenz-96 : la carte du rmse.a."""
    lam = np.array(assim.MAP_INFLATIONS)
    map_glyphs = tuple(Glyph(f"map_{N}", "line", color, f"N = {N}", x="lam", width=1.8)
                       for N, color in zip(assim.MAP_MEMBERS, _MAP_COLORS))
    return SliderSpec(
        name="assimilation-inflation",
        chapter=ENSEMBLE_CHAPTER,
        title="EnKF stochastique sur Lorenz-96 (n = 40, expérience courte : 300 cycles) : taille N et inflation λ",
        x_label="cycle d'assimilation k (numéro)",
        axes=inflation_axes(),
        run=inflation_run,
        time=_CYCLES,
        fixed={"lam": lam, "div_lo": np.ones_like(lam), "div_hi": np.full_like(lam, 20.0)},
        panels=(
            _rmse_panel((Glyph("rmse", "line", "royalblue", "EnKF stochastique", width=1.5),)),
            Panel(
                "Carte du rmse.a : une courbe par taille N, le point affiché en étoile",
                "rmse.a (sans unité)",
                (Glyph("div_lo", "band", "crimson", "divergence : pire que les observations", x="lam", upper="div_hi",
                       alpha=0.6),) + map_glyphs
                + (Glyph("here_y", "scatter", "black", "réglage affiché", x="here_x", marker="star", size=16),),
                y_log=True, y_range=(0.05, 20.0), x_label="inflation λ (sans unité)", x_range=(0.99, 1.21),
                height=280,
            ),
        ),
        readout=_inflation_readout,
    )


# --------------------------------------------------------------------------- rayon de localisation


#: Distances du taper tracé (nombre de variables).
_DISTANCES = np.linspace(0.0, 20.0, 201)


def localization_axes() -> tuple[ParameterAxis]:
    """Le rayon de localisation du LETKF (1 à 16, ou ∞ : l'ETKF global) ; 4 par défaut (la ligne de DAPPER).
    L'axe porte la position (0 à 5) ; :func:`localization_run` la traduit en rayon."""
    radii = assim.LOCALIZATION_RADII
    return (ParameterAxis("radius", "r", "rayon de localisation", "", np.arange(len(radii), dtype=float),
                          default=radii.index(4.0), scale="index",
                          tick_labels=tuple("∞ (aucune)" if np.isinf(r) else number(r) for r in radii)),)


def localization_run(position: float) -> dict[str, np.ndarray]:
    """Le LETKF à 7 membres (inflation 1,04) de rayon ``LOCALIZATION_RADII[position]`` : erreur à chaque cycle,
    poids de Gaspari–Cohn en fonction de la distance."""
    radius = assim.LOCALIZATION_RADII[int(round(position))]
    exp = assim.localization_run(radius)
    return {"rmse": exp.rmse, "rmse_a": np.array([exp.rmse_a]), "rho": gaspari_cohn(_DISTANCES, radius),
            "radius": np.array([radius])}


def _localization_readout(series, values) -> str:
    radius = series["radius"][0]
    what = "sans localisation (ETKF global)" if np.isinf(radius) else f"rayon {number(radius)}"
    return (f"LETKF à {assim.LOCALIZATION_MEMBERS} membres, {what} : rmse.a = {number(series['rmse_a'][0])} "
            f"(erreur des observations : 1).")


@register_sliders("assimilation-localisation", chapter=ENSEMBLE_CHAPTER)
def localization_spec() -> SliderSpec:
    """Le rayon de localisation du LETKF à 7 membres sur Lorenz-96."""
    return SliderSpec(
        name="assimilation-localisation",
        chapter=ENSEMBLE_CHAPTER,
        title="LETKF à 7 membres sur Lorenz-96 (n = 40, expérience courte : 300 cycles) : rayon de localisation",
        x_label="cycle d'assimilation k (numéro)",
        axes=localization_axes(),
        run=localization_run,
        time=_CYCLES,
        fixed={"d": _DISTANCES},
        panels=(
            _rmse_panel((Glyph("rmse", "line", "royalblue", "LETKF, 7 membres", width=1.5),)),
            Panel(
                "Poids de Gaspari–Cohn d'une observation à la distance d",
                "poids ρ(d) (sans unité)",
                (Glyph("rho", "line", "darkgreen", "taper de Gaspari–Cohn", x="d", width=2.0),),
                y_range=(-0.05, 1.1), x_label="distance d (nombre de variables)", x_range=(0.0, 20.0), height=220,
            ),
        ),
        readout=_localization_readout,
    )


# --------------------------------------------------------------------------- densité d'observation


_DENSITY_STYLE = {"letkf": ("royalblue", "LETKF (10 membres, rayon 4)"), "3dvar": ("darkorange", "3D-Var (B = 0,02 Σ)"),
                  "oi": ("seagreen", "interpolation optimale")}


def density_axes() -> tuple[ParameterAxis]:
    """Une variable observée sur :math:`k` (1, 2, 4, 8 : 40, 20, 10 ou 5 observations) ; toutes par défaut."""
    spacings = assim.DENSITY_SPACINGS
    return (ParameterAxis("spacing", "k", "une variable observée sur k", "", np.array(spacings, dtype=float),
                          default=0, scale="index",
                          tick_labels=tuple(f"{k} ({40 // k} observations)" for k in spacings)),)


def density_run(spacing: float) -> dict[str, np.ndarray]:
    """Les trois méthodes quand une variable sur ``spacing`` est observée : erreur à chaque cycle, et le
    rmse.a de chacune pour toutes les densités (le point affiché marqué)."""
    k = int(round(spacing))
    table = assim.density_table()
    out = {"m_here": np.array([40.0 / k])}
    for method, row in zip(assim.DENSITY_METHODS, table):
        exp = assim.density_run(k, method)
        out[f"rmse_{method}"] = exp.rmse
        out[f"curve_{method}"] = row
        out[f"here_{method}"] = np.array([exp.rmse_a])
    return out


def _density_readout(series, values) -> str:
    k = int(round(values[0]))
    parts = [f"{_DENSITY_STYLE[m][1].split(' (')[0]} {number(series[f'here_{m}'][0])}" for m in assim.DENSITY_METHODS]
    return f"Une variable observée sur {k} ({40 // k} observations) — rmse.a : " + " ; ".join(parts) + "."


@register_sliders("assimilation-densite", chapter=VARIATIONAL_CHAPTER)
def density_spec() -> SliderSpec:
    """La densité d'observation : LETKF, 3D-Var et interpolation optimale sur Lorenz-96."""
    observed = np.array([40.0 / k for k in assim.DENSITY_SPACINGS])
    curves = tuple(Glyph(f"curve_{m}", "line", _DENSITY_STYLE[m][0], _DENSITY_STYLE[m][1], x="m_obs", width=1.8)
                   for m in assim.DENSITY_METHODS)
    marks = tuple(Glyph(f"here_{m}", "scatter", _DENSITY_STYLE[m][0], "", x="m_here", marker="star", size=15)
                  for m in assim.DENSITY_METHODS)
    return SliderSpec(
        name="assimilation-densite",
        chapter=VARIATIONAL_CHAPTER,
        title="Lorenz-96 (n = 40, expérience courte : 300 cycles) : combien de variables observer ?",
        x_label="cycle d'assimilation k (numéro)",
        axes=density_axes(),
        run=density_run,
        time=_CYCLES,
        fixed={"m_obs": observed},
        panels=(
            _rmse_panel(tuple(Glyph(f"rmse_{m}", "line", _DENSITY_STYLE[m][0], _DENSITY_STYLE[m][1], width=1.4)
                              for m in assim.DENSITY_METHODS)),
            Panel(
                "rmse.a en fonction du nombre de variables observées, le réglage affiché en étoile",
                "rmse.a (sans unité)",
                curves + marks,
                y_log=True, y_range=(0.05, 20.0), x_label="variables observées (nombre)", x_range=(0.0, 42.0),
                height=260,
            ),
        ),
        readout=_density_readout,
    )
