"""Figures des travaux dirigés : les calculs à la main, dessinés avec les valeurs du paquet."""

from __future__ import annotations

import numpy as np
import scipy.stats

from ..scenarios.tutorials import (
    FOUR_U,
    FOUR_WEIGHTS,
    THERMOMETER,
    THREE_STEPS,
    four_particles,
    square_transform,
    thermometer_update,
    three_step_smoothing,
)
from ..numbers import format_number
from ._registry import new_figure, register


def _fr(x: float) -> str:
    return format_number(x, significant=3, trim=True)


@register("td-gaussiennes", chapter="td-filtre-lineaire",
          title="TD 1 : a priori, mesure et a posteriori du thermomètre")
def thermometer_figure():
    c = THERMOMETER
    post = thermometer_update()
    x = np.linspace(13.0, 28.0, 600)
    fig, ax = new_figure(width=7.0, height=3.4)
    for mean, var, color, name in (
        (c["x_prior"], c["P_prior"], "tab:blue", "a priori"),
        (c["y"], c["R"], "tab:red", "mesure"),
        (float(post.x[0]), float(post.P[0, 0]), "tab:purple", "a posteriori"),
    ):
        label = f"{name} N({_fr(mean)} ; {_fr(var)})"
        ax.plot(x, scipy.stats.norm(mean, np.sqrt(var)).pdf(x), color=color, lw=2.0, label=label)
        ax.axvline(mean, color=color, lw=0.8, ls=":")
    ax.set_xlabel("température (°C)")
    ax.set_ylabel("densité (1/°C)")
    ax.set_title("Le produit des deux gaussiennes, renormalisé : moyenne pondérée, variance plus petite",
                 fontsize=10)
    ax.legend(loc="upper left", fontsize=8)
    ax.grid(alpha=0.3)
    return fig


@register("td-transformee-carre", chapter="td-filtres-a-points",
          title="TD 2 : les trois points sigma de N(0, 1) et leurs images par x²")
def square_transform_figure():
    s = square_transform()
    x = np.linspace(-2.5, 2.5, 400)
    fig, ax = new_figure(width=7.0, height=3.6)
    ax.plot(x, x**2, color="0.3", lw=1.5, label="f(x) = x²")
    ax.plot(s.points, s.images, "o", color="tab:orange", ms=8, label="points sigma et leurs images")
    for p, img, w in zip(s.points, s.images, s.Wm):
        ax.vlines(p, 0.0, img, color="tab:orange", lw=0.8, ls=":")
        ax.annotate(f"poids {'2/3' if w > 0.5 else '1/6'}", (p, img), textcoords="offset points", xytext=(6, 6),
                    fontsize=8)
    ax.axhline(s.mean, color="tab:blue", lw=1.5, label="moyenne unscented (= 1, exacte)")
    ax.axhline(s.linearised_mean, color="tab:red", lw=1.5, ls="--", label="moyenne linéarisée f(0) = 0")
    ax.set_xlabel("x (sans unité)")
    ax.set_ylabel("f(x) = x² (sans unité)")
    ax.legend(loc="upper center", fontsize=8)
    ax.grid(alpha=0.3)
    return fig


@register("td-reechantillonnage", chapter="td-filtres-a-points",
          title="TD 2 : rééchantillonnage systématique de quatre particules")
