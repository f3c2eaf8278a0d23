r"""Filtrer et lisser en parallèle dans le temps : le balayage associatif de Särkkä et García-Fernández (2021).

Le filtre de Kalman est une récurrence : :math:`(\hat x_k, P_k)` dépend de :math:`(\hat x_{k-1}, P_{k-1})`,
donc :math:`T` pas l'un après l'autre. Särkkä et García-Fernández écrivent chaque pas comme un **élément**
:math:`a_k` et la loi filtrée au pas :math:`k` comme le **produit** :math:`a_1 \otimes a_2 \otimes \cdots
\otimes a_k` d'un opérateur :math:`\otimes` **associatif** : tous les produits préfixes se calculent alors
par un balayage (*prefix scan*) en :math:`O(\log T)` passes, chacune étant une seule opération sur tous les
éléments à la fois.

**Éléments du filtre** (modèle :math:`x_k = Ax_{k-1} + c_k + w_k`, :math:`c_k = Bu_k`,
:math:`y_k = Cx_k + v_k`). Un élément :math:`a = (F, b, \Sigma, \eta, J)` représente la loi conditionnelle
:math:`p(x_k \mid x_{k-1}, y_k) = \mathcal N(Fx_{k-1} + b, \Sigma)` et la vraisemblance
:math:`p(y_k \mid x_{k-1}) \propto \exp(-\tfrac12 x_{k-1}^TJx_{k-1} + \eta^Tx_{k-1})` :

.. math::

    S_k = CQC^T + R,\quad K_k = QC^TS_k^{-1},\quad
    F_k = (I - K_kC)A,\quad b_k = c_k + K_k(y_k - Cc_k),\quad \Sigma_k = (I - K_kC)Q,

    \eta_k = A^TC^TS_k^{-1}(y_k - Cc_k),\qquad J_k = A^TC^TS_k^{-1}CA ;

le premier élément contient l'a priori : :math:`F_1 = 0`, :math:`\eta_1 = 0`, :math:`J_1 = 0`,
:math:`(b_1, \Sigma_1)` la correction de Kalman de :math:`(A\hat x_0 + c_1, AP_0A^T + Q)` par :math:`y_1`.
Une composante manquante a sa ligne de :math:`C` mise à zéro (et sa variance dans :math:`R` à 1, sans
corrélation) : elle ne compte pas.

**Opérateur** (:math:`a_i` avant :math:`a_j`), avec :math:`M = (I + \Sigma_iJ_j)^{-1}` :

.. math::

    F_{ij} = F_jMF_i,\quad b_{ij} = F_jM(b_i + \Sigma_i\eta_j) + b_j,\quad
    \Sigma_{ij} = F_jM\Sigma_iF_j^T + \Sigma_j,

    \eta_{ij} = F_i^TM^T(\eta_j - J_jb_i) + \eta_i,\quad J_{ij} = F_i^TM^TJ_jF_i + J_i

(:math:`(I + J_j\Sigma_i)^{-1} = M^T` car :math:`\Sigma_i` et :math:`J_j` sont symétriques : une seule
résolution par combinaison). Le produit :math:`a_1 \otimes \cdots \otimes a_k` a :math:`F = 0` et
:math:`(b, \Sigma) = (\hat x_{k\mid k}, P_{k\mid k})`.

**Éléments du lisseur** : :math:`E_k = P_kA^T(P^-_{k+1})^{-1}` (le gain de RTS),
:math:`g_k = \hat x_k - E_k\hat x^-_{k+1}`, :math:`L_k = P_k - E_kP^-_{k+1}E_k^T` (au dernier pas
:math:`E = 0`, :math:`g = \hat x_T`, :math:`L = P_T`), et :math:`a_k \otimes a_{k+1} = (E_kE_{k+1},\
E_kg_{k+1} + g_k,\ E_kL_{k+1}E_k^T + L_k)` ; le produit suffixe :math:`a_k \otimes \cdots \otimes a_T` a
:math:`(g, L) = (\hat x_{k\mid T}, P_{k\mid T})`.

**Balayage** : celui de Blelloch (ou de ``jax.lax.associative_scan``) : combiner les paires voisines,
balayer récursivement la suite deux fois plus courte, puis compléter les rangs pairs — :math:`2\lceil\log_2
T\rceil` passes vectorisées (numpy, sur tous les éléments d'un niveau à la fois) et environ :math:`2T`
combinaisons en tout. Sur un processeur à deux cœurs, cela paie parce que numpy traite un niveau entier en
un appel là où la boucle de :func:`~kalman_course.kalman_filter` paie le surcoût de Python à chaque pas ;
sur un GPU, les :math:`T` éléments d'un niveau se combinent réellement en même temps.

Les prédictions, innovations, :math:`S_k` et gains sont recalculés ensuite, tous les pas à la fois, avec les
formules du filtre séquentiel : le résultat est le même :class:`~kalman_course.FilterResult` que celui de
:func:`~kalman_course.kalman_filter` (donc la même log-vraisemblance).
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np
import scipy.linalg

from ..core.linalg import symmetrize
from ..core.models import LinearGaussianModel
from ..core.results import FilterResult
from ..core.validation import (
    as_controls,
    as_gaussian,
    as_measurements,
    check_instance,
)
from .smoothers import SmootherResult, smoother_gains

__all__ = [
    "associative_scan",
    "filtering_elements",
    "combine_filtering",
    "combine_smoothing",
    "observation_patterns",
    "parallel_kalman_filter",
    "parallel_rts_smoother",
    "scan_passes",
]

_HINT = "le filtre parallèle est celui du modèle linéaire ; pour un modèle non linéaire, utilisez extended_kalman_filter"

Elements = tuple[np.ndarray, ...]


# --------------------------------------------------------------------------- le balayage


def associative_scan(combine: Callable[[Elements, Elements], Elements], elements: Elements) -> Elements:
    r"""Tous les produits préfixes :math:`a_0 \otimes a_1 \otimes \cdots \otimes a_k` (:math:`k = 0 \dots T-1`)
    d'un opérateur associatif ``combine``, par le balayage de Blelloch.

    ``elements`` : tuple de tableaux dont le premier axe est celui des éléments (T, …) ;
    ``combine(a, b)`` combine deux piles de même longueur, :math:`a_i \otimes b_i` élément par élément
    (``a`` avant ``b``). :math:`2\lceil\log_2 T\rceil` appels de ``combine`` (:func:`scan_passes`),
    environ :math:`2T` combinaisons en tout. Renvoie un tuple de tableaux (T, …)."""
    T = elements[0].shape[0]
    if T < 2:
        return tuple(np.array(e) for e in elements)
    pairs = combine(tuple(e[0:-1:2] for e in elements), tuple(e[1::2] for e in elements))
    odd = associative_scan(combine, pairs)  # préfixes aux rangs impairs 1, 3, 5…
    out = []
    for e, o in zip(elements, odd):
        r = np.empty((T,) + o.shape[1:], dtype=o.dtype)
        r[0] = e[0]
        r[1::2] = o
        out.append(r)
    if T > 2:  # rangs pairs 2, 4… : le préfixe impair qui précède, combiné avec l'élément
        even = combine(tuple(o[: (T - 1) // 2] for o in odd), tuple(e[2::2] for e in elements))
        for r, v in zip(out, even):
            r[2::2] = v
    return tuple(out)


def scan_passes(T: int) -> int:
    r"""Nombre d'appels de l'opérateur (passes vectorisées) de :func:`associative_scan` pour ``T`` éléments
    (:math:`2\lceil\log_2 T\rceil - 1` environ ; 0 pour un seul élément)."""
    if T < 2:
        return 0
    return 1 + scan_passes(T // 2) + (1 if (T - 1) // 2 > 0 else 0)


def _mT(M: np.ndarray) -> np.ndarray:
    return np.swapaxes(M, -1, -2)


def _mv(M: np.ndarray, v: np.ndarray) -> np.ndarray:
    return (M @ v[..., None])[..., 0]


def combine_filtering(first: Elements, second: Elements) -> Elements:
    r"""L'opérateur associatif du filtre, :math:`a_i \otimes a_j` (voir l'en-tête) ; ``first`` et ``second``
    sont des piles ``(F (N, n, n), b (N, n), Σ (N, n, n), η (N, n), J (N, n, n))``.

    Si ``first`` est une pile de **préfixes** (:math:`F_i = 0`, donc :math:`\eta_i = 0`, :math:`J_i = 0` :
    une loi filtrée), le produit en est un aussi : seuls :math:`b` et :math:`\Sigma` sont calculés (c'est
    le cas de la moitié des combinaisons du balayage, qui complètent un préfixe par un élément)."""
    Fi, bi, Si, ei, Ji = first
    Fj, bj, Sj, ej, Jj = second
    n = bi.shape[-1]
    M = np.eye(n) + Si @ Jj
    prefix = not Fi.any()
    if prefix:
        rhs = np.concatenate([(bi + _mv(Si, ej))[..., None], Si], axis=-1)
    else:
        rhs = np.concatenate([Fi, (bi + _mv(Si, ej))[..., None], Si], axis=-1)
    W = np.linalg.solve(M, rhs)  # (I + Σᵢ Jⱼ)⁻¹ [Fᵢ | bᵢ + Σᵢηⱼ | Σᵢ]
    Wb, WS = W[..., -n - 1], W[..., -n:]
    b = _mv(Fj, Wb) + bj
    S = symmetrize(Fj @ WS @ _mT(Fj) + Sj)
    if prefix:
        zero_n, zero_nn = np.zeros((1, n)), np.zeros((1, n, n))
        N = bi.shape[0]
        return (np.broadcast_to(zero_nn, (N, n, n)), b, S, np.broadcast_to(zero_n, (N, n)),
                np.broadcast_to(zero_nn, (N, n, n)))
    WF = W[..., :n]
    WFt = _mT(WF)
    return (
        Fj @ WF,
        b,
        S,
        _mv(WFt, ej - _mv(Jj, bi)) + ei,
        symmetrize(WFt @ Jj @ Fi + Ji),
    )


def combine_smoothing(later: Elements, earlier: Elements) -> Elements:
    r"""L'opérateur associatif du lisseur, dans l'ordre du balayage arrière : ``later`` (les pas
    :math:`k+1 \dots T`, déjà combinés) puis ``earlier`` (le pas :math:`k`) ; piles
    ``(E (N, n, n), g (N, n), L (N, n, n))``. Renvoie :math:`(E_kE_{k+1}, E_kg_{k+1} + g_k,
    E_kL_{k+1}E_k^T + L_k)`."""
    Ep, gp, Lp = later
    Eq, gq, Lq = earlier
    E = np.broadcast_to(np.zeros((1,) + Ep.shape[1:]), Ep.shape) if not Ep.any() else Eq @ Ep  # suffixe : E = 0
    return E, _mv(Eq, gp) + gq, symmetrize(Eq @ Lp @ _mT(Eq) + Lq)


# --------------------------------------------------------------------------- éléments


def observation_patterns(observed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Motifs distincts de composantes observées (P, m) et motif de chaque pas (T,) — comme
    ``np.unique(observed, axis=0, return_inverse=True)``, sans tri de lignes quand tout est observé."""
    T, m = observed.shape
    if observed.all():
        return np.ones((1, m), dtype=bool), np.zeros(T, dtype=int)
    codes = observed.astype(np.int64) @ (1 << np.arange(m, dtype=np.int64)) if m < 62 else None
    if codes is None:
        patterns, group = np.unique(observed, axis=0, return_inverse=True)
        return patterns, group.ravel()
    values, group = np.unique(codes, return_inverse=True)
    patterns = ((values[:, None] >> np.arange(m)) & 1).astype(bool)
    return patterns, group.ravel()


