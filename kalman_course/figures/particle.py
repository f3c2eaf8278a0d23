"""Figures du chapitre « Le filtre particulaire »."""

from __future__ import annotations

import numpy as np
import scipy.stats
from matplotlib.colors import PowerNorm

from ..filters.particle import RESAMPLING_SCHEMES
from ..numbers import format_number
from ..scenarios import growth
from ..scenarios.grid_bayes import bimodal_step, growth_grid_posteriors
from ..scenarios.convergence import particle_convergence
from ..scenarios.importance import degeneracy, importance_example
from ._registry import new_figure, register

CHAPTER = "filtre-particulaire"


@register("pf-grille", chapter=CHAPTER,
          title="Le filtre bayésien exact sur une grille : loi a posteriori à deux modes du modèle de croissance")
def pf_grid():
    data = growth.growth_data()
    post = growth_grid_posteriors()
    runs = growth.growth_filters(data)
    k = bimodal_step(post)
    fig, (ax, ad) = new_figure(2, 1, width=8.0, height=6.4, gridspec_kw={"height_ratios": [1.3, 1]})
    dx = post.grid[1] - post.grid[0]
    # échelle de couleur en puissance 0,4 : les modes secondaires, moins hauts, restent visibles
    ax.imshow(post.density.T, origin="lower", aspect="auto", cmap="Blues",
                      extent=(data.t[0] - 0.5, data.t[-1] + 0.5, post.grid[0] - dx / 2, post.grid[-1] + dx / 2),
                      norm=PowerNorm(gamma=0.4, vmin=0.0, vmax=float(post.density.max())))
    ax.plot(data.t, data.x_true[:, 0], "k.-", lw=0.8, ms=4, label="état vrai")
    ax.axvline(data.t[k], color="tab:red", lw=1.0, ls=":", label=f"pas {int(data.t[k])} (en bas)")
    ax.set_ylim(-26.0, 26.0)
    ax.set_xlabel("pas de temps k")
    ax.set_ylabel("état x (sans unité)")
    ax.set_title(r"Densité a posteriori exacte $p(x_k \mid y_{1:k})$ (plus foncé : plus probable)", fontsize=10)
    ax.legend(fontsize=7, loc="lower left")
    ad.plot(post.grid, post.density[k], color="tab:blue", lw=1.8, label="filtre bayésien sur grille (exact)")
    for name, color, ls in (("EKF", "tab:red", "--"), ("UKF", "tab:orange", "-.")):
        m, s = runs[name].x[k, 0], np.sqrt(runs[name].P[k, 0, 0])
        ad.plot(post.grid, scipy.stats.norm.pdf(post.grid, m, s), ls, color=color, lw=1.4,
                label=f"gaussienne de l'{name}")
    ad.axvline(data.x_true[k, 0], color="k", lw=1.5, label="état vrai")
    ad.set_xlim(-26.0, 26.0)
    ad.set_xlabel("état x (sans unité)")
    ad.set_ylabel("densité (sans unité)")
    ad.set_title(f"Au pas {int(data.t[k])} : deux modes, de part et d'autre de 0", fontsize=10)
    ad.legend(fontsize=7, loc="upper left")
    ad.grid(alpha=0.3)
    return fig


@register("pf-importance", chapter=CHAPTER,
          title="Échantillonnage d'importance : particules de l'a priori pondérées par la vraisemblance")
