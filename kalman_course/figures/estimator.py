"""Figures du chapitre « Construction d'un estimateur » : récurrence de l'erreur moyenne, stabilité."""

from __future__ import annotations

import numpy as np
from matplotlib.ticker import MaxNLocator

from ..numbers import format_number
from ..scenarios.engine import ENGINE_DT, mean_error_experiment
from ..scenarios.stability import STABILITY_RUNS, fixed_gain_experiment
from ._registry import new_figure, register

CHAPTER = "estimateur"

def _mean_error_panel(ax, mc, rec, title: str) -> None:
    t = ENGINE_DT * np.arange(rec.e.shape[0])
    mean, sem = mc.mean_error(), mc.mean_error_sem()
    for i, (color, label) in enumerate([("tab:red", r"\theta_m"), ("tab:blue", r"\theta_a")]):
        ax.plot(t, rec.e[:, i], color=color, lw=1.6, label=f"récurrence du cours, ${label}$")
        ax.errorbar(
            t[::2], mean[::2, i], yerr=2 * sem[::2, i], fmt="o", ms=3, color=color, alpha=0.6, elinewidth=0.8,
            label=f"Monte-Carlo ({mc.n_runs} tirages) ± 2 σ, ${label}$",
        )
    ax.axhline(0.0, color="0.3", lw=0.8)
    ax.set_ylabel(r"erreur moyenne $\mathbb{E}[e_n]$ (°C)")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper right", ncol=2)


@register("estimateur-erreur-moyenne", chapter=CHAPTER, title="Erreur moyenne : Monte-Carlo contre la récurrence")
def mean_error_figure():
    fig, axes = new_figure(2, 1, width=7.0, height=6.4, sharex=True)
    mc, rec = mean_error_experiment(forget_command=False)
    _mean_error_panel(axes[0], mc, rec, r"Conditions respectées : $A_f = (I-KC)A$, $B_f = (I-KC)B$")
    mc, rec = mean_error_experiment(forget_command=True)
    _mean_error_panel(axes[1], mc, rec, r"Condition 1 violée : $B_f = 0$ (l'estimateur oublie la commande)")
    axes[1].set_xlabel("temps (s)")
    return fig


#: Les deux gains de la figure : la condition imprimée |1 − KC| < 1 tient pour les deux.
COUNTER_GAINS = (0.4, 0.6)


@register("estimateur-stabilite", chapter=CHAPTER, title="Stabilité : (I − KC) ne suffit pas, c'est (I − KC)A qui compte")
def stability_figure():
    fig, ax = new_figure(width=7.0, height=3.8)
    colors = {0.4: "tab:red", 0.6: "tab:green"}
    for K in COUNTER_GAINS:
        run = fixed_gain_experiment(K)
        mc, rec = run.monte_carlo, run.recursion
        n = np.arange(rec.e.shape[0])
        # nombres hors des formules : mathtext espacerait la virgule décimale
        label = (rf"$K$ = {format_number(K, decimals=1)} : $|1-KC|$ = {format_number(run.printed_radius, decimals=1)}, "
                 rf"$|(1-KC)A|$ = {format_number(run.radius, decimals=1)}")
        ax.semilogy(n, np.abs(rec.e[:, 0]), color=colors[K], lw=1.8, label=label)
        ax.semilogy(n[1::2], np.abs(mc.mean_error()[1::2, 0]), "o", ms=3.5, color=colors[K], alpha=0.7)
    ax.plot([], [], "o", ms=3.5, color="0.4", label=f"moyenne de Monte-Carlo ({STABILITY_RUNS} tirages)")
    ax.set_xlabel("itération n (sans unité)")
    ax.xaxis.set_major_locator(MaxNLocator(integer=True, steps=[1, 2, 5, 10]))
    ax.set_ylabel(r"$|\mathbb{E}[e_n]|$ (unités de x)")
    ax.set_title(r"Contre-exemple $A = 2$, $C = 1$ : l'erreur moyenne est multipliée par $(1-KC)A$")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8, loc="upper left")
    return fig
