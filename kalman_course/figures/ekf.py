"""Figures du chapitre « Dynamique non linéaire — le filtre de Kalman étendu »."""

from __future__ import annotations

import numpy as np

from ..filters.extended import ekf_predict
from ..core.models import NonlinearModel
from ..scenarios.banana import banana_truth
from ._geometry import draw_ellipse
from ..numbers import format_spec as fr
from ._registry import new_figure, register

CHAPTER = "ekf"

#: Loi de départ en coordonnées polaires : distance 10 m ± 0,5 m, azimut 0 ± 20°.
POLAR_MEAN = np.array([10.0, 0.0])
POLAR_STD = np.array([0.5, np.deg2rad(20.0)])
#: Graine des tirages de Monte-Carlo de la figure.
LINEARISATION_SEED = 11


def polar_to_cartesian(x, u=None):
    r""":math:`f(r, \theta) = (r\cos\theta,\ r\sin\theta)`."""
    return np.array([x[0] * np.cos(x[1]), x[0] * np.sin(x[1])])


def polar_to_cartesian_jacobian(x, u=None):
    r""":math:`J^A = \begin{bmatrix}\cos\theta & -r\sin\theta\\ \sin\theta & r\cos\theta\end{bmatrix}`."""
    c, s = np.cos(x[1]), np.sin(x[1])
    return np.array([[c, -x[0] * s], [s, x[0] * c]])


@register("ekf-linearisation", chapter=CHAPTER,
          title="Linéarisation : une loi gaussienne transformée par f, et son approximation par l'EKF")
def ekf_linearisation():
    P = np.diag(POLAR_STD**2)
    model = NonlinearModel(polar_to_cartesian, lambda x: x[:1], np.zeros((2, 2)), np.eye(1),
                           f_jacobian=polar_to_cartesian_jacobian)
    pred = ekf_predict(model, POLAR_MEAN, P)  # x⁻ = f(x̂), P⁻ = J^A P (J^A)ᵀ (bruit d'état nul)
    rng = np.random.default_rng(LINEARISATION_SEED)
    samples = POLAR_MEAN + rng.standard_normal((3000, 2)) * POLAR_STD
    mapped = np.array([polar_to_cartesian(s) for s in samples])
    exact = banana_truth(POLAR_STD[0], POLAR_STD[1], r=POLAR_MEAN[0], bearing=POLAR_MEAN[1])  # forme close
    mc_mean, mc_cov = exact.mean, exact.cov

    fig, (ax0, ax1) = new_figure(1, 2, width=9.5, height=4.4, gridspec_kw={"width_ratios": [1, 1.3]})
    ax0.plot(samples[:, 0], np.rad2deg(samples[:, 1]), ".", ms=1.5, color="0.55", alpha=0.5)
    draw_ellipse(ax0, [POLAR_MEAN[0], 0.0], np.diag([POLAR_STD[0], np.rad2deg(POLAR_STD[1])]) ** 2, 2.0,
                 color="tab:blue", lw=1.8)
    ax0.plot(POLAR_MEAN[0], 0.0, "o", color="tab:blue")
    ax0.set_xlabel("distance r (m)")
    ax0.set_ylabel(r"azimut $\theta$ (°)")
    ax0.set_title(r"Avant : $x \sim \mathcal{N}(\hat x, P)$ (gaussienne)", fontsize=10)
    ax0.grid(alpha=0.3)

    ax1.plot(mapped[:, 0], mapped[:, 1], ".", ms=1.5, color="0.55", alpha=0.5, label="tirages transformés $f(x)$")
    draw_ellipse(ax1, mc_mean, mc_cov, 2.0, color="k", lw=1.5, ls="--", label=r"moyenne et covariance exactes ($2\sigma$)")
    draw_ellipse(ax1, pred.x, pred.P, 2.0, color="tab:red", lw=1.8,
                 label=r"EKF : $f(\hat x)$, $J^A P (J^A)^T$ ($2\sigma$)")
    ax1.plot(*mc_mean, "o", color="k", ms=5)
    ax1.plot(*pred.x, "o", color="tab:red", ms=5)
    ax1.set_xlim(-3.0, 12.5)
    ax1.set_ylim(-10.0, 10.0)
    ax1.set_xlabel("x (m)")
    ax1.set_ylabel("y (m)")
    ax1.set_title(
        f"Après : $f(r, \\theta) = (r\\cos\\theta, r\\sin\\theta)$ — biais de la moyenne "
        f"{fr(np.linalg.norm(mc_mean - pred.x), '.2f')} m",
        fontsize=10,
    )
    ax1.grid(alpha=0.3)
    ax1.legend(loc="upper left", fontsize=7)
    return fig
