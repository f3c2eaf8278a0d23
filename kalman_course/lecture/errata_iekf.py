r"""Les mises à jour itérées **telles qu'écrites** dans les notes (fausses), pour montrer l'erratum.

Ne pas utiliser pour filtrer : la forme correcte est :func:`kalman_course.ekf.iekf_update` (Gauss–Newton).
Chaque fonction renvoie la suite des itérés :math:`x^{(0)} = \hat x^-, x^{(1)}, \dots`, forme (N+1, n).

* :func:`table_literal_iterates` — tableau de l'EKF itéré des notes (erratum 000-6), avec la seule coquille
  :math:`f \to g` corrigée : :math:`x^{(i+1)} = \hat x^- + K_i\,[y - g(\hat x^-)]`, seul le gain est
  relinéarisé en :math:`x^{(i)}`. Converge, mais pas vers le maximum a posteriori.
* :func:`no_correction_iterates` — innovation évaluée à l'itéré mais sans le terme
  :math:`-H_i(\hat x^- - x^{(i)})` : :math:`x^{(i+1)} = \hat x^- + K_i\,[y - g(x^{(i)})]` ; diverge
  dans l'exemple du radar.
* :func:`measurement_only_iterates` — la boucle des notes SE(3) (erratum 004-9),
  :math:`x^{(i+1)} = x^{(i)} + K_i\,[y - g(x^{(i)})]` : l'a priori est oublié après le premier pas, la boucle
  converge vers l'ajustement aux seules mesures.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..core.linalg import kalman_gain
from ..core.validation import as_gaussian, as_vector
from ..filters.extended import check_model
from ..filters.iteration import DEFAULT_MAX_ITER, DEFAULT_TOL, iterate

__all__ = ["table_literal_iterates", "no_correction_iterates", "measurement_only_iterates"]


def _iterate(model, x_pred, P_pred, y, max_iter, tol, step) -> np.ndarray:
    """La boucle commune (:func:`~kalman_course.filters.iteration.iterate`) avec le pas ``step`` des notes."""
    model = check_model(model)
    xp, Pp = as_gaussian(x_pred, P_pred, model.n_state, "x_pred", "P_pred")
    y_arr = as_vector("y", y, model.n_obs)
    R = model.measurement_noise(xp)

    def one_step(x_i):
        K_i = kalman_gain(Pp, model.observation_jacobian(x_i), R)[0]
        x_next = step(model, xp, x_i, y_arr, K_i)
        return x_next, float(np.linalg.norm(x_next - x_i)), None

    return iterate(xp, one_step, max_iter, tol).iterates


def table_literal_iterates(
    model, x_pred: Any, P_pred: Any, y: Any, max_iter: int = DEFAULT_MAX_ITER, tol: float = DEFAULT_TOL
) -> np.ndarray:
    r"""Tableau des notes (000), :math:`f\to g` corrigé : :math:`x^{(i+1)} = \hat x^- + K_i[y - g(\hat x^-)]`."""
    return _iterate(
        model, x_pred, P_pred, y, max_iter, tol,
        lambda m, xp, xi, y, K: xp + K.dot(m.residual(y, m.observe(xp))),
    )


def no_correction_iterates(
    model, x_pred: Any, P_pred: Any, y: Any, max_iter: int = DEFAULT_MAX_ITER, tol: float = DEFAULT_TOL
) -> np.ndarray:
    r"""Innovation à l'itéré sans terme de linéarisation : :math:`x^{(i+1)} = \hat x^- + K_i[y - g(x^{(i)})]`."""
    return _iterate(
        model, x_pred, P_pred, y, max_iter, tol,
        lambda m, xp, xi, y, K: xp + K.dot(m.residual(y, m.observe(xi))),
    )


def measurement_only_iterates(
    model, x_pred: Any, P_pred: Any, y: Any, max_iter: int = DEFAULT_MAX_ITER, tol: float = DEFAULT_TOL
) -> np.ndarray:
    r"""Boucle des notes SE(3) (004) : :math:`x^{(i+1)} = x^{(i)} + K_i[y - g(x^{(i)})]` (a priori oublié)."""
    return _iterate(
        model, x_pred, P_pred, y, max_iter, tol,
        lambda m, xp, xi, y, K: xi + K.dot(m.residual(y, m.observe(xi))),
    )
