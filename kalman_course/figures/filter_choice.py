"""Figures du chapitre « Quel filtre choisir ? »."""

from __future__ import annotations

import numpy as np

from ..diagnostics.consistency import chi2_band
from ..numbers import format_number
from ..scenarios import filter_choice
from ._registry import new_figure, register

CHAPTER = "quel-filtre"

#: Couleur et trait de chaque filtre (mêmes dans la figure et les curseurs du chapitre).
STYLES = {
    "EKF": ("tab:red", "-"),
    "EKF itéré": ("tab:purple", "--"),
    "UKF": ("tab:blue", "-"),
    "CKF": ("tab:green", "-."),
    "GHKF": ("tab:olive", ":"),
    "filtre particulaire": ("tab:gray", "-"),
    "EnKF": ("tab:orange", "--"),
}


@register("choix-cible-lointaine", chapter=CHAPTER,
          title="Cible lointaine, σ₀ = 300 m : erreur de position et NEES moyennes des sept filtres")
def choice_distant_target():
    runs = filter_choice.choice_runs()
    fig, (ax, an) = new_figure(2, 1, width=8.0, height=6.2, sharex=True)
    for name in filter_choice.CHOICE_FILTERS:
        color, ls = STYLES[name]
        ax.semilogy(runs.t, runs.position_error[name], color=color, ls=ls, lw=1.6, label=name)
        nees = np.minimum(runs.nees[name], 1e8)  # NEES infinie (nuage dégénéré) : tracée au bord
        an.semilogy(runs.t, nees, color=color, ls=ls, lw=1.6, label=name)
    lo, hi = chi2_band(4, runs.n_runs)
    an.axhspan(lo, hi, color="tab:green", alpha=0.2, label=f"bande à 95 % ({runs.n_runs} tirages)")
    an.axhline(4.0, color="tab:green", lw=1.0)
    an.set_ylim(1.0, 2e8)
    ax.set_ylabel("erreur de position moyenne (m)")
    ax.set_title(f"σ₀ = {format_number(runs.prior_std, decimals=0)} m, {runs.n_runs} tirages : "
                 "erreur ‖p̂ₖ − pₖ‖ moyenne", fontsize=10)
    an.set_ylabel("NEES moyenne (sans unité)")
    an.set_xlabel("temps (s)")
    an.set_title("NEES moyenne (4 attendu)", fontsize=10)
    for a in (ax, an):
        a.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, ncol=4, loc="upper right")
    an.legend(fontsize=7, ncol=2, loc="upper right")
    return fig
