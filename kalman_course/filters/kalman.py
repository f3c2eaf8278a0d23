r"""Filtre de Kalman linéaire : étapes pures ``predict`` / ``update`` et une boucle ``kalman_filter``.

Notations (cours → paquet) : :math:`A, B, C` identiques, :math:`\Phi \to Q`, :math:`\Psi \to R`,
:math:`\hat x^-_{n+1} \to` ``x_pred``, :math:`\hat x_{n+1} \to` ``x``.

Les étapes publiques vérifient leurs entrées ; la boucle les vérifie une fois puis appelle les noyaux
internes (mêmes formules, sans vérification répétée).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
import scipy.linalg

from ..core.linalg import S_NOT_PD, correct, kalman_gain, symmetrize
from ..core.models import LinearGaussianModel
from ..core.results import FilterResult, FilterRuns
from ..core.validation import (
    as_batch_measurements,
    as_batch_vector,
    KalmanInputError,
    as_float_array,
    as_gaussian,
    as_square_matrix,
    as_vector,
    check_control_allowed,
    check_instance,
    check_psd,
    shape_text,
)
from .engine import Correction, FilterFamily, gaussian_moments, gaussian_prior, run_filter

__all__ = [
    "Prediction", "Update", "predict", "update", "kalman_filter", "kalman_family", "kalman_filter_runs", "recipe_step",
]


class Prediction(NamedTuple):
    r"""Résultat de :func:`predict` : :math:`\hat x_{k\mid k-1}` (n,) et :math:`P_{k\mid k-1}` (n, n)."""

    x: np.ndarray
    P: np.ndarray


class Update(NamedTuple):
    r"""Résultat de :func:`update`.

    ``x`` (n,), ``P`` (n, n) : estimation a posteriori ; ``K`` (n, m) : gain ;
    ``innovation`` (m,) : :math:`\nu = y - C\hat x^-` ; ``S`` (m, m) : covariance d'innovation.
    """

    x: np.ndarray
    P: np.ndarray
    K: np.ndarray
    innovation: np.ndarray
    S: np.ndarray


# --------------------------------------------------------------------------- noyaux internes


def _predict(x: np.ndarray, P: np.ndarray, A: np.ndarray, Q: np.ndarray, Bu: np.ndarray | None):
    # ``A.dot(P)`` plutôt que ``A @ P`` : même calcul, trois fois moins de surcoût par appel sur de
    # petites matrices (voir benchmarks/).
    x_pred = A.dot(x)
    if Bu is not None:
        x_pred += Bu
    return x_pred, symmetrize(A.dot(P).dot(A.T) + Q)


def _check_state(x: Any, P: Any, n: int, x_name: str, P_name: str):
    return as_gaussian(x, P, n, x_name, P_name)


def _control_term(model: LinearGaussianModel, u: Any) -> np.ndarray | None:
    if u is None:
        return None
    check_control_allowed("u", model.n_control)
    return model.B @ as_vector("u", u, model.n_control)


# --------------------------------------------------------------------------- étapes publiques


def predict(model: LinearGaussianModel, x: Any, P: Any, u: Any = None) -> Prediction:
    r"""Étape de prédiction (*time update*).

    .. math::

        \hat x_{k\mid k-1} = A\,\hat x_{k-1\mid k-1} + B\,u_{k-1},\qquad
        P_{k\mid k-1} = A\,P_{k-1\mid k-1}A^T + Q

    Paramètres : ``x`` (n,), ``P`` (n, n) symétrique semi-définie positive, ``u`` (p,) ou ``None``.
    """
    x_arr, P_arr = _check_state(x, P, model.n_state, "x", "P")
    x_pred, P_pred = _predict(x_arr, P_arr, model.A, model.Q, _control_term(model, u))
    return Prediction(x_pred, P_pred)


def update(model: LinearGaussianModel, x_pred: Any, P_pred: Any, y: Any, joseph: bool = False) -> Update:
    r"""Étape de correction (*measurement update*).

    .. math::

        \nu_k = y_k - C\hat x_{k\mid k-1},\quad S_k = C P_{k\mid k-1} C^T + R,\quad
        K_k = P_{k\mid k-1} C^T S_k^{-1},

        \hat x_{k\mid k} = \hat x_{k\mid k-1} + K_k\nu_k,\qquad
        P_{k\mid k} = (I - K_kC)\,P_{k\mid k-1}

    ``S`` n'est jamais inversée : :math:`K` est obtenu en résolvant :math:`S K^T = C P^-` par Cholesky
    (LAPACK ``posv``) ; une ``S`` non définie positive lève une :class:`KalmanInputError`.

    Par défaut (``joseph=False``), la covariance a posteriori suit la forme du cours
    :math:`P = (I - KC)P^-`, calculée comme :math:`P^- - K(P^-C^T)^T` puis symétrisée : c'est la formule
    enseignée et la moins coûteuse, exacte pour le gain optimal. ``joseph=True`` utilise la forme de Joseph

    .. math:: P_{k\mid k} = (I - K_kC)P_{k\mid k-1}(I-K_kC)^T + K_kRK_k^T,

    somme de termes semi-définis positifs, valable pour n'importe quel gain et plus robuste aux arrondis
    quand :math:`P` est mal conditionnée (c'est la forme de filterpy) ; elle coûte environ 30 % de plus.

    Paramètres : ``x_pred`` (n,), ``P_pred`` (n, n), ``y`` (m,) (scalaire accepté si m = 1).
    """
    x_arr, P_arr = _check_state(x_pred, P_pred, model.n_state, "x_pred", "P_pred")
    y_arr = as_vector("y", y, model.n_obs)
    nu = y_arr - model.C @ x_arr
    x, P, K, S = correct(x_arr, P_arr, nu, model.C, model.R, joseph)
    return Update(x, P, K, nu, S)


def recipe_step(model: LinearGaussianModel, x: Any, P: Any, y: Any, u: Any = None):
    r"""La « recette de cuisine » du cours en une ligne, **corrigée** (erratum 001-7).

    .. math::

        K_{n+1} = (AP_nA^T+\Phi)C^T\,\big[C(AP_nA^T+\Phi)C^T+\Psi\big]^{-1}

        \hat x_{n+1} = A\hat x_n + Bu_n + K_{n+1}\big[y_{n+1} - C(A\hat x_n + Bu_n)\big]

        P_{n+1} = (I - K_{n+1}C)(AP_nA^T + \Phi)

    Écrite indépendamment de :func:`predict`/:func:`update` (résolution par ``scipy.linalg.solve``)
    pour les vérifier l'une par l'autre. Renvoie ``(x, P, K)``.
    """
    x_arr, P_arr = _check_state(x, P, model.n_state, "x", "P")
    y_arr = as_vector("y", y, model.n_obs)
    A, C, Phi, Psi = model.A, model.C, model.Q, model.R
    Bu = _control_term(model, u)
    x_model = A @ x_arr + (0.0 if Bu is None else Bu)
    M = A @ P_arr @ A.T + Phi
    K = scipy.linalg.solve(C @ M @ C.T + Psi, C @ M.T, assume_a="pos").T
    x_new = x_model + K @ (y_arr - C @ x_model)
    P_new = (np.eye(model.n_state) - K @ C) @ M
    return x_new, P_new, K


# --------------------------------------------------------------------------- boucle


def kalman_filter(
    model: LinearGaussianModel,
    y: Any,
    x0: Any,
    P0: Any,
    u: Any = None,
    joseph: bool = False,
) -> FilterResult:
    r"""Filtre de Kalman sur toutes les mesures : pour chaque ``y[k]``, prédiction puis correction.

    L'ordre est celui du cours (:math:`\hat x_n \to \hat x^-_{n+1} \to \hat x_{n+1}`) et de la boucle
    ``predict()``/``update()`` de filterpy : la ligne ``k`` du résultat est l'estimation après la
    mesure ``y[k]``, la prédiction utilisant la commande ``u[k]``.

    Paramètres
    ----------
    model : LinearGaussianModel
    y : (T, m), ou (T,) si m = 1
        Mesures. ``None`` ou ``NaN`` : mesure manquante, le pas se réduit à la prédiction
        (gain nul). Une ligne partiellement manquante n'utilise que ses composantes présentes.
    x0 : (n,) — :math:`\hat x_0` (scalaire accepté si n = 1).
    P0 : (n, n) — :math:`P_0`, symétrique semi-définie positive (scalaire accepté si n = 1).
    u : (T, p), ou (T,) si p = 1, optionnel — commandes (exige un modèle avec ``B``).
    joseph : bool — forme de Joseph pour la covariance a posteriori (``False`` par défaut : forme du
        cours ; voir :func:`update`).

    Renvoie
    -------
    FilterResult
        ``x`` (T, n), ``P`` (T, n, n), ``x_pred``, ``P_pred``, ``K`` (T, n, m), ``innovation`` (T, m),
        ``S`` (T, m, m), ``observed`` (T, m).
    """
    return run_filter(kalman_family(joseph), model, y, x0, P0, u)


def kalman_family(joseph: bool = False) -> FilterFamily:
    r"""Les étapes du filtre de Kalman linéaire pour le moteur :func:`~kalman_course.filters.engine.run_filter`
    (état interne :math:`(\hat x, P)`)."""

    def predict_step(model: LinearGaussianModel, state, u):
        x, P = state
        return _predict(x, P, model.A, model.Q, None if u is None else model.B.dot(u))

    def update_step(model: LinearGaussianModel, state, y, idx):
        x_pred, P_pred = state
        if idx is None:
            C, R = model.C, model.R
        else:
            C, R = model.C[idx], model.R[np.ix_(idx, idx)]
        nu = y - C.dot(x_pred)
        x, P, K, S = correct(x_pred, P_pred, nu, C, R, joseph)
        return (x, P), Correction(K, nu, S)

    return FilterFamily(
        name="filtre de Kalman",
        model_type=LinearGaussianModel,
        model_hint="pour un modèle non linéaire, utilisez extended_kalman_filter",
        prior=gaussian_prior,
        predict=predict_step,
        update=update_step,
        moments=gaussian_moments,
    )


# --------------------------------------------------------------------------- tirages en lot


def kalman_filter_runs(
    model: LinearGaussianModel,
    Y: Any,
    x0: Any,
    P0: Any,
    u: Any = None,
    joseph: bool = False,
) -> FilterRuns:
    r"""Filtre de Kalman sur ``N`` tirages à la fois (mêmes équations que :func:`kalman_filter`).

    Sans mesure manquante, la récurrence des covariances :math:`P_{k\mid k-1}, S_k, K_k, P_{k\mid k}` ne
    dépend pas des mesures : elle est calculée **une fois** pour tous les tirages, et seule la moyenne est
    propagée en lot, :math:`\hat X_{k\mid k-1} = \hat X_{k-1\mid k-1}A^T + (Bu_{k-1})^T`,
    :math:`\hat X_{k\mid k} = \hat X_{k\mid k-1} + (Y_k - \hat X_{k\mid k-1}C^T)K_k^T` (une ligne par
    tirage). Avec des mesures manquantes (``NaN``, tirage par tirage), chaque tirage garde sa covariance ;
    à chaque pas, les tirages qui ont le même motif de composantes observées sont corrigés ensemble.

    Paramètres
    ----------
    model : LinearGaussianModel
    Y : (N, T, m), ou (N, T) si m = 1 — mesures des ``N`` tirages ; ``NaN`` : composante manquante.
    x0 : (n,) commun (scalaire si n = 1), ou (N, n) un par tirage. P0 : (n, n) commun.
    u : (T, p) commun, ou (N, T, p), optionnel.
    joseph : forme de Joseph pour la covariance a posteriori.

    Renvoie un :class:`~kalman_course.core.results.FilterRuns` : ``x`` (N, T, n), ``innovation``
    (N, T, m)… et ``P``, ``P_pred``, ``K``, ``S`` de forme (T, …) s'ils sont communs (aucune mesure
    manquante), (N, T, …) sinon. Chaque tirage est égal à :func:`kalman_filter` sur ses mesures.
    """
    model = check_instance("model", model, LinearGaussianModel, "pour un modèle non linéaire, bouclez sur extended_kalman_filter")
    n, m = model.n_state, model.n_obs
    Yarr = as_batch_measurements("Y", Y, m)
    N, T, _ = Yarr.shape
    X0 = as_batch_vector("x0", x0, n, N)
    P = check_psd("P0", as_square_matrix("P0", P0, n))
    BU = _batch_controls(model, u, N, T)  # None, (T, n) ou (N, T, n)
    observed = ~np.isnan(Yarr)
    A, C, Q, R = model.A, model.C, model.Q, model.R

    X = X0
    xs, xps = np.empty((N, T, n)), np.empty((N, T, n))
    nus = np.full((N, T, m), np.nan)
    if observed.all():
        Ps, Pps, Ks, Ss = np.empty((T, n, n)), np.empty((T, n, n)), np.empty((T, n, m)), np.empty((T, m, m))
        for k in range(T):
            Xp = X.dot(A.T)
            if BU is not None:
                Xp += BU[..., k, :]
            P_pred = symmetrize(A.dot(P).dot(A.T) + Q)
            K, S, PCt = kalman_gain(P_pred, C, R, f"au pas {k}")
            nu = Yarr[:, k] - Xp.dot(C.T)
            X = Xp + nu.dot(K.T)
            if joseph:
                IKC = np.eye(n) - K.dot(C)
                P = symmetrize(IKC.dot(P_pred).dot(IKC.T) + K.dot(R).dot(K.T))
            else:
                P = symmetrize(P_pred - K.dot(PCt.T))
            xps[:, k], xs[:, k], nus[:, k] = Xp, X, nu
            Pps[k], Ps[k], Ks[k], Ss[k] = P_pred, P, K, S
        n_iter = np.ones((N, T), dtype=int)
        return FilterRuns(x=xs, P=Ps, x_pred=xps, P_pred=Pps, K=Ks, innovation=nus, S=Ss,
                          observed=observed, n_iter=n_iter)

    Ps, Pps = np.empty((N, T, n, n)), np.empty((N, T, n, n))
    Ks, Ss = np.zeros((N, T, n, m)), np.full((N, T, m, m), np.nan)
    n_iter = np.zeros((N, T), dtype=int)
    Pr = np.broadcast_to(P, (N, n, n)).copy()
    for k in range(T):
        Xp = X.dot(A.T)
        if BU is not None:
            Xp += BU[..., k, :]
        Pp = symmetrize(A @ Pr @ A.T + Q)
        X, Pr = Xp.copy(), Pp.copy()
        patterns, group = np.unique(observed[:, k], axis=0, return_inverse=True)
        for g, pattern in enumerate(patterns):
            if not pattern.any():
                continue
            runs = np.flatnonzero(group.ravel() == g)
            idx = np.flatnonzero(pattern)
            Ck, Rk = C[idx], R[np.ix_(idx, idx)]
            PCt = Pp[runs] @ Ck.T                                  # (g, n, q)
            S = Ck @ PCt + Rk                                      # (g, q, q)
            K = np.swapaxes(_batched_solve_pd(S, np.swapaxes(PCt, 1, 2), k), 1, 2)  # (g, n, q)
            nu = Yarr[runs, k][:, idx] - Xp[runs] @ Ck.T           # (g, q)
            X[runs] = Xp[runs] + np.einsum("gij,gj->gi", K, nu)
            if joseph:
                IKC = np.eye(n) - K @ Ck
                Pr[runs] = symmetrize(IKC @ Pp[runs] @ np.swapaxes(IKC, 1, 2) + K @ Rk @ np.swapaxes(K, 1, 2))
            else:
                Pr[runs] = symmetrize(Pp[runs] - K @ np.swapaxes(PCt, 1, 2))
            for j, r in enumerate(runs):
                Ks[r, k][:, idx] = K[j]
                Ss[r, k][np.ix_(idx, idx)] = S[j]
                nus[r, k, idx] = nu[j]
            n_iter[runs, k] = 1
        xps[:, k], xs[:, k], Pps[:, k], Ps[:, k] = Xp, X, Pp, Pr
    return FilterRuns(x=xs, P=Ps, x_pred=xps, P_pred=Pps, K=Ks, innovation=nus, S=Ss,
                      observed=observed, n_iter=n_iter)


def _batched_solve_pd(S: np.ndarray, B: np.ndarray, k: int) -> np.ndarray:
    """Résout :math:`S_j X_j = B_j` pour une pile de matrices définies positives (Cholesky)."""
    try:
        L = np.linalg.cholesky(S)
    except np.linalg.LinAlgError:
        raise KalmanInputError(f"{S_NOT_PD[:-1]} (au pas {k}).") from None
    Z = np.linalg.solve(L, B)
    return np.linalg.solve(np.swapaxes(L, 1, 2), Z)


def _batch_controls(model: LinearGaussianModel, u: Any, N: int, T: int) -> np.ndarray | None:
    """Termes :math:`Bu` : ``None``, (T, n) communs ou (N, T, n)."""
    if u is None:
        return None
    check_control_allowed("u", model.n_control)
    p = model.n_control
    U = as_float_array("u", u)
    if U.ndim == 1 and p == 1:
        U = U[:, None]
    if U.ndim == 2 and U.shape == (T, p):
        return U @ model.B.T
    if U.ndim == 3 and U.shape == (N, T, p):
        return U @ model.B.T
    raise KalmanInputError(
        f"« u » doit être de forme ({T}, {p}) (commune) ou ({N}, {T}, {p}) (une par tirage) ; reçu {shape_text(U.shape)}."
    )
