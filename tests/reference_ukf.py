r"""Référence des tests : la boucle ``predict()``/``update()`` de ``filterpy.kalman.UnscentedKalmanFilter``
avec les points sigma ``MerweScaledSigmaPoints`` (filterpy 2.0.0), sur un :class:`~kalman_course.NonlinearModel`.

Ce n'est pas une partie du paquet (qui a son propre UKF, :func:`kalman_course.unscented_kalman_filter`) :
c'est l'implémentation indépendante à laquelle on le compare. Rien ici n'utilise le moteur du paquet ;
seules les fonctions ``f``, ``h`` de l'utilisateur et les covariances du modèle sont lues. Les
composantes angulaires de la mesure reçoivent la moyenne circulaire (``z_mean_fn``) et le résidu replié
(``residual_z``) que filterpy permet de fournir. Une ligne de ``y`` entièrement ``NaN`` : prédiction seule.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np


def _wrap(a):
    return np.pi - np.mod(np.pi - a, 2.0 * np.pi)


def filterpy_unscented_filter(model, y, x0, P0, u=None, *, alpha, beta=2.0, kappa):
    """Renvoie un espace de noms avec ``x``, ``P``, ``x_pred``, ``P_pred``, ``K``, ``innovation``, ``S``
    empilés dans le temps (mêmes conventions que ``FilterResult``)."""
    from filterpy.kalman import MerweScaledSigmaPoints, UnscentedKalmanFilter

    n, m = model.n_state, model.n_obs
    angles = list(model.angle_indices)
    Y = np.asarray(y, dtype=float).reshape(len(y), m)

    def fx(x, dt, u=None):
        return np.asarray(model.f(np.asarray(x, dtype=float), u), dtype=float).reshape(n)

    def hx(x):
        return np.asarray(model.h(np.asarray(x, dtype=float)), dtype=float).reshape(m)

    def z_mean(sigmas, Wm):
        z = np.dot(Wm, sigmas)
        z[angles] = np.arctan2(np.dot(Wm, np.sin(sigmas[:, angles])), np.dot(Wm, np.cos(sigmas[:, angles])))
        return z

    def residual_z(a, b):
        d = np.asarray(a, dtype=float) - b
        d[angles] = _wrap(d[angles])
        return d

    points = MerweScaledSigmaPoints(n, alpha=alpha, beta=beta, kappa=kappa)
    ukf = UnscentedKalmanFilter(
        dim_x=n, dim_z=m, dt=1.0, hx=hx, fx=fx, points=points,
        z_mean_fn=z_mean if angles else None, residual_z=residual_z if angles else None,
    )
    ukf.Q = np.array(model.Q)
    ukf.R = np.array(model.R)
    ukf.x = np.array(x0, dtype=float)
    ukf.P = np.array(P0, dtype=float)
    out = {k: [] for k in ("x", "P", "x_pred", "P_pred", "K", "innovation", "S")}
    for k in range(len(Y)):
        ukf.predict(u=None if u is None else np.atleast_1d(np.asarray(u[k], dtype=float)))
        out["x_pred"].append(ukf.x.copy())
        out["P_pred"].append(ukf.P.copy())
        if np.isnan(Y[k]).all():
            out["K"].append(np.zeros((n, m)))
            out["innovation"].append(np.full(m, np.nan))
            out["S"].append(np.full((m, m), np.nan))
        else:
            ukf.update(Y[k])
            out["K"].append(ukf.K.copy())
            out["innovation"].append(np.array(ukf.y, dtype=float))
            out["S"].append(ukf.S.copy())
        out["x"].append(ukf.x.copy())
        out["P"].append(ukf.P.copy())
    return SimpleNamespace(**{k: np.array(v) for k, v in out.items()})
