r"""Filtre de Kalman étendu (EKF) : étapes pures et famille pour le moteur.

Notations (cours → paquet) : :math:`J^A \to F`, :math:`J^H \to H`, :math:`W`, :math:`V` (jacobiennes des
bruits), :math:`\Phi \to Q`, :math:`\Psi \to R`, :math:`\hat x^-_{n+1} \to` ``x_pred``.

* Prédiction : :math:`\hat x_{k\mid k-1} = f(\hat x_{k-1\mid k-1}, u_{k-1})`,
  :math:`P_{k\mid k-1} = F P_{k-1\mid k-1} F^T + W Q W^T`, :math:`F` et :math:`W` évaluées en
  :math:`(\hat x_{k-1\mid k-1}, u_{k-1})`.
* Correction : celle du filtre linéaire (:func:`kalman_course.core.linalg.correct`, le même code) avec la
  jacobienne :math:`H` évaluée en :math:`\hat x_{k\mid k-1}` à la place de :math:`C`, l'innovation
  :math:`\nu_k = y_k - h(\hat x_{k\mid k-1})` (angles ramenés dans :math:`(-\pi,\pi]`) et
  :math:`V R V^T` à la place de :math:`R`.

La correction itérée (Gauss–Newton) est dans :mod:`kalman_course.filters.iterated`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..core.linalg import correct, symmetrize
from ..core.models import NonlinearModel
from ..core.results import FilterResult
from ..core.validation import as_gaussian, as_vector, check_control_allowed, check_instance
from .engine import Correction, FilterFamily, gaussian_moments, gaussian_prior, run_filter
from .kalman import Prediction, Update

__all__ = ["ekf_predict", "ekf_update", "extended_kalman_filter", "extended_family"]

#: Piste donnée quand un filtre non linéaire reçoit un modèle linéaire.
NONLINEAR_HINT = "pour un modèle linéaire, utilisez kalman_filter ou NonlinearModel.from_linear"


# --------------------------------------------------------------------------- vérifications


def check_model(model: Any) -> NonlinearModel:
    """Le modèle d'un filtre non linéaire doit être un :class:`~kalman_course.NonlinearModel`."""
    return check_instance("model", model, NonlinearModel, NONLINEAR_HINT)


def check_control(model: NonlinearModel, u: Any) -> np.ndarray | None:
    """Une commande ``u`` (p,) pour ``model``, ou ``None``."""
    if u is None:
        return None
    check_control_allowed("u", model.n_control)
    return as_vector("u", u, model.n_control)


# --------------------------------------------------------------------------- noyaux internes


def predict_moments(model: NonlinearModel, x: np.ndarray, P: np.ndarray, u: np.ndarray | None):
    """Prédiction de l'EKF ; renvoie ``(x_pred, P_pred)``."""
    F = model.transition_jacobian(x, u)
    x_pred = model.transition(x, u)
    P_pred = symmetrize(F.dot(P).dot(F.T) + model.process_noise(x, u))
    return x_pred, P_pred


def linearize_observation(model: NonlinearModel, x: np.ndarray, y: np.ndarray, idx: np.ndarray | None):
    """Résidu :math:`y - h(x)` (angles ramenés), jacobienne :math:`H` et :math:`VRV^T` en ``x``,
    restreints aux composantes observées ``idx`` (``None`` : toutes ; ``y`` ne contient alors que ces
    composantes)."""
    h = model.observe(x)
    H = model.observation_jacobian(x)
    R = model.measurement_noise(x)
    if idx is not None:
        h, H, R = h[idx], H[idx], R[np.ix_(idx, idx)]
    return model.residual(y, h, idx), H, R


def _ekf_correct(model, x_pred, P_pred, y, idx, joseph):
    nu, H, R = linearize_observation(model, x_pred, y, idx)
    x, P, K, S = correct(x_pred, P_pred, nu, H, R, joseph)
    return x, P, K, nu, S


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
    model = check_model(model)
    x_arr, P_arr = as_gaussian(x, P, model.n_state, "x", "P")
    return Prediction(*predict_moments(model, x_arr, P_arr, check_control(model, u)))


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
    model = check_model(model)
    x_arr, P_arr = as_gaussian(x_pred, P_pred, model.n_state, "x_pred", "P_pred")
    y_arr = as_vector("y", y, model.n_obs)
    return Update(*_ekf_correct(model, x_arr, P_arr, y_arr, None, joseph))


# --------------------------------------------------------------------------- boucle


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

    return run_filter(extended_family(joseph), model, y, x0, P0, u)


def extended_family(joseph: bool = False) -> FilterFamily:
    r"""Les étapes de l'EKF pour le moteur (état interne :math:`(\hat x, P)`)."""

    def predict_step(model, state, u):
        return predict_moments(model, *state, u)

    def update_step(model, state, y, idx):
        x, P, K, nu, S = _ekf_correct(model, *state, y, idx, joseph)
        return (x, P), Correction(K, nu, S)

    return FilterFamily(
        name="filtre de Kalman étendu",
        model_type=NonlinearModel,
        model_hint=NONLINEAR_HINT,
        prior=gaussian_prior,
        predict=predict_step,
        update=update_step,
        moments=gaussian_moments,
    )
