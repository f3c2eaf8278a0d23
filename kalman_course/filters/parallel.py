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

from ..core.linalg import symmetrize
from ..core.models import LinearGaussianModel
from ..core.results import FilterResult
from ..core.validation import KalmanInputError, as_controls, as_gaussian, as_measurements, check_instance
from .smoothers import SmootherResult, linear_smoother_inputs, smoother_gains

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

#: Nombre d'éléments combinés à la fois : des blocs qui tiennent dans le cache (quelques centaines de Ko
#: par tableau pour n = 4), au lieu de tableaux de tout un niveau qui en sortent.
CHUNK = 8192


# --------------------------------------------------------------------------- le balayage


def associative_scan(combine: Callable[[Elements, Elements], Elements], elements: Elements, axis: int = 0) -> Elements:
    r"""Tous les produits préfixes :math:`a_0 \otimes a_1 \otimes \cdots \otimes a_k` (:math:`k = 0 \dots T-1`)
    d'un opérateur associatif ``combine``, par le balayage de Blelloch.

    ``elements`` : tuple de tableaux dont l'axe ``axis`` (0 par défaut, ou -1) est celui des éléments ;
    ``combine(a, b)`` combine deux piles de même longueur, :math:`a_i \otimes b_i` élément par élément
    (``a`` avant ``b``). :math:`2\lceil\log_2 T\rceil` appels de ``combine`` (:func:`scan_passes`),
    environ :math:`2T` combinaisons en tout. Renvoie un tuple de tableaux de même forme."""
    if axis not in (0, -1):
        raise KalmanInputError(f"« axis » doit valoir 0 ou -1 (axe des éléments) ; reçu {axis!r}.")
    T = elements[0].shape[axis]

    def take(a, sl):
        return a[sl] if axis == 0 else a[..., sl]

    if T < 2:
        return tuple(np.array(e) for e in elements)
    pairs = combine(tuple(take(e, slice(0, -1, 2)) for e in elements), tuple(take(e, slice(1, None, 2)) for e in elements))
    odd = associative_scan(combine, pairs, axis)  # préfixes aux rangs impairs 1, 3, 5…
    out = []
    for e, o in zip(elements, odd):
        shape = (T,) + o.shape[1:] if axis == 0 else o.shape[:-1] + (T,)
        r = np.empty(shape, dtype=o.dtype)
        if axis == 0:
            r[0], r[1::2] = e[0], o
        else:
            r[..., 0], r[..., 1::2] = e[..., 0], o
        out.append(r)
    if T > 2:  # rangs pairs 2, 4… : le préfixe impair qui précède, combiné avec l'élément
        half = (T - 1) // 2
        even = combine(tuple(take(o, slice(0, half)) for o in odd), tuple(take(e, slice(2, None, 2)) for e in elements))
        for r, v in zip(out, even):
            if axis == 0:
                r[2::2] = v
            else:
                r[..., 2::2] = v
    return tuple(out)


