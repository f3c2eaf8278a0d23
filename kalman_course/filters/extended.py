r"""Filtre de Kalman étendu (EKF) : étapes pures et famille pour le moteur.

Notations (cours → paquet) : :math:`J^A \to F`, :math:`J^H \to H`, :math:`W`, :math:`V` (jacobiennes des
bruits), :math:`\Phi \to Q`, :math:`\Psi \to R`, :math:`\hat x^-_{n+1} \to` ``x_pred``.

* Prédiction : :math:`\hat x_{k\mid k-1} = f(\hat x_{k-1\mid k-1}, u_{k-1})`,
  :math:`P_{k\mid k-1} = F P_{k-1\mid k-1} F^T + W Q W^T`, :math:`F` et :math:`W` évaluées en
  :math:`(\hat x_{k-1\mid k-1}, u_{k-1})`.
* Correction : celle du filtre linéaire avec la jacobienne :math:`H` évaluée en :math:`\hat x_{k\mid k-1}` à
  la place de :math:`C`, l'innovation :math:`\nu_k = y_k - h(\hat x_{k\mid k-1})` (angles ramenés dans
  :math:`(-\pi,\pi]`) et :math:`V R V^T` à la place de :math:`R`.

C'est le filtre gaussien (:mod:`kalman_course.filters.gaussian`) avec la règle de **linéarisation**
(:class:`Linearization`) : :math:`\mathbb E[g(x)] \approx g(\hat x)`, :math:`\operatorname{Cov}[g(x)]
\approx GPG^T`, :math:`\operatorname{Cov}[x, g(x)] \approx PG^T`, :math:`G = \partial g/\partial x\,(\hat x)` ;
la correction gaussienne :math:`K = P_{xy}S^{-1}` avec :math:`P_{xy} = P^-H^T` est alors exactement celle du
filtre linéaire. La correction itérée (Gauss–Newton) est dans :mod:`kalman_course.filters.iterated`.

**Tirages en lot** (:func:`extended_kalman_filter_runs`) : les mêmes étapes sur une pile de ``N`` tirages
(``X`` (N, n), ``P`` (N, n, n)). :math:`f` et :math:`h` passent par :meth:`NonlinearModel.transition_many`
et :meth:`NonlinearModel.observe_many` (un appel pour toute la pile si le modèle est vectorisé, un appel
par tirage sinon) ; les jacobiennes par :func:`transition_jacobians` et :func:`observation_jacobians`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..core.linalg import S_NOT_PD
from ..core.models import NonlinearModel
from ..core.results import FilterResult, FilterRuns
from ..core.validation import (
    KalmanInputError,
    as_gaussian,
    as_vector,
    call_user_function,
    check_control_allowed,
    check_instance,
)
from .engine import FilterFamily, run_filter, run_filter_runs
from .gaussian import (
    NONLINEAR_HINT,
    GaussianRule,
    Moments,
    correct_gaussian,
    gaussian_family,
    predict_gaussian_many,
    predict_gaussian,
    residuals,
)
from .kalman import Prediction, Update

__all__ = [
    "Linearization",
    "LINEARIZATION",
    "ekf_predict",
    "ekf_update",
    "extended_kalman_filter",
    "extended_kalman_filter_runs",
    "extended_family",
    "transition_jacobians",
    "observation_jacobians",
]

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


# --------------------------------------------------------------------------- la règle de linéarisation


class Linearization(GaussianRule):
    r"""La règle de **linéarisation** du filtre gaussien (l'EKF) : :math:`g` remplacée par sa tangente en
    :math:`\hat x`,

    .. math::

        \mathbb E[g(x)] \approx g(\hat x),\qquad \operatorname{Cov}[g(x)] \approx GPG^T,\qquad
        \operatorname{Cov}[x, g(x)] \approx PG^T,\qquad G = \left.\frac{\partial g}{\partial x}\right|_{\hat x},

    exacte pour :math:`g` affine. Une seule évaluation de :math:`g` et de sa jacobienne (analytique ou par
    différences centrées) ; bruits non additifs acceptés (:math:`WQW^T`, :math:`VRV^T`)."""

    label = "EKF"
    filter_name = "filtre de Kalman étendu"

    def innovation_message(self) -> str:
        return S_NOT_PD

    def __repr__(self) -> str:
        return "Linearization()"

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Linearization)

    def __hash__(self) -> int:
        return hash(Linearization)

    def transition(self, model, x, P, u, where):
        F = model.transition_jacobian(x, u)
        return Moments(model.transition(x, u), F.dot(P).dot(F.T), P.dot(F.T))

    def observation(self, model, x, P, idx, where, points=None):
        h = model.observe(x)
        H = model.observation_jacobian(x)
        if idx is not None:
            h, H = h[idx], H[idx]
        cross = P.dot(H.T)
        return Moments(h, H.dot(cross), cross)

    def transition_many(self, model, X, P, u, where):
        F = transition_jacobians(model, X, u)
        Ft = np.swapaxes(F, -1, -2)
        return Moments(model.transition_many(X, u), F @ P @ Ft, P @ Ft)

    def observation_many(self, model, X, P, idx, where, points=None):
        h = model.observe_many(X)
        H = observation_jacobians(model, X)
        if idx is not None:
            h, H = h[:, idx], H[..., idx, :]
        cross = P @ np.swapaxes(H, -1, -2)
        return Moments(h, H @ cross, cross)


#: La règle de linéarisation (sans paramètre : une seule instance suffit).
LINEARIZATION = Linearization()


# --------------------------------------------------------------------------- noyaux internes


def predict_moments(model: NonlinearModel, x: np.ndarray, P: np.ndarray, u: np.ndarray | None):
    """Prédiction de l'EKF (la prédiction gaussienne, règle de linéarisation) ; renvoie ``(x_pred, P_pred)``."""
    x_pred, P_pred, _ = predict_gaussian(LINEARIZATION, model, x, P, u)
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
    return correct_gaussian(LINEARIZATION, model, x_pred, P_pred, y, idx, joseph)


# --------------------------------------------------------------------------- noyaux en lot


def _stacked_jacobian(model: NonlinearModel, name: str, X: np.ndarray, args: tuple, shape: tuple[int, int],
                      one: Any) -> np.ndarray:
    """Jacobienne ``name`` en chaque ligne de ``X`` (N, n) : (N, *shape), ou ``shape`` si elle est constante
    (commune à tous les tirages, diffusée par les produits matriciels)."""
    value = getattr(model, name)
    if value is not None and not callable(value):
        return value  # constante
    N = X.shape[0]
    if value is not None and model.vectorized and N > 1:
        try:
            with np.errstate(all="ignore"):  # l'essai sur la pile ne doit rien signaler : il peut échouer
                J = np.asarray(call_user_function(name, value, X, args), dtype=float)
        except KalmanInputError:
            J = None  # elle n'accepte pas de pile : un appel par tirage
        if J is not None and J.shape == (N, *shape) and np.isfinite(J).all():
            J0 = one(X[0])
            if np.abs(J[0] - J0).max() <= 1e-12 * max(1.0, float(np.abs(J0).max())):
                return J
    return np.array([one(x) for x in X]).reshape(N, *shape)


def transition_jacobians(model: NonlinearModel, X: np.ndarray, u: np.ndarray | None = None) -> np.ndarray:
    r""":math:`F_i = \partial f/\partial x` en chaque ligne :math:`x_i` de ``X`` (N, n) : (N, n, n), ou
    (n, n) si ``f_jacobian`` est une matrice constante.

    Une jacobienne **fonction** d'un modèle vectorisé est d'abord appelée une fois sur la pile ``X`` :
    son résultat est pris s'il a la forme (N, n, n), des valeurs finies, et si sa première ligne égale
    l'appel sur ``X[0]`` seul ; sinon (et pour un modèle non vectorisé ou des différences centrées), un
    appel vérifié par tirage (:meth:`NonlinearModel.transition_jacobian`)."""
    n = model.n_state
    return _stacked_jacobian(model, "f_jacobian", X, (u,), (n, n), lambda x: model.transition_jacobian(x, u))


def observation_jacobians(model: NonlinearModel, X: np.ndarray) -> np.ndarray:
    r""":math:`H_i = \partial h/\partial x` en chaque ligne :math:`x_i` de ``X`` (N, n) : (N, m, n), ou
    (m, n) si ``h_jacobian`` est une matrice constante (même règle que :func:`transition_jacobians`)."""
    return _stacked_jacobian(model, "h_jacobian", X, (), (model.n_obs, model.n_state), model.observation_jacobian)





def predict_moments_many(model: NonlinearModel, X: np.ndarray, P: np.ndarray, u: np.ndarray | None):
    r"""Prédiction de l'EKF sur ``N`` tirages : :math:`\hat X^- = f(\hat X)` (N, n),
    :math:`P^-_i = F_iP_iF_i^T + W_iQW_i^T` (N, n, n)."""
    X_pred, P_pred, _ = predict_gaussian_many(LINEARIZATION, model, X, P, u, "prédiction")
    return X_pred, P_pred


def linearize_observations(model: NonlinearModel, X: np.ndarray, Y: np.ndarray, idx: np.ndarray | None):
    r"""Pour chaque tirage : résidu :math:`y_i - h(x_i)` (N, m_k), jacobienne :math:`H_i` (N, m_k, n) ou
    (m_k, n), en ``X`` (N, n), restreints aux composantes observées ``idx`` (``None`` : toutes)."""
    h = model.observe_many(X)
    H = observation_jacobians(model, X)
    if idx is not None:
        h, H = h[:, idx], H[..., idx, :]
    return residuals(model, Y, h, idx), H


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


def ekf_update(model: NonlinearModel, x_pred: Any, P_pred: Any, y: Any, *, joseph: bool = False) -> Update:
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
    model: NonlinearModel, y: Any, x0: Any, P0: Any, u: Any = None, *, joseph: bool = False, gate: Any = None,
    fading: Any = None,
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
    gate, fading : porte et mémoire évanescente, options du moteur (:mod:`~kalman_course.filters.gating`),
        comme pour :func:`~kalman_course.kalman_filter` (la NIS de la porte est celle de l'innovation
        :math:`y_k - h(\hat x^-_k)` sous :math:`S_k = H_kP^-_kH_k^T + VRV^T`).

    Renvoie un :class:`~kalman_course.FilterResult` (``n_iter`` vaut 1 à chaque pas observé, 0 sinon, et aux
    pas rejetés par la porte).
    """
    return run_filter(extended_family(joseph), model, y, x0, P0, u, gate=gate, fading=fading)


def extended_kalman_filter_runs(
    model: NonlinearModel, Y: Any, x0: Any, P0: Any, u: Any = None, *, joseph: bool = False
) -> FilterRuns:
    r"""Filtre de Kalman étendu sur ``N`` tirages indépendants du même modèle, tous à la fois
    (:func:`~kalman_course.filters.engine.run_filter_runs`) : mêmes équations que
    :func:`extended_kalman_filter`, appliquées à la pile des tirages (:math:`\hat X` (N, n), :math:`P`
    (N, n, n)). Avec un modèle vectorisé, :math:`f` et :math:`h` sont appelées une fois par pas pour toute la
    pile ; sinon une fois par tirage (même résultat, plus lent).

    Paramètres
    ----------
    model : NonlinearModel
    Y : (N, T, m), ou (N, T) si m = 1 — ``NaN`` : composante manquante (tirage par tirage).
    x0 : (n,) commun ou (N, n) ; P0 : (n, n) commune ou (N, n, n).
    u : (T, p) commune à tous les tirages, optionnelle.
    joseph : forme de Joseph pour la covariance a posteriori.

    Renvoie un :class:`~kalman_course.FilterRuns` : ``x`` (N, T, n), ``P`` (N, T, n, n)… ;
    ``result.run(i)`` est égal à ``extended_kalman_filter(model, Y[i], …)`` aux arrondis près.
    """
    return run_filter_runs(extended_family(joseph), model, Y, x0, P0, u)


def extended_family(joseph: bool = False) -> FilterFamily:
    r"""Les étapes de l'EKF pour le moteur : celles du filtre gaussien
    (:func:`~kalman_course.filters.gaussian.gaussian_family`) avec la règle de linéarisation."""
    return gaussian_family(LINEARIZATION, joseph=joseph)
