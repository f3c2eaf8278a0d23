"""Figures de la partie « Plusieurs cibles » : « Fouillis et association » et « Gérer les pistes », sur le trafic
de Toulouse-Blagnac vu par un radar (:mod:`kalman_course.scenarios.traffic`) et sur deux avions qui se croisent
(:mod:`kalman_course.scenarios.crossing`)."""

from __future__ import annotations

import numpy as np
import scipy.stats

from ..multitarget.gate import gate_threshold
from ..numbers import format_spec as fr
from ..scenarios import crossing as cr
from ..scenarios import traffic as tr
from ..scenarios import tutorials
from ._geometry import ellipse_points
from ._registry import new_figure, register

ASSOCIATION_CHAPTER = "fouillis-association"
MANAGEMENT_CHAPTER = "gestion-pistes"

#: Couleurs des cinq avions (les mêmes que les figures à curseurs).
COLOURS = ("royalblue", "darkorange", "seagreen", "crimson", "purple")
#: Couleurs des pistes de la figure du croisement.
TRACK_COLOURS = ("tab:blue", "tab:red", "tab:green", "tab:purple", "tab:brown")


def _plane(ax, unit: str = "km") -> None:
    ax.set_xlabel(f"est ({unit})")
    ax.set_ylabel(f"nord ({unit})")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(alpha=0.3)


# --------------------------------------------------------------------------- fouillis et association


@register("fouillis-scene", chapter=ASSOCIATION_CHAPTER,
          title="Cinq avions autour de Toulouse-Blagnac vus par un radar, et le nombre de détections de chaque relevé")
def scene_figure():
    scans = tr.radar_scans()
    truth = scans.truth
    names = tr.truth_names()
    k = tr.SNAPSHOT_SCAN
    fig, axes = new_figure(1, 2, width=10.0, height=4.4, gridspec_kw={"width_ratios": [1.35, 1.0]})
    ax = axes[0]
    for a, colour in enumerate(COLOURS):
        ax.plot(truth[:, a, 0] / 1e3, truth[:, a, 1] / 1e3, color=colour, lw=2.0, alpha=0.8, label=names[a])
        ax.plot(truth[0, a, 0] / 1e3, truth[0, a, 1] / 1e3, "o", color=colour, ms=5)
    z, origin = scans.scans[k], scans.origin[k]
    ax.plot(z[origin >= 0, 0] / 1e3, z[origin >= 0, 1] / 1e3, "o", mfc="none", color="black", ms=7,
            label=f"détections des avions (t = {fr(tr.DT * k, '.0f')} s)")
    ax.plot(z[origin < 0, 0] / 1e3, z[origin < 0, 1] / 1e3, "x", color="0.4", ms=6,
            label=f"fausses détections (t = {fr(tr.DT * k, '.0f')} s)")
    e0, e1, n0, n1 = (v / 1e3 for v in tr.REGION)
    ax.plot([e0, e1, e1, e0, e0], [n0, n0, n1, n1, n0], color="0.3", lw=0.8, ls="--", label="zone surveillée")
    ax.plot(0.0, 0.0, "s", color="black", ms=6)
    ax.annotate("Blagnac", (0.0, 0.0), xytext=(5, 4), textcoords="offset points", fontsize=8)
    _plane(ax)
    ax.legend(loc="upper right", fontsize=7, ncol=2)
    ax.set_title("Trajectoires (point : t = 0) et un relevé", fontsize=9)
    ax = axes[1]
    t = scans.t
    ax.bar(t, scans.n_detected, width=4.0, color="0.2", label="détections des avions")
    ax.bar(t, scans.n_clutter, width=4.0, bottom=scans.n_detected, color="0.7", label="fausses détections")
    mean = scans.clutter_density * tr.AREA
    ax.axhline(mean + 5 * scans.detection_probability, color="crimson", ls="--", lw=1.2,
               label=f"moyenne attendue : 5 P_D + λV = {fr(mean + 5 * scans.detection_probability, '.1f')}")
    ax.set_xlabel("temps (s)")
    ax.set_ylabel("détections par relevé (nombre)")
    ax.legend(loc="upper left", fontsize=7)
    ax.grid(alpha=0.3)
    ax.set_title(f"λ = {fr(scans.clutter_density, '.2g')} m⁻², V = {fr(tr.AREA / 1e6, '.0f')} km², "
                 f"P_D = {fr(scans.detection_probability, '.1f')}", fontsize=9)
    return fig


