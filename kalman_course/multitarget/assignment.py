r"""L'association **ferme** : chaque piste reçoit une détection de sa porte, ou aucune, et une détection
va à une piste au plus.

Le coût d'un couple piste–détection est sa NIS :math:`d^2_{tj}` (:func:`~kalman_course.validation_gate`),
seuls les couples de la porte sont permis, et une piste laissée sans détection coûte :math:`\gamma`, le
seuil de la porte (comme ``DistanceHypothesiser(SquaredMahalanobis(), missed_distance=γ)`` de Stone
Soup).

* :func:`gnn_assign` — le plus proche voisin **global** (GNN) : l'affectation de coût total minimal, par
  ``scipy.optimize.linear_sum_assignment`` sur la matrice (T, N + T) des coûts, augmentée d'un bloc
  diagonal :math:`\gamma` (« aucune détection » de chaque piste) ;
* :func:`nn_assign` — le plus proche voisin **glouton** (NN) : on prend le couple libre de plus petite
  NIS, puis le suivant parmi ceux qui restent libres, et ainsi de suite. Deux pistes proches peuvent
  ainsi échanger leurs détections, ce que le GNN évite.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.optimize

from ..core.results import freeze
from ..core.validation import as_probability
from .gate import check_detections, check_model, check_tracks, gate_threshold, innovations

__all__ = ["gnn_assign", "nn_assign", "global_assignment", "greedy_assignment"]


def global_assignment(nis: np.ndarray, gamma: float) -> np.ndarray:
    r"""L'affectation de coût minimal (T,) (indice de détection ou −1) pour la matrice des NIS (T, N) et le
    seuil :math:`\gamma` (noyau de :func:`gnn_assign`, sans vérification)."""
    T, N = nis.shape
    out = np.full(T, -1, dtype=np.intp)
    if T == 0 or N == 0:
        return out
    cost = np.full((T, N + T), np.inf)
    cost[:, :N] = np.where(nis <= gamma, nis, np.inf)
    cost[np.arange(T), N + np.arange(T)] = gamma
    rows, cols = scipy.optimize.linear_sum_assignment(cost)
    hit = cols < N
    out[rows[hit]] = cols[hit]
    return out


def greedy_assignment(nis: np.ndarray, gamma: float) -> np.ndarray:
    r"""L'affectation gloutonne (T,) : couples de la porte pris par NIS croissante, chacun seulement si sa
    piste et sa détection sont encore libres (noyau de :func:`nn_assign`, sans vérification)."""
    T, N = nis.shape
    out = np.full(T, -1, dtype=np.intp)
    t_idx, d_idx = np.nonzero(nis <= gamma)
    taken = np.zeros(N, dtype=bool)
    for k in np.argsort(nis[t_idx, d_idx], kind="stable"):
        t, j = t_idx[k], d_idx[k]
        if out[t] < 0 and not taken[j]:
            out[t] = j
            taken[j] = True
    return out


def _nis_and_threshold(model: Any, x_pred: Any, P_pred: Any, detections: Any, gate_probability: Any):
    model = check_model(model)
    p_gate = as_probability("gate_probability", gate_probability)
    x, P = check_tracks(x_pred, P_pred, model.n_state)
    z = check_detections(detections, model.n_obs)
    return innovations(model.C, model.R, x, P, z).nis, gate_threshold(p_gate, model.n_obs)


def gnn_assign(model: Any, x_pred: Any, P_pred: Any, detections: Any, *, gate_probability: Any) -> np.ndarray:
    r"""Le plus proche voisin global : l'affectation pistes–détections de coût total minimal,

    .. math::

        \min_a \sum_{t:\,a(t)\ne0} d^2_{t,a(t)} + \gamma\,\#\{t : a(t) = 0\},

    parmi les affectations où chaque piste prend une détection de sa porte (:math:`d^2 \le \gamma`) ou
    aucune, et chaque détection va à une piste au plus. Arguments de :func:`~kalman_course.validation_gate`.

    Renvoie un tableau d'entiers (T,) : l'indice de la détection de chaque piste, ou −1.
    """
    nis, gamma = _nis_and_threshold(model, x_pred, P_pred, detections, gate_probability)
    return freeze(global_assignment(nis, gamma), np.intp)


def nn_assign(model: Any, x_pred: Any, P_pred: Any, detections: Any, *, gate_probability: Any) -> np.ndarray:
    r"""Le plus proche voisin glouton : on affecte le couple (piste libre, détection libre) de la porte de plus
    petite NIS :math:`d^2_{tj}`, et on recommence jusqu'à épuisement des couples. Arguments de
    :func:`~kalman_course.validation_gate`.

    Renvoie un tableau d'entiers (T,) : l'indice de la détection de chaque piste, ou −1.
    """
    nis, gamma = _nis_and_threshold(model, x_pred, P_pred, detections, gate_probability)
    return freeze(greedy_assignment(nis, gamma), np.intp)
