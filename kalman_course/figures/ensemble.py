"""Figures du chapitre « Le filtre de Kalman d'ensemble (EnKF) »."""

from __future__ import annotations

import numpy as np

from ..numbers import format_number
from ..scenarios.convergence import ensemble_convergence, ensemble_spread
from ._registry import new_figure, register

CHAPTER = "enkf"


@register("enkf-convergence", chapter=CHAPTER,
          title="Convergence de l'EnKF vers le filtre de Kalman : erreur en 1/√N")
def enkf_convergence():
    conv = ensemble_convergence()
    N = conv.sizes
    fig, ax = new_figure(width=7.0, height=3.8)
    ax.loglog(N, conv.mean_error, "o-", color="tab:blue",
              label=f"moyenne : ‖x̄ − x̂_KF‖ (pente {format_number(conv.mean_slope, decimals=2)})")
    ax.loglog(N, conv.cov_error, "s-", color="tab:orange",
              label=f"covariance : ‖P − P_KF‖ (pente {format_number(conv.cov_slope, decimals=2)})")
    ax.loglog(N, conv.mean_error[0] * np.sqrt(N[0] / N), "k:", label="pente −1/2")
    ax.set_xlabel("taille de l’ensemble N (sans unité)")
    ax.set_ylabel("écart quadratique moyen (unités de l'état)")
    ax.set_title(f"Banc d'essai linéaire, {conv.n_runs} graines par N", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    return fig


@register("enkf-perturbations", chapter=CHAPTER,
          title="Observations perturbées : dispersion de l'ensemble contre la variance du filtre de Kalman")
def enkf_perturbations():
    s = ensemble_spread()
    t = np.arange(1, s.kalman.size + 1)
    fig, ax = new_figure(width=7.5, height=3.6)
    ax.plot(t, s.kalman, "k-", lw=2, label="filtre de Kalman : P_k|k (exacte)")
    ax.plot(t, s.perturbed, color="tab:blue", lw=1.4, label="EnKF, observations perturbées")
    ax.plot(t, s.unperturbed, color="tab:red", lw=1.4, ls="--", label="EnKF sans perturbations")
    ax.set_xlabel("pas de temps k")
    ax.set_ylabel("variance de position (m²)")
    ax.set_ylim(0, None)
    ax.set_title("Dispersion de l'ensemble analysé (200 membres)", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return fig
