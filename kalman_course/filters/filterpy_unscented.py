r"""Filtre de Kalman « unscented » (UKF) de filterpy, appliqué à un :class:`~kalman_course.NonlinearModel`.

Le paquet n'implémente pas l'UKF : ce module adapte le modèle (vecteurs 1-D, ``f(x, u)``, ``h(x)``,
angles) aux conventions de ``filterpy.kalman.UnscentedKalmanFilter`` avec les points sigma de
``MerweScaledSigmaPoints`` (Wan & van der Merwe, 2000) et rend le résultat dans le type commun
:class:`~kalman_course.FilterResult`. filterpy 2.0.0 est importé à l'appel.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..core.results import FilterResult
from ..core.validation import KalmanInputError, as_controls, as_gaussian, as_measurements
from .extended import check_model

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

    Mesures manquantes : une ligne entièrement ``NaN`` ne fait que la prédiction ; une ligne partielle
    est refusée (filterpy ne sait pas restreindre la mesure).

    Renvoie un :class:`~kalman_course.FilterResult` (``x``, ``P``, ``x_pred``, ``P_pred``, ``K``,
    ``innovation``, ``S`` de filterpy).
    """
    from filterpy.kalman import MerweScaledSigmaPoints, UnscentedKalmanFilter

    model = check_model(model)
    if model.f_noise_jacobian is not None or model.h_noise_jacobian is not None:
        raise KalmanInputError(
            "L'UKF de filterpy suppose des bruits additifs : le modèle ne doit pas avoir de "
            "f_noise_jacobian ni de h_noise_jacobian."
        )
    n, m = model.n_state, model.n_obs
    Y = as_measurements("y", y, m)
    T = Y.shape[0]
    U = as_controls("u", u, T, model.n_control)
    x, P = as_gaussian(x0, P0, n, "x0", "P0")
    observed = ~np.isnan(Y)
    partial = observed.any(axis=1) & ~observed.all(axis=1)
    if partial.any():
        raise KalmanInputError(
            f"« y » a des lignes partiellement manquantes (pas {np.flatnonzero(partial)[:5].tolist()}…) : "
            "l'UKF de filterpy n'accepte que des lignes complètes ou entièrement manquantes."
        )

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
    ukf = UnscentedKalmanFilter(
        dim_x=n, dim_z=m, dt=1.0, hx=hx, fx=fx, points=points,
        z_mean_fn=z_mean if angles else None,
        residual_z=model.residual if angles else None,
    )
    ukf.x = x.copy()
    ukf.P = P.copy()
    ukf.Q = np.array(model.Q)
    ukf.R = np.array(model.R)

    xs, Ps = np.empty((T, n)), np.empty((T, n, n))
    xps, Pps = np.empty((T, n)), np.empty((T, n, n))
    Ks = np.zeros((T, n, m))
    nus = np.full((T, m), np.nan)
    Ss = np.full((T, m, m), np.nan)
    for k in range(T):
        ukf.predict(u=None if U is None else U[k])
        xps[k] = ukf.x
        Pps[k] = ukf.P
        if observed[k].all():
            ukf.update(Y[k])
            Ks[k] = ukf.K
            nus[k] = ukf.y
            Ss[k] = ukf.S
        xs[k] = ukf.x
        Ps[k] = ukf.P
    return FilterResult(x=xs, P=Ps, x_pred=xps, P_pred=Pps, K=Ks, innovation=nus, S=Ss, observed=observed)
