"""Figures des travaux dirigés : les calculs à la main, dessinés avec les valeurs du paquet."""

from __future__ import annotations

import numpy as np
import scipy.stats

from ..scenarios.tutorials import (
    FOUR_U,
    FOUR_WEIGHTS,
    THERMOMETER,
    THREE_STEPS,
    four_particles,
    square_transform,
    thermometer_update,
    three_step_smoothing,
)
from ..numbers import format_number
from ._registry import new_figure, register


def _fr(x: float) -> str:
    return format_number(x, significant=3, trim=True)


@register("td-gaussiennes", chapter="td-filtre-lineaire",
          title="TD 1 : a priori, mesure et a posteriori du thermomètre")
def thermometer_figure():
    c = THERMOMETER
    post = thermometer_update()
    x = np.linspace(13.0, 28.0, 600)
    fig, ax = new_figure(width=7.0, height=3.4)
    for mean, var, color, name in (
        (c["x_prior"], c["P_prior"], "tab:blue", "a priori"),
        (c["y"], c["R"], "tab:red", "mesure"),
        (float(post.x[0]), float(post.P[0, 0]), "tab:purple", "a posteriori"),
    ):
        label = f"{name} N({_fr(mean)} ; {_fr(var)})"
        ax.plot(x, scipy.stats.norm(mean, np.sqrt(var)).pdf(x), color=color, lw=2.0, label=label)
        ax.axvline(mean, color=color, lw=0.8, ls=":")
    ax.set_xlabel("température (°C)")
    ax.set_ylabel("densité (1/°C)")
    ax.set_title("Le produit des deux gaussiennes, renormalisé : moyenne pondérée, variance plus petite",
                 fontsize=10)
    ax.legend(loc="upper left", fontsize=8)
    ax.grid(alpha=0.3)
    return fig


@register("td-transformee-carre", chapter="td-filtres-a-points",
          title="TD 2 : les trois points sigma de N(0, 1) et leurs images par x²")
def square_transform_figure():
    s = square_transform()
    x = np.linspace(-2.5, 2.5, 400)
    fig, ax = new_figure(width=7.0, height=3.6)
    ax.plot(x, x**2, color="0.3", lw=1.5, label="f(x) = x²")
    ax.plot(s.points, s.images, "o", color="tab:orange", ms=8, label="points sigma et leurs images")
    for p, img, w in zip(s.points, s.images, s.Wm):
        ax.vlines(p, 0.0, img, color="tab:orange", lw=0.8, ls=":")
        ax.annotate(f"poids {'2/3' if w > 0.5 else '1/6'}", (p, img), textcoords="offset points", xytext=(6, 6),
                    fontsize=8)
    ax.axhline(s.mean, color="tab:blue", lw=1.5, label="moyenne unscented (= 1, exacte)")
    ax.axhline(s.linearised_mean, color="tab:red", lw=1.5, ls="--", label="moyenne linéarisée f(0) = 0")
    ax.set_xlabel("x (sans unité)")
    ax.set_ylabel("f(x) = x² (sans unité)")
    ax.legend(loc="upper center", fontsize=8)
    ax.grid(alpha=0.3)
    return fig


@register("td-reechantillonnage", chapter="td-filtres-a-points",
          title="TD 2 : rééchantillonnage systématique de quatre particules")
def four_particles_figure():
    w = np.asarray(FOUR_WEIGHTS)
    N = w.size
    c = np.concatenate([[0.0], np.cumsum(w)])
    positions = (FOUR_U + np.arange(N)) / N
    chosen = four_particles()
    fig, ax = new_figure(width=7.0, height=3.6)
    for i in range(N):
        ax.fill_between([0, 1], c[i], c[i + 1], color=f"C{i}", alpha=0.25, lw=0)
        ax.text(0.03, (c[i] + c[i + 1]) / 2, f"particule {i + 1} (poids {_fr(w[i])})",
                va="center", fontsize=8)
    for p, j in zip(positions, chosen):
        ax.plot([0.55, 0.95], [p, p], color="k", lw=1.2)
        ax.plot(0.95, p, "o", color=f"C{j}", ms=7)
        ax.text(0.97, p, f"→ {j + 1}", va="center", fontsize=8)
    ax.set_xlim(0, 1.1)
    ax.set_ylim(0, 1)
    ax.set_xticks([])
    ax.set_ylabel("poids cumulé (sans unité)")
    ax.set_xlabel(f"positions (u + i)/N, u = {_fr(FOUR_U)} (sans unité)")
    ax.set_title("Chaque position tombe dans la bande d'une particule : celle-ci est copiée", fontsize=10)
    return fig


@register("td-lissage-trois-pas", chapter="td-lissage-em",
          title="TD 3 : trois pas de filtre et de lisseur RTS sur une marche aléatoire")
def three_steps_figure():
    r = three_step_smoothing()
    k = np.arange(1, 4)
    fig, ax = new_figure(width=7.0, height=3.6)
    ax.plot(k, THREE_STEPS["y"], "s", color="0.35", ms=7, label="mesures $y_k$")
    ax.errorbar(k - 0.04, r.x, yerr=2 * np.sqrt(r.P), fmt="o-", color="tab:blue", capsize=4,
                label=r"filtre $\hat x_{k|k}$ ± 2σ")
    ax.errorbar(k + 0.04, r.xs, yerr=2 * np.sqrt(r.Ps), fmt="o-", color="tab:orange", capsize=4,
                label=r"lisseur $\hat x_{k|3}$ ± 2σ")
    ax.set_xticks(k)
    ax.set_xlabel("pas de temps k")
    ax.set_ylabel("état x (unité arbitraire)")
    ax.set_title("Le lisseur tire les estimations passées vers les mesures futures", fontsize=10)
    ax.legend(loc="lower right", fontsize=8)
    ax.grid(alpha=0.3)
    return fig
