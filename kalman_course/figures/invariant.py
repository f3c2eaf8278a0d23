"""Figures du chapitre « Filtrage invariant sur les groupes de Lie »."""

from __future__ import annotations

import numpy as np

from ..geometry.lie import se2_exp
from ..numbers import format_number
from ..scenarios import robot_localization as rl
from ..scenarios import robot_localization_results as cached
from ._registry import new_figure, register

CHAPTER = "filtrage-invariant"

#: Couleur et trait de chaque filtre (mêmes dans les figures et les curseurs du chapitre).
STYLES = {"invariant": ("tab:blue", "-"), "standard": ("tab:red", "--"), "invariant_ukfm": ("tab:purple", ":")}
LABELS = {"invariant": "EKF invariant", "standard": "EKF standard", "invariant_ukfm": "EKF invariant, G de ukfm"}


def _robot(ax, T, color, size=0.18, **kw):
    """Le robot : un triangle pointé selon son cap, centré sur sa position."""
    pts = np.array([[size, 0.0], [-0.6 * size, 0.45 * size], [-0.6 * size, -0.45 * size], [size, 0.0]])
    world = pts @ T[:2, :2].T + T[:2, 2]
    ax.fill(world[:, 0], world[:, 1], color=color, alpha=0.85, lw=0, **kw)


@register("se2-exponentielle", chapter=CHAPTER,
          title="L'exponentielle de SE(2) : Exp(sξ), s de 0 à 1, est un mouvement à vitesses constantes")
