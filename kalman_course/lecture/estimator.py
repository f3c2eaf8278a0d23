r"""L'estimateur linéaire du cours, la récurrence de son erreur et le gain vu comme un réglage.

Chapitres « Construction d'un estimateur » et « Gain optimal ». L'estimateur général du cours est

.. math::

    \hat x_{n+1} = A_f\,\hat x_n + B_f\,u_n + K_{n+1}\,y_{n+1},

et son erreur :math:`e_n = \hat x_n - x_n` suit (erratum 001-1 : :math:`\mathbb E[\hat x_n]`, pas
:math:`\hat x_n`, dans la moyenne)

.. math::

    \mathbb E[e_{n+1}] = (I - K_{n+1}C)A\,\mathbb E[e_n] + (A_f + K_{n+1}CA - A)\,\mathbb E[\hat x_n]
    + (B_f + K_{n+1}CB - B)\,u_n .

Les conditions suffisantes du cours donnent :math:`A_f = (I - K_{n+1}C)A` et :math:`B_f = (I - K_{n+1}C)B`
(:func:`filter_matrices`) ; l'erreur moyenne décroît alors si le **produit** :math:`(I - KC)A` est stable
(erratum 001-3, :func:`error_transition`). Ces fonctions acceptent n'importe quel gain : c'est ce qui
permet de comparer le gain de Kalman à d'autres réglages.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
import scipy.linalg

from ..core.models import LinearGaussianModel
from ..core.validation import (
    number_text,
    KalmanInputError,
    as_batch_measurements,
    as_controls,
    as_float_array,
    as_matrix,
    as_measurements,
    as_square_matrix,
    as_vector,
    check_psd,
    check_instance,
)

__all__ = [
    "MeanError",
    "covariance_for_gain",
    "error_transition",
    "filter_matrices",
    "gains_sequence",
    "linear_estimator",
    "linear_estimator_runs",
    "mean_error_recursion",
    "measurement_initialisation",
    "spectral_radius",
]


class MeanError(NamedTuple):
    r"""Espérances propagées par :func:`mean_error_recursion`, chacune de forme (T+1, n), ligne 0 = instant 0.

    ``x`` : :math:`\mathbb E[x_n]` ; ``x_hat`` : :math:`\mathbb E[\hat x_n]` ; ``e`` : :math:`\mathbb E[e_n]`,
    calculée par la récurrence du cours (et non comme la différence des deux premières).
    """

    x: np.ndarray
    x_hat: np.ndarray
    e: np.ndarray


def _check_model(model: Any) -> LinearGaussianModel:
    return check_instance("model", model, LinearGaussianModel)


def gains_sequence(model: LinearGaussianModel, K: Any, n_steps: int | None = None) -> np.ndarray:
    """Gains empilés (T, n, m) : ``K`` de forme (n, m) (gain fixe, répété ``n_steps`` fois) ou (T, n, m)
    (par exemple ``FilterResult.K``)."""
    n, m = model.n_state, model.n_obs
    arr = as_float_array("K", K)
    if arr.ndim == 3:
        if arr.shape[1:] != (n, m):
            raise KalmanInputError(f"« K » doit être de forme (T, {n}, {m}) ou ({n}, {m}) ; reçu {arr.shape}.")
        if n_steps is not None and arr.shape[0] != n_steps:
            raise KalmanInputError(
                f"« K » doit contenir un gain par pas de temps : {n_steps} attendus, {arr.shape[0]} reçus."
            )
        return arr
    if n_steps is None:
        raise KalmanInputError("Un gain fixe « K » de forme (n, m) exige le nombre de pas « n_steps ».")
    return np.broadcast_to(as_matrix("K", arr, n, m), (n_steps, n, m))


def filter_matrices(model: LinearGaussianModel, K: Any):
    r"""Matrices du filtre imposées par les conditions suffisantes du cours :

    .. math:: A_f = (I - KC)A,\qquad B_f = (I - KC)B .

    ``K`` (n, m). Renvoie ``(A_f, B_f)`` de formes (n, n) et (n, p) (``B_f`` vaut ``None`` sans commande).
    """
    model = _check_model(model)
    K_arr = as_matrix("K", K, model.n_state, model.n_obs)
    IKC = np.eye(model.n_state) - K_arr @ model.C
    return IKC @ model.A, (None if model.B is None else IKC @ model.B)


def error_transition(model: LinearGaussianModel, K: Any) -> np.ndarray:
    r"""Matrice de transition de l'erreur moyenne :math:`(I - KC)A`, forme (n, n) (erratum 001-3)."""
    return filter_matrices(model, K)[0]


def spectral_radius(M: Any) -> float:
    r"""Rayon spectral :math:`\rho(M) = \max_i |\lambda_i(M)|` ; :math:`\rho < 1` ⇔ :math:`M^n \to 0`."""
    arr = as_square_matrix("M", M, None)
    return float(np.max(np.abs(scipy.linalg.eigvals(arr))))