def scan_passes(T: int) -> int:
    r"""Nombre d'appels de l'opérateur (passes vectorisées) de :func:`associative_scan` pour ``T`` éléments
    (:math:`2\lceil\log_2 T\rceil - 1` environ ; 0 pour un seul élément)."""
    if T < 2:
        return 0
    return 1 + scan_passes(T // 2) + (1 if (T - 1) // 2 > 0 else 0)


# --------------------------------------------------------------------------- petites matrices en colonnes
# Les piles de petites matrices sont rangées « en colonnes » (n, n, N) : le coefficient (i, j) de toutes les
# matrices est un vecteur contigu de N nombres, et un produit n × n est n³ opérations vectorielles sur des
# vecteurs de N nombres, au lieu de N petits produits matriciels (sur une pile (N, n, n), numpy et LAPACK
# paient un appel par matrice). Un opérande (p, q) sans axe des éléments est commun à tous.


#: En deçà de ce nombre d'éléments, un produit en colonnes est un seul appel à ``numpy.einsum`` (moins
#: d'appels Python) ; au-delà, n³ opérations vectorielles, plus rapides sur de longs vecteurs.
SMALL = 2048


def _mm(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Produit de piles en colonnes : (p, q[, N]) · (q, r[, N]) → (p, r, N)."""
    p, q, r = A.shape[0], A.shape[1], B.shape[1]
    N = A.shape[2] if A.ndim == 3 else B.shape[2]
    if N <= SMALL:
        return np.einsum("ij...,jk...->ik...", A, B)
    out = np.empty((p, r, N))
    for i in range(p):
        Ai = A[i]
        for k in range(r):
            o = out[i, k]
            np.multiply(Ai[0], B[0, k], out=o)
            for j in range(1, q):
                o += Ai[j] * B[j, k]
    return out


def _mv(A: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(p, q[, N]) · (q, N) → (p, N)."""
    p, q = A.shape[0], A.shape[1]
    if v.shape[-1] <= SMALL:
        return np.einsum("ijn,jn->in", A, v) if A.ndim == 3 else A.dot(v)
    out = np.empty((p, v.shape[-1]))
    for i in range(p):
        o = out[i]
        np.multiply(A[i, 0], v[0], out=o)
        for j in range(1, q):
            o += A[i, j] * v[j]
    return out


def _tr(A: np.ndarray) -> np.ndarray:
    """Transposée de chaque matrice d'une pile en colonnes (une vue)."""
    return np.swapaxes(A, 0, 1)


def _sym(A: np.ndarray) -> np.ndarray:
    """Partie symétrique de chaque matrice (en place, renvoie ``A``)."""
    n = A.shape[0]
    for i in range(n):
        for j in range(i + 1, n):
            v = 0.5 * (A[i, j] + A[j, i])
            A[i, j] = v
            A[j, i] = v
    return A


def _add_identity(A: np.ndarray) -> np.ndarray:
    for i in range(A.shape[0]):
        A[i, i] += 1.0
    return A


#: Seuil relatif des pivots de l'élimination sans échange de lignes : en deçà, la matrice est résolue
#: par LAPACK (``numpy.linalg.solve``, avec pivot partiel).
PIVOT_RTOL = 1e-6


def _solve(M: np.ndarray, R: np.ndarray) -> np.ndarray:
    r""":math:`M^{-1}R` pour des piles en colonnes ``M`` (n, n, N) et ``R`` (n, q, N), par élimination de Gauss
    vectorisée sans échange de lignes (:math:`M = I + \Sigma J` a ici ses pivots proches de 1) ; les matrices
    dont un pivot est petit devant sa ligne (:data:`PIVOT_RTOL`) sont résolues à part par LAPACK, avec pivot
    partiel. ``M`` et ``R`` sont modifiées."""
    n = M.shape[0]
    scale = np.abs(M).max(axis=1)  # (n, N) : plus grand coefficient de chaque ligne
    bad = np.zeros(M.shape[2], dtype=bool)
    for k in range(n):
        piv = M[k, k]
        bad |= ~(np.abs(piv) > PIVOT_RTOL * scale[k])
        inv = 1.0 / np.where(bad, 1.0, piv)
        for i in range(k + 1, n):
            f = M[i, k] * inv
            for j in range(k + 1, n):
                M[i, j] -= f * M[k, j]
            R[i] -= f * R[k]
        R[k] *= inv
        for j in range(k + 1, n):
            M[k, j] *= inv
    for i in range(n - 2, -1, -1):  # substitution arrière (diagonale ramenée à 1)
        for j in range(i + 1, n):
            R[i] -= M[i, j] * R[j]
    if bad.any():
        raise _Pivot(np.flatnonzero(bad))
    return R


class _Pivot(Exception):
    """Des matrices à résoudre avec pivot partiel (indices ``rows``)."""

    def __init__(self, rows: np.ndarray) -> None:
        super().__init__()
        self.rows = rows


def _solve_safe(M: np.ndarray, R: np.ndarray) -> np.ndarray:
    """:func:`_solve`, et LAPACK pour les matrices dont un pivot est trop petit (et pour une petite pile, où
    un appel LAPACK par matrice coûte moins que n³ opérations vectorielles)."""
    if M.shape[-1] <= SMALL // 8:
        return _columns(np.linalg.solve(_rows(M), _rows(R)))
    M0, R0 = M.copy(), R.copy()
    try:
        return _solve(M, R)
    except _Pivot as exc:
        rows = exc.rows
        out = R  # les autres matrices sont résolues
        sol = np.linalg.solve(np.moveaxis(M0[..., rows], -1, 0), np.moveaxis(R0[..., rows], -1, 0))
        out[..., rows] = np.moveaxis(sol, 0, -1)
        return out


def _cho_solve(S: np.ndarray, R: np.ndarray) -> np.ndarray:
    r""":math:`S^{-1}R` pour une pile en colonnes ``S`` (m, m, N) symétrique définie positive, par Cholesky
    vectorisée (``S`` et ``R`` sont modifiées). Une matrice qui n'est pas définie positive : une
    :class:`KalmanInputError` (comme la correction du filtre séquentiel)."""
    m = S.shape[0]
    L = S
    for k in range(m):  # Cholesky en place : L triangulaire inférieure
        for j in range(k):
            L[k, k] -= L[k, j] * L[k, j]
        if not (L[k, k] > 0).all():
            from ..core.linalg import S_NOT_PD

            raise KalmanInputError(S_NOT_PD)
        L[k, k] = np.sqrt(L[k, k])
        for i in range(k + 1, m):
            for j in range(k):
                L[i, k] -= L[i, j] * L[k, j]
            L[i, k] /= L[k, k]
    for i in range(m):  # L z = R
        for j in range(i):
            R[i] -= L[i, j] * R[j]
        R[i] /= L[i, i]
    for i in range(m - 1, -1, -1):  # Lᵀ x = z
        for j in range(i + 1, m):
            R[i] -= L[j, i] * R[j]
        R[i] /= L[i, i]
    return R


def _columns(a: np.ndarray) -> np.ndarray:
    """Pile (N, …) → en colonnes (…, N), contiguë."""
    return np.ascontiguousarray(np.moveaxis(a, 0, -1))


def _rows(a: np.ndarray) -> np.ndarray:
    """En colonnes (…, N) → pile (N, …), contiguë."""
    return np.ascontiguousarray(np.moveaxis(a, -1, 0))


def _chunked(combine: Callable[[Elements, Elements], Elements]) -> Callable[[Elements, Elements], Elements]:
    """L'opérateur appliqué par blocs de :data:`CHUNK` éléments (axe des éléments en dernier), les résultats
    écrits dans des tableaux préalloués : les temporaires restent dans le cache."""

    def chunked(first: Elements, second: Elements) -> Elements:
        N = first[0].shape[-1]
        if N <= CHUNK:
            return combine(first, second)
        out = None
        for s in range(0, N, CHUNK):
            sl = slice(s, min(s + CHUNK, N))
            part = combine(tuple(a[..., sl] for a in first), tuple(a[..., sl] for a in second))
            if out is None:
                out = tuple(np.empty(p.shape[:-1] + (N,)) for p in part)
            for o, p in zip(out, part):
                o[..., sl] = p
        return out

    return chunked


# --------------------------------------------------------------------------- opérateurs


def combine_filtering(first: Elements, second: Elements) -> Elements:
    r"""L'opérateur associatif du filtre, :math:`a_i \otimes a_j` (voir l'en-tête) ; ``first`` et ``second``
    sont des piles **en colonnes** ``(F (n, n, N), b (n, N), Σ (n, n, N), η (n, N), J (n, n, N))`` (axe des
    éléments en dernier).

    Si ``first`` est une pile de **préfixes** (:math:`F_i = 0`, donc :math:`\eta_i = 0`, :math:`J_i = 0` :
    une loi filtrée), le produit en est un aussi : seuls :math:`b` et :math:`\Sigma` sont calculés (c'est
    le cas de la moitié des combinaisons du balayage, qui complètent un préfixe par un élément)."""
    Fi, bi, Si, ei, Ji = first
    Fj, bj, Sj, ej, Jj = second
    n, N = bi.shape
    M = _add_identity(_mm(Si, Jj))                        # I + Σᵢ Jⱼ
    prefix = not Fi.any()
    rhs = np.empty((n, (0 if prefix else n) + 1 + n, N))
    col = 0
    if not prefix:
        rhs[:, :n] = Fi
        col = n
    rhs[:, col] = bi + _mv(Si, ej)
    rhs[:, col + 1:] = Si
    W = _solve_safe(M, rhs)                              # (I + Σᵢ Jⱼ)⁻¹ [Fᵢ | bᵢ + Σᵢηⱼ | Σᵢ]
    Wb, WS = W[:, col], W[:, col + 1:]
    b = _mv(Fj, Wb) + bj
    S = _mm(_mm(Fj, WS), _tr(Fj))
    S += Sj
    _sym(S)
    if prefix:
        zero_n, zero_nn = np.zeros((n, 1)), np.zeros((n, n, 1))
        return (np.broadcast_to(zero_nn, (n, n, N)), b, S, np.broadcast_to(zero_n, (n, N)),
                np.broadcast_to(zero_nn, (n, n, N)))
    WF = W[:, :n]
    WFt = _tr(WF)
    eta = _mv(WFt, ej - _mv(Jj, bi))
    eta += ei
    J = _mm(_mm(WFt, Jj), Fi)
    J += Ji
    return _mm(Fj, WF), b, S, eta, _sym(J)


def combine_smoothing(later: Elements, earlier: Elements) -> Elements:
    r"""L'opérateur associatif du lisseur, dans l'ordre du balayage arrière : ``later`` (les pas
    :math:`k+1 \dots T`, déjà combinés) puis ``earlier`` (le pas :math:`k`) ; piles en colonnes
    ``(E (n, n, N), g (n, N), L (n, n, N))``. Renvoie :math:`(E_kE_{k+1}, E_kg_{k+1} + g_k,
    E_kL_{k+1}E_k^T + L_k)`."""
    Ep, gp, Lp = later
    Eq, gq, Lq = earlier
    n, N = gp.shape
    E = np.broadcast_to(np.zeros((n, n, 1)), Ep.shape) if not Ep.any() else _mm(Eq, Ep)  # suffixe : E = 0
    g = _mv(Eq, gp)
    g += gq
    L = _mm(_mm(Eq, Lp), _tr(Eq))
    L += Lq
    return E, g, _sym(L)


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


def _step_matrices(model: LinearGaussianModel, observed: np.ndarray):
    r"""Les matrices de chaque pas, par groupes de pas qui les partagent : ``group`` (T,) et, pour chaque
    groupe, :math:`A, Q` et :math:`C, R` où les composantes non observées ne comptent plus (lignes de
    :math:`C` nulles, variance 1 sans corrélation dans :math:`R`) — piles (G, …). Un modèle constant a un
    groupe par motif de composantes observées ; un modèle variable dans le temps, un groupe par pas."""
    T = observed.shape[0]
    if model.time_varying:
        group = np.arange(T)
        pattern = observed
        A, Q, C, R = (np.asarray(model.sequence(name, T)) for name in ("A", "Q", "C", "R"))
    else:
        pattern, group = observation_patterns(observed)
        G = len(pattern)
        A, Q, C, R = (np.broadcast_to(getattr(model, name), (G,) + getattr(model, name).shape)
                      for name in ("A", "Q", "C", "R"))
    keep = pattern[:, :, None] & pattern[:, None, :]
    eye = np.eye(pattern.shape[1], dtype=bool)
    C = C * pattern[:, :, None]
    R = np.where(keep, R, 0.0) + np.where(eye & ~pattern[:, :, None], 1.0, 0.0)
    return group, A, Q, C, R


def filtering_elements(model: LinearGaussianModel, Y: np.ndarray, x0: np.ndarray, P0: np.ndarray,
                       BU: np.ndarray | None) -> Elements:
    r"""Les :math:`T` éléments :math:`(F_k, b_k, \Sigma_k, \eta_k, J_k)` du filtre (voir l'en-tête), rangés
    **en colonnes** (axe des éléments en dernier : ``F`` (n, n, T), ``b`` (n, T)…) : ``Y`` (T, m)
    (``NaN`` : composante manquante), ``x0`` (n,), ``P0`` (n, n), ``BU`` (T, n) les termes :math:`B_ku_k` ou
    ``None``. Les matrices sont calculées une fois par groupe de pas qui les partagent (un seul groupe pour
    un modèle constant sans mesure manquante ; un par pas pour un modèle variable dans le temps)."""
    T, n = Y.shape[0], model.n_state
    observed = ~np.isnan(Y)
    Yz = np.where(observed, Y, 0.0)
    group, A, Q, C, R = _step_matrices(model, observed)
    S = C @ Q @ np.swapaxes(C, 1, 2) + R
    SiC = np.linalg.solve(S, C)                                # S⁻¹C (G, m, n)
    K = np.swapaxes(SiC @ Q, 1, 2)                             # Q Cᵀ S⁻¹
    IKC = np.eye(n) - K @ C
    SiCA = SiC @ A
    Fg = IKC @ A
    Sg = symmetrize(IKC @ Q)
    Jg = symmetrize(np.swapaxes(C @ A, 1, 2) @ SiCA)           # Aᵀ Cᵀ S⁻¹ C A
    single = len(A) == 1
    F = np.repeat(_columns(Fg), T, axis=-1) if single else _columns(Fg)[..., group]
    Sigma = np.repeat(_columns(Sg), T, axis=-1) if single else _columns(Sg)[..., group]
    J = np.repeat(_columns(Jg), T, axis=-1) if single else _columns(Jg)[..., group]
    # rₖ = yₖ − Cₖcₖ ; bₖ = cₖ + Kₖrₖ ; ηₖ = Aₖᵀ Cₖᵀ S⁻¹ rₖ
    if single:
        r = Yz if BU is None else Yz - BU @ C[0].T
        b = r @ K[0].T
        eta = r @ SiCA[0]
    else:
        Cr = C[group]
        r = Yz if BU is None else Yz - (Cr @ BU[:, :, None])[:, :, 0]
        b = (K[group] @ r[:, :, None])[:, :, 0]
        eta = (np.swapaxes(SiCA[group], 1, 2) @ r[:, :, None])[:, :, 0]
    if BU is not None:
        b += BU
    # le premier élément porte l'a priori : la correction de Kalman de (A₀x̂₀ + c₀, A₀P₀A₀ᵀ + Q₀) par y₀
    A0, Q0, C0, R0 = A[group[0]], Q[group[0]], C[group[0]], R[group[0]]
    m_pred = A0 @ x0 + (0.0 if BU is None else BU[0])
    P_pred = symmetrize(A0 @ P0 @ A0.T + Q0)
    S0 = C0 @ P_pred @ C0.T + R0
    K0 = np.linalg.solve(S0, C0 @ P_pred).T
    b[0] = m_pred + K0 @ (Yz[0] - C0 @ m_pred)
    b, eta = _columns(b), _columns(eta)
    F[..., 0], eta[..., 0], J[..., 0] = 0.0, 0.0, 0.0
    Sigma[..., 0] = symmetrize(P_pred - K0 @ S0 @ K0.T)
    return F, b, Sigma, eta, J


# --------------------------------------------------------------------------- filtre et lisseur


def _inputs(model: Any, y: Any, x0: Any, P0: Any, u: Any):
    model = check_instance("model", model, LinearGaussianModel, _HINT)
    Y = as_measurements("y", y, model.n_obs)
    if model.time_varying:
        model.steps(Y.shape[0])  # vérifie que le modèle a autant de pas que de mesures
    x0_arr, P0_arr = as_gaussian(x0, P0, model.n_state, "x0", "P0")
    U = as_controls("u", u, Y.shape[0], model.n_control)
    if U is None:
        BU = None
    elif model.B.ndim == 3:
        BU = (model.B @ U[:, :, None])[:, :, 0]
    else:
        BU = U @ model.B.T
    return model, Y, x0_arr, P0_arr, BU


def _result(model: LinearGaussianModel, Y: np.ndarray, x0: np.ndarray, P0: np.ndarray, BU: np.ndarray | None,
            x: np.ndarray, P: np.ndarray) -> FilterResult:
    r"""Le :class:`FilterResult` complet à partir des estimations filtrées en colonnes ``x`` (n, T), ``P``
    (n, n, T) : prédictions :math:`\hat x^-_k = A_k\hat x_{k-1} + B_ku_k`, :math:`P^-_k = A_kP_{k-1}A_k^T + Q_k`,
    innovations, :math:`S_k` et gains de tous les pas à la fois (formules du filtre séquentiel, composantes
    observées seulement)."""
    T, n, m = Y.shape[0], model.n_state, model.n_obs
    tv = model.time_varying
    A = _columns(model.A) if tv and model.A.ndim == 3 else model.A
    Q = _columns(model.Q) if tv and model.Q.ndim == 3 else model.Q
    x_prev = np.concatenate([x0[:, None], x[:, :-1]], axis=1)
    P_prev = np.concatenate([P0[:, :, None], P[:, :, :-1]], axis=2)
    x_pred = _mv(A, x_prev)
    if BU is not None:
        x_pred += BU.T
    P_pred = _mm(_mm(A, P_prev), _tr(A))
    P_pred += Q if Q.ndim == 3 else Q[:, :, None]
    _sym(P_pred)
    observed = ~np.isnan(Y)
    S_all = np.full((T, m, m), np.nan)
    K_all = np.zeros((T, n, m))
    innovation = np.full((T, m), np.nan)
    C_all = np.asarray(model.sequence("C", T)) if tv else None
    R_all = np.asarray(model.sequence("R", T)) if tv else None
    patterns, group = observation_patterns(observed)
    for g, pattern in enumerate(patterns):
        if not pattern.any():
            continue
        rows = np.flatnonzero(group == g) if len(patterns) > 1 else slice(None)
        idx = np.flatnonzero(pattern)
        if tv:
            Co = _columns(C_all[rows][:, idx])                 # (q, n, g)
            Ro = _columns(R_all[rows][:, idx[:, None], idx])
        else:
            Co, Ro = model.C[idx], model.R[np.ix_(idx, idx)][:, :, None]
        Pp, xp = P_pred[..., rows], x_pred[:, rows]
        PCt = _mm(Pp, _tr(Co))                                 # (n, q, g)
        S = _mm(Co, PCt)
        S += Ro
        _sym(S)
        nu = Y[rows][:, idx].T - _mv(Co, xp)                   # (q, g)
        Kt = _cho_solve(S.copy(), _tr(PCt).copy())             # S Kᵀ = C P⁻
        sel = np.arange(T)[rows]
        S_all[np.ix_(sel, idx, idx)] = _rows(S)
        K_all[np.ix_(sel, np.arange(n), idx)] = _rows(_tr(Kt))
        innovation[np.ix_(sel, idx)] = nu.T
    n_iter = observed.any(axis=1).astype(int)
    return FilterResult(x=_rows(x), P=_rows(P), x_pred=_rows(x_pred), P_pred=_rows(P_pred), K=K_all,
                        innovation=innovation, S=S_all, observed=observed, n_iter=n_iter)


_COMBINE_FILTERING = _chunked(combine_filtering)
_COMBINE_SMOOTHING = _chunked(combine_smoothing)


def parallel_kalman_filter(model: LinearGaussianModel, y: Any, x0: Any, P0: Any, u: Any = None) -> FilterResult:
    r"""Le filtre de Kalman par balayage associatif (Särkkä et García-Fernández, 2021) : les :math:`T`
    éléments du filtre (voir l'en-tête), leurs produits préfixes en :math:`O(\log T)` passes vectorisées
    (:func:`associative_scan`), puis prédictions, innovations, :math:`S_k` et gains de tous les pas à la fois.

    Paramètres et résultat : ceux de :func:`~kalman_course.kalman_filter` — ``model`` constant ou variable
    dans le temps (matrices (T, …) : les éléments du pas ``k`` sont faits de :math:`A_k, B_k, C_k, Q_k,
    R_k`), ``y`` (T, m) (``NaN`` : composante manquante), ``x0`` (n,), ``P0`` (n, n), ``u`` (T, p)
    optionnelle ; un :class:`~kalman_course.FilterResult` égal à celui du filtre séquentiel aux arrondis
    près (tests : :math:`10^{-8}` relatif, a priori loin de zéro, modèle variable et lignes manquantes
    compris), donc la même log-vraisemblance (:func:`~kalman_course.filter_log_likelihood`).
    """
    model, Y, x0_arr, P0_arr, BU = _inputs(model, y, x0, P0, u)
    elements = filtering_elements(model, Y, x0_arr, P0_arr, BU)
    _, x, P, _, _ = associative_scan(_COMBINE_FILTERING, elements, axis=-1)
    return _result(model, Y, x0_arr, P0_arr, BU, x, P)


def parallel_rts_smoother(model: LinearGaussianModel, result: FilterResult, x0: Any = None, P0: Any = None,
                          u: Any = None) -> SmootherResult:
    r"""Le lisseur de Rauch–Tung–Striebel par balayage associatif, sur un résultat de filtre — la forme de
    tous les lisseurs du paquet (``lisseur(model, result, x0, P0, u)``, voir
    :func:`~kalman_course.rts_smoother`) : ``parallel_rts_smoother(model, parallel_kalman_filter(model, y,
    x0, P0), x0, P0)``.

    Éléments :math:`(E_k, g_k, L_k)` (voir l'en-tête) faits des estimations filtrées et prédites du
    résultat, puis leurs produits suffixes en :math:`O(\log T)` passes. Avec l'a priori ``x0``, ``P0`` du
    filtre, l'état initial est un élément de plus : il est lissé aussi.

    Paramètres : ``model`` (LinearGaussianModel, constant ou variable dans le temps), ``result`` (sortie
    de :func:`parallel_kalman_filter` ou de :func:`~kalman_course.kalman_filter` pour ce modèle, vérifiée
    comme par :func:`~kalman_course.rts_smoother`), ``x0`` (n,), ``P0`` (n, n) optionnels, ``u`` (T, p) les
    commandes du filtre (pour la vérification des prédictions).

    Renvoie le même :class:`~kalman_course.SmootherResult` que :func:`~kalman_course.rts_smoother` aux
    arrondis près (``x``, ``P``, gains ``G``, covariances de décalage ``P_lag`` et, avec l'a priori,
    ``x_initial``, ``P_initial``, ``G_initial``).
    """
    inputs = linear_smoother_inputs(model, result, x0, P0, u, "parallel_rts_smoother", "parallel_kalman_filter",
                                    diffuse=False)
    A, prior = inputs.A, inputs.prior
    x, P = np.asarray(result.x), np.asarray(result.P)
    T, n = x.shape
    xp, Pp = np.asarray(result.x_pred), np.asarray(result.P_pred)
    # la suite à lisser : (l'a priori à l'instant 0), puis les T estimations filtrées
    if prior is not None:
        x = np.concatenate([prior[0][None], x])
        P = np.concatenate([prior[1][None], P])
        A_next = A                                             # la ligne k est prédite par A_k depuis la ligne k−1
    else:
        A_next = A[1:]
        xp, Pp = xp[1:], Pp[1:]
    E = np.zeros_like(P)
    if len(P) > 1:
        E[:-1] = smoother_gains(P[:-1], Pp, A_next)           # E_k = P_k A_{k+1}ᵀ (P⁻_{k+1})⁻¹
    xp_next = np.concatenate([xp, np.zeros((1, n))])
    Pp_next = np.concatenate([Pp, np.zeros((1, n, n))])
    g = x - (E @ xp_next[:, :, None])[:, :, 0]
    L = symmetrize(P - E @ Pp_next @ np.swapaxes(E, 1, 2))
    reverse = tuple(_columns(a[::-1]) for a in (E, g, L))
    _, xs, Ps = (_rows(a)[::-1] for a in associative_scan(_COMBINE_SMOOTHING, reverse, axis=-1))
    xs, Ps = np.ascontiguousarray(xs), np.ascontiguousarray(Ps)
    lag = np.full((len(xs), n, n), np.nan)
    lag[1:] = Ps[1:] @ np.swapaxes(E[:-1], 1, 2)              # Cov(x_{k+1}, x_k | y) = P_{k+1|T} E_kᵀ
    if prior is None:
        return SmootherResult(xs, Ps, E, lag, method="RTS parallèle (balayage associatif)")
    return SmootherResult(xs[1:], Ps[1:], E[1:], lag[1:], xs[0], Ps[0], E[0].copy(),
                          method="RTS parallèle (balayage associatif)")
