r"""Curseur du chapitre « Filtre d'information en racine carrée (SRIF) » : la force de l'a priori fictif.

:func:`~kalman_course.scenarios.diffuse.diffuse_errors` : le filtre de Kalman parti de
:math:`\hat x_0 = 0`, :math:`P_0 = 10^k I`, contre le SRIF parti de :math:`\mathcal R_{xx} = 0` (aucun a
priori), comparés à la référence en précision étendue. Un seul curseur, :math:`k` ; position par défaut
:math:`k = 10`, l'une des deux courbes de la figure du chapitre.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..scenarios.diffuse import DIFFUSE_FIX_STD, diffuse_errors
from .figure import SliderSpec, number, register_sliders
from .grid import ParameterAxis
from .spec import Glyph, Panel

__all__ = ["srif_axes", "srif_run", "srif_spec"]

CHAPTER = "srif"
#: Plancher d'affichage (un écart nul serait invisible en échelle logarithmique).
FLOOR = 1e-16
_SUP = str.maketrans("0123456789", "⁰¹²³⁴⁵⁶⁷⁸⁹")


@lru_cache(maxsize=1)
def _errors():
    return diffuse_errors()


def srif_axes() -> tuple[ParameterAxis]:
    """L'exposant :math:`k` de :math:`P_0 = 10^k I` (10 par défaut)."""
    exponents = _errors().exponents
    return (
        ParameterAxis("exponent", "k", "a priori du filtre de Kalman P₀ = 10ᵏ I", "", exponents,
                      default=int(np.flatnonzero(exponents == 10)[0]), scale="index",
                      tick_labels=tuple(f"10{str(int(e)).translate(_SUP)} I" for e in exponents)),
    )


def srif_run(exponent: float) -> dict[str, np.ndarray]:
    """L'écart du filtre de Kalman à chaque relevé (NaN s'il a échoué) et son écart maximal."""
    err = _errors()
    i = int(np.flatnonzero(err.exponents == exponent)[0])
    failed = bool(err.kf_failed[i])
    kf = np.full(err.srif.shape, np.nan) if failed else np.maximum(err.kf[i], FLOOR)
    return {
        "kf": kf,
        "k_now": np.array([exponent]),
        "max_now": np.array([1e-2 if failed else max(err.kf_max[i], FLOOR)]),
        "failed": np.array([float(failed)]),
        "raw_max": np.array([np.nan if failed else err.kf_max[i]]),
    }


def _readout(series, values) -> str:
    k = int(values[0])
    srif = number(_errors().srif_max, "m")
    if series["failed"][0]:
        return (f"P₀ = 10{str(k).translate(_SUP)} I : le filtre de Kalman s'arrête, la covariance d'innovation "
                f"calculée n'est plus définie positive. SRIF : écart maximal {srif}.")
    return (f"P₀ = 10{str(k).translate(_SUP)} I : écart maximal du filtre de Kalman "
            f"{number(series['raw_max'][0], 'm')} ; SRIF sans a priori : {srif}.")


@register_sliders("srif-a-priori", chapter=CHAPTER)
def srif_spec() -> SliderSpec:
    """Le filtre de Kalman à a priori fictif contre le SRIF sans a priori."""
    err = _errors()
    ok = ~err.kf_failed
    steps = np.arange(1, err.srif.shape[0] + 1, dtype=float)
    return SliderSpec(
        name="srif-a-priori",
        chapter=CHAPTER,
        title="Départ sans a priori (relevés au millimètre) : réglez l'a priori fictif du filtre de Kalman",
        x_label="relevé n° (un par seconde)",
        axes=srif_axes(),
        run=srif_run,
        time=steps,
        panels=(
            Panel(
                "Écart à la référence à chaque relevé (écart nul tracé à 10⁻¹⁶)",
                "écart de position (m)",
                (
                    Glyph("srif", "line", "seagreen", "SRIF sans a priori", width=2.5),
                    Glyph("kf", "line", "royalblue", "filtre de Kalman, P₀ = 10ᵏ I"),
                    Glyph("kf", "scatter", "royalblue", "", marker="circle", size=5),
                    Glyph("", "hline", "gray", "bruit de mesure σ = 1 mm", value=DIFFUSE_FIX_STD, dash="dotted"),
                ),
                y_log=True,
                y_range=(FLOOR, 0.1),
                height=260,
            ),
            Panel(
                "Écart maximal en fonction de k (croix rouge : le filtre échoue)",
                "écart maximal (m)",
                (
                    Glyph("kf_max", "line", "royalblue", "filtre de Kalman", x="exponents"),
                    Glyph("", "hline", "seagreen", "SRIF", value=max(err.srif_max, FLOOR)),
                    Glyph("failed_y", "scatter", "firebrick", "échec", x="failed_x", marker="x", size=12),
                    Glyph("max_now", "scatter", "crimson", "k choisi", x="k_now", marker="circle", size=12),
                ),
                x_label="exposant k de P₀ = 10ᵏ I (sans unité)",
                x_range=(float(err.exponents[0]) - 0.5, float(err.exponents[-1]) + 0.5),
                y_log=True,
                y_range=(FLOOR, 0.1),
                height=230,
            ),
        ),
        fixed={
            "srif": np.maximum(err.srif, FLOOR),
            "exponents": err.exponents[ok],
            "kf_max": np.maximum(err.kf_max[ok], FLOOR),
            "failed_x": err.exponents[~ok] if (~ok).any() else np.array([np.nan]),
            "failed_y": np.full(max(int((~ok).sum()), 1), 1e-2),
        },
        readout=_readout,
    )
