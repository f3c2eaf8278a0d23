r"""Le trafic de Toulouse-Blagnac vu par un radar : les expériences de la partie « Plusieurs cibles », écrites
une fois (les chapitres « Fouillis et association » et « Gérer les pistes », leurs figures, leurs curseurs et
leurs tests les appellent).

**La scène.** Cinq vols réels (:func:`~kalman_course.datasets.toulouse_traffic` : l'hélicoptère SAMU 31,
l'avion de prises de vues Pixair, trois vols de calibration), enregistrés des jours différents et rejoués sur
une horloge commune, survolent un rectangle de :data:`REGION` (26 km sur 17 km) au sud-est de l'aérodrome.
Leurs trajectoires se croisent.

**Le radar** tourne en :data:`DT` = 5 s : :data:`N_SCANS` relevés, de 0 à 300 s. À chaque relevé :

* chaque avion est détecté avec la probabilité :math:`P_D`, à sa position vraie (interpolée entre ses
  positions ADS-B) plus un bruit gaussien d'écart-type :data:`NOISE_STD` sur chaque axe ;
* le **fouillis** : un nombre poissonnien de fausses détections, de moyenne :math:`\lambda V` (:math:`V`,
  l'aire du rectangle), uniformes sur le rectangle.

Les tirages sont **communs** à tous les réglages (graine :data:`SEED`) : une détection manquée à
:math:`P_D = 0{,}7` l'est aussi à :math:`P_D = 0{,}5` (même uniforme comparée à :math:`P_D`), et le fouillis de
densité :math:`\lambda` est celui de la densité maximale :data:`MAX_CLUTTER` éclairci (on garde chaque point
avec la probabilité :math:`\lambda/\lambda_{\max}` : c'est encore un processus de Poisson uniforme). Bouger un
curseur ne change que ce qu'il règle.

**Le pisteur** (:func:`~kalman_course.multi_target_tracker`) suit un modèle à vitesse presque constante de
densité :data:`ACCEL_PSD` et connaît :math:`P_D`, :math:`\lambda` et le bruit du radar. On le juge par la
**GOSPA** (:func:`~kalman_course.gospa`, coupure :data:`GOSPA_CUTOFF`, :math:`p = 1`) entre les positions
vraies et celles des pistes confirmées, relevé par relevé, et par les **changements d'identité** : le nombre
de fois où l'avion couplé par la GOSPA change de numéro de piste.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import NamedTuple

import numpy as np
import scipy.stats

from ..core.models import LinearGaussianModel
from ..core.motion import constant_velocity_model
from ..core.results import freeze, freeze_fields
from ..datasets.adsb import Traffic, toulouse_traffic
from ..multitarget.assignment import gnn_assign, nn_assign
from ..multitarget.gate import Gate, validation_gate
from ..multitarget.jpda import jpda_probabilities
from ..multitarget.metrics import gospa
from ..multitarget.pda import pda_update
from ..multitarget.tracker import MultiTargetResult, multi_target_tracker

__all__ = [
    "DT", "N_SCANS", "NOISE_STD", "REGION", "AREA", "SEED", "MAX_CLUTTER", "CLUTTER_DENSITY", "DETECTION_PROBABILITY",
    "GATE_PROBABILITY", "ACCEL_PSD", "MAX_SPEED", "GOSPA_CUTOFF", "PERSIST", "CONFIRM", "DELETE_AFTER", "RadarScans",
    "TrackingRun", "scan_times", "truth", "truth_names", "radar_model", "radar_scans", "track_scene", "identity_changes",
    "TRACK_SLOTS", "FALSE_SLOTS", "track_owners", "track_series", "confirmation_probability", "SNAPSHOT_SCAN", "Snapshot", "scan_snapshot",
]

#: Période de rotation du radar (s) et nombre de relevés (de 0 à 300 s).
DT = 5.0
N_SCANS = 61
#: Écart-type du bruit de position du radar, sur chaque axe (m).
NOISE_STD = 50.0
#: Surveillance : est de −7 à 19 km, nord de −13 à 4 km (m), et son aire (m²).
REGION = (-7000.0, 19000.0, -13000.0, 4000.0)
AREA = (REGION[1] - REGION[0]) * (REGION[3] - REGION[2])
#: Graine de tous les tirages de la scène.
SEED = 37
#: Densité maximale de fausses détections (par m² et par relevé : 44 par relevé en moyenne sur la zone).
MAX_CLUTTER = 1e-7
#: Réglages par défaut : densité du fouillis (par m² : 13 fausses détections par relevé), probabilités de
#: détection et de la porte.
CLUTTER_DENSITY = 3e-8
DETECTION_PROBABILITY = 0.9
GATE_PROBABILITY = 0.99
#: Densité d'accélération du modèle du pisteur (m²/s³) : un virage au taux standard (3°/s) à 90 m/s demande
#: 4,7 m/s², soit 23 m/s de vitesse en plus ou en moins en 5 s, et :math:`q \approx (23\ \text{m/s})^2/5\ \text{s}`.
#: Vitesse maximale d'une cible (m/s), pour la naissance des pistes.
ACCEL_PSD = 100.0
MAX_SPEED = 120.0
#: Confirmation « M sur N » et suppression par défaut.
CONFIRM = (4, 5)
DELETE_AFTER = 3
#: Coupure de la GOSPA (m).
GOSPA_CUTOFF = 1000.0
#: Un changement d'identité ne compte que si le nouveau numéro dure au moins ce nombre de relevés (15 s) : quand
#: deux avions passent à quelques dizaines de mètres l'un de l'autre, le couplage de la GOSPA peut échanger
#: leurs pistes un relevé, sans que le pisteur les ait échangées.
PERSIST = 3


@dataclass(frozen=True, eq=False)
class RadarScans:
    r"""Les relevés radar de la scène.

    ``t`` (K,) s ; ``truth`` (K, A, 2) m : positions vraies des ``A`` avions ; ``scans`` : tuple de ``K``
    tableaux (N_k, 2) m ; ``origin`` : tuple de ``K`` tableaux (N_k,) entiers, l'avion qui a produit chaque
    détection (−1 : fouillis) ; ``names`` : indicatifs ; ``detection_probability``, ``clutter_density``,
    ``noise_std`` : les réglages."""

    t: np.ndarray
    truth: np.ndarray
    scans: tuple
    origin: tuple
    names: tuple
    detection_probability: float
    clutter_density: float
    noise_std: float

    def __post_init__(self) -> None:
        freeze_fields(self, "t", "truth")

    @property
    def n_clutter(self) -> np.ndarray:
        """Nombre de fausses détections de chaque relevé (K,)."""
        return np.array([np.sum(o < 0) for o in self.origin])

    @property
    def n_detected(self) -> np.ndarray:
        """Nombre d'avions détectés à chaque relevé (K,)."""
        return np.array([np.sum(o >= 0) for o in self.origin])


