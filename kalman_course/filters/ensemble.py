r"""Filtre de Kalman d'ensemble stochastique (EnKF : Evensen 1994 ; observations perturbées : Burgers,
van Leeuwen & Evensen 1998) : étapes pures et famille pour le moteur.

La loi est représentée par :math:`N` membres :math:`x^i` ; la moyenne et la covariance ne sont que des
statistiques d'échantillon, :math:`\bar x = \frac1N\sum_i x^i`,
:math:`P = \frac1{N-1}\sum_i (x^i - \bar x)(x^i - \bar x)^T` — un centre météorologique ne forme jamais
:math:`P` (:math:`n \approx 10^8`) : il n'en utilise que les produits par :math:`H^T`.

* prévision : :math:`x^i \leftarrow f(x^i, u) + w^i`, :math:`w^i \sim \mathcal N(0, Q)` ;
* analyse : avec :math:`\bar y = \frac1N\sum_i h(x^i)`,

  .. math::

      P_{xy} = \tfrac1{N-1}\sum_i (x^i - \bar x)(h(x^i) - \bar y)^T,\quad
      P_{yy} = \tfrac1{N-1}\sum_i (h(x^i) - \bar y)(h(x^i) - \bar y)^T,\quad
      K = P_{xy}(P_{yy} + R)^{-1},

      x^i \leftarrow x^i + K\,(y + v^i - h(x^i)),\qquad v^i \sim \mathcal N(0, R).

Sans les perturbations :math:`v^i`, la dispersion de l'ensemble analysé serait
:math:`(I - KH)P(I - KH)^T` au lieu de :math:`(I - KH)P` : trop petite. Sur un modèle linéaire gaussien,
la moyenne et la covariance de l'ensemble tendent vers celles du filtre de Kalman quand :math:`N \to \infty`
(erreur en :math:`1/\sqrt N`).

Les analyses déterministes de l'assimilation de données — ETKF, LETKF, DEnKF — et le taper de
Gaspari–Cohn sont dans :mod:`.ensemble_analysis` ; la même famille les enchaîne dans le temps
(``method=``), suivies de l'**inflation** des anomalies analysées,
:math:`x^i \leftarrow \bar x + \lambda(x^i - \bar x)`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from ..core.angles import wrap_angle
from ..core.linalg import centred_rows, covariance_factor, psd_solve, symmetrize
from ..core.models import NonlinearModel
from ..core.results import FilterResult
from ..core.simulation import check_positive_int
from ..core.validation import KalmanInputError, as_gaussian
from .engine import Correction, FilterFamily, run_filter
from .ensemble_analysis import (
    as_distances,
    check_inflation,
    check_radius,
    denkf_analysis,
    etkf_analysis,
    gaspari_cohn,
    letkf_analysis,
    symmetric_inverse_root,
)
from .extended import NONLINEAR_HINT

__all__ = ["METHODS", "EnsembleFilterResult", "ensemble_family", "ensemble_kalman_filter"]

@dataclass(frozen=True, eq=False, repr=False)
class EnsembleFilterResult(FilterResult):
    r"""Résultat de l'EnKF : les champs de :class:`~kalman_course.FilterResult` (``x`` moyenne et ``P``
    covariance d'échantillon de l'ensemble, ``K`` gain de l'analyse…) et ``members`` (T, N, n), l'ensemble
    analysé de chaque pas si ``keep_members=True`` (sinon ``None``)."""

    members: np.ndarray | None = None


class EnsembleState(NamedTuple):
    r"""État interne : ``X`` (N, n) les membres ; ``k`` l'indice de la mesure visée (messages d'erreur) ;
    ``LQ`` (n, n), ``LR`` (m, m) : facteurs :math:`L_QL_Q^T = Q`, :math:`L_RL_R^T = R` (calculés une fois,
    le modèle ne change pas) ; ``moments`` : :math:`(\bar x, P, X - \bar x)` de l'ensemble, calculés une
    seule fois (le moteur les range, l'analyse réutilise la moyenne et les écarts de l'ensemble prévu) ;
    ``W`` (m, m) : :math:`R^{-1/2}` des analyses déterministes ; ``rho`` (m, n) : poids de Gaspari–Cohn du
    LETKF."""

    X: np.ndarray
    k: int
    LQ: np.ndarray | None = None
    LR: np.ndarray | None = None
    moments: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
    W: np.ndarray | None = None
    rho: np.ndarray | None = None


def _moments(X: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""Moyenne :math:`\bar x` (n,), covariance d'échantillon :math:`P` (n, n) et écarts
    :math:`X - \bar x` (N, n) de l'ensemble ``X`` (N, n)."""
    x = X.mean(axis=0)
    D = centred_rows(X, x)
    return x, symmetrize(D.T.dot(D) / (X.shape[0] - 1)), D


#: Les analyses de ``ensemble_kalman_filter(method=...)``.
METHODS = ("stochastic", "etkf", "denkf")


