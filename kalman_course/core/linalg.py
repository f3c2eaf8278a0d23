r"""Algèbre linéaire commune à tous les filtres : symétrisation, résolution définie positive, gain,
corrections (forme du cours, de Joseph, en racine carrée), facteurs nommés.

:math:`S` n'est jamais inversée : le gain :math:`K = P^-H^TS^{-1}` vient de la résolution de
:math:`S K^T = H P^-` par Cholesky — une seule fonction pour tout le paquet, :func:`psd_solve` (LAPACK
``?posv`` pour une matrice, Cholesky en pile pour ``N`` tirages). Une factorisation qui échoue devient une
:class:`~kalman_course.core.validation.KalmanInputError` qui dit quelle matrice et quoi vérifier, jamais
une ``LinAlgError`` nue.

**Racines carrées.** Une covariance :math:`P` peut être portée par une racine triangulaire supérieure
:math:`U` (:math:`U^TU = P`, :func:`covariance_root`). Une somme de covariances
:math:`M_1^TM_1 + M_2^TM_2` a pour racine le facteur :math:`R` de la QR de :math:`[M_1; M_2]`
(:func:`triangular_root`) : aucune soustraction, donc aucun chiffre perdu (Morf & Kailath 1975 ;
Bierman 1977). C'est la correction par défaut du filtre de Kalman (:func:`correct_square_root`).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import scipy.linalg

from .validation import KalmanInputError

__all__ = [
    "symmetrize", "psd_solve", "is_positive_definite", "kalman_gain", "correct", "correct_many", "cholesky_factor",
    "covariance_factor", "covariance_root", "gram", "triangular_root", "square_root_blocks", "correct_square_root",
    "centred_rows", "weighted_rows",
]

_posv, _geqrf = scipy.linalg.get_lapack_funcs(("posv", "geqrf"), dtype=np.float64)
_trsm = scipy.linalg.get_blas_funcs("trsm", dtype=np.float64)

#: Message par défaut quand :math:`S` n'est pas définie positive.
S_NOT_PD = (
    "La covariance d'innovation « S = C P⁻ Cᵀ + R » n'est pas définie positive (singulière "
    "numériquement) : vérifiez les ordres de grandeur de P0, Q et R."
)


def symmetrize(P: np.ndarray) -> np.ndarray:
    """Partie symétrique :math:`(P + P^T)/2` (efface l'asymétrie due aux arrondis) ; ``P`` (…, n, n).

    Renvoie toujours un nouveau tableau. Une matrice 1 × 1 est symétrique : c'en est une simple copie
    (mêmes valeurs que :math:`(p + p)/2`, calculée sans les deux opérations : les filtres scalaires, comme
    le niveau local du Nil, l'appellent à chaque pas)."""
    if P.shape[-1] == 1:
        return P.copy()
    P = P + P.swapaxes(-1, -2)
    P *= 0.5
    return P


def psd_solve(S: np.ndarray, B: np.ndarray, *, message: str = S_NOT_PD, where: str = "", name: str = "S") -> np.ndarray:
    r"""Résout :math:`SX = B` pour :math:`S` symétrique définie positive, par Cholesky, sans jamais
    former :math:`S^{-1}` : la résolution définie positive de tout le paquet (comme ``psd_solve`` de
    dynamax).

    ``S`` (m, m) et ``B`` (m,) ou (m, q) : LAPACK ``posv`` ; ``S`` (N, m, m) et ``B`` (N, m, q) : une pile,
    matrice par matrice (``numpy.linalg.cholesky``). Renvoie ``X`` de la forme de ``B``.

    Si :math:`S` (ou l'une des :math:`S_i`) n'est pas définie positive : :class:`KalmanInputError` avec
    ``message``, précisé de ``where`` (« au pas 12 »…) et, pour une pile, de ``name`` et du premier
    tirage fautif."""
    if S.ndim == 2:
        _, X, info = _posv(S, B)
        if info != 0:
            raise KalmanInputError(message if not where else f"{message[:-1]} ({where}).")
        return X
    try:
        L = np.linalg.cholesky(S)
    except np.linalg.LinAlgError:
        bad = next(i for i in range(S.shape[0]) if not is_positive_definite(S[i]))
        place = ", ".join([name, f"tirage {bad}"] + ([where] if where else []))
        raise KalmanInputError(f"{message[:-1]} ({place}).") from None
    return np.linalg.solve(np.swapaxes(L, -1, -2), np.linalg.solve(L, B))


def is_positive_definite(M: np.ndarray) -> bool:
    """``M`` (n, n) est-elle définie positive (sa factorisation de Cholesky réussit-elle) ?"""
    try:
        np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        return False
    return True


def kalman_gain(P_pred: np.ndarray, H: np.ndarray, R: np.ndarray, where: str = ""):
    r"""Gain :math:`K = P^-H^TS^{-1}` avec :math:`S = HP^-H^T + R`, par résolution de Cholesky.

    ``P_pred`` (n, n), ``H`` (m, n), ``R`` (m, m). Renvoie ``(K (n, m), S (m, m), P^-H^T (n, m))``.
    ``where`` précise le pas dans le message d'erreur (« au pas 12 »…).
    """
    PHt = P_pred.dot(H.T)
    S = H.dot(PHt) + R
    Kt = psd_solve(S, PHt.T, where=where)  # S Kᵀ = H P⁻
    return Kt.T, S, PHt


def correct(x_pred: np.ndarray, P_pred: np.ndarray, nu: np.ndarray, H: np.ndarray, R: np.ndarray,
            joseph: bool = False):
    r"""Correction linéaire commune à tous les filtres gaussiens (KF, EKF, EKF itéré, SE(3)).

    .. math::

        K = P^-H^T(HP^-H^T + R)^{-1},\qquad x = x^- + K\nu,\qquad
        P = (I - KH)P^-\ \ \text{ou (Joseph)}\ \ (I-KH)P^-(I-KH)^T + KRK^T.

    ``x_pred`` (n,), ``P_pred`` (n, n), ``nu`` (m,), ``H`` (m, n), ``R`` (m, m).
    Renvoie ``(x (n,), P (n, n), K (n, m), S (m, m))``.
    """
    K, S, PHt = kalman_gain(P_pred, H, R)
    x = x_pred + K.dot(nu)
    if joseph:
        IKH = np.eye(P_pred.shape[0]) - K.dot(H)
        P = IKH.dot(P_pred).dot(IKH.T) + K.dot(R).dot(K.T)
    else:
        P = P_pred - K.dot(PHt.T)
    return x, symmetrize(P), K, S


def correct_many(X_pred: np.ndarray, P_pred: np.ndarray, nu: np.ndarray, H: np.ndarray, R: np.ndarray,
                 joseph: bool = False, where: str = ""):
    r"""La correction linéaire de :func:`correct` sur ``N`` tirages à la fois (mêmes formules, tirage par
    tirage) :

    .. math::

        S_i = H_iP^-_iH_i^T + R_i,\quad K_i = P^-_iH_i^TS_i^{-1},\quad x_i = x^-_i + K_i\nu_i,\quad
        P_i = (I - K_iH_i)P^-_i\ \ \text{ou (Joseph)}\ \ (I-K_iH_i)P^-_i(I-K_iH_i)^T + K_iR_iK_i^T.

    ``X_pred`` (N, n), ``P_pred`` (N, n, n), ``nu`` (N, m) ; ``H`` (m, n) commune ou (N, m, n) ;
    ``R`` (m, m) commune ou (N, m, m). :math:`K_i` vient de la résolution de :math:`S_iK_i^T = H_iP^-_i`
    par Cholesky (jamais d'inverse). Renvoie ``(X (N, n), P (N, n, n), K (N, n, m), S (N, m, m))``.
    """
    Ht = np.swapaxes(H, -1, -2)
    PHt = P_pred @ Ht                                   # (N, n, m)
    S = H @ PHt + R                                     # (N, m, m)
    K = np.swapaxes(psd_solve(S, np.swapaxes(PHt, -1, -2), where=where), -1, -2)
    X = X_pred + (K @ nu[..., None])[..., 0]
    if joseph:
        IKH = np.eye(P_pred.shape[-1]) - K @ H
        P = IKH @ P_pred @ np.swapaxes(IKH, -1, -2) + K @ R @ np.swapaxes(K, -1, -2)
    else:
        P = P_pred - K @ np.swapaxes(PHt, -1, -2)
    return X, symmetrize(P), K, S


def cholesky_factor(M: np.ndarray, name: str, what: str = "définie positive", lower: bool = True) -> np.ndarray:
    """Facteur de Cholesky de ``M`` ; en cas d'échec, une :class:`KalmanInputError` qui nomme ``name``."""
    try:
        return scipy.linalg.cholesky(M, lower=lower, check_finite=False)
    except np.linalg.LinAlgError:
        raise KalmanInputError(f"« {name} » doit être {what}.") from None


def covariance_factor(M: np.ndarray) -> np.ndarray:
    r"""Facteur :math:`L` tel que :math:`LL^T = M` pour une covariance semi-définie positive (par ``eigh``,
    donc valable aussi pour une covariance singulière, par exemple :math:`Q = 0`)."""
    lam, V = scipy.linalg.eigh(M)
    return V * np.sqrt(np.clip(lam, 0.0, None))


#: Seuil relatif sur la diagonale de la racine :math:`U_S` de :math:`S` : en deçà, :math:`S` est tenue pour
#: singulière (conditionnement :math:`\gtrsim 10^{24}`, la QR en double précision n'en garde plus les petites
#: valeurs propres).
SINGULAR_ROOT_RTOL = 1e-12


@lru_cache(maxsize=64)
def _upper_mask(shape: tuple[int, int]) -> np.ndarray:
    """Masque ``shape`` des éléments sur et au-dessus de la diagonale, rangé en ordre Fortran comme la sortie
    de LAPACK : ``qr *= _upper_mask(qr.shape)`` parcourt alors deux tableaux contigus (sur une vue, numpy
    paierait deux à trois fois plus cher)."""
    mask = np.asfortranarray(np.triu(np.ones(shape)))
    mask.setflags(write=False)
    return mask


def gram(M: np.ndarray) -> np.ndarray:
    r""":math:`M^TM` (…, n, n) d'une racine ``M`` (…, r, n) : la covariance qu'elle porte, exactement
    symétrique (un seul produit, en lot pour une pile de racines ; des lignes nulles n'y changent rien)."""
    return M.T.dot(M) if M.ndim == 2 else np.matmul(np.swapaxes(M, -1, -2), M)


def triangular_root(M: np.ndarray) -> np.ndarray:
    r"""Racine triangulaire supérieure :math:`U` (n, n) de :math:`M^TM` : le facteur :math:`R` de la QR
    de Householder de ``M`` (r, n) (LAPACK ``geqrf``), :math:`U^TU = M^TM`.

    Empiler des racines puis triangulariser, c'est additionner des covariances sans soustraction :
    :math:`[U_1; U_2]` donne la racine de :math:`U_1^TU_1 + U_2^TU_2`. ``M`` (N, r, n) : une pile
    (``numpy.linalg.qr``), renvoie (N, n, n). La diagonale de :math:`U` peut être négative (une racine
    reste une racine)."""
    r, n = M.shape[-2:]
    if M.ndim > 2:
        if r < n:
            M = np.concatenate([M, np.zeros(M.shape[:-2] + (n - r, n))], axis=-2)
        return np.linalg.qr(M, mode="r")
    if r < n:
        M = np.vstack([M, np.zeros((n - r, n))])
    qr = _geqrf(M)[0]  # R au-dessus de la diagonale, réflecteurs de Householder au-dessous…
    qr *= _upper_mask(qr.shape)  # … effacés
    return qr[:n]


def covariance_root(P: np.ndarray) -> np.ndarray:
    r"""Racine triangulaire supérieure :math:`U` (n, n) d'une covariance :math:`P` semi-définie positive,
    :math:`U^TU = P` : Cholesky si :math:`P` est définie positive, sinon par ``eigh``
    (:func:`covariance_factor`) puis :func:`triangular_root` (une covariance singulière, :math:`Q = 0`
    par exemple, a aussi une racine). ``P`` (N, n, n) : une racine par matrice."""
    try:
        return np.swapaxes(np.linalg.cholesky(P), -1, -2)
    except np.linalg.LinAlgError:
        if P.ndim > 2:
            return np.array([covariance_root(Pi) for Pi in P])
        return triangular_root(covariance_factor(P).T)


def square_root_blocks(H: np.ndarray, U_R: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r"""Les deux blocs constants du pré-tableau de :func:`correct_square_root`, qui ne dépendent que de
    :math:`H` (m, n) et :math:`U_R` (m, m) :

    .. math::

        \begin{bmatrix} U_R & 0 \end{bmatrix}\ (m \times (m + n)),\qquad
        \begin{bmatrix} H^T & I_n \end{bmatrix}\ (n \times (m + n)),

    le second donnant toutes les autres lignes en un seul produit : :math:`[MH^T\ \ M] = M\,[H^T\ \ I_n]`
    (multiplier par :math:`I_n` est exact). Un modèle constant les calcule une fois
    (:attr:`~kalman_course.LinearGaussianModel.square_root_blocks`)."""
    m, n = H.shape
    top = np.zeros((m, m + n))
    top[:, :m] = U_R
    HtI = np.empty((n, m + n))
    HtI[:, :m] = H.T
    HtI[:, m:] = np.eye(n)
    return top, HtI


def correct_square_root(x_pred: np.ndarray, M_pred: np.ndarray, nu: np.ndarray, H: np.ndarray,
                        U_R: np.ndarray, where: str = "", blocks: tuple[np.ndarray, np.ndarray] | None = None):
    r"""Correction linéaire en racine carrée : la forme « tableau » de Morf et Kailath (1975).

    Avec une racine :math:`M` de :math:`P^-` (:math:`M^TM = P^-`, ``r`` ≥ n lignes : triangulaire, ou
    les racines empilées de la prédiction, :math:`[U A^T; U_Q]`) et :math:`U_R^TU_R = R`, une seule QR
    (:func:`triangular_root`) du pré-tableau donne tout :

    .. math::

        \begin{bmatrix} U_R & 0 \\ MH^T & M \end{bmatrix}
        \;\xrightarrow{\ \mathrm{QR}\ }\;
        \begin{bmatrix} U_S & \bar K^T \\ 0 & U^+ \end{bmatrix},\qquad
        U_S^TU_S = S = HP^-H^T + R,\quad (U^+)^TU^+ = P^- - P^-H^TS^{-1}HP^-,

    et :math:`\bar K^T = U_S^{-T}HP^-`, d'où :math:`K^T = U_S^{-1}\bar K^T` (:math:`U_S` triangulaire,
    :math:`m \times m`, une résolution triangulaire) et :math:`x = x^- + K\nu`. La covariance a
    posteriori n'est jamais calculée par la soustraction :math:`P^- - KHP^-` : elle reste semi-définie
    positive et garde ses petites valeurs propres même quand :math:`P^-` est énorme (a priori vague,
    :math:`P_0 = 10^{14}I`). Si un élément diagonal de :math:`U_S` ne dépasse pas
    :data:`SINGULAR_ROOT_RTOL` fois le plus grand, :math:`S` est singulière à la précision de la double
    (la QR n'en garde plus la petite racine) : :class:`KalmanInputError`, comme la forme du cours.

    ``x_pred`` (n,), ``M_pred`` (r, n), ``nu`` (m,), ``H`` (m, n), ``U_R`` (m, m) ; ``blocks`` : les
    blocs constants :math:`([U_R\ \ 0], [H^T\ \ I_n])` de :func:`square_root_blocks`, s'ils sont déjà
    calculés. Ou, pour ``N`` tirages, ``x_pred`` (N, n), ``nu`` (N, m) et ``M_pred`` (r, n) commune
    (covariances communes) ou (N, r, n). Renvoie ``(x, U, K, U_S)`` : ``U`` (…, n, n) racine triangulaire
    de :math:`P`, ``K`` (…, n, m), ``U_S`` (…, m, m) racine de :math:`S`."""
    m, n = H.shape
    r = M_pred.shape[-2]
    if M_pred.ndim > 2:  # une racine par tirage : QR en pile
        pre = np.zeros(M_pred.shape[:-2] + (m + r, m + n))
        pre[..., :m, :m] = U_R
        pre[..., m:, :m] = M_pred @ H.T
        pre[..., m:, m:] = M_pred
        post = np.linalg.qr(pre, mode="r")
        U_S = post[..., :m, :m]
        _check_root(np.abs(np.diagonal(U_S, axis1=-2, axis2=-1)), where, stacked=True)
        Kt = np.linalg.solve(U_S, post[..., :m, m:])
        K = np.swapaxes(Kt, -1, -2)
        return x_pred + (K @ nu[..., None])[..., 0], post[..., m:, m:], K, U_S
    top, HtI = square_root_blocks(H, U_R) if blocks is None else blocks
    pre = np.empty((m + r, m + n))
    pre[:m] = top                          # [U_R, 0]
    np.dot(M_pred, HtI, out=pre[m:])       # [M Hᵀ, M] = M [Hᵀ, I]
    post = _geqrf(pre)[0]                  # R au-dessus de la diagonale, réflecteurs au-dessous…
    post *= _upper_mask(post.shape)        # … effacés : U_S et U⁺ triangulaires
    U_S = post[:m, :m]
    if m > 1:  # en flottants Python : une réduction numpy coûte plus cher que toute la correction
        d = [abs(U_S.item(i, i)) for i in range(m)]
        if min(d) <= SINGULAR_ROOT_RTOL * max(d):
            _check_root(np.array([d]), where)
    Kt = _trsm(1.0, U_S, post[:m, m:])     # U_S Kᵀ = K̄ᵀ (résolution triangulaire, BLAS trsm)
    return x_pred + nu.dot(Kt), post[m:m + n, m:], Kt.T, U_S  # nu (N, m) : une ligne par tirage


def _check_root(d: np.ndarray, where: str, stacked: bool = False) -> None:
    """Diagonale(s) ``d`` (…, m) de la racine :math:`U_S` : :math:`S` numériquement singulière ?"""
    singular = d.min(axis=-1) <= SINGULAR_ROOT_RTOL * d.max(axis=-1)
    if np.any(singular):
        place = [f"tirage {int(np.argmax(singular))}"] if stacked else []
        place = ", ".join(place + ([where] if where else []))
        raise KalmanInputError(f"{S_NOT_PD[:-1]} ({place})." if place else S_NOT_PD)


#: Au plus autant de colonnes, les opérations « par ligne » d'un nuage (N, n) ∘ (n,) se font colonne par
#: colonne : numpy diffuse mal un vecteur court sur beaucoup de lignes (boucle interne de longueur n, ≈ 5×
#: plus lente), alors qu'une colonne est un seul tableau de N valeurs. Mêmes opérations, mêmes valeurs.
COLUMNWISE_MAX = 16


def centred_rows(X: np.ndarray, x: np.ndarray) -> np.ndarray:
    r"""Écarts :math:`x^i - \hat x` des lignes d'un nuage : ``X`` (N, n), ``x`` (n,) ; renvoie (N, n)
    (la même chose que ``X - x``, calculée colonne par colonne si :math:`n \le` :data:`COLUMNWISE_MAX`)."""
    if X.shape[1] > COLUMNWISE_MAX:
        return X - x
    D = np.empty_like(X)
    for j in range(X.shape[1]):
        np.subtract(X[:, j], x[j], out=D[:, j])
    return D


def weighted_rows(w: np.ndarray, D: np.ndarray) -> np.ndarray:
    r"""Lignes pondérées :math:`w^i d^i` : ``w`` (N,), ``D`` (N, n) ; renvoie (N, n) (la même chose que
    ``w[:, None] * D``, colonne par colonne si :math:`n \le` :data:`COLUMNWISE_MAX`)."""
    if D.shape[1] > COLUMNWISE_MAX:
        return w[:, None] * D
    out = np.empty_like(D)
    for j in range(D.shape[1]):
        np.multiply(w, D[:, j], out=out[:, j])
    return out
