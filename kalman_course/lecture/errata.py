r"""Les formules **fausses** du support de cours (document 001), recopiées telles qu'imprimées.

Ce module n'est là que pour montrer et tester les errata : aucun filtre du paquet ne l'utilise. Chaque
fonction cite la ligne du support et l'identifiant d'erratum de ``ALGORITHMS.md`` §6.2 ; la forme
correcte est ailleurs dans le paquet (:func:`kalman_course.filters.kalman.recipe_step`,
:func:`kalman_course.lecture.estimator.error_transition`,
:func:`kalman_course.lecture.estimator.measurement_initialisation`).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.linalg

from .estimator import spectral_radius
from ..core.models import LinearGaussianModel
from ..core.results import FilterResult
from ..core.validation import (
    KalmanInputError,
    as_matrix,
    as_measurements,
    as_square_matrix,
    as_vector,
    check_psd,
    check_instance,
)

__all__ = [
    "printed_gain_from_P",
    "printed_initialisation",
    "printed_recipe_filter",
    "printed_recipe_gain",
    "printed_stability_radius",
]


def _check_square_observation(model: LinearGaussianModel, formula: str) -> None:
    check_instance("model", model, LinearGaussianModel)
    n, m = model.n_state, model.n_obs
    if n != m:
        raise KalmanInputError(
            f"La formule imprimée {formula} additionne une matrice ({n}, {n}) et Ψ de forme ({m}, {m}) : "
            f"elle n'a de sens (dimensionnel) que si dim y = dim x."
        )


def printed_recipe_gain(model: LinearGaussianModel, P: Any) -> np.ndarray:
    r"""Gain de la « recette de cuisine » **tel qu'imprimé** (ligne 293, erratum 001-7) :

    .. math:: K_{n+1} = (AP_nA^T + \Psi)C^T\,(CAP_nA^TC^T + C\Psi C^T + \Psi)^{-1}.

    Deux :math:`\Psi` occupent la place de :math:`\Phi`. La formule n'est définie que si
    :math:`\dim y = \dim x` (sinon :class:`KalmanInputError`) ; dans l'exemple scalaire de la tension
    constante, elle tend vers :math:`1/2` au lieu du gain de Kalman. ``P`` (n, n) ; renvoie (n, m).
    """
    _check_square_observation(model, "« (A P Aᵀ + Ψ) Cᵀ (C A P Aᵀ Cᵀ + C Ψ Cᵀ + Ψ)⁻¹ »")
    n = model.n_state
    P_arr = check_psd("P", as_square_matrix("P", P, n))
    A, C, Psi = model.A, model.C, model.R
    M = A @ P_arr @ A.T + Psi
    S = C @ A @ P_arr @ A.T @ C.T + C @ Psi @ C.T + Psi
    return scipy.linalg.solve(S.T, (M @ C.T).T).T


def printed_gain_from_P(model: LinearGaussianModel, P: Any) -> np.ndarray:
    r"""« Formule de :math:`K` à partir de :math:`P` » **telle qu'imprimée** (ligne 346, erratum 001-12),
    lue comme un gain (le support écrit :math:`P_{n+1}` à gauche et :math:`P_{nn}`) :

    .. math:: (AP_nA^T + \Psi)C^T\,(CAP_nA^TC^T + C\Phi C^T + \Psi)^{-1}.

    Le premier :math:`\Psi` devrait être :math:`\Phi`. ``P`` (n, n) ; renvoie (n, m).
    """
    _check_square_observation(model, "« (A P Aᵀ + Ψ) Cᵀ (C A P Aᵀ Cᵀ + C Φ Cᵀ + Ψ)⁻¹ »")
    n = model.n_state
    P_arr = check_psd("P", as_square_matrix("P", P, n))
    A, C, Phi, Psi = model.A, model.C, model.Q, model.R
    M = A @ P_arr @ A.T + Psi
    S = C @ A @ P_arr @ A.T @ C.T + C @ Phi @ C.T + Psi
    return scipy.linalg.solve(S.T, (M @ C.T).T).T


def printed_recipe_filter(model: LinearGaussianModel, y: Any, x0: Any, P0: Any) -> FilterResult:
    r"""La recette du cours exécutée avec le gain **imprimé** (:func:`printed_recipe_gain`, erratum 001-7),
    les étapes 4 et 5 étant celles du cours (avec :math:`P_n` à la place du :math:`P` de la ligne 299,
    erratum 001-8) :

    .. math::

        \hat x_{n+1} = A\hat x_n + K_{n+1}[y_{n+1} - CA\hat x_n],\qquad
        P_{n+1} = (I - K_{n+1}C)(AP_nA^T + \Phi).

    Sans commande. ``y`` (T, m) ; renvoie un :class:`~kalman_course.core.results.FilterResult` (``S`` y est le
    dénominateur imprimé :math:`CAP_nA^TC^T + C\Psi C^T + \Psi`).
    """
    _check_square_observation(model, "de la recette")
    n, m = model.n_state, model.n_obs
    Y = as_measurements("y", y, m)
    if np.isnan(Y).any():
        raise KalmanInputError("« y » contient des mesures manquantes (NaN) : la recette imprimée les refuse.")
    x = as_vector("x0", x0, n)
    P = check_psd("P0", as_square_matrix("P0", P0, n))
    A, C, Phi, Psi = model.A, model.C, model.Q, model.R
    T = Y.shape[0]
    out = {k: [] for k in ("x", "P", "x_pred", "P_pred", "K", "innovation", "S")}
    for k in range(T):
        K = printed_recipe_gain(model, P)
        x_pred = A @ x
        P_pred = A @ P @ A.T + Phi
        nu = Y[k] - C @ x_pred
        S = C @ A @ P @ A.T @ C.T + C @ Psi @ C.T + Psi
        x = x_pred + K @ nu
        P = (np.eye(n) - K @ C) @ P_pred
        for key, val in zip(out, (x, P, x_pred, P_pred, K, nu, S)):
            out[key].append(val)
    return FilterResult(**{k: np.array(v) for k, v in out.items()}, observed=np.ones((T, m), dtype=bool))


def printed_stability_radius(model: LinearGaussianModel, K: Any) -> float:
    r"""La condition de stabilité **telle qu'imprimée** (lignes 110 et 123, erratum 001-3) :
    rayon spectral de :math:`I - KC`, alors que l'erreur moyenne est propagée par :math:`(I - KC)A`
    (voir :func:`kalman_course.lecture.estimator.error_transition`). ``K`` (n, m)."""
    check_instance("model", model, LinearGaussianModel)
    K_arr = as_matrix("K", K, model.n_state, model.n_obs)
    return spectral_radius(np.eye(model.n_state) - K_arr @ model.C)


def printed_initialisation(model: LinearGaussianModel, y0: Any):
    r"""L'initialisation **telle qu'imprimée** (lignes 288–290, errata 001-5 et 001-6) :
    :math:`\hat x_0 = y_0` et :math:`P_0 = \Psi`. Juste seulement si :math:`C = I` ; la forme correcte
    est :func:`kalman_course.lecture.estimator.measurement_initialisation`. Renvoie ``(x0_hat, P0)``."""
    _check_square_observation(model, "« x̂₀ = y₀, P₀ = Ψ »")
    y_arr = as_vector("y0", y0, model.n_obs)
    return y_arr.copy(), np.array(model.R)
