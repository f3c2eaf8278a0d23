r"""Filtre de Kalman « unscented » (UKF) de filterpy, appliqué à un :class:`~kalman_course.NonlinearModel`.

Ce module adapte le modèle (vecteurs 1-D, ``f(x, u)``, ``h(x)``, angles) aux conventions de
``filterpy.kalman.UnscentedKalmanFilter`` avec les points sigma de ``MerweScaledSigmaPoints`` (Wan & van der
Merwe, 2000) : les étapes ``predict``/``update`` de l'objet de filterpy deviennent les étapes pures d'une
famille du moteur commun (l'état :math:`(\hat x, P)` et les points sigma propagés entrent et sortent à
chaque pas), qui rend le résultat commun :class:`~kalman_course.FilterResult`. filterpy 2.0.0 est importé
à l'appel.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..core.models import NonlinearModel
from ..core.results import FilterResult
from ..core.validation import KalmanInputError, as_gaussian, check_pd
from .engine import Correction, FilterFamily, run_filter
from .extended import NONLINEAR_HINT, check_model

__all__ = ["filterpy_unscented_filter"]


def filterpy_unscented_filter(
    model,
    y: Any,
    x0: Any,
    P0: Any,
    u: Any = None,
    *,
    alpha: float = 0.1,
    beta: float = 2.0,
    kappa: float | None = None,
) -> FilterResult:
    r"""UKF de filterpy sur toutes les mesures (même ordre que :func:`~kalman_course.extended_kalman_filter`).

    Points sigma de van der Merwe :math:`(\alpha, \beta, \kappa)`, par défaut :math:`\alpha = 0{,}1`,
    :math:`\beta = 2` (optimal pour une loi gaussienne), :math:`\kappa = 3 - n`. Les bruits doivent être
    additifs (modèle sans ``f_noise_jacobian`` ni ``h_noise_jacobian``). Les composantes angulaires de la
    mesure sont traitées par un résidu ramené dans :math:`(-\pi, \pi]` et une moyenne circulaire.
    ``P0`` doit être définie positive (racine de Cholesky des points sigma).

    Mesures manquantes (moteur commun) : une ligne entièrement ``NaN`` ne fait que la prédiction ; une
    ligne partielle est refusée (la mise à jour de filterpy réutilise ses points sigma pour toute la mesure).

    Renvoie un :class:`~kalman_course.FilterResult` (``x``, ``P``, ``x_pred``, ``P_pred``, ``K``,
    ``innovation``, ``S`` de filterpy).
    """
    model = check_model(model)
    if model.f_noise_jacobian is not None or model.h_noise_jacobian is not None:
        raise KalmanInputError(
            "L'UKF de filterpy suppose des bruits additifs : le modèle ne doit pas avoir de "
            "f_noise_jacobian ni de h_noise_jacobian."
        )
    return run_filter(_filterpy_family(model, alpha, beta, kappa), model, y, x0, P0, u)


def _filterpy_family(model: NonlinearModel, alpha: float, beta: float, kappa: float | None) -> FilterFamily:
    from filterpy.kalman import MerweScaledSigmaPoints, UnscentedKalmanFilter

    n, m = model.n_state, model.n_obs
    angles = list(model.angle_indices)

    def fx(x, dt, u=None):
        return model.transition(np.asarray(x, dtype=float), u)

    def hx(x):
        return model.observe(np.asarray(x, dtype=float))

    def z_mean(sigmas, Wm):
        z = np.dot(Wm, sigmas)
        if angles:
            z[angles] = np.arctan2(np.dot(Wm, np.sin(sigmas[:, angles])), np.dot(Wm, np.cos(sigmas[:, angles])))
        return z

    points = MerweScaledSigmaPoints(n, alpha=alpha, beta=beta, kappa=(3.0 - n) if kappa is None else kappa)
    ukf = UnscentedKalmanFilter(  # objet de travail : son état est remplacé à chaque appel
        dim_x=n, dim_z=m, dt=1.0, hx=hx, fx=fx, points=points,
        z_mean_fn=z_mean if angles else None,
        residual_z=model.residual if angles else None,
    )
    ukf.Q = np.array(model.Q)
    ukf.R = np.array(model.R)

    def prior(model, x0, P0):
        x, P = as_gaussian(x0, P0, n, "x0", "P0")
        return x, check_pd("P0", P), None  # les points sigma demandent une racine de Cholesky de P0

    def guarded(step: str, call):
        try:
            return call()
        except np.linalg.LinAlgError:
            raise KalmanInputError(
                f"UKF de filterpy ({step}) : la covariance n'est plus définie positive (la racine de "
                "Cholesky des points sigma échoue). Augmentez Q ou P0, ou réduisez alpha."
            ) from None

    def predict_step(model, state, u):
        ukf.x, ukf.P = state[0].copy(), state[1].copy()
        guarded("prédiction", lambda: ukf.predict(u=u))
        return ukf.x.copy(), ukf.P.copy(), ukf.sigmas_f.copy()

    def update_step(model, state, y, idx):
        if idx is not None:
            raise KalmanInputError(
                "« y » a des lignes partiellement manquantes : l'UKF de filterpy n'accepte que des lignes "
                "complètes ou entièrement manquantes (NaN)."
            )
        ukf.x, ukf.P, ukf.sigmas_f = state[0].copy(), state[1].copy(), state[2].copy()
        guarded("correction", lambda: ukf.update(y))
        return (ukf.x.copy(), ukf.P.copy(), None), Correction(ukf.K.copy(), np.array(ukf.y, dtype=float), ukf.S.copy())

    return FilterFamily(
        name="UKF de filterpy",
        model_type=NonlinearModel,
        model_hint=NONLINEAR_HINT,
        prior=prior,
        predict=predict_step,
        update=update_step,
        moments=lambda state: (state[0], state[1]),
    )