def _check_method(method: Any) -> str:
    if not isinstance(method, str) or method not in METHODS:
        raise KalmanInputError(
            f"« method » doit valoir {', '.join(repr(m) for m in METHODS)} (EnKF stochastique, ETKF, DEnKF) ; "
            f"reçu {method!r}."
        )
    return method


def ensemble_family(n_members: int, keep_members: bool = False, perturb: bool = True, method: str = "stochastic",
                    inflation: float = 1.0, localization: Any = None, distances: Any = None) -> FilterFamily:
    r"""Les étapes des filtres d'ensemble pour le moteur : l'analyse ``method`` (``"stochastic"`` :
    observations perturbées ; ``"etkf"`` : transformée symétrique, ou LETKF avec ``localization`` ;
    ``"denkf"`` : EnKF déterministe), puis les anomalies analysées multipliées par ``inflation``.
    ``perturb=False`` retire les perturbations :math:`v^i` des observations de l'EnKF stochastique (pour
    montrer pourquoi elles sont nécessaires)."""
    N = check_positive_int("n_members", n_members, minimum=2)
    if not isinstance(perturb, (bool, np.bool_)):
        raise KalmanInputError(f"« perturb » doit être un booléen ; reçu {perturb!r}.")
    method = _check_method(method)
    if not perturb and method != "stochastic":
        raise KalmanInputError(
            f"« perturb=False » ne s'applique qu'à l'EnKF stochastique (method='stochastic') : l'analyse "
            f"{method!r} ne perturbe pas les observations."
        )
    lam = check_inflation(inflation)
    radius = None
    if localization is not None:
        radius = check_radius("localization", localization)
        if method != "etkf":
            raise KalmanInputError(
                f"« localization » s'applique à method='etkf' (le LETKF) ; reçu method={method!r}."
            )
        if distances is None:
            raise KalmanInputError(
                "« localization » exige « distances » (m, n) : la distance de chaque observation à chaque "
                "composante de l'état."
            )
    elif distances is not None:
        raise KalmanInputError(
            "« distances » est fourni sans « localization » : donnez le rayon de localisation (localization=…), "
            "ou retirez distances."
        )

    def prior(model, x0, P0, rng):
        if model.f_noise_jacobian is not None or model.h_noise_jacobian is not None:
            raise KalmanInputError(
                "L'EnKF du paquet suppose des bruits additifs : le modèle ne doit avoir ni f_noise_jacobian ni "
                "h_noise_jacobian."
            )
        x, P = as_gaussian(x0, P0, model.n_state, "x0", "P0")
        rho = None
        if radius is not None:
            rho = gaspari_cohn(as_distances("distances", distances, model.n_obs, model.n_state), radius)
        X = x + rng.standard_normal((N, model.n_state)).dot(covariance_factor(P).T)
        W = None if method == "stochastic" else symmetric_inverse_root(model.R)
        return EnsembleState(X, -1, covariance_factor(model.Q), np.linalg.cholesky(model.R), None, W, rho)

    def predict_step(model, state, u, rng):
        X = model.transition_many(state.X, u)
        X = X + rng.standard_normal(X.shape).dot(state.LQ.T)
        return state._replace(X=X, k=state.k + 1, moments=_moments(X))

    def update_step(model, state, y, idx, rng):
        X = state.X
        HX = model.observe_many(X)
        R, LR, W, rho = model.R, state.LR, state.W, state.rho
        if idx is not None:
            HX, R = HX[:, idx], R[np.ix_(idx, idx)]
            LR = np.linalg.cholesky(R)
            W = None if W is None else symmetric_inverse_root(R)
            rho = None if rho is None else rho[idx]
        angles = model.observed_angles(idx)
        x_bar, _, dX = state.moments or _moments(X)  # moyenne et écarts de l'ensemble prévu
        y_bar = HX.mean(axis=0)
        if angles:
            y_bar[angles] = np.arctan2(np.sin(HX[:, angles]).mean(axis=0), np.cos(HX[:, angles]).mean(axis=0))
        dY = centred_rows(HX, y_bar)
        if angles:
            dY[:, angles] = wrap_angle(dY[:, angles])
        Pxy = dX.T.dot(dY) / (N - 1)
        S = dY.T.dot(dY) / (N - 1) + R
        K = psd_solve(S, Pxy.T, message=f"EnKF, analyse par y[{state.k}] : la covariance d'innovation P_yy + R "
                                         "n'est pas définie positive.").T
        nu = model.residual(y, y_bar, idx)
        if method == "stochastic":
            D = y - HX
            if perturb:
                D = D + rng.standard_normal((N, R.shape[0])).dot(LR.T)
            if angles:
                D[:, angles] = wrap_angle(D[:, angles])
            X_new = X + D.dot(K.T)
            if lam != 1.0:
                x_a = X_new.mean(axis=0)
                X_new = x_a + lam * (X_new - x_a)
        elif method == "denkf":
            X_new = denkf_analysis(x_bar, dX, dY, nu, R, lam, K=K)
        elif rho is None:
            X_new = etkf_analysis(x_bar, dX, dY, nu, R, lam, W=W)
        else:
            X_new = letkf_analysis(x_bar, dX, dY, nu, R, rho, lam, W=W)
        return state._replace(X=X_new, moments=_moments(X_new)), Correction(K, nu, S)

    def outputs(state):
        return {"members": state.X} if keep_members else {}

    names = {"stochastic": "filtre de Kalman d'ensemble (EnKF)", "denkf": "EnKF déterministe (DEnKF)",
             "etkf": "filtre de Kalman d'ensemble à transformée (ETKF)" if radius is None
             else "ETKF local (LETKF)"}
    return FilterFamily(
        name=names[method],
        model_type=NonlinearModel,
        model_hint=NONLINEAR_HINT,
        prior=prior,
        predict=predict_step,
        update=update_step,
        moments=lambda state: (state.moments or _moments(state.X))[:2],
        result_type=EnsembleFilterResult,
        stochastic=True,
        step_outputs=outputs if keep_members else None,
    )


