r"""Filtre à linéarisation a posteriori itérée (*iterated posterior linearisation filter*, IPLF ;
García-Fernández, Svensson, Morelande et Särkkä, 2015 ; Särkkä et Svensson, 2023, § 10.6).

C'est la contrepartie « à points » de l'EKF itéré. La correction d'un filtre gaussien revient à remplacer
:math:`h` par une fonction affine, :math:`h(x) \approx Hx + b`, d'erreur :math:`e \sim \mathcal N(0, \Omega)` :
la **régression linéaire statistique** de :math:`h` sous une loi :math:`\mathcal N(x_i, P_i)`, dont les
intégrales viennent de la règle (:class:`~kalman_course.filters.gaussian.GaussianRule`) :

.. math::

    H = C^TP_i^{-1},\qquad b = \mu - Hx_i,\qquad \Omega = \Sigma - HP_iH^T,

avec :math:`(\mu, \Sigma, C)` les moments de :math:`h` sous :math:`\mathcal N(x_i, P_i)`. Le filtre à points
ordinaire linéarise sous la loi **prédite** :math:`(\hat x^-, P^-)` ; l'IPLF recommence sous la loi
**a posteriori** obtenue, jusqu'à ce qu'elle ne bouge plus :

.. math::

    S_i = HP^-H^T + R + \Omega,\quad K_i = P^-H^TS_i^{-1},\quad
    x_{i+1} = \hat x^- + K_i\big(y - \mu - H(\hat x^- - x_i)\big),\quad P_{i+1} = (I - K_iH)P^- ,

toujours à partir de l'a priori :math:`(\hat x^-, P^-)`. Une itération redonne exactement le filtre à points
(sa correction) ; avec la règle de linéarisation (:math:`C = P_iH^T`, :math:`\Omega = 0`), les itérations
sont celles de Gauss–Newton : c'est l'EKF itéré. La boucle est celle du paquet
(:func:`~kalman_course.filters.iteration.iterate`, arrêt sur la taille du pas) ; la correction linéaire,
:func:`~kalman_course.core.linalg.correct`.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.linalg

from ..core.linalg import correct, symmetrize
from ..core.models import NonlinearModel
from ..core.results import FilterResult
from ..core.validation import KalmanInputError, as_gaussian, check_pd
from .cubature import CUBATURE
from .engine import Correction, FilterFamily, run_filter
from .gaussian import NONLINEAR_HINT, GaussianRule, predict_gaussian, where_text
from .iteration import DEFAULT_MAX_ITER, DEFAULT_TOL, check_iterations, iterate

__all__ = ["iplf_update", "posterior_linearization_family", "iterated_posterior_linearization_filter"]


def iplf_update(rule: GaussianRule, model: NonlinearModel, x_pred: np.ndarray, P_pred: np.ndarray, y: np.ndarray,
                idx: np.ndarray | None, max_iter: int = DEFAULT_MAX_ITER, tol: float = DEFAULT_TOL,
                joseph: bool = False, where: Any = "correction"):
    r"""La correction itérée de l'IPLF (voir l'en-tête), sans vérification des entrées.

    ``y`` ne contient que les composantes observées ``idx`` (``None`` : toutes). Renvoie
    ``(x, P, K, nu, S, n_iter)`` : ``K``, ``nu`` :math:`= y - \mu - H(\hat x^- - x_i)` et ``S`` sont ceux de
    la dernière régression."""
    current = {"P": P_pred}

    def step(x_i):
        P_i = current["P"]
        mom = rule.observation(model, x_i, P_i, idx, where)
        try:
            H = scipy.linalg.solve(P_i, mom.cross, assume_a="pos", check_finite=False).T   # Cᵀ P_i⁻¹
        except np.linalg.LinAlgError:
            raise KalmanInputError(
                f"IPLF, {where_text(where)} : la covariance a posteriori de l'itération n'est plus définie positive."
            ) from None
        omega = symmetrize(mom.cov - H.dot(P_i).dot(H.T))
        R = model.measurement_noise(x_i)
        if idx is not None:
            R = R[np.ix_(idx, idx)]
        nu = model.residual(y, mom.mean, idx) - H.dot(x_pred - x_i)  # y − (Hx̂⁻ + b), b = μ − Hx_i
        x_new, P_new, K, S = correct(x_pred, P_pred, nu, H, R + omega, joseph)
        current["P"] = P_new
        return x_new, float(np.linalg.norm(x_new - x_i)), (P_new, K, S, nu)

    out = iterate(x_pred, step, max_iter, tol)
    P, K, S, nu = out.last
    return out.x, P, K, nu, S, out.n_iter


def posterior_linearization_family(rule: GaussianRule = CUBATURE, max_iter: int = DEFAULT_MAX_ITER,
                                   tol: float = DEFAULT_TOL, joseph: bool = False) -> FilterFamily:
    r"""Les étapes de l'IPLF pour le moteur : la prédiction du filtre gaussien de règle ``rule``, puis la
    correction itérée :func:`iplf_update`. État interne :math:`(\hat x, P, k)`."""
    if not isinstance(rule, GaussianRule):
        raise KalmanInputError(
            "« rule » doit être une règle d'intégration gaussienne (kc.CubatureRule(), kc.UnscentedRule(...), "
            f"kc.GaussHermiteRule(order=...), kc.Linearization()) ; reçu {type(rule).__name__}."
        )
    max_iter, tol = check_iterations(max_iter, tol)
    if not isinstance(joseph, (bool, np.bool_)):
        raise KalmanInputError(f"« joseph » doit être un booléen (True ou False) ; reçu {joseph!r}.")

    def prior(model, x0, P0):
        rule.check(model)
        x, P = as_gaussian(x0, P0, model.n_state, "x0", "P0")
        return x, check_pd("P0", P), -1  # la régression demande P⁻¹ (et les points, une racine)

    def predict_step(model, state, u):
        x, P, k = state
        x_pred, P_pred, _ = predict_gaussian(rule, model, x, P, u, ("prédiction vers", k + 1))
        return x_pred, P_pred, k + 1

    def update_step(model, state, y, idx):
        x_pred, P_pred, k = state
        x, P, K, nu, S, n_iter = iplf_update(rule, model, x_pred, P_pred, y, idx, max_iter, tol, joseph,
                                             ("correction par", k))
        return (x, P, k), Correction(K, nu, S, n_iter)

    return FilterFamily(
        name="filtre à linéarisation a posteriori itérée (IPLF)",
        model_type=NonlinearModel,
        model_hint=NONLINEAR_HINT,
        prior=prior,
        predict=predict_step,
        update=update_step,
        moments=lambda state: (state[0], state[1]),
    )


def iterated_posterior_linearization_filter(
    model: NonlinearModel,
    y: Any,
    x0: Any,
    P0: Any,
    u: Any = None,
    *,
    rule: GaussianRule = CUBATURE,
    max_iter: int = DEFAULT_MAX_ITER,
    tol: float = DEFAULT_TOL,
    joseph: bool = False,
) -> FilterResult:
    r"""Le filtre à linéarisation a posteriori itérée (IPLF) sur toutes les mesures : prédiction du filtre
    gaussien, puis correction par régressions linéaires statistiques répétées sous la loi a posteriori
    courante (voir l'en-tête du module).

    Paramètres
    ----------
    model : NonlinearModel (bruits additifs pour une règle à points).
    y : (T, m), ou (T,) si m = 1 — ``NaN`` : composante manquante.
    x0 : (n,) ; P0 : (n, n) symétrique **définie** positive.
    u : (T, p), ou (T,) si p = 1, optionnel — commandes (``u[k]``, qui contient :math:`u_{k-1}`, sert à prédire vers ``y[k]``).
    rule : la règle d'intégration (cubature par défaut ; ``kc.Linearization()`` donne l'EKF itéré).
    max_iter, tol : au plus ``max_iter`` régressions par correction ; arrêt quand le pas
        :math:`\lVert x_{i+1} - x_i\rVert` est au plus ``tol``.
    joseph : forme de Joseph pour :math:`P`.

    Renvoie un :class:`~kalman_course.FilterResult` (``n_iter`` : régressions faites à chaque pas).
    """
    return run_filter(posterior_linearization_family(rule, max_iter, tol, joseph), model, y, x0, P0, u)
