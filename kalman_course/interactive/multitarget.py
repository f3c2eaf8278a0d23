r"""Curseurs de la partie « Plusieurs cibles », sur le trafic réel de Toulouse-Blagnac vu par un radar
(:mod:`kalman_course.scenarios.traffic`).

* « Fouillis et association » — la **méthode d'association** (NN, GNN, PDA, JPDA), la **densité du fouillis**
  et la **probabilité de détection** ;
* « Gérer les pistes » — la **probabilité de la fenêtre de validation**, la densité du fouillis et la **règle de
  confirmation** « M sur N » (pisteur JPDA).

Les deux figures montrent les pistes confirmées dans le plan, de la couleur de l'avion qu'elles ont suivi
d'abord (les fausses pistes en points noirs), et la GOSPA de chaque relevé avec ses trois composantes.
"""

from __future__ import annotations

import numpy as np

from ..multitarget.tracker import ASSOCIATIONS
from ..scenarios import traffic as tr
from .figure import SliderSpec, number, register_sliders
from .grid import ParameterAxis
from .spec import Follow, Glyph, Panel

__all__ = ["ASSOCIATION_LABELS", "CLUTTER_DENSITIES", "DETECTION_PROBABILITIES", "GATE_PROBABILITIES", "CONFIRM_RULES",
           "association_axes", "association_run", "association_spec", "management_axes", "management_run",
           "management_spec", "AIRCRAFT_COLOURS"]

ASSOCIATION_CHAPTER = "fouillis-association"
MANAGEMENT_CHAPTER = "gestion-pistes"

#: Les méthodes d'association, dans l'ordre du curseur.
ASSOCIATION_LABELS = ("NN", "GNN", "PDA", "JPDA")
#: Densités du fouillis proposées (par m² et par relevé) : 2,2, 13 et 44 fausses détections par relevé.
CLUTTER_DENSITIES = (5e-9, 3e-8, 1e-7)
#: Probabilités de détection proposées.
DETECTION_PROBABILITIES = (0.6, 0.9)
#: Probabilités de la porte proposées (à 0,999, avec 44 fausses détections par relevé et une confirmation 3 sur
#: 4, les fausses pistes s'agglutinent en grappes que la JPDA exacte ne peut plus énumérer).
GATE_PROBABILITIES = (0.9, 0.95, 0.99)
#: Règles de confirmation « M sur N » proposées.
CONFIRM_RULES = ((3, 4), (4, 5), (5, 6))
#: Bornes du plan (km) : la zone surveillée et une marge, où s'égarent quelques pistes.
PLANE_EAST = (-9.0, 21.0)
PLANE_NORTH = (-15.0, 6.0)
#: Couleurs des cinq avions (trajectoire vraie en clair, pistes en trait plein).
AIRCRAFT_COLOURS = ("royalblue", "darkorange", "seagreen", "crimson", "purple")


def _per_scan(density: float) -> str:
    return number(density * tr.AREA, significant=2)


def _clutter_axis() -> ParameterAxis:
    return ParameterAxis("clutter", "λ", "densité du fouillis (fausses détections par relevé)", "m⁻²",
                         np.array(CLUTTER_DENSITIES), default=1, scale="index",
                         tick_labels=tuple(_per_scan(v) for v in CLUTTER_DENSITIES))


def association_axes() -> tuple[ParameterAxis, ParameterAxis, ParameterAxis]:
    """Méthode d'association (indice dans :data:`ASSOCIATION_LABELS`), densité du fouillis, :math:`P_D`."""
    return (
        ParameterAxis("method", "assoc.", "méthode d'association", "", np.arange(len(ASSOCIATIONS), dtype=float),
                      default=3, scale="index", tick_labels=ASSOCIATION_LABELS),
        _clutter_axis(),
        ParameterAxis("pd", "P_D", "probabilité de détection", "", np.array(DETECTION_PROBABILITIES), default=1,
                      scale="index", tick_labels=tuple(number(p) for p in DETECTION_PROBABILITIES)),
    )


def _series(run: tr.TrackingRun) -> dict[str, np.ndarray]:
    return {**tr.track_series(run), "gospa": run.gospa, "localisation": run.localisation, "missed": run.missed,
            "false": run.false,
            "summary": np.array([run.mean_gospa, run.localisation.mean(), run.missed.mean(), run.false.mean(),
                                 run.n_tracks, run.identity_changes])}


def association_run(method: float, clutter: float, pd: float) -> dict[str, np.ndarray]:
    """Le pisteur (méthode ``ASSOCIATIONS[method]``) sur la scène : pistes et GOSPA."""
    return _series(tr.track_scene(ASSOCIATIONS[int(method)], pd, clutter))


def _readout(series, values) -> str:
    mean, loc, missed, false, n_tracks, changes = series["summary"]
    n_tracks, changes = int(n_tracks), int(changes)
    return (f"GOSPA moyenne : {number(mean, 'm')} (localisation {number(loc, 'm')}, cibles manquées "
            f"{number(missed, 'm')}, fausses pistes {number(false, 'm')}) ; {n_tracks} piste{'s' * (n_tracks > 1)} "
            f"confirmée{'s' * (n_tracks > 1)} pour 5 avions ; {changes} changement{'s' * (changes > 1)} "
            f"d'identité ; {_per_scan(values[1])} fausses détections par relevé en moyenne.")


