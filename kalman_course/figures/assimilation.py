"""Figures de la partie « Assimilation de données » : « Le filtre d'ensemble en grande dimension » et
« Méthodes variationnelles », et celle du TP de l'ETKF."""

from __future__ import annotations

import numpy as np

from ..numbers import format_number
from ..scenarios import assimilation as assim
from ._registry import new_figure, register

ENSEMBLE_CHAPTER = "assimilation-ensemble"
VARIATIONAL_CHAPTER = "methodes-variationnelles"


@register("lorenz63-attracteur", chapter=ENSEMBLE_CHAPTER,
          title="L'attracteur de Lorenz-63, ses observations et l'analyse de l'ETKF")
def lorenz63_attractor():
    pic = assim.lorenz63_picture()
    exp = pic.experiment
    K = exp.x_true.shape[0]
    t = 0.25 * np.arange(1, K + 1)  # un cycle = 25 pas de 0,01
    fig, (ax, bx) = new_figure(1, 2, width=9.0, height=3.9, gridspec_kw={"width_ratios": [1, 1.5]})
    ax.plot(pic.path[:, 0], pic.path[:, 2], color="0.6", lw=0.6, label="vérité (pas de 0,01)")
    ax.plot(exp.y[:, 0], exp.y[:, 2], "+", color="tab:red", ms=5, alpha=0.7, label="observations")
    ax.plot(exp.x[:, 0], exp.x[:, 2], ".", color="tab:blue", ms=5, label="analyse de l'ETKF")
    ax.set_xlabel("x₁ (sans unité)")
    ax.set_ylabel("x₃ (sans unité)")
    ax.set_title("Le « papillon » : le plan (x₁, x₃)", fontsize=10)
    ax.legend(fontsize=7, loc="upper left")
    bx.plot(t, exp.x_true[:, 0], color="black", lw=1.5, label="vérité")
    bx.plot(t, pic.free[:, 0], color="tab:orange", lw=1.2, ls="--", label="prévision libre (départ à 10⁻³ près)")
    bx.plot(t, exp.y[:, 0], "+", color="tab:red", ms=5, label="observations (écart-type √2)")
    bx.plot(t, exp.x[:, 0], ".", color="tab:blue", ms=5, label="analyse de l'ETKF (10 membres)")
    bx.set_xlabel("temps (unités de temps du modèle)")
    bx.set_ylabel("x₁ (sans unité)")
    bx.set_title(f"Un cycle d'assimilation toutes les 0,25 unité de temps ({K} cycles)", fontsize=10)
    bx.legend(fontsize=7, loc="lower left", ncols=2)
    for a in (ax, bx):
        a.grid(alpha=0.3)
    return fig


@register("lorenz96-hovmoller", chapter=ENSEMBLE_CHAPTER,
          title="Diagramme de Hovmöller de Lorenz-96 : vérité, prévision libre, observations et analyse de l'ETKF")
def lorenz96_hovmoller():
    pic = assim.lorenz96_picture()
    exp = pic.experiment
    K = exp.x_true.shape[0]
    extent = (-0.5, 39.5, 0.05 * K, 0.0)
    fig, axes = new_figure(1, 4, width=10.0, height=4.6, sharey=True)
    panels = (
        (exp.x_true, "vérité", dict(cmap="viridis")),
        (pic.free - exp.x_true, "prévision libre − vérité", dict(cmap="RdBu_r", vmin=-8.0, vmax=8.0)),
        (exp.y - exp.x_true, "observations − vérité", dict(cmap="RdBu_r", vmin=-2.0, vmax=2.0)),
        (exp.x - exp.x_true, "analyse de l'ETKF − vérité", dict(cmap="RdBu_r", vmin=-2.0, vmax=2.0)),
    )
    images = []
    for ax, (values, title, style) in zip(axes, panels):
        images.append(ax.imshow(values, aspect="auto", extent=extent, interpolation="nearest", **style))
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("variable i (numéro)")
    axes[0].set_ylabel("temps (unités de temps du modèle)")
    for image, where, label in ((images[0], [axes[0]], "xᵢ vrai (sans unité)"),
                                (images[1], [axes[1]], "erreur (sans unité)"),
                                (images[3], list(axes[2:]), "erreur, échelle ±2 (sans unité)")):
        bar = fig.colorbar(image, ax=where, location="bottom", shrink=0.85)
        bar.set_label(label, fontsize=8)
    return fig


@register("assimilation-correlations", chapter=ENSEMBLE_CHAPTER,
          title="Corrélations d'échantillon parasites d'un petit ensemble, et le taper de Gaspari–Cohn")
