r"""Mouvement à vitesse constante dans le plan (état :math:`[p_x, p_y, v_x, v_y]`), commun aux scénarios.

Accélération blanche constante par morceaux d'écart-type :math:`\sigma_a` (m/s²) sur chaque axe :

.. math::

    x_k = F x_{k-1} + G a_{k-1},\quad
    F = \begin{bmatrix} I_2 & \Delta t\, I_2 \\ 0 & I_2 \end{bmatrix},\quad
    G = \begin{bmatrix} \tfrac{\Delta t^2}{2} I_2 \\ \Delta t\, I_2 \end{bmatrix},\quad
    Q = \sigma_a^2\, G G^T .
"""

from __future__ import annotations

import numpy as np

from ..core.simulation import as_generator

__all__ = ["cv_transition", "cv_process_noise", "simulate_cv"]


def cv_transition(dt: float) -> np.ndarray:
    """Matrice de transition :math:`F` (4, 4) du mouvement à vitesse constante."""
    F = np.eye(4)
    F[0, 2] = F[1, 3] = dt
    return F


def _cv_noise_gain(dt: float) -> np.ndarray:
    return np.vstack([0.5 * dt**2 * np.eye(2), dt * np.eye(2)])


def cv_process_noise(dt: float, accel_std: float) -> np.ndarray:
    r"""Covariance :math:`Q = \sigma_a^2 G G^T` (4, 4) de l'accélération blanche constante par morceaux."""
    G = _cv_noise_gain(dt)
    return accel_std**2 * G @ G.T


def simulate_cv(x0, n_steps: int, dt: float, accel_std: float, rng) -> np.ndarray:
    r"""États vrais :math:`x_1, \dots, x_T` (T, 4) partant de ``x0`` (4,), accélérations tirées avec ``rng``."""
    gen = as_generator(rng)
    F, G = cv_transition(dt), _cv_noise_gain(dt)
    a = accel_std * gen.standard_normal((n_steps, 2))
    xs = np.empty((n_steps, 4))
    x = np.asarray(x0, dtype=float)
    for k in range(n_steps):
        x = F @ x + G @ a[k]
        xs[k] = x
    return xs
