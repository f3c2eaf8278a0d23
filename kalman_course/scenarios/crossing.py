r"""Deux avions qui se croisent sous un petit angle : quand l'association échange les pistes (chapitre
« Fouillis et association »).

Deux avions volent en ligne droite à :data:`SPEED` m/s et se croisent sous l'angle :math:`\theta` au centre
de la scène, à :math:`t` = :data:`CROSSING_TIME` s. Le radar de la scène de Blagnac
(:mod:`~kalman_course.scenarios.traffic` : relevé toutes les 5 s, bruit de 50 m par axe) les voit avec la
probabilité :data:`DETECTION_PROBABILITY`, dans un fouillis de densité :data:`CLUTTER_DENSITY` sur un rectangle
de 14 km sur 4 km. Le pisteur est réglé pour la ligne droite (densité :data:`ACCEL_PSD`).

On juge chaque tirage sur les numéros de piste couplés aux deux avions par la GOSPA, :data:`BEFORE` relevés
avant le croisement et au dernier relevé : **gardées** (mêmes numéros), **échangées** (numéros croisés), ou
**autre** (une piste perdue, ou les deux pistes confondues sur un seul avion). Les quatre associations
voient les mêmes relevés (graine du tirage).
"""

from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

import numpy as np

from ..core.results import freeze
from ..multitarget.metrics import gospa
from ..multitarget.tracker import ASSOCIATIONS, multi_target_tracker
from . import traffic

__all__ = ["SPEED", "CROSSING_TIME", "N_SCANS", "BOX", "DETECTION_PROBABILITY", "CLUTTER_DENSITY", "ACCEL_PSD",
           "BEFORE", "ANGLE", "RUNS", "OUTCOMES", "crossing_truth", "crossing_scans", "crossing_labels",
           "crossing_outcome", "CrossingStudy", "crossing_study"]

#: Vitesse des deux avions (m/s), instant du croisement (s) et nombre de relevés (de 0 à 150 s).
SPEED = 80.0
CROSSING_TIME = 75.0
N_SCANS = 31
#: Rectangle du fouillis (m) : 14 km sur 4 km, centré sur le croisement.
BOX = (14000.0, 4000.0)
#: Réglages du radar et du pisteur.
DETECTION_PROBABILITY = 0.9
CLUTTER_DENSITY = 2e-8
ACCEL_PSD = 1.0
#: Les numéros sont relevés ce nombre de relevés avant le croisement (35 s : à 8°, les avions sont encore à 390 m
#: l'un de l'autre, hors de leurs portes).
BEFORE = 7
#: Angle de croisement (degrés) et nombre de tirages de l'étude.
ANGLE = 8.0
RUNS = 30
#: Issues d'un tirage.
OUTCOMES = ("gardées", "échangées", "autre")


def crossing_truth(angle: float) -> np.ndarray:
    r"""Positions vraies (K, 2, 2) m des deux avions, symétriques par rapport à l'axe est, qui se croisent à
    l'origine sous l'angle ``angle`` (degrés) à :data:`CROSSING_TIME`."""
    t = traffic.DT * np.arange(N_SCANS) - CROSSING_TIME
    half = np.radians(angle) / 2.0
    along, across = SPEED * np.cos(half) * t, SPEED * np.sin(half) * t
    return np.stack([np.column_stack([along, across]), np.column_stack([along, -across])], axis=1)


def crossing_scans(angle: float, seed: int) -> tuple[np.ndarray, ...]:
    """Les relevés d'un tirage : détections des deux avions (bruit de 50 m par axe, probabilité de détection
    :data:`DETECTION_PROBABILITY`) et fouillis poissonnien uniforme sur :data:`BOX`."""
    rng = np.random.default_rng([seed, 37])
    truth = crossing_truth(angle)
    width, height = BOX
    scans = []
    for k in range(N_SCANS):
        seen = rng.uniform(size=2) < DETECTION_PROBABILITY
        noise = traffic.NOISE_STD * rng.standard_normal((2, 2))
        n_false = rng.poisson(CLUTTER_DENSITY * width * height)
        false = np.column_stack([rng.uniform(-width / 2, width / 2, n_false),
                                 rng.uniform(-height / 2, height / 2, n_false)])
        scans.append(freeze(np.vstack([(truth[k] + noise)[seen], false])))
    return tuple(scans)


def crossing_labels(angle: float, seed: int, association: str) -> np.ndarray:
    """Numéros de piste couplés aux deux avions par la GOSPA (coupure 1 km), relevé par relevé (K, 2) ; −1 :
    aucune piste."""
    truth = crossing_truth(angle)
    tracks = multi_target_tracker(traffic.radar_model(ACCEL_PSD), crossing_scans(angle, seed),
                                  detection_probability=DETECTION_PROBABILITY, clutter_density=CLUTTER_DENSITY,
                                  max_speed=traffic.MAX_SPEED, association=association, confirm=traffic.CONFIRM,
                                  delete_after=traffic.DELETE_AFTER)
    labels = np.full((N_SCANS, 2), -1)
    for k in range(N_SCANS):
        g = gospa(truth[k], tracks.x[k][:, :2], c=traffic.GOSPA_CUTOFF, p=1)
        matched = g.assignment >= 0
        labels[k, matched] = tracks.ids[k][g.assignment[matched]]
    return labels


def crossing_outcome(labels: np.ndarray) -> str:
    """« gardées », « échangées » ou « autre » (voir l'en-tête du module)."""
    k = int(CROSSING_TIME / traffic.DT) - BEFORE
    before, after = labels[k], labels[-1]
    if np.all(before >= 0) and before[0] != before[1]:
        if np.array_equal(after, before):
            return OUTCOMES[0]
        if np.array_equal(after, before[::-1]):
            return OUTCOMES[1]
    return OUTCOMES[2]


class CrossingStudy(NamedTuple):
    """Résultat de :func:`crossing_study` : ``counts[association]`` = nombres de tirages (gardées, échangées,
    autre) ; ``angle`` (degrés) et ``runs``."""

    counts: dict
    angle: float
    runs: int


@lru_cache(maxsize=8)
def crossing_study(angle: float = ANGLE, runs: int = RUNS) -> CrossingStudy:
    """Les ``runs`` tirages de deux avions qui se croisent sous ``angle``, pistés par les quatre associations
    sur les mêmes relevés."""
    counts = {}
    for association in ASSOCIATIONS:
        outcomes = [crossing_outcome(crossing_labels(angle, seed, association)) for seed in range(runs)]
        counts[association] = tuple(outcomes.count(o) for o in OUTCOMES)
    return CrossingStudy(counts, angle, runs)