def sample_correlations():
    c = assim.sample_correlations()
    offset = (np.arange(40) - c.centre + 20) % 40 - 20  # j − centre, ramené dans [−20, 20)
    order = np.argsort(offset)
    fig, ax = new_figure(width=7.5, height=3.8)
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.plot(offset[order], c.reference[order], "o-", color="black", lw=1.5, ms=4,
            label=f"{c.n_large} membres (référence)")
    ax.plot(offset[order], c.small[order], "s--", color="tab:red", lw=1.2, ms=4,
            label=f"{c.n_small} membres")
    ax.plot(offset[order], c.tapered[order], "^-", color="tab:blue", lw=1.2, ms=4,
            label=f"{c.n_small} membres × taper (rayon {format_number(c.radius, decimals=0)})")
    d = np.linspace(-20, 20, 401)
    from ..filters.ensemble_analysis import gaspari_cohn

    ax.plot(d, gaspari_cohn(np.abs(d), c.radius), ":", color="tab:green", lw=1.5, label="taper ρ(d)")
    ax.set_xlabel("écart j − i sur l'anneau (nombre de variables)")
    ax.set_ylabel("corrélation avec xᵢ (sans unité)")
    ax.set_title(f"Ensemble prévu de Lorenz-96, corrélations de la variable i = {c.centre}", fontsize=10)
    ax.set_ylim(-1.05, 1.15)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="lower left", ncols=2)
    return fig


@register("3dvar-cout", chapter=VARIATIONAL_CHAPTER,
          title="La fonction de coût du 3D-Var en deux dimensions : son minimum est la correction de Kalman")
