"""Figures du chapitre « Contrôle d'un système dynamique »."""

from __future__ import annotations

import numpy as np

from ..scenarios.engine import ENGINE_DT, engine_commands, engine_simulation
from ._registry import new_figure, register

CHAPTER = "controle-systeme"


@register("systeme-moteur", chapter=CHAPTER, title="État, commande et mesure du moteur simulé")
def engine_system():
    u = engine_commands(120)
    sim = engine_simulation(120)
    t = ENGINE_DT * np.arange(1, u.shape[0] + 1)
    fig, axes = new_figure(3, 1, width=7.0, height=7.0, sharex=True)
    ax_u, ax_x, ax_y = axes
    ax_u.step(ENGINE_DT * np.arange(u.shape[0]), u[:, 0], where="post", color="tab:purple", lw=1.8)
    ax_u.set_ylabel("débit $u_n$ (g/s)")
    ax_u.set_title("Commande : débit de carburant")
    ax_x.plot(t, sim.x[:, 0], color="tab:red", lw=1.6, label=r"moteur $\theta_m$")
    ax_x.plot(t, sim.x[:, 1], color="tab:blue", lw=1.6, label=r"air $\theta_a$")
    ax_x.set_ylabel("échauffement (°C)")
    ax_x.set_title(r"État $x_n = (\theta_m, \theta_a)$ : inconnu en pratique")
    ax_x.legend(loc="lower right", fontsize=8)
    ax_y.plot(t, sim.y[:, 0], ".", ms=3, color="tab:red", label="thermocouple du moteur $y_1$")
    ax_y.plot(t, sim.y[:, 1], ".", ms=3, color="tab:blue", label="thermocouple dans l'air $y_2$")
    ax_y.set_ylabel("tension mesurée (mV)")
    ax_y.set_xlabel("temps (s)")
    ax_y.set_title(r"Mesure $y_n = C x_n + \psi_n$ : dans l'espace des mesures (mV)")
    ax_y.legend(loc="lower right", fontsize=8)
    for ax in axes:
        ax.grid(alpha=0.3)
    return fig
