r"""L'association probabiliste **conjointe** (JPDA, Fortmann, Bar-Shalom & Scheffe 1983) : plusieurs pistes
se disputent les détections d'un même relevé.

Un **événement conjoint** :math:`a` donne à chaque piste :math:`t` une détection :math:`a(t)` de sa
porte, ou aucune (:math:`a(t) = 0`), sans qu'une détection aille à deux pistes. Avec les poids PDA
:math:`w_{tj}` de chaque piste (:func:`~kalman_course.multitarget.pda.association_weights`), il pèse

.. math::

    W(a) = \prod_t w_{t,a(t)},\qquad
    \beta_{tj} = \frac{\sum_{a:\,a(t) = j} W(a)}{\sum_a W(a)} ,

la probabilité marginale que la détection :math:`j` soit celle de la piste :math:`t` (:math:`j = 0` :
aucune). Chaque piste est ensuite corrigée comme par la PDA, avec ses :math:`\beta_{t\cdot}`.

**Énumération exacte.** Les pistes qui ne partagent aucune détection (même par l'intermédiaire d'une
autre) sont indépendantes : le graphe pistes–détections de la porte se coupe en **grappes**
(composantes connexes) et les marginales d'une grappe ne dépendent que de ses
événements. Dans une grappe, les événements sont construits piste par piste, en tableaux : à chaque piste,
chaque événement partiel est prolongé par chacune de ses options, et ceux qui réutilisent une détection
(un bit déjà levé dans leur masque) sont retirés. Le nombre d'événements croît comme celui des couplages
partiels d'un graphe biparti : pour :math:`k` pistes qui voient toutes les mêmes :math:`k` détections,
:math:`\sum_i \binom{k}{i}^2 i!` — 7 pour :math:`k = 2`, 1 441 729 pour :math:`k = 8`, 2,3 × 10⁸ pour
:math:`k = 10` (``benchmarks/jpda_vs_stonesoup.py`` mesure où le calcul cesse d'être utilisable). Au-delà de
:data:`MAX_EVENTS` événements dans une grappe, le calcul exact est refusé (erreur française) plutôt que
d'épuiser la mémoire : jamais d'approximation silencieuse.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..core.results import freeze
from ..core.validation import KalmanInputError
from .gate import check_detections, check_model, check_tracks, gate_threshold, innovations
from .pda import association_weights, check_clutter

__all__ = ["MAX_EVENTS", "jpda_probabilities", "joint_marginals", "joint_events", "count_events", "clusters"]

#: Nombre maximal d'événements conjoints énumérés dans une grappe (au-delà : KalmanInputError).
MAX_EVENTS = 20_000_000


def clusters(inside: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    r"""Les grappes du graphe pistes–détections de la porte ``inside`` (T, N) : une liste de couples
    ``(pistes, détections)`` (indices croissants) ; chaque piste d'une grappe a au moins une détection dans
    sa porte (les pistes sans détection n'y figurent pas). Deux pistes sont voisines si elles partagent une
    détection (:math:`M = \mathbb 1[\text{inside}\,\text{inside}^T > 0]`) ; les grappes sont les composantes
    connexes de ce graphe (fermeture transitive de :math:`M`, par produits booléens)."""
    tracks = np.flatnonzero(inside.any(axis=1))
    if tracks.size == 0:
        return []
    sub = inside[tracks].astype(float)
    shared = sub @ sub.T > 0.0
    if np.count_nonzero(shared) == tracks.size:  # aucune détection partagée : une grappe par piste
        return [(tracks[i:i + 1], np.flatnonzero(inside[tracks[i]])) for i in range(tracks.size)]
    reach = shared
    while True:  # fermeture transitive par carrés successifs : au plus log₂ T produits booléens
        wider = (reach.astype(np.int32) @ reach.astype(np.int32)) > 0
        if np.array_equal(wider, reach):
            break
        reach = wider
    labels = np.argmax(reach, axis=1)  # le plus petit indice de la composante
    out = []
    for lab in np.unique(labels):
        members = tracks[labels == lab]
        out.append((members, np.flatnonzero(inside[members].any(axis=0))))
    return out


def joint_events(w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r"""Tous les événements conjoints d'une grappe : ``w`` (T_c, N_c + 1) poids des options de ses pistes
    (colonne 0 : aucune détection ; un poids nul : option impossible, hors de la porte). Renvoie ``choice``
    (E, T_c), l'option de chaque piste dans chacun des E événements, et ``weight`` (E,), leur poids
    :math:`\prod_t w_{t,a(t)}`.

    Les événements partiels sont des lignes de tableaux : ``choice`` (option de chaque piste déjà vue),
    ``used`` (masque des détections prises, un mot de 64 bits par tranche de 64 détections), ``weight``
    (produit des poids). Chaque piste prolonge chaque ligne par chacune de ses options ; une option dont
    le bit est déjà levé est retirée."""
    T_c, n_options = w.shape
    words = max(1, -(-(n_options - 1) // 64))
    choice = np.zeros((1, 0), dtype=np.int32)
    used = np.zeros((1, words), dtype=np.uint64)
    weight = np.ones(1)
    for t in range(T_c):
        options = np.flatnonzero(w[t] > 0.0)
        total = choice.shape[0] * options.size
        if total > MAX_EVENTS:
            raise KalmanInputError(
                f"JPDA exacte : une grappe de {T_c} pistes et {n_options - 1} détections demanderait d'examiner "
                f"{total:,} événements conjoints à la piste {t + 1} (limite : {MAX_EVENTS:,}) ; resserrez la porte "
                f"(« gate_probability ») ou séparez les pistes.".replace(",", "\u202f"))
        rows = np.repeat(np.arange(choice.shape[0]), options.size)
        opt = np.tile(options, choice.shape[0])
        word = np.maximum(opt - 1, 0) // 64
        bit = np.where(opt > 0, np.left_shift(np.uint64(1), (np.maximum(opt - 1, 0) % 64).astype(np.uint64)),
                       np.uint64(0))
        free = (used[rows, word] & bit) == 0
        rows, opt, word, bit = rows[free], opt[free], word[free], bit[free]
        choice = np.concatenate([choice[rows], opt[:, None].astype(np.int32)], axis=1)
        used = used[rows]
        used[np.arange(rows.size), word] |= bit
        weight = weight[rows] * w[t, opt]
    return choice, weight


def count_events(inside) -> int:
    r"""Le nombre d'événements conjoints que la JPDA exacte énumère pour la porte ``inside`` (T, N) booléen :
    le produit, sur les grappes, du nombre d'événements de chacune (une piste sans détection n'a qu'un
    événement, « aucune »). Pour :math:`k` pistes qui voient les mêmes :math:`k` détections,
    :math:`\sum_{i=0}^k\binom{k}{i}^2\,i!`."""
    inside = np.asarray(inside, dtype=bool)
    total = 1
    for tracks, dets in clusters(inside):
        w = np.hstack([np.ones((tracks.size, 1)), inside[np.ix_(tracks, dets)].astype(float)])
        total *= joint_events(w)[0].shape[0]
    return total


def _cluster_marginals(w: np.ndarray) -> np.ndarray:
    r"""Marginales exactes d'une grappe (``w`` : voir :func:`joint_events`) : :math:`\beta` (T_c, N_c + 1),
    lignes de somme 1."""
    T_c, n_options = w.shape
    if T_c == 1:  # une piste seule : ses poids PDA normalisés
        return w / w.sum()
    choice, weight = joint_events(w)
    total = weight.sum()
    return np.stack([np.bincount(choice[:, t], weights=weight, minlength=n_options) for t in range(T_c)]) / total


def joint_marginals(w: np.ndarray, inside: np.ndarray) -> np.ndarray:
    r"""Les probabilités JPDA :math:`\beta` (T, N + 1) à partir des poids PDA ``w`` (T, N + 1) et de la porte
    ``inside`` (T, N), grappe par grappe (sans vérification des entrées)."""
    beta = np.zeros_like(w)
    beta[:, 0] = 1.0  # une piste sans détection dans sa porte : aucune
    for tracks, dets in clusters(inside):
        cols = np.concatenate([[0], 1 + dets])
        beta[np.ix_(tracks, cols)] = _cluster_marginals(w[np.ix_(tracks, cols)])
    return beta


def jpda_probabilities(model: Any, x_pred: Any, P_pred: Any, detections: Any, *, detection_probability: Any,
                       clutter_density: Any, gate_probability: Any) -> np.ndarray:
    r"""Les probabilités d'association JPDA de ``T`` pistes et ``N`` détections, par énumération exacte des
    événements conjoints.

    .. math::

        \beta_{tj} = \frac{\sum_{a:\,a(t)=j}\prod_s w_{s,a(s)}}{\sum_a\prod_s w_{s,a(s)}},\qquad
        w_{t0} = 1 - P_DP_G,\quad w_{tj} = \frac{P_D\,\mathcal N(z_j; C\hat x_t, S_t)}{\lambda}\,\mathbb 1[d^2_{tj}\le\gamma],

    la somme portant sur les événements :math:`a` où chaque piste prend une détection de sa porte ou
    aucune, et chaque détection va à une piste au plus. Mêmes arguments que
    :func:`~kalman_course.pda_update`, avec ``x_pred`` (T, n) et ``P_pred`` (T, n, n).

    Renvoie un tableau (T, N + 1) : colonne 0, aucune détection de la piste ; colonne ``1 + j``, la détection
    ``j``. Chaque ligne est de somme 1 et nulle hors de la porte.
    """
    model = check_model(model)
    p_detect, density, p_gate = check_clutter(detection_probability, clutter_density, gate_probability)
    x, P = check_tracks(x_pred, P_pred, model.n_state)
    z = check_detections(detections, model.n_obs)
    m = model.n_obs
    w, inside = association_weights(innovations(model.C, model.R, x, P, z), m, p_detect, density,
                                    gate_threshold(p_gate, m), p_gate)
    return freeze(joint_marginals(w, inside))
