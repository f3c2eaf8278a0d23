"""Figures des travaux pratiques : le filtre de l'étudiant contre celui du paquet.

Chaque figure prend les fonctions de l'étudiant en arguments nommés
(``kc.figures.draw("tp-tension", predict=predict, update=update)``) ; sans argument, elle trace les
solutions de référence du correcteur. Si le code de l'étudiant échoue (fonction pas encore écrite,
exception), la figure montre le seul filtre du paquet et dit pourquoi dans son titre.
"""

from __future__ import annotations

import textwrap

import numpy as np

from ..scenarios.labs import LAB_SAMU_GATE, nile_lab, pda_lab, pendulum_lab, samu_lab, tag_lab, voltage_lab
from ._registry import new_figure, register
from .likelihood import FLOW, _year_formatter

YOURS = "tab:orange"
PACKAGE = "tab:blue"


def _note(fig, message: str | None) -> None:
    """Le message d'échec du code de l'étudiant, en tête de figure (sinon rien)."""
    if message:
        text = "\n".join(textwrap.wrap(f"Votre filtre n'a pas pu tourner : {message}.", 110))
        fig.suptitle(text, fontsize=8, color="#8a1c13", ha="left", x=0.01)


@register("tp-tension", chapter="tp-filtre-lineaire",
          title="TP 1 : votre filtre et celui du paquet sur la tension constante")
def voltage_lab_figure(predict=None, update=None):
    run = voltage_lab(predict, update)
    n = run.data["n"]
    fig, (ax, az) = new_figure(2, 1, width=7.0, height=5.6, sharex=True)
    ax.axhline(run.data["true"], color="tab:green", lw=1.2, label="valeur vraie")
    ax.plot(n, run.data["z"], "+", color="0.45", ms=6, label="mesures $y_n$")
    ax.plot(n, run.reference["x"], color=PACKAGE, lw=2.0, label="paquet : kc.kalman_filter")
    az.plot(n, run.reference["P"], color=PACKAGE, lw=2.0, label="paquet")
    if run.student is not None:
        ax.plot(n, run.student["x"], "o", ms=3.5, mfc="none", color=YOURS, label="votre filtre")
        az.plot(n, run.student["P"], "o", ms=3.5, mfc="none", color=YOURS, label="votre filtre")
    ax.set_ylabel("tension (V)")
    ax.set_title(r"Estimation $\hat x_n$ : vos points doivent tomber sur la courbe du paquet", fontsize=10)
    ax.legend(loc="lower right", fontsize=8)
    az.set_yscale("log")
    az.set_ylabel(r"variance $P_n$ (V²)")
    az.set_xlabel("itération n (sans unité)")
    az.legend(loc="upper right", fontsize=8)
    for a in (ax, az):
        a.grid(alpha=0.3)
    _note(fig, run.message)
    return fig


@register("tp-tag", chapter="tp-ekf-tag", title="TP 2 : votre EKF et celui du paquet sur le tag radio")
def tag_lab_figure(update=None, ranges_jacobian=None):
    run = tag_lab(update, ranges_jacobian)
    true, anchors, t = run.data["true"], run.data["anchors"], run.data["t"]
    fig, (ax, az) = new_figure(1, 2, width=8.0, height=3.8)
    ax.plot(true[:, 0], true[:, 1], color="tab:green", lw=1.2, label="trajectoire vraie")
    ax.plot(anchors[:, 0], anchors[:, 1], "^", color="k", ms=7, label="ancres")
    ax.plot(run.reference["x"][:, 0], run.reference["x"][:, 1], color=PACKAGE, lw=1.5, label="paquet")
    err_ref = np.linalg.norm(run.reference["x"][:, :2] - true[:, :2], axis=1)
    az.plot(t, err_ref, color=PACKAGE, lw=1.5, label="paquet")
    if run.student is not None:
        x = run.student["x"]
        ax.plot(x[:, 0], x[:, 1], "--", color=YOURS, lw=1.5, label="votre EKF")
        az.plot(t, np.linalg.norm(x[:, :2] - true[:, :2], axis=1), "--", color=YOURS, lw=1.5, label="votre EKF")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal")
    ax.set_title("Trajectoires estimées", fontsize=10)
    ax.legend(loc="upper center", fontsize=7, ncol=2)
    az.set_yscale("log")
    az.set_xlabel("temps (s)")
    az.set_ylabel("erreur de position (m)")
    az.set_title("Erreur de position", fontsize=10)
    az.legend(loc="upper right", fontsize=8)
    for a in (ax, az):
        a.grid(alpha=0.3)
    _note(fig, run.message)
    return fig


