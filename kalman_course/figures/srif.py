"""Figures du chapitre « Filtre d'information en racine carrée (SRIF) »."""

from __future__ import annotations

import numpy as np

from ..scenarios.diffuse import DIFFUSE_FIX_STD, diffuse_errors
from ._registry import new_figure, register

CHAPTER = "srif"

#: Plancher d'affichage en échelle logarithmique (un écart nul serait invisible).
_FLOOR = 1e-16


@register("srif-depart-diffus", chapter=CHAPTER,
          title="Initialisation sans a priori : filtre de Kalman avec P₀ = 10ᵏ I contre SRIF parti d'une information nulle")
def srif_diffuse_start():
    err = diffuse_errors()
    fig, (ax, at) = new_figure(2, 1, width=7.5, height=8.0)

    # gauche : écart maximal en fonction de l'a priori du filtre de Kalman
    ok = ~err.kf_failed
    ax.semilogy(err.exponents[ok], np.maximum(err.kf_max[ok], _FLOOR), "o-", color="tab:blue", ms=5,
                label=r"filtre de Kalman, $\hat x_0 = 0$, $P_0 = 10^k I$")
    if err.kf_failed.any():
        top = 1e-2
        ax.semilogy(err.exponents[~ok], np.full((~ok).sum(), top), "x", color="tab:red", ms=9, mew=2,
                    label=r"échec : $S$ non définie positive")
    ax.axhline(max(err.srif_max, _FLOOR), color="tab:green", lw=2,
               label=r"SRIF sans a priori ($\mathcal{R}_{xx} = 0$)")
    ax.axhline(DIFFUSE_FIX_STD, color="0.4", lw=1, ls=":", label=r"bruit de mesure $\sigma$ = 1 mm")
    ax.set_xlabel(r"exposant $k$ de l'a priori $P_0 = 10^k I$ (sans unité)")
    ax.set_ylabel("écart maximal de position (m)")
    ax.set_ylim(1e-16, 1e-1)
    ax.set_title("Écart à la référence (précision étendue), max. sur 30 relevés", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(loc="upper left", fontsize=8)

    # droite : écart pas à pas pour deux a priori et le SRIF
    steps = np.arange(1, err.srif.shape[0] + 1)
    colors = {6: "tab:purple", 10: "tab:blue"}
    for e, color in colors.items():
        i = list(err.exponents).index(e)
        at.semilogy(steps, np.maximum(err.kf[i], _FLOOR), "o-", ms=3, color=color,
                    label=rf"filtre de Kalman, $P_0 = 10^{{{e}}} I$")
    at.semilogy(steps, np.maximum(err.srif, _FLOOR), "s-", ms=3, color="tab:green", label="SRIF sans a priori")
    at.axhline(DIFFUSE_FIX_STD, color="0.4", lw=1, ls=":")
    at.set_xlabel("relevé n° (un par seconde)")
    at.set_ylabel("écart de position (m)")
    at.set_ylim(1e-16, 1e-1)
    at.set_title("Écart à chaque relevé (le premier ne fixe pas la vitesse ; écart nul tracé à $10^{-16}$)", fontsize=10)
    at.grid(alpha=0.3, which="both")
    at.legend(loc="center right", fontsize=8)
    return fig
