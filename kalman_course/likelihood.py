r"""Vraisemblance d'un modèle linéaire gaussien, initialisation diffuse exacte, maximum de vraisemblance et EM.

**Décomposition en erreurs de prédiction.** Les innovations :math:`\nu_k = y_k - C\hat x_{k\mid k-1}`
sont indépendantes, de lois :math:`\mathcal N(0, S_k)` : la densité des mesures est le produit de
leurs densités,

.. math::

    \log L = \log p(y_1, \dots, y_T) = \sum_k \log p(y_k \mid y_{1:k-1})
    = -\frac12\sum_k \Big(p_k\log 2\pi + \log|S_k| + \nu_k^TS_k^{-1}\nu_k\Big),

:math:`p_k` étant le nombre de composantes observées de :math:`y_k` (un pas sans mesure n'ajoute rien ;
une mesure partielle compte ses seules composantes observées, avec le bloc correspondant de :math:`S_k`).

**Initialisation diffuse exacte** (Durbin & Koopman 2012, § 5.2 et § 7.2.2 ; de Jong 1991). Sans a priori sur
l'état :math:`\delta` de la première mesure, la vraisemblance est la limite de
:math:`\kappa^{n/2}L_\kappa` quand l'a priori :math:`\mathcal N(0, \kappa I)` s'élargit. Avec le filtre
augmenté (:mod:`kalman_course.filters.diffuse` : innovations :math:`v_k - E_k\delta`, covariances
:math:`S_k`, information :math:`J_T = \sum E_k^TS_k^{-1}E_k`, :math:`h_T = \sum E_k^TS_k^{-1}v_k`) :

.. math::

    \log L_d = -\frac12\Big(N\log 2\pi + \sum_k \log|S_k| + \sum_k v_k^TS_k^{-1}v_k
    - h_T^TJ_T^{-1}h_T + \log|J_T|\Big),\qquad N = \sum_k p_k .

C'est la valeur de statsmodels (``use_exact_diffuse=True``). Pour le niveau local et la tendance
locale, elle vaut aussi la somme ordinaire des termes des pas :math:`k > d`, une fois l'état déterminé
par les :math:`d` premières mesures (par exemple par le SRIF parti de :math:`\mathcal R_{xx} = 0`),
moins :math:`\tfrac d2\log 2\pi`.

**Maximum de vraisemblance** : :func:`maximum_likelihood` maximise :math:`\log L(\theta)` avec
``scipy.optimize.minimize`` et calcule les écarts-types par la hessienne (``scipy.differentiate``).

**EM** (Shumway & Stoffer 1982) : :func:`expectation_maximization` alterne le lisseur (étape E, avec les
covariances de décalage un) et les formules closes de :math:`Q` et :math:`R` (étape M).

Ce module n'importe ni matplotlib ni statsmodels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
import scipy.differentiate
import scipy.linalg
import scipy.optimize

from .core.linalg import symmetrize
from .core.models import LinearGaussianModel
from .core.results import FilterResult, freeze
from .core.validation import (
    KalmanInputError,
    array_text,
    as_controls,
    as_float_array,
    as_measurements,
    check_instance,
    shape_text,
)
from .filters.diffuse import (
    DiffuseFilterResult,
    diffuse_family,
    diffuse_information,
    diffuse_kalman_filter,
    is_determined,
    masked_innovations,
)
from .filters.engine import run_filter, run_filter_runs
from .filters.ensemble import EnsembleFilterResult
from .filters.imm import IMMResult
from .filters.kalman import kalman_filter
from .filters.particle import ParticleFilterResult
from .filters.smoothers import diffuse_rts_pass, rts_smoother

__all__ = [
    "log_likelihood_terms",
    "filter_log_likelihood",
    "log_likelihood",
    "log_likelihoods",
    "MaximumLikelihood",
    "maximum_likelihood",
    "EMResult",
    "expectation_maximization",
    "em_step",
]

LOG_2PI = math.log(2.0 * math.pi)


# --------------------------------------------------------------------------- vraisemblance


def log_likelihood_terms(result: FilterResult) -> np.ndarray:
    r"""Termes de la décomposition en erreurs de prédiction, un par pas :

    .. math:: \ell_k = -\frac12\Big(p_k\log 2\pi + \log|S_k| + \nu_k^TS_k^{-1}\nu_k\Big),

    calculés par Cholesky :math:`S_k = L_kL_k^T` (:math:`\log|S_k| = 2\sum\log (L_k)_{ii}`,
    :math:`\nu_k^TS_k^{-1}\nu_k = \lVert L_k^{-1}\nu_k\rVert^2`), sur les composantes observées.

    Paramètres : ``result`` — :class:`~kalman_course.FilterResult`. Renvoie (T,) : 0 pour un pas sans
    mesure ou dont la mesure a été rejetée par la porte (``result.rejected`` : le filtre ne l'a pas utilisée,
    comme une mesure manquante) ; NaN pour un pas observé dont la prédiction n'est pas déterminée (début d'une
    initialisation diffuse, SRIF parti de :math:`\mathcal R_{xx} = 0`).

    IMM : ses propres termes :math:`\log\sum_j \bar c_j\,\mathcal N(\nu_j; 0, S_j)` (vraisemblance du mélange,
    ``result.log_likelihood_increments``), et non ceux de la gaussienne de mêmes moments.
    Filtres de Monte-Carlo : le filtre particulaire a sa propre estimation
    :math:`\log\hat p(y_k\mid y_{1:k-1})` (``result.log_likelihood_increments``), rendue telle quelle ;
    l'EnKF n'en a pas, et la formule gaussienne appliquée à ses innovations n'en serait qu'un substitut :
    refusé (:func:`filter_log_likelihood`).
    """
    result = _own_estimate_or_refuse(result, "log_likelihood_terms")
    if isinstance(result, (ParticleFilterResult, IMMResult)):
        return np.array(result.log_likelihood_increments, dtype=float)
    nu, S, obs = result.innovation, result.S, np.asarray(result.observed, dtype=bool)
    if nu.ndim != 2 or S.shape != nu.shape + nu.shape[-1:]:
        raise KalmanInputError(
            f"« result » doit porter des innovations (T, m) et leurs covariances (T, m, m) ; reçu "
            f"{nu.shape} et {S.shape} (un lot de tirages se traite tirage par tirage)."
        )
    return _prediction_error_terms(nu, S, obs & ~np.asarray(result.rejected)[:, None])


def _prediction_error_terms(nu: np.ndarray, S: np.ndarray, obs: np.ndarray) -> np.ndarray:
    r"""Les termes :math:`\ell_k` (…, T) d'innovations ``nu`` (…, T, m) de covariances ``S`` (…, T, m, m) aux
    composantes observées ``obs`` (…, T, m) : 0 sans composante observée, NaN si l'innovation observée n'est
    pas finie (prédiction non déterminée)."""
    out = np.zeros(obs.shape[:-1])
    rows = obs.any(axis=-1)
    known = rows & np.isfinite(np.where(obs, nu, 0.0)).all(axis=-1)
    out[rows & ~known] = np.nan
    if known.any():
        v, S_full = masked_innovations(nu[known], S[known], obs[known])
        try:
            L = np.linalg.cholesky(S_full)
        except np.linalg.LinAlgError:
            raise KalmanInputError(
                "« result.S » n'est pas définie positive à un pas observé : vraisemblance impossible à calculer."
            ) from None
        w = np.linalg.solve(L, v[:, :, None])[:, :, 0]
        logdet = 2.0 * np.sum(np.log(np.diagonal(L, axis1=1, axis2=2)), axis=1)
        p = obs[known].sum(axis=1)
        out[known] = -0.5 * (p * LOG_2PI + logdet + np.sum(w * w, axis=1))
    return out


def filter_log_likelihood(result: FilterResult) -> float:
    r"""Log-vraisemblance des mesures filtrées par ``result``.

    * :class:`~kalman_course.FilterResult` d'un filtre à a priori connu : :math:`\sum_k \ell_k`
      (:func:`log_likelihood_terms`) ;
    * :class:`~kalman_course.filters.diffuse.DiffuseFilterResult` : la vraisemblance diffuse exacte
      :math:`\log L_d` (voir le module), à partir du filtre augmenté ;
    * :class:`~kalman_course.IMMResult` : la vraisemblance du mélange,
      :math:`\sum_k\log\sum_j \bar c_j\,\mathcal N(\nu_j; 0, S_j)` (``result.log_likelihood``) ;
    * un filtre à porte (``gate=p``) : les pas rejetés (``result.rejected``) ne comptent pas, comme des
      mesures manquantes ;
    * :class:`~kalman_course.ParticleFilterResult` : l'estimation du filtre particulaire lui-même,
      :math:`\log\hat p(y_{1:T}) = \sum_k\log\hat p(y_k\mid y_{1:k-1})` (``result.log_likelihood``) ;
    * :class:`~kalman_course.EnsembleFilterResult` : refusé — l'EnKF n'estime pas la vraisemblance, et la
      formule gaussienne appliquée à ses innovations (covariance d'échantillon) n'en serait qu'un substitut
      silencieux (:class:`KalmanInputError`, qui dit quoi faire).

    Tout autre filtre gaussien (KF, EKF, UKF, SRIF…) : la décomposition en erreurs de prédiction de ses
    propres innovations et covariances :math:`S_k` (pour l'EKF, la vraisemblance de son modèle linéarisé).
    """
    result = _own_estimate_or_refuse(result, "filter_log_likelihood")
    if isinstance(result, (ParticleFilterResult, IMMResult)):
        return result.log_likelihood
    if isinstance(result, DiffuseFilterResult):
        return _diffuse_value(result.augmented, result.information[-1], result.information_vector[-1])
    terms = log_likelihood_terms(result)
    if np.isnan(terms).any():
        k = int(np.argmax(np.isnan(terms)))
        raise KalmanInputError(
            f"« result » a une prédiction non déterminée au pas k = {k} (départ sans a priori) : utilisez "
            "log_likelihood(model, y) sans x0 ni P0 (vraisemblance diffuse exacte), ou log_likelihood_terms."
        )
    return float(np.sum(terms))


def _own_estimate_or_refuse(result: Any, call: str) -> FilterResult:
    """``result`` doit être un résultat de filtre dont la vraisemblance est définie (voir
    :func:`filter_log_likelihood`) ; un modèle passé à sa place reçoit l'appel juste."""
    if isinstance(result, LinearGaussianModel):
        raise KalmanInputError(
            f"« result » est un modèle (LinearGaussianModel) : {call} prend le résultat d'un filtre. Pour la "
            "vraisemblance d'un modèle et de mesures, appelez log_likelihood(model, y, x0, P0)."
        )
    check_instance("result", result, FilterResult, "la sortie d'un filtre, par exemple kalman_filter")
    if isinstance(result, EnsembleFilterResult):
        raise KalmanInputError(
            "« result » vient de l'EnKF (ensemble_kalman_filter), qui n'estime pas la vraisemblance : la formule "
            "gaussienne appliquée à ses innovations n'en serait qu'un substitut. Pour un modèle linéaire, "
            "calculez log_likelihood(model, y, x0, P0) ; sinon, particle_filter(...).log_likelihood (estimation "
            "sans biais de p(y)) ; log_likelihood_terms(kalman_filter(...)) donne les termes gaussiens."
        )
    return result


def _diffuse_value(augmented: FilterResult, J: np.ndarray, h: np.ndarray):
    r""":math:`\log L_d` à partir du filtre augmenté et de :math:`J_T`, :math:`h_T` (voir le module) :
    :math:`\sum_k \ell_k(v_k, S_k) + \tfrac12 h_T^TJ_T^{-1}h_T - \tfrac12\log|J_T|`, par Cholesky de :math:`J_T`.
    Un lot (``augmented`` de :func:`~kalman_course.filters.engine.run_filter_runs`, ``J`` (N, n, n), ``h``
    (N, n)) : les N valeurs, (N,)."""
    det = is_determined(J)
    if not np.all(det):
        which = f" pour « models[{int(np.argmin(det))}] »" if np.ndim(det) else ""
        raise KalmanInputError(
            f"Les mesures ne déterminent pas l'état{which} (information J_T singulière : modèle non observable "
            "ou trop peu de mesures) : la vraisemblance diffuse n'est pas définie."
        )
    terms = _prediction_error_terms(augmented.innovation, augmented.S, np.asarray(augmented.observed, dtype=bool))
    L = np.linalg.cholesky(J)
    w = np.linalg.solve(L, h[..., None])[..., 0]
    value = (np.sum(terms, axis=-1) + 0.5 * np.sum(w * w, axis=-1)
             - np.sum(np.log(np.diagonal(L, axis1=-2, axis2=-1)), axis=-1))
    return float(value) if np.ndim(value) == 0 else value


def _prior(x0: Any, P0: Any) -> bool:
    """Vrai si l'a priori est donné, faux pour l'initialisation diffuse ; erreur si un seul des deux l'est."""
    if (x0 is None) != (P0 is None):
        raise KalmanInputError(
            "« x0 » et « P0 » vont ensemble : donnez les deux (a priori connu) ou aucun (initialisation diffuse exacte)."
        )
    return x0 is not None


def _filter(model: LinearGaussianModel, y: Any, x0: Any, P0: Any, u: Any) -> FilterResult:
    if _prior(x0, P0):
        return kalman_filter(model, y, x0, P0, u)
    return diffuse_kalman_filter(model, y, u)


def log_likelihood(model: LinearGaussianModel, y: Any, x0: Any = None, P0: Any = None, u: Any = None) -> float:
    r"""Log-vraisemblance gaussienne des mesures ``y`` sous ``model``.

    Avec ``x0``, ``P0`` (a priori connu de l'état initial, instant 0, comme pour
    :func:`~kalman_course.kalman_filter`) : décomposition en erreurs de prédiction
    :math:`\log L = -\tfrac12\sum_k (p_k\log 2\pi + \log|S_k| + \nu_k^TS_k^{-1}\nu_k)`.

    Sans ``x0`` ni ``P0`` : vraisemblance **diffuse exacte** de Durbin & Koopman (aucun a priori sur
    l'état de la première mesure), par le filtre augmenté (voir le module).

    Paramètres
    ----------
    model : LinearGaussianModel
    y : (T, m), ou (T,) si m = 1 — ``NaN``/``None`` : composante manquante.
    x0 : (n,), P0 : (n, n), optionnels, ensemble.
    u : (T, p), ou (T,) si p = 1, optionnel — commandes (``u[k]``, qui contient :math:`u_{k-1}`, sert à prédire vers ``y[k]``).

    Renvoie un ``float`` (nats).
    """
    if isinstance(model, FilterResult):
        raise KalmanInputError(
            "« model » est un résultat de filtre (FilterResult) : log_likelihood prend le modèle d'abord, "
            "log_likelihood(model, y, x0, P0) ; pour la vraisemblance d'un résultat déjà filtré, appelez "
            "filter_log_likelihood(result)."
        )
    check_instance("model", model, LinearGaussianModel, "la vraisemblance est celle d'un modèle linéaire gaussien")
    if _prior(x0, P0):
        return filter_log_likelihood(kalman_filter(model, y, x0, P0, u))
    # initialisation diffuse : le filtre augmenté et l'information suffisent (pas besoin des estimations exactes)
    augmented = run_filter(diffuse_family(), model, y, None, None, u)
    J, h = diffuse_information(model, augmented)
    return _diffuse_value(augmented, J[-1], h[-1])


def log_likelihoods(models: Any, y: Any) -> np.ndarray:
    r"""Vraisemblances **diffuses exactes** de plusieurs modèles de mêmes dimensions sur les mêmes mesures,
    calculées en lot (une grille de paramètres, les points d'une hessienne).

    Même calcul que :func:`log_likelihood` sans ``x0`` ni ``P0`` (voir le module), par le même filtre
    augmenté (:func:`~kalman_course.filters.diffuse.diffuse_family`), que le mode en lot du moteur
    (:func:`~kalman_course.filters.engine.run_filter_runs`) fait tourner sur les ``G`` modèles à la fois : les
    modèles sont empilés (:class:`~kalman_course.core.models.ModelBatch`, un tirage par modèle, tous sur
    ``y``), puis :math:`J_T`, :math:`h_T` et :math:`\log L_d` sont formés pour tous les modèles en lot.

    Paramètres
    ----------
    models : suite de ``G`` :class:`~kalman_course.LinearGaussianModel` de mêmes ``n`` et ``m``, sans
        commande (des modèles variables dans le temps sont calculés un à un par :func:`log_likelihood`).
    y : (T, m), ou (T,) si m = 1 — ``NaN`` : composante manquante (lignes entières ou partielles).

    Renvoie (G,) : les :math:`\log L_d` (nats), égales à celles de :func:`log_likelihood` aux arrondis près.
    """
    from .core.models import ModelBatch

    models = [models] if isinstance(models, LinearGaussianModel) else list(models)
    if any(isinstance(model, LinearGaussianModel) and model.time_varying and model.B is None for model in models):
        return np.array([log_likelihood(model, y) for model in models])  # un modèle variable : un par un
    batch = ModelBatch(models)
    Y = as_measurements("y", y, batch.n_obs)
    augmented = run_filter_runs(diffuse_family(), batch, np.broadcast_to(Y, (batch.n_models,) + Y.shape), None, None)
    J, h = diffuse_information(batch, augmented)
    return _diffuse_value(augmented, J[:, -1], h[:, -1])


# --------------------------------------------------------------------------- maximum de vraisemblance


@dataclass(frozen=True, eq=False)
class MaximumLikelihood:
    r"""Résultat de :func:`maximum_likelihood`.

    ``theta`` (q,) : :math:`\hat\theta` ; ``model`` : ``build(theta)`` ; ``log_likelihood`` :
    :math:`\log L(\hat\theta)` ; ``hessian`` (q, q) : hessienne de :math:`\log L` en :math:`\hat\theta`
    (``scipy.differentiate.hessian``) ; ``covariance`` (q, q) : :math:`(-\nabla^2\log L)^{-1}`,
    covariance asymptotique de :math:`\hat\theta` ; ``standard_errors`` (q,) : sa diagonale en racine
    (NaN si la hessienne n'est pas définie négative) ; ``converged``, ``message``, ``n_evaluations``,
    ``n_iterations`` : ce que dit l'optimiseur ; ``method`` : son nom.
    """

    theta: np.ndarray
    model: LinearGaussianModel
    log_likelihood: float
    hessian: np.ndarray
    covariance: np.ndarray
    standard_errors: np.ndarray
    converged: bool
    message: str
    n_evaluations: int
    n_iterations: int
    method: str

    def __post_init__(self) -> None:
        for name in ("theta", "hessian", "covariance", "standard_errors"):
            object.__setattr__(self, name, freeze(getattr(self, name)))

    def __repr__(self) -> str:
        from .numbers import format_number  # Babel, chargé à l'affichage seulement

        theta = " ; ".join(format_number(v, significant=6) for v in self.theta)
        return (f"<MaximumLikelihood : log L = {format_number(self.log_likelihood, decimals=4)}, θ = ({theta}), "
                f"{'convergé' if self.converged else 'non convergé'} ({self.n_evaluations} évaluations)>")


def _theta(name: str, value: Any) -> np.ndarray:
    arr = as_float_array(name, value)
    if arr.ndim == 0:
        arr = arr.reshape(1)
    if arr.ndim != 1 or arr.size == 0:
        raise KalmanInputError(f"« {name} » doit être un vecteur de paramètres (q,) non vide ; reçu {shape_text(arr.shape)}.")
    return arr


def _call_build(build: Callable, theta: np.ndarray, where: str) -> LinearGaussianModel:
    try:
        model = build(theta.copy())
    except KalmanInputError as exc:
        raise KalmanInputError(f"« build » a refusé {where} = {array_text(theta, significant=6, trim=True)} : {exc}") from exc
    except Exception as exc:  # noqa: BLE001 — l'erreur de l'utilisateur, rendue lisible
        raise KalmanInputError(
            f"« build » a échoué pour {where} = {array_text(theta, significant=6, trim=True)} ({type(exc).__name__}: {exc}) ; "
            f"« {where} » a-t-il la bonne longueur ({theta.size}) ?"
        ) from exc
    if not isinstance(model, LinearGaussianModel):
        raise KalmanInputError(
            f"« build » doit renvoyer un LinearGaussianModel ; il a renvoyé {type(model).__name__} pour "
            f"{where} = {array_text(theta, significant=6, trim=True)}."
        )
    return model


def _same_model(a: LinearGaussianModel, b: LinearGaussianModel) -> bool:
    if (a.B is None) != (b.B is None):
        return False
    pairs = [(a.A, b.A), (a.C, b.C), (a.Q, b.Q), (a.R, b.R)] + ([] if a.B is None else [(a.B, b.B)])
    return all(x.shape == y.shape and np.array_equal(x, y) for x, y in pairs)


def _hessian(f: Callable[[np.ndarray], np.ndarray], theta: np.ndarray) -> np.ndarray:
    r"""Hessienne de ``f`` en ``theta`` par ``scipy.differentiate.hessian`` (différences finies et
    extrapolation de Richardson). Les paramètres sont d'abord ramenés à l'échelle 1
    (:math:`\theta = \hat\theta + Ds`, :math:`D = \operatorname{diag}(\max(1, |\hat\theta_i|))`, d'où
    :math:`\nabla^2_\theta f = D^{-1}\nabla^2_s f D^{-1}`) ; ``f`` est vectorisée : elle reçoit les
    points d'essai en colonnes, (q, N), et renvoie leurs N valeurs (tous les points d'une itération
    de ``scipy.differentiate`` sont évalués en un seul lot)."""
    scale = np.maximum(1.0, np.abs(theta))

    def vectorised(s: np.ndarray) -> np.ndarray:
        s = np.asarray(s)
        points = theta[:, None] + scale[:, None] * s.reshape(s.shape[0], -1)
        return np.asarray(f(points), dtype=float).reshape(s.shape[1:])

    res = scipy.differentiate.hessian(vectorised, np.zeros_like(theta), initial_step=0.05, order=4, maxiter=2)
    H = np.asarray(res.ddf, dtype=float) / np.outer(scale, scale)
    return 0.5 * (H + H.T)


def maximum_likelihood(
    build: Callable[[np.ndarray], LinearGaussianModel],
    y: Any,
    theta0: Any,
    x0: Any = None,
    P0: Any = None,
    u: Any = None,
    *,
    method: str = "BFGS",
) -> MaximumLikelihood:
    r"""Estimation de paramètres :math:`\theta` par maximum de vraisemblance :
    :math:`\hat\theta = \arg\max_\theta \log L(\theta)`, :math:`\log L` donnée par :func:`log_likelihood`.

    Paramètres
    ----------
    build : fonction ``theta (q,) -> LinearGaussianModel`` — construit le modèle ; paramétrez les
        variances par leurs logarithmes (:math:`\sigma^2 = e^{\theta}`) pour un problème sans contrainte.
    y : (T, m), ou (T,) si m = 1 — mesures (``NaN`` : manquante).
    theta0 : (q,) — point de départ ; la vraisemblance doit y être finie et chaque composante doit agir
        sur le modèle.
    x0, P0 : a priori connu (sinon initialisation diffuse exacte), comme :func:`log_likelihood`.
    u : (T, p), optionnel — commandes (``u[k]``, qui contient :math:`u_{k-1}`, sert à prédire vers ``y[k]``).
    method : méthode de ``scipy.optimize.minimize`` (``"BFGS"`` par défaut, ``"Nelder-Mead"``…).

    Un point d'essai où ``build`` refuse les paramètres (:class:`KalmanInputError`) ou où la
    vraisemblance n'est pas finie vaut :math:`-\infty` pour l'optimiseur. Les écarts-types sont ceux de la
    matrice d'information observée :math:`(-\nabla^2\log L(\hat\theta))^{-1}`.

    Renvoie un :class:`MaximumLikelihood`.
    """
    if not callable(build):
        raise KalmanInputError(
            f"« build » doit être une fonction theta -> LinearGaussianModel ; reçu {type(build).__name__}."
        )
    if not isinstance(method, str):
        raise KalmanInputError(f"« method » doit être un nom de méthode de scipy.optimize.minimize ; reçu {method!r}.")
    theta0 = _theta("theta0", theta0)
    _prior(x0, P0)
    model0 = _call_build(build, theta0, "theta0")
    Y = as_measurements("y", y, model0.n_obs)
    U = as_controls("u", u, Y.shape[0], model0.n_control)
    for i in range(theta0.size):
        moved = theta0.copy()
        moved[i] += 1e-3 * max(1.0, abs(moved[i]))
        if _same_model(model0, _call_build(build, moved, "theta0")):
            raise KalmanInputError(
                f"La composante {i} de « theta0 » n'agit pas sur le modèle construit par « build » : "
                f"« theta0 » a-t-il la bonne longueur ({theta0.size}) ?"
            )
    try:
        with np.errstate(over="ignore", invalid="ignore"):  # une valeur non finie est traitée ci-dessous
            ll0 = log_likelihood(model0, Y, x0, P0, U)
    except KalmanInputError as exc:
        raise KalmanInputError(f"La log-vraisemblance n'est pas calculable en « theta0 » : {exc}") from exc
    if not np.isfinite(ll0):
        raise KalmanInputError(f"La log-vraisemblance n'est pas finie en « theta0 » ({ll0!r}) : changez de point de départ.")

    def loglik(theta: np.ndarray) -> float:
        try:
            model = build(np.array(theta, dtype=float))
            if not isinstance(model, LinearGaussianModel):
                raise KalmanInputError("modèle invalide")
            with np.errstate(over="ignore", invalid="ignore"):
                value = log_likelihood(model, Y, x0, P0, U)
        except KalmanInputError:
            return -np.inf
        return value if np.isfinite(value) else -np.inf

    try:
        opt = scipy.optimize.minimize(lambda t: -loglik(t), theta0, method=method)
    except ValueError as exc:
        raise KalmanInputError(f"« method » = {method!r} : scipy.optimize.minimize refuse ({exc}).") from exc
    theta = np.asarray(opt.x, dtype=float)
    model = _call_build(build, theta, "theta")
    ll = log_likelihood(model, Y, x0, P0, U)
    def loglik_batch(points: np.ndarray) -> np.ndarray:
        r""":math:`\log L` aux colonnes de ``points`` (q, N) : en lot (:func:`log_likelihoods`) au départ
        diffus sans commande, sinon (ou si un point est refusé) point par point."""
        if x0 is None and U is None:
            try:
                models = [build(np.array(p, dtype=float)) for p in points.T]
                if all(isinstance(mdl, LinearGaussianModel) and mdl.B is None for mdl in models):
                    with np.errstate(over="ignore", invalid="ignore"):
                        values = log_likelihoods(models, Y)
                    return np.where(np.isfinite(values), values, -np.inf)
            except KalmanInputError:
                pass
        return np.array([loglik(p) for p in points.T])

    H = _hessian(loglik_batch, theta)
    q = theta.size
    cov = np.full((q, q), np.nan)
    se = np.full(q, np.nan)
    if np.isfinite(H).all():
        try:
            cho = scipy.linalg.cho_factor(-H, lower=True)
            cov = symmetrize(scipy.linalg.cho_solve(cho, np.eye(q)))
            se = np.sqrt(np.diag(cov))
        except np.linalg.LinAlgError:
            pass
    return MaximumLikelihood(
        theta=theta, model=model, log_likelihood=float(ll), hessian=H, covariance=cov, standard_errors=se,
        converged=bool(opt.success), message=str(opt.message), n_evaluations=int(opt.nfev),
        n_iterations=int(getattr(opt, "nit", 0)), method=method,
    )


# --------------------------------------------------------------------------- EM


@dataclass(frozen=True, eq=False)
class EMResult:
    r"""Résultat de :func:`expectation_maximization`.

    ``model`` : le dernier modèle (:math:`Q`, :math:`R` estimées) ; ``log_likelihood`` : sa
    log-vraisemblance ; ``history`` (N+1,) : log-vraisemblance de chaque itéré (le modèle de départ
    compris) ; ``Q`` (N+1, n, n) et ``R`` (N+1, m, m) : les itérés ; ``n_iter`` : nombre N d'itérations ;
    ``converged`` : arrêt par le seuil ``tol`` (et non par ``max_iter``).
    """

    model: LinearGaussianModel
    log_likelihood: float
    history: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    n_iter: int
    converged: bool

    def __post_init__(self) -> None:
        for name in ("history", "Q", "R"):
            object.__setattr__(self, name, freeze(getattr(self, name)))

    def __repr__(self) -> str:
        from .numbers import format_number  # Babel, chargé à l'affichage seulement

        return (f"<EMResult : {self.n_iter} itérations, log L = {format_number(self.log_likelihood, decimals=5)}, "
                f"{'convergé' if self.converged else 'non convergé'}>")


def _initial_noise_moment(model: LinearGaussianModel, res: FilterResult, x_smooth: np.ndarray,
                          P_smooth: np.ndarray) -> np.ndarray:
    r""":math:`\mathbb E[w_1w_1^T \mid y]` du premier bruit d'état :math:`w_1 = x_1 - Ax_0 - Bu_1`, par le
    lissage des bruits (Durbin & Koopman 2012, § 4.5) :

    .. math::

        \mathbb E[w_1 \mid y] = QP_{1\mid 0}^{-1}(\hat x_{1\mid T} - \hat x_{1\mid 0}),\qquad
        \operatorname{Cov}(w_1 \mid y) = Q - QP_{1\mid 0}^{-1}Q + QP_{1\mid 0}^{-1}P_{1\mid T}P_{1\mid 0}^{-1}Q .

    Même valeur que :math:`r_1r_1^T + P_{1\mid T} - P_{1,0\mid T}A^T - AP_{1,0\mid T}^T + AP_{0\mid T}A^T`
    avec l'état initial lissé, mais sans :math:`P_{0\mid T} = P_0 - G_0(P_{1\mid 0} - P_{1\mid T})G_0^T`, qui
    soustrait des nombres de l'ordre de :math:`P_0` et perd tous ses chiffres quand l'a priori est vague
    (:math:`P_0 = 10^{14}I`) : ici :math:`P_{1\mid 0}` n'apparaît qu'inversée."""
    Q = model.Q
    W = scipy.linalg.lstsq(res.P_pred[0], Q)[0]  # P⁻⁻¹Q (moindres carrés : P⁻ = AP0Aᵀ + Q peut être singulière)
    w = W.T.dot(x_smooth - res.x_pred[0])
    return np.outer(w, w) + Q - Q.dot(W) + W.T.dot(P_smooth).dot(W)


def em_step(model: LinearGaussianModel, Y: np.ndarray, x0: Any, P0: Any, U: np.ndarray | None):
    r"""Une itération d'EM : filtre, lisseur (étape E), formules closes (étape M).

    Étape M, avec :math:`\hat x_{k\mid T}`, :math:`P_{k\mid T}`, :math:`P_{k,k-1\mid T}` du lisseur (un modèle
    variable dans le temps a ses :math:`A_k, B_k, C_k` ; :math:`Q` et :math:`R` sont constantes) :

    .. math::

        Q' = \frac1{N_Q}\sum_k \Big[r_kr_k^T + P_{k\mid T} - P_{k,k-1\mid T}A_k^T - A_kP_{k,k-1\mid T}^T
        + A_kP_{k-1\mid T}A_k^T\Big],\quad r_k = \hat x_{k\mid T} - A_k\hat x_{k-1\mid T} - B_ku_{k-1},

        R' = \frac1T\sum_k \Big[e_ke_k^T + C_kP_{k\mid T}C_k^T\Big],\quad e_k = y_k - C_k\hat x_{k\mid T},

    la somme sur :math:`Q` portant sur les :math:`N_Q` transitions (depuis l'état initial si l'a priori est
    connu, terme calculé par le lissage des bruits, :func:`_initial_noise_moment`, sûr pour un a priori
    vague ; à partir de la deuxième mesure à l'initialisation diffuse). Pour une mesure
    manquante, le terme de :math:`R'` est son espérance sachant les composantes observées :
    :math:`R` lui-même si tout manque, sinon
    :math:`M(e_oe_o^T + C_oPC_o^T)M^T + \operatorname{diag}(0, R_{mm} - R_{mo}R_{oo}^{-1}R_{om})`,
    :math:`M = [I;\ R_{mo}R_{oo}^{-1}]` (Shumway & Stoffer).

    À l'initialisation diffuse, l'étape E ne passe que par le filtre augmenté (:func:`diffuse_family` dans le
    moteur), l'information :math:`J_T`, :math:`h_T` et le lissage exact
    (:func:`~kalman_course.filters.smoothers.diffuse_rts_pass`) : ni estimations exactes du filtre, ni
    gains du lisseur exact, ni vérification « ce résultat vient de ce modèle » (l'étape filtre elle-même) ;
    mêmes valeurs que :func:`diffuse_kalman_filter` suivi de :func:`rts_smoother`.

    Renvoie ``(log L du modèle donné, nouveau modèle)``.
    """
    if _prior(x0, P0):
        res = kalman_filter(model, Y, x0, P0, U)
        ll = filter_log_likelihood(res)
        sm = rts_smoother(model, res)
        xs, Ps, lag, known_prior = sm.x, sm.P, sm.P_lag, True
    else:
        augmented = run_filter(diffuse_family(), model, Y, None, None, U)
        J, h = diffuse_information(model, augmented)
        ll = _diffuse_value(augmented, J[-1], h[-1])  # vérifie que J_T est inversible
        xs, Ps, lag = diffuse_rts_pass(np.asarray(model.sequence("A", Y.shape[0])), augmented, J[-1], h[-1])
        known_prior = False
    T, m = Y.shape
    A, C = np.asarray(model.sequence("A", T)), np.asarray(model.sequence("C", T))  # (T, …) : A_k, C_k
    R = model.R
    Bu = np.zeros_like(xs) if U is None else (np.asarray(model.sequence("B", T)) @ U[:, :, None])[:, :, 0]
    # transitions k-1 → k, k = 1…T-1 :
    # E[w wᵀ | y] = r rᵀ + P_{k|T} − P_{k,k-1|T}A_kᵀ − A_k P_{k,k-1|T}ᵀ + A_k P_{k-1|T} A_kᵀ
    if xs.shape[0] < 2 and not known_prior:
        raise KalmanInputError("Il faut au moins deux pas de mesure pour estimer Q par EM sans a priori.")
    Ak, Akt = A[1:], np.swapaxes(A[1:], 1, 2)
    r = xs[1:] - (Ak @ xs[:-1, :, None])[:, :, 0] - Bu[1:]
    LA = lag[1:] @ Akt
    terms_Q = r[:, :, None] * r[:, None, :] + Ps[1:] - LA - np.swapaxes(LA, 1, 2) + Ak @ Ps[:-1] @ Akt
    if known_prior:  # et la transition 0 → 1 depuis l'a priori
        terms_Q = np.concatenate([_initial_noise_moment(model.at(0), res, xs[0], Ps[0])[None], terms_Q])
    Q_new = np.mean(terms_Q, axis=0)
    # mesures
    obs = ~np.isnan(Y)
    terms = np.empty((T, m, m))
    full, none = obs.all(axis=1), ~obs.any(axis=1)
    Cf = C[full]
    e = Y[full] - (Cf @ xs[full][:, :, None])[:, :, 0]  # lignes complètes, d'un bloc
    terms[full] = e[:, :, None] * e[:, None, :] + Cf @ Ps[full] @ np.swapaxes(Cf, 1, 2)
    terms[none] = R
    for k in np.flatnonzero(~full & ~none):  # lignes partielles
        o = obs[k]
        io, im = np.flatnonzero(o), np.flatnonzero(~o)
        Co = C[k][io]
        e = Y[k, io] - Co.dot(xs[k])
        Eo = np.outer(e, e) + Co.dot(Ps[k]).dot(Co.T)
        Roo, Rmo = R[np.ix_(io, io)], R[np.ix_(im, io)]
        W = scipy.linalg.solve(Roo, Rmo.T, assume_a="pos").T  # R_mo R_oo⁻¹
        M = np.zeros((m, io.size))
        M[io] = np.eye(io.size)
        M[im] = W
        block = np.zeros((m, m))
        block[np.ix_(im, im)] = R[np.ix_(im, im)] - W.dot(Rmo.T)
        terms[k] = M.dot(Eo).dot(M.T) + block
    R_new = terms.mean(axis=0)
    new = LinearGaussianModel(model.A, model.C, symmetrize(Q_new), symmetrize(R_new), model.B)
    return ll, new


def expectation_maximization(
    model: LinearGaussianModel,
    y: Any,
    x0: Any = None,
    P0: Any = None,
    u: Any = None,
    *,
    max_iter: int = 500,
    tol: float = 1e-10,
) -> EMResult:
    r"""Estimation de :math:`Q` et :math:`R` par l'algorithme EM (Shumway & Stoffer 1982) ;
    :math:`A`, :math:`B`, :math:`C` restent ceux de ``model``.

    Chaque itération (:func:`em_step`) filtre, lisse (étape E : :math:`\hat x_{k\mid T}`,
    :math:`P_{k\mid T}` et les covariances de décalage un :math:`P_{k,k-1\mid T}`) puis maximise en
    :math:`(Q, R)` l'espérance de la log-vraisemblance complète (étape M, formules closes). La
    log-vraisemblance ne décroît jamais d'une itération à l'autre ; l'arrêt a lieu quand elle gagne moins
    de ``tol`` × max(1, :math:`|\log L|`).

    Paramètres
    ----------
    model : LinearGaussianModel — point de départ (ses :math:`Q`, :math:`R` initiales, constantes ; :math:`A`,
        :math:`B`, :math:`C` peuvent varier dans le temps).
    y : (T, m), ou (T,) si m = 1 ; ``NaN`` : manquante.
    x0, P0 : a priori connu (sinon initialisation diffuse exacte), comme :func:`log_likelihood`.
    u : (T, p), optionnel — commandes (``u[k]``, qui contient :math:`u_{k-1}`, sert à prédire vers ``y[k]``).
    max_iter : nombre maximal d'itérations (≥ 1) ; tol : seuil relatif d'arrêt (> 0).

    Renvoie un :class:`EMResult`.
    """
    check_instance("model", model, LinearGaussianModel, "EM estime Q et R d'un modèle linéaire gaussien")
    if model.Q.ndim == 3 or model.R.ndim == 3:
        name = "Q" if model.Q.ndim == 3 else "R"
        raise KalmanInputError(
            f"« model » a une covariance « {name} » variable dans le temps : EM estime une seule paire (Q, R) "
            "constante (A, B et C peuvent varier d'un pas à l'autre) ; pour des pas irréguliers, dont Q dépend, "
            "estimez plutôt la densité du bruit par maximum_likelihood."
        )
    if isinstance(max_iter, bool) or not isinstance(max_iter, (int, np.integer)) or max_iter < 1:
        raise KalmanInputError(f"« max_iter » doit être un entier ≥ 1 ; reçu {max_iter!r}.")
    tol_arr = as_float_array("tol", tol)
    if tol_arr.ndim != 0 or not tol_arr > 0:
        raise KalmanInputError(f"« tol » doit être un nombre strictement positif ; reçu {tol!r}.")
    _prior(x0, P0)
    Y = as_measurements("y", y, model.n_obs)
    U = as_controls("u", u, Y.shape[0], model.n_control)
    if not (~np.isnan(Y)).any():
        raise KalmanInputError("« y » ne contient aucune mesure observée : rien à apprendre.")
    history, Qs, Rs = [], [model.Q], [model.R]
    current = model
    converged = False
    for _ in range(int(max_iter)):
        ll, new = em_step(current, Y, x0, P0, U)
        history.append(ll)
        if len(history) > 1 and history[-1] - history[-2] < float(tol_arr) * max(1.0, abs(history[-2])):
            converged = True
            break
        current = new
        Qs.append(new.Q)
        Rs.append(new.R)
    else:
        history.append(log_likelihood(current, Y, x0, P0, U))
    return EMResult(model=current, log_likelihood=history[-1], history=np.array(history), Q=np.array(Qs),
                    R=np.array(Rs), n_iter=len(history) - 1, converged=converged)