def four_particles_figure():
    w = np.asarray(FOUR_WEIGHTS)
    N = w.size
    c = np.concatenate([[0.0], np.cumsum(w)])
    positions = (FOUR_U + np.arange(N)) / N
    chosen = four_particles()
    fig, ax = new_figure(width=7.0, height=3.6)
    for i in range(N):
        ax.fill_between([0, 1], c[i], c[i + 1], color=f"C{i}", alpha=0.25, lw=0)
        ax.text(0.03, (c[i] + c[i + 1]) / 2, f"particule {i + 1} (poids {_fr(w[i])})",
                va="center", fontsize=8)
    for p, j in zip(positions, chosen):
        ax.plot([0.55, 0.95], [p, p], color="k", lw=1.2)
        ax.plot(0.95, p, "o", color=f"C{j}", ms=7)
        ax.text(0.97, p, f"→ {j + 1}", va="center", fontsize=8)
    ax.set_xlim(0, 1.1)
    ax.set_ylim(0, 1)
    ax.set_xticks([])
    ax.set_ylabel("poids cumulé (sans unité)")
    ax.set_xlabel(f"positions (u + i)/N, u = {_fr(FOUR_U)} (sans unité)")
    ax.set_title("Chaque position tombe dans la bande d'une particule : celle-ci est copiée", fontsize=10)
    return fig


@register("td-lissage-trois-pas", chapter="td-lissage-em",
          title="TD 3 : trois pas de filtre et de lisseur RTS sur une marche aléatoire")
def three_steps_figure():
    r = three_step_smoothing()
    k = np.arange(1, 4)
    fig, ax = new_figure(width=7.0, height=3.6)
    ax.plot(k, THREE_STEPS["y"], "s", color="0.35", ms=7, label="mesures $y_k$")
    ax.errorbar(k - 0.04, r.x, yerr=2 * np.sqrt(r.P), fmt="o-", color="tab:blue", capsize=4,
                label=r"filtre $\hat x_{k|k}$ ± 2σ")
    ax.errorbar(k + 0.04, r.xs, yerr=2 * np.sqrt(r.Ps), fmt="o-", color="tab:orange", capsize=4,
                label=r"lisseur $\hat x_{k|3}$ ± 2σ")
    ax.set_xticks(k)
    ax.set_xlabel("pas de temps k")
    ax.set_ylabel("état x (unité arbitraire)")
    ax.set_title("Le lisseur tire les estimations passées vers les mesures futures", fontsize=10)
    ax.legend(loc="lower right", fontsize=8)
    ax.grid(alpha=0.3)
    return fig


@register("td-porte-imm", chapter="td-cibles-reelles",
          title="TD 4 : le quantile de la porte pour m = 2, et un pas d'IMM scalaire")
def gate_and_imm_figure():
    from ..scenarios.tutorials import GATE_EXAMPLE, IMM_EXAMPLE, gate_example, imm_step

    gate = gate_example()
    r = imm_step()
    fig, (ax, az) = new_figure(1, 2, width=10.0, height=3.8)
    e = np.linspace(0.0, 18.0, 400)
    ax.plot(e, scipy.stats.chi2(2).cdf(e), color="tab:blue", lw=2.5, label=r"$\chi^2_2$ (scipy)")
    ax.plot(e, 1.0 - np.exp(-e / 2.0), "--", color="tab:orange", lw=1.5, label=r"$1 - e^{-\epsilon/2}$")
    for p, threshold in zip(GATE_EXAMPLE["p"], gate["thresholds"]):
        ax.plot([threshold, threshold], [0.0, p], ":", color="0.3", lw=1.0)
        ax.plot(threshold, p, "o", color="0.3", ms=5)
        ax.annotate(f"p = {format_number(p, decimals=3)} : ε ≤ {format_number(threshold, decimals=2)}",
                    (threshold, p), xytext=(-12, -34 if p < 0.995 else -18), textcoords="offset points",
                    ha="right", fontsize=8)
    ax.set_xlabel(r"NIS $\epsilon$ (sans unité)")
    ax.set_ylabel(r"probabilité $P(\epsilon_k \leq \epsilon)$ (sans unité)")
    ax.set_title("La porte pour m = 2 : quantile −2 ln(1 − p)", fontsize=10)
    ax.legend(loc="center right", fontsize=8)
    ax.grid(alpha=0.3)
    x = np.linspace(0.0, 6.0, 500)
    mu, xm, Pm = r.mu[0], r.x_modes[0, :, 0], r.P_modes[0, :, 0, 0]
    mixture = np.zeros_like(x)
    for j, (name, color) in enumerate((("calme", "tab:blue"), ("agité", "tab:red"))):
        density = mu[j] * scipy.stats.norm(xm[j], np.sqrt(Pm[j])).pdf(x)
        mixture += density
        az.plot(x, density, color=color, lw=1.5,
                label=f"régime {name} : μ = {format_number(mu[j], decimals=3)}, x̂ = {_fr(xm[j])}")
    az.plot(x, mixture, color="0.2", lw=2.0, label="mélange des deux régimes")
    az.plot(x, scipy.stats.norm(r.x[0, 0], np.sqrt(r.P[0, 0, 0])).pdf(x), "--", color="tab:purple", lw=1.8,
            label=f"combinaison : N({format_number(r.x[0, 0], decimals=3)} ; {format_number(r.P[0, 0, 0], decimals=3)})")
    az.axvline(IMM_EXAMPLE["y"], color="0.5", lw=0.8, ls=":")
    az.set_xlabel("état x (unité arbitraire)")
    az.set_ylabel("densité (par unité de x)")
    az.set_title(f"Un pas d'IMM, mesure y = {_fr(IMM_EXAMPLE['y'])}", fontsize=10)
    az.legend(loc="upper left", fontsize=7)
    az.grid(alpha=0.3)
    return fig