@register("association-porte", chapter=ASSOCIATION_CHAPTER,
          title="Le relevé de t = 140 s : pistes prédites, fenêtres de validation, détections, affectations du NN et du GNN")
def gate_snapshot_figure():
    snap = tr.scan_snapshot()
    names = tr.truth_names()
    gamma = gate_threshold(tr.GATE_PROBABILITY, 2)
    R = tr.radar_model().R
    fig, axes = new_figure(1, 2, width=10.0, height=5.4)
    # deux grappes : SAMU 31 et SAVAN11 (à gauche), CALIBRA et SAVAN03 (à droite)
    groups = [[t for t in range(snap.ids.size) if snap.owner[t] in (0, 4)],
              [t for t in range(snap.ids.size) if snap.owner[t] in (2, 3)]]
    for ax, tracks in zip(axes, groups):
        centre = snap.x_pred[tracks, :2].mean(axis=0)
        gates = {t: ellipse_points(snap.x_pred[t, :2], snap.P_pred[t][:2, :2] + R, np.sqrt(gamma)) - centre
                 for t in tracks}  # S = C P Cᵀ + R avec C = [I 0]
        half = 1.05 * max(np.abs(g).max() for g in gates.values())
        for t in tracks:
            a = snap.owner[t]
            ax.plot(gates[t][:, 0], gates[t][:, 1], color=COLOURS[a], lw=1.2)
            ax.plot(*(snap.x_pred[t, :2] - centre), "+", color=COLOURS[a], ms=12, mew=2,
                    label=f"piste {snap.ids[t]} ({names[a]}) prédite, sa fenêtre")
            ax.plot(*(snap.truth[a] - centre), "*", color=COLOURS[a], ms=11, mec="black", mew=0.5)
        near = np.all(np.abs(snap.detections - centre) < half, axis=1)
        for j in np.flatnonzero(near):
            source = snap.origin[j]
            style = dict(marker="o", mfc="none", color=COLOURS[source]) if source >= 0 else \
                dict(marker="x", color="0.4")
            ax.plot(*(snap.detections[j] - centre), ls="none", ms=8, mew=1.5, **style)
            ax.annotate(f"z{j}", snap.detections[j] - centre, xytext=(5, 5), textcoords="offset points", fontsize=8)
        for t in tracks:  # le plus proche voisin : flèche pleine ; le GNN : flèche pointillée
            for assignment, ls in ((snap.nn, "-"), (snap.gnn, ":")):
                j = assignment[t]
                if j >= 0:
                    ax.annotate("", snap.detections[j] - centre, xytext=snap.x_pred[t, :2] - centre,
                                arrowprops=dict(arrowstyle="->", ls=ls, lw=1.4, color=COLOURS[snap.owner[t]],
                                                shrinkA=4, shrinkB=6))
        ax.plot([], [], "*", color="0.5", mec="black", mew=0.5, ms=9, label="positions vraies")
        ax.plot([], [], "o", mfc="none", color="0.3", label="détections (couleur : l'avion qui l'a produite)")
        ax.plot([], [], "-", color="0.3", label="affectation du NN (flèche pleine)")
        ax.plot([], [], ":", color="0.3", label="affectation du GNN (flèche pointillée)")
        _plane(ax, "m")
        ax.set_aspect("equal", adjustable="box")  # bornes fixées : le cadre s'ajuste, pas les bornes
        ax.set_xlim(-half, half)
        ax.set_ylim(-half, half)
        ax.set_xlabel(f"est (m, depuis {fr(centre[0] / 1e3, '.1f')} km)")
        ax.set_ylabel(f"nord (m, depuis {fr(centre[1] / 1e3, '.1f')} km)")
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), fontsize=7, ncol=1)
        ax.set_title(" et ".join(names[snap.owner[t]] for t in tracks), fontsize=9)
    return fig


@register("association-croisement", chapter=ASSOCIATION_CHAPTER,
          title="Deux avions qui se croisent sous 8° : le plus proche voisin échange les pistes, la JPDA les garde")
