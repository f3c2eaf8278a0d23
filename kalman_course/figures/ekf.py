"""Figures du chapitre « Dynamique non linéaire — le filtre de Kalman étendu »."""

from __future__ import annotations

import numpy as np

from ..numbers import format_spec as fr
from ..scenarios.polar import POLAR_BEARING_STD_DEG, POLAR_MEAN, POLAR_RANGE_STD, polar_transform
from ._geometry import draw_ellipse
from ._registry import new_figure, register

CHAPTER = "ekf"


@register("ekf-linearisation", chapter=CHAPTER,
          title="Linéarisation : une loi gaussienne transformée par f, et son approximation par l'EKF")
def ekf_linearisation():
    run = polar_transform()  # 3000 tirages, σ_r = 0,5 m, σ_θ = 20°
    samples, mapped = run.samples, run.mapped
    mc_mean, mc_cov = run.exact_mean, run.exact_cov
    std_deg = np.array([POLAR_RANGE_STD, POLAR_BEARING_STD_DEG])  # (m, °)

    fig, (ax0, ax1) = new_figure(1, 2, width=9.5, height=4.4, gridspec_kw={"width_ratios": [1, 1.3]})
    ax0.plot(samples[:, 0], np.rad2deg(samples[:, 1]), ".", ms=1.5, color="0.55", alpha=0.5)
    draw_ellipse(ax0, [POLAR_MEAN[0], 0.0], np.diag(std_deg) ** 2, 2.0,
                 color="tab:blue", lw=1.8)
    ax0.plot(POLAR_MEAN[0], 0.0, "o", color="tab:blue")
    ax0.set_xlabel("distance r (m)")
    ax0.set_ylabel(r"azimut $\theta$ (°)")
    ax0.set_title(r"Avant : $x \sim \mathcal{N}(\hat x, P)$ (gaussienne)", fontsize=10)
    ax0.grid(alpha=0.3)

    ax1.plot(mapped[:, 0], mapped[:, 1], ".", ms=1.5, color="0.55", alpha=0.5, label="tirages transformés $f(x)$")
    draw_ellipse(ax1, mc_mean, mc_cov, 2.0, color="k", lw=1.5, ls="--", label=r"moyenne et covariance exactes ($2\sigma$)")
    draw_ellipse(ax1, run.ekf_mean, run.ekf_cov, 2.0, color="tab:red", lw=1.8,
                 label=r"EKF : $f(\hat x)$, $J^A P (J^A)^T$ ($2\sigma$)")
    ax1.plot(*mc_mean, "o", color="k", ms=5)
    ax1.plot(*run.ekf_mean, "o", color="tab:red", ms=5)
    ax1.set_xlim(-3.0, 12.5)
    ax1.set_ylim(-10.0, 10.0)
    ax1.set_xlabel("x (m)")
    ax1.set_ylabel("y (m)")
    ax1.set_title(
        f"Après : $f(r, \\theta) = (r\\cos\\theta, r\\sin\\theta)$ — biais de la moyenne "
        f"{fr(run.ekf_bias, '.2f')} m",
        fontsize=10,
    )
    ax1.grid(alpha=0.3)
    ax1.legend(loc="upper left", fontsize=7)
    return fig
