r"""Filtre d'information en racine carrée (SRIF, *square-root information filter*) par factorisation QR.

Représentation (« équation de données », Bierman 1977) : une gaussienne :math:`\mathcal N(\hat x, P)` est
stockée sous la forme :math:`(\mathcal R_{xx}, z_x)` avec

.. math::

    \mathcal R_{xx}^T\mathcal R_{xx} = P^{-1}\ (\mathcal R_{xx}\ \text{triangulaire supérieure}),\qquad
    z_x = \mathcal R_{xx}\hat x,\qquad\text{soit}\quad \mathcal R_{xx}\,x = z_x - w_x,\ w_x\sim\mathcal N(0, I).

:math:`\mathcal R_{xx} = 0` (aucune information : a priori diffus) est permis. L'état et la covariance
se retrouvent par substitution arrière : :math:`\hat x = \mathcal R_{xx}^{-1}z_x`,
:math:`P = \mathcal R_{xx}^{-1}\mathcal R_{xx}^{-T}` (:func:`information_to_state`).

Notations (cours → paquet → notes du SRIF) : :math:`A` = ``A`` = :math:`F(k)`, :math:`C` = ``C`` =
:math:`H(k)`, :math:`\Phi` = ``Q`` = :math:`\Gamma Q\Gamma^T`, :math:`\Psi` = ``R`` = :math:`R(k)`.
Le bruit d'état est ramené à une covariance unité : :math:`Q = \Gamma\Gamma^T` avec :math:`\Gamma` de
forme ``(n, q)``, ``q`` = rang de ``Q`` (:func:`noise_factor`), donc :math:`\mathcal R_{vv} = I_q`,
:math:`z_v = 0`.

Ce module n'importe pas matplotlib.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
import scipy.linalg

from ..core.linalg import psd_solve
from ..core.models import LinearGaussianModel, NonlinearModel
from ..core.results import FilterResult
from ..core.validation import (
    number_text,
    KalmanInputError,
    as_square_matrix,
    as_vector,
    check_control_allowed,
    check_pd,
    check_psd,
    check_instance,
)
from .engine import Correction, FilterFamily, run_filter
from .extended import linearize_observation

__all__ = [
    "SquareRootInformation",
    "SrifUpdate",
    "StateEstimate",
    "RANK_RTOL",
    "noise_factor",
    "state_to_information",
    "information_to_state",
    "information_rank",
    "srif_predict",
    "srif_update",
    "square_root_information_filter",
    "extended_srif_predict",
    "extended_srif_update",
    "extended_square_root_information_filter",
]

#: Seuil relatif de rang : :math:`\mathcal R_{xx}` est tenue pour inversible si sa plus petite valeur
#: singulière dépasse ``RANK_RTOL`` fois la plus grande (au-delà, :math:`P` aurait un conditionnement
#: supérieur à :math:`10^{24}` et ne voudrait plus rien dire en double précision).
RANK_RTOL = 1e-12

#: Formes de l'étape de prédiction : ``"inverse"`` (§ 4.2, :math:`A` inversible) et ``"joint"``
#: (§ 4.4, sans :math:`A^{-1}`, bruit d'état de rang plein).
METHODS = ("inverse", "joint")


class SquareRootInformation(NamedTuple):
    r"""Information en racine carrée : ``R`` (n, n) triangulaire supérieure (:math:`\mathcal R_{xx}`),
    ``z`` (n,) (:math:`z_x`), avec :math:`\mathcal R_{xx}x = z_x - w_x`, :math:`w_x \sim \mathcal N(0, I)`."""

    R: np.ndarray
    z: np.ndarray


class SrifUpdate(NamedTuple):
    r"""Résultat de :func:`srif_update` : ``R`` (n, n), ``z`` (n,) a posteriori, et ``residual`` (m,) =
    :math:`z_r`, dont la norme au carré :math:`\lVert z_r\rVert^2` est la somme des carrés des résidus
    blanchis (égale à la NIS :math:`\nu^TS^{-1}\nu` quand l'a priori est de rang plein). Seule la norme de
    :math:`z_r` a un sens (la QR la concentre sur la première composante)."""

    R: np.ndarray
    z: np.ndarray
    residual: np.ndarray


class StateEstimate(NamedTuple):
    r"""Estimation :math:`\hat x` (n,) et covariance :math:`P` (n, n) tirées d'une information en racine carrée."""

    x: np.ndarray
    P: np.ndarray


# --------------------------------------------------------------------------- vérifications


def _check_information(R: Any, z: Any, n: int, R_name: str = "R_xx", z_name: str = "z_x"):
    R_arr = as_square_matrix(R_name, R, n)
    lower = np.tril(R_arr, -1)
    if np.any(lower != 0.0):
        i, j = np.unravel_index(np.argmax(np.abs(lower)), lower.shape)
        raise KalmanInputError(
            f"« {R_name} » doit être triangulaire supérieure (racine carrée de l'information, "
            f"{R_name}ᵀ{R_name} = P⁻¹) ; coefficient non nul sous la diagonale en ({i}, {j}) : "
            f"{number_text(R_arr[i, j], '.3g')}."
        )
    z_arr = as_vector(z_name, z, n)
    return R_arr, z_arr


def _check_method(method: Any) -> str:
    if method not in METHODS:
        raise KalmanInputError(
            f"« method » doit valoir \"inverse\" (A inversible, A⁻¹ dans le pré-tableau) ou \"joint\" "
            f"(sans A⁻¹, bruit d'état Q défini positif) ; reçu {method!r}."
        )
    return method


def _check_linear(model: Any) -> LinearGaussianModel:
    return check_instance(
        "model", model, LinearGaussianModel,
        "pour un modèle non linéaire, utilisez extended_square_root_information_filter",
    )


def _check_nonlinear(model: Any) -> NonlinearModel:
    return check_instance(
        "model", model, NonlinearModel, "pour un modèle linéaire, utilisez square_root_information_filter"
    )


# --------------------------------------------------------------------------- noyaux internes


def noise_factor(Q: Any, name: str = "Q") -> np.ndarray:
    r"""Facteur de rang plein :math:`\Gamma` (n, q) tel que :math:`\Gamma\Gamma^T = Q`, ``q`` = rang de ``Q``.

    Par ``eigh`` : :math:`\Gamma = V_+\Lambda_+^{1/2}` sur les valeurs propres supérieures à
    :math:`10^{-12}\lambda_{\max}` ; ``q = 0`` (forme (n, 0)) si :math:`Q = 0`. C'est le :math:`\Gamma` des
    notes avec :math:`\mathcal R_{vv} = I_q` : un bruit d'état de rang déficient (moins de ``n`` colonnes)
    est permis.
    """
    Q_arr = check_psd(name, as_square_matrix(name, Q, None))
    lam, V = scipy.linalg.eigh(Q_arr)
    if lam[-1] <= 0.0:
        return np.zeros((Q_arr.shape[0], 0))
    keep = lam > 1e-12 * lam[-1]
    return V[:, keep] * np.sqrt(lam[keep])


def _positive_diagonal(R: np.ndarray, z: np.ndarray):
    """Multiplie chaque ligne de ``[R z]`` par ±1 pour rendre la diagonale ≥ 0 (transformation orthogonale)."""
    s = np.where(np.diag(R) < 0.0, -1.0, 1.0)
    return R * s[:, None], z * s


def _triangularize(pre: np.ndarray) -> np.ndarray:
    """Facteur triangulaire de la QR (Householder, LAPACK ``geqrf``) du pré-tableau : :math:`T\\,\\text{pré} = \\text{post}`."""
    return scipy.linalg.qr(pre, mode="r", check_finite=False)[0]


def _time_update_inverse(R, z, lu, G, c):
    r"""Prédiction § 4.2 : QR de :math:`\begin{bmatrix} I_q & 0 & 0\\ -\mathcal R A^{-1}\Gamma & \mathcal R A^{-1} & z + \mathcal R A^{-1}c\end{bmatrix}`.

    ``lu`` : factorisation LU de :math:`A` (:func:`_lu_invertible`, calculée une fois par passage quand
    :math:`A` est constante) ; ``c`` (n,) ou ``None`` : terme forcé :math:`x_{k+1} = Ax_k + c + \Gamma v`
    (:math:`Bu`, ou :math:`f(\hat x) - F\hat x` pour le filtre étendu).
    """
    n, q = G.shape
    RAinv = scipy.linalg.lu_solve(lu, R.T, trans=1, check_finite=False).T  # X A = R  ⇔  Aᵀ Xᵀ = Rᵀ
    pre = np.zeros((q + n, q + n + 1))
    pre[:q, :q] = np.eye(q)
    pre[q:, :q] = -RAinv.dot(G)
    pre[q:, q:q + n] = RAinv
    pre[q:, -1] = z if c is None else z + RAinv.dot(c)
    post = _triangularize(pre)
    return (*_positive_diagonal(post[q:, q:q + n], post[q:, -1]), _norm(pre[q:, :-1]))


def _lu_invertible(A: np.ndarray, name: str = "A"):
    """Factorisation LU de la transition, après avoir vérifié qu'elle est inversible (la prédiction des
    notes utilise :math:`A^{-1}`). ``name="F"`` : jacobienne du SRIF étendu, évaluée à chaque pas."""
    sv = scipy.linalg.svdvals(A)
    if sv[-1] <= A.shape[0] * np.finfo(float).eps * sv[0]:
        cond = f"conditionnement {number_text(sv[0] / max(sv[-1], 1e-300), '.3g')}"
        if name == "A":
            raise KalmanInputError(
                f"La matrice de transition « A » (F des notes) est singulière ({cond}) : la prédiction du "
                "SRIF sous la forme des notes utilise A⁻¹. Utilisez method=\"joint\" (forme sans A⁻¹, qui "
                "demande un bruit d'état Q défini positif)."
            )
        raise KalmanInputError(
            f"La jacobienne « F » = ∂f/∂x de la transition est singulière en l'estimation courante ({cond}) : "
            "la prédiction du SRIF étendu utilise F⁻¹. Utilisez extended_kalman_filter pour ce modèle."
        )
    return scipy.linalg.lu_factor(A, check_finite=False)


def _time_update_joint(R, z, A, L, c):
    r"""Prédiction sans :math:`A^{-1}` (§ 4.4) : inconnues :math:`[x_k; x_{k+1}]`, QR de
    :math:`\begin{bmatrix}\mathcal R & 0 & z\\ -L^{-1}A & L^{-1} & L^{-1}c\end{bmatrix}`, :math:`LL^T = Q` ;
    le bloc en bas à droite est :math:`[\bar{\mathcal R}\ \ \bar z]`."""
    n = A.shape[0]
    Linv = scipy.linalg.solve_triangular(L, np.eye(n), lower=True, check_finite=False)
    pre = np.zeros((2 * n, 2 * n + 1))
    pre[:n, :n] = R
    pre[:n, -1] = z
    pre[n:, :n] = -Linv.dot(A)
    pre[n:, n:2 * n] = Linv
    if c is not None:
        pre[n:, -1] = Linv.dot(c)
    post = _triangularize(pre)
    return (*_positive_diagonal(post[n:, n:2 * n], post[n:, -1]), _norm(pre[:, :-1]))


def _joint_factor(Q: np.ndarray) -> np.ndarray:
    try:
        return scipy.linalg.cholesky(Q, lower=True, check_finite=False)
    except np.linalg.LinAlgError:
        raise KalmanInputError(
            "method=\"joint\" (prédiction sans A⁻¹) demande un bruit d'état « Q » défini positif "
            "(Q = L Lᵀ avec L inversible) ; ici Q est singulière. Utilisez method=\"inverse\" "
            "(A inversible, Q quelconque)."
        ) from None


def _measurement_update(R, z, H, Ra, y_lin):
    r"""Correction § 4.3 : blanchiment par :math:`R_a^{-T}` puis QR de
    :math:`\begin{bmatrix}\bar{\mathcal R} & \bar z\\ H_a & z_a\end{bmatrix}`.

    ``Ra`` : facteur de Cholesky supérieur de la covariance de mesure (:math:`R = R_a^TR_a`) ;
    ``y_lin`` (m,) : :math:`y` (linéaire) ou :math:`y - h(\bar x) + H\bar x` (étendu).
    """
    n = R.shape[0]
    Ha = scipy.linalg.solve_triangular(Ra, H, trans="T", lower=False, check_finite=False)
    za = scipy.linalg.solve_triangular(Ra, y_lin, trans="T", lower=False, check_finite=False)
    pre = np.empty((n + H.shape[0], n + 1))
    pre[:n, :n] = R
    pre[:n, n] = z
    pre[n:, :n] = Ha
    pre[n:, n] = za
    post = _triangularize(pre)
    R_new, z_new = _positive_diagonal(post[:n, :n], post[:n, n])
    return R_new, z_new, post[n:, n], _norm(pre[:, :n])


def _upper_cholesky(name: str, M: np.ndarray) -> np.ndarray:
    try:
        return scipy.linalg.cholesky(M, lower=False, check_finite=False)
    except np.linalg.LinAlgError:
        raise KalmanInputError(f"« {name} » doit être définie positive (covariance de mesure).") from None


def _norm(M: np.ndarray) -> float:
    return float(np.linalg.norm(M)) if M.size else 0.0


def information_rank(R: Any, scale: float = 0.0) -> int:
    r"""Rang numérique de :math:`\mathcal R_{xx}` : nombre de valeurs singulières supérieures à
    ``RANK_RTOL`` × max(plus grande valeur singulière, ``scale``).

    ``scale`` : ordre de grandeur des tableaux dont :math:`\mathcal R_{xx}` est issue (norme du
    pré-tableau de la dernière QR, que la boucle transmet) : une information faite uniquement d'arrondis
    de la QR (parties non observées) est ainsi reconnue comme nulle.
    """
    R_arr = np.asarray(R, dtype=float)
    sv = scipy.linalg.svdvals(R_arr)
    ref = max(float(sv[0]) if sv.size else 0.0, float(scale))
    if ref == 0.0:
        return 0
    return int(np.count_nonzero(sv > RANK_RTOL * ref))


def _state(R: np.ndarray, z: np.ndarray):
    n = R.shape[0]
    x = scipy.linalg.solve_triangular(R, z, lower=False, check_finite=False)
    Rinv = scipy.linalg.solve_triangular(R, np.eye(n), lower=False, check_finite=False)
    P = Rinv.dot(Rinv.T)
    return x, 0.5 * (P + P.T)


# --------------------------------------------------------------------------- conversions


def state_to_information(x: Any, P: Any) -> SquareRootInformation:
    r"""De :math:`(\hat x, P)` à :math:`(\mathcal R_{xx}, z_x)`, sans inverser :math:`P`.

    :math:`P = UU^T` avec :math:`U` triangulaire supérieure (Cholesky « renversée » :
    :math:`JPJ = LL^T`, :math:`U = JLJ`, :math:`J` la permutation qui renverse l'ordre), puis
    :math:`\mathcal R_{xx} = U^{-1}` par substitution (triangulaire supérieure, diagonale > 0) :
    :math:`\mathcal R_{xx}^T\mathcal R_{xx} = (UU^T)^{-1} = P^{-1}`, et :math:`z_x = \mathcal R_{xx}\hat x`.

    Paramètres : ``x`` (n,), ``P`` (n, n) symétrique **définie** positive (un a priori sans information
    s'écrit directement :math:`\mathcal R_{xx} = 0`, :math:`z_x = 0`).
    """
    return _to_information(x, P, "x", "P")


def _to_information(x: Any, P: Any, x_name: str, P_name: str) -> SquareRootInformation:
    P_arr = as_square_matrix(P_name, P, None)
    n = P_arr.shape[0]
    x_arr = as_vector(x_name, x, n)
    P_arr = check_pd(P_name, P_arr)
    L = scipy.linalg.cholesky(P_arr[::-1, ::-1], lower=True, check_finite=False)
    U = L[::-1, ::-1]
    R = scipy.linalg.solve_triangular(U, np.eye(n), lower=False, check_finite=False)
    return SquareRootInformation(R, R.dot(x_arr))


def information_to_state(R: Any, z: Any) -> StateEstimate:
    r"""De :math:`(\mathcal R_{xx}, z_x)` à :math:`(\hat x, P)` par substitution arrière (``solve_triangular``) :
    :math:`\hat x = \mathcal R_{xx}^{-1}z_x`, :math:`P = \mathcal R_{xx}^{-1}\mathcal R_{xx}^{-T}`.

    ``R`` (n, n) triangulaire supérieure, ``z`` (n,). Lève une :class:`KalmanInputError` si
    :math:`\mathcal R_{xx}` est singulière (l'information ne détermine pas tout l'état).
    """
    R_arr = as_square_matrix("R_xx", R, None)
    R_arr, z_arr = _check_information(R_arr, z, R_arr.shape[0])
    rank = information_rank(R_arr)
    if rank < R_arr.shape[0]:
        raise KalmanInputError(
            f"« R_xx » est singulière (rang numérique {rank} < n = {R_arr.shape[0]}) : l'information "
            "accumulée ne détermine pas encore tout l'état, x̂ et P ne sont pas définis."
        )
    return StateEstimate(*_state(R_arr, z_arr))


# --------------------------------------------------------------------------- étapes publiques


def srif_predict(model: LinearGaussianModel, R: Any, z: Any, u: Any = None, *,
                 method: str = "inverse") -> SquareRootInformation:
    r"""Prédiction (*time update*) du SRIF : :math:`(\hat{\mathcal R}_{xx}(k), \hat z_x(k)) \to
    (\bar{\mathcal R}_{xx}(k+1), \bar z_x(k+1))`.

    ``method="inverse"`` (notes, corrigées) : avec :math:`Q = \Gamma\Gamma^T` (:func:`noise_factor`,
    :math:`\mathcal R_{vv} = I_q`, :math:`z_v = 0`), une QR :math:`T_a` triangularise

    .. math::

        T_a\begin{bmatrix} I_q & 0 & 0\\ -\mathcal R_{xx}A^{-1}\Gamma & \mathcal R_{xx}A^{-1} &
        z_x + \mathcal R_{xx}A^{-1}Bu \end{bmatrix}
        = \begin{bmatrix} \bar{\mathcal R}_{vv} & \bar{\mathcal R}_{vx} & \bar z_v\\
        0 & \bar{\mathcal R}_{xx} & \bar z_x \end{bmatrix}.

    :math:`A` doit être inversible ; :math:`\mathcal R_{xx}A^{-1}` est obtenue par une factorisation LU
    de :math:`A` (jamais d'inverse explicite). ``method="joint"`` (sans :math:`A^{-1}`, :math:`A` peut être
    singulière, :math:`Q = LL^T` définie positive) triangularise
    :math:`\begin{bmatrix}\mathcal R_{xx} & 0 & z_x\\ -L^{-1}A & L^{-1} & L^{-1}Bu\end{bmatrix}` (inconnues
    :math:`[x_k; x_{k+1}]`) et garde le bloc en bas à droite.

    Paramètres : ``R`` (n, n) triangulaire supérieure (``0`` permis), ``z`` (n,), ``u`` (p,) ou ``None``.
    Renvoie :class:`SquareRootInformation` (diagonale de :math:`\bar{\mathcal R}_{xx}` ≥ 0).
    """
    model = _check_linear(model)
    method = _check_method(method)
    R_arr, z_arr = _check_information(R, z, model.n_state)
    c = None
    if u is not None:
        check_control_allowed("u", model.n_control)
        c = model.B @ as_vector("u", u, model.n_control)
    if method == "inverse":
        R_new, z_new, _ = _time_update_inverse(R_arr, z_arr, _lu_invertible(model.A), noise_factor(model.Q), c)
    else:
        R_new, z_new, _ = _time_update_joint(R_arr, z_arr, model.A, _joint_factor(model.Q), c)
    return SquareRootInformation(R_new, z_new)


def srif_update(model: LinearGaussianModel, R: Any, z: Any, y: Any) -> SrifUpdate:
    r"""Correction (*measurement update*) du SRIF.

    Blanchiment par le facteur de Cholesky supérieur :math:`R_a` de la covariance de mesure
    (:math:`\Psi = R_a^TR_a`) : :math:`H_a = R_a^{-T}C`, :math:`z_a = R_a^{-T}y` (substitutions
    triangulaires), puis une QR :math:`T_b` :

    .. math::

        T_b\begin{bmatrix}\bar{\mathcal R}_{xx} & \bar z_x\\ H_a & z_a\end{bmatrix}
        = \begin{bmatrix}\hat{\mathcal R}_{xx} & \hat z_x\\ 0 & z_r\end{bmatrix}.

    Paramètres : ``R`` (n, n) triangulaire supérieure (a priori, ``0`` permis), ``z`` (n,), ``y`` (m,).
    Renvoie :class:`SrifUpdate` ``(R, z, residual)``, ``residual`` = :math:`z_r` (m,).
    """
    model = _check_linear(model)
    R_arr, z_arr = _check_information(R, z, model.n_state)
    y_arr = as_vector("y", y, model.n_obs)
    Ra = _upper_cholesky("R", model.R)
    return SrifUpdate(*_measurement_update(R_arr, z_arr, model.C, Ra, y_arr)[:3])


# --------------------------------------------------------------------------- boucle


def _initial_information(n: int, x0: Any, P0: Any, R0: Any, z0: Any):
    given_state = x0 is not None or P0 is not None
    given_info = R0 is not None or z0 is not None
    if given_state and given_info:
        raise KalmanInputError(
            "Donnez l'a priori soit par (x0, P0), soit par (R0, z0) (information en racine carrée), pas les deux."
        )
    if given_state:
        if x0 is None or P0 is None:
            raise KalmanInputError("« x0 » et « P0 » vont ensemble : donnez les deux (ou aucun : a priori diffus).")
        return _to_information(as_vector("x0", x0, n), as_square_matrix("P0", P0, n), "x0", "P0")
    if given_info:
        if R0 is None or z0 is None:
            raise KalmanInputError("« R0 » et « z0 » vont ensemble : donnez les deux (ou aucun : a priori diffus).")
        return SquareRootInformation(*_check_information(R0, z0, n, "R0", "z0"))
    return SquareRootInformation(np.zeros((n, n)), np.zeros(n))


class _Information(NamedTuple):
    """État interne du SRIF dans le moteur : :math:`(\\mathcal R_{xx}, z_x)` et, quand l'information est
    de rang plein, :math:`(\\hat x, P)` (NaN sinon)."""

    R: np.ndarray
    z: np.ndarray
    x: np.ndarray
    P: np.ndarray

    @property
    def full(self) -> bool:
        return bool(np.isfinite(self.x[0]))


def _information_state(R: np.ndarray, z: np.ndarray, full: bool) -> _Information:
    n = R.shape[0]
    if full:
        return _Information(R, z, *_state(R, z))
    return _Information(R, z, np.full(n, np.nan), np.full((n, n), np.nan))


def _with_rank(R: np.ndarray, z: np.ndarray, scale: float, already_full: bool = False) -> _Information:
    """``scale`` : norme du pré-tableau de la dernière QR (voir :func:`information_rank`)."""
    return _information_state(R, z, already_full or information_rank(R, scale) == R.shape[0])


def _diagnostics(prior: _Information, post: _Information, H: np.ndarray, Rm: np.ndarray, nu: np.ndarray) -> Correction:
    """Diagnostics du KF équivalent : :math:`\\nu`, :math:`S = HP^-H^T + R`, :math:`K = PH^TR^{-1}` (forme a
    posteriori du gain) ; NaN si l'a priori n'est pas de rang plein (pas de gain de Kalman défini)."""
    n, m = prior.R.shape[0], H.shape[0]
    if not prior.full:
        return Correction(np.full((n, m), np.nan), np.full(m, np.nan), np.full((m, m), np.nan))
    S = H.dot(prior.P).dot(H.T) + Rm
    K = psd_solve(Rm, H.dot(post.P), message="« R » doit être définie positive.").T
    return Correction(K, nu, S)


def _information_moments(state: _Information):
    return state.x, state.P


def square_root_information_filter(
    model: LinearGaussianModel,
    y: Any,
    x0: Any = None,
    P0: Any = None,
    u: Any = None,
    *,
    R0: Any = None,
    z0: Any = None,
    method: str = "inverse",
) -> FilterResult:
    r"""SRIF sur toutes les mesures : pour chaque ``y[k]``, :func:`srif_predict` puis :func:`srif_update`,
    dans l'ordre de :func:`~kalman_course.kalman_filter` (même :class:`~kalman_course.FilterResult`).

    A priori : ``(x0, P0)`` (converti par :func:`state_to_information`), **ou** ``(R0, z0)``, **ou rien** :
    a priori diffus :math:`\mathcal R_{xx} = 0`, :math:`z_x = 0` (aucune information sur l'état initial).

    Tant que :math:`\mathcal R_{xx}` est singulière (rang < n, voir :data:`RANK_RTOL`), l'état n'est pas
    déterminé : les lignes correspondantes de ``x``, ``P`` (a posteriori) et ``x_pred``, ``P_pred``
    (a priori) valent **NaN** ; ``observed`` indique toujours les mesures reçues, et
    ``np.isfinite(result.x).all(axis=1)`` les pas où l'état est défini.
    Là où l'a priori est de rang plein, ``innovation`` :math:`\nu = y - C\hat x^-`, ``S`` :math:`= CP^-C^T + R`
    et ``K`` :math:`= P C^T R^{-1}` sont ceux du filtre de Kalman équivalent (diagnostics : le SRIF ne
    calcule ni gain ni :math:`S`) ; quand une mesure est utilisée avec un a priori singulier, les colonnes
    correspondantes de ``K`` valent NaN.

    Paramètres
    ----------
    model : LinearGaussianModel
    y : (T, m), ou (T,) si m = 1 — ``NaN``/``None`` : composante manquante.
    x0 : (n,), P0 : (n, n) définie positive — optionnels, ensemble.
    u : (T, p), ou (T,) si p = 1, optionnel — commandes (``u[k]``, qui contient :math:`u_{k-1}`, sert à prédire vers ``y[k]``).
    R0 : (n, n) triangulaire supérieure, z0 : (n,) — optionnels, ensemble.
    method : ``"inverse"`` (défaut, :math:`A` inversible) ou ``"joint"`` (sans :math:`A^{-1}`, :math:`Q`
        définie positive), voir :func:`srif_predict`.
    """
    model = _check_linear(model)
    family = srif_family(method)
    prior = _initial_information(model.n_state, x0, P0, R0, z0)
    return run_filter(family, model, y, prior, None, u)


def srif_family(method: str = "inverse") -> FilterFamily:
    """Les étapes du SRIF pour le moteur. Chaque étape reçoit le modèle du pas (``model.at(k)`` pour un
    modèle variable dans le temps) ; ses factorisations (LU de :math:`A` ou facteur de Cholesky de :math:`Q`,
    facteur du bruit d'état, facteur de :math:`R`) sont calculées une fois par modèle de pas et gardées pour
    la durée du filtrage (une seule fois pour un modèle constant). L'a priori passé au moteur est un
    :class:`SquareRootInformation` (voir :func:`square_root_information_filter`)."""
    method = _check_method(method)
    factors: dict[int, tuple] = {}  # id(modèle du pas) → (modèle, prédiction, facteur de R)

    def factored(model: LinearGaussianModel):
        entry = factors.get(id(model))
        if entry is None or entry[0] is not model:
            if method == "inverse":
                lu, G = _lu_invertible(model.A), noise_factor(model.Q)

                def time_update(R, z, c):
                    return _time_update_inverse(R, z, lu, G, c)
            else:
                A, L = model.A, _joint_factor(model.Q)

                def time_update(R, z, c):
                    return _time_update_joint(R, z, A, L, c)

            entry = factors[id(model)] = (model, time_update, _upper_cholesky("R", model.R))
        return entry

    def prior(model, info, _):
        return _with_rank(info.R, info.z, 0.0)

    def predict_step(model, state: _Information, u):
        R, z, scale = factored(model)[1](state.R, state.z, None if u is None else model.B.dot(u))
        return _with_rank(R, z, scale)

    def update_step(model, state: _Information, y, idx):
        _, _, Ra_full = factored(model)
        if idx is None:
            C_k, R_k, Ra = model.C, model.R, Ra_full
        else:
            C_k, R_k = model.C[idx], model.R[np.ix_(idx, idx)]
            Ra = _upper_cholesky("R", R_k)
        R, z, _, scale = _measurement_update(state.R, state.z, C_k, Ra, y)
        post = _with_rank(R, z, scale, already_full=state.full)
        nu = y - C_k.dot(state.x) if state.full else None
        return post, _diagnostics(state, post, C_k, R_k, nu)

    return FilterFamily(
        name="filtre d'information en racine carrée",
        model_type=LinearGaussianModel,
        model_hint="pour un modèle non linéaire, utilisez extended_square_root_information_filter",
        prior=prior,
        predict=predict_step,
        update=update_step,
        moments=_information_moments,
    )


# --------------------------------------------------------------------------- SRIF étendu


def _require_state(R: np.ndarray, z: np.ndarray, what: str) -> np.ndarray:
    if information_rank(R) < R.shape[0]:
        raise KalmanInputError(
            f"Le SRIF étendu linéarise autour de {what} : il faut une information de rang plein "
            "(« R_xx » inversible), donc un a priori (x0, P0) ; une initialisation diffuse n'est possible qu'en linéaire."
        )
    return _state(R, z)[0]


def _extended_time_update(model: NonlinearModel, R, z, u):
    x_hat = _require_state(R, z, "l'estimation a posteriori x̂(k)")
    F = model.transition_jacobian(x_hat, u)
    c = model.transition(x_hat, u) - F.dot(x_hat)  # f(x̂) − F x̂ : z + R F⁻¹ c = z + R (F⁻¹ f − x̂)
    G = noise_factor(model.process_noise(x_hat, u), "W Q Wᵀ")
    return _time_update_inverse(R, z, _lu_invertible(F, "F"), G, c)[:2]


def _extended_measurement_update(model: NonlinearModel, R, z, y, idx):
    x_bar = _require_state(R, z, "la prédiction x̄(k+1)")
    r, H, Rm = linearize_observation(model, x_bar, y, idx)  # y − h(x̄), angles ramenés dans (−π, π]
    Ra = _upper_cholesky("R", Rm)
    R_new, z_new, zr, _ = _measurement_update(R, z, H, Ra, r + H.dot(x_bar))
    return R_new, z_new, zr, x_bar, H, Rm, r


def extended_srif_predict(model: NonlinearModel, R: Any, z: Any, u: Any = None) -> SquareRootInformation:
    r"""Prédiction du SRIF étendu (§ 4.2 des notes, corrigée) : linéarisation en :math:`\hat x(k)`,
    :math:`F = \partial f/\partial x`, :math:`\Gamma\Gamma^T = WQW^T`, puis la QR de :func:`srif_predict`
    avec le second membre :math:`z_x + \mathcal R_{xx}\,[F^{-1}f(\hat x, u) - \hat x]`.

    ``R`` doit être inversible (il faut :math:`\hat x` pour linéariser) et :math:`F` aussi.
    """
    model = _check_nonlinear(model)
    R_arr, z_arr = _check_information(R, z, model.n_state)
    u_arr = None
    if u is not None:
        check_control_allowed("u", model.n_control)
        u_arr = as_vector("u", u, model.n_control)
    return SquareRootInformation(*_extended_time_update(model, R_arr, z_arr, u_arr))


def extended_srif_update(model: NonlinearModel, R: Any, z: Any, y: Any) -> SrifUpdate:
    r"""Correction du SRIF étendu (§ 4.3) : linéarisation en :math:`\bar x = \bar{\mathcal R}^{-1}\bar z`,
    :math:`H = \partial h/\partial x\rvert_{\bar x}`, puis la QR de :func:`srif_update` avec la mesure
    blanchie :math:`z_a - h_a(\bar x) + H_a\bar x` (résidus angulaires ramenés dans :math:`(-\pi,\pi]`)."""
    model = _check_nonlinear(model)
    R_arr, z_arr = _check_information(R, z, model.n_state)
    y_arr = as_vector("y", y, model.n_obs)
    R_new, z_new, zr, *_ = _extended_measurement_update(model, R_arr, z_arr, y_arr, None)
    return SrifUpdate(R_new, z_new, zr)


def extended_square_root_information_filter(
    model: NonlinearModel, y: Any, x0: Any, P0: Any, u: Any = None
) -> FilterResult:
    r"""SRIF étendu sur toutes les mesures (:func:`extended_srif_predict` puis :func:`extended_srif_update`).

    Avec ces points de linéarisation, il est algébriquement l'EKF
    (:func:`~kalman_course.extended_kalman_filter`). Il faut un a priori ``(x0, P0)`` (``P0`` définie
    positive) : on linéarise autour de l'estimation. Même :class:`~kalman_course.FilterResult` que l'EKF
    (``innovation``, ``S`` et ``K = P H^T R^{-1}`` en diagnostics).
    """
    model = _check_nonlinear(model)
    return run_filter(extended_srif_family(), model, y, x0, P0, u)


def extended_srif_family() -> FilterFamily:
    """Les étapes du SRIF étendu pour le moteur (a priori :math:`(\\hat x_0, P_0)`, :math:`P_0` définie positive)."""

    def prior(model, x0, P0):
        n = model.n_state
        R, z = _to_information(as_vector("x0", x0, n), as_square_matrix("P0", P0, n), "x0", "P0")
        return _information_state(R, z, True)

    def predict_step(model, state: _Information, u):
        R, z = _extended_time_update(model, state.R, state.z, u)
        return _information_state(R, z, information_rank(R) == R.shape[0])

    def update_step(model, state: _Information, y, idx):
        R, z, _, _, H, Rm, r = _extended_measurement_update(model, state.R, state.z, y, idx)
        post = _information_state(R, z, True)
        return post, _diagnostics(state, post, H, Rm, r)

    return FilterFamily(
        name="filtre d'information en racine carrée étendu",
        model_type=NonlinearModel,
        model_hint="pour un modèle linéaire, utilisez square_root_information_filter",
        prior=prior,
        predict=predict_step,
        update=update_step,
        moments=_information_moments,
    )