def var3d_cost():
    case = assim.var3d_cost_case()
    g = np.linspace(-1.5, 3.5, 161)
    X, Y = np.meshgrid(g, g)
    pts = np.stack([X.ravel(), Y.ravel()], axis=1)
    Bi, Ri = np.linalg.inv(case.B), 1.0 / case.R[0, 0]
    db = pts - case.x_b
    Jb = 0.5 * np.einsum("ij,jk,ik->i", db, Bi, db).reshape(X.shape)
    Jo = (0.5 * Ri * (case.y[0] - pts @ case.C[0]) ** 2).reshape(X.shape)
    fig, ax = new_figure(width=6.4, height=5.0)
    levels = [0.125, 0.5, 1.125, 2.0]
    ax.contour(X, Y, Jb, levels=levels, colors="tab:orange", linewidths=1.0, linestyles="--")
    ax.contour(X, Y, Jo, levels=levels, colors="tab:red", linewidths=1.0, linestyles=":")
    J = Jb + Jo
    J_min = J.min()
    ax.contour(X, Y, J, levels=[J_min + v for v in levels], colors="tab:blue", linewidths=1.4)
    ax.plot(*case.x_b, "o", color="tab:orange", ms=8, label=r"ébauche $x_b$ (contours de $J_b$)")
    ax.plot([], [], ":", color="tab:red", label=r"observation de x₁ (contours de $J_o$)")
    ax.plot([], [], "-", color="tab:blue", label=r"$J = J_b + J_o$")
    ax.plot(*case.x_a, "*", color="tab:blue", ms=14, label="minimum de J = correction de Kalman")
    ax.plot(*case.x_numeric, "x", color="black", ms=9, label="minimum trouvé par scipy.optimize")
    ax.set_xlabel("x₁, observée (sans unité)")
    ax.set_ylabel("x₂, non observée (sans unité)")
    ax.set_aspect("equal")
    ax.set_title("B corrèle x₁ et x₂ : l'observation de x₁ corrige aussi x₂", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper left")
    return fig


@register("3dvar-lorenz63", chapter=VARIATIONAL_CHAPTER,
          title="3D-Var et interpolation optimale sur Lorenz-63")
def var3d_lorenz63():
    runs = assim.variational_lorenz63()
    window = slice(200, 260)
    exp = runs["3dvar"]
    t = 0.25 * np.arange(1, exp.x_true.shape[0] + 1)[window]
    fig, (ax, bx) = new_figure(2, 1, width=8.0, height=5.6, sharex=True, gridspec_kw={"height_ratios": [1.4, 1]})
    ax.plot(t, exp.x_true[window, 0], color="black", lw=1.6, label="vérité")
    ax.plot(t, exp.y[window, 0], "+", color="tab:red", ms=6, label="observations (écart-type √2)")
    ax.plot(t, exp.x[window, 0], "o-", color="tab:blue", ms=3, lw=1.0, label="3D-Var (B = 0,1 Σ)")
    ax.plot(t, runs["oi"].x[window, 0], "s--", color="tab:green", ms=3, lw=1.0,
            label="interpolation optimale (ébauche climatologique)")
    ax.set_ylabel("x₁ (sans unité)")
    ax.set_title("Lorenz-63, cycles 200 à 260 d'une expérience de 1000 cycles", fontsize=10)
    ax.legend(fontsize=7, loc="lower left", ncols=2)
    obs = np.sqrt(np.mean((exp.y - exp.x_true) ** 2, axis=1))
    bx.plot(t, obs[window], "+:", color="tab:red", ms=6, lw=0.8, label="observations")
    bx.plot(t, exp.rmse[window], "o-", color="tab:blue", ms=3, lw=1.0, label="3D-Var")
    bx.plot(t, runs["oi"].rmse[window], "s--", color="tab:green", ms=3, lw=1.0, label="interpolation optimale")
    bx.set_xlabel("temps (unités de temps du modèle)")
    bx.set_ylabel("erreur (sans unité)")
    bx.set_title("Erreur de chaque cycle (moyenne quadratique sur les trois variables)", fontsize=10)
    bx.set_ylim(0.0, None)
    bx.legend(fontsize=7, loc="upper right", ncols=3)
    for a in (ax, bx):
        a.grid(alpha=0.3)
    return fig


def _note(fig, message: str | None) -> None:
    if message:
        fig.suptitle(f"Votre fonction n'a pas pu servir : {message}", fontsize=9, color="tab:red")


@register("tp-etkf", chapter="tp-assimilation", title="TP 6 : votre ETKF et votre taper contre ceux du paquet (Lorenz-96)")
def etkf_lab_figure(etkf_update=None, gaspari_cohn=None):
    run = assim.etkf_lab(etkf_update, gaspari_cohn)
    fig, (ax, bx) = new_figure(1, 2, width=9.0, height=3.6, gridspec_kw={"width_ratios": [1.6, 1]})
    k = np.arange(1, run.data["reference_rmse"].size + 1)
    ax.plot(k, run.data["reference_rmse"], color="black", lw=1.5, label="ETKF du paquet")
    ax.axhline(1.0, color="tab:red", ls=":", lw=1.2, label="erreur des observations (R = I)")
    bx.plot(run.data["distance"], run.data["reference_taper"], color="black", lw=1.5, label="kc.gaspari_cohn")
    if run.student is not None:
        ax.plot(k, run.student["rmse"], color="tab:blue", ls="--", lw=1.2, label="votre ETKF")
        bx.plot(run.data["distance"], run.student["taper"], color="tab:blue", ls="--", lw=1.5, label="votre taper")
    ax.set_ylim(0.0, None)
    ax.set_xlabel("cycle d'assimilation k (numéro)")
    ax.set_ylabel("erreur quadratique moyenne (sans unité)")
    ax.set_title("Lorenz-96, 20 membres, inflation 1,04", fontsize=10)
    bx.set_xlabel("distance d (nombre de variables)")
    bx.set_ylabel("poids ρ(d) (sans unité)")
    bx.set_title("Gaspari–Cohn, rayon 4", fontsize=10)
    for a in (ax, bx):
        a.grid(alpha=0.3)
        a.legend(fontsize=7)
    _note(fig, run.message)
    return fig


@register("td-etkf-deux-membres", chapter="td-assimilation",
          title="TD 6 : une analyse de l'ETKF à deux membres, et le taper de Gaspari–Cohn de demi-support 2")
def td_two_members():
    from ..filters.ensemble_analysis import etkf_update, gaspari_cohn

    E = np.array([[1.0, 0.0], [3.0, 2.0]])
    Ea = etkf_update(E, np.array([3.5]), np.array([[1.0, 0.0]]), np.array([[2.0]]))
    fig, (ax, bx) = new_figure(1, 2, width=9.0, height=3.8)
    ax.axvline(3.5, color="tab:red", ls=":", lw=1.5, label="observation de la position, y = 3,5 (R = 2)")
    ax.plot(E[:, 0], E[:, 1], "o", color="tab:orange", ms=9, label="membres prévus")
    ax.plot(*E.mean(axis=0), "+", color="tab:orange", ms=14, mew=2, label="moyenne prévue")
    ax.plot(Ea[:, 0], Ea[:, 1], "s", color="tab:blue", ms=8, label="membres analysés (ETKF)")
    ax.plot(*Ea.mean(axis=0), "x", color="tab:blue", ms=12, mew=2, label="moyenne analysée = Kalman")
    for i in range(2):
        ax.annotate("", Ea[i], E[i], arrowprops={"arrowstyle": "->", "color": "0.5"})
    ax.set_xlabel("position (m)")
    ax.set_ylabel("vitesse (m/s)")
    ax.set_xlim(0.0, 4.5)
    ax.set_ylim(-0.5, 3.0)
    ax.set_title("Deux membres, une observation", fontsize=10)
    ax.legend(fontsize=7, loc="upper left")
    c = 2.0
    d = np.linspace(0.0, 5.0, 501)
    bx.plot(d, gaspari_cohn(d, c / 1.82), color="tab:green", lw=2, label="ρ(d), c = 2")
    points = np.arange(5.0)
    bx.plot(points, gaspari_cohn(points, c / 1.82), "o", color="black", ms=6, label="d = 0, 1, 2, 3, 4")
    bx.set_xlabel("distance d (nombre de variables)")
    bx.set_ylabel("poids ρ(d) (sans unité)")
    bx.set_title("Gaspari–Cohn de demi-support c = 2 (rayon 2/1,82)", fontsize=10)
    bx.grid(alpha=0.3)
    bx.legend(fontsize=7)
    ax.grid(alpha=0.3)
    return fig
