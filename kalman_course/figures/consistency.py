r"""Figures du chapitre « Vérifier les hypothèses : tests statistiques » (NIS, NEES, blancheur, centrage).

Tous les filtres portent sur les mêmes relevés du moteur (:mod:`kalman_course.scenarios.engine`, graine
fixe) : le modèle juste, :math:`\Psi` dix fois trop petit, :math:`\Phi` dix fois trop grand, et un modèle
incomplet qui oublie le couplage thermique entre le moteur et l'air (:math:`A` diagonale).
"""

from __future__ import annotations

import numpy as np
import scipy.stats

from ..diagnostics.consistency import (
    chi2_band,
    nis,
    whitened_innovations,
    whiteness_test,
)
from ..scenarios.engine import CONSISTENCY_MC_RUNS, CONSISTENCY_MC_STEPS, ENGINE_DT, consistency_monte_carlo, consistency_runs
from ..numbers import format_spec as fr
from ._registry import new_figure, register

CHAPTER = "tests-statistiques"

#: Décalage maximal des autocorrélations.
MAX_LAG = 20


#: Titres des panneaux : le nom court du filtre et ce qu'il a de faux.
_TITLES = {
    "modèle juste": "modèle juste",
    "Ψ ÷ 10": "Ψ ÷ 10 : bruit de mesure dix fois trop petit (filtre optimiste)",
    "Φ × 10": "Φ × 10 : bruit d'état dix fois trop grand (filtre pessimiste)",
    "couplage oublié": "couplage oublié : A diagonale (modèle incomplet)",
}

_COLORS = {
    "modèle juste": "tab:blue",
    "Ψ ÷ 10": "tab:red",
    "Φ × 10": "tab:orange",
    "couplage oublié": "tab:purple",
}


