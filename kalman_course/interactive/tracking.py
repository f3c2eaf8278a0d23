r"""Curseurs des chapitres de pistage.

* « Plusieurs capteurs, temps irrégulier » — la **fenêtre de validation** (probabilité :math:`p`) et la **densité**
  :math:`q` du filtre sur l'hélicoptère SAMU 31, dont six positions ont été corrompues
  (:mod:`kalman_course.scenarios.helicopter`) : la trajectoire estimée et ses ellipses dans le plan, les
  positions rejetées, la NIS de chaque position et le seuil de la fenêtre.
* « Cibles qui manœuvrent » — le **facteur d'oubli** :math:`\alpha` sur la cible simulée qui vire, et
  l'**IMM** : probabilité de changer de régime et densités des deux régimes
  (:mod:`kalman_course.scenarios.manoeuvre`).
"""

from __future__ import annotations


import numpy as np

from ..diagnostics.consistency import nis
from ..filters.gating import gate_threshold
from ..filters.imm import imm_filter
from ..filters.kalman import kalman_filter
from ..scenarios import helicopter as heli
from ..scenarios import manoeuvre as man
from ..numbers import format_number
from .figure import SliderSpec, ellipse_outline, number, register_sliders
from .grid import ParameterAxis
from .spec import Follow, Glyph, Panel

__all__ = ["GATES", "Q_FACTORS", "gate_axes", "gate_run", "gate_spec", "FADINGS", "fading_axes", "fading_run",
           "fading_spec", "SWITCHES", "QUIET_DENSITIES", "MANOEUVRE_DENSITIES", "imm_axes", "imm_run", "imm_spec"]

SENSORS_CHAPTER = "capteurs-temps-irregulier"
MANOEUVRE_CHAPTER = "cibles-manoeuvrantes"

#: Probabilités de la porte proposées ; la dernière position (1) : pas de porte.
GATES = (0.9, 0.99, 0.999, 0.9999, 1.0)
#: Facteurs appliqués à la densité apprise.
Q_FACTORS = (0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0)
#: Une ellipse (2σ) toutes les ``ELLIPSE_EVERY`` positions.
ELLIPSE_EVERY = 6


def _joined(curves) -> tuple[np.ndarray, np.ndarray]:
    """Plusieurs contours ``(x, y)`` réunis en une seule série, séparés par NaN (un seul tracé)."""
    xs, ys = [], []
    for x, y in curves:
        xs += [x, [np.nan]]
        ys += [y, [np.nan]]
    return np.concatenate(xs), np.concatenate(ys)


# --------------------------------------------------------------------------- porte et densité


def gate_axes() -> tuple[ParameterAxis, ParameterAxis]:
    """La fenêtre de validation :math:`p` (0,9 à 0,9999, ou aucune) et la densité :math:`q` (0,01 à 10 fois l'apprise)."""
    q_fit = heli.fitted_parameters("position")[0]
    return (
        ParameterAxis("gate", "p", "fenêtre de validation", "", np.array(GATES), default=2, scale="index",
                      tick_labels=tuple(format_number(g, significant=5, trim=True) for g in GATES[:-1])
                      + ("sans fenêtre",)),
        ParameterAxis("q", "q", "densité d'accélération", "m²/s³", q_fit * np.array(Q_FACTORS),
                      default=Q_FACTORS.index(1.0)),
    )


def gate_run(gate: float, q: float) -> dict[str, np.ndarray]:
    """Le filtre (positions seules, six positions corrompues) avec la fenêtre ``gate`` (1 : aucune) et la
    densité ``q`` : estimation, ellipses à 2σ, positions rejetées, NIS et seuil."""
    track = heli.helicopter_track("position")
    sp = heli.fitted_parameters("position")[1]
    y = heli.with_outliers(track)
    res = kalman_filter(heli.helicopter_model(track, q, sp), y, track.x0, track.P0,
                        gate=None if gate >= 1.0 else gate)
    rej = np.asarray(res.rejected)
    ell = _joined(ellipse_outline(res.x[k, :2], res.P[k, :2, :2], 2.0, n_points=25)
                  for k in range(0, len(y), ELLIPSE_EVERY))
    threshold = np.nan if gate >= 1.0 else gate_threshold(gate, 2)
    return {
        "est_e": res.x[:, 0] / 1e3, "est_n": res.x[:, 1] / 1e3,
        "ell_e": ell[0] / 1e3, "ell_n": ell[1] / 1e3,
        "rej_e": np.where(rej, y[:, 0], np.nan) / 1e3, "rej_n": np.where(rej, y[:, 1], np.nan) / 1e3,
        "nis": nis(res), "threshold": np.full(len(y), threshold),
        "n_rejected": np.array([rej.sum()]),
        "n_outliers": np.array([rej[np.flatnonzero(track.position_rows)[list(heli.OUTLIER_ROWS)]].sum()]),
        "rms": np.array([heli.prediction_rms(res, track)]),
        "lost": np.array([heli.lost_track_time(res, track) or np.nan]),
    }


