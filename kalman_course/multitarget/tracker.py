r"""Un pisteur multi-cibles complet : naissance des pistes par deux points, confirmation « M sur N »,
association (NN, GNN, PDA ou JPDA) et suppression, relevé après relevé.

Une piste passe par deux états : **provisoire** (elle vient de naître, peut-être d'une fausse détection)
puis **confirmée** (elle est montrée, avec un numéro). À chaque relevé :math:`k` (détections
:math:`Z_k`, ``N_k`` lignes) :

1. **Pistes confirmées.** Prédiction, puis correction : PDA piste par piste (``"pda"``), JPDA sur toutes
   à la fois (``"jpda"``, un appel de :func:`~kalman_course.jpda_probabilities`), ou correction de Kalman
   par la détection que leur donne :func:`~kalman_course.gnn_assign` / :func:`~kalman_course.nn_assign`
   (``"gnn"``, ``"nn"`` ; prédiction seule sans détection). Une piste **touche** si elle reçoit une
   détection, ou si une probabilité :math:`\beta_{tj}` dépasse :math:`\beta_{t0}` ; ces détections sont
   **prises**. Une piste qui ne touche pas ``delete_after`` relevés de suite est supprimée.
2. **Pistes provisoires.** Prédiction, puis :func:`~kalman_course.gnn_assign` sur les détections non
   prises (correction de Kalman, la détection est prise). Les deux détections de naissance comptent comme
   touches des deux premiers relevés. Une piste provisoire est confirmée dès qu'elle a ``M`` touches dans
   ses ``N`` premiers relevés (``confirm = (M, N)``), supprimée dès qu'elle ne peut plus les atteindre.
3. **Naissance par deux points.** Un *germe* est une détection du relevé :math:`k-1` restée non prise
   après l'étape 2 et qui n'a fait naître aucune piste. Chaque couple d'un germe :math:`s` et d'une
   détection non prise :math:`z` du relevé :math:`k` avec :math:`\lVert z - s\rVert \le v_{\max}\Delta t`
   fait naître une piste provisoire :math:`x = [z,\ (z - s)/\Delta t]`,
   :math:`P = \begin{bmatrix} R & R/\Delta t \\ R/\Delta t & 2R/\Delta t^2\end{bmatrix}` (la covariance de
   la différence de deux mesures indépendantes) ; confirmée aussitôt si ``M = 2``.

Les numéros des pistes sont 0, 1, 2… dans l'ordre de confirmation, jamais réutilisés.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np

from ..core.linalg import symmetrize
from ..core.results import freeze
from ..core.validation import KalmanInputError, as_integer, as_positive_number
from .assignment import global_assignment, greedy_assignment
from .gate import check_detections, check_model, gate_threshold, innovations
from .jpda import joint_marginals
from .pda import association_weights, check_clutter, combine

__all__ = ["ASSOCIATIONS", "MultiTargetResult", "multi_target_tracker", "check_constant_velocity"]

#: Les méthodes d'association du pisteur.
ASSOCIATIONS = ("nn", "gnn", "pda", "jpda")


class MultiTargetResult(NamedTuple):
    r"""Résultat de :func:`multi_target_tracker`, trois tuples de longueur ``T`` (un élément par relevé) :
    ``ids[k]`` (n_k,) entiers, ``x[k]`` (n_k, n) et ``P[k]`` (n_k, n, n) : les pistes confirmées après le
    relevé ``k`` (celles confirmées à ``k`` comprises, celles supprimées à ``k`` exclues), par numéro
    croissant."""

    ids: tuple
    x: tuple
    P: tuple


def check_constant_velocity(model: Any) -> float:
    r"""``model`` doit être le modèle à vitesse presque constante de
    :func:`~kalman_course.constant_velocity_model` : état :math:`[p, v]` (d positions en m, d vitesses en
    m/s), :math:`A = \begin{bmatrix} I & \Delta t\,I \\ 0 & I\end{bmatrix}`, :math:`C = [I\ \ 0]`. Renvoie
    :math:`\Delta t`."""
    model = check_model(model)
    n, m = model.n_state, model.n_obs
    d = n // 2
    expected = ("le modèle à vitesse presque constante de kc.constant_velocity_model(dt, q, C, R) : état "
                "[positions, vitesses], A = [[I, dt·I], [0, I]], C = [I, 0]")
    if n % 2 or m != d:
        raise KalmanInputError(f"« model » doit être {expected} ; reçu n = {n} états et m = {m} mesures.")
    dt = float(model.A[0, d])
    A = np.block([[np.eye(d), dt * np.eye(d)], [np.zeros((d, d)), np.eye(d)]])
    C = np.hstack([np.eye(d), np.zeros((d, d))])
    if not dt > 0 or not np.allclose(model.A, A, rtol=0.0, atol=1e-12 * max(1.0, dt)) \
            or not np.array_equal(model.C, C):
        raise KalmanInputError(f"« model » doit être {expected}.")
    return dt


def _check_scans(scans: Any, m: int) -> list[np.ndarray]:
    if isinstance(scans, (str, bytes)) or not isinstance(scans, (Sequence, np.ndarray)):
        raise KalmanInputError(f"« scans » doit être une suite de relevés (liste de tableaux (N_k, {m})) ; "
                               f"reçu {type(scans).__name__}.")
    out = [check_detections(scan, m, f"scans[{k}]") for k, scan in enumerate(scans)]
    if not out:
        raise KalmanInputError("« scans » ne contient aucun relevé (T = 0).")
    return out


def _check_confirm(confirm: Any) -> tuple[int, int]:
    if isinstance(confirm, (str, bytes)) or not isinstance(confirm, (Sequence, np.ndarray)) or len(confirm) != 2 \
            or any(isinstance(v, bool) or not isinstance(v, (int, np.integer)) for v in confirm) \
            or not 2 <= confirm[0] <= confirm[1]:
        raise KalmanInputError(f"« confirm » doit être un couple d'entiers (M, N) avec 2 ≤ M ≤ N (M touches dans les "
                               f"N premiers relevés d'une piste) ; reçu {confirm!r}.")
    return int(confirm[0]), int(confirm[1])


def _one_hot(assigned: np.ndarray, N: int) -> np.ndarray:
    """Les probabilités (T, N + 1) d'une association ferme : 1 sur la détection reçue, ou sur « aucune »."""
    beta = np.zeros((assigned.size, N + 1))
    beta[np.arange(assigned.size), assigned + 1] = 1.0  # −1 + 1 = 0 : aucune détection
    return beta