def crossing_figure():
    angle = 8.0
    seed = next(s for s in range(200) if cr.crossing_outcome(cr.crossing_labels(angle, s, "nn")) == "échangées"
                and cr.crossing_outcome(cr.crossing_labels(angle, s, "jpda")) == "gardées")
    truth = cr.crossing_truth(angle)
    scans = cr.crossing_scans(angle, seed)
    fig, axes = new_figure(1, 2, width=10.0, height=3.6, sharey=True)
    from ..multitarget.tracker import multi_target_tracker

    for ax, association, title in zip(axes, ("nn", "jpda"), ("plus proche voisin (NN)", "JPDA")):
        res = multi_target_tracker(tr.radar_model(cr.ACCEL_PSD), scans, detection_probability=cr.DETECTION_PROBABILITY,
                                   clutter_density=cr.CLUTTER_DENSITY, max_speed=tr.MAX_SPEED,
                                   association=association, confirm=tr.CONFIRM, delete_after=tr.DELETE_AFTER)
        for a in range(2):
            ax.plot(truth[:, a, 0] / 1e3, truth[:, a, 1], color="0.6", lw=5, alpha=0.5,
                    label="trajectoires vraies" if a == 0 else None)
        for k, z in enumerate(scans):
            ax.plot(z[:, 0] / 1e3, z[:, 1], "+", color="0.55", ms=4, label="détections" if k == 0 else None)
        tracks = sorted({int(i) for ids in res.ids for i in ids})
        for n, track in enumerate(tracks):
            pts = np.array([x[list(ids).index(track), :2] if track in ids else [np.nan, np.nan]
                            for ids, x in zip(res.ids, res.x)])
            ax.plot(pts[:, 0] / 1e3, pts[:, 1], "-o", ms=3, lw=1.5, color=TRACK_COLOURS[n % len(TRACK_COLOURS)],
                    label=f"piste {track}")
        ax.axvline(0.0, color="black", lw=0.6, ls=":")
        ax.set_xlabel("est (km)")
        ax.set_title(f"{title} : {cr.crossing_outcome(cr.crossing_labels(angle, seed, association))}", fontsize=9)
        ax.set_ylim(-700, 700)
        ax.grid(alpha=0.3)
        ax.legend(loc="upper center", fontsize=7, ncol=3)
    axes[0].set_ylabel("nord (m)")
    return fig


# --------------------------------------------------------------------------- gérer les pistes


@register("pistes-confirmation", chapter=MANAGEMENT_CHAPTER,
          title="Confirmer une piste : « M sur N » pour une vraie cible et pour une piste née du fouillis")