def _gate_readout(series, values) -> str:
    lost = series["lost"][0]
    where = "jamais perdue" if np.isnan(lost) else f"perdue à t = {number(lost, 's')}"
    return (f"Positions rejetées : {int(series['n_rejected'][0])} sur 278, dont {int(series['n_outliers'][0])} "
            f"des 6 aberrantes ; REQM de prédiction des positions : {number(series['rms'][0], 'm')} ; "
            f"piste {where}.")


#: Agrandissement : les deux positions aberrantes consécutives (lignes 80 et 81 de :data:`~.helicopter.OUTLIER_ROWS`),
#: à ± ``ZOOM_HALF_WIDTH`` km en est.
ZOOM_ROWS, ZOOM_HALF_WIDTH = (1, 2), 0.35


@register_sliders("capteurs-porte-curseurs", chapter=SENSORS_CHAPTER)
def gate_spec() -> SliderSpec:
    """La fenêtre de validation et la densité, au curseur, sur l'hélicoptère aux six positions corrompues ;
    un agrandissement montre le crochet de l'estimation vers deux positions aberrantes consécutives."""
    track = heli.helicopter_track("position")
    y = heli.with_outliers(track)
    bad = np.flatnonzero(track.position_rows)[list(heli.OUTLIER_ROWS)]
    e, n = np.asarray(track.y)[:, 0] / 1e3, np.asarray(track.y)[:, 1] / 1e3
    zoom = np.asarray(track.y)[bad[list(ZOOM_ROWS)], :2].mean(axis=0) / 1e3
    def plane(zoom: bool) -> tuple[Glyph, ...]:
        """Les tracés du plan ; dans l'agrandissement, coupés par son cadre et sans légende (la même)."""
        def name(text: str) -> str:
            return "" if zoom else text
        return (
            Glyph("meas_n", "scatter", "gray", name("positions mesurées"), x="meas_e", marker="cross", size=5,
                  clip=zoom),
            Glyph("ell_n", "line", "royalblue", name("ellipses à 2σ"), x="ell_e", width=1.0, alpha=0.7, clip=zoom),
            Glyph("est_n", "line", "darkorange", name("estimation"), x="est_e", width=1.8, clip=zoom),
            Glyph("rej_n", "scatter", "black", name("positions rejetées"), x="rej_e", marker="circle", size=9,
                  clip=zoom),
            Glyph("out_n", "scatter", "crimson", name("positions aberrantes"), x="out_e", marker="x", size=11,
                  clip=zoom),
        )
    return SliderSpec(
        name="capteurs-porte-curseurs",
        chapter=SENSORS_CHAPTER,
        title="Hélicoptère SAMU 31, six positions corrompues : fenêtre de validation p et densité q du filtre",
        x_label="temps (s)",
        axes=gate_axes(),
        run=gate_run,
        time=np.asarray(track.t),
        panels=(
            Panel("Estimation, ellipses à 2σ (une sur six)", "nord (km)", plane(False),
                  x_label="est (km)", x_range=(-1.5, 5.5), y_range=Follow(aspect=7.0 / 7.8, margin=0.04),
                  equal_aspect=True, width=400, height=370),  # une piste perdue part loin : le plan la suit
            Panel("Agrandissement : deux positions aberrantes consécutives", "nord (km)", plane(True),
                  x_label="est (km)", x_range=(zoom[0] - ZOOM_HALF_WIDTH, zoom[0] + ZOOM_HALF_WIDTH),
                  y_range=(zoom[1] - 0.3, zoom[1] + 0.3), equal_aspect=True, width=400, height=340),
            Panel("NIS de chaque position et seuil de la fenêtre", "NIS (sans unité)", (
                Glyph("nis", "scatter", "darkorange", "NIS", marker="dot", size=6),
                Glyph("threshold", "line", "black", "seuil χ²₂(p)", dash="dashed", width=1.5),
            ), y_log=True, y_range=(1e-4, 1e6), height=220),
        ),
        fixed={"meas_e": e, "meas_n": n, "out_e": y[bad, 0] / 1e3, "out_n": y[bad, 1] / 1e3},
        readout=_gate_readout,
    )


