r"""Méthodes variationnelles : 3D-Var et interpolation optimale — la correction de Kalman avec une
covariance d'ébauche :math:`B` **fixe**.

Le 3D-Var cherche l'état qui concilie l'ébauche :math:`x_b` (la prévision) et l'observation :math:`y`, en
minimisant

.. math::

    J(x) = \tfrac12 (x - x_b)^TB^{-1}(x - x_b) + \tfrac12 (y - Cx)^TR^{-1}(y - Cx).

Pour :math:`C` linéaire, :math:`J` est quadratique, de gradient
:math:`B^{-1}(x - x_b) - C^TR^{-1}(y - Cx)` ; il s'annule en

.. math::

    x_a = x_b + K(y - Cx_b),\qquad K = BC^T(CBC^T + R)^{-1},

la correction du filtre de Kalman avec :math:`P^- = B` (Lorenc 1986). Ce que le 3D-Var perd : :math:`B`
ne suit pas l'écoulement — ni la prévision de :math:`P` ni sa réduction par les observations passées ;
un centre de prévision l'estime une fois pour toutes (statistiques climatologiques), et l'inflate à la
main (``background_scale``).

* :func:`var3d_update` : une analyse (étape pure) ;
* :func:`three_dimensional_var` : le cycle d'assimilation, l'ébauche de chaque cycle étant la prévision
  de l'analyse précédente, :math:`x_b = f(x_a)` ;
* :func:`optimal_interpolation` : la même analyse depuis une ébauche **fixe** (la climatologie), sans
  prévision (l'``OptInterp`` de DAPPER).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..core.linalg import kalman_gain, symmetrize
from ..core.models import NonlinearModel
from ..core.results import FilterResult
from ..core.validation import (
    KalmanInputError,
    as_float_array,
    as_matrix,
    as_square_matrix,
    as_vector,
    check_instance,
    check_pd,
    check_psd,
    shape_text,
)
from .engine import Correction, FilterFamily, gaussian_moments, run_filter
from .extended import NONLINEAR_HINT

__all__ = ["var3d_update", "three_dimensional_var", "optimal_interpolation", "variational_family"]


def var3d_update(x_b: Any, y: Any, C: Any, B: Any, R: Any) -> np.ndarray:
    r"""L'analyse du 3D-Var : le minimiseur de
    :math:`J(x) = \tfrac12\|x - x_b\|^2_{B^{-1}} + \tfrac12\|y - Cx\|^2_{R^{-1}}`,

    .. math::

        x_a = x_b + BC^T(CBC^T + R)^{-1}(y - Cx_b).

    Paramètres
    ----------
    x_b : (n,) ébauche ; y : (m,) observation ; C : (m, n) matrice d'observation ;
    B : (n, n) covariance d'erreur d'ébauche, symétrique semi-définie positive ;
    R : (m, m) covariance d'erreur d'observation, définie positive.

    Renvoie :math:`x_a` (n,).
    """
    y = as_float_array("y", y)
    if y.ndim == 0:
        y = y.reshape(1)
    if y.ndim != 1:
        raise KalmanInputError(f"« y » doit être un vecteur (m,) ; reçu {shape_text(y.shape)}.")
    C = as_matrix("C", C, y.size, None, free_cols="n")
    n = C.shape[1]
    x_b = as_vector("x_b", x_b, n)
    B = check_psd("B", as_square_matrix("B", B, n))
    R = check_pd("R", as_square_matrix("R", R, y.size))
    K = kalman_gain(B, C, R, where="3D-Var : C B Cᵀ + R")[0]
    return x_b + K.dot(y - C.dot(x_b))


def variational_family(background: np.ndarray | None = None) -> FilterFamily:
    r"""Les étapes du 3D-Var pour le moteur ; ``background`` (n,) donné : l'interpolation optimale (ébauche
    fixe, aucune prévision). L'état interne est :math:`(x, P, B)` : l'analyse :math:`x_a` et
    :math:`(I - KH)B` après correction, l'ébauche :math:`x_b` et :math:`B` après prévision."""

    def prior(model, x0, B):
        n = model.n_state
        x = as_vector("x0" if background is None else "x_clim", x0, n)
        B = check_psd("B", as_square_matrix("B", B, n))
        return (x, B, B)

    def predict(model, state, u):
        B = state[2]
        if background is not None:
            return (background, B, B)
        return (model.transition(state[0], u), B, B)

    def update(model, state, y, idx):
        x_b, _, B = state
        H = model.observation_jacobian(x_b)
        R = model.measurement_noise(x_b)
        y_hat = model.observe(x_b)
        if idx is not None:
            H, R, y_hat = H[idx], R[np.ix_(idx, idx)], y_hat[idx]
        K, S, BHt = kalman_gain(B, H, R, where="3D-Var : H B Hᵀ + R")
        nu = model.residual(y, y_hat, idx)
        return (x_b + K.dot(nu), symmetrize(B - K.dot(BHt.T)), B), Correction(K, nu, S)

    return FilterFamily(
        name="3D-Var" if background is None else "interpolation optimale",
        model_type=NonlinearModel,
        model_hint=NONLINEAR_HINT,
        prior=prior,
        predict=predict,
        update=update,
        moments=gaussian_moments,
    )


