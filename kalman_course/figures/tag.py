"""Figures du chapitre « Exemple — suivi d'un tag radio (UWB) »."""

from __future__ import annotations

import numpy as np

from ..scenarios.tag import TAG_ROOM, position_rmse, run_tag_ekf, tag_data, tag_ranges_jacobian
from ._geometry import draw_ellipse
from ..numbers import format_spec as fr
from ._registry import new_figure, register

CHAPTER = "suivi-tag"

#: Pas où l'on détaille la géométrie de la mesure : le deuxième (t = 0,2 s), quand la prédiction est
#: encore incertaine (σ ≈ 12 cm) et que la correction divise l'écart-type par deux.
DETAIL_STEP = 1


def _room(ax, anchors) -> None:
    L, W = TAG_ROOM
    ax.plot([0, L, L, 0, 0], [0, 0, W, W, 0], color="0.3", lw=1.2)
    ax.plot(anchors[:, 0], anchors[:, 1], "^", color="tab:red", ms=10, label="ancres $a_i$", zorder=5)
    for i, a in enumerate(anchors, start=1):
        dx = 0.25 if a[0] < L / 2 else -0.25
        dy = 0.3 if a[1] < W / 2 else -0.45
        ax.annotate(f"$a_{i}$", a, xytext=(a[0] + dx, a[1] + dy), ha="center", color="tab:red")
    ax.set_aspect("equal")
    ax.set_xlim(-0.8, L + 0.8)
    ax.set_ylim(-0.8, W + 0.8)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.grid(alpha=0.3)


@register("tag-trajectoire", chapter=CHAPTER, title="Trajectoire vraie et estimée du tag dans la pièce")
def tag_track():
    data = tag_data()
    res = run_tag_ekf(data=data)
    rmse = position_rmse(res.x, data.x_true)
    fig, ax = new_figure(width=7.0, height=6.0)
    _room(ax, data.anchors)
    ax.plot(data.x_true[:, 0], data.x_true[:, 1], color="tab:green", lw=2.5, alpha=0.7, label="trajectoire vraie")
    ax.plot(res.x[:, 0], res.x[:, 1], color="tab:blue", lw=1.2, label=r"estimation EKF $\hat p_{k\mid k}$")
    ax.plot(*data.x0[:2], "o", color="tab:blue", mfc="white", ms=8, label=r"départ du filtre $\hat x_0$")
    ax.plot(*data.x_true[0, :2], "s", color="tab:green", ms=7, label="départ du tag")
    ax.set_title(f"Tag UWB, {data.t[-1]:.0f} s, 4 ancres, $\\sigma_r$ = 10 cm : "
                 f"REQM {fr(100 * rmse, '.1f')} cm")
    ax.legend(loc="upper center", fontsize=8, ncol=3, bbox_to_anchor=(0.5, -0.1))
    return fig


@register("tag-erreurs", chapter=CHAPTER, title="Erreurs d'estimation du tag et bornes ±3σ")
def tag_errors():
    data = tag_data()
    res = run_tag_ekf(data=data)
    err = res.x - data.x_true
    three_sigma = 3 * res.std()
    labels = [r"$\hat p_x - p_x$ (m)", r"$\hat p_y - p_y$ (m)", r"$\hat v_x - v_x$ (m/s)", r"$\hat v_y - v_y$ (m/s)"]
    limits = [0.4, 0.4, 0.6, 0.6]
    fig, axes = new_figure(2, 2, width=8.0, height=5.5, sharex=True)
    for i, ax in enumerate(axes.ravel()):
        ax.fill_between(data.t, -three_sigma[:, i], three_sigma[:, i], color="tab:blue", alpha=0.18,
                        label=r"$\pm 3\sigma$ (filtre)")
        ax.plot(data.t, err[:, i], color="tab:blue", lw=1.0, label="erreur")
        ax.axhline(0, color="0.3", lw=0.8)
        ax.set_ylim(-limits[i], limits[i])
        ax.set_ylabel(labels[i])
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("temps (s)")
    axes[0, 0].legend(loc="upper right", fontsize=8)
    fig.suptitle("Erreur de l'EKF et son écart-type annoncé (départ : 3,5 m d'erreur, hors échelle)")
    return fig


@register("tag-jacobienne", chapter=CHAPTER,
          title="Les lignes de la jacobienne H : vecteurs unitaires des ancres vers le tag")
def tag_jacobian():
    data = tag_data()
    res = run_tag_ekf(data=data)
    k = DETAIL_STEP
    x_pred = res.x_pred[k]
    H = tag_ranges_jacobian(x_pred, data.anchors)
    fig, (ax, az) = new_figure(1, 2, width=9.0, height=4.6, gridspec_kw={"width_ratios": [1.25, 1]})
    _room(ax, data.anchors)
    t = np.linspace(0, 2 * np.pi, 400)
    for i, a in enumerate(data.anchors):
        r = data.y[k, i]
        ax.plot(a[0] + r * np.cos(t), a[1] + r * np.sin(t), "--", color="tab:red", lw=0.7, alpha=0.6)
        ax.annotate("", xy=x_pred[:2] + 1.5 * H[i, :2], xytext=x_pred[:2],
                    arrowprops=dict(arrowstyle="->", color="tab:purple", lw=1.8))
    ax.plot(*x_pred[:2], "o", color="tab:blue", ms=6, label=r"prédiction $\hat p_{k\mid k-1}$")
    ax.plot([], [], "--", color="tab:red", lw=0.7, label="cercles des distances mesurées")
    ax.plot([], [], color="tab:purple", lw=1.8, label=r"lignes de $H_k$ (×1,5 m)")
    ax.set_title(f"t = {fr(data.t[k], '.1f')} s : géométrie de la mesure", fontsize=10)
    ax.legend(loc="lower center", fontsize=7, bbox_to_anchor=(0.5, -0.42), ncol=1)

    # zoom : covariance avant / après la correction, directions des ancres
    c = x_pred[:2]
    draw_ellipse(az, c, res.P_pred[k], 3.0, color="tab:orange", lw=1.8, label=r"$3\sigma$ a priori $P_{k\mid k-1}$")
    draw_ellipse(az, res.x[k], res.P[k], 3.0, color="tab:blue", lw=1.8, label=r"$3\sigma$ a posteriori $P_{k\mid k}$")
    span = 3.2 * np.sqrt(np.max(np.linalg.eigvalsh(res.P_pred[k][:2, :2])))
    for i in range(H.shape[0]):
        az.annotate("", xy=c + 0.8 * span * H[i, :2], xytext=c,
                    arrowprops=dict(arrowstyle="->", color="tab:purple", lw=1.2, alpha=0.7))
    az.plot(*c, "o", color="tab:orange", ms=5)
    az.plot(*res.x[k, :2], "o", color="tab:blue", ms=5)
    az.plot(*data.x_true[k, :2], "x", color="tab:green", ms=9, mew=2, label="position vraie")
    az.set_xlim(c[0] - span, c[0] + span)
    az.set_ylim(c[1] - span, c[1] + span)
    az.set_aspect("equal")
    az.set_xlabel("x (m)")
    az.set_ylabel("y (m)")
    az.grid(alpha=0.3)
    az.set_title("zoom : la correction resserre l'ellipse", fontsize=10)
    az.legend(loc="lower center", fontsize=7, bbox_to_anchor=(0.5, -0.42))
    return fig