@register("td-information", chapter="td-autres-formes",
          title="TD 5 : un pas du filtre d'information, vu dans le plan position–vitesse")
def information_figure():
    from ._geometry import ellipse_points
    from ..scenarios.tutorials import INFORMATION_EXAMPLE, information_step

    c = INFORMATION_EXAMPLE
    r = information_step()
    fig, ax = new_figure(width=7.0, height=4.6)
    prior = ellipse_points(np.array(c["x"]), np.array(c["P"]))
    post = ellipse_points(r["x"], r["P"])
    ax.axvspan(c["y"] - np.sqrt(c["R"]), c["y"] + np.sqrt(c["R"]), color="tab:red", alpha=0.12,
               label=f"mesure de la position : {_fr(c['y'])} ± 1")
    ax.plot(prior[:, 0], prior[:, 1], color="tab:blue", lw=2.0, label="a priori (ellipse à 1σ)")
    ax.plot(*c["x"], "o", color="tab:blue")
    ax.plot(post[:, 0], post[:, 1], color="tab:purple", lw=2.0, label="a posteriori, forme information")
    ax.plot(r["kalman_x"][0], r["kalman_x"][1], "x", color="tab:orange", ms=10, mew=2,
            label="a posteriori, filtre de Kalman")
    ax.plot(*r["x"], "o", color="tab:purple", ms=4)
    ax.set_xlabel("position (unité arbitraire)")
    ax.set_ylabel("vitesse (unité arbitraire)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title("La vitesse, corrélée à la position, est corrigée sans être mesurée", fontsize=10)
    ax.legend(loc="lower right", fontsize=8)
    ax.grid(alpha=0.3)
    return fig


@register("examen-gain-stationnaire", chapter="sujet-examen",
          title="Examen : la variance prédite et le gain convergent vers le nombre d'or et son inverse")
def exam_stationary_figure():
    from ..scenarios.tutorials import exam_stationary

    r = exam_stationary()
    k = np.arange(1, len(r["K"]) + 1)
    golden = (1.0 + np.sqrt(5.0)) / 2.0
    fig, ax = new_figure(width=7.0, height=3.6)
    ax.plot(k, r["P_pred"], "o-", color="tab:blue", ms=3.5, label=r"variance prédite $P_{k|k-1}$")
    ax.plot(k, r["K"], "s-", color="tab:orange", ms=3.5, label=r"gain $K_k$")
    ax.axhline(golden, color="tab:blue", lw=0.8, ls=":", label=r"$\varphi = (1 + \sqrt{5})/2$")
    ax.axhline(1.0 / golden, color="tab:orange", lw=0.8, ls=":", label=r"$1/\varphi$")
    ax.set_yscale("log")
    ax.set_xlabel("pas de temps k")
    ax.set_ylabel("valeur (sans unité)")
    ax.set_title(r"Marche aléatoire, $Q = R = 1$, $P_0 = 10$ : convergence en quelques pas", fontsize=10)
    ax.legend(loc="upper right", fontsize=8)
    ax.grid(alpha=0.3)
    return fig


@register("td-ekf-invariant", chapter="td-filtrage-invariant",
          title="TD 7 : l'exponentielle de SE(2) à la main, puis une correction de l'EKF invariant")
def se2_by_hand_figure():
    from ..geometry.lie import se2_exp
    from ..scenarios.tutorials import SE2_BY_HAND, se2_by_hand
    from .invariant import _robot

    c, r = SE2_BY_HAND, se2_by_hand()
    s = np.linspace(0.0, 1.0, 41)
    fig, (ax1, ax2) = new_figure(1, 2, width=8.0, height=3.9)
    xi = np.array(c["xi"])
    arc = np.array([se2_exp(si * xi)[:2, 2] for si in s])
    ax1.plot(arc[:, 0], arc[:, 1], color="tab:blue", lw=2.0, label="Exp(sξ), s de 0 à 1 : un quart de cercle")
    _robot(ax1, np.eye(3), "black", size=0.12)
    _robot(ax1, r.exp, "tab:blue", size=0.12)
    ax1.plot([1.0], [0.0], "x", color="tab:red", ms=8, mew=2, label="(1 ; 0) : V(θ) oublié")
    ax1.plot([0.0], [1.0], "+", color="tab:orange", ms=10, mew=2, label="(0 ; 1) : tourner, puis avancer")
    ax1.set_xlim(-0.3, 1.3)
    ax1.set_ylim(-0.3, 1.45)
    ax1.set_title(f"Exercice 1 : arrivée en ({_fr(r.exp[0, 2])} ; {_fr(r.exp[1, 2])})", fontsize=9)
    T_pred = np.array(c["T_pred"])
    step = np.array([(T_pred @ se2_exp(si * r.update.K @ r.update.innovation))[:2, 2] for si in s])
    y = np.array(c["y"])
    circle = y + c["gnss_std"] * np.c_[np.cos(2 * np.pi * s), np.sin(2 * np.pi * s)]
    ax2.plot(circle[:, 0], circle[:, 1], color="tab:red", lw=1.0, ls=":")
    ax2.plot(*y, "o", color="tab:red", label=f"GNSS y = ({_fr(y[0])} ; {_fr(y[1])}), σ = {_fr(c['gnss_std'])} m")
    ax2.plot(step[:, 0], step[:, 1], color="tab:purple", lw=1.5, ls="--", label="T̂ Exp(s Kz), s de 0 à 1")
    _robot(ax2, T_pred, "tab:gray", size=0.3)
    _robot(ax2, np.asarray(r.update.T), "tab:purple", size=0.3)
    ax2.text(T_pred[0, 2] + 0.25, T_pred[1, 2] - 0.1, "prédite (cap 90°)", fontsize=8, color="0.3")
    ax2.text(r.update.T[0, 2] - 0.2, r.update.T[1, 2] - 0.45, "corrigée (cap 180°)", fontsize=8,
             color="tab:purple", ha="center")
    ax2.set_xlim(1.4, 4.4)
    ax2.set_ylim(0.2, 4.3)
    ax2.set_title("Exercice 2 : la mesure est devant le robot,\nle cap tourne par la corrélation de P⁻",
                  fontsize=9)
    for ax in (ax1, ax2):
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.legend(fontsize=7, loc="upper left")
        ax.grid(alpha=0.3)
    return fig
