"""Figures des chapitres de pistage : « Plusieurs capteurs, temps irrégulier » (l'hélicoptère SAMU 31,
:mod:`kalman_course.scenarios.helicopter`) et « Cibles qui manœuvrent : filtres adaptatifs et IMM »
(:mod:`kalman_course.scenarios.manoeuvre`)."""

from __future__ import annotations

import numpy as np

from ..numbers import format_spec as fr
from ..scenarios import helicopter as heli
from ..scenarios import manoeuvre as man
from ._geometry import ellipse_points
from ._registry import new_figure, register

SENSORS_CHAPTER = "capteurs-temps-irregulier"
MANOEUVRE_CHAPTER = "cibles-manoeuvrantes"

#: Couleurs : positions mesurées, filtre sur les positions seules, filtre sur les deux capteurs.
MEASURED, POSITION_ONLY, FUSED = "0.45", "tab:orange", "tab:blue"
#: Couleurs des cinq filtres du chapitre des manœuvres.
FILTER_COLORS = {"calme": "tab:green", "agité": "tab:red", "oubli": "tab:purple", "adaptatif": "tab:brown",
                 "IMM": "tab:blue"}


def _grid(ax) -> None:
    ax.grid(alpha=0.3)


def _km(ax, equal: bool = True) -> None:
    ax.set_xlabel("est (km)")
    ax.set_ylabel("nord (km)")
    if equal:
        ax.set_aspect("equal", adjustable="datalim")
    _grid(ax)


def _ellipses(ax, x, P, rows, color, scale=1e-3, n_sigma=2.0, label=None) -> None:
    """Ellipses à ``n_sigma`` écarts-types des positions aux lignes ``rows`` (une seule entrée de légende)."""
    for i, k in enumerate(rows):
        pts = ellipse_points(x[k, :2], P[k, :2, :2], n_sigma) * scale
        ax.plot(pts[:, 0], pts[:, 1], color=color, lw=0.8, alpha=0.8, label=label if i == 0 else None)


# --------------------------------------------------------------------------- capteurs, temps irrégulier


@register("capteurs-helicoptere", chapter=SENSORS_CHAPTER,
          title="Le vol de l'hélicoptère SAMU 31 au-dessus de Toulouse et ses instants de mesure")
