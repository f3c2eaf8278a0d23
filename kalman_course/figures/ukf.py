"""Figures du chapitre « Pour aller plus loin » (UKF de filterpy et EKF sur le tag UWB)."""

from __future__ import annotations

import numpy as np

from ..scenarios.tag import TAG_TRANSIENT_STEPS, position_rmse, run_tag_ekf, run_tag_ukf, tag_data
from ..numbers import format_spec as fr
from ._registry import new_figure, register

CHAPTER = "pour-aller-plus-loin"


@register("ukf-comparaison", chapter=CHAPTER, title="Tag UWB : EKF et UKF (filterpy) sur les mêmes mesures")
def ukf_comparison():
    data = tag_data()
    ekf = run_tag_ekf(data=data)
    ukf = run_tag_ukf(data=data)
    e_ekf = np.linalg.norm(ekf.x[:, :2] - data.x_true[:, :2], axis=1)
    e_ukf = np.linalg.norm(ukf.x[:, :2] - data.x_true[:, :2], axis=1)
    gap = np.linalg.norm(ekf.x[:, :2] - ukf.x[:, :2], axis=1)
    fig, (ax, ad) = new_figure(2, 1, width=7.5, height=5.2, sharex=True)
    ax.plot(data.t, 100 * e_ekf, color="tab:blue", lw=1.4,
            label=f"EKF (erreur quadratique moyenne {fr(100 * position_rmse(ekf.x, data.x_true), '.2f')} cm)")
    ax.plot(data.t, 100 * e_ukf, color="tab:orange", lw=1.0, ls="--",
            label=f"UKF (erreur quadratique moyenne {fr(100 * position_rmse(ukf.x, data.x_true), '.2f')} cm)")
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
