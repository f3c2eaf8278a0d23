"""Figures du chapitre « Le filtre de Kalman *unscented* (UKF) »."""

from __future__ import annotations

import numpy as np

from ..diagnostics.consistency import chi2_band
from ..filters.unscented import sigma_weights
from ..numbers import format_number
from ..scenarios import banana
from ..scenarios.distant_target import distant_target_comparison
from ..scenarios.tag import TAG_TRANSIENT_STEPS, tag_comparison
from ._geometry import draw_ellipse
from ._registry import new_figure, register

CHAPTER = "ukf"

COLORS = {"truth": "k", "linearized": "tab:red", "unscented": "tab:blue"}


@register("ukf-banane", chapter=CHAPTER,
          title="La « banane » : loi polaire vue en cartésien — vérité, linéarisation, transformée unscented")
def ukf_banana():
    comp = banana.banana_comparison()
    polar = banana.banana_polar_sample(3000)
    cloud = banana.polar_to_cartesian(polar)
    r0, th0 = banana.BANANA_RANGE, banana.BANANA_BEARING
    sr, st = banana.BANANA_RANGE_STD, banana.BANANA_BEARING_STD

    fig, (ax0, ax1) = new_figure(1, 2, width=10.0, height=5.4, gridspec_kw={"width_ratios": [1, 1.6]})
    ax0.plot(polar[:, 0], np.rad2deg(polar[:, 1]), ".", ms=1.5, color="0.6", alpha=0.5)
    draw_ellipse(ax0, [r0, np.rad2deg(th0)], np.diag([sr, np.rad2deg(st)]) ** 2, 2.0, color="k", lw=1.5)
    pts = comp.sigma_points
    ax0.plot(pts[:, 0], np.rad2deg(pts[:, 1]), "D", color=COLORS["unscented"], ms=7, label="points sigma χᵢ")
    ax0.set_xlabel("distance r (m)")
    ax0.set_ylabel("azimut θ (°)")
    ax0.set_title("Avant : gaussienne en (r, θ)", fontsize=10)
    ax0.grid(alpha=0.3)
    ax0.legend(loc="upper left", fontsize=8)

    ax1.plot(cloud[:, 0], cloud[:, 1], ".", ms=1.5, color="0.6", alpha=0.5, label="tirages transformés g(r, θ)")
    e_lin, e_ut = comp.mean_errors()
    for key, mom, label in (
        ("truth", comp.truth, "vérité (forme close)"),
        ("linearized", comp.linearized, f"linéarisation (EKF) : moyenne à {format_number(100 * e_lin, decimals=1)} cm"),
        ("unscented", comp.unscented, f"transformée unscented (UKF) : moyenne à {format_number(1000 * e_ut, significant=2)} mm"),
    ):
        draw_ellipse(ax1, mom.mean, mom.cov, 2.0, color=COLORS[key], lw=1.8, ls="--" if key == "truth" else "-",
                     label=f"{label} (2σ)")
        ax1.plot(*mom.mean, "o", color=COLORS[key], ms=6)
    ax1.plot(comp.sigma_images[:, 0], comp.sigma_images[:, 1], "D", color=COLORS["unscented"], ms=7,
             label="images g(χᵢ) des points sigma")
    ax1.set_aspect("equal")
    ax1.set_xlim(-1.0, 1.0)
    ax1.set_ylim(0.4, 1.25)
    ax1.set_xlabel("x (m)")
    ax1.set_ylabel("y (m)")
    ax1.set_title("Après : g(r, θ) = (r cos θ, r sin θ)", fontsize=10)
    ax1.grid(alpha=0.3)
    ax1.legend(loc="upper center", bbox_to_anchor=(0.5, -0.18), ncol=2, fontsize=7)
    return fig


@register("ukf-poids", chapter=CHAPTER, title="Poids W₀ des points sigma en fonction de α : souvent négatifs")
def ukf_weights():
    alphas = np.logspace(-2, 0.5, 200)
    fig, ax = new_figure(width=7.0, height=3.6)
    for n, kappa, color, label in (
        (2, 0.0, "k", "κ = 0 : W₀ᵐ = 1 − 1/α², quelle que soit n"),
        (2, 1.0, "tab:blue", "n = 2, κ = 3 − n = 1"),
        (4, -1.0, "tab:orange", "n = 4, κ = 3 − n = −1"),
    ):
        w0 = [sigma_weights(n, alpha=a, beta=2.0, kappa=kappa)[0][0] for a in alphas]
        ax.plot(alphas, w0, "-" if kappa == 0 else "--", color=color, lw=1.6, label=label)
    ax.axhline(0.0, color="k", lw=0.8)
    ax.axhspan(-1e4, 0.0, color="tab:red", alpha=0.06)
    ax.set_xscale("log")
    ax.set_yscale("symlog", linthresh=1.0)
    ax.set_ylim(-1e4, 2.0)
    ax.set_xlabel("α (sans unité)")
    ax.set_ylabel("W₀ᵐ = λ / (n + λ) (sans unité)")
    ax.set_title("Poids du point central : négatif dès que α²(n + κ) < n", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8, loc="lower right")
    return fig