def _estimator_matrices(model, Ks, A_f, B_f):
    """Suite de (A_f, B_f) : imposées par les conditions si None, sinon fixes (pour enfreindre les conditions)."""
    n, p = model.n_state, model.n_control
    T = Ks.shape[0]
    IKC = np.eye(n)[None] - Ks @ model.C  # (T, n, n)
    if A_f is None:
        A_fs = IKC @ model.A
    else:
        A_fs = np.broadcast_to(as_square_matrix("A_f", A_f, n), (T, n, n))
    if p == 0:
        if B_f is not None:
            raise KalmanInputError("« B_f » est fourni mais le modèle n'a pas de commande (pas de matrice B).")
        return A_fs, None
    if B_f is None:
        B_fs = IKC @ model.B
    else:
        B_fs = np.broadcast_to(as_matrix("B_f", B_f, n, p), (T, n, p))
    return A_fs, B_fs


def linear_estimator(
    model: LinearGaussianModel,
    y: Any,
    x0_hat: Any,
    K: Any,
    u: Any = None,
    *,
    A_f: Any = None,
    B_f: Any = None,
) -> np.ndarray:
    r"""L'estimateur linéaire général du cours, pour un gain donné :

    .. math:: \hat x_{n+1} = A_f\,\hat x_n + B_f\,u_n + K_{n+1}\,y_{n+1}.

    Paramètres
    ----------
    y : (T, m), ou (T,) si m = 1 — mesures :math:`y_1 \dots y_T` (pas de mesure manquante).
    x0_hat : (n,) — :math:`\hat x_0`.
    K : (n, m) gain fixe, ou (T, n, m) gains :math:`K_1 \dots K_T` (par exemple ceux d'un filtre de Kalman).
    u : (T, p), optionnel — commandes :math:`u_0 \dots u_{T-1}`.
    A_f, B_f : (n, n), (n, p), optionnels — par défaut ceux des conditions suffisantes, recalculés à chaque
        pas avec :math:`K_{n+1}` ; les fournir permet d'étudier un estimateur qui ne les respecte pas.

    Renvoie :math:`\hat x_1 \dots \hat x_T`, forme (T, n). Avec les gains d'un filtre de Kalman et les
    matrices par défaut, c'est exactement le filtre de Kalman.
    """
    model = _check_model(model)
    return _estimate(model, as_measurements("y", y, model.n_obs)[None], "y", x0_hat, K, u, A_f, B_f)[0]


def linear_estimator_runs(
    model: LinearGaussianModel,
    Y: Any,
    x0_hat: Any,
    K: Any,
    u: Any = None,
    *,
    A_f: Any = None,
    B_f: Any = None,
) -> np.ndarray:
    r""":func:`linear_estimator` appliqué à ``N`` tirages à la fois (même modèle, mêmes gains, mêmes
    commandes) : la même récurrence, sur la pile des estimations (axe des tirages en tête).

    ``Y`` : (N, T, m), ou (N, T) si m = 1. Renvoie (N, T, n) ; la ligne ``i`` est
    ``linear_estimator(model, Y[i], …)``.
    """
    model = _check_model(model)
    return _estimate(model, as_batch_measurements("Y", Y, model.n_obs), "Y", x0_hat, K, u, A_f, B_f)


def _estimate(model, Y, name, x0_hat, K, u, A_f, B_f) -> np.ndarray:
    r"""La récurrence :math:`\hat x_{n+1} = A_f\hat x_n + B_f u_n + K_{n+1}y_{n+1}` sur ``Y`` (N, T, m) → (N, T, n)."""
    if np.isnan(Y).any():
        raise KalmanInputError(f"« {name} » contient des mesures manquantes (NaN) : l'estimateur linéaire les refuse.")
    N, T, _ = Y.shape
    x = np.broadcast_to(as_vector("x0_hat", x0_hat, model.n_state), (N, model.n_state))
    U = as_controls("u", u, T, model.n_control)
    Ks = gains_sequence(model, K, T)
    A_fs, B_fs = _estimator_matrices(model, Ks, A_f, B_f)
    out = np.empty((N, T, model.n_state))
    for k in range(T):
        x = x @ A_fs[k].T + Y[:, k] @ Ks[k].T
        if U is not None:
            x = x + B_fs[k] @ U[k]
        out[:, k] = x
    return out


