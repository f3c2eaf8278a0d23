r"""Filtre de Kalman étendu itéré : prédiction de l'EKF, correction de Gauss–Newton sur le coût MAP
(Bell & Cathey, 1993).

La boucle de Gauss–Newton est celle de :mod:`kalman_course.filters.iteration` (la même que l'EKF itéré
sur SE(3) et que les variantes des notes), avec l'espace des vecteurs (:math:`\oplus = +`).

:func:`iterated_extended_kalman_filter_runs` filtre ``N`` tirages à la fois (moteur en lot,
:func:`~kalman_course.filters.iteration.gauss_newton_update_many`) : chaque tirage itère et s'arrête
selon sa propre règle, comme s'il était seul.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
import scipy.linalg

from ..core.linalg import cholesky_factor
from ..core.models import NonlinearModel
from ..core.results import FilterResult, FilterRuns
from ..core.validation import KalmanInputError, as_float_array, as_gaussian, as_vector, shape_text
from .engine import (
    Correction,
    FilterFamily,
    gaussian_moments,
    gaussian_prior,
    gaussian_prior_many,
    run_filter,
    run_filter_runs,
)
from .extended import (
    NONLINEAR_HINT,
    check_model,
    linearize_observation,
    linearize_observations,
    predict_moments,
    predict_moments_many,
)
from .gaussian import measurement_noises
from .iteration import (
    DEFAULT_MAX_ITER,
    DEFAULT_TOL,
    VECTOR_SPACE,
    IteratedCorrection,
    check_iterations,
    gauss_newton_update,
    gauss_newton_update_many,
)

__all__ = [
    "IteratedUpdate",
    "iekf_update",
    "map_cost",
    "map_costs",
    "iterated_extended_kalman_filter",
    "iterated_extended_kalman_filter_runs",
    "iterated_family",
]


class IteratedUpdate(NamedTuple):
    r"""Résultat de :func:`iekf_update`.

    ``x`` (n,) : dernier itéré :math:`x^{(N)}` ; ``P`` (n, n) : :math:`(I - K_{N-1}H_{N-1})P^-` ;
    ``K`` (n, m) : gain de la dernière itération ; ``innovation`` (m,) et ``S`` (m, m) : innovation
    linéarisée et sa covariance à la dernière itération (voir :func:`iekf_update`) ;
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