def multi_target_tracker(model: Any, scans: Any, *, detection_probability: Any, clutter_density: Any, max_speed: Any,
                         gate_probability: Any = 0.99, association: Any = "jpda", confirm: Any = (4, 5),
                         delete_after: Any = 3) -> MultiTargetResult:
    r"""Piste un nombre inconnu de cibles dans le fouillis (voir l'en-tête du module pour les trois étapes
    de chaque relevé).

    Paramètres
    ----------
    model : le modèle à vitesse presque constante de :func:`~kalman_course.constant_velocity_model`
        (état [positions (m), vitesses (m/s)], :math:`A = [[I, \Delta t\,I], [0, I]]`, :math:`C = [I, 0]`).
    scans : suite de ``T`` relevés, tableaux (N_k, m) (``N_k ≥ 0``), espacés de :math:`\Delta t`.
    detection_probability : :math:`P_D \in (0, 1]` ; clutter_density : :math:`\lambda > 0` (par m² en 2-D).
    max_speed : :math:`v_{\max} > 0` (m/s) — vitesse maximale d'une cible, pour la naissance des pistes.
    gate_probability : :math:`P_G \in (0, 1)`.
    association : ``"nn"``, ``"gnn"``, ``"pda"`` ou ``"jpda"``.
    confirm : ``(M, N)``, 2 ≤ M ≤ N — confirmation « M touches sur les N premiers relevés ».
    delete_after : entier ≥ 1 — relevés de suite sans touche avant la suppression d'une piste confirmée.

    Renvoie :class:`MultiTargetResult` ``(ids, x, P)``.
    """
    dt = check_constant_velocity(model)
    p_detect, density, p_gate = check_clutter(detection_probability, clutter_density, gate_probability)
    v_max = as_positive_number("max_speed", max_speed, "une vitesse strictement positive (m/s)")
    if association not in ASSOCIATIONS:
        raise KalmanInputError(f"« association » doit valoir {', '.join(repr(a) for a in ASSOCIATIONS)} ; "
                               f"reçu {association!r}.")
    M, N_window = _check_confirm(confirm)
    delete_after = as_integer("delete_after", delete_after, 1, "relevés de suite sans touche")
    n, m = model.n_state, model.n_obs
    scans = _check_scans(scans, m)
    A, C, Q, R = model.A, model.C, model.Q, model.R
    gamma = gate_threshold(p_gate, m)
    P_birth = np.block([[R, R / dt], [R / dt, 2.0 * R / dt ** 2]])

    def predict(x, P):
        return x @ A.T, symmetrize(A @ P @ A.T + Q)

    # pistes confirmées : numéros, états, relevés de suite sans touche
    ids, xc, Pc, misses = np.zeros(0, np.intp), np.zeros((0, n)), np.zeros((0, n, n)), np.zeros(0, np.intp)
    # pistes provisoires : états, touches, relevés vus (naissance comprise)
    xt, Pt, hits, seen = np.zeros((0, n)), np.zeros((0, n, n)), np.zeros(0, np.intp), np.zeros(0, np.intp)
    seeds = np.zeros((0, m))
    next_id = 0
    out_ids, out_x, out_P = [], [], []
    for Z in scans:
        N = Z.shape[0]
        used = np.zeros(N, dtype=bool)
        # 1. pistes confirmées
        if ids.size:
            xc, Pc = predict(xc, Pc)
            inn = innovations(C, R, xc, Pc, Z)
            if association in ("pda", "jpda"):
                w, inside = association_weights(inn, m, p_detect, density, gamma, p_gate)
                beta = w / w.sum(axis=1, keepdims=True) if association == "pda" else joint_marginals(w, inside)
                taken = beta[:, 1:] > beta[:, :1]
                hit = taken.any(axis=1)
                used |= taken.any(axis=0)
            else:
                assigned = (global_assignment if association == "gnn" else greedy_assignment)(inn.nis, gamma)
                beta = _one_hot(assigned, N)
                hit = assigned >= 0
                used[assigned[hit]] = True
            xc, Pc = combine(xc, Pc, inn, beta)
            misses = np.where(hit, 0, misses + 1)
            keep = misses < delete_after
            ids, xc, Pc, misses = ids[keep], xc[keep], Pc[keep], misses[keep]
        # 2. pistes provisoires, sur les détections non prises
        if hits.size:
            xt, Pt = predict(xt, Pt)
            free = np.flatnonzero(~used)
            inn = innovations(C, R, xt, Pt, Z[free])
            assigned = global_assignment(inn.nis, gamma)
            xt, Pt = combine(xt, Pt, inn, _one_hot(assigned, free.size))
            hit = assigned >= 0
            used[free[assigned[hit]]] = True
            hits, seen = hits + hit, seen + 1
            confirmed = hits >= M
            if confirmed.any():
                new = np.arange(next_id, next_id + confirmed.sum())
                next_id += new.size
                ids, misses = np.concatenate([ids, new]), np.concatenate([misses, np.zeros(new.size, np.intp)])
                xc, Pc = np.concatenate([xc, xt[confirmed]]), np.concatenate([Pc, Pt[confirmed]])
            keep = ~confirmed & (hits + (N_window - seen) >= M)
            xt, Pt, hits, seen = xt[keep], Pt[keep], hits[keep], seen[keep]
        # 3. naissance par deux points : germes du relevé précédent × détections non prises
        free = np.flatnonzero(~used)
        started = np.zeros(N, dtype=bool)
        if seeds.shape[0] and free.size:
            near = np.linalg.norm(Z[free][None, :, :] - seeds[:, None, :], axis=2) <= v_max * dt
            s_idx, z_idx = np.nonzero(near)  # germe après germe, détection après détection
            if s_idx.size:
                z = Z[free[z_idx]]
                born_x = np.hstack([z, (z - seeds[s_idx]) / dt])
                born_P = np.broadcast_to(P_birth, (s_idx.size, n, n))
                started[free[z_idx]] = True
                if M == 2:
                    new = np.arange(next_id, next_id + s_idx.size)
                    next_id += new.size
                    ids, misses = np.concatenate([ids, new]), np.concatenate([misses, np.zeros(new.size, np.intp)])
                    xc, Pc = np.concatenate([xc, born_x]), np.concatenate([Pc, born_P])
                else:
                    xt, Pt = np.concatenate([xt, born_x]), np.concatenate([Pt, born_P])
                    hits = np.concatenate([hits, np.full(s_idx.size, 2, np.intp)])
                    seen = np.concatenate([seen, np.full(s_idx.size, 2, np.intp)])
        seeds = Z[~used & ~started]
        out_ids.append(freeze(ids, np.intp))
        out_x.append(freeze(xc))
        out_P.append(freeze(Pc))
    return MultiTargetResult(tuple(out_ids), tuple(out_x), tuple(out_P))