def confirmation_figure():
    from ..scenarios import traffic

    model = traffic.radar_model()
    R = model.R
    dt = traffic.DT
    P_birth = np.block([[R, R / dt], [R / dt, 2.0 * R / dt ** 2]])
    P_pred = model.A @ P_birth @ model.A.T + model.Q
    S = model.C @ P_pred @ model.C.T + model.R
    gamma = gate_threshold(traffic.GATE_PROBABILITY, 2)
    volume = np.pi * gamma * np.sqrt(np.linalg.det(S))
    per_scan = np.logspace(-0.5, 2.5, 200)  # fausses détections par relevé
    density = per_scan / traffic.AREA
    p_false = 1.0 - np.exp(-density * volume)
    p_true = traffic.DETECTION_PROBABILITY * traffic.GATE_PROBABILITY
    fig, ax = new_figure(width=7.0, height=3.8)
    for (M, N), style in zip(((3, 4), (4, 5), (5, 6)), ("-", "--", ":")):
        ax.plot(per_scan, tr.confirmation_probability(p_false, M, N), ls=style, color="crimson", lw=1.8,
                label=f"piste née du fouillis, {M} sur {N}")
        ax.axhline(tr.confirmation_probability(np.array(p_true), M, N), ls=style, color="royalblue", lw=1.4,
                   label=f"vraie cible, {M} sur {N}")
    for density_mark in (3e-8, 1e-7):
        ax.axvline(density_mark * traffic.AREA, color="0.5", lw=0.8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_ylim(1e-6, 2.0)
    ax.set_xlabel("fausses détections par relevé dans la zone (nombre)")
    ax.set_ylabel("probabilité de confirmation (sans unité)")
    ax.set_title(f"Fenêtre de validation d'une piste qui vient de naître : {fr(volume / 1e6, '.2f')} km² "
                 f"(P_G = {fr(traffic.GATE_PROBABILITY, '.2f')}), P_D = {fr(traffic.DETECTION_PROBABILITY, '.1f')}",
                 fontsize=9)
    ax.legend(loc="lower right", fontsize=7, ncol=2)
    ax.grid(alpha=0.3, which="both")
    return fig


@register("pistes-gospa", chapter=MANAGEMENT_CHAPTER,
          title="La GOSPA de chaque relevé sur la scène de Blagnac, décomposée : localisation, cibles manquées, fausses pistes")
def gospa_figure():
    runs = {name: tr.track_scene(name) for name in ("nn", "jpda")}
    fig, axes = new_figure(1, 2, width=10.0, height=3.6, sharey=True)
    t = tr.scan_times()
    for ax, (name, run) in zip(axes, runs.items()):
        ax.stackplot(t, run.localisation, run.missed, run.false, colors=("royalblue", "darkorange", "crimson"),
                     alpha=0.7, labels=("localisation", "cibles manquées", "fausses pistes"))
        ax.plot(t, run.gospa, color="black", lw=1.0, label="GOSPA")
        ax.set_xlabel("temps (s)")
        ax.set_title(f"{name.upper()} : GOSPA moyenne {fr(run.mean_gospa, '.0f')} m", fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize=7)
    axes[0].set_ylabel("GOSPA (m)")
    return fig


# --------------------------------------------------------------------------- TD 8


@register("td-pda", chapter="td-plusieurs-cibles",
          title="TD 8 : la correction PDA à la main — un mélange de trois gaussiennes et sa gaussienne résumée")
def pda_by_hand_figure():
    c = tutorials.PDA_BY_HAND
    step = tutorials.pda_by_hand()
    beta = step.weights
    x0, P0, R = c["x_prior"], c["P_prior"], c["R"]
    S = P0 + R
    K = P0 / S
    z = np.array(c["detections"])
    gamma = gate_threshold(c["P_G"], 1)
    means = np.r_[x0, x0 + K * (z - x0)]
    variances = np.r_[P0, np.full(z.size, (1 - K) * P0)]
    grid = np.linspace(-6.0, 6.0, 1201)
    parts = [b * scipy.stats.norm(m, np.sqrt(v)).pdf(grid) for b, m, v in zip(beta, means, variances)]
    fig, ax = new_figure(width=7.5, height=3.8)
    half = np.sqrt(gamma * S)
    ax.axvspan(x0 - half, x0 + half, color="0.92", label=f"fenêtre (P_G = {fr(c['P_G'], '.1f')})")
    ax.plot(grid, scipy.stats.norm(x0, np.sqrt(P0)).pdf(grid), color="0.4", ls=":", lw=1.5,
            label="prédiction N(0 ; 3)")
    for j, (part, style) in enumerate(zip(parts, ("--", "-.", "-."))):
        ax.plot(grid, part, ls=style, lw=1.2, color=("0.5", "tab:orange", "tab:green")[j],
                label=("β₀ × prédiction" if j == 0 else f"β{j} × Kalman avec z{j}") + f" (β = {fr(beta[j], '.3f')})")
    ax.plot(grid, sum(parts), color="black", lw=2.0, label="loi a posteriori : le mélange")
    ax.plot(grid, scipy.stats.norm(step.x[0], np.sqrt(step.P[0, 0])).pdf(grid), color="tab:blue", lw=2.0,
            label=f"PDA : N({fr(step.x[0], '.3f')} ; {fr(step.P[0, 0], '.3f')})")
    for j, zj in enumerate(z, start=1):
        ax.axvline(zj, color=("tab:orange", "tab:green")[j - 1], lw=1.0)
        ax.annotate(f"z{j} = {fr(zj, '.0f')}", (zj, 0.5), xytext=(4, 0), textcoords="offset points", fontsize=8)
    ax.set_xlabel("position (sans unité)")
    ax.set_ylabel("densité (sans unité)")
    ax.set_xlim(-6.0, 6.0)
    ax.set_ylim(0.0, 0.55)
    ax.legend(loc="upper left", fontsize=7)
    ax.grid(alpha=0.3)
    return fig
