r"""Scénario « pendule » (Särkkä, *Bayesian Filtering and Smoothing*, 2013, exemple 3.7) : un pendule
simple dont on ne mesure que la position horizontale de la masse.

État :math:`x = (\theta, \omega)` (angle en rad, vitesse angulaire en rad/s), discrétisation d'Euler de
:math:`\ddot\theta = -(g/L)\sin\theta` au pas :math:`\Delta t`, bruit de couple blanc de densité
:math:`q_c` :

.. math::

    f(x) = \begin{bmatrix} \theta + \omega\,\Delta t \\ \omega - (g/L)\sin\theta\,\Delta t \end{bmatrix},\qquad
    Q = q_c \begin{bmatrix} \Delta t^3/3 & \Delta t^2/2 \\ \Delta t^2/2 & \Delta t \end{bmatrix},\qquad
    h(x) = L\sin\theta,\qquad R = \sigma^2 .

Le modèle est vectorisé : ``f`` et ``h`` acceptent un état (2,) ou une pile d'états (N, 2) (points sigma,
particules). La mesure est ambiguë (:math:`\sin\theta = \sin(\pi - \theta)`) : seule la dynamique lève
l'ambiguïté.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.models import NonlinearModel
from ..core.results import freeze_fields
from ..core.simulation import as_generator, check_positive_int, simulate
from ..core.validation import KalmanInputError

__all__ = [
    "PENDULUM_DT",
    "PENDULUM_G_OVER_L",
    "PENDULUM_LENGTH",
    "PENDULUM_QC",
    "PENDULUM_R_STD",
    "PENDULUM_X_TRUE0",
    "PENDULUM_X0",
    "PENDULUM_P0",
    "PENDULUM_SEED",
    "PendulumData",
    "pendulum_transition",
    "pendulum_observation",
    "pendulum_model",
    "pendulum_data",
]

#: Pas de temps (s).
PENDULUM_DT = 0.01
#: :math:`g/L` (s⁻²), pour un pendule de 1 m.
PENDULUM_G_OVER_L = 9.81
#: Longueur du pendule (m).
PENDULUM_LENGTH = 1.0
#: Densité spectrale :math:`q_c` du bruit de couple (rad²/s³).
PENDULUM_QC = 0.1
#: Écart-type de la mesure de position horizontale (m).
PENDULUM_R_STD = 0.1
#: État vrai initial : lâché à 1,5 rad (86°) sans vitesse.
PENDULUM_X_TRUE0 = np.array([1.5, 0.0])
PENDULUM_X_TRUE0.setflags(write=False)
#: Estimation initiale des filtres (angle connu à 0,5 rad près, vitesse à 1 rad/s près).
PENDULUM_X0 = np.array([1.0, 0.0])
PENDULUM_X0.setflags(write=False)
#: Covariance initiale des filtres.
PENDULUM_P0 = np.diag([0.5**2, 1.0])
PENDULUM_P0.setflags(write=False)
#: Graine des données du chapitre.
PENDULUM_SEED = 7


def _check_positive(name: str, value: Any) -> float:
    if isinstance(value, bool) or not np.isscalar(value) or not np.isfinite(value) or value <= 0:
        raise KalmanInputError(f"« {name} » doit être un réel strictement positif ; reçu {value!r}.")
    return float(value)


def pendulum_transition(x: Any, dt: float = PENDULUM_DT, g_over_l: float = PENDULUM_G_OVER_L) -> np.ndarray:
    r""":math:`f(x)` (forme de ``x`` : (2,) ou (N, 2)) : un pas d'Euler de :math:`\ddot\theta = -(g/L)\sin\theta`."""
    x = np.asarray(x, dtype=float)
    theta, omega = x[..., 0], x[..., 1]
    return np.stack([theta + omega * dt, omega - g_over_l * np.sin(theta) * dt], axis=-1)


def pendulum_observation(x: Any, length: float = PENDULUM_LENGTH) -> np.ndarray:
    r""":math:`h(x) = L\sin\theta` (m) : forme (1,) pour un état (2,), (N, 1) pour une pile (N, 2)."""
    x = np.asarray(x, dtype=float)
    return length * np.sin(x[..., :1])


def pendulum_model(
    dt: float = PENDULUM_DT,
    qc: float = PENDULUM_QC,
    r_std: float = PENDULUM_R_STD,
    *,
    g_over_l: float = PENDULUM_G_OVER_L,
    length: float = PENDULUM_LENGTH,
    vectorized: bool = True,
) -> NonlinearModel:
    r"""Le modèle du pendule (voir l'en-tête), avec ses jacobiennes analytiques
    :math:`F = \begin{bmatrix}1 & \Delta t\\ -(g/L)\cos\theta\,\Delta t & 1\end{bmatrix}`,
    :math:`H = [L\cos\theta,\ 0]`. ``vectorized=False`` donne le même modèle, point par point."""
    dt, qc, r_std = _check_positive("dt", dt), _check_positive("qc", qc), _check_positive("r_std", r_std)
    g_over_l, length = _check_positive("g_over_l", g_over_l), _check_positive("length", length)
    Q = qc * np.array([[dt**3 / 3.0, dt**2 / 2.0], [dt**2 / 2.0, dt]])

    def F(x, u=None):
        return np.array([[1.0, dt], [-g_over_l * np.cos(x[0]) * dt, 1.0]])

    def H(x):
        return np.array([[length * np.cos(x[0]), 0.0]])

    return NonlinearModel(
        f=lambda x, u: pendulum_transition(x, dt, g_over_l),
        h=lambda x: pendulum_observation(x, length),
        Q=Q,
        R=[[r_std**2]],
        f_jacobian=F,
        h_jacobian=H,
        vectorized=vectorized,
    )


@dataclass(frozen=True, eq=False)
class PendulumData:
    r"""Données du pendule : ``t`` (T,) instants (s), ``x_true`` (T, 2) états vrais, ``y`` (T, 1) mesures
    (m), ``x0`` (2,) et ``P0`` (2, 2) l'initialisation des filtres."""

    t: np.ndarray
    x_true: np.ndarray
    y: np.ndarray
    x0: np.ndarray
    P0: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, "t", "x_true", "y", "x0", "P0")


def pendulum_data(
    n_steps: int = 500,
    rng: Any = PENDULUM_SEED,
    *,
    dt: float = PENDULUM_DT,
    qc: float = PENDULUM_QC,
    r_std: float = PENDULUM_R_STD,
) -> PendulumData:
    r"""Trajectoire et mesures simulées par :func:`~kalman_course.simulate` avec
    ``pendulum_model(dt, qc, r_std)`` depuis :data:`PENDULUM_X_TRUE0` (graine ``rng``)."""
    n_steps = check_positive_int("n_steps", n_steps)
    model = pendulum_model(dt, qc, r_std)
    sim = simulate(model, PENDULUM_X_TRUE0, n_steps, rng=as_generator(rng))
    return PendulumData(t=dt * np.arange(1, n_steps + 1), x_true=sim.x, y=sim.y, x0=PENDULUM_X0, P0=PENDULUM_P0)
