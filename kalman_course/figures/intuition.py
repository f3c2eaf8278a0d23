"""Figures du chapitre « Le filtre de Kalman en images » (le chariot sur un rail, une dimension)."""

from __future__ import annotations

import numpy as np

from ..numbers import format_number
from ..scenarios import intuition as sc
from ._registry import new_figure, register

CHAPTER = "intuition"


def _fr(value: float, unit: str) -> str:
    """Nombre français à trois chiffres significatifs, sans zéros finals (« 0,8 m² », « 12,4 m »)."""
    return format_number(value, significant=3, trim=True, unit=unit or None)


@register("intuition-gaussiennes", chapter=CHAPTER,
          title="A priori × vraisemblance de la mesure = loi a posteriori (produit de deux gaussiennes)")
def product_figure():
    out = sc.product_experiment()
    x = out["x"]
    fig, ax = new_figure(width=7.5, height=3.8)
    ax.fill_between(x, out["prior"], color="tab:orange", alpha=0.25, lw=0)
    ax.plot(x, out["prior"], color="tab:orange", lw=1.6,
            label=rf"a priori $\mathcal{{N}}(\hat x^-, P^-)$ : ${sc.PRIOR_MEAN:g}$ m, ${sc.PRIOR_VAR:g}$ m²")
    ax.fill_between(x, out["likelihood"], color="tab:green", alpha=0.25, lw=0)
    ax.plot(x, out["likelihood"], color="tab:green", lw=1.6,
            label=rf"mesure $\mathcal{{N}}(y ; x, R)$ : $y = {sc.MEASUREMENT:g}$ m, $R = {sc.MEASUREMENT_VAR:g}$ m²")
    ax.plot(x, out["posterior"], color="tab:blue", lw=2.0, label=r"a posteriori $\mathcal{N}(\hat x, P)$ du paquet")
    ax.plot(x[::10], out["product"][::10], "o", ms=3.5, color="black", label="produit normalisé (calcul point par point)")
    for value, color in ((sc.PRIOR_MEAN, "tab:orange"), (sc.MEASUREMENT, "tab:green"), (out["x_post"][0], "tab:blue")):
        ax.axvline(value, color=color, lw=0.9, ls="--")
    K = out["K"][0]
    ax.set_title(f"K = P⁻/(P⁻ + R) = {_fr(K, '')} : x̂ = {_fr(out['x_post'][0], 'm')}, "
                 f"P = {_fr(out['P_post'][0], 'm²')}", fontsize=10)
    ax.set_xlim(2.0, 20.0)
    ax.set_xlabel("position du chariot x (m)")
    ax.set_ylabel("densité de probabilité (1/m)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7.5, loc="upper right")
    return fig


@register("intuition-boucle", chapter=CHAPTER,
          title="Le chariot, mesure après mesure : la prédiction élargit la gaussienne, la correction la resserre")
def cycle_figure():
    cycle = sc.cart_cycle()
    x = np.linspace(-3.0, 9.0, 601)
    fig, (ax, ab) = new_figure(2, 1, width=7.5, height=6.4)
    ax.plot(x, sc.gaussian_density(x, cycle.mean[0], cycle.var[0]), color="0.5", lw=1.4, label=r"départ $(\hat x_0, P_0)$")
    ax.plot(x, sc.gaussian_density(x, cycle.mean[1], cycle.var[1]), color="tab:orange", lw=1.6, ls="--",
            label=r"prédiction $(\hat x^-_1, P^-_1)$ : décalée de $v\,\Delta t$, élargie de $Q$")
    ax.plot(x, sc.gaussian_density(x, cycle.y[0], sc.CART_R), color="tab:green", lw=1.4,
            label=r"mesure $y_1$ (vraisemblance, variance $R$)")
    ax.fill_between(x, sc.gaussian_density(x, cycle.mean[2], cycle.var[2]), color="tab:blue", alpha=0.25, lw=0)
    ax.plot(x, sc.gaussian_density(x, cycle.mean[2], cycle.var[2]), color="tab:blue", lw=2.0,
            label=r"correction $(\hat x_1, P_1)$ : resserrée")
    ax.axvline(cycle.truth[0], color="black", lw=1.0, ls=":", label="position vraie $x_1$")
    ax.set_xlabel("position du chariot x (m)")
    ax.set_ylabel("densité de probabilité (1/m)")
    ax.set_title("Premier pas de la boucle", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7.5, loc="upper right")
    stages = np.arange(cycle.var.size)
    ab.plot(stages, np.sqrt(cycle.var), "-o", ms=4, color="tab:blue")
    ab.plot(stages[1::2], np.sqrt(cycle.var[1::2]), "o", ms=7, mfc="none", color="tab:orange", label="prédiction")
    ab.plot(stages[2::2], np.sqrt(cycle.var[2::2]), "o", ms=7, mfc="none", color="tab:green", label="correction")
    ab.set_xlabel("étape de la boucle (0 = départ ; impaire = prédiction ; paire = correction) (sans unité)")
    ab.set_ylabel(r"écart-type $\sqrt{P}$ (m)")
    ab.set_title(f"Les dents de scie de la variance ; régime permanent P = {_fr(cycle.var[-1], 'm²')}", fontsize=10)
    ab.grid(alpha=0.3)
    ab.legend(fontsize=8)
    return fig
