r"""Filtre de Kalman étendu (EKF) et filtre de Kalman étendu itéré (Gauss–Newton).

Notations (cours → paquet) : :math:`J^A \to F`, :math:`J^H \to H`, :math:`W`, :math:`V` (jacobiennes des
bruits), :math:`\Phi \to Q`, :math:`\Psi \to R`, :math:`\hat x^-_{n+1} \to` ``x_pred``.

* Prédiction : :math:`\hat x_{k\mid k-1} = f(\hat x_{k-1\mid k-1}, u_{k-1})`,
  :math:`P_{k\mid k-1} = F P_{k-1\mid k-1} F^T + W Q W^T`, :math:`F` et :math:`W` évaluées en
  :math:`(\hat x_{k-1\mid k-1}, u_{k-1})`.
* Correction : celle du filtre linéaire (:func:`kalman_course.kf._correct`, le même code) avec la
  jacobienne :math:`H` évaluée en :math:`\hat x_{k\mid k-1}` à la place de :math:`C`, l'innovation
  :math:`\nu_k = y_k - h(\hat x_{k\mid k-1})` (angles ramenés dans :math:`(-\pi,\pi]`) et
  :math:`V R V^T` à la place de :math:`R`.
* Correction itérée : Gauss–Newton sur le coût MAP (Bell & Cathey, 1993), voir :func:`iekf_update`.

Ce module n'importe pas matplotlib.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
import scipy.linalg

from .kf import Prediction, Update, _check_state, _correct, _symmetrize
from .models import NonlinearModel
from .results import FilterHistory, FilterResult
from .validation import (
    KalmanInputError,
    as_controls,
    as_measurements,
    as_vector,
    check_control_allowed,
    check_instance,
)

__all__ = [
    "IteratedUpdate",
    "ekf_predict",
    "ekf_update",
    "iekf_update",
    "map_cost",
    "extended_kalman_filter",
    "iterated_extended_kalman_filter",
]

#: Nombre maximal d'itérations de Gauss–Newton par défaut.
DEFAULT_MAX_ITER = 20
#: Seuil d'arrêt par défaut sur :math:`\lVert x^{(i+1)} - x^{(i)}\rVert` (unités de l'état).
DEFAULT_TOL = 1e-10


class IteratedUpdate(NamedTuple):
    r"""Résultat de :func:`iekf_update`.

    ``x`` (n,) : dernier itéré :math:`x^{(N)}` ; ``P`` (n, n) : :math:`(I - K_{N-1}H_{N-1})P^-` ;
    ``K`` (n, m) : gain de la dernière itération ; ``innovation`` (m,) : :math:`y - h(\hat x^-)` (l'innovation
    de la prédiction, comme l'EKF) ; ``S`` (m, m) : :math:`H_{N-1}P^-H_{N-1}^T + R` ;
    ``n_iter`` : nombre :math:`N` d'itérations de Gauss–Newton ; ``iterates`` (N+1, n) :
    :math:`x^{(0)} = \hat x^-, x^{(1)}, \dots, x^{(N)}` ; ``converged`` : arrêt par le seuil ``tol``
    (et non par ``max_iter``).
    """

    x: np.ndarray
    P: np.ndarray
    K: np.ndarray
    innovation: np.ndarray
    S: np.ndarray
    n_iter: int
    iterates: np.ndarray
    converged: bool


# --------------------------------------------------------------------------- vérifications


def _check_model(model: Any) -> NonlinearModel:
    return check_instance(
        "model", model, NonlinearModel, "pour un modèle linéaire, utilisez kalman_filter ou NonlinearModel.from_linear"
    )


def _check_control(model: NonlinearModel, u: Any) -> np.ndarray | None:
    if u is None:
        return None
    check_control_allowed("u", model.n_control)
    return as_vector("u", u, model.n_control)


def _check_iterations(max_iter: Any, tol: Any) -> tuple[int, float]:
    if not isinstance(max_iter, (int, np.integer)) or isinstance(max_iter, bool) or max_iter < 1:
        raise KalmanInputError(f"« max_iter » doit être un entier ≥ 1 ; reçu {max_iter!r}.")
    try:
        tol_f = float(tol)
    except (TypeError, ValueError):
        tol_f = float("nan")
    if not tol_f >= 0 or not np.isfinite(tol_f):
        raise KalmanInputError(f"« tol » doit être un réel ≥ 0 ; reçu {tol!r}.")
    return int(max_iter), tol_f


# --------------------------------------------------------------------------- noyaux internes


def _predict(model: NonlinearModel, x: np.ndarray, P: np.ndarray, u: np.ndarray | None):
    """Prédiction de l'EKF ; renvoie ``(x_pred, P_pred)``."""
    F = model.transition_jacobian(x, u)
    x_pred = model.transition(x, u)
    P_pred = _symmetrize(F.dot(P).dot(F.T) + model.process_noise(x, u))
    return x_pred, P_pred


def _observed_parts(model: NonlinearModel, x: np.ndarray, y: np.ndarray, idx: np.ndarray | None):
    """Résidu :math:`y - h(x)` (angles ramenés), jacobienne :math:`H` et :math:`VRV^T` en ``x``,
    restreints aux composantes observées ``idx`` (``None`` : toutes)."""
    r = model.residual(y, model.observe(x))
    H = model.observation_jacobian(x)
    R = model.measurement_noise(x)
    if idx is None:
        return r, H, R
    return r[idx], H[idx], R[np.ix_(idx, idx)]


def _ekf_correct(model, x_pred, P_pred, y, idx, joseph):
    nu, H, R = _observed_parts(model, x_pred, y, idx)
    x, P, K, S = _correct(x_pred, P_pred, nu, H, R, joseph)
    return x, P, K, nu, S


def _iekf_correct(model, x_pred, P_pred, y, idx, joseph, max_iter, tol):
    r"""Gauss–Newton : :math:`x^{(i+1)} = \hat x^- + K_i\,[y - h(x^{(i)}) - H_i(\hat x^- - x^{(i)})]`."""
    R = model.measurement_noise(x_pred)
    if idx is not None:
        R = R[np.ix_(idx, idx)]
    x_i = x_pred
    iterates = [x_pred]
    converged = False
    nu0 = None
    for i in range(max_iter):
        r_i, H_i, _ = _observed_parts(model, x_i, y, idx)
        if nu0 is None:
            nu0 = r_i  # innovation de la prédiction (i = 0)
        # le terme −H_i(x⁻ − x_i) ramène la linéarisation de h au point x_i
        nu_i = r_i - H_i.dot(x_pred - x_i)
        x_next, P, K, S = _correct(x_pred, P_pred, nu_i, H_i, R, joseph)
        iterates.append(x_next)
        step = float(np.linalg.norm(x_next - x_i))
        x_i = x_next
        if step <= tol:
            converged = True
            break
    return x_i, P, K, nu0, S, len(iterates) - 1, np.array(iterates), converged


# --------------------------------------------------------------------------- étapes publiques


def ekf_predict(model: NonlinearModel, x: Any, P: Any, u: Any = None) -> Prediction:
    r"""Prédiction de l'EKF (notes du tag, étapes 1 à 3 ; cours : « on utilise directement f »).

    .. math::

        \hat x_{k\mid k-1} = f(\hat x_{k-1\mid k-1}, u_{k-1}),\qquad
        P_{k\mid k-1} = F_k P_{k-1\mid k-1} F_k^T + W Q W^T,\qquad
        F_k = \left.\frac{\partial f}{\partial x}\right|_{(\hat x_{k-1\mid k-1},\,u_{k-1})}

    Paramètres : ``x`` (n,), ``P`` (n, n) symétrique semi-définie positive, ``u`` (p,) ou ``None``.
    Renvoie :class:`~kalman_course.kf.Prediction` ``(x, P)``.
    """
    model = _check_model(model)
    x_arr, P_arr = _check_state(x, P, model.n_state, "x", "P")
    return Prediction(*_predict(model, x_arr, P_arr, _check_control(model, u)))


def ekf_update(model: NonlinearModel, x_pred: Any, P_pred: Any, y: Any, joseph: bool = False) -> Update:
    r"""Correction de l'EKF : la correction linéaire avec la jacobienne :math:`H_k` à la place de :math:`C`.

    .. math::

        \nu_k = y_k - h(\hat x_{k\mid k-1}),\quad
        H_k = \left.\frac{\partial h}{\partial x}\right|_{\hat x_{k\mid k-1}},\quad
        S_k = H_kP_{k\mid k-1}H_k^T + VRV^T,\quad K_k = P_{k\mid k-1}H_k^TS_k^{-1},

        \hat x_{k\mid k} = \hat x_{k\mid k-1} + K_k\nu_k,\qquad P_{k\mid k} = (I - K_kH_k)P_{k\mid k-1}

    Les composantes angulaires de :math:`\nu_k` (``model.angle_indices``) sont ramenées dans
    :math:`(-\pi, \pi]`. Paramètres : ``x_pred`` (n,), ``P_pred`` (n, n), ``y`` (m,).
    Renvoie :class:`~kalman_course.kf.Update` ``(x, P, K, innovation, S)``.
    """
    model = _check_model(model)
    x_arr, P_arr = _check_state(x_pred, P_pred, model.n_state, "x_pred", "P_pred")
    y_arr = as_vector("y", y, model.n_obs)
    return Update(*_ekf_correct(model, x_arr, P_arr, y_arr, None, joseph))


def iekf_update(
    model: NonlinearModel,
    x_pred: Any,
    P_pred: Any,
    y: Any,
    max_iter: int = DEFAULT_MAX_ITER,
    tol: float = DEFAULT_TOL,
    joseph: bool = False,
) -> IteratedUpdate:
    r"""Correction itérée (Gauss–Newton sur le coût MAP, Bell & Cathey 1993).

    Avec :math:`\hat x^- = \hat x_{k\mid k-1}`, :math:`P^- = P_{k\mid k-1}` et :math:`x^{(0)} = \hat x^-`,
    pour :math:`i = 0, 1, \dots` :

    .. math::

        H_i = \left.\frac{\partial h}{\partial x}\right|_{x^{(i)}},\quad
        K_i = P^-H_i^T(H_iP^-H_i^T + R)^{-1},\quad
        x^{(i+1)} = \hat x^- + K_i\big[y - h(x^{(i)}) - H_i(\hat x^- - x^{(i)})\big]

    arrêt quand :math:`\lVert x^{(i+1)} - x^{(i)}\rVert \le` ``tol`` ou après ``max_iter`` itérations ;
    puis :math:`P_{k\mid k} = (I - K_{N-1}H_{N-1})P^-`. Une seule itération (``max_iter=1``) est exactement
    l'EKF. Un point fixe annule le gradient du coût :func:`map_cost` :
    :math:`(P^-)^{-1}(x - \hat x^-) = H^TR^{-1}(y - h(x))`.

    Le pas de Gauss–Newton pur ne garantit pas la décroissance du coût ; il converge ici en quelques
    itérations dans les exemples du cours (pas de recherche linéaire).
    Renvoie :class:`IteratedUpdate` (avec ``n_iter`` et la suite des itérés).
    """
    model = _check_model(model)
    max_iter, tol = _check_iterations(max_iter, tol)
    x_arr, P_arr = _check_state(x_pred, P_pred, model.n_state, "x_pred", "P_pred")
    y_arr = as_vector("y", y, model.n_obs)
    return IteratedUpdate(*_iekf_correct(model, x_arr, P_arr, y_arr, None, joseph, max_iter, tol))


def map_cost(model: NonlinearModel, x: Any, x_pred: Any, P_pred: Any, y: Any) -> float:
    r"""Coût MAP de la correction, que l'EKF itéré minimise :

    .. math::

        J(x) = \tfrac12 (x - \hat x^-)^T (P^-)^{-1} (x - \hat x^-)
             + \tfrac12 \big(y - h(x)\big)^T R^{-1} \big(y - h(x)\big)

    (:math:`R` devient :math:`VRV^T` évaluée en :math:`\hat x^-` ; résidus angulaires ramenés dans
    :math:`(-\pi,\pi]`). ``P_pred`` doit être définie positive. Renvoie un ``float``.
    """
    model = _check_model(model)
    n = model.n_state
    x_arr = as_vector("x", x, n)
    xp, Pp = _check_state(x_pred, P_pred, n, "x_pred", "P_pred")
    y_arr = as_vector("y", y, model.n_obs)
    try:
        cP = scipy.linalg.cho_factor(Pp, lower=True)
    except np.linalg.LinAlgError:
        raise KalmanInputError("« P_pred » doit être définie positive pour évaluer le coût MAP.") from None
    cR = scipy.linalg.cho_factor(model.measurement_noise(xp), lower=True)
    d = x_arr - xp
    r = model.residual(y_arr, model.observe(x_arr))
    return float(0.5 * d.dot(scipy.linalg.cho_solve(cP, d)) + 0.5 * r.dot(scipy.linalg.cho_solve(cR, r)))


# --------------------------------------------------------------------------- boucles


def _run(model, y, x0, P0, u, correct) -> FilterResult:
    model = _check_model(model)
    n, m = model.n_state, model.n_obs
    Y = as_measurements("y", y, m)
    T = Y.shape[0]
    U = as_controls("u", u, T, model.n_control)
    x, P = _check_state(x0, P0, n, "x0", "P0")
    observed = ~np.isnan(Y)
    out = FilterHistory(T, n, m, observed, iterated=True)

    for k in range(T):
        x_pred, P_pred = _predict(model, x, P, None if U is None else U[k])
        if observed[k].any():
            idx = None if observed[k].all() else np.flatnonzero(observed[k])
            x, P, K, nu, S, out.n_iter[k] = correct(model, x_pred, P_pred, Y[k], idx)
            out.correction(k, K, nu, S, idx)
        else:
            x, P = x_pred, P_pred
        out.store(k, x_pred, P_pred, x, P)
    return out.result()


def extended_kalman_filter(
    model: NonlinearModel, y: Any, x0: Any, P0: Any, u: Any = None, joseph: bool = False
) -> FilterResult:
    r"""Filtre de Kalman étendu sur toutes les mesures (pour chaque ``y[k]`` : :func:`ekf_predict` puis
    :func:`ekf_update`), dans l'ordre de :func:`~kalman_course.kalman_filter`.

    Paramètres
    ----------
    model : NonlinearModel
    y : (T, m), ou (T,) si m = 1 — mesures ; ``NaN`` (ou ``None``) : composante manquante.
    x0 : (n,) — :math:`\hat x_0` ; P0 : (n, n) — :math:`P_0`.
    u : (T, p), ou (T,) si p = 1, optionnel — commandes (``u[k]`` sert à prédire vers ``y[k]``).
    joseph : forme de Joseph pour la covariance a posteriori.

    Renvoie un :class:`~kalman_course.FilterResult` (``n_iter`` vaut 1 à chaque pas observé, 0 sinon).
    """

    def correct(model, x_pred, P_pred, y_k, idx):
        x, P, K, nu, S = _ekf_correct(model, x_pred, P_pred, y_k, idx, joseph)
        return x, P, K, nu, S, 1

    return _run(model, y, x0, P0, u, correct)


def iterated_extended_kalman_filter(
    model: NonlinearModel,
    y: Any,
    x0: Any,
    P0: Any,
    u: Any = None,
    max_iter: int = DEFAULT_MAX_ITER,
    tol: float = DEFAULT_TOL,
    joseph: bool = False,
) -> FilterResult:
    r"""Filtre de Kalman étendu itéré : prédiction de l'EKF, correction de Gauss–Newton (:func:`iekf_update`).

    Mêmes paramètres que :func:`extended_kalman_filter`, plus ``max_iter`` (≥ 1) et ``tol`` (seuil sur
    :math:`\lVert x^{(i+1)}-x^{(i)}\rVert`). ``result.n_iter`` (T,) donne le nombre d'itérations à chaque
    pas ; ``max_iter=1`` redonne exactement l'EKF.
    """
    max_iter, tol = _check_iterations(max_iter, tol)

    def correct(model, x_pred, P_pred, y_k, idx):
        x, P, K, nu, S, N, _, _ = _iekf_correct(model, x_pred, P_pred, y_k, idx, joseph, max_iter, tol)
        return x, P, K, nu, S, N

    return _run(model, y, x0, P0, u, correct)