@dataclass(frozen=True, eq=False)
class TrackingRun:
    r"""Une exécution du pisteur sur la scène, jugée par la GOSPA (:math:`p = 1`, coupure :data:`GOSPA_CUTOFF`).

    ``tracks`` : le :class:`~kalman_course.MultiTargetResult` ; ``gospa``, ``localisation``, ``missed``,
    ``false`` (K,) m : la GOSPA de chaque relevé et ses trois composantes ; ``labels`` (K, A) entiers : le numéro
    de la piste couplée à chaque avion par la GOSPA (−1 : aucune) ; ``identity_changes`` : nombre de
    changements de numéro d'un même avion (:func:`identity_changes`) ; ``association``
    et les réglages."""

    tracks: MultiTargetResult
    gospa: np.ndarray
    localisation: np.ndarray
    missed: np.ndarray
    false: np.ndarray
    labels: np.ndarray
    identity_changes: int
    association: str
    detection_probability: float
    clutter_density: float
    gate_probability: float

    def __post_init__(self) -> None:
        freeze_fields(self, "gospa", "localisation", "missed", "false")
        object.__setattr__(self, "labels", freeze(self.labels, np.intp))

    @property
    def mean_gospa(self) -> float:
        """GOSPA moyenne sur les relevés (m)."""
        return float(np.mean(self.gospa))

    @property
    def n_tracks(self) -> int:
        """Nombre de pistes confirmées pendant toute la scène (numéros distincts)."""
        return int(max((int(ids.max()) + 1 for ids in self.tracks.ids if ids.size), default=0))