@register("tests-nis-loi", chapter=CHAPTER, title="Distribution de la NIS du modèle juste et loi du χ² à 2 degrés")
def nis_distribution_figure():
    _, results = consistency_runs()
    values = nis(results["modèle juste"])
    fig, ax = new_figure(width=7.0, height=3.4)
    edges = np.linspace(0.0, 12.0, 31)
    ax.hist(values, bins=edges, density=True, color="tab:blue", alpha=0.55,
            label=f"NIS du modèle juste ({values.size} pas)")
    grid = np.linspace(0.0, 12.0, 300)
    ax.plot(grid, scipy.stats.chi2.pdf(grid, 2), color="k", lw=1.6, label=r"densité de la loi $\chi^2_2$")
    ax.set_xlabel(r"NIS $\tilde y_n^T S_n^{-1} \tilde y_n$ (sans unité)")
    ax.set_ylabel("densité de probabilité (sans unité)")
    ax.set_title("Modèle juste : la NIS suit la loi du χ² à m = 2 degrés de liberté", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return fig


@register("tests-nis", chapter=CHAPTER, title="NIS au cours du temps : filtre bien ou mal réglé")
def nis_figure():
    _, results = consistency_runs()
    names = ["modèle juste", "Ψ ÷ 10", "Φ × 10"]
    fig, axes = new_figure(3, 1, width=7.0, height=7.2, sharex=True, sharey=True)
    step_lo, step_hi = chi2_band(2, 1)
    for ax, name in zip(axes, names):
        values = nis(results[name])
        t = ENGINE_DT * np.arange(1, values.size + 1)
        lo, hi = chi2_band(2, values.size)
        ax.axhspan(step_lo, step_hi, color="0.88", label=r"95 % d'une $\chi^2_2$ (un pas)")
        ax.plot(t, values, ".", ms=2.5, color=_COLORS[name], label=r"NIS$_n$")
        ax.axhline(values.mean(), color=_COLORS[name], lw=1.8, label=f"moyenne = {fr(values.mean(), '.2f')}")
        ax.axhspan(lo, hi, color="tab:green", alpha=0.35, label=f"bande de la moyenne [{fr(lo, '.2f')} ; {fr(hi, '.2f')}]")
        ax.set_yscale("log")
        ax.set_ylim(1e-3, 1e4)
        ax.set_ylabel("NIS (sans unité)")
        ax.set_title(_TITLES[name], fontsize=10)
        ax.grid(alpha=0.3, which="major")
        ax.legend(fontsize=7, loc="upper right", ncol=2)
    axes[-1].set_xlabel("temps (s)")
    return fig


@register("tests-nees", chapter=CHAPTER, title="NEES moyenne de 100 tirages de Monte-Carlo et sa bande du χ²")
def nees_figure():
    runs = consistency_monte_carlo()
    fig, ax = new_figure(width=7.0, height=3.8)
    lo, hi = chi2_band(2, CONSISTENCY_MC_RUNS)
    t = ENGINE_DT * np.arange(1, CONSISTENCY_MC_STEPS + 1)
    ax.axhspan(lo, hi, color="tab:green", alpha=0.3, label=f"bande à 95 % de la moyenne [{fr(lo, '.2f')} ; {fr(hi, '.2f')}]")
    ax.axhline(2.0, color="0.3", lw=0.8, ls="--", label="espérance d = 2 (dimension de l'état)")
    for name, run in runs.items():
        ax.plot(t, run.nees.mean(axis=0), lw=1.4, color=_COLORS[name], label=_TITLES[name].split(" (")[0])
    ax.set_yscale("log")
    ax.set_ylim(1.0, 50.0)
    ax.set_yticks([1, 2, 5, 10, 20, 50], labels=["1", "2", "5", "10", "20", "50"])
    ax.set_yticks([], minor=True)
    ax.set_xlabel("temps (s)")
    ax.set_ylabel(f"NEES moyenne sur {CONSISTENCY_MC_RUNS} tirages (sans unité)")
    ax.set_title("NEES : erreur vraie comparée à la covariance P annoncée par le filtre", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper right", ncol=2)
    return fig


@register("tests-autocorrelation", chapter=CHAPTER,
          title="Autocorrélation des innovations blanchies et bande ± 1,96/√T")
def autocorrelation_figure():
    _, results = consistency_runs()
    names = ["modèle juste", "Ψ ÷ 10", "couplage oublié"]
    fig, axes = new_figure(3, 1, width=7.0, height=7.2, sharex=True, sharey=True)
    for ax, name in zip(axes, names):
        test = whiteness_test(results[name], MAX_LAG)
        ax.axhspan(-test.band, test.band, color="0.85", label=f"± 1,96/√T = ± {fr(test.band, '.3f')}")
        for i, (offset, marker) in enumerate(((-0.15, "o"), (0.15, "s"))):
            ax.vlines(test.lags + offset, 0.0, test.autocorrelation[i], color=_COLORS[name], lw=1.2,
                      alpha=1.0 if i == 0 else 0.55)
            ax.plot(test.lags + offset, test.autocorrelation[i], marker, ms=3.5, color=_COLORS[name],
                    alpha=1.0 if i == 0 else 0.55, label=f"composante {i + 1} (capteur {'moteur' if i == 0 else 'air'})")
        ax.axhline(0.0, color="0.3", lw=0.8)
        ax.set_ylabel("autocorrélation (sans unité)")
        ax.set_title(f"{_TITLES[name]} — Ljung–Box p = {fr(test.p_value, '.2g')}", fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper right", ncol=3)
    axes[0].set_ylim(-0.45, 0.75)
    axes[-1].set_xlabel("décalage ℓ (pas de 1 s)")
    axes[-1].set_xticks(np.arange(1, MAX_LAG + 1, 2))
    return fig


@register("tests-centrage", chapter=CHAPTER, title="Moyenne cumulée des innovations blanchies")
def centring_figure():
    _, results = consistency_runs()
    names = ["modèle juste", "couplage oublié"]
    fig, axes = new_figure(1, 2, width=7.5, height=3.4, sharey=False)
    for ax, name in zip(axes, names):
        e = whitened_innovations(results[name])
        k = np.arange(1, e.shape[0] + 1)
        t = ENGINE_DT * k
        funnel = 1.96 / np.sqrt(k)
        ax.fill_between(t, -funnel, funnel, color="0.85", label="± 1,96/√k (moyenne de k valeurs N(0, 1))")
        for i, style in enumerate(("-", "--")):
            ax.plot(t, np.cumsum(e[:, i]) / k, style, lw=1.4, color=_COLORS[name],
                    label=f"composante {i + 1} (capteur {'moteur' if i == 0 else 'air'})")
        ax.axhline(0.0, color="0.3", lw=0.8)
        ax.set_xscale("log")
        ax.set_xlabel("temps (s)")
        ax.set_ylabel("moyenne cumulée (sans unité)")
        ax.set_title(_TITLES[name].split(" : ")[0], fontsize=10)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7, loc="lower right")
    axes[0].set_ylim(-2.5, 2.5)
    return fig


__all__ = ["CHAPTER", "MAX_LAG"]
