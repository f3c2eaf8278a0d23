"""Figures du chapitre « Filtre de Kalman étendu itéré »."""

from __future__ import annotations

import numpy as np

from ..scenarios.radar import radar_cost_grid, radar_iterations
from ._geometry import draw_ellipse
from ._registry import new_figure, register

CHAPTER = "ekf-itere"


@register("ekf-itere-iterations", chapter=CHAPTER,
          title="Radar précis, a priori médiocre : itérés de Gauss–Newton et coût MAP")
def iekf_iterations():
    it = radar_iterations()
    p = it.problem
    fig, (ax, ac) = new_figure(1, 2, width=9.5, height=5.4, gridspec_kw={"width_ratios": [1.2, 1]})

    # plan : courbes de niveau du coût J(x), sur une grille de 4 cm (100 × 100 évaluations du coût, en lot)
    xs, ys, J = radar_cost_grid(p)
    levels = [1, 3, 10, 30, 100, 300, 1000, 3000]
    cs = ax.contour(xs, ys, J, levels=levels, cmap="viridis_r", linewidths=0.9)
    ax.clabel(cs, fontsize=6, fmt="%g")
    draw_ellipse(ax, p.x_pred, p.P_pred, 1.0, color="tab:orange", lw=1.2, ls="--",
                 label=r"a priori $\hat x^-$, $1\sigma$ (3 m)")
    ax.plot(*p.x_pred, "o", color="tab:orange", ms=7)
    gn = it.iterates
    ax.plot(gn[:, 0], gn[:, 1], "-o", color="tab:blue", ms=4, lw=1.2, label="Gauss–Newton $x^{(i)}$")
    for i in (1, 2):
        ax.annotate(f"$x^{{({i})}}$", gn[i], xytext=(gn[i][0] + 0.12, gn[i][1] - 0.25), color="tab:blue")
    ax.plot(*it.ekf, "s", color="tab:red", ms=7, mfc="none", mew=1.5, label=r"EKF $= x^{(1)}$")
    tl = it.table_literal
    ax.plot(tl[:, 0], tl[:, 1], ":", color="tab:purple", lw=1.2)
    ax.plot(*tl[-1], "D", color="tab:purple", ms=6, label="tableau des notes (limite)")
    ax.plot(*it.map, "*", color="k", ms=11, label="MAP (optimiseur indépendant)")
    ax.plot(*p.truth, "x", color="tab:green", ms=9, mew=2, label="cible vraie")
    ax.set_xlim(xs[0], xs[-1])
    ax.set_ylim(ys[0], ys[-1])
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("Courbes de niveau du coût $J(x)$", fontsize=10)
    ax.legend(loc="upper center", fontsize=7, ncol=2, bbox_to_anchor=(0.5, -0.14))

    # convergence : distance au MAP par itération
    i_gn = np.arange(it.iterates.shape[0])
    d_gn = np.maximum(it.distance_to_map, 1e-16)
    d_tl = np.linalg.norm(tl - it.map, axis=1)
    n_show = min(tl.shape[0], 16)
    ac.semilogy(i_gn, d_gn, "-o", color="tab:blue", ms=4, label="Gauss–Newton (forme correcte)")
    ac.semilogy(np.arange(n_show), d_tl[:n_show], "-D", color="tab:purple", ms=3,
                label="tableau des notes (gain seul relinéarisé)")
    ac.axhline(1e-10, color="0.5", lw=0.8, ls=":", label=r"seuil d'arrêt $10^{-10}$ m")
    ac.set_xlabel("itération i")
    ac.set_ylabel(r"distance au MAP $\|x^{(i)} - x_{\mathrm{MAP}}\|$ (m)")
    ac.set_title("Convergence", fontsize=10)
    ac.grid(alpha=0.3, which="both")
    ac.legend(loc="upper center", fontsize=7, bbox_to_anchor=(0.5, -0.14))
    return fig
