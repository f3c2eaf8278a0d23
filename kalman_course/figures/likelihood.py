"""Figures du chapitre « Apprendre Q et R : vraisemblance et données réelles » : le Nil à Assouan et le
niveau local (:mod:`kalman_course.scenarios.nile`)."""

from __future__ import annotations

import numpy as np

from ..datasets.nile import nile
from ..likelihood import log_likelihood
from ..numbers import format_number, matplotlib_formatter, matplotlib_log_formatter
from ..scenarios.nile import (
    NILE_DK_VARIANCES,
    diffuse_limit,
    level_drop,
    likelihood_surface,
    local_level_model,
    nile_diagnostics,
    nile_em,
    nile_fit,
    nile_smoothing,
)
from ._registry import new_figure, register
from .smoothing import FILTER_COLOR, SMOOTHER_COLOR, french_axes, log_axis

CHAPTER = "vraisemblance"
FLOW = "débit (10⁸ m³ par an)"

#: Valeurs de :math:`\kappa` de la figure de l'initialisation diffuse approchée.
KAPPAS = 10.0 ** np.arange(2, 18)


def _level_panel(ax, run, title: str, filtered: bool = True) -> None:
    years, y = run.data.year, run.data.flow
    for i, (start, stop) in enumerate(_runs(np.isnan(y))):
        ax.axvspan(years[start] - 0.5, years[stop - 1] + 0.5, color="0.88", zorder=0,
                   label="années retirées" if i == 0 else None)
    ax.plot(years, y, "o", ms=3, color="tab:red", label="débit mesuré")
    if filtered:
        ax.plot(years, run.filtered.x[:, 0], color=FILTER_COLOR, lw=1.2, label="niveau filtré")
    mean, sd = run.smoothed.x[:, 0], run.smoothed.std()[:, 0]
    ax.plot(years, mean, color=SMOOTHER_COLOR, lw=2.0, label="niveau lissé")
    ax.fill_between(years, mean - 2 * sd, mean + 2 * sd, color=SMOOTHER_COLOR, alpha=0.2, lw=0,
                    label="lissé ± 2σ")
    ax.set_xlabel("temps (année)")
    ax.set_ylabel(FLOW)
    ax.set_title(title)
    ax.xaxis.set_major_formatter(_year_formatter())
    ax.yaxis.set_major_formatter(matplotlib_formatter())
    ax.grid(alpha=0.3)


def decades(axis) -> None:
    """Graduations d'un axe logarithmique en puissances de dix (10⁶ ; aucune décimale à écrire)."""
    axis.set_major_formatter(matplotlib_log_formatter())