def _masked(model: LinearGaussianModel, pattern: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:math:`C` et :math:`R` où les composantes non observées ne comptent plus : lignes de :math:`C` nulles,
    variance 1 sans corrélation dans :math:`R`."""
    C = model.C * pattern[:, None]
    keep = np.outer(pattern, pattern)
    R = np.where(keep, model.R, 0.0) + np.diag((~pattern).astype(float))
    return C, R


def filtering_elements(model: LinearGaussianModel, Y: np.ndarray, x0: np.ndarray, P0: np.ndarray,
                       BU: np.ndarray | None) -> Elements:
    r"""Les :math:`T` éléments :math:`(F_k, b_k, \Sigma_k, \eta_k, J_k)` du filtre (voir l'en-tête) :
    ``Y`` (T, m) (``NaN`` : composante manquante), ``x0`` (n,), ``P0`` (n, n), ``BU`` (T, n) les termes
    :math:`Bu_k` ou ``None``. Calculés par motif de composantes observées (un seul motif sans mesure
    manquante : les matrices sont alors communes à tous les pas)."""
    T, n = Y.shape[0], model.n_state
    A, Q = model.A, model.Q
    observed = ~np.isnan(Y)
    Yz = np.where(observed, Y, 0.0)
    c = np.zeros((T, n)) if BU is None else BU
    F = np.empty((T, n, n))
    b = np.empty((T, n))
    S_ = np.empty((T, n, n))
    eta = np.empty((T, n))
    J = np.empty((T, n, n))
    patterns, group = observation_patterns(observed)
    for g, pattern in enumerate(patterns):
        rows = np.flatnonzero(group == g) if len(patterns) > 1 else slice(None)
        C, R = _masked(model, pattern)
        S = C @ Q @ C.T + R
        SiC = scipy.linalg.solve(S, C, assume_a="pos")      # S⁻¹C (m, n)
        K = Q @ SiC.T                                        # Q Cᵀ S⁻¹
        IKC = np.eye(n) - K @ C
        SiCA = SiC @ A
        F[rows] = IKC @ A
        S_[rows] = symmetrize(IKC @ Q)
        J[rows] = symmetrize(A.T @ C.T @ SiCA)
        r = Yz[rows] - c[rows] @ C.T                         # yₖ − C cₖ
        b[rows] = c[rows] + r @ K.T
        eta[rows] = r @ SiCA                                 # Aᵀ Cᵀ S⁻¹ (yₖ − C cₖ)
    # le premier élément porte l'a priori
    C, R = _masked(model, observed[0])
    m_pred = A @ x0 + c[0]
    P_pred = symmetrize(A @ P0 @ A.T + Q)
    S = C @ P_pred @ C.T + R
    K = scipy.linalg.solve(S, C @ P_pred, assume_a="pos").T
    F[0], eta[0], J[0] = 0.0, 0.0, 0.0
    b[0] = m_pred + K @ (Yz[0] - C @ m_pred)
    S_[0] = symmetrize(P_pred - K @ S @ K.T)
    return F, b, S_, eta, J


# --------------------------------------------------------------------------- filtre et lisseur


def _inputs(model: Any, y: Any, x0: Any, P0: Any, u: Any):
    model = check_instance("model", model, LinearGaussianModel, _HINT)
    Y = as_measurements("y", y, model.n_obs)
    x0_arr, P0_arr = as_gaussian(x0, P0, model.n_state, "x0", "P0")
    U = as_controls("u", u, Y.shape[0], model.n_control)
    BU = None if U is None else U @ model.B.T
    return model, Y, x0_arr, P0_arr, BU


def _result(model: LinearGaussianModel, Y: np.ndarray, x0: np.ndarray, P0: np.ndarray, BU: np.ndarray | None,
            x: np.ndarray, P: np.ndarray) -> FilterResult:
    r"""Le :class:`FilterResult` complet à partir des estimations filtrées : prédictions
    :math:`\hat x^-_k = A\hat x_{k-1} + Bu_k`, :math:`P^-_k = AP_{k-1}A^T + Q`, innovations, :math:`S_k`
    et gains de tous les pas à la fois (formules du filtre séquentiel, composantes observées seulement)."""
    A, C, Q, R = model.A, model.C, model.Q, model.R
    T, n, m = Y.shape[0], model.n_state, model.n_obs
    x_prev = np.concatenate([x0[None], x[:-1]])
    P_prev = np.concatenate([P0[None], P[:-1]])
    x_pred = x_prev @ A.T
    if BU is not None:
        x_pred = x_pred + BU
    P_pred = symmetrize(A @ P_prev @ A.T + Q)
    observed = ~np.isnan(Y)
    innovation = np.where(observed, Y - x_pred @ C.T, np.nan)
    S_all = np.full((T, m, m), np.nan)
    K_all = np.zeros((T, n, m))
    patterns, group = observation_patterns(observed)
    for g, pattern in enumerate(patterns):
        if not pattern.any():
            continue
        rows = np.flatnonzero(group == g)
        idx = np.flatnonzero(pattern)
        Co = C[idx]
        PCt = P_pred[rows] @ Co.T                            # (g, n, q)
        S = Co @ PCt + R[np.ix_(idx, idx)]                   # (g, q, q)
        K = _mT(np.linalg.solve(S, _mT(PCt)))                # S Kᵀ = C P⁻
        S_all[np.ix_(rows, idx, idx)] = S
        K_all[np.ix_(rows, np.arange(n), idx)] = K
    n_iter = observed.any(axis=1).astype(int)
    return FilterResult(x=x, P=P, x_pred=x_pred, P_pred=P_pred, K=K_all, innovation=innovation, S=S_all,
                        observed=observed, n_iter=n_iter)


def parallel_kalman_filter(model: LinearGaussianModel, y: Any, x0: Any, P0: Any, u: Any = None) -> FilterResult:
    r"""Le filtre de Kalman par balayage associatif (Särkkä et García-Fernández, 2021) : les :math:`T`
    éléments du filtre (voir l'en-tête), leurs produits préfixes en :math:`O(\log T)` passes vectorisées
    (:func:`associative_scan`), puis prédictions, innovations, :math:`S_k` et gains de tous les pas à la fois.

    Paramètres et résultat : ceux de :func:`~kalman_course.kalman_filter` — ``y`` (T, m) (``NaN`` :
    composante manquante), ``x0`` (n,), ``P0`` (n, n), ``u`` (T, p) optionnelle ; un
    :class:`~kalman_course.FilterResult` égal à celui du filtre séquentiel aux arrondis près (tests :
    :math:`10^{-8}` relatif, a priori loin de zéro compris), donc la même log-vraisemblance
    (:func:`~kalman_course.filter_log_likelihood`).
    """
    model, Y, x0_arr, P0_arr, BU = _inputs(model, y, x0, P0, u)
    elements = filtering_elements(model, Y, x0_arr, P0_arr, BU)
    _, x, P, _, _ = associative_scan(combine_filtering, elements)
    return _result(model, Y, x0_arr, P0_arr, BU, x, P)


def parallel_rts_smoother(model: LinearGaussianModel, y: Any, x0: Any, P0: Any, u: Any = None) -> SmootherResult:
    r"""Le lisseur de Rauch–Tung–Striebel par balayage associatif : :func:`parallel_kalman_filter`, puis les
    éléments :math:`(E_k, g_k, L_k)` du lisseur (voir l'en-tête) et leurs produits suffixes en
    :math:`O(\log T)` passes. L'état initial (l'a priori ``x0``, ``P0``) est un élément de plus : il est
    lissé aussi.

    Renvoie le même :class:`~kalman_course.SmootherResult` que
    ``rts_smoother(model, kalman_filter(model, y, x0, P0, u), x0, P0)`` aux arrondis près (``x``, ``P``,
    gains ``G``, covariances de décalage ``P_lag``, ``x_initial``, ``P_initial``, ``G_initial``).
    """
    model, Y, x0_arr, P0_arr, BU = _inputs(model, y, x0, P0, u)
    filt = _result(model, Y, x0_arr, P0_arr, BU,
                   *associative_scan(combine_filtering, filtering_elements(model, Y, x0_arr, P0_arr, BU))[1:3])
    A = model.A
    # la suite à lisser : l'a priori (instant 0) puis les T estimations filtrées
    x = np.concatenate([x0_arr[None], filt.x])
    P = np.concatenate([P0_arr[None], filt.P])
    E = np.zeros_like(P)
    E[:-1] = smoother_gains(P[:-1], filt.P_pred, A)          # E_k = P_k Aᵀ (P⁻_{k+1})⁻¹
    g = x - _mv(E[:, :, :], np.concatenate([filt.x_pred, np.zeros((1, x.shape[1]))]))
    L = symmetrize(P - E @ np.concatenate([filt.P_pred, np.zeros_like(P[:1])]) @ _mT(E))
    reverse = (E[::-1], g[::-1], L[::-1])
    _, xs, Ps = (a[::-1] for a in associative_scan(combine_smoothing, reverse))
    G = E[1:].copy()
    lag = np.full_like(Ps[1:], np.nan)
    lag[1:] = Ps[2:] @ _mT(G[:-1])                           # Cov(x_{k+1}, x_k | y) = P_{k+1|T} G_kᵀ
    lag[0] = Ps[1] @ E[0].T
    return SmootherResult(xs[1:], Ps[1:], G, lag, xs[0], Ps[0], E[0].copy(),
                          method="RTS parallèle (balayage associatif)")
