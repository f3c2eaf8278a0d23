"""Figures du chapitre « Exemple — estimation d'une tension constante » (Welch & Bishop)."""

from __future__ import annotations

import numpy as np

from ..scenarios import TRUE_VOLTAGE
from ..scenarios.voltage import voltage_run
from ..numbers import format_spec as fr
from ._registry import new_figure, register

CHAPTER = "tension-constante"


def _voltage_panel(ax, R: float, title: str) -> None:
    z, result = voltage_run(R)
    n = np.arange(1, z.size + 1)
    ax.axhline(TRUE_VOLTAGE, color="tab:green", lw=1.5, label=f"valeur vraie x = {fr(TRUE_VOLTAGE, 'g')} V")
    ax.plot(n, z, "+", color="tab:red", ms=7, label="mesures $y_n$")
    ax.plot(n, result.x[:, 0], color="tab:blue", lw=1.8, label=r"estimation $\hat x_n$")
    ax.set_xlabel("itération n (sans unité)")
    ax.set_ylabel("tension (V)")
    ax.set_title(title)
    ax.legend(loc="lower right", fontsize=8)
    ax.grid(alpha=0.3)


@register("tension-estimation", chapter=CHAPTER, title="Valeur vraie, mesures et estimation (50 relevés)")
def voltage_estimation():
    fig, ax = new_figure()
    _voltage_panel(ax, R=0.01, title=r"$\Phi = 10^{-5}$ V², $\Psi = 0{,}01$ V², $P_0 = 1$ V²")
    return fig


@register("tension-covariance", chapter=CHAPTER, title="Convergence de la covariance de l'erreur Pₙ")
def voltage_covariance():
    _, result = voltage_run(R=0.01)
    n = np.arange(1, result.n_steps + 1)
    fig, ax = new_figure()
    ax.plot(n, result.P[:, 0, 0], color="tab:blue", lw=1.8, label=r"$P_n$ (a posteriori)")
    ax.set_xlabel("itération n (sans unité)")
    ax.set_ylabel(r"covariance $P_n$ (V²)")
    ax.set_yscale("log")
    ax.set_title(r"$\Psi = 0{,}01$ V² : $P_n$ décroît de $P_0 = 1$ V² vers son régime permanent")
    ax.grid(alpha=0.3, which="both")
    ax.legend(loc="upper right", fontsize=8)
    return fig


@register("tension-psi-grand", chapter=CHAPTER, title="Influence des bruits : Ψ = 1")
def voltage_large_psi():
    fig, ax = new_figure()
    _voltage_panel(ax, R=1.0, title=r"$\Psi = 1$ V² : le filtre se fie au modèle, réponse lente")
    return fig


@register("tension-psi-petit", chapter=CHAPTER, title="Influence des bruits : Ψ = 10⁻⁴")
def voltage_small_psi():
    fig, ax = new_figure()
    _voltage_panel(ax, R=1e-4, title=r"$\Psi = 10^{-4}$ V² : le filtre suit les mesures")
    return fig