def _year_formatter():
    from matplotlib.ticker import FuncFormatter

    return FuncFormatter(lambda v, _pos=None: f"{v:.0f}")  # une année s'écrit sans séparateur de milliers


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Intervalles ``[début, fin)`` où ``mask`` est vrai."""
    out, start = [], None
    for k, flag in enumerate(mask):
        if flag and start is None:
            start = k
        elif not flag and start is not None:
            out.append((start, k))
            start = None
    if start is not None:
        out.append((start, len(mask)))
    return out


@register("vraisemblance-diffus", chapter=CHAPTER, title="Initialisation diffuse : l'a priori large et sa limite exacte")
def diffuse_start():
    model = local_level_model(*NILE_DK_VARIANCES)
    exact = log_likelihood(model, nile().flow)
    gap = np.abs(diffuse_limit(KAPPAS) - exact)
    fig, ax = new_figure(width=7.0, height=3.6)
    ax.loglog(KAPPAS, gap, "o-", color="tab:purple", ms=4,
              label=r"$|\log L_\kappa + \frac{1}{2}\log\kappa - \log L_d|$")
    ref = gap[4] * KAPPAS[4] / KAPPAS
    ax.loglog(KAPPAS, ref, "--", color="0.5", lw=1, label=r"pente $1/\kappa$")
    ax.set_xlabel(r"variance a priori $P_0 = \kappa$ (10¹⁶ m⁶)")
    ax.set_ylabel("écart à la vraisemblance diffuse exacte (nats)")
    ax.set_title(r"Filtre de Kalman avec $P_0 = \kappa$ : convergence puis arrondis")
    decades(ax.xaxis)
    decades(ax.yaxis)
    ax.grid(alpha=0.3, which="major")
    ax.legend(fontsize=8, loc="upper right")
    return fig


@register("vraisemblance-surface", chapter=CHAPTER, title="La log-vraisemblance du Nil et le chemin d'EM")
def likelihood_surface_figure():
    surf = likelihood_surface()
    fit = nile_fit()
    em = nile_em()
    fig, ax = new_figure(width=6.8, height=5.0)
    top = float(np.max(surf.log_likelihood))
    best = max(top, fit.log_likelihood)
    gaps = np.array([-1000.0, -200, -100, -50, -20, -10, -5, -2, -1, -0.5, 0.0])
    rel = np.maximum(surf.log_likelihood - best, gaps[0])
    from matplotlib.colors import BoundaryNorm

    norm = BoundaryNorm(gaps, ncolors=256)  # une couleur bien distincte par bande
    ax.contourf(surf.sigma2_eps, surf.sigma2_eta, rel, levels=gaps, cmap="viridis", norm=norm)
    lines = ax.contour(surf.sigma2_eps, surf.sigma2_eta, rel, levels=gaps[1:-1], colors="white", linewidths=0.6,
                       linestyles="solid")
    ax.clabel(lines, fmt=lambda v: format_number(v, significant=2), fontsize=7, colors="white")
    ax.plot(em.R[:, 0, 0], em.Q[:, 0, 0], ".-", color="tab:red", ms=3, lw=1.0, label="itérés d'EM")
    var = np.exp(fit.theta)
    ax.plot(*var, "*", color="black", ms=14, label="maximum de vraisemblance")
    ax.plot(*NILE_DK_VARIANCES, "x", color="tab:orange", ms=9, mew=2, label="Durbin & Koopman (2012)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(r"$R = \sigma^2_\varepsilon$ (10¹⁶ m⁶)")
    ax.set_ylabel(r"$Q = \sigma^2_\eta$ (10¹⁶ m⁶)")
    ax.set_title(r"Courbes de niveau de $\log L - \log L_{\max}$ (nats), initialisation diffuse exacte")
    decades(ax.xaxis)
    decades(ax.yaxis)
    ax.legend(fontsize=8, loc="lower left", framealpha=0.9)
    ax.grid(alpha=0.3, which="major")
    return fig


@register("vraisemblance-nil-lisse", chapter=CHAPTER, title="Le Nil : niveau filtré et lissé, baisse de 1899")
def nile_level():
    run = nile_smoothing(False)
    drop = level_drop(run)
    fig, ax = new_figure(width=7.5, height=4.0)
    _level_panel(ax, run, "Niveau local au maximum de vraisemblance (initialisation diffuse exacte)")
    year = drop["year"]
    at = float(run.smoothed.x[run.data.year == year, 0][0])
    ax.axvline(year, color="0.3", lw=1, ls="--")
    ax.annotate(f"{year:.0f} : le niveau lissé baisse\nde {format_number(drop['level_1894'], decimals=0)} (1894) "
                f"à {format_number(drop['level_1903'], decimals=0)} (1903)",
                xy=(year, at), xytext=(year + 8, 1270), fontsize=8,
                arrowprops={"arrowstyle": "->", "color": "0.3"})
    ax.legend(fontsize=8, loc="lower left", ncol=2)
    return fig


@register("vraisemblance-nil-manquantes", chapter=CHAPTER,
          title="Le Nil sans les années 1891–1910 et 1931–1950 : le lisseur les comble")
def nile_missing():
    run = nile_smoothing(True)
    full = nile_smoothing(False)
    fig, ax = new_figure(width=7.5, height=4.0)
    _level_panel(ax, run, "Données manquantes de Durbin & Koopman, variances réestimées")
    ax.plot(full.data.year[run.data.missing], full.data.flow[run.data.missing], "o", ms=3, mfc="none",
            color="tab:red", alpha=0.6, label="débits retirés (non utilisés)")
    ax.legend(fontsize=8, loc="lower left", ncol=2)
    return fig


@register("vraisemblance-residus", chapter=CHAPTER, title="Innovations normalisées du Nil et leurs autocorrélations")
def nile_residuals():
    diag = nile_diagnostics()
    fig, axes = new_figure(1, 2, width=9.0, height=3.4, gridspec_kw={"width_ratios": [1.8, 1]})
    ax = axes[0]
    ax.axhline(0.0, color="black", lw=0.8)
    for v in (-2.0, 2.0):
        ax.axhline(v, color="0.4", lw=0.8, ls="--")
    ax.plot(diag.years, diag.standardized, "o-", ms=3, lw=0.8, color="tab:blue")
    ax.set_xlabel("temps (année)")
    ax.set_ylabel(r"$\nu_k/\sqrt{S_k}$ (sans unité)")
    ax.set_title("Innovations normalisées (± 2 en tirets)")
    ax.xaxis.set_major_formatter(_year_formatter())
    ax.yaxis.set_major_formatter(matplotlib_formatter())
    ax.grid(alpha=0.3)
    ax = axes[1]
    w = diag.whiteness
    ax.bar(w.lags, w.autocorrelation[0], color="tab:blue", width=0.6)
    ax.axhline(w.band, color="0.4", ls="--", lw=0.8)
    ax.axhline(-w.band, color="0.4", ls="--", lw=0.8)
    ax.axhline(0.0, color="black", lw=0.8)
    ax.set_xlabel("décalage (années)")
    ax.set_ylabel("autocorrélation (sans unité)")
    ax.set_title("Autocorrélations, bande à 95 %")
    french_axes(ax)
    from matplotlib.ticker import MaxNLocator

    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    return fig


@register("vraisemblance-em", chapter=CHAPTER, title="EM : la vraisemblance monte à chaque itération")
def em_convergence():
    em = nile_em()
    fit = nile_fit()
    best = max(fit.log_likelihood, em.log_likelihood)
    it = np.arange(em.history.size)
    fig, axes = new_figure(1, 2, width=8.5, height=3.4)
    ax = axes[0]
    gap = best - em.history
    ax.semilogy(it[gap > 0], gap[gap > 0], color="tab:red", lw=1.5)
    ax.set_xlabel("itération d'EM")
    ax.set_ylabel(r"$\log L_{\max} - \log L_i$ (nats)")
    ax.set_title("Écart au maximum")
    ax.xaxis.set_major_formatter(matplotlib_formatter())
    decades(ax.yaxis)
    ax.grid(alpha=0.3, which="major")
    ax = axes[1]
    var = np.exp(fit.theta)
    ax.semilogy(it, em.R[:, 0, 0], color="tab:green", lw=1.5, label=r"$R = \sigma^2_\varepsilon$")
    ax.semilogy(it, em.Q[:, 0, 0], color="tab:purple", lw=1.5, label=r"$Q = \sigma^2_\eta$")
    for v in var:
        ax.axhline(v, color="0.3", lw=0.8, ls=":")
    ax.set_xlabel("itération d'EM")
    ax.set_ylabel("variance (10¹⁶ m⁶)")
    ax.set_title("Variances itérées (pointillés : MV)")
    ax.xaxis.set_major_formatter(matplotlib_formatter())
    log_axis(ax)
    ax.legend(fontsize=8)
    return fig


__all__ = ["diffuse_start", "likelihood_surface_figure", "nile_level", "nile_missing", "nile_residuals",
           "em_convergence", "KAPPAS"]