def se2_exponential():
    fig, ax = new_figure(1, 1, width=6.0, height=4.0)
    rho = np.array([2.0, 0.0])
    s = np.linspace(0.0, 1.0, 61)
    colors = ["tab:gray", "tab:blue", "tab:green", "tab:orange"]
    for theta, color in zip((0.0, np.pi / 2, np.pi, 3 * np.pi / 2), colors):
        xi = np.r_[rho, theta]
        path = np.array([se2_exp(si * xi)[:2, 2] for si in s])
        end = se2_exp(xi)[:2, 2]
        label = (f"θ = {format_number(np.degrees(theta), decimals=0)}° : arrivée à "
                 f"{format_number(np.linalg.norm(end), decimals=2)} m du départ")
        ax.plot(path[:, 0], path[:, 1], color=color, lw=2.0, label=label)
        for si in (0.5, 1.0):
            _robot(ax, se2_exp(si * xi), color)
    _robot(ax, np.eye(3), "black")
    ax.annotate("", xy=(2.0, -0.25), xytext=(0.0, -0.25), arrowprops={"arrowstyle": "->", "color": "black"})
    ax.text(1.0, -0.45, "ρ = (2 m, 0)", ha="center", va="top", fontsize=8)
    ax.set_aspect("equal")
    ax.set_xlim(-1.0, 2.6)
    ax.set_ylim(-0.8, 1.7)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("Exp(sξ), ξ = (ρ, θ) : le robot avance de |ρ| en tournant de θ", fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    ax.grid(alpha=0.3)
    return fig


@register("invariant-deux-caps", chapter=CHAPTER,
          title="Un tirage du banc d'essai depuis deux caps initiaux (0° et 60°) : trajectoires, erreur de cap et "
                "incertitude annoncée des deux filtres")
def invariant_two_headings():
    th = rl.two_headings()
    data, k = th.data, 1  # le cap faux de 60°
    fig, (ax, ah, ac) = new_figure(1, 3, width=12.0, height=4.0, gridspec_kw={"width_ratios": [1, 1.1, 1.1]})
    truth = data.truth[:, :2, 2]
    ax.plot(truth[:, 0], truth[:, 1], color="black", lw=1.5, label="trajectoire vraie")
    gnss = data.y[0][~np.isnan(data.y[0, :, 0])]
    ax.plot(gnss[:, 0], gnss[:, 1], "o", ms=3.5, mfc="none", color="tab:gray", label="positions GNSS (σ = 1 m)")
    every = 5  # un point tracé tous les 5 pas (0,05 s) : les courbes restent fidèles, le tracé léger
    t = (data.model.dt * np.arange(1, data.y.shape[1] + 1))[::every]
    theta_true = rl.TURN_RATE * t
    for kind, runs in (("invariant", th.invariant), ("standard", th.standard)):
        color, ls = STYLES[kind]
        res = runs[k]
        ax.plot(res.position[::every, 0], res.position[::every, 1], color=color, ls=ls, lw=1.5, label=LABELS[kind])
        err = np.abs(np.degrees(np.angle(np.exp(1j * (res.heading[::every] - theta_true)))))
        sigma = 2 * np.degrees(np.sqrt(res.P_world[::every, 2, 2]))
        ah.semilogy(t, err, color=color, ls=ls, lw=1.8, label=f"{LABELS[kind]} : |θ̂ − θ|")
        ah.semilogy(t, sigma, color=color, ls=ls, lw=0.9, alpha=0.6, label=f"{LABELS[kind]} : 2σ annoncé")
        for deg, r, style in zip(th.headings_deg, runs, ({"lw": 2.4}, {"lw": 0.0, "marker": "o", "ms": 4,
                                                                        "mfc": "none", "markevery": 30})):
            label = f"{LABELS[kind]}, cap initial {format_number(deg, decimals=0)}°"
            ac.semilogy(t, np.degrees(np.sqrt(r.P_world[::every, 2, 2])), color=color, label=label, **style)
    _robot(ax, np.eye(3), "black", size=0.45)  # le robot au départ (cap nul)
    _robot(ax, se2_exp([0.0, 0.0, np.radians(th.headings_deg[k])]), "tab:gray", size=0.45)  # ce que croient les filtres
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("Trajectoires, départ à 60° du vrai cap", fontsize=9)
    ax.legend(fontsize=6.5, loc="lower center", ncol=2, bbox_to_anchor=(0.5, -0.02))
    ax.grid(alpha=0.3)
    ax.set_ylim(-3.0, 11.0)
    ah.set_ylim(0.05, 200.0)
    ah.set_ylabel("erreur de cap (°)")
    ah.set_title("Départ à 60° : erreur de cap (épais), 2σ annoncé (fin)", fontsize=9)
    ah.legend(fontsize=6.5, loc="lower left", ncol=1)
    ac.set_ylabel("σ du cap annoncé (°)")
    ac.set_title("σ annoncé depuis les deux départs", fontsize=9)
    ac.legend(fontsize=6.5, loc="upper right")
    for a in (ah, ac):
        a.set_xlabel("temps (s)")
        a.grid(alpha=0.3, which="both")
    return fig


@register("localisation-banc-essai", chapter=CHAPTER,
          title="Banc d'essai de ukfm, 100 tirages : erreur de position et NEES des deux filtres au cours du temps")
def localization_benchmark_curves():
    t = np.asarray(cached.CURVE_TIME)
    curves = cached.CURVES
    fig, (ax, an) = new_figure(1, 2, width=9.5, height=4.0, sharex=True)
    for kind in ("invariant", "standard"):
        color, ls = STYLES[kind]
        ax.plot(t, np.sqrt(curves[f"{kind} position_mse"]), color=color, ls=ls, lw=1.6, label=LABELS[kind])
    for kind in ("invariant", "standard", "invariant_ukfm"):
        color, ls = STYLES[kind]
        an.semilogy(t, curves[f"{kind} position_nees"], color=color, ls=ls, lw=1.6, label=LABELS[kind])
    an.axhline(1.0, color="black", lw=1.0, label="1 : filtre cohérent")
    an.axvspan(0.0, 20.0, color="tab:gray", alpha=0.12, lw=0)
    an.text(10.0, 0.2, "hors de la moyenne\n(avant 20 s)", ha="center", fontsize=7, color="dimgray")
    an.set_ylim(0.1, 1e5)
    ax.set_ylim(0.0, None)
    ax.set_ylabel("erreur quadratique moyenne de position (m)")
    an.set_ylabel("NEES de position moyenne (sans unité)")
    ax.set_title(f"Erreur de position ({cached.N_RUNS} tirages)", fontsize=9)
    an.set_title("NEES de position, e_pᵀ Σ_pp⁻¹ e_p / 2", fontsize=9)
    for a in (ax, an):
        a.set_xlabel("temps (s)")
        a.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, loc="upper right")
    an.legend(fontsize=7, loc="upper right")
    return fig
