"""Figures du chapitre « Implémentation pratique et synthèse » : innovations d'un filtre bien ou mal réglé."""

from __future__ import annotations

import numpy as np

from ..scenarios.engine import ENGINE_DT, forgotten_command
from ._registry import new_figure, register

CHAPTER = "pratique-synthese"


@register("pratique-innovations", chapter=CHAPTER, title="Innovations normalisées : modèle juste ou modèle incomplet")
def innovations_figure():
    run = forgotten_command()
    good, bad = run.normalised_good, run.normalised_bad
    t = ENGINE_DT * np.arange(1, good.size + 1)
    fig, axes = new_figure(2, 1, width=7.0, height=5.6, sharex=True, sharey=True)
    for ax, data, color, title in (
        (axes[0], good, "tab:blue", "Modèle juste (avec la commande) : innovations centrées"),
        (axes[1], bad, "tab:red", "Modèle sans la commande : innovations biaisées dès que le débit n'est pas nul"),
    ):
        ax.axhspan(-2, 2, color="0.85", label="± 2 (95 % si N(0, 1))")
        ax.plot(t, data, ".-", ms=3, lw=0.6, color=color, label=r"$\nu_{n,1} / \sqrt{S_{n,11}}$")
        ax.axhline(0.0, color="0.3", lw=0.8)
        ax.set_ylabel("innovation normalisée (sans unité)")
        ax.set_title(title, fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper right")
    axes[1].set_xlabel("temps (s)")
    return fig
