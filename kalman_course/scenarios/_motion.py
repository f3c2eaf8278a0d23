r"""Trajectoires simulées communes aux scénarios et aux tests : une cible à vitesse presque constante
(:func:`simulate_cv`) et une cible qui vire (:func:`simulate_turning`). Les modèles eux-mêmes viennent du
constructeur unique du paquet, :func:`~kalman_course.core.motion.constant_velocity`, et du virage coordonné
exact, :func:`~kalman_course.core.motion.turn_transition`.

Vitesse presque constante dans le plan (état :math:`[p_x, p_y, v_x, v_y]`), accélération constante pendant
le pas d'écart-type :math:`\sigma_a` (m/s²) sur chaque axe :

.. math::

    x_k = A x_{k-1} + G a_{k-1},\quad a_{k-1} \sim \mathcal N(0, \sigma_a^2 I_2),\quad
    A = \begin{bmatrix} I_2 & \Delta t\, I_2 \\ 0 & I_2 \end{bmatrix},\quad
    G = \begin{bmatrix} \tfrac{\Delta t^2}{2} I_2 \\ \Delta t\, I_2 \end{bmatrix}

(``constant_velocity(dt, accel_std=σ_a)`` : :math:`Q = \sigma_a^2 GG^T`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..core.motion import acceleration_gain, constant_velocity, turn_transition
from ..core.simulation import as_generator
from ..core.validation import KalmanInputError, as_float_array, as_vector

__all__ = ["simulate_cv", "simulate_turning"]


def simulate_cv(x0, n_steps: int, dt: float, accel_std: float, rng) -> np.ndarray:
    r"""États vrais :math:`x_1, \dots, x_T` (T, 4) partant de ``x0`` (4,), accélérations tirées avec ``rng``."""
    gen = as_generator(rng)
    A = constant_velocity(dt, accel_std=accel_std).A
    G = acceleration_gain(dt)
    a = accel_std * gen.standard_normal((n_steps, 2))
    xs = np.empty((n_steps, 4))
    x = np.asarray(x0, dtype=float)
    for k in range(n_steps):
        x = A @ x + G @ a[k]
        xs[k] = x
    return xs


def simulate_turning(turn_rate: Any, x0: Any, dt: float = 1.0, position_std: float = 0.0,
                     rng: Any = None) -> tuple[np.ndarray, np.ndarray]:
    r"""Une cible qui vire : le virage coordonné exact (:func:`~kalman_course.core.motion.turn_transition`),
    sans bruit d'état — la vitesse garde sa norme et tourne de :math:`\omega_k\Delta t` au pas :math:`k`.

    ``turn_rate`` (T,) : vitesse de rotation :math:`\omega_k` (rad/s) du pas qui mène à l'instant ``k`` ;
    ``x0`` (4,) : :math:`[p_x, p_y, v_x, v_y]` avant le premier pas ; ``dt`` : pas (s) ; ``position_std`` :
    écart-type (m) des relevés de position, tirés avec ``rng`` (graine ou ``numpy.random.Generator``).

    Renvoie ``(truth (T, 5), y (T, 2))`` : les états vrais :math:`[p_x, p_y, v_x, v_y, \omega]` après chaque
    pas et les relevés de position :math:`y_k = [p_x, p_y]_k + \psi_k`, :math:`\psi_k \sim
    \mathcal N(0, \sigma^2 I_2)` (``y`` sans bruit si ``position_std = 0``)."""
    w = as_float_array("turn_rate", turn_rate)
    if w.ndim != 1 or w.size == 0:
        raise KalmanInputError(f"« turn_rate » doit être une suite (T,) de vitesses de rotation (rad/s) ; reçu {w.shape}.")
    x = np.append(as_vector("x0", x0, 4), 0.0)
    truth = np.empty((w.size, 5))
    for k, rate in enumerate(w):
        x[4] = rate
        x = turn_transition(x, dt)
        truth[k] = x
    y = truth[:, :2].copy()
    if position_std:
        y += position_std * as_generator(rng).standard_normal(y.shape)
    return truth, y