@register("tp-pendule", chapter="tp-ukf-particulaire",
          title="TP 3 : votre UKF et votre filtre particulaire contre ceux du paquet (pendule)")
def pendulum_lab_figure(sigma_points=None, unscented_transform=None, systematic_resample=None,
                        particle_weights=None):
    run = pendulum_lab(sigma_points, unscented_transform, systematic_resample, particle_weights)
    t, true = run.data["t"], run.data["true"]
    fig, axes = new_figure(2, 1, width=7.0, height=5.6, sharex=True, sharey=True)
    for ax, key, name in ((axes[0], "ukf", "UKF"), (axes[1], "pf", "filtre particulaire")):
        ax.plot(t, true[:, 0], color="tab:green", lw=1.2, label="angle vrai")
        ax.plot(t, run.reference[key][:, 0], color=PACKAGE, lw=2.0, label=f"{name} du paquet")
        if run.student[key] is not None:
            ax.plot(t, run.student[key][:, 0], "--", color=YOURS, lw=1.5, label=f"votre {name}")
        ax.set_ylabel(r"angle $\theta$ (rad)")
        ax.legend(loc="lower left", fontsize=8, ncol=3)
        ax.grid(alpha=0.3)
    axes[0].set_title("UKF : mêmes points sigma, mêmes résultats (à l'arrondi près)", fontsize=10)
    axes[1].set_title("Filtre particulaire : mêmes lois, tirages différents, résultats proches", fontsize=10)
    axes[1].set_xlabel("temps (s)")
    _note(fig, run.message)
    return fig


@register("tp-nil", chapter="tp-lissage-em", title="TP 4 : votre lisseur et votre EM contre ceux du paquet (Nil)")
def nile_lab_figure(rts_step=None, m_step=None):
    run = nile_lab(rts_step, m_step)
    year, y = run.data["year"], run.data["y"]
    fig, (ax, az) = new_figure(2, 1, width=7.0, height=6.0)
    ax.plot(year, y, ".", color="0.45", ms=4, label="débit mesuré")
    ax.plot(year, run.reference["smoothed"], color=PACKAGE, lw=2.0, label="niveau lissé (paquet)")
    if run.student["smoothed"] is not None:
        ax.plot(year, run.student["smoothed"], "--", color=YOURS, lw=1.5, label="votre lisseur")
    ax.set_xlabel("temps (année)")
    ax.xaxis.set_major_formatter(_year_formatter())
    ax.set_ylabel(FLOW)
    ax.legend(loc="upper right", fontsize=8)
    it = np.arange(run.reference["variances"].shape[0])
    for j, (name, style) in enumerate(((r"$\sigma^2_\varepsilon$", "-"), (r"$\sigma^2_\eta$", ":"))):
        az.plot(it, run.reference["variances"][:, j], style, color=PACKAGE, lw=2.0, label=f"{name}, EM du paquet")
        if run.student["variances"] is not None:
            az.plot(it, run.student["variances"][:, j], "o", ms=3.5, mfc="none", color=YOURS,
                    label=f"{name}, votre étape M")
    az.set_yscale("log")
    az.set_xlabel("itération d'EM")
    az.set_ylabel("variance (10¹⁶ m⁶)")
    az.legend(loc="center right", fontsize=8)
    for a in (ax, az):
        a.grid(alpha=0.3)
    _note(fig, run.message)
    return fig


@register("tp-samu", chapter="tp-helicoptere-samu",
          title="TP 5 : votre fenêtre de validation et votre IMM contre ceux du paquet sur le vol de l'hélicoptère SAMU 31")