# --------------------------------------------------------------------------- mémoire évanescente

#: Facteurs d'oubli proposés.
FADINGS = (1.0, 1.02, 1.05, 1.1, 1.2, 1.3, 1.5, 2.0)


def fading_axes() -> tuple[ParameterAxis]:
    """Le facteur :math:`\\alpha` de 1 (filtre calme ordinaire) à 2."""
    return (ParameterAxis("alpha", "α", "facteur d'oubli", "", np.array(FADINGS), default=FADINGS.index(man.FADING),
                          scale="index", tick_labels=tuple(number(a) for a in FADINGS)),)


def _segments_rms(err: np.ndarray) -> tuple[float, float]:
    st = man.manoeuvre_example()
    straight = (st.t > 10.0) & ~st.turning
    return float(np.sqrt(np.mean(err[straight] ** 2))), float(np.sqrt(np.mean(err[st.turning] ** 2)))


def fading_run(alpha: float) -> dict[str, np.ndarray]:
    """Le filtre calme avec l'oubli ``alpha`` sur la trajectoire d'exemple : estimation et erreur."""
    st = man.manoeuvre_example()
    res = kalman_filter(man.cv_model(man.Q_QUIET), st.y, man.X0, man.P0, fading=None if alpha == 1.0 else alpha)
    err = np.hypot(*(res.x[:, :2] - st.truth[:, :2]).T)
    straight, turn = _segments_rms(err)
    return {"est_e": res.x[:, 0] / 1e3, "est_n": res.x[:, 1] / 1e3, "err": err,
            "sd": 2.0 * np.sqrt(res.P[:, 0, 0] + res.P[:, 1, 1]),
            "rms": np.array([straight, turn])}


def _fading_readout(series, values) -> str:
    straight, turn = series["rms"]
    return (f"REQM de position : {number(straight, 'm')} en ligne droite, "
            f"{number(turn, 'm')} dans les virages (et les 10 s qui suivent).")


def _plane_glyphs(estimate_legend: str) -> tuple[Glyph, ...]:
    return (
        Glyph("true_n", "line", "black", "trajectoire vraie", x="true_e", width=3.0, alpha=0.4),
        Glyph("meas_n", "scatter", "gray", "relevés radar", x="meas_e", marker="cross", size=5),
        Glyph("est_n", "line", "darkorange", estimate_legend, x="est_e", width=1.8),
    )


#: Hauteur (m) des surfaces « virages » : bien au-delà de l'axe, elles le couvrent en entier (tracé ``clip``).
TURN_BAND = 1e5


def _example_fixed() -> dict[str, np.ndarray]:
    st = man.manoeuvre_example()
    return {"true_e": st.truth[:, 0] / 1e3, "true_n": st.truth[:, 1] / 1e3, "meas_e": st.y[:, 0] / 1e3,
            "meas_n": st.y[:, 1] / 1e3, "turn": TURN_BAND * (man.turn_rate_profile(st.t - man.DT) != 0)}


_PLANE = dict(x_label="est (km)", x_range=(-0.3, 3.3), y_range=(-0.3, 3.7), equal_aspect=True, width=400,
              height=400)


