r"""Référence des tests : la boucle ``predict()``/``update()`` de ``filterpy.kalman.CubatureKalmanFilter``
(filterpy 2.0.0) sur un :class:`~kalman_course.NonlinearModel` à bruits additifs.

Ce n'est pas une partie du paquet : c'est l'implémentation indépendante à laquelle on compare
``kc.cubature_kalman_filter(..., redraw=False)`` (filterpy réutilise à la correction les points propagés
par ``f``). Le CKF de filterpy travaille en vecteurs **colonnes** : l'état ``x`` est (n, 1) et la mesure
doit être passée en colonne (m, 1), sinon ``z - ẑ`` se diffuse en une matrice (m, m). Une ligne de ``y``
entièrement ``NaN`` : prédiction seule (``update(None)``).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np


def filterpy_cubature_filter(model, y, x0, P0):
    """Renvoie un espace de noms avec ``x``, ``P``, ``x_pred``, ``P_pred``, ``K``, ``innovation``, ``S``
    empilés dans le temps (mêmes conventions que ``FilterResult``)."""
    from filterpy.kalman import CubatureKalmanFilter

    n, m = model.n_state, model.n_obs
    Y = np.asarray(y, dtype=float).reshape(len(y), m)

    def fx(x, dt):
        return np.asarray(model.f(np.asarray(x, dtype=float).ravel(), None), dtype=float).reshape(n)

    def hx(x):
        return np.asarray(model.h(np.asarray(x, dtype=float).ravel()), dtype=float).reshape(m)

    ckf = CubatureKalmanFilter(dim_x=n, dim_z=m, dt=1.0, hx=hx, fx=fx)
    ckf.Q = np.array(model.Q)
    ckf.R = np.array(model.R)
    ckf.x = np.array(x0, dtype=float).reshape(n, 1)
    ckf.P = np.array(P0, dtype=float)
    out = {k: [] for k in ("x", "P", "x_pred", "P_pred", "K", "innovation", "S")}
    for k in range(len(Y)):
        ckf.predict()
        out["x_pred"].append(ckf.x.ravel().copy())
        out["P_pred"].append(ckf.P.copy())
        if np.isnan(Y[k]).all():
            ckf.update(None)
            out["K"].append(np.zeros((n, m)))
            out["innovation"].append(np.full(m, np.nan))
            out["S"].append(np.full((m, m), np.nan))
        else:
            ckf.update(Y[k].reshape(m, 1))
            out["K"].append(np.array(ckf.K).copy())
            out["innovation"].append(np.asarray(ckf.y, dtype=float).ravel())
            out["S"].append(ckf.S.copy())
        out["x"].append(ckf.x.ravel().copy())
        out["P"].append(ckf.P.copy())
    return SimpleNamespace(**{k: np.array(v) for k, v in out.items()})
