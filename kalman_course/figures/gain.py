"""Figures des chapitres « Le filtre prédicteur–correcteur » et « Gain optimal » : le gain de Kalman."""

from __future__ import annotations

import numpy as np
import scipy.linalg
import scipy.stats

from ..scenarios import TRUE_VOLTAGE
from ..scenarios.engine import ENGINE_DT, LIMIT_SCALES, engine_model, gain_limit_run, gain_limit_sweep
from ..scenarios.gain_trace import engine_trace_ratios, gain_trace
from ..scenarios.voltage import posterior_coverage, printed_recipe_comparison
from ._registry import new_figure, register

CHAPTER_LOOP = "predicteur-correcteur"
CHAPTER_OPTIMAL = "gain-optimal"


@register("gain-limites", chapter=CHAPTER_LOOP, title="Limites du gain : K → 0 et K → C⁻¹")
def gain_limits_figure():
    fig, (ax_run, ax_sweep) = new_figure(2, 1, width=7.0, height=7.0)
    sim, nominal = gain_limit_run(1.0)
    t = ENGINE_DT * np.arange(1, sim.y.shape[0] + 1)
    x_from_y = scipy.linalg.solve(engine_model().C, sim.y.T).T
    ax_run.plot(t, x_from_y[:, 0], ".", ms=3, color="0.55", label=r"mesure inversée $(C^{-1}y_n)_1$")
    ax_run.plot(t, sim.x[:, 0], color="black", lw=1.2, label=r"valeur vraie $\theta_m$")
    large, small = (gain_limit_run(s)[1] for s in LIMIT_SCALES)
    ax_run.plot(t, large.x[:, 0], color="tab:orange", lw=1.8, label=r"filtre avec $10^{6}\,\Psi$ : $K \to 0$")
    ax_run.plot(t, small.x[:, 0], color="tab:green", lw=1.0, label=r"filtre avec $10^{-6}\,\Psi$ : $K \to C^{-1}$")
    ax_run.plot(t, nominal.x[:, 0], color="tab:blue", lw=1.6, label=r"filtre avec le vrai $\Psi$")
    ax_run.set_xlabel("temps (s)")
    ax_run.set_ylabel(r"échauffement du moteur $\theta_m$ (°C)")
    ax_run.set_title("Confiance au modèle (orange) ou aux mesures (vert)")
    ax_run.legend(fontsize=7, loc="lower right")
    ax_run.grid(alpha=0.3)

    scales, to_zero, to_inverse = gain_limit_sweep()
    ax_sweep.loglog(scales, to_zero, "o-", ms=3, color="tab:orange", label=r"$\|K_T\| / \|C^{-1}\|$")
    ax_sweep.loglog(scales, to_inverse, "s-", ms=3, color="tab:green", label=r"$\|K_T - C^{-1}\| / \|C^{-1}\|$")
    ax_sweep.axvline(1.0, color="tab:blue", lw=1.0, ls="--", label=r"vrai $\Psi$ ($s = 1$)")
    ax_sweep.set_xlabel(r"facteur $s$ appliqué à $\Psi$ dans le filtre (sans unité)")
    ax_sweep.set_ylabel("écart relatif (sans unité)")
    ax_sweep.set_title(r"Gain final $K_T$ ($T = 120$) quand $\Psi \to s\,\Psi$")
    ax_sweep.legend(fontsize=8, loc="center right")
    ax_sweep.grid(alpha=0.3, which="both")
    return fig


@register("recette-gain-imprime", chapter=CHAPTER_LOOP, title="La recette imprimée (Ψ au lieu de Φ) contre la recette corrigée")
def printed_recipe_figure():
    z, good, bad = printed_recipe_comparison()
    n = np.arange(1, z.size + 1)
    fig, (ax_k, ax_x) = new_figure(2, 1, width=7.0, height=6.0, sharex=True)
    ax_k.plot(n, good.K[:, 0, 0], "o-", ms=3, color="tab:blue", label=r"gain corrigé $P^-(P^-+\Psi)^{-1}$")
    ax_k.plot(n, bad.K[:, 0, 0], "s-", ms=3, color="tab:red", label=r"gain imprimé $(P+\Psi)(P+2\Psi)^{-1}$")
    ax_k.set_ylabel("gain $K_n$ (sans unité)")
    ax_k.set_title(r"Tension constante : $\Phi = 10^{-5}$ V², $\Psi = 0{,}01$ V², $P_0 = 1$ V²")
    ax_k.legend(fontsize=8)
    ax_k.grid(alpha=0.3)
    ax_x.axhline(TRUE_VOLTAGE, color="tab:green", lw=1.4, label="valeur vraie")
    ax_x.plot(n, z, "+", color="0.4", ms=6, label="mesures $y_n$")
    ax_x.plot(n, good.x[:, 0], color="tab:blue", lw=1.8, label="estimation, gain corrigé")
    ax_x.plot(n, bad.x[:, 0], color="tab:red", lw=1.2, label="estimation, gain imprimé")
    ax_x.set_xlabel("itération n (sans unité)")
    ax_x.set_ylabel("tension (V)")
    ax_x.legend(fontsize=8, loc="lower right", ncol=2)
    ax_x.grid(alpha=0.3)
    return fig