@register_sliders("manoeuvre-oubli-curseurs", chapter=MANOEUVRE_CHAPTER)
def fading_spec() -> SliderSpec:
    """Le facteur d'oubli au curseur, sur la cible simulée qui vire."""
    st = man.manoeuvre_example()
    return SliderSpec(
        name="manoeuvre-oubli-curseurs",
        chapter=MANOEUVRE_CHAPTER,
        title="Cible simulée qui vire deux fois : filtre calme (q = 0,05 m²/s³) à mémoire évanescente α",
        x_label="temps (s)",
        axes=fading_axes(),
        run=fading_run,
        time=st.t,
        panels=(
            Panel("Dans le plan", "nord (km)", _plane_glyphs("estimation avec oubli"), **_PLANE),
            Panel("Erreur de position et son 2σ annoncé", "erreur (m)", (
                Glyph("turn", "area", "gray", "virages", alpha=0.6, clip=True),  # toute la hauteur
                Glyph("sd", "line", "royalblue", "2σ annoncé", dash="dashed", width=1.5),
                Glyph("err", "line", "darkorange", "erreur de position", width=1.6),
            ), y_log=False, y_range=Follow(include=(0.0,)), height=230),  # sans oubli, l'erreur passe 120 m
        ),
        fixed=_example_fixed(),
        readout=_fading_readout,
    )


# --------------------------------------------------------------------------- IMM

#: Probabilités de changer de régime à chaque pas.
SWITCHES = (0.005, 0.02, 0.05, 0.2)
#: Densités (m²/s³) du régime calme et du régime agité.
QUIET_DENSITIES = (0.005, 0.05, 0.5, 5.0)
MANOEUVRE_DENSITIES = (2.0, 20.0, 200.0, 2000.0)


def imm_axes() -> tuple[ParameterAxis, ParameterAxis, ParameterAxis]:
    """Probabilité de changer de régime, densité du régime calme, densité du régime agité."""
    return (
        ParameterAxis("switch", "π", "changement de régime", "", np.array(SWITCHES),
                      default=SWITCHES.index(man.SWITCH)),
        ParameterAxis("q_quiet", "q₁", "régime calme", "m²/s³", np.array(QUIET_DENSITIES),
                      default=QUIET_DENSITIES.index(man.Q_QUIET)),
        ParameterAxis("q_manoeuvre", "q₂", "régime agité", "m²/s³", np.array(MANOEUVRE_DENSITIES),
                      default=MANOEUVRE_DENSITIES.index(man.Q_MANOEUVRE)),
    )


def imm_run(switch: float, q_quiet: float, q_manoeuvre: float) -> dict[str, np.ndarray]:
    """L'IMM sur la trajectoire d'exemple : probabilité du régime agité, erreur et estimation."""
    st = man.manoeuvre_example()
    res = imm_filter([man.cv_model(q_quiet), man.cv_model(q_manoeuvre)], st.y, man.X0, man.P0,
                     transition=man.imm_transition(switch), mu0=[1.0 - switch, switch])
    err = np.hypot(*(res.x[:, :2] - st.truth[:, :2]).T)
    straight, turn = _segments_rms(err)
    return {"mu": res.mu[:, 1], "err": err, "est_e": res.x[:, 0] / 1e3, "est_n": res.x[:, 1] / 1e3,
            "rms": np.array([straight, turn])}


def _imm_readout(series, values) -> str:
    straight, turn = series["rms"]
    return (f"REQM de position : {number(straight, 'm')} en ligne droite, "
            f"{number(turn, 'm')} dans les virages ; probabilité moyenne du régime agité "
            f"{number(float(np.mean(series['mu'])), significant=2)}.")


@register_sliders("manoeuvre-imm-curseurs", chapter=MANOEUVRE_CHAPTER)
def imm_spec() -> SliderSpec:
    """L'IMM au curseur : probabilité de changer de régime et densités des deux régimes."""
    st = man.manoeuvre_example()
    return SliderSpec(
        name="manoeuvre-imm-curseurs",
        chapter=MANOEUVRE_CHAPTER,
        title="IMM à deux régimes (calme, agité) sur la cible simulée qui vire",
        x_label="temps (s)",
        axes=imm_axes(),
        run=imm_run,
        time=st.t,
        panels=(
            Panel("Probabilité du régime agité et virages vrais", "probabilité (sans unité)", (
                Glyph("turn_scaled", "area", "gray", "virage en cours (vrai)", alpha=0.6),
                Glyph("mu", "line", "crimson", "μ(agité)", width=1.8),
            ), y_range=(0.0, 1.05), height=210),
            Panel("Erreur de position", "erreur (m)", (
                Glyph("err", "line", "darkorange", "IMM", width=1.6),
            ), y_range=(0.0, 60.0), height=200),
        ),
        fixed={"turn_scaled": (man.turn_rate_profile(st.t - man.DT) != 0).astype(float)},
        readout=_imm_readout,
    )