def pf_importance():
    ex = importance_example()
    grid = np.linspace(-3.0, 3.5, 400)
    prior = scipy.stats.norm.pdf(grid)
    like = scipy.stats.norm.pdf(ex.y, grid, ex.r_std)
    post = scipy.stats.norm.pdf(grid, ex.posterior_mean, np.sqrt(ex.posterior_var))
    fig, (ax, aw) = new_figure(2, 1, width=7.5, height=5.0, sharex=True)
    ax.plot(grid, prior, color="0.4", lw=1.5, label=r"a priori $p(x) = \mathcal{N}(0, 1)$")
    ax.plot(grid, like / like.max() * post.max() * 0.8, color="tab:orange", lw=1.5, ls="--",
            label=f"vraisemblance p(y | x), y = {format_number(ex.y, decimals=1)} (à l'échelle)")
    ax.plot(grid, post, color="tab:blue", lw=1.8, label="a posteriori exacte p(x | y)")
    ax.plot(ex.particles, np.zeros_like(ex.particles), "|", color="k", ms=14, label="particules xⁱ ~ p(x)")
    ax.set_ylabel("densité (1/unité de x)")
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(alpha=0.3)
    aw.vlines(ex.particles, 0, ex.weights, color="tab:blue", lw=2)
    aw.axvline(ex.estimate, color="tab:blue", ls=":", lw=1.2,
               label=f"Σ wⁱxⁱ = {format_number(ex.estimate, decimals=2)} (exacte : {format_number(ex.posterior_mean, decimals=2)})")
    aw.set_ylabel("poids wⁱ (sans unité)")
    aw.set_xlabel("état x (unité arbitraire)")
    aw.set_title(f"{len(ex.particles)} particules, taille effective ESS = {format_number(ex.ess, decimals=1)}",
                 fontsize=10)
    aw.legend(fontsize=8, loc="upper left")
    aw.grid(alpha=0.3)
    return fig


@register("pf-degenerescence", chapter=CHAPTER,
          title="Dégénérescence des poids : ESS/N sans et avec rééchantillonnage")
def pf_degeneracy():
    d = degeneracy()
    t = np.arange(1, d.without.size + 1)
    fig, ax = new_figure(width=7.5, height=3.6)
    ax.semilogy(t, d.without, "o-", ms=3, color="tab:red", label="sans rééchantillonnage (τ = 0)")
    ax.semilogy(t, d.with_, "o-", ms=3, color="tab:blue", label="avec rééchantillonnage quand ESS < N/2 (τ = 0,5)")
    ax.axhline(0.5, color="tab:blue", lw=0.8, ls=":")
    ax.axhline(1.0 / d.n_particles, color="k", lw=0.8, ls="--", label="une seule particule (ESS = 1)")
    ax.set_xlabel("pas de temps k")
    ax.set_ylabel("ESS / N (sans unité)")
    ax.set_title(f"{format_number(d.n_particles, decimals=0)} particules, banc d'essai linéaire", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8, loc="lower left")
    return fig


@register("pf-reechantillonnage", chapter=CHAPTER,
          title="Rééchantillonnage : positions tirées sur la fonction de répartition des poids")
def pf_resampling():
    rng = np.random.default_rng(2)
    w = rng.gamma(0.6, size=8)
    w /= w.sum()
    c = np.concatenate([[0.0], np.cumsum(w)])
    N = w.size
    fig, ax = new_figure(width=8.0, height=3.6)
    colors = [f"C{i}" for i in range(N)]
    rows = [("multinomial", rng.random(N)), ("stratified", rng.random(N)), ("systematic", rng.random())]
    names = {"multinomial": "multinomial", "stratified": "stratifié", "systematic": "systématique"}
    for row, (scheme, u) in enumerate(rows):
        y0 = len(rows) - row
        for i in range(N):
            ax.barh(y0, w[i], left=c[i], height=0.5, color=colors[i], alpha=0.35, edgecolor="white")
        positions = u if scheme == "multinomial" else (u + np.arange(N)) / N
        idx = RESAMPLING_SCHEMES[scheme].function(w, u)
        counts = np.bincount(idx, minlength=N)
        ax.plot(positions, np.full(N, y0), "v", color="k", ms=6)
        ax.text(1.02, y0, "copies : " + " ".join(str(k) for k in counts), va="center", fontsize=8)
    for k in range(N + 1):
        ax.axvline(k / N, color="0.7", lw=0.6, ls=":")
    ax.set_yticks([3, 2, 1], [names[r[0]] for r in rows])
    ax.set_xlim(0, 1.35)
    ax.set_xticks(np.linspace(0, 1, 5))
    ax.set_xlabel("somme cumulée des poids ; ▼ : positions ; pointillés : strates k/N (sans unité)")
    ax.set_ylabel("schéma (sans unité)")
    ax.set_title(f"{N} particules : la particule i est copiée autant de fois que de positions tombent dans son segment",
                 fontsize=9)
    return fig