def scan_times() -> np.ndarray:
    """Les instants des relevés (K,) s : 0, 5, …, 300."""
    return DT * np.arange(N_SCANS)


@lru_cache(maxsize=1)
def _traffic() -> Traffic:
    return toulouse_traffic()


def truth() -> np.ndarray:
    """Positions vraies des cinq avions aux instants des relevés (K, 5, 2) m."""
    return _traffic().positions(scan_times())


def truth_names() -> tuple[str, ...]:
    """Les indicatifs des cinq avions, dans l'ordre de :func:`truth`."""
    return _traffic().names


def radar_model(accel_psd: float = ACCEL_PSD, noise_std: float = NOISE_STD) -> LinearGaussianModel:
    r"""Le modèle du pisteur : vitesse presque constante (état [e, n, vₑ, vₙ]), pas :data:`DT`, densité
    ``accel_psd`` (m²/s³), positions mesurées avec :math:`R = \sigma^2 I`."""
    C = np.hstack([np.eye(2), np.zeros((2, 2))])
    return constant_velocity_model(DT, accel_psd, C, noise_std ** 2 * np.eye(2))


@lru_cache(maxsize=1)
def _draws():
    """Les tirages communs à tous les réglages : uniformes de détection (K, A), bruits (K, A, 2), fouillis à la
    densité maximale (points et marques d'éclaircissement, par relevé)."""
    rng = np.random.default_rng(SEED)
    K, A = N_SCANS, len(_traffic())
    detect = rng.uniform(size=(K, A))
    noise = rng.standard_normal((K, A, 2))
    counts = rng.poisson(MAX_CLUTTER * AREA, size=K)
    clutter = [np.column_stack([rng.uniform(REGION[0], REGION[1], c), rng.uniform(REGION[2], REGION[3], c)])
               for c in counts]
    marks = [rng.uniform(size=c) for c in counts]
    return detect, noise, clutter, marks


@lru_cache(maxsize=64)
def radar_scans(detection_probability: float = DETECTION_PROBABILITY, clutter_density: float = CLUTTER_DENSITY,
                noise_std: float = NOISE_STD) -> RadarScans:
    r"""Les :data:`N_SCANS` relevés du radar (tirages communs, voir l'en-tête du module) : ``clutter_density``
    :math:`\lambda \le` :data:`MAX_CLUTTER` par m² et par relevé."""
    if not 0.0 < clutter_density <= MAX_CLUTTER:
        raise ValueError(f"clutter_density doit être dans ]0, {MAX_CLUTTER}] (tirages communs)")
    detect, noise, clutter, marks = _draws()
    pos = truth()
    scans, origins = [], []
    for k in range(N_SCANS):
        seen = np.flatnonzero(detect[k] < detection_probability)
        false = clutter[k][marks[k] < clutter_density / MAX_CLUTTER]
        scans.append(freeze(np.vstack([pos[k, seen] + noise_std * noise[k, seen], false])))
        origins.append(freeze(np.concatenate([seen, np.full(len(false), -1)]), np.intp))
    return RadarScans(scan_times(), pos, tuple(scans), tuple(origins), _traffic().names, detection_probability,
                      clutter_density, noise_std)


def identity_changes(labels: np.ndarray, persist: int = PERSIST) -> int:
    """Nombre de changements d'identité : pour chaque avion (colonne de ``labels`` (K, A), −1 : aucune piste),
    les numéros de piste successifs, pertes retirées, forment des séries ; une série d'au moins ``persist``
    relevés dont le numéro diffère du numéro en cours compte pour un changement (et devient le numéro en
    cours). Une perte seule, ou un échange d'un ou deux relevés, ne compte pas."""
    changes = 0
    for column in np.asarray(labels).T:
        known = column[column >= 0]
        if known.size == 0:
            continue
        starts = np.flatnonzero(np.r_[True, known[1:] != known[:-1]])
        lengths = np.diff(np.r_[starts, known.size])
        current = known[0]
        for value, length in zip(known[starts], lengths):
            if length >= persist and value != current:
                changes += 1
                current = value
    return changes


