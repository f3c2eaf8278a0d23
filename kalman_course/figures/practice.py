"""Figures du chapitre « Implémentation pratique et synthèse » : innovations d'un filtre bien ou mal réglé."""

from __future__ import annotations

import numpy as np

from ..filters.kalman import kalman_filter
from ..core.models import LinearGaussianModel
from ..scenarios.engine import (
    ENGINE_DT,
    ENGINE_P0,
    ENGINE_SEED,
    ENGINE_X0_HAT,
    ENGINE_X0_MEAN,
    engine_commands,
    engine_model,
)
from ..core.simulation import simulate
from ._registry import new_figure, register

CHAPTER = "pratique-synthese"


def innovation_runs(n_steps: int = 120):
    r"""Moteur simulé, filtré deux fois : avec le bon modèle, puis avec un modèle qui ignore la commande
    (pas de :math:`B`). Renvoie ``(normalised_good, normalised_bad)``, innovations normalisées
    :math:`\nu_{n,1} / \sqrt{S_{n,11}}` du premier capteur, formes (T,)."""
    model = engine_model()
    u = engine_commands(n_steps)
    sim = simulate(model, ENGINE_X0_MEAN, n_steps, u, rng=ENGINE_SEED)
    good = kalman_filter(model, sim.y, ENGINE_X0_HAT, ENGINE_P0, u)
    no_command = LinearGaussianModel(model.A, model.C, model.Q, model.R)
    bad = kalman_filter(no_command, sim.y, ENGINE_X0_HAT, ENGINE_P0)
    return tuple(r.innovation[:, 0] / np.sqrt(r.S[:, 0, 0]) for r in (good, bad))


@register("pratique-innovations", chapter=CHAPTER, title="Innovations normalisées : modèle juste ou modèle incomplet")
def innovations_figure():
    good, bad = innovation_runs()
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
