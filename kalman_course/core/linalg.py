r"""Algèbre linéaire commune à tous les filtres : symétrisation, gain par Cholesky, facteurs nommés.

:math:`S` n'est jamais inversée : le gain :math:`K = P^-H^TS^{-1}` vient de la résolution de
:math:`S K^T = H P^-` par Cholesky (LAPACK ``?posv`` via ``scipy.linalg``). Une factorisation qui échoue
devient une :class:`~kalman_course.core.validation.KalmanInputError` qui dit quelle matrice et quoi
vérifier, jamais une ``LinAlgError`` nue.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from .validation import KalmanInputError

__all__ = [
    "symmetrize", "kalman_gain", "correct", "solve_pd_many", "correct_many", "cholesky_factor", "covariance_factor",
    "centred_rows", "weighted_rows",
]

_posv = scipy.linalg.get_lapack_funcs("posv", dtype=np.float64)

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


def kalman_gain(P_pred: np.ndarray, H: np.ndarray, R: np.ndarray, where: str = ""):
    r"""Gain :math:`K = P^-H^TS^{-1}` avec :math:`S = HP^-H^T + R`, par résolution de Cholesky.

    ``P_pred`` (n, n), ``H`` (m, n), ``R`` (m, m). Renvoie ``(K (n, m), S (m, m), P^-H^T (n, m))``.
    ``where`` précise le pas dans le message d'erreur (« au pas 12 »…).
    """
    PHt = P_pred.dot(H.T)
    S = H.dot(PHt) + R
    _, Kt, info = _posv(S, PHt.T)
    if info != 0:
        raise KalmanInputError(S_NOT_PD if not where else f"{S_NOT_PD[:-1]} ({where}).")
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


def solve_pd_many(S: np.ndarray, B: np.ndarray, name: str, message: str, where: str = "") -> np.ndarray:
    r"""Résout :math:`S_i X_i = B_i` pour une pile de matrices définies positives, par Cholesky.

    ``S`` (N, m, m), ``B`` (N, m, q) ; renvoie ``X`` (N, m, q). Si une :math:`S_i` n'est pas définie
    positive : :class:`KalmanInputError` avec ``message``, le premier tirage fautif et ``where``."""
    try:
        L = np.linalg.cholesky(S)
    except np.linalg.LinAlgError:
        bad = next(i for i in range(S.shape[0]) if not _is_pd(S[i]))
        place = f"tirage {bad}" + (f", {where}" if where else "")
        raise KalmanInputError(f"{message[:-1]} ({name}, {place}).") from None
    return np.linalg.solve(np.swapaxes(L, -1, -2), np.linalg.solve(L, B))


def _is_pd(M: np.ndarray) -> bool:
    try:
        np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        return False
    return True


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
    K = np.swapaxes(solve_pd_many(S, np.swapaxes(PHt, -1, -2), "S", S_NOT_PD, where), -1, -2)
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
