r"""Lisseurs : le lisseur de Rauch–Tung–Striebel (1965) et sa version étendue.

Le filtre donne :math:`\hat x_{k\mid k}`, ce qu'on sait de l'état **au pas** :math:`k` ; le lisseur
donne :math:`\hat x_{k\mid T}`, ce qu'on en sait **à la fin**, toutes les mesures reçues. Une passe
arrière, de :math:`k = T-1` à :math:`1`, sur les résultats du filtre :

.. math::

    G_k = P_{k\mid k}A^T P_{k+1\mid k}^{-1},\qquad
    \hat x_{k\mid T} = \hat x_{k\mid k} + G_k\,(\hat x_{k+1\mid T} - \hat x_{k+1\mid k}),

    P_{k\mid T} = P_{k\mid k} + G_k\,(P_{k+1\mid T} - P_{k+1\mid k})\,G_k^T,\qquad
    P_{k+1,k\mid T} = \operatorname{Cov}(x_{k+1}, x_k \mid y_{1:T}) = P_{k+1\mid T}G_k^T,

en partant de :math:`\hat x_{T\mid T}`, :math:`P_{T\mid T}` (la dernière estimation du filtre). La
covariance de décalage un :math:`P_{k+1,k\mid T}` sert à l'algorithme EM
(:func:`~kalman_course.likelihood.expectation_maximization`). :math:`G_k` vient d'une résolution
linéaire, jamais d'une inverse. Un pas sans mesure a :math:`\hat x_{k\mid k} = \hat x_{k\mid k-1}` et
ne demande rien de particulier ; la commande est déjà dans les prédictions
:math:`\hat x_{k+1\mid k}` du filtre.

* :func:`rts_smoother` lisse un résultat de :func:`~kalman_course.kalman_filter` (:math:`A`) ou de
  :func:`~kalman_course.filters.diffuse.diffuse_kalman_filter` (initialisation diffuse exacte) ;
* :func:`extended_rts_smoother` lisse un résultat de l'EKF (ou de l'EKF itéré) : :math:`A` devient la
  jacobienne :math:`F_k = \partial f/\partial x` en :math:`(\hat x_{k\mid k}, u)`, la prédiction du filtre ;
* :func:`unscented_rts_smoother` lisse un résultat de l'UKF (Särkkä, 2008) : la covariance croisée
  :math:`C_{k,k+1}` des points sigma remplace :math:`P_{k\mid k}F_k^T`.

Les deux vérifient que le résultat vient bien du filtre de ce modèle (prédictions
:math:`P_{k+1\mid k} = F_kP_{k\mid k}F_k^T + Q` et :math:`S_k = CP_{k\mid k-1}C^T + R` retrouvées) :
un résultat d'un autre modèle ou d'un autre filtre est refusé. Le résultat :class:`SmootherResult`
est commun à tous les lisseurs (un lisseur RTS « unscented » pourra le remplir : ses gains
:math:`G_k = C_{k,k+1}P_{k+1\mid k}^{-1}` ont la même forme).

Ce module n'importe pas matplotlib.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
import scipy.linalg

from ..core.linalg import correct_square_root, covariance_root, symmetrize, triangular_root
from ..core.models import LinearGaussianModel, NonlinearModel
from ..core.results import FilterResult, FilterRuns, freeze
from ..core.validation import KalmanInputError, as_controls, as_gaussian, check_instance, number_text
from .diffuse import DiffuseFilterResult, is_determined
from .extended import NONLINEAR_HINT

__all__ = ["SmootherResult", "rts_smoother", "extended_rts_smoother", "unscented_rts_smoother", "smoother_gains",
           "rts_pass", "square_root_rts_pass", "diffuse_rts_pass", "CONSISTENCY_RTOL", "LinearSmootherInputs",
           "linear_smoother_inputs"]

#: Tolérance relative de la vérification « ce résultat vient du filtre de ce modèle ».
CONSISTENCY_RTOL = 1e-6


@dataclass(frozen=True, eq=False)
class SmootherResult:
    r"""Sortie d'un lisseur sur ``T`` pas (``n`` états), sur l'axe des temps du filtre.

    Attributs
    ---------
    x : (T, n)
        Estimation lissée :math:`\hat x_{k\mid T}`.
    P : (T, n, n)
        Covariance lissée :math:`P_{k\mid T}`.
    G : (T, n, n)
        Gains du lisseur : ``G[k]`` relie les lignes ``k`` et ``k+1`` ; ``G[T-1] = 0`` (dernier pas :
        le lissage ne change rien). NaN aux pas dont l'estimation filtrée n'est pas déterminée (départ
        diffus).
    P_lag : (T, n, n)
        Covariances de décalage un :math:`\operatorname{Cov}(x_k, x_{k-1}\mid y_{1:T})` : ``P_lag[k]``
        relie la ligne ``k`` à la précédente ; ``P_lag[0]`` la relie à l'état initial (instant 0) quand
        celui-ci est lissé (``x0``, ``P0`` donnés), NaN sinon.
    x_initial : (n,) ou None
        État initial lissé :math:`\hat x_{0\mid T}` (si l'a priori ``x0``, ``P0`` du filtre est donné).
    P_initial : (n, n) ou None
        Sa covariance :math:`P_{0\mid T}`.
    G_initial : (n, n) ou None
        Le gain qui relie l'état initial à la ligne 0.
    method : str
        Le lisseur (« RTS », « RTS étendu », « RTS, initialisation diffuse exacte »…).
    """

    x: np.ndarray
    P: np.ndarray
    G: np.ndarray
    P_lag: np.ndarray
    x_initial: np.ndarray | None = None
    P_initial: np.ndarray | None = None
    G_initial: np.ndarray | None = None
    method: str = "RTS"

    def __post_init__(self) -> None:
        for name in ("x", "P", "G", "P_lag", "x_initial", "P_initial", "G_initial"):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, freeze(getattr(self, name)))

    @property
    def n_steps(self) -> int:
        """Nombre de pas ``T``."""
        return self.x.shape[0]

    def std(self) -> np.ndarray:
        r"""Écarts-types lissés :math:`\sqrt{\operatorname{diag} P_{k\mid T}}`, forme (T, n)."""
        return np.sqrt(np.diagonal(self.P, axis1=-2, axis2=-1))

    def __repr__(self) -> str:
        return f"<SmootherResult ({self.method}) : {self.n_steps} pas, état de dimension {self.x.shape[1]}>"


# --------------------------------------------------------------------------- noyau


def smoother_gains(P: np.ndarray, P_pred_next: np.ndarray, F: np.ndarray) -> np.ndarray:
    r"""Gains :math:`G_k = P_kF_k^T(P^-_{k+1})^{-1}` pour une pile de pas, par résolution de
    :math:`P^-_{k+1}G_k^T = F_kP_k` (:math:`P_k` et :math:`P^-_{k+1}` symétriques).

    ``P`` (N, n, n), ``P_pred_next`` (N, n, n), ``F`` (N, n, n) ou (n, n). Si :math:`P^-_{k+1}` est
    singulière (bruit d'état dégénéré), la solution de moindres carrés (pseudo-inverse) est la bonne :
    :math:`F_kP_kF_k^T \preceq P^-_{k+1}`, donc l'image de :math:`F_kP_k` est dans celle de
    :math:`P^-_{k+1}`."""
    rhs = F @ P
    try:
        Gt = np.linalg.solve(P_pred_next, rhs)
        if not np.isfinite(Gt).all():
            raise np.linalg.LinAlgError
    except np.linalg.LinAlgError:
        Gt = np.empty_like(rhs)
        for k in range(rhs.shape[0]):
            Gt[k] = scipy.linalg.lstsq(P_pred_next[k], rhs[k])[0]
    return np.swapaxes(Gt, -1, -2)


def rts_pass(x: np.ndarray, P: np.ndarray, x_pred: np.ndarray, P_pred: np.ndarray, G: np.ndarray):
    r"""Passe arrière de RTS avec des gains ``G`` (T, n, n) déjà calculés (``G[T-1]`` ignoré).

    ``x`` (T, n) — ou (T, n, c) : plusieurs moyennes filtrées ensemble, comme le filtre augmenté de
    l'initialisation diffuse — ``P`` (T, n, n), ``x_pred``, ``P_pred`` du filtre. Renvoie ``(xs, Ps, P_lag)`` ;
    ``P_lag[k]`` :math:`= P_{k\mid T}G_{k-1}^T` pour :math:`k \ge 1`, NaN en 0.

    Seule la récurrence est dans la boucle ; les lignes sont lues dans des listes de vues (pas d'indexation
    de tableau à chaque pas) et les résultats empilés à la fin."""
    T = x.shape[0]
    x_next, P_next = x[-1].copy(), P[-1].copy()
    xs_rev, Ps_rev = [x_next], [P_next]
    # lignes k = T-2 … 0 : (x_k, P_k, G_k, x⁻_{k+1}, P⁻_{k+1})
    rows = zip(list(x[-2::-1]), list(P[-2::-1]), list(G[-2::-1]), list(x_pred[:0:-1]), list(P_pred[:0:-1]))
    scalar = P.shape[-1] == 1  # une covariance 1 × 1 est symétrique : rien à symétriser
    for xk, Pk, Gk, xp_next, Pp_next in rows:
        x_next = xk + Gk.dot(x_next - xp_next)
        P_next = Pk + Gk.dot(P_next - Pp_next).dot(Gk.T)
        if not scalar:
            P_next = symmetrize(P_next)  # symétrisation (arrondis)
        xs_rev.append(x_next)
        Ps_rev.append(P_next)
    xs = np.array(xs_rev[::-1]).reshape(x.shape)
    Ps = np.array(Ps_rev[::-1]).reshape(P.shape)
    lag = np.full_like(P, np.nan)
    if T > 1:
        lag[1:] = Ps[1:] @ G[:-1].swapaxes(1, 2)  # Cov(x_{k+1}, x_k | y) = P_{k+1|T} G_kᵀ
    return xs, Ps, lag


def square_root_rts_pass(x: np.ndarray, P: np.ndarray, x_pred: np.ndarray, A: np.ndarray, U_Q: np.ndarray):
    r"""Passe arrière de RTS **en racine carrée**, pour un filtre linéaire (:math:`A`, :math:`Q = U_Q^TU_Q`).

    Le lisseur conditionne :math:`x_k` (filtré : :math:`\hat x_k`, :math:`P_k = U_k^TU_k`) par
    :math:`x_{k+1} = Ax_k + w_k` : c'est une correction de Kalman de « mesure » :math:`x_{k+1}`, de matrice
    :math:`A` et de bruit :math:`Q` (:func:`~kalman_course.core.linalg.correct_square_root`, une QR) ; son
    gain est :math:`G_k = P_kA^T(P^-_{k+1})^{-1}` et sa covariance a posteriori
    :math:`P_k - G_kP^-_{k+1}G_k^T`, de racine :math:`U^c_k`. Alors

    .. math::

        \hat x_{k\mid T} = \hat x_k + G_k(\hat x_{k+1\mid T} - \hat x^-_{k+1}),\qquad
        P_{k\mid T} = (U^c_k)^TU^c_k + G_kP_{k+1\mid T}G_k^T,

    racine de :math:`P_{k\mid T}` par une QR de :math:`[U^c_k;\ U_{k+1\mid T}G_k^T]` : une somme de termes
    semi-définis positifs, sans la soustraction :math:`P_{k+1\mid T} - P^-_{k+1}` de la forme usuelle, qui
    perd tous ses chiffres quand :math:`P_k` est énorme (a priori vague). Mêmes valeurs que
    :func:`rts_pass` aux arrondis près.

    ``x`` (T, n), ``P`` (T, n, n), ``x_pred`` (T, n) du filtre. Renvoie ``(xs, Ps, G, P_lag)`` comme
    :func:`rts_pass` (``G[T-1] = 0``, ``P_lag[0]`` NaN). Lève :class:`KalmanInputError` si une
    :math:`P^-_{k+1}` est singulière (bruit d'état dégénéré et covariance filtrée singulière)."""
    T, n = x.shape
    G = np.zeros((T, n, n))
    U_cond = np.zeros((max(T - 1, 0), n, n))
    if T > 1:
        zeros = np.zeros((T - 1, n))
        _, U_cond, G[:-1], _ = correct_square_root(zeros, covariance_root(P[:-1]), zeros, A, U_Q)
    xs = np.empty_like(x)
    Us = np.empty((T, n, n))
    xs[-1], Us[-1] = x[-1], covariance_root(P[-1])
    for k in range(T - 2, -1, -1):
        xs[k] = x[k] + G[k].dot(xs[k + 1] - x_pred[k + 1])
        Us[k] = triangular_root(np.concatenate((U_cond[k], Us[k + 1].dot(G[k].T))))
    Ps = np.swapaxes(Us, 1, 2) @ Us
    lag = np.full_like(Ps, np.nan)
    if T > 1:
        lag[1:] = Ps[1:] @ np.swapaxes(G[:-1], 1, 2)  # Cov(x_{k+1}, x_k | y) = P_{k+1|T} G_kᵀ
    return xs, Ps, G, lag


def diffuse_rts_pass(A: np.ndarray, augmented: FilterResult, J: np.ndarray, h: np.ndarray):
    r"""Lissage exact de l'initialisation diffuse, sans vérification (le noyau de :func:`rts_smoother` pour un
    :class:`~kalman_course.filters.diffuse.DiffuseFilterResult`, appelé tel quel par l'étape E d'EM, qui
    filtre elle-même et n'a rien à vérifier).

    On lisse le filtre augmenté (moyennes :math:`[a \mid X]` affines en :math:`\delta`, covariance
    :math:`P^a`) avec ses gains :math:`G^a_k = P^a_kA^T(P^{a-}_{k+1})^{-1}`, puis on intègre
    :math:`\delta \sim \mathcal N(J_T^{-1}h_T, J_T^{-1})` :

    .. math::

        \hat x_{k\mid T} = a^s_k + X^s_kJ_T^{-1}h_T,\quad P_{k\mid T} = P^{a,s}_k + X^s_kJ_T^{-1}X^{sT}_k,\quad
        \operatorname{Cov}(x_{k+1}, x_k\mid y) = P^{a,s}_{k+1}G^{aT}_k + X^s_{k+1}J_T^{-1}X^{sT}_k.

    ``A`` (n, n), ou (T, n, n) les matrices de chaque pas d'un modèle variable dans le temps (la ligne
    ``k`` prédite par :math:`A_k`) ; ``augmented`` : le filtre augmenté (``x``, ``x_pred`` (T, n, 1+n), ``P``,
    ``P_pred`` (T, n, n)) ; ``J`` (n, n) définie positive, ``h`` (n,) : :math:`J_T`, :math:`h_T`. Renvoie
    ``(x (T, n), P (T, n, n), P_lag (T, n, n))`` (``P_lag[0]`` NaN)."""
    n = A.shape[-1]
    G_a = np.zeros_like(augmented.P)
    T = G_a.shape[0]
    if T > 1:
        G_a[:-1] = smoother_gains(augmented.P[:-1], augmented.P_pred[1:], A if A.ndim == 2 else A[1:])
    xs_a, Ps_a, lag_a = rts_pass(augmented.x, augmented.P, augmented.x_pred, augmented.P_pred, G_a)
    Xs = xs_a[:, :, 1:]
    cho = scipy.linalg.cho_factor(J, lower=True)
    delta = scipy.linalg.cho_solve(cho, h)
    # J⁻¹Xₖᵀ pour tous les pas d'une seule résolution : J⁻¹[X₀ᵀ … X_{T-1}ᵀ]
    JiXt = scipy.linalg.cho_solve(cho, Xs.swapaxes(1, 2).transpose(1, 0, 2).reshape(n, T * n))
    JiXt = JiXt.reshape(n, T, n).transpose(1, 0, 2)  # (T, n, n)
    xs = xs_a[:, :, 0] + Xs @ delta
    Ps = symmetrize(Ps_a + Xs @ JiXt)
    lag = np.full_like(Ps, np.nan)
    lag[1:] = lag_a[1:] + Xs[1:] @ JiXt[:-1]
    return xs, Ps, lag


# --------------------------------------------------------------------------- vérifications


def _check_order(model: Any, result: Any, call: str) -> None:
    """Les arguments inversés (``rts_smoother(result, model)``) : une erreur qui donne l'appel juste."""
    if isinstance(model, FilterResult):
        raise KalmanInputError(
            f"« model » est un résultat de filtre ({type(model).__name__}) : les arguments sont inversés ; "
            f"appelez {call}(model, result), le modèle d'abord."
        )


def _check_result(result: Any, call: str = "rts_smoother", filter_call: str = "kalman_filter") -> FilterResult:
    """``result`` doit être la sortie d'un filtre (un tirage) ; des mesures à sa place reçoivent l'appel juste :
    tous les lisseurs prennent ``(model, result, x0, P0, u)``."""
    if isinstance(result, FilterRuns):
        raise KalmanInputError(
            f"« result » est un lot de tirages (FilterRuns) : lissez un tirage à la fois, par exemple "
            f"{call}(model, runs.run(0))."
        )
    if isinstance(result, (np.ndarray, list, tuple)):
        raise KalmanInputError(
            f"« result » est un tableau ({type(result).__name__}) : tous les lisseurs du paquet lissent la sortie "
            f"d'un filtre, {call}(model, result, x0, P0, u) ; filtrez d'abord les mesures : "
            f"{call}(model, {filter_call}(model, y, x0, P0), x0, P0)."
        )
    check_instance("result", result, FilterResult, f"la sortie d'un filtre, par exemple {filter_call}")
    if result.x.ndim != 2:
        raise KalmanInputError(
            f"« result » a des états de forme {result.x.shape[1:]} : le lisseur RTS attend des vecteurs "
            "(T, n) (les poses SE(3) ne sont pas prises en charge)."
        )
    return result


def _close(a: np.ndarray, b: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """Écart relatif maximal par pas entre ``a`` et ``b`` (…, ·) rapporté à ``scale`` (…,)."""
    axes = tuple(range(1, a.ndim))
    return np.max(np.abs(a - b), axis=axes) / np.maximum(scale, np.finfo(float).tiny)


def _mismatch(where: str, what: str, k: int, err: float, filters: str) -> KalmanInputError:
    return KalmanInputError(
        f"« result » ne vient pas du {filters} de ce modèle : {what} au pas k = {k} ne correspond pas "
        f"(écart relatif {number_text(err, '.2g')}). Lissez le résultat du filtre qui a utilisé ce même « model »{where}."
    )


def _check_consistency(result: FilterResult, P_pred_next: np.ndarray, x_pred_next: np.ndarray | None,
                       H: np.ndarray, Rn: np.ndarray, filters: str, where: str) -> None:
    r"""Le résultat doit être celui du filtre de ce modèle : :math:`P^-_{k+1}` (et :math:`\hat x^-_{k+1}`
    si fourni) recalculés depuis la ligne ``k``, :math:`S_k = HP^-_kH^T + R` sur les composantes
    observées (si ``H`` est donnée). ``P_pred_next`` (T-1, n, n), ``x_pred_next`` (T-1, n) ou
    (T-1, n, c), ``H`` (T, m, n), (m, n) ou None, ``Rn`` (T, m, m) ou (m, m)."""
    if result.n_steps > 1:
        ref = result.P_pred[1:]
        err = _close(P_pred_next, ref, np.max(np.abs(ref), axis=(1, 2)))
        if (err > CONSISTENCY_RTOL).any():
            k = int(np.argmax(err > CONSISTENCY_RTOL))
            raise _mismatch(where, "la covariance prédite P_pred[k+1] = F P[k] Fᵀ + Q", k, float(err[k]), filters)
        if x_pred_next is not None:
            refx = result.x_pred[1:]
            sd = np.sqrt(np.max(np.diagonal(ref, axis1=1, axis2=2), axis=1))
            scale = np.max(np.abs(refx), axis=tuple(range(1, refx.ndim))) + sd
            err = _close(x_pred_next, refx, scale)
            if (err > CONSISTENCY_RTOL).any():
                k = int(np.argmax(err > CONSISTENCY_RTOL))
                raise _mismatch(where, "la prédiction x_pred[k+1] = f(x[k], u)", k, float(err[k]), filters)
    obs = np.asarray(result.observed, dtype=bool)
    rows = obs.any(axis=1)
    if H is not None and rows.any():
        Hs = np.broadcast_to(H, (result.n_steps,) + np.shape(H)[-2:])[rows]
        Rs = np.broadcast_to(Rn, (result.n_steps,) + np.shape(Rn)[-2:])[rows]
        S = Hs @ result.P_pred[rows] @ np.swapaxes(Hs, 1, 2) + Rs
        both = obs[rows][:, :, None] & obs[rows][:, None, :]
        S_ref = np.where(both, result.S[rows], 0.0)
        S_new = np.where(both, S, 0.0)
        err = _close(S_new, S_ref, np.max(np.abs(S_ref), axis=(1, 2)))
        if (err > CONSISTENCY_RTOL).any():
            k = int(np.flatnonzero(rows)[np.argmax(err > CONSISTENCY_RTOL)])
            i = int(np.argmax(err > CONSISTENCY_RTOL))
            raise _mismatch(where, "la covariance d'innovation S[k] = C P_pred[k] Cᵀ + R", k, float(err[i]), filters)


def _check_finite(result: FilterResult) -> None:
    bad = ~np.isfinite(result.P).all(axis=(1, 2)) | ~np.isfinite(result.x).all(axis=1)
    if bad.any():
        raise KalmanInputError(
            f"« result » contient des estimations non déterminées (NaN) à partir du pas k = {int(np.argmax(bad))} : "
            "pour un départ sans a priori, filtrez avec diffuse_kalman_filter, dont rts_smoother sait lisser "
            "le résultat."
        )


def _initial(model_n: int, x0: Any, P0: Any):
    if (x0 is None) != (P0 is None):
        raise KalmanInputError("« x0 » et « P0 » vont ensemble : donnez les deux (a priori du filtre) ou aucun.")
    if x0 is None:
        return None
    return as_gaussian(x0, P0, model_n, "x0", "P0")


def _check_prior(P_pred0, fx0, result: FilterResult) -> None:
    """``(x0, P0)`` doit être l'a priori du filtre : sa prédiction ``P_pred0`` (:math:`F_0P_0F_0^T + Q_0`)
    redonne ``result.P_pred[0]`` (et ``fx0``, :math:`f(x_0)`, redonne ``result.x_pred[0]`` si elle est
    donnée)."""
    ref = result.P_pred[0]
    if np.max(np.abs(P_pred0 - ref)) > CONSISTENCY_RTOL * max(np.max(np.abs(ref)), np.finfo(float).tiny):
        raise KalmanInputError(
            "« P0 » n'est pas l'a priori du filtre : F P0 Fᵀ + Q ne redonne pas result.P_pred[0]. "
            "Donnez les x0, P0 passés au filtre."
        )
    if fx0 is not None:
        scale = np.max(np.abs(result.x_pred[0])) + np.sqrt(np.max(np.diag(ref)))
        if np.max(np.abs(fx0 - result.x_pred[0])) > CONSISTENCY_RTOL * max(scale, np.finfo(float).tiny):
            raise KalmanInputError(
                "« x0 » n'est pas l'a priori du filtre : sa prédiction ne redonne pas result.x_pred[0]. "
                "Donnez les x0, P0 passés au filtre."
            )


def _smooth_initial(x0, P0, F0, Q0, fx0, result: FilterResult, xs0, Ps0):
    """Lisse l'état initial (instant 0) : vérifie que ``(x0, P0)`` est l'a priori du filtre."""
    _check_prior(symmetrize(F0.dot(P0).dot(F0.T) + Q0), fx0, result)
    ref = result.P_pred[0]
    try:  # en racine carrée (voir square_root_rts_pass) : sûr pour un a priori vague
        _, U_cond, G0, _ = correct_square_root(x0, covariance_root(P0), np.zeros(len(x0)), F0, covariance_root(Q0))
        U_init = triangular_root(np.concatenate((U_cond, covariance_root(Ps0).dot(G0.T))))
        P_init = U_init.T.dot(U_init)
    except KalmanInputError:  # P⁻ singulière : gain de moindres carrés, forme usuelle
        G0 = smoother_gains(P0[None], ref[None], F0)[0]
        P_init = symmetrize(P0 + G0.dot(Ps0 - ref).dot(G0.T))
    x_init = x0 + G0.dot(xs0 - result.x_pred[0])
    return x_init, P_init, G0, Ps0.dot(G0.T)


class LinearSmootherInputs(NamedTuple):
    r"""Ce que les lisseurs linéaires lisent, vérifié (:func:`linear_smoother_inputs`) : ``A`` (T, n, n) et
    ``Q`` (T, n, n) les matrices de chaque pas (la ligne ``k`` est prédite depuis la ligne ``k-1`` par
    :math:`A_k`), ``prior`` :math:`(\hat x_0, P_0)` ou ``None``, ``U`` (T, p) ou ``None``."""

    A: np.ndarray
    Q: np.ndarray
    prior: tuple[np.ndarray, np.ndarray] | None
    U: np.ndarray | None


def linear_smoother_inputs(model: Any, result: Any, x0: Any, P0: Any, u: Any, call: str = "rts_smoother",
                           filter_call: str = "kalman_filter", diffuse: bool = True) -> LinearSmootherInputs:
    r"""Les vérifications communes des lisseurs linéaires (``lisseur(model, result, x0, P0, u)`` :
    :func:`rts_smoother`, :func:`~kalman_course.parallel_rts_smoother`) : ordre des arguments, ``model``
    linéaire, ``result`` d'un filtre de ce modèle (dimensions, valeurs déterminées, prédictions
    :math:`P^-_{k+1} = A_{k+1}P_kA_{k+1}^T + Q_{k+1}` et :math:`\hat x^-_{k+1} = A_{k+1}\hat x_k + B_{k+1}u_{k+1}`
    retrouvées, :math:`S_k`), et l'a priori ``(x0, P0)`` du filtre s'il est donné. ``diffuse=False`` : un
    résultat de :func:`~kalman_course.diffuse_kalman_filter` est refusé (``call`` ne le lisse pas)."""
    _check_order(model, result, call)
    check_instance("model", model, LinearGaussianModel, "pour un modèle non linéaire, utilisez extended_rts_smoother")
    result = _check_result(result, call, filter_call)
    if isinstance(result, DiffuseFilterResult) and not diffuse:
        raise KalmanInputError(
            f"« result » vient de diffuse_kalman_filter : {call} ne lisse pas l'initialisation diffuse ; "
            "lissez-le avec rts_smoother(model, result)."
        )
    n, m, T = model.n_state, model.n_obs, result.n_steps
    _check_dimensions(result, n, m)
    _check_finite(result)
    U = as_controls("u", u, T, model.n_control)
    A, Q = np.asarray(model.sequence("A", T)), np.asarray(model.sequence("Q", T))
    x, P = result.x, result.P
    x_next = None
    if model.B is None:
        x_next = (A[1:] @ x[:-1, :, None])[:, :, 0]
    elif U is not None:
        Bu = (np.asarray(model.sequence("B", T)) @ U[:, :, None])[:, :, 0]
        x_next = (A[1:] @ x[:-1, :, None])[:, :, 0] + Bu[1:]
    C, R = (model.sequence("C", T), model.sequence("R", T)) if model.time_varying else (model.C, model.R)
    _check_consistency(result, symmetrize(A[1:] @ P[:-1] @ np.swapaxes(A[1:], 1, 2) + Q[1:]), x_next, C, R,
                       "filtre de Kalman", f" ({call} lisse la sortie de {filter_call})")
    prior = _initial(n, x0, P0)
    if prior is not None:
        fx0 = None
        if model.B is None:
            fx0 = A[0].dot(prior[0])
        elif U is not None:
            fx0 = A[0].dot(prior[0]) + np.asarray(model.sequence("B", T))[0].dot(U[0])
        _check_prior(symmetrize(A[0].dot(prior[1]).dot(A[0].T) + Q[0]), fx0, result)
    return LinearSmootherInputs(A, Q, prior, U)


# --------------------------------------------------------------------------- lisseurs


def rts_smoother(model: LinearGaussianModel, result: FilterResult, x0: Any = None, P0: Any = None,
                 u: Any = None) -> SmootherResult:
    r"""Lisseur de Rauch–Tung–Striebel pour un résultat du filtre de Kalman linéaire.

    .. math::

        G_k = P_{k\mid k}A^TP_{k+1\mid k}^{-1},\quad
        \hat x_{k\mid T} = \hat x_{k\mid k} + G_k(\hat x_{k+1\mid T} - \hat x_{k+1\mid k}),\quad
        P_{k\mid T} = P_{k\mid k} + G_k(P_{k+1\mid T} - P_{k+1\mid k})G_k^T.

    **La forme de tous les lisseurs du paquet** : ``lisseur(model, result, x0, P0, u)`` — le modèle, la
    sortie du filtre (comme un filtre prend les mesures), l'a priori du filtre et ses commandes, tous
    positionnels et facultatifs après ``result`` ; puis les options par leur nom. Le lisseur ne refiltre pas :
    il lisse le résultat qu'on lui donne (celui de :func:`~kalman_course.kalman_filter`, d'un filtre à porte,
    du filtre parallèle…), après avoir vérifié qu'il vient bien de ce modèle.

    Paramètres
    ----------
    model : LinearGaussianModel — celui du filtre (constant ou variable dans le temps).
    result : FilterResult de :func:`~kalman_course.kalman_filter` (mesures manquantes et commandes
        comprises), ou :class:`~kalman_course.filters.diffuse.DiffuseFilterResult` de
        :func:`~kalman_course.diffuse_kalman_filter` (initialisation diffuse exacte, voir plus bas).
    x0 : (n,), P0 : (n, n), optionnels — l'a priori donné au filtre : l'état initial (instant 0) est
        alors lissé aussi (``x_initial``, ``P_initial``, ``G_initial``, ``P_lag[0]``).
    u : (T, p), optionnel — les commandes données au filtre (elles servent à vérifier ses prédictions).

    Initialisation diffuse : sachant :math:`\delta` (l'état de la première mesure), le filtre augmenté est un
    filtre ordinaire ; on lisse ses moyennes :math:`[a \mid X]` (affines en :math:`\delta`) et sa
    covariance, puis on intègre :math:`\delta \sim \mathcal N(J_T^{-1}h_T, J_T^{-1})` :
    :math:`\hat x_{k\mid T} = a^s_k + X^s_kJ_T^{-1}h_T`,
    :math:`P_{k\mid T} = P^{a,s}_k + X^s_kJ_T^{-1}X^{sT}_k` et
    :math:`\operatorname{Cov}(x_{k+1}, x_k\mid y) = P^{a,s}_{k+1}G^{aT}_k + X^s_{k+1}J_T^{-1}X^{sT}_k`.

    Renvoie un :class:`SmootherResult` (``x`` (T, n), ``P`` (T, n, n), ``G``, ``P_lag``).
    """
    _check_order(model, result, "rts_smoother")
    if isinstance(result, DiffuseFilterResult):
        check_instance("model", model, LinearGaussianModel,
                       "pour un modèle non linéaire, utilisez extended_rts_smoother")
        if x0 is not None or P0 is not None:
            raise KalmanInputError(
                "« x0 », « P0 » : un résultat de diffuse_kalman_filter n'a pas d'a priori ; ne les donnez pas."
            )
        return _diffuse_rts(model, result, u)
    inputs = linear_smoother_inputs(model, result, x0, P0, u)
    A, Q = inputs.A, inputs.Q
    x, P = result.x, result.P
    sqrt_pass = None
    if not model.time_varying:  # en racine carrée : sûr pour un a priori vague (modèle constant)
        try:
            sqrt_pass = square_root_rts_pass(x, P, result.x_pred, model.A, model.noise_roots[0])
        except KalmanInputError:  # P⁻ singulière : gains de moindres carrés, forme usuelle ci-dessous
            pass
    if sqrt_pass is not None:
        xs, Ps, G, lag = sqrt_pass
    else:  # modèle variable dans le temps, ou P⁻ singulière : gains de smoother_gains, forme usuelle
        G = np.zeros_like(P)
        if result.n_steps > 1:
            G[:-1] = smoother_gains(P[:-1], result.P_pred[1:], A[1:])
        xs, Ps, lag = rts_pass(x, P, result.x_pred, result.P_pred, G)
    initial = (None, None, None)
    if inputs.prior is not None:
        x0_arr, P0_arr = inputs.prior
        *initial, lag[0] = _smooth_initial(x0_arr, P0_arr, A[0], Q[0], None, result, xs[0], Ps[0])
    return SmootherResult(xs, Ps, G, lag, *initial, method="RTS")


def _check_dimensions(result: FilterResult, n: int, m: int) -> None:
    if result.x.shape[1] != n or result.innovation.shape[1] != m:
        raise KalmanInputError(
            f"« result » ne vient pas de ce modèle : états de dimension {result.x.shape[1]} et mesures de "
            f"dimension {result.innovation.shape[1]}, le modèle attend n = {n} et m = {m}."
        )


def _diffuse_rts(model: LinearGaussianModel, result: DiffuseFilterResult, u: Any = None) -> SmootherResult:
    aug = result.augmented
    n, T = model.n_state, result.n_steps
    _check_dimensions(result, n, model.n_obs)
    U = as_controls("u", u, T, model.n_control)
    A, Q = np.asarray(model.sequence("A", T)), np.asarray(model.sequence("Q", T))
    x_next = None  # la ligne k+1 prédite depuis la ligne k, colonne a avec B u, colonnes X sans
    if model.B is None or U is not None:
        x_next = A[1:] @ aug.x[:-1]
        if model.B is not None:
            x_next[:, :, 0] += (np.asarray(model.sequence("B", T)) @ U[:, :, None])[1:, :, 0]
    C, R = (model.sequence("C", T), model.sequence("R", T)) if model.time_varying else (model.C, model.R)
    _check_consistency(aug, symmetrize(A[1:] @ aug.P[:-1] @ np.swapaxes(A[1:], 1, 2) + Q[1:]), x_next, C, R,
                       "filtre de Kalman à initialisation diffuse", " (diffuse_kalman_filter)")
    J, h = result.information[-1], result.information_vector[-1]
    if not is_determined(J):
        raise KalmanInputError(
            "Les mesures ne déterminent pas l'état (information J_T singulière : modèle non observable "
            "ou trop peu de mesures) : pas de lissage possible sans a priori."
        )
    xs, Ps, lag = diffuse_rts_pass(A, aug, J, h)
    # gains du filtre exact là où son estimation est déterminée
    G = np.full_like(Ps, np.nan)
    G[-1] = 0.0
    ok = np.isfinite(result.P[:-1]).all(axis=(1, 2))
    if ok.any():
        G[:-1][ok] = smoother_gains(result.P[:-1][ok], result.P_pred[1:][ok], A[1:][ok])
    return SmootherResult(xs, Ps, G, lag, method="RTS, initialisation diffuse exacte")


def extended_rts_smoother(model: NonlinearModel, result: FilterResult, x0: Any = None, P0: Any = None,
                          u: Any = None) -> SmootherResult:
    r"""Lisseur RTS étendu pour un résultat de :func:`~kalman_course.extended_kalman_filter` (ou de l'EKF
    itéré, dont la prédiction est la même).

    :math:`A` devient la jacobienne de la prédiction du filtre,
    :math:`F_k = \partial f/\partial x\,(\hat x_{k\mid k}, u_k)` (la ligne ``k+1`` est prédite avec
    ``u[k+1]``, qui contient :math:`u_k`) :

    .. math::

        G_k = P_{k\mid k}F_k^TP_{k+1\mid k}^{-1},\quad
        \hat x_{k\mid T} = \hat x_{k\mid k} + G_k(\hat x_{k+1\mid T} - \hat x_{k+1\mid k}),\quad
        P_{k\mid T} = P_{k\mid k} + G_k(P_{k+1\mid T} - P_{k+1\mid k})G_k^T.

    Sur un modèle linéaire (:meth:`~kalman_course.NonlinearModel.from_linear`), c'est :func:`rts_smoother`.

    Paramètres
    ----------
    model : NonlinearModel — celui du filtre.
    result : FilterResult de l'EKF.
    x0 : (n,), P0 : (n, n), optionnels — l'a priori du filtre, pour lisser aussi l'état initial.
    u : (T, p), ou (T,) si p = 1, optionnel — les commandes données au filtre (nécessaires : elles
        entrent dans :math:`F_k`).
    """
    _check_order(model, result, "extended_rts_smoother")
    model = check_instance("model", model, NonlinearModel, NONLINEAR_HINT.replace("kalman_filter", "rts_smoother"))
    result = _check_result(result, "extended_rts_smoother", "extended_kalman_filter")
    if isinstance(result, DiffuseFilterResult):
        raise KalmanInputError("« result » vient du filtre à initialisation diffuse (linéaire) : lissez-le avec rts_smoother.")
    n, m, T = model.n_state, model.n_obs, result.n_steps
    _check_dimensions(result, n, m)
    _check_finite(result)
    U = as_controls("u", u, T, model.n_control)

    def control(k):
        return None if U is None else U[k]

    x, P = result.x, result.P
    F = np.empty((max(T - 1, 0), n, n))
    Qn = np.empty_like(F)
    fx = np.empty((max(T - 1, 0), n))
    for k in range(T - 1):
        F[k] = model.transition_jacobian(x[k], control(k + 1))
        Qn[k] = model.process_noise(x[k], control(k + 1))
        fx[k] = model.transition(x[k], control(k + 1))
    # S_k = H P⁻ Hᵀ + VRVᵀ en x̂⁻ pour l'EKF ; l'EKF itéré linéarise ailleurs (dernier itéré) : seule sa
    # prédiction, la même que celle de l'EKF, est alors vérifiée
    H = Rn = None
    iterated = result.n_iter is not None and bool((np.asarray(result.n_iter) > 1).any())
    if not iterated:
        H = np.empty((T, m, n))
        Rn = np.empty((T, m, m))
        for k in range(T):
            H[k] = model.observation_jacobian(result.x_pred[k])
            Rn[k] = model.measurement_noise(result.x_pred[k])
    _check_consistency(result, symmetrize(F @ P[:-1] @ np.swapaxes(F, 1, 2) + Qn), fx, H, Rn,
                       "filtre de Kalman étendu", " et les mêmes commandes « u » (extended_rts_smoother lisse la "
                       "sortie d'extended_kalman_filter)")
    G = np.zeros_like(P)
    if T > 1:
        G[:-1] = smoother_gains(P[:-1], result.P_pred[1:], F)
    xs, Ps, lag = rts_pass(x, P, result.x_pred, result.P_pred, G)
    prior = _initial(n, x0, P0)
    initial = (None, None, None)
    if prior is not None:
        x0_arr, P0_arr = prior
        F0 = model.transition_jacobian(x0_arr, control(0))
        *initial, lag[0] = _smooth_initial(x0_arr, P0_arr, F0, model.process_noise(x0_arr, control(0)),
                                           model.transition(x0_arr, control(0)), result, xs[0], Ps[0])
    return SmootherResult(xs, Ps, G, lag, *initial, method="RTS étendu")


def unscented_rts_smoother(model: NonlinearModel, result: FilterResult, x0: Any = None, P0: Any = None,
                           u: Any = None, *, alpha: float | None = None, beta: float = 2.0,
                           kappa: float | None = None) -> SmootherResult:
    r"""Lisseur RTS « unscented » (Särkkä, 2008) pour un résultat de
    :func:`~kalman_course.unscented_kalman_filter`, avec les mêmes paramètres :math:`(\alpha, \beta, \kappa)`.

    Pour :math:`k = T-2, \dots, 0` : points sigma :math:`\chi_i` de :math:`(\hat x_{k\mid k}, P_{k\mid k})`,
    images :math:`\chi_i^f = f(\chi_i, u_k)` (:math:`u_k` : ligne ``u[k+1]``), puis

    .. math::

        \bar x = \sum_i W^m_i\chi_i^f,\quad
        \bar P = \sum_i W^c_i(\chi_i^f - \bar x)(\chi_i^f - \bar x)^T + Q,\quad
        C = \sum_i W^c_i(\chi_i - \hat x_{k\mid k})(\chi_i^f - \bar x)^T,

        G_k = C\bar P^{-1},\quad
        \hat x_{k\mid T} = \hat x_{k\mid k} + G_k(\hat x_{k+1\mid T} - \bar x),\quad
        P_{k\mid T} = P_{k\mid k} + G_k(P_{k+1\mid T} - \bar P)G_k^T .

    :math:`(\bar x, \bar P)` est la prédiction de l'UKF : on vérifie qu'elle redonne celle du résultat
    (même modèle, même filtre, mêmes paramètres). Sur un modèle linéaire avec :math:`\alpha = 1`,
    :math:`\beta = 2`, :math:`\kappa = 0`, c'est :func:`rts_smoother`. ``G`` (T, n, n), ``P_lag`` comme
    :func:`rts_smoother`.

    Paramètres : la forme de tous les lisseurs, ``(model, result, x0, P0, u)`` (voir :func:`rts_smoother`) —
    ``x0`` (n,), ``P0`` (n, n) : l'a priori du filtre, pour lisser aussi l'état initial (même étape depuis
    :math:`(\hat x_0, P_0)`) ; ``u`` (T, p) : les commandes données au filtre ; puis ``alpha``, ``beta``,
    ``kappa`` : ceux du filtre, avec les mêmes règles (``alpha`` et ``kappa`` obligatoires, ``beta = 2`` par
    défaut).
    """
    from .gaussian import predict_gaussian
    from .unscented import UnscentedRule

    _check_order(model, result, "unscented_rts_smoother")
    model = check_instance("model", model, NonlinearModel, NONLINEAR_HINT.replace("kalman_filter", "rts_smoother"))
    result = _check_result(result, "unscented_rts_smoother", "unscented_kalman_filter")
    n, m, T = model.n_state, model.n_obs, result.n_steps
    _check_dimensions(result, n, m)
    _check_finite(result)
    U = as_controls("u", u, T, model.n_control)
    rule = UnscentedRule(alpha, beta, kappa)
    rule.check(model)
    x, P = result.x, result.P
    xb = np.empty((max(T - 1, 0), n))
    Pb = np.empty((max(T - 1, 0), n, n))
    G = np.zeros_like(P)
    for k in range(T - 1):
        # la prédiction de l'UKF (filtre gaussien, même code) et sa covariance croisée C = Cov[x, f(x)]
        xb[k], Pb[k], mom = predict_gaussian(rule, model, x[k], P[k], None if U is None else U[k + 1],
                                             f"lissage du pas {k}")
        G[k] = np.linalg.solve(Pb[k], mom.cross.T).T  # G = C P̄⁻¹, P̄ symétrique
    _check_consistency(result, Pb, xb, None, None, "filtre de Kalman unscented",
                       ", les mêmes paramètres (alpha, beta, kappa) et les mêmes commandes « u » "
                       "(unscented_rts_smoother lisse la sortie d'unscented_kalman_filter)")
    xs, Ps, lag = rts_pass(x, P, result.x_pred, result.P_pred, G)
    prior = _initial(n, x0, P0)
    initial = (None, None, None)
    if prior is not None:  # l'état initial : la même étape depuis (x̂₀, P₀)
        x0_arr, P0_arr = prior
        x_bar, P_bar, mom = predict_gaussian(rule, model, x0_arr, P0_arr, None if U is None else U[0],
                                             "lissage de l'état initial")
        _check_prior(P_bar, x_bar, result)
        G0 = np.linalg.solve(P_bar, mom.cross.T).T
        x_init = x0_arr + G0.dot(xs[0] - x_bar)
        P_init = symmetrize(P0_arr + G0.dot(Ps[0] - P_bar).dot(G0.T))
        initial = (x_init, P_init, G0)
        lag[0] = Ps[0].dot(G0.T)
    return SmootherResult(xs, Ps, G, lag, *initial, method="RTS unscented")