def mean_error_recursion(
    model: LinearGaussianModel,
    K: Any,
    *,
    x0_mean: Any,
    x0_hat: Any,
    n_steps: int | None = None,
    u: Any = None,
    A_f: Any = None,
    B_f: Any = None,
) -> MeanError:
    r"""Propage l'espérance de l'erreur par la récurrence du cours (corrigée, erratum 001-1) :

    .. math::

        \mathbb E[e_{n+1}] = (I - K_{n+1}C)A\,\mathbb E[e_n] + (A_f + K_{n+1}CA - A)\,\mathbb E[\hat x_n]
        + (B_f + K_{n+1}CB - B)\,u_n,

    avec :math:`\mathbb E[e_0] = \hat x_0 - \mathbb E[x_0]`, et en parallèle
    :math:`\mathbb E[x_{n+1}] = A\,\mathbb E[x_n] + Bu_n`,
    :math:`\mathbb E[\hat x_{n+1}] = A_f\,\mathbb E[\hat x_n] + B_fu_n + K_{n+1}C\,\mathbb E[x_{n+1}]`.

    ``K`` : (n, m) avec ``n_steps``, ou (T, n, m) ; ``x0_mean`` (n,) : :math:`\mathbb E[x_0]` ;
    ``x0_hat`` (n,) : :math:`\hat x_0` ; ``u`` (T, p) ; ``A_f``, ``B_f`` comme :func:`linear_estimator`.
    Renvoie :class:`MeanError` (tableaux (T+1, n)).
    """
    model = _check_model(model)
    Ks = gains_sequence(model, K, n_steps)
    T = Ks.shape[0]
    n = model.n_state
    m_x = as_vector("x0_mean", x0_mean, n)
    m_hat = as_vector("x0_hat", x0_hat, n)
    U = as_controls("u", u, T, model.n_control)
    A_fs, B_fs = _estimator_matrices(model, Ks, A_f, B_f)
    A, B, C = model.A, model.B, model.C
    I = np.eye(n)
    xs = np.empty((T + 1, n))
    xh = np.empty((T + 1, n))
    es = np.empty((T + 1, n))
    xs[0], xh[0], es[0] = m_x, m_hat, m_hat - m_x
    for k in range(T):
        Kk = Ks[k]
        e_next = (I - Kk @ C) @ A @ es[k] + (A_fs[k] + Kk @ C @ A - A) @ xh[k]
        x_next = A @ xs[k]
        xh_next = A_fs[k] @ xh[k]
        if U is not None:
            e_next = e_next + (B_fs[k] + Kk @ C @ B - B) @ U[k]
            x_next = x_next + B @ U[k]
            xh_next = xh_next + B_fs[k] @ U[k]
        xh_next = xh_next + Kk @ C @ x_next
        xs[k + 1], xh[k + 1], es[k + 1] = x_next, xh_next, e_next
    return MeanError(x=xs, x_hat=xh, e=es)


def covariance_for_gain(model: LinearGaussianModel, P_pred: Any, K: Any) -> np.ndarray:
    r"""Covariance de l'erreur a posteriori pour un gain **quelconque** :math:`K` (forme de Joseph) :

    .. math:: P_{n+1}(K) = (I - KC)\,P^-_{n+1}\,(I - KC)^T + K\,\Psi\,K^T .

    C'est la fonction que le gain optimal minimise (au sens de la trace) ; pour le gain de Kalman elle
    se réduit à :math:`(I - KC)P^-_{n+1}`. ``P_pred`` (n, n), ``K`` (n, m) ; renvoie (n, n).
    """
    model = _check_model(model)
    n = model.n_state
    P = check_psd("P_pred", as_square_matrix("P_pred", P_pred, n))
    K_arr = as_matrix("K", K, n, model.n_obs)
    IKC = np.eye(n) - K_arr @ model.C
    return IKC @ P @ IKC.T + K_arr @ model.R @ K_arr.T


def measurement_initialisation(model: LinearGaussianModel, y0: Any):
    r"""Initialisation par une première mesure (conseil du cours, corrigé par les errata 001-5 et 001-6) :

    .. math:: \hat x_0 = C^{-1} y_0,\qquad P_0 = C^{-1}\,\Psi\,C^{-T},

    valable quand :math:`C` est carrée et inversible (alors :math:`\hat x_0 - x_0 = C^{-1}\psi_0` a bien
    la covariance :math:`P_0`). Le cours écrit :math:`\hat x_0 = y_0` et :math:`P_0 = \Psi`, ce qui n'est
    juste que pour :math:`C = I`. ``y0`` (m,) ; renvoie ``(x0_hat (n,), P0 (n, n))``.
    """
    model = _check_model(model)
    n, m = model.n_state, model.n_obs
    if n != m:
        raise KalmanInputError(
            f"Initialiser par une mesure exige une matrice C carrée inversible ; ici C est de forme ({m}, {n}) : "
            f"choisissez plutôt x0 a priori et une P0 grande."
        )
    y_arr = as_vector("y0", y0, m)
    cond = np.linalg.cond(model.C)
    if not np.isfinite(cond) or cond > 1e12:
        raise KalmanInputError(
            f"« C » est (numériquement) singulière (conditionnement {number_text(cond, '.3g')}) : impossible d'initialiser "
            f"l'état par C⁻¹ y0."
        )
    C_inv = scipy.linalg.inv(model.C)
    P0 = C_inv @ model.R @ C_inv.T
    return scipy.linalg.solve(model.C, y_arr), 0.5 * (P0 + P0.T)
