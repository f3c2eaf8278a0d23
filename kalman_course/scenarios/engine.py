r"""Scénario « moteur d'avion » : l'exemple du cours (température, débit de carburant, thermomètre).

État :math:`x = (\theta_m, \theta_a)` : échauffement du moteur et de l'air autour de la sonde, en °C
au-dessus de l'air extérieur. Commande :math:`u` : débit de carburant (g/s). Mesure :math:`y` : tensions
(mV) de deux thermocouples, l'un sur le moteur, l'autre dans le flux d'air qui le refroidit.

.. math::

    x_{n+1} = A x_n + B u_n + \phi_n,\qquad y_{n+1} = C x_{n+1} + \psi_{n+1},

    A = \begin{pmatrix} 0{,}95 & 0{,}03\\ 0{,}02 & 0{,}96\end{pmatrix},\quad
    B = \begin{pmatrix} 0{,}5\\ 0\end{pmatrix},\quad
    C = s\begin{pmatrix} 1 & 0\\ 0{,}3 & 0{,}7\end{pmatrix},\quad s = 0{,}041\ \text{mV/°C}.

:math:`C` est l'**opérateur d'observation** du cours : il passe de l'espace d'état (°C) à l'espace des
mesures (mV). Il est inversible sans être l'identité, ce qui sert à illustrer les limites du gain
(:math:`K \to C^{-1}`) et l'initialisation (errata 001-4 à 001-6). Un pas de temps dure une seconde.
"""

from __future__ import annotations

import numpy as np

from ..core.models import LinearGaussianModel

__all__ = [
    "ENGINE_DT",
    "ENGINE_P0",
    "ENGINE_PHI",
    "ENGINE_PSI",
    "ENGINE_SEED",
    "ENGINE_SENSITIVITY",
    "ENGINE_STATE_NAMES",
    "ENGINE_X0_COV",
    "ENGINE_X0_HAT",
    "ENGINE_X0_MEAN",
    "engine_commands",
    "engine_model",
]

#: Durée d'un pas de temps (s).
ENGINE_DT = 1.0
#: Sensibilité des thermocouples (mV/°C), de l'ordre de celle d'un thermocouple de type K.
ENGINE_SENSITIVITY = 0.041
#: Graine des tirages du scénario.
ENGINE_SEED = 1960
#: Noms des composantes de l'état, pour les légendes.
ENGINE_STATE_NAMES = ("échauffement du moteur θ_m", "échauffement de l'air θ_a")

_A = np.array([[0.95, 0.03], [0.02, 0.96]])
_B = np.array([[0.5], [0.0]])
_C = ENGINE_SENSITIVITY * np.array([[1.0, 0.0], [0.3, 0.7]])
#: Covariance du bruit d'état par défaut (°C²) : écarts-types 0,3 °C et 0,2 °C par pas.
ENGINE_PHI = np.diag([0.3**2, 0.2**2])
#: Covariance du bruit de mesure par défaut (mV²) : écart-type de 0,5 °C ramené en mV.
ENGINE_PSI = (0.5 * ENGINE_SENSITIVITY) ** 2 * np.eye(2)
#: Loi de l'état initial vrai : moteur froid (échauffement nul), à 1 °C près.
ENGINE_X0_MEAN = np.zeros(2)
ENGINE_X0_COV = np.eye(2)
#: Estimation initiale volontairement fausse (°C) et covariance initiale du filtre (°C²).
ENGINE_X0_HAT = np.array([15.0, 5.0])
ENGINE_P0 = np.diag([15.0**2, 15.0**2])


def engine_model(Phi=None, Psi=None) -> LinearGaussianModel:
    r"""Le modèle du moteur ; ``Phi`` (2, 2) en °C² et ``Psi`` (2, 2) en mV² remplacent les valeurs par défaut.

    Renvoie un :class:`~kalman_course.models.LinearGaussianModel` avec ``A``, ``B`` (2, 1), ``C`` (2, 2),
    ``Q`` = :math:`\Phi`, ``R`` = :math:`\Psi`.
    """
    return LinearGaussianModel(
        A=_A,
        C=_C,
        Q=ENGINE_PHI if Phi is None else Phi,
        R=ENGINE_PSI if Psi is None else Psi,
        B=_B,
    )


def engine_commands(n_steps: int = 120) -> np.ndarray:
    """Profil de débit de carburant (g/s), forme (T, 1) : ralenti nul, plein régime à 5 g/s à partir de
    t = 10 s, réduit à 2 g/s à partir de t = 70 s."""
    t = np.arange(n_steps)
    u = np.where(t >= 10, 5.0, 0.0)
    u = np.where(t >= 70, 2.0, u)
    return u.reshape(-1, 1)