def ensemble_kalman_filter(
    model: NonlinearModel,
    y: Any,
    x0: Any,
    P0: Any,
    u: Any = None,
    *,
    n_members: int,
    rng: Any,
    keep_members: bool = False,
    perturb: bool = True,
    method: str = "stochastic",
    inflation: float = 1.0,
    localization: Any = None,
    distances: Any = None,
) -> EnsembleFilterResult:
    r"""Filtre de Kalman d'ensemble sur toutes les mesures : stochastique (observations perturbées, par
    défaut), à transformée (ETKF, ou LETKF avec ``localization``) ou déterministe (DEnKF).

    Les membres partent i.i.d. de :math:`\mathcal N(x_0, P_0)` ; à chaque cycle, chaque membre est prévu par
    :math:`f` plus un bruit :math:`\mathcal N(0, Q)`, l'ensemble est analysé avec ``y[k]`` (l'analyse de
    ``method``), puis ses anomalies analysées sont multipliées par ``inflation``.

    Paramètres
    ----------
    model : NonlinearModel à bruits additifs (``vectorized=True`` conseillé : tout l'ensemble passe par
        ``f`` et ``h`` en un appel).
    y : (T, m), ou (T,) si m = 1 — ``NaN`` : composante manquante (ligne entière : prévision seule).
    x0 : (n,), P0 : (n, n) — loi de l'ensemble initial.
    u : (T, p), ou (T,) si p = 1, optionnel — commandes (``u[k]``, qui contient :math:`u_{k-1}`, sert à prédire vers ``y[k]``).
    n_members : taille :math:`N \ge 2` de l'ensemble.
    rng : graine entière ou ``numpy.random.Generator`` (obligatoire) ; tous les tirages en viennent.
    keep_members : garder l'ensemble analysé de chaque pas (``members`` (T, N, n)).
    perturb : perturber les observations (défaut, l'EnKF stochastique) ; ``False`` : même gain sans
        perturbations — l'ensemble analysé est alors trop resserré, :math:`(I-KH)P(I-KH)^T` au lieu de
        :math:`(I-KH)P` (démonstration du chapitre). Pour ``method="stochastic"`` seulement.
    method : ``"stochastic"`` (observations perturbées), ``"etkf"``
        (:func:`~kalman_course.filters.ensemble_analysis.etkf_update`) ou ``"denkf"``
        (:func:`~kalman_course.filters.ensemble_analysis.denkf_update`).
    inflation : :math:`\lambda \ge 1`, facteur des anomalies analysées (1 : aucune inflation).
    localization : rayon de localisation :math:`> 0` (``numpy.inf`` permis) : ``"etkf"`` devient le LETKF
        (:func:`~kalman_course.filters.ensemble_analysis.letkf_update`) ; ``numpy.inf`` redonne, avec le même
        ``rng``, le résultat de ``localization=None`` (au bit près : tous les poids valent 1, les analyses
        locales sont l'analyse globale).
    distances : (m, n), exigé avec ``localization`` — distance de l'observation :math:`i` à la composante
        :math:`j` de l'état.

    Renvoie un :class:`EnsembleFilterResult` : ``x`` (T, n) moyenne et ``P`` (T, n, n) covariance
    d'échantillon de l'ensemble analysé, ``x_pred``, ``P_pred`` celles de l'ensemble prévu, ``K`` (T, n, m)
    gain :math:`P_{xy}(P_{yy} + R)^{-1}` de l'ensemble prévu, ``innovation`` :math:`y - \bar y`,
    ``S`` :math:`P_{yy} + R`, ``members`` (T, N, n) si ``keep_members``.
    """
    family = ensemble_family(n_members, keep_members, perturb, method, inflation, localization, distances)
    return run_filter(family, model, y, x0, P0, u, rng=rng)