@lru_cache(maxsize=256)
def track_scene(association: str = "jpda", detection_probability: float = DETECTION_PROBABILITY,
                clutter_density: float = CLUTTER_DENSITY, gate_probability: float = GATE_PROBABILITY,
                confirm: tuple = CONFIRM, delete_after: int = DELETE_AFTER) -> TrackingRun:
    """Le pisteur sur la scène (relevés de :func:`radar_scans` aux mêmes réglages), jugé par la GOSPA."""
    scans = radar_scans(detection_probability, clutter_density)
    tracks = multi_target_tracker(radar_model(), scans.scans, detection_probability=detection_probability,
                                  clutter_density=clutter_density, max_speed=MAX_SPEED,
                                  gate_probability=gate_probability, association=association, confirm=confirm,
                                  delete_after=delete_after)
    K, A = scans.truth.shape[:2]
    parts = np.zeros((4, K))
    labels = np.full((K, A), -1)
    for k in range(K):
        g = gospa(scans.truth[k], tracks.x[k][:, :2], c=GOSPA_CUTOFF, p=1)
        parts[:, k] = g.distance, g.localisation, g.missed, g.false
        matched = g.assignment >= 0
        labels[k, matched] = tracks.ids[k][g.assignment[matched]]
    return TrackingRun(tracks, *parts, labels, identity_changes(labels), association, detection_probability,
                       clutter_density, gate_probability)


def track_owners(run: TrackingRun) -> dict[int, int]:
    """Numéro de piste → l'avion qu'elle a suivi d'abord (le premier avion que la GOSPA lui couple) ; les
    fausses pistes n'y sont pas."""
    owner: dict[int, int] = {}
    for row in run.labels:
        for a, track in enumerate(row):
            if track >= 0:
                owner.setdefault(int(track), a)
    return owner


#: Pour les tracés : lignes par avion (une piste à la fois par ligne) et points des fausses pistes par relevé.
TRACK_SLOTS = 3
FALSE_SLOTS = 16


def track_series(run: TrackingRun) -> dict[str, np.ndarray]:
    r"""Les pistes d'une exécution, prêtes à tracer à longueur fixe (toutes de longueur K) :

    * ``"a{i}_e"``, ``"a{i}_n"`` (TRACK_SLOTS · (K + 1),) km : les pistes **de l'avion** ``i`` — celles dont le
      premier avion couplé (GOSPA) est ``i`` —, rangées en :data:`TRACK_SLOTS` lignes de K relevés mises bout à
      bout, chacune suivie d'un NaN (une seule courbe par avion, coupée entre les lignes). Une piste prend la
      ligne libre depuis le plus longtemps, avec au moins un relevé vide entre deux pistes (une ligne ne relie
      jamais deux pistes) ;
    * ``"false_e"``, ``"false_n"`` (K · :data:`FALSE_SLOTS`) km : les positions des **fausses pistes** (jamais
      couplées à un avion), relevé par relevé, NaN pour compléter.

    Une piste de l'avion ``i`` qui part sur la trajectoire d'un autre avion est un **échange** ; une piste
    interrompue puis une autre de même couleur, une **perte** suivie d'une nouvelle naissance. Plus de pistes
    qu'il n'y a de lignes ou de places : ``RuntimeError`` (agrandir les constantes)."""
    K, A = run.labels.shape
    owner = track_owners(run)
    span = {}
    for k, ids in enumerate(run.tracks.ids):
        for i, track in enumerate(ids):
            first, _, rows = span.get(int(track), (k, k, []))
            span[int(track)] = (first, k, rows + [(k, i)])
    lines = {c: np.full((A, TRACK_SLOTS, K + 1), np.nan) for c in "en"}
    false_e, false_n = np.full((K, FALSE_SLOTS), np.nan), np.full((K, FALSE_SLOTS), np.nan)
    free_since = {(a, j): -2 for a in range(A) for j in range(TRACK_SLOTS)}
    for track in sorted(span, key=lambda t: span[t][0]):
        first, last, rows = span[track]
        if track in owner:
            a = owner[track]
            slots = [j for j in range(TRACK_SLOTS) if free_since[(a, j)] < first - 1]
            if not slots:
                raise RuntimeError(f"avion {a} : plus de {TRACK_SLOTS} pistes à la fois (TRACK_SLOTS)")
            j = min(slots, key=lambda s: free_since[(a, s)])
            free_since[(a, j)] = last
            for k, i in rows:
                lines["e"][a, j, k], lines["n"][a, j, k] = run.tracks.x[k][i, :2] / 1e3
        else:
            for k, i in rows:
                place = np.flatnonzero(np.isnan(false_e[k]))
                if place.size == 0:
                    raise RuntimeError(f"plus de {FALSE_SLOTS} fausses pistes au relevé {k} (FALSE_SLOTS)")
                false_e[k, place[0]], false_n[k, place[0]] = run.tracks.x[k][i, :2] / 1e3
    out = {f"a{a}_{c}": lines[c][a].ravel() for a in range(A) for c in "en"}
    out["false_e"], out["false_n"] = false_e.ravel(), false_n.ravel()
    return out