def three_dimensional_var(model: NonlinearModel, y: Any, x0: Any, B: Any, u: Any = None) -> FilterResult:
    r"""Le 3D-Var cyclé : à chaque cycle, l'ébauche est la prévision de l'analyse précédente,
    :math:`x_b = f(x_a, u)` (:math:`x_0` d'abord), puis

    .. math::

        x_a = x_b + K\big(y_k - h(x_b)\big),\qquad K = BH^T(HBH^T + R)^{-1},\qquad H = \partial h/\partial x\,(x_b),

    avec la même covariance d'ébauche :math:`B` à chaque cycle (elle ne suit pas l'écoulement).

    Paramètres
    ----------
    model : NonlinearModel (``f``, ``h``, ``R`` ; ``Q`` n'est pas utilisée).
    y : (T, m) — ``NaN`` : composante manquante (ligne entière : prévision seule).
    x0 : (n,) état de départ ; B : (n, n) covariance d'ébauche, semi-définie positive.
    u : (T, p) optionnel — commandes.

    Renvoie un :class:`~kalman_course.FilterResult` : ``x`` les analyses, ``x_pred`` les ébauches,
    ``P`` :math:`(I - KH)B`, ``P_pred`` :math:`B`, ``K``, ``innovation`` :math:`y - h(x_b)`,
    ``S`` :math:`HBH^T + R`.
    """
    return run_filter(variational_family(), model, y, x0, B, u)


def optimal_interpolation(model: NonlinearModel, y: Any, x_clim: Any, B: Any) -> FilterResult:
    r"""L'interpolation optimale : l'analyse du 3D-Var à chaque pas depuis l'ébauche **fixe**
    :math:`x_b = x_{\mathrm{clim}}` (la climatologie), sans prévision (``OptInterp`` de DAPPER) :
    :math:`x_a = x_{\mathrm{clim}} + K(y_k - h(x_{\mathrm{clim}}))`.

    Paramètres
    ----------
    model : NonlinearModel (seuls ``h`` et ``R`` servent) ; y : (T, m) ; x_clim : (n,) ; B : (n, n).

    Renvoie un :class:`~kalman_course.FilterResult` (mêmes champs que :func:`three_dimensional_var` ;
    ``x_pred`` vaut :math:`x_{\mathrm{clim}}` à chaque pas).
    """
    check_instance("model", model, NonlinearModel, NONLINEAR_HINT)
    x_clim = as_vector("x_clim", x_clim, model.n_state)
    return run_filter(variational_family(background=x_clim), model, y, x_clim, B)