def _plane_glyphs() -> tuple[Glyph, ...]:
    glyphs = [Glyph("region_n", "line", "gray", "zone surveillée", x="region_e", width=1.0, dash="dashed")]
    names = tr.truth_names()
    for a, colour in enumerate(AIRCRAFT_COLOURS):
        glyphs.append(Glyph(f"true{a}_n", "line", colour, "", x=f"true{a}_e", width=7.0, alpha=0.25))
    for a, colour in enumerate(AIRCRAFT_COLOURS):
        glyphs.append(Glyph(f"a{a}_n", "line", colour, f"pistes de {names[a]}", x=f"a{a}_e", width=1.8))
    glyphs.append(Glyph("false_n", "scatter", "black", "fausses pistes", x="false_e", marker="dot", size=6))
    return tuple(glyphs)


def _panels() -> tuple[Panel, ...]:
    return (
        Panel("Pistes confirmées (trajectoires vraies en clair)", "nord (km)", _plane_glyphs(), x_label="est (km)",
              x_range=PLANE_EAST, y_range=PLANE_NORTH, equal_aspect=True, width=460),
        Panel("GOSPA de chaque relevé et ses composantes (p = 1, c = 1 km)", "GOSPA (m)", (
            Glyph("gospa", "line", "black", "GOSPA", width=2.0),
            Glyph("localisation", "line", "royalblue", "localisation", width=1.5),
            Glyph("missed", "line", "darkorange", "cibles manquées", width=1.5, dash="dashed"),
            Glyph("false", "line", "crimson", "fausses pistes", width=1.5, dash="dotted"),
        ), y_range=Follow(include=(0.0,)), height=230),
    )


def _fixed() -> dict[str, np.ndarray]:
    truth = tr.truth()
    e0, e1, n0, n1 = (v / 1e3 for v in tr.REGION)
    out = {"region_e": np.array([e0, e1, e1, e0, e0]), "region_n": np.array([n0, n0, n1, n1, n0])}
    for a in range(truth.shape[1]):
        out[f"true{a}_e"], out[f"true{a}_n"] = truth[:, a, 0] / 1e3, truth[:, a, 1] / 1e3
    return out


@register_sliders("association-curseurs", chapter=ASSOCIATION_CHAPTER)
def association_spec() -> SliderSpec:
    """Méthode d'association, densité du fouillis et probabilité de détection, sur la scène de Blagnac."""
    return SliderSpec(
        name="association-curseurs",
        chapter=ASSOCIATION_CHAPTER,
        title="Cinq avions autour de Toulouse-Blagnac vus par un radar : méthode d'association, fouillis, P_D",
        x_label="temps (s)",
        axes=association_axes(),
        run=association_run,
        time=tr.scan_times(),
        panels=_panels(),
        fixed=_fixed(),
        readout=_readout,
    )


# --------------------------------------------------------------------------- gestion des pistes


def management_axes() -> tuple[ParameterAxis, ParameterAxis, ParameterAxis]:
    """Probabilité de la porte, densité du fouillis, règle de confirmation (indice dans :data:`CONFIRM_RULES`)."""
    return (
        ParameterAxis("gate", "P_G", "probabilité de la fenêtre", "", np.array(GATE_PROBABILITIES), default=2,
                      scale="index", tick_labels=tuple(number(p, significant=4) for p in GATE_PROBABILITIES)),
        _clutter_axis(),
        ParameterAxis("confirm", "M/N", "confirmation : M touches sur N relevés", "",
                      np.arange(len(CONFIRM_RULES), dtype=float), default=1, scale="index",
                      tick_labels=tuple(f"{m} sur {n}" for m, n in CONFIRM_RULES)),
    )


def management_run(gate: float, clutter: float, confirm: float) -> dict[str, np.ndarray]:
    """Le pisteur JPDA sur la scène, avec la porte ``gate`` et la confirmation ``CONFIRM_RULES[confirm]``."""
    return _series(tr.track_scene("jpda", tr.DETECTION_PROBABILITY, clutter, gate, CONFIRM_RULES[int(confirm)]))


@register_sliders("pistes-curseurs", chapter=MANAGEMENT_CHAPTER)
def management_spec() -> SliderSpec:
    """Probabilité de la porte, densité du fouillis et confirmation M sur N, pisteur JPDA."""
    return SliderSpec(
        name="pistes-curseurs",
        chapter=MANAGEMENT_CHAPTER,
        title="Gérer les pistes de la scène de Blagnac (JPDA, P_D = 0,9) : fenêtre de validation, fouillis, confirmation M sur N",
        x_label="temps (s)",
        axes=management_axes(),
        run=management_run,
        time=tr.scan_times(),
        panels=_panels(),
        fixed=_fixed(),
        readout=_readout,
    )