def samu_lab_figure(cv_model=None, nis_gate=None, van_loan=None, imm_mix=None, mode_probabilities=None,
                    imm_merge=None):
    from ..numbers import format_number

    run = samu_lab(cv_model, nis_gate, van_loan, imm_mix, mode_probabilities, imm_merge)
    t, y, y_bad, bad = run.data["t"], run.data["y"], run.data["y_bad"], run.data["outliers"]
    ref, you = run.reference, run.student
    fig, (ax, az) = new_figure(1, 2, width=10.0, height=4.6, gridspec_kw={"width_ratios": [1.0, 1.25]})
    km = 1e-3
    ax.plot(y[:, 0] * km, y[:, 1] * km, "+", color="0.55", ms=4, label="positions mesurées")
    ax.plot(y_bad[bad, 0] * km, y_bad[bad, 1] * km, "x", color="crimson", ms=8, mew=2, label="positions aberrantes")
    ax.plot(ref["gate_x"][:, 0] * km, ref["gate_x"][:, 1] * km, color=PACKAGE, lw=2.0, label="paquet : fenêtre de validation")
    rejected = ref["rejected"]
    ax.plot(y_bad[rejected, 0] * km, y_bad[rejected, 1] * km, "o", mfc="none", color=PACKAGE, ms=9,
            label="rejetées par le paquet")
    if you["gate_x"] is not None:
        ax.plot(you["gate_x"][:, 0] * km, you["gate_x"][:, 1] * km, "--", color=YOURS, lw=1.5, label="votre filtre")
        mine = you["rejected"]
        ax.plot(y_bad[mine, 0] * km, y_bad[mine, 1] * km, "s", mfc="none", color=YOURS, ms=12,
                label="rejetées par votre fenêtre")
    ax.set_xlabel("est (km)")
    ax.set_ylabel("nord (km)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title(f"Fenêtre de validation p = {format_number(LAB_SAMU_GATE, decimals=3)} sur six positions "
                 "corrompues", fontsize=9)
    ax.legend(loc="lower left", fontsize=7)
    turn = az.twinx()
    turn.fill_between(run.data["rate_t"], np.abs(run.data["rate"]), color="0.85", lw=0, zorder=0)
    turn.set_ylabel("vitesse de virage mesurée, en gris (°/s)", color="0.35")
    turn.set_ylim(0.0, 1.03 * float(np.max(np.abs(run.data["rate"]))))
    az.set_zorder(turn.get_zorder() + 1)
    az.patch.set_visible(False)
    az.plot(t, ref["mu"][:, 1], color=PACKAGE, lw=1.6, label="paquet : kc.imm_filter")
    if you["mu"] is not None:
        az.plot(t, you["mu"][:, 1], "o", ms=2.5, mfc="none", color=YOURS, label="votre IMM")
    az.set_ylim(-0.03, 1.03)
    az.set_xlabel("temps depuis la première position (s)")
    az.set_ylabel("probabilité du régime agité μ (sans unité)")
    az.set_title("IMM calme/agité : vos points doivent tomber sur la courbe du paquet", fontsize=9)
    az.legend(loc="upper left", fontsize=8)
    for a in (ax, az):
        a.grid(alpha=0.3)
    _note(fig, run.message)
    return fig


@register("tp-pda", chapter="tp-plusieurs-cibles",
          title="TP 7 : votre PDA et celle du paquet sur l'hélicoptère SAMU 31 dans un fouillis dense")
def pda_lab_figure(pda_weights=None, pda_update=None):
    run = pda_lab(pda_weights, pda_update)
    truth, det, t = run.data["truth"], run.data["detections"], run.data["t"]
    fig, (ax, az) = new_figure(1, 2, width=9.0, height=4.0, gridspec_kw={"width_ratios": [1.1, 1.0]})
    ax.plot(det[:, 0] / 1e3, det[:, 1] / 1e3, "+", color="0.6", ms=4, label="détections (à moins de 1,5 km)")
    ax.plot(truth[:, 0] / 1e3, truth[:, 1] / 1e3, color="black", lw=3, alpha=0.35, label="trajectoire vraie")
    ax.plot(run.reference["x"][:, 0] / 1e3, run.reference["x"][:, 1] / 1e3, color=PACKAGE, lw=1.8,
            label="PDA du paquet")
    az.plot(t, run.reference["error"], color=PACKAGE, lw=1.8, label="PDA du paquet")
    if run.student is not None:
        ax.plot(run.student["x"][:, 0] / 1e3, run.student["x"][:, 1] / 1e3, "o", ms=3.5, mfc="none", color=YOURS,
                label="votre PDA")
        az.plot(t, run.student["error"], "o", ms=3.5, mfc="none", color=YOURS, label="votre PDA")
    ax.set_xlabel("est (km)")
    ax.set_ylabel("nord (km)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(loc="lower left", fontsize=7)
    ax.set_title("Vos points doivent tomber sur la piste du paquet", fontsize=10)
    az.set_xlabel("temps (s)")
    az.set_ylabel("erreur de position (m)")
    az.legend(loc="upper left", fontsize=8)
    for a in (ax, az):
        a.grid(alpha=0.3)
    _note(fig, run.message)
    return fig