@register("pf-croissance", chapter=CHAPTER,
          title="Modèle de croissance (Gordon–Salmond–Smith) : nuage de particules, EKF et UKF")
def pf_growth():
    data = growth.growth_data()
    runs = growth.growth_filters(data, keep_particles=True)
    pf = runs["filtre particulaire"]
    fig, (ax, ah) = new_figure(2, 1, width=8.0, height=6.2, gridspec_kw={"height_ratios": [2, 1]})
    T, N = pf.particles.shape[:2]
    sel = np.random.default_rng(0).choice(N, 300, replace=False)
    for k in range(T):
        ax.scatter(np.full(sel.size, data.t[k]), pf.particles[k, sel, 0], s=4, color="tab:blue",
                   alpha=np.clip(pf.weights[k, sel] * N * 0.15, 0.02, 0.6), linewidths=0)
    ax.plot(data.t, data.x_true[:, 0], "k-", lw=1.5, label="état vrai")
    rmse = {name: np.sqrt(np.mean((r.x[:, 0] - data.x_true[:, 0]) ** 2)) for name, r in runs.items()}
    for name, color, ls in (("EKF", "tab:red", "--"), ("UKF", "tab:orange", "-."), ("filtre particulaire", "tab:blue", "-")):
        ax.plot(data.t, runs[name].x[:, 0], ls, color=color, lw=1.3,
                label=f"{name} (REQM {format_number(rmse[name], decimals=1)})")
    ax.set_ylabel("état x (sans unité)")
    ax.set_xlabel("pas de temps k")
    ax.legend(fontsize=7, loc="lower left", ncol=2)
    ax.grid(alpha=0.3)
    ax.set_title("Particules (points bleus, opacité ∝ poids) : souvent deux groupes, en ±x", fontsize=10)
    k = _bimodal_step(pf)
    X, w = pf.particles[k, :, 0], pf.weights[k]
    ah.hist(X, bins=60, weights=w, color="tab:blue", alpha=0.6, label=f"particules pondérées au pas {k + 1}")
    ah.axvline(data.x_true[k, 0], color="k", lw=1.5, label="état vrai")
    ah.axvline(runs["UKF"].x[k, 0], color="tab:orange", ls="-.", label="UKF")
    ah.axvline(runs["EKF"].x[k, 0], color="tab:red", ls="--", label="EKF")
    ah.axvline(pf.x[k, 0], color="tab:blue", ls=":", label="moyenne des particules")
    ah.set_xlabel("état x (sans unité)")
    ah.set_ylabel("poids (sans unité)")
    ah.legend(fontsize=7)
    ah.grid(alpha=0.3)
    return fig


def _bimodal_step(pf) -> int:
    """Le pas où le poids est le mieux partagé entre x < 0 et x > 0."""
    X, w = pf.particles[:, :, 0], pf.weights
    balance = np.minimum((w * (X > 0)).sum(axis=1), (w * (X < 0)).sum(axis=1))
    return int(np.argmax(balance))


@register("pf-convergence", chapter=CHAPTER,
          title="Convergence du filtre particulaire vers le filtre de Kalman : erreur en 1/√N")
def pf_convergence():
    conv = particle_convergence()
    N = conv.sizes
    fig, ax = new_figure(width=7.0, height=3.8)
    ax.loglog(N, conv.mean_error, "o-", color="tab:blue",
              label=r"moyenne : $\|\hat x - \hat x_{\mathrm{KF}}\|$" + f" (pente {format_number(conv.mean_slope, decimals=2)})")
    ax.loglog(N, conv.cov_error, "s-", color="tab:orange",
              label=r"covariance : $\|P - P_{\mathrm{KF}}\|$" + f" (pente {format_number(conv.cov_slope, decimals=2)})")
    ax.loglog(N, conv.loglik_error, "^-", color="tab:green", label="log-vraisemblance (nats)")
    ax.loglog(N, conv.mean_error[0] * np.sqrt(N[0] / N), "k:", label="pente −1/2")
    ax.set_xlabel("nombre de particules N (sans unité)")
    ax.set_ylabel("écart quadratique moyen (unités de l'état)")
    ax.set_title(f"Banc d'essai linéaire, {conv.n_runs} graines par N", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    return fig