def helicopter_flight():
    f = heli.helicopter_track("both").flight
    fig, axes = new_figure(1, 2, width=9.0, height=4.2, gridspec_kw={"width_ratios": [1.15, 1.0]})
    ax = axes[0]
    ax.plot(f.east / 1e3, f.north / 1e3, ".", color="tab:blue", ms=3, label="positions", zorder=3)
    ax.plot(0, 0, "s", color="black", ms=7, label="première position", zorder=4)
    ax.plot(f.east[-1] / 1e3, f.north[-1] / 1e3, "^", color="black", ms=8, label="dernière position", zorder=4)
    track_km = np.column_stack([f.east, f.north]) / 1e3
    placed: list[np.ndarray] = []
    for minute in range(1, int(f.duration // 60) + 1):  # repères de temps le long du vol
        k = int(np.searchsorted(f.t, 60.0 * minute))
        # étiquette à 0,45 km du repère, dans la direction (parmi huit) la plus loin de la trajectoire et
        # des étiquettes déjà posées : l'aller et le retour passent au même endroit (1 et 4 min)
        angles = np.deg2rad(np.arange(0, 360, 45))
        spots = track_km[k] + 0.45 * np.column_stack([np.cos(angles), np.sin(angles)])
        obstacles = np.vstack([track_km] + [np.repeat(q[None], 40, axis=0) for q in placed])
        clearance = [np.min(np.hypot(*(obstacles - spot).T)) for spot in spots]
        spot = spots[int(np.argmax(clearance))]
        placed.append(spot)
        ax.annotate(f"{minute} min", track_km[k], xytext=tuple(spot), textcoords="data", fontsize=8,
                    color="0.2", ha="center", va="center",
                    arrowprops=dict(arrowstyle="-", color="0.5", lw=0.6, shrinkA=0, shrinkB=3))
        ax.plot(f.east[k] / 1e3, f.north[k] / 1e3, "o", color="0.25", ms=4, zorder=4)
    ax.set_title(f"{len(f)} positions ADS-B en {fr(f.duration / 60, '.1f')} min")
    ax.legend(loc="upper right", fontsize=8)
    _km(ax)
    ax = axes[1]
    bins = np.arange(0.0, 8.5, 0.25)
    ax.hist(f.dt, bins=bins, color="tab:blue", alpha=0.75, label="entre deux positions")
    ax.hist(np.diff(f.velocity_t), bins=bins, histtype="step", color="tab:red", lw=1.5,
            label="entre deux vitesses")
    ax.set_xlabel("écart entre deux messages Δt (s)")
    ax.set_ylabel("messages (nombre)")
    ax.set_title(f"Δt des positions de {fr(f.dt.min(), '.2f')} à {fr(f.dt.max(), '.1f')} s")
    ax.legend(fontsize=8)
    _grid(ax)
    return fig


@register("capteurs-incertitude", chapter=SENSORS_CHAPTER,
          title="Écart-type de position prédit et corrigé au fil des messages irréguliers")
def helicopter_uncertainty():
    track = heli.helicopter_track("position")
    res = heli.helicopter_filter("position")
    t = np.asarray(track.t)
    sd_pred = np.sqrt(res.P_pred[:, 0, 0])
    sd_post = np.sqrt(res.P[:, 0, 0])
    keep = t <= 120.0
    # dent de scie : l'écart-type monte pendant chaque attente (prédiction), retombe à chaque mesure
    saw_t = np.repeat(t[keep], 2)
    saw = np.column_stack([sd_pred[keep], sd_post[keep]]).ravel()
    fig, axes = new_figure(2, 1, width=8.0, height=5.2, sharex=True, gridspec_kw={"height_ratios": [2.2, 1.0]})
    ax = axes[0]
    ax.plot(saw_t, saw, color=POSITION_ONLY, lw=1.2, label="écart-type de la position est")
    ax.plot(t[keep], sd_pred[keep], ".", color="tab:red", ms=4, label=r"prédit, $\sqrt{P_{k\mid k-1}}$")
    ax.plot(t[keep], sd_post[keep], ".", color="tab:blue", ms=4, label=r"corrigé, $\sqrt{P_{k\mid k}}$")
    q, sp = heli.fitted_parameters("position")
    ax.axhline(sp, color="0.3", lw=0.8, ls="--", label=f"σ de la mesure appris ({fr(sp, '.1f')} m)")
    ax.set_ylabel("écart-type (m)")
    ax.set_title(f"Positions seules, q = {fr(q, '.1f')} m²/s³ appris : l'attente se paie en incertitude")
    ax.legend(loc="upper right", fontsize=8, ncol=2)
    _grid(ax)
    ax = axes[1]
    ax.vlines(t[keep][1:], 0, np.diff(t[keep]), color="0.4", lw=1.0)
    ax.set_ylabel("Δt (s)")
    ax.set_xlabel("temps (s)")
    _grid(ax)
    return fig


@register("capteurs-deux-capteurs", chapter=SENSORS_CHAPTER,
          title="Positions seules ou positions et vitesses : le silence le plus long et l'erreur de prédiction")
def two_sensors():
    pos_track, both_track = heli.helicopter_track("position"), heli.helicopter_track("both")
    pos, both = heli.helicopter_filter("position"), heli.helicopter_filter("both")
    tp, tb = np.asarray(pos_track.t), np.asarray(both_track.t)
    # le plus long silence des positions après le début (7,2 s, vers t = 319 s)
    k = int(np.argmax(np.where(tp > 60.0, pos_track.dt, 0.0)))
    t_gap = tp[k]
    t0, t1 = tp[k - 1] - 8.0, t_gap + 6.0
    fig, axes = new_figure(1, 2, width=10.0, height=4.8, gridspec_kw={"width_ratios": [1.0, 1.15]})
    ax = axes[0]
    wp, wb = (tp >= t0) & (tp <= t1), (tb >= t0) & (tb <= t1)
    ax.plot(pos_track.y[wp, 0], pos_track.y[wp, 1], "+", color=MEASURED, ms=8, mew=1.5, label="positions mesurées")
    ax.plot(pos.x[wp, 0], pos.x[wp, 1], color=POSITION_ONLY, lw=1.4, label="positions seules")
    ax.plot(both.x[wb, 0], both.x[wb, 1], color=FUSED, lw=1.4, label="positions et vitesses")
    kb = int(np.searchsorted(tb, np.round(t_gap, 3)))
    for res, row, color in ((pos, k, POSITION_ONLY), (both, kb, FUSED)):
        pts = ellipse_points(res.x_pred[row, :2], res.P_pred[row, :2, :2], 2.0)
        ax.plot(pts[:, 0], pts[:, 1], color=color, lw=1.0, ls="--")
        ax.plot(*res.x_pred[row, :2], "o", color=color, mfc="white", ms=7)
    ax.plot(*pos_track.y[k, :2], "*", color="black", ms=12, label=f"position après {fr(pos_track.dt[k], '.1f')} s")
    ax.set_xlabel("est (m)")
    ax.set_ylabel("nord (m)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title(f"Le plus long silence (t = {fr(t_gap, '.0f')} s) : prédictions (○) et ellipses à 2σ",
                 fontsize=9)
    ax.legend(loc="best", fontsize=8)
    _grid(ax)
    ax = axes[1]
    for res, track, color, label in ((pos, pos_track, POSITION_ONLY, "positions seules"),
                                     (both, both_track, FUSED, "positions et vitesses")):
        rows = np.asarray(track.position_rows)
        err = np.hypot(*(np.asarray(track.y)[rows, :2] - res.x_pred[rows, :2]).T)
        rms = heli.prediction_rms(res, track)
        ax.plot(np.asarray(track.t)[rows], err, color=color, lw=1.0,
                label=f"{label} (REQM {fr(rms, '.1f')} m)")
    ax.set_yscale("log")
    ax.set_xlabel("temps (s)")
    ax.set_ylabel("|position mesurée − prédite| (m)")
    ax.set_title("Erreur de prédiction de chaque position", fontsize=9)
    ax.legend(loc="lower left", fontsize=8)
    _grid(ax)
    return fig


@register("capteurs-porte", chapter=SENSORS_CHAPTER,
          title="La fenêtre de validation : six positions aberrantes rejetées, puis une piste perdue derrière sa fenêtre")
def gate_figure():
    track = heli.helicopter_track("position")
    study = heli.gate_study()
    clean = heli.helicopter_filter("position")
    plain = heli.helicopter_filter("position", outliers=True)
    gated = heli.helicopter_filter("position", gate=0.999, outliers=True)
    y_bad = heli.with_outliers(track)
    bad = np.flatnonzero(track.position_rows)[list(heli.OUTLIER_ROWS)]
    fig, axes = new_figure(1, 2, width=10.0, height=4.8)
    ax = axes[0]
    k = bad[0]
    win = slice(max(k - 12, 0), k + 14)
    ax.plot(track.y[win, 0], track.y[win, 1], "+", color=MEASURED, ms=7, label="positions vraies (mesurées)")
    ax.plot(y_bad[k, 0], y_bad[k, 1], "x", color="crimson", ms=10, mew=2, label="position aberrante")
    ax.plot(plain.x[win, 0], plain.x[win, 1], color=POSITION_ONLY, lw=1.5, label="sans fenêtre")
    ax.plot(gated.x[win, 0], gated.x[win, 1], color=FUSED, lw=1.5, ls="--", label="fenêtre de validation p = 0,999")
    ax.set_xlabel("est (m)")
    ax.set_ylabel("nord (m)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title(f"Une position aberrante : écart maximal {fr(study.deviation_plain, '.0f')} m\n"
                 f"sans fenêtre, {fr(study.deviation_gated, '.0f')} m avec", fontsize=9)
    ax.legend(loc="best", fontsize=8)
    _grid(ax)
    ax = axes[1]
    q, sp = heli.fitted_parameters("position")
    quiet = heli.helicopter_filter("position", q / 100.0, sp, gate=0.999)
    ax.plot(track.y[:, 0] / 1e3, track.y[:, 1] / 1e3, "+", color=MEASURED, ms=4, label="positions mesurées")
    ax.plot(clean.x[:, 0] / 1e3, clean.x[:, 1] / 1e3, color=FUSED, lw=1.0, label=f"q appris ({fr(q, '.1f')} m²/s³)")
    ax.plot(quiet.x[:, 0] / 1e3, quiet.x[:, 1] / 1e3, color="crimson", lw=1.4,
            label=f"q / 100, fenêtre p = {fr(0.999, '.3f')}")
    rej = np.asarray(quiet.rejected)
    ax.plot(track.y[rej, 0] / 1e3, track.y[rej, 1] / 1e3, "o", mfc="none", color="crimson", ms=4, alpha=0.6,
            label="positions rejetées")
    ax.set_title(f"Réglé pour la ligne droite : piste perdue à t = {fr(study.lost_at_quiet, '.0f')} s\n"
                 f"(premier virage), jamais retrouvée", fontsize=9)
    ax.legend(loc="lower left", fontsize=8)
    _km(ax, equal=False)
    ax.set_xlim(track.y[:, 0].min() / 1e3 - 1.0, track.y[:, 0].max() / 1e3 + 1.5)
    ax.set_ylim(track.y[:, 1].min() / 1e3 - 1.0, 1.0)
    ax.set_aspect("equal")
    return fig


# --------------------------------------------------------------------------- cibles qui manœuvrent


def _shade_turns(ax, label=True) -> None:
    for i, (start, end, _) in enumerate(man.TURNS):
        ax.axvspan(start, end, color="0.9", zorder=0, label="virages" if (label and i == 0) else None)


@register("manoeuvre-retard", chapter=MANOEUVRE_CHAPTER,
          title="Un filtre réglé pour la ligne droite décroche dans le virage ; réglé pour virer, il suit le bruit des relevés")
def lag_figure():
    st = man.manoeuvre_study()
    truth, y, ex = st.truth, st.y, st.example
    fig, axes = new_figure(1, 2, width=10.0, height=4.4, gridspec_kw={"width_ratios": [1.2, 1.0]})
    ax = axes[0]
    ax.plot(truth[:, 0] / 1e3, truth[:, 1] / 1e3, color="black", lw=2.0, alpha=0.5, label="trajectoire vraie")
    ax.plot(y[:, 0] / 1e3, y[:, 1] / 1e3, "+", color=MEASURED, ms=4, label="relevés radar (σ = 10 m)")
    for name in ("calme", "agité"):
        ax.plot(ex[name].x[:, 0] / 1e3, ex[name].x[:, 1] / 1e3, color=FILTER_COLORS[name], lw=1.3,
                label=f"filtre {name}")
    ax.set_title("Une trajectoire : deux virages à 50 m/s")
    ax.legend(loc="best", fontsize=8)
    _km(ax)
    ax = axes[1]
    _shade_turns(ax)
    for name in ("calme", "agité"):
        i = st.index(name)
        ax.plot(st.t, st.rmse[i], color=FILTER_COLORS[name], lw=1.5, label=f"filtre {name}")
    ax.set_yscale("log")
    ax.set_xlabel("temps (s)")
    ax.set_ylabel("REQM de position (m)")
    ax.set_title(f"Racine de l'erreur quadratique moyenne sur {man.N_RUNS} trajectoires", fontsize=9)
    ax.legend(loc="upper left", fontsize=8)
    _grid(ax)
    return fig


@register("manoeuvre-comparaison", chapter=MANOEUVRE_CHAPTER,
          title="Cinq filtres face aux virages : erreur de position et cohérence (NEES) en Monte-Carlo")
def comparison_figure():
    st = man.manoeuvre_study()
    fig, axes = new_figure(2, 1, width=8.5, height=6.8, sharex=True)
    ax = axes[0]
    _shade_turns(ax)
    for name in st.names:
        ax.plot(st.t, st.rmse[st.index(name)], color=FILTER_COLORS[name], lw=1.4, label=name)
    ax.set_yscale("log")
    ax.set_ylabel("REQM de position (m)")
    ax.set_title(f"Racine de l'erreur quadratique moyenne (REQM) sur {man.N_RUNS} trajectoires")
    ax.legend(loc="upper left", fontsize=8, ncol=3)
    _grid(ax)
    ax = axes[1]
    _shade_turns(ax, label=False)
    lo, hi = st.band
    ax.axhspan(lo, hi, color="tab:green", alpha=0.15, label="filtre cohérent (95 %)")
    for name in st.names:
        ax.plot(st.t, st.nees[st.index(name)], color=FILTER_COLORS[name], lw=1.2)
    ax.axhline(4.0, color="0.3", lw=0.8, ls="--", label="n = 4")
    ax.set_yscale("log")
    ax.set_xlabel("temps (s)")
    ax.set_ylabel("NEES moyenne (sans unité)")
    ax.set_title("Cohérence : l'erreur est-elle celle que P annonce ?")
    ax.legend(loc="upper left", fontsize=8)
    _grid(ax)
    return fig


@register("manoeuvre-imm-helicoptere", chapter=MANOEUVRE_CHAPTER,
          title="L'IMM sur l'hélicoptère : probabilité du régime agité et virages mesurés")
def helicopter_imm_figure():
    h = man.helicopter_imm()
    track = heli.helicopter_track("both")
    rows = np.asarray(track.position_rows)
    res = h.result
    fig, axes = new_figure(1, 2, width=10.0, height=4.4, gridspec_kw={"width_ratios": [1.0, 1.35]})
    ax = axes[0]
    agitated = rows & (res.mu[:, 1] > 0.5)
    quiet = rows & ~(res.mu[:, 1] > 0.5)
    ax.plot(res.x[quiet, 0] / 1e3, res.x[quiet, 1] / 1e3, ".", color="tab:blue", ms=4, label="μ(agité) ≤ 0,5")
    ax.plot(res.x[agitated, 0] / 1e3, res.x[agitated, 1] / 1e3, ".", color="tab:red", ms=4,
            label="μ(agité) > 0,5")
    ax.set_title("Position estimée et régime le plus probable")
    ax.legend(loc="upper right", fontsize=8)
    _km(ax)
    ax = axes[1]
    ax2 = ax.twinx()
    ax2.fill_between(h.t, 0.0, res.mu[:, 1], color="tab:red", alpha=0.3, lw=0, label="μ(agité)")
    ax2.set_ylim(0.0, 1.02)
    ax2.set_ylabel("probabilité du régime agité (sans unité)")
    ax.plot(h.rate_t, np.abs(h.rate), color="black", lw=1.0, label="|vitesse de virage| mesurée")
    ax.set_ylabel("|vitesse de virage| (°/s)")
    ax.set_xlabel("temps (s)")
    ax.set_zorder(ax2.get_zorder() + 1)
    ax.patch.set_visible(False)
    ax.set_title(f"Corrélation {fr(h.correlation, '.2f')} entre μ(agité) et |vitesse de virage|", fontsize=9)
    lines, lines2 = ax.get_legend_handles_labels(), ax2.get_legend_handles_labels()
    ax.legend(lines[0] + lines2[0], lines[1] + lines2[1], loc="upper center", bbox_to_anchor=(0.5, -0.16),
              ncol=2, fontsize=8)
    _grid(ax)
    return fig


@register("manoeuvre-imm-virage", chapter=MANOEUVRE_CHAPTER,
          title="L'IMM vitesse constante / virage coordonné sur l'hélicoptère : vitesse de rotation estimée "
                "et probabilités des régimes")
def helicopter_turn_imm_figure():
    h = man.helicopter_turn_imm()
    cvcv = man.helicopter_imm()
    res = h.result
    fig, axes = new_figure(2, 1, width=9.0, height=6.2, sharex=True)
    ax = axes[0]
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.plot(h.rate_t, h.rate, color="black", lw=1.0, label="mesurée (messages de vitesse)")
    ax.plot(h.t, np.rad2deg(res.x[:, 4]), color="tab:blue", lw=1.3, label="estimée par l'IMM CV/CT, ω̂")
    ax.set_ylabel("vitesse de rotation ω (°/s)")
    ax.set_title(f"Vitesse de rotation, positive vers la gauche : corrélation {fr(h.rate_correlation, '.2f')}",
                 fontsize=9)
    ax.legend(loc="lower left", fontsize=8, ncol=2)
    _grid(ax)
    ax = axes[1]
    ax.fill_between(h.t, 0.0, res.mu[:, 1], color="tab:blue", alpha=0.3, lw=0, label="μ(virage), IMM CV/CT")
    ax.plot(cvcv.t, cvcv.result.mu[:, 1], color="tab:red", lw=1.0, label="μ(agité), IMM CV/CV")
    ax.set_ylim(0.0, 1.02)
    ax.set_ylabel("probabilité du régime (sans unité)")
    ax.set_xlabel("temps (s)")
    ax.set_title(f"Corrélation avec |ω| mesurée : {fr(h.correlation, '.2f')} (virage), "
                 f"{fr(h.correlation_cvcv, '.2f')} (agité)", fontsize=9)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.22), ncol=2, fontsize=8)
    _grid(ax)
    return fig


__all__ = ["helicopter_flight", "helicopter_uncertainty", "two_sensors", "gate_figure", "lag_figure",
           "comparison_figure", "helicopter_imm_figure", "helicopter_turn_imm_figure"]