@register("gain-trace-minimale", chapter=CHAPTER_OPTIMAL, title="Le gain de Kalman minimise la trace de P")
def trace_figure():
    fig, (ax1, ax2) = new_figure(1, 2, width=7.5, height=3.6)
    Ks = np.linspace(0.0, 0.4, 201)
    P_of_K = [gain_trace(10, k).P for k in Ks]  # tension constante, pas n = 10
    optimum = gain_trace(10, 0.0)
    ax1.plot(Ks, 1e3 * np.array(P_of_K), color="tab:blue", lw=1.8, label=r"$(1-K)^2P^-_{10} + K^2\Psi$")
    ax1.plot([optimum.K_star], [1e3 * optimum.P_star], "o", color="tab:red", label=r"gain de Kalman $K_{10}$")
    ax1.set_xlabel("gain K (sans unité)")
    ax1.set_ylabel(r"$P_{10}(K)$ ($10^{-3}$ V²)")
    ax1.set_title(r"Tension constante, pas $n = 10$", fontsize=10)
    ax1.legend(fontsize=8)
    ax1.grid(alpha=0.3)
    t, ratios = engine_trace_ratios()
    for r in ratios:
        ax2.plot(t, r, lw=1.2)
    ax2.plot([0.0], [1.0], "o", color="tab:red", label=r"$K^\star$ (Kalman)")
    ax2.set_xlabel(r"pas $t$ dans la direction $D$ (sans unité)")
    ax2.set_ylabel(r"$\mathrm{tr}\,P(K^\star + tD)\,/\,\mathrm{tr}\,P(K^\star)$ (sans unité)")
    ax2.set_title("Moteur (2 × 2), 6 directions au hasard", fontsize=10)
    ax2.legend(fontsize=8, loc="upper center")
    ax2.grid(alpha=0.3)
    return fig


@register("gain-loi-a-posteriori", chapter=CHAPTER_OPTIMAL, title="La loi a posteriori N(x̂ₙ, Pₙ) vérifiée par Monte-Carlo")
def posterior_figure():
    post = posterior_coverage()
    mc, z = post.monte_carlo, post.normalised  # (R, T)
    fig, (ax1, ax2) = new_figure(1, 2, width=7.5, height=3.6)
    ax1.hist(z[:, -1], bins=40, density=True, color="tab:blue", alpha=0.6, label=f"{mc.n_runs} tirages")
    grid = np.linspace(-4, 4, 201)
    ax1.plot(grid, scipy.stats.norm.pdf(grid), color="tab:red", lw=1.8, label=r"$\mathcal{N}(0, 1)$")
    ax1.set_xlabel(r"$(x_{50} - \hat x_{50}) / \sqrt{P_{50}}$ (sans unité)")
    ax1.set_ylabel("densité (sans unité)")
    ax1.set_title("Erreur normalisée après 50 relevés")
    ax1.legend(fontsize=8)
    ax1.grid(alpha=0.3)
    coverage = 100 * post.coverage
    n = np.arange(1, z.shape[1] + 1)
    band = 100 * 1.96 * np.sqrt(0.95 * 0.05 / mc.n_runs)
    ax2.fill_between(n, 95 - band, 95 + band, color="tab:red", alpha=0.15, label="95 % ± 2 écarts-types de MC")
    ax2.plot(n, coverage, "o-", ms=3, color="tab:blue", label=r"$|x_n - \hat x_n| \leq 1{,}96\sqrt{P_n}$")
    ax2.set_ylim(85, 100)
    ax2.set_xlabel("itération n (sans unité)")
    ax2.set_ylabel("taux de couverture (%)")
    ax2.set_title("Intervalle à 95 % de la loi a posteriori")
    ax2.legend(fontsize=8, loc="lower right")
    ax2.grid(alpha=0.3)
    return fig