#: Le relevé montré en détail (t = 140 s) : CALIBRA et SAVAN03 viennent de se croiser à moins de 100 m, et
#: l'hélicoptère SAMU 31 et SAVAN11 passent l'un près de l'autre. Le plus proche voisin y fait deux erreurs.
SNAPSHOT_SCAN = 28


class Snapshot(NamedTuple):
    r"""Un relevé en détail, vu par le pisteur JPDA de la scène (réglages par défaut) : ``k`` ; ``ids`` (T,) ;
    ``x_pred`` (T, 4), ``P_pred`` (T, 4, 4) : ses pistes confirmées au relevé ``k − 1``, prédites ;
    ``owner`` (T,) : l'avion que chaque piste a suivi d'abord (:func:`track_owners`) ; ``detections`` (N, 2), ``origin`` (N,) ; ``truth``
    (A, 2) ; ``gate`` (:class:`~kalman_course.Gate`) ; ``nn``, ``gnn`` (T,) : les affectations ; ``pda``
    (T, N + 1) : les probabilités PDA de chaque piste seule ; ``jpda`` (T, N + 1)."""

    k: int
    ids: np.ndarray
    x_pred: np.ndarray
    P_pred: np.ndarray
    owner: np.ndarray
    detections: np.ndarray
    origin: np.ndarray
    truth: np.ndarray
    gate: Gate
    nn: np.ndarray
    gnn: np.ndarray
    pda: np.ndarray
    jpda: np.ndarray


@lru_cache(maxsize=4)
def scan_snapshot(k: int = SNAPSHOT_SCAN) -> Snapshot:
    """Le relevé ``k`` en détail (voir :class:`Snapshot`) : porte, NN, GNN, PDA et JPDA des pistes confirmées du
    pisteur JPDA au relevé précédent."""
    run, scans, model = track_scene(), radar_scans(), radar_model()
    ids, x, P = run.tracks.ids[k - 1], run.tracks.x[k - 1], run.tracks.P[k - 1]
    x_pred, P_pred = x @ model.A.T, model.A @ P @ model.A.T + model.Q
    z = scans.scans[k]
    settings = dict(detection_probability=DETECTION_PROBABILITY, clutter_density=CLUTTER_DENSITY,
                    gate_probability=GATE_PROBABILITY)
    first = track_owners(run)
    owner = np.array([first.get(int(i), -1) for i in ids])
    pda = np.array([pda_update(model, x_pred[t], P_pred[t], z, **settings).weights for t in range(ids.size)])
    return Snapshot(k, ids, x_pred, P_pred, owner, z, scans.origin[k], scans.truth[k],
                    validation_gate(model, x_pred, P_pred, z, gate_probability=GATE_PROBABILITY),
                    nn_assign(model, x_pred, P_pred, z, gate_probability=GATE_PROBABILITY),
                    gnn_assign(model, x_pred, P_pred, z, gate_probability=GATE_PROBABILITY), pda,
                    jpda_probabilities(model, x_pred, P_pred, z, **settings))


def confirmation_probability(p_hit, M: int, N: int):
    r"""Probabilité qu'une piste provisoire soit confirmée par la règle « M sur N » (les deux détections de
    naissance comptant pour deux touches) quand elle touche à chaque relevé avec la probabilité ``p_hit``,
    indépendamment : :math:`\mathbb P[\mathrm{Bin}(N - 2, p) \ge M - 2]` (``scipy.stats.binom``)."""
    return scipy.stats.binom.sf(M - 3, N - 2, p_hit)
