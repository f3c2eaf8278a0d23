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

from ..core.linalg import correct, symmetrize
from ..core.models import LinearGaussianModel
from ..core.results import FilterResult
from ..core.validation import as_gaussian, as_vector, check_control_allowed
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