@register("ukf-ordres", chapter=CHAPTER,
          title="Erreur de la moyenne transformée en fonction de l'incertitude d'azimut : ordres 2, 4 et 6")
def ukf_orders():
    stds = np.logspace(np.log10(0.02), np.log10(0.6), 15)
    errors = banana.mean_error_orders(stds)
    fig, ax = new_figure(width=7.0, height=3.8)
    labels = ("linéarisation (EKF) : pente 2", "unscented, κ = 0 : pente 4", "unscented, κ = 3 − n = 1 : pente 6")
    for e, label, color in zip(errors, labels, ("tab:red", "tab:blue", "tab:green")):
        ax.loglog(np.rad2deg(stds), 1000 * e, "o-", ms=3, color=color, label=label)
    ax.set_xlabel("écart-type de l'azimut σθ (°)")
    ax.set_ylabel("erreur de la moyenne (mm)")
    ax.set_title("Banane (r = 1 m) : erreur de la moyenne en fonction de σθ", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    return fig


@register("ukf-cible-lointaine", chapter=CHAPTER,
          title="Cible lointaine : erreur de position et NEES moyennes de l'EKF, de l'UKF et de l'EKF itéré (100 tirages)")
def ukf_distant_target():
    comp = distant_target_comparison()
    fig, (ax, an) = new_figure(2, 1, width=7.5, height=5.6, sharex=True)
    for name, color, ls in (("EKF", "tab:red", "-"), ("UKF", "tab:blue", "-"), ("EKF itéré", "tab:purple", "--")):
        ax.semilogy(comp.t, comp.position_error[name], color=color, lw=1.6, ls=ls, label=name)
        an.semilogy(comp.t, comp.nees[name], color=color, lw=1.6, ls=ls, label=name)
    lo, hi = chi2_band(4, comp.n_runs)
    an.axhspan(lo, hi, color="tab:green", alpha=0.2, label=f"bande à 95 % de la NEES moyenne ({comp.n_runs} tirages)")
    an.axhline(4.0, color="tab:green", lw=1.0)
    ax.set_ylabel("erreur de position moyenne (m)")
    ax.set_title("Erreur ‖p̂ₖ − pₖ‖ moyenne", fontsize=10)
    an.set_ylabel("NEES moyenne (sans unité)")
    an.set_xlabel("temps (s)")
    an.set_title("NEES moyenne : 4 attendu (dimension de l'état)", fontsize=10)
    for a in (ax, an):
        a.grid(alpha=0.3, which="both")
        a.legend(fontsize=8, loc="upper right")
    return fig


@register("ukf-comparaison", chapter=CHAPTER, title="Tag UWB : EKF et UKF sur les mêmes mesures")
def ukf_comparison():
    run = tag_comparison()
    data, gap = run.data, run.gap
    fig, (ax, ad) = new_figure(2, 1, width=7.5, height=5.2, sharex=True)
    ax.plot(data.t, 100 * run.ekf_error, color="tab:red", lw=1.4,
            label=f"EKF (REQM {format_number(100 * run.ekf_rmse, decimals=2)} cm)")
    ax.plot(data.t, 100 * run.ukf_error, color="tab:blue", lw=1.0, ls="--",
            label=f"UKF (REQM {format_number(100 * run.ukf_rmse, decimals=2)} cm)")
    ax.axvspan(0, data.t[TAG_TRANSIENT_STEPS - 1], color="0.85", label="régime transitoire (exclu)")
    ax.set_ylim(0, 30)
    ax.set_ylabel(r"erreur de position $\|\hat p - p\|$ (cm)")
    ax.legend(loc="upper right", fontsize=8)
    ax.grid(alpha=0.3)
    ad.semilogy(data.t, 1000 * np.maximum(gap, 1e-9), color="tab:purple", lw=1.2)
    ad.set_ylabel(r"$\|\hat p_{\mathrm{EKF}} - \hat p_{\mathrm{UKF}}\|$ (mm)")
    ad.set_xlabel("temps (s)")
    ad.grid(alpha=0.3, which="both")
    ad.set_title("Écart entre les deux estimations", fontsize=10)
    return fig
