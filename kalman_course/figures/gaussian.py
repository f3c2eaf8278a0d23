"""Figures du chapitre « Un seul filtre gaussien : linéarisation, points sigma, cubature, Gauss–Hermite »."""

from __future__ import annotations

import numpy as np

from ..filters.cubature import CUBATURE
from ..filters.gauss_hermite import GaussHermiteRule
from ..filters.unscented import UnscentedRule
from ..numbers import format_number
from ..scenarios import banana, gaussian_rules
from ._geometry import draw_ellipse
from ._registry import new_figure, register

CHAPTER = "filtre-gaussien"

#: Couleur de chaque règle (mêmes couleurs dans les figures et les curseurs du chapitre).
COLORS = {
    "vérité": "black",
    "linéarisation (EKF)": "tab:red",
    "unscented (UKF)": "tab:blue",
    "cubature (CKF)": "tab:green",
    "Gauss–Hermite": "tab:purple",
    "Gauss–Hermite, p = 5": "tab:brown",
}

#: La loi gaussienne des points montrés : moyenne et covariance (corrélées).
POINTS_MEAN = np.array([0.0, 0.0])
POINTS_COV = np.array([[1.0, 0.6], [0.6, 0.8]])


def _color(name: str) -> str:
    return COLORS.get(name, COLORS["Gauss–Hermite"] if name.startswith("Gauss–Hermite, p = 3") else
                      COLORS.get(name.split(" (")[0], "tab:purple"))


@register("gaussien-points", chapter=CHAPTER,
          title="Les points de quatre règles d'intégration pour une même loi gaussienne (aire ∝ poids)")
def gaussian_points():
    panels = (
        ("unscented (α = 1, κ = 1) : 2n + 1 = 5 points", UnscentedRule(1.0, 2.0, 1.0), COLORS["unscented (UKF)"]),
        ("cubature : 2n = 4 points", CUBATURE, COLORS["cubature (CKF)"]),
        ("Gauss–Hermite p = 3 : 3² = 9 points", GaussHermiteRule(3), COLORS["Gauss–Hermite"]),
        ("Gauss–Hermite p = 5 : 5² = 25 points", GaussHermiteRule(5), COLORS["Gauss–Hermite, p = 5"]),
    )
    fig, axes = new_figure(2, 2, width=7.5, height=7.2, sharex=True, sharey=True)
    for ax, (title, rule, color) in zip(axes.ravel(), panels):
        pts = gaussian_rules.rule_points(rule, POINTS_MEAN, POINTS_COV)
        for k in (1.0, 2.0, 3.0):
            draw_ellipse(ax, POINTS_MEAN, POINTS_COV, k, color="0.6", lw=0.8, ls="--")
        area = 900.0 * np.abs(pts.Wm) / np.abs(pts.Wm).max()
        ax.scatter(pts.points[:, 0], pts.points[:, 1], s=area, color=color, alpha=0.8, edgecolor="k", lw=0.5)
        ax.set_title(title, fontsize=9)
        ax.set_aspect("equal")
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("x₁ (sans unité)")
    for ax in axes[:, 0]:
        ax.set_ylabel("x₂ (sans unité)")
    axes[0, 0].set_xlim(-4.2, 4.2)
    axes[0, 0].set_ylim(-4.2, 4.2)
    return fig


@register("gaussien-banane", chapter=CHAPTER,
          title="La banane par chaque règle : ellipses à 2σ et erreur de la moyenne selon σθ (pentes 2, 4, 6, 10)")
def gaussian_banana():
    moments = gaussian_rules.banana_rules()
    cloud = banana.banana_sample(3000)
    stds = np.logspace(np.log10(0.08), np.log10(0.6), 12)
    errors = gaussian_rules.banana_mean_errors(stds, orders=(3, 5))
    fig, (ax0, ax1) = new_figure(1, 2, width=11.0, height=4.6, gridspec_kw={"width_ratios": [1.25, 1]})
    ax0.plot(cloud[:, 0], cloud[:, 1], ".", ms=1.5, color="0.65", alpha=0.5, label="tirages de g(r, θ)")
    for name, mom in moments.items():
        color = _color(name)
        draw_ellipse(ax0, mom.mean, mom.cov, 2.0, color=color, lw=1.7, ls="--" if name == "vérité" else "-",
                     label=name)
        ax0.plot(*mom.mean, "o", color=color, ms=5)
    ax0.set_aspect("equal")
    ax0.set_xlim(-1.0, 1.0)
    ax0.set_ylim(0.35, 1.25)
    ax0.set_xlabel("x (m)")
    ax0.set_ylabel("y (m)")
    ax0.set_title(f"σθ = {format_number(np.rad2deg(banana.BANANA_BEARING_STD), decimals=0)}°, "
                  f"σᵣ = {format_number(100 * banana.BANANA_RANGE_STD, decimals=0)} cm : ellipses à 2σ", fontsize=10)
    ax0.grid(alpha=0.3)
    ax0.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2, fontsize=7)
    slopes = {"linéarisation (EKF)": 2, "unscented (UKF)": 6, "cubature (CKF)": 4,
              "Gauss–Hermite, p = 3 (GHKF)": 6, "Gauss–Hermite, p = 5 (GHKF)": 10}
    for name, err in errors.items():
        color = COLORS["Gauss–Hermite, p = 5"] if "p = 5" in name else _color(name)
        ls = ":" if name.startswith("unscented") else "-"
        ax1.loglog(np.rad2deg(stds), 1000 * err, "o" + ls, ms=3, color=color,
                   label=f"{name.replace(' (GHKF)', '')} : pente {slopes[name]}")
    ax1.set_xlabel("écart-type de l'azimut σθ (°)")
    ax1.set_ylabel("erreur de la moyenne (mm)")
    ax1.set_title("Erreur de la moyenne transformée", fontsize=10)
    ax1.grid(alpha=0.3, which="both")
    ax1.legend(fontsize=7, loc="lower right")
    return fig


@register("gaussien-cout", chapter=CHAPTER,
          title="Nombre de points par étape selon la dimension de l'état : 2n + 1, 2n et pⁿ")
def gaussian_cost():
    ns = np.arange(1, 11)
    counts = gaussian_rules.points_per_step(ns)
    fig, ax = new_figure(width=7.0, height=3.8)
    colors = [COLORS["unscented (UKF)"], COLORS["cubature (CKF)"], COLORS["Gauss–Hermite"],
              COLORS["Gauss–Hermite, p = 5"]]
    for (name, values), color in zip(counts.items(), colors):
        ax.semilogy(ns, values, "o-", ms=4, color=color, label=name)
    ax.axhline(1e5, color="k", lw=0.8, ls="--")
    ax.text(1.2, 1.4e5, "100 000 points : la limite du paquet", fontsize=8)
    ax.set_xlabel("dimension n de l'état (sans unité)")
    ax.set_ylabel("points par étape (sans unité)")
    ax.set_xticks(ns)
    ax.set_title("Coût d'une étape : nombre d'évaluations de f (et de h)", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8, loc="upper left")
    return fig