def iekf_update(
    model: NonlinearModel,
    x_pred: Any,
    P_pred: Any,
    y: Any,
    *,
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
    itérations dans les exemples du cours (pas de recherche linéaire). La boucle et sa règle d'arrêt sont
    celles de :mod:`kalman_course.filters.iteration`, communes à tous les filtres itérés.

    ``innovation`` et ``S`` viennent de la **dernière linéarisation**, au point :math:`x^{(N-1)}` :
    :math:`\nu = y - h(x^{(N-1)}) - H_{N-1}(\hat x^- - x^{(N-1)})`, :math:`S = H_{N-1}P^-H_{N-1}^T + R`,
    avec le gain ``K`` de la même itération, de sorte que :math:`x^{(N)} = \hat x^- + K\nu` et que la NIS
    :math:`\nu^TS^{-1}\nu` est celle du filtre linéarisé en ce point (pour une itération : celle de l'EKF).
    Renvoie :class:`IteratedUpdate` (avec ``n_iter`` et la suite des itérés).
    """
    model = check_model(model)
    max_iter, tol = check_iterations(max_iter, tol)
    x_arr, P_arr = as_gaussian(x_pred, P_pred, model.n_state, "x_pred", "P_pred")
    y_arr = as_vector("y", y, model.n_obs)
    c = _iterated_correct(model, x_arr, P_arr, y_arr, None, joseph, max_iter, tol)
    return IteratedUpdate(c.x, c.P, c.K, c.innovation, c.S, c.n_iter, c.iterates, c.converged)


def map_cost(model: NonlinearModel, x: Any, x_pred: Any, P_pred: Any, y: Any) -> float:
    r"""Coût MAP de la correction, que l'EKF itéré minimise :

    .. math::

        J(x) = \tfrac12 (x - \hat x^-)^T (P^-)^{-1} (x - \hat x^-)
             + \tfrac12 \big(y - h(x)\big)^T R^{-1} \big(y - h(x)\big)

    (:math:`R` devient :math:`VRV^T` évaluée en :math:`\hat x^-` ; résidus angulaires ramenés dans
    :math:`(-\pi,\pi]`). ``P_pred`` doit être définie positive. Renvoie un ``float``.
    """
    model = check_model(model)
    n = model.n_state
    x_arr = as_vector("x", x, n)
    xp, Pp = as_gaussian(x_pred, P_pred, n, "x_pred", "P_pred")
    y_arr = as_vector("y", y, model.n_obs)
    cP = (cholesky_factor(Pp, "P_pred", "définie positive pour évaluer le coût MAP"), True)
    cR = (cholesky_factor(model.measurement_noise(xp), "R", "définie positive"), True)
    d = x_arr - xp
    r = model.residual(y_arr, model.observe(x_arr))
    return float(0.5 * d.dot(scipy.linalg.cho_solve(cP, d)) + 0.5 * r.dot(scipy.linalg.cho_solve(cR, r)))


def map_costs(model: NonlinearModel, X: Any, x_pred: Any, P_pred: Any, y: Any) -> np.ndarray:
    r"""Le coût MAP :math:`J(x)` de :func:`map_cost` en ``N`` points à la fois (une grille pour des
    courbes de niveau) : ``X`` (N, n) ; renvoie (N,). Les vérifications et les factorisations de
    Cholesky de :math:`P^-` et :math:`R` sont faites une fois ; :math:`h` est appelée une fois sur la
    pile si le modèle est vectorisé (``vectorized=True``), sinon point par point."""
    model = check_model(model)
    n = model.n_state
    X_arr = as_float_array("X", X)
    if X_arr.ndim != 2 or X_arr.shape[1] != n:
        raise KalmanInputError(f"« X » doit être de forme (N, {n}) : un point par ligne ; reçu {shape_text(X_arr.shape)}.")
    xp, Pp = as_gaussian(x_pred, P_pred, n, "x_pred", "P_pred")
    y_arr = as_vector("y", y, model.n_obs)
    cP = (cholesky_factor(Pp, "P_pred", "définie positive pour évaluer le coût MAP"), True)
    cR = (cholesky_factor(model.measurement_noise(xp), "R", "définie positive"), True)
    D = (X_arr - xp).T  # (n, N)
    Rr = model.residual(y_arr[:, None], model.observe_many(X_arr).T)  # (m, N), angles ramenés
    return (0.5 * np.sum(D * scipy.linalg.cho_solve(cP, D), axis=0)
            + 0.5 * np.sum(Rr * scipy.linalg.cho_solve(cR, Rr), axis=0))


# --------------------------------------------------------------------------- boucle


def iterated_extended_kalman_filter(
    model: NonlinearModel,
    y: Any,
    x0: Any,
    P0: Any,
    u: Any = None,
    *,
    max_iter: int = DEFAULT_MAX_ITER,
    tol: float = DEFAULT_TOL,
    joseph: bool = False,
) -> FilterResult:
    r"""Filtre de Kalman étendu itéré : prédiction de l'EKF, correction de Gauss–Newton (:func:`iekf_update`).

    Mêmes paramètres que :func:`extended_kalman_filter`, plus ``max_iter`` (≥ 1) et ``tol`` (seuil sur
    :math:`\lVert x^{(i+1)}-x^{(i)}\rVert`). ``result.n_iter`` (T,) donne le nombre d'itérations à chaque
    pas ; ``max_iter=1`` redonne exactement l'EKF.
    """
    return run_filter(iterated_family(max_iter, tol, joseph), model, y, x0, P0, u)


def iterated_extended_kalman_filter_runs(
    model: NonlinearModel,
    Y: Any,
    x0: Any,
    P0: Any,
    u: Any = None,
    *,
    max_iter: int = DEFAULT_MAX_ITER,
    tol: float = DEFAULT_TOL,
    joseph: bool = False,
) -> FilterRuns:
    r"""EKF itéré sur ``N`` tirages indépendants du même modèle, tous à la fois
    (:func:`~kalman_course.filters.engine.run_filter_runs`).

    Mêmes paramètres que :func:`~kalman_course.filters.extended.extended_kalman_filter_runs` (``Y``
    (N, T, m), ``x0`` (n,) ou (N, n), ``P0`` (n, n) ou (N, n, n), ``u`` (T, p) commune), plus ``max_iter``
    et ``tol``. À chaque pas, la correction de Gauss–Newton itère sur la pile des tirages ; chacun s'arrête
    par la règle de :func:`iterated_extended_kalman_filter` (:math:`\lVert x^{(i+1)} - x^{(i)}\rVert \le`
    ``tol`` ou ``max_iter`` itérations), les tirages arrêtés restant figés pendant que les autres itèrent.
    ``result.n_iter`` (N, T) ; ``result.run(i)`` est égal à ``iterated_extended_kalman_filter(model, Y[i], …)``
    aux arrondis près.
    """
    return run_filter_runs(iterated_family(max_iter, tol, joseph), model, Y, x0, P0, u)


def _iterated_correct_many(model, X_pred, P_pred, Y, idx, joseph, max_iter, tol, k):
    R = measurement_noises(model, X_pred, idx)  # évaluée en x̂⁻, comme pour un seul tirage

    def linearize(X_a, runs):
        r, H = linearize_observations(model, X_a, Y[runs], idx)
        return r, H, (R if R.ndim == 2 else R[runs])

    return gauss_newton_update_many(X_pred, P_pred, linearize, max_iter, tol, joseph, f"correction par y[{k}]")


def _iterated_correct(model, x_pred, P_pred, y, idx, joseph, max_iter, tol) -> IteratedCorrection:
    R = model.measurement_noise(x_pred)
    if idx is not None:
        R = R[np.ix_(idx, idx)]

    def linearize(x_i):
        r, H, _ = linearize_observation(model, x_i, y, idx)
        return r, H, R

    return gauss_newton_update(x_pred, P_pred, linearize, VECTOR_SPACE, max_iter, tol, joseph)


def iterated_family(max_iter: int = DEFAULT_MAX_ITER, tol: float = DEFAULT_TOL, joseph: bool = False) -> FilterFamily:
    r"""Les étapes de l'EKF itéré pour le moteur : prédiction de l'EKF, correction de Gauss–Newton."""
    max_iter, tol = check_iterations(max_iter, tol)

    def predict_step(model, state, u):
        return predict_moments(model, *state, u)

    def update_step(model, state, y, idx):
        c = _iterated_correct(model, *state, y, idx, joseph, max_iter, tol)
        return (c.x, c.P), Correction(c.K, c.innovation, c.S, c.n_iter)

    def predict_many(model, state, u, k):
        return predict_moments_many(model, *state, u)

    def update_many(model, state, Y, idx, k):
        c = _iterated_correct_many(model, *state, Y, idx, joseph, max_iter, tol, k)
        return (c.x, c.P), Correction(c.K, c.innovation, c.S, c.n_iter)

    return FilterFamily(
        name="filtre de Kalman étendu itéré",
        model_type=NonlinearModel,
        model_hint=NONLINEAR_HINT,
        prior=gaussian_prior,
        predict=predict_step,
        update=update_step,
        moments=gaussian_moments,
        prior_many=gaussian_prior_many,
        predict_many=predict_many,
        update_many=update_many,
    )
