r"""Scénario « croissance » : le modèle non linéaire de Gordon, Salmond & Smith (1993) et Kitagawa (1996),
banc d'essai classique des filtres particulaires :

.. math::

    x_k = \frac{x_{k-1}}{2} + \frac{25\,x_{k-1}}{1 + x_{k-1}^2} + 8\cos(1{,}2\,k) + w_k,\qquad
    y_k = \frac{x_k^2}{20} + v_k,\qquad w_k \sim \mathcal N(0, 10),\ v_k \sim \mathcal N(0, 1).

La mesure ne voit que :math:`x_k^2` : :math:`x_k` et :math:`-x_k` l'expliquent aussi bien, et la loi a
posteriori a souvent **deux modes**. Un filtre gaussien (EKF, UKF) n'en garde qu'un — souvent le mauvais —
alors que le nuage de particules garde les deux. Le terme :math:`8\cos(1{,}2k)` est passé comme une
commande (le modèle du paquet n'a pas de temps explicite) : la ligne de :math:`y_k` porte :math:`8\cos(1{,}2\,k)`,
la commande :math:`u_{k-1}` de la transition vers :math:`x_k`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.models import NonlinearModel
from ..core.results import freeze_fields
from ..core.simulation import as_generator, check_positive_int, simulate
from ..filters.extended import extended_kalman_filter
from ..filters.particle import particle_filter
from ..filters.unscented import unscented_kalman_filter

__all__ = [
    "GROWTH_Q",
    "GROWTH_R",
    "GROWTH_X_TRUE0",
    "GROWTH_X0",
    "GROWTH_P0",
    "GROWTH_STEPS",
    "GROWTH_SEED",
    "GROWTH_PARTICLES",
    "GROWTH_UKF",
    "growth_transition",
    "growth_observation",
    "growth_controls",
    "growth_model",
    "GrowthData",
    "growth_data",
    "GrowthRuns",
    "growth_filters",
    "growth_comparison",
]

#: Variance du bruit d'état.
GROWTH_Q = 10.0
#: Variance du bruit de mesure.
GROWTH_R = 1.0
#: État vrai initial.
GROWTH_X_TRUE0 = 0.1
#: A priori des filtres : :math:`\hat x_0 = 0`, :math:`P_0 = 5`.
GROWTH_X0 = 0.0
GROWTH_P0 = 5.0
#: Nombre de pas.
GROWTH_STEPS = 50
#: Graine des données du chapitre.
GROWTH_SEED = 4
#: Nombre de particules du chapitre.
GROWTH_PARTICLES = 2000
#: Points sigma de l'UKF (n = 1) : :math:`\alpha = 1`, :math:`\beta = 2`, :math:`\kappa = 3 - n = 2`.
GROWTH_UKF = {"alpha": 1.0, "beta": 2.0, "kappa": 2.0}


def growth_transition(x: Any, u: Any) -> np.ndarray:
    r""":math:`f(x, u) = x/2 + 25x/(1 + x^2) + u` ; ``x`` (1,) ou (N, 1), ``u`` (1,)."""
    x = np.asarray(x, dtype=float)
    return x / 2.0 + 25.0 * x / (1.0 + x**2) + u


def growth_observation(x: Any) -> np.ndarray:
    r""":math:`h(x) = x^2/20` ; ``x`` (1,) ou (N, 1)."""
    x = np.asarray(x, dtype=float)
    return x**2 / 20.0


def growth_controls(n_steps: int = GROWTH_STEPS) -> np.ndarray:
    r"""Les « commandes » : ligne :math:`k` (:math:`k = 1\dots T`) :math:`8\cos(1{,}2\,k)`, terme de la transition vers :math:`x_k`, forme (T, 1)."""
    n_steps = check_positive_int("n_steps", n_steps)
    return 8.0 * np.cos(1.2 * np.arange(1, n_steps + 1))[:, None]


def growth_model(Q: float = GROWTH_Q, R: float = GROWTH_R) -> NonlinearModel:
    r"""Le modèle (vectorisé) avec ses jacobiennes :math:`F = 1/2 + 25(1 - x^2)/(1 + x^2)^2`, :math:`H = x/10`."""
    return NonlinearModel(
        growth_transition,
        growth_observation,
        [[Q]],
        [[R]],
        f_jacobian=lambda x, u: np.array([[0.5 + 25.0 * (1.0 - x[0] ** 2) / (1.0 + x[0] ** 2) ** 2]]),
        h_jacobian=lambda x: np.array([[x[0] / 10.0]]),
        n_control=1,
        vectorized=True,
    )


@dataclass(frozen=True, eq=False)
class GrowthData:
    """Données : ``t`` (T,) indices 1…T, ``x_true`` (T, 1), ``y`` (T, 1), ``u`` (T, 1)."""

    t: np.ndarray
    x_true: np.ndarray
    y: np.ndarray
    u: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, "t", "x_true", "y", "u")


def growth_data(n_steps: int = GROWTH_STEPS, rng: Any = GROWTH_SEED) -> GrowthData:
    """Trajectoire et mesures simulées (:func:`~kalman_course.simulate`, graine ``rng``)."""
    u = growth_controls(n_steps)
    sim = simulate(growth_model(), [GROWTH_X_TRUE0], n_steps, u=u, rng=rng)
    return GrowthData(t=np.arange(1, n_steps + 1, dtype=float), x_true=sim.x, y=sim.y, u=u)


def growth_filters(data: GrowthData | None = None, n_particles: int = GROWTH_PARTICLES, rng: Any = 1,
                   keep_particles: bool = False) -> dict:
    r"""EKF, UKF (:data:`GROWTH_UKF`) et filtre particulaire sur les mesures ``data`` ; renvoie
    ``{"EKF": …, "UKF": …, "filtre particulaire": …}``."""
    data = growth_data() if data is None else data
    model = growth_model()
    return {
        "EKF": extended_kalman_filter(model, data.y, [GROWTH_X0], [[GROWTH_P0]], data.u),
        "UKF": unscented_kalman_filter(model, data.y, [GROWTH_X0], [[GROWTH_P0]], data.u, **GROWTH_UKF),
        "filtre particulaire": particle_filter(model, data.y, [GROWTH_X0], [[GROWTH_P0]], data.u,
                                               n_particles=n_particles, rng=rng, keep_particles=keep_particles),
    }


@dataclass(frozen=True, eq=False)
class GrowthRuns:
    """Erreurs quadratiques moyennes (sur le temps) de chaque filtre pour ``n_runs`` jeux de données :
    ``rmse[nom]`` (n_runs,)."""

    rmse: dict
    n_runs: int

    def median(self) -> dict:
        """Médiane des erreurs quadratiques moyennes de chaque filtre."""
        return {name: float(np.median(v)) for name, v in self.rmse.items()}


def growth_comparison(n_runs: int = 50, n_particles: int = GROWTH_PARTICLES, rng: Any = GROWTH_SEED) -> GrowthRuns:
    """Erreur quadratique moyenne de l'EKF, de l'UKF et du filtre particulaire sur ``n_runs`` jeux de
    données indépendants (graines tirées de ``rng``)."""
    n_runs = check_positive_int("n_runs", n_runs)
    gen = as_generator(rng)
    rmse: dict[str, list] = {}
    for _ in range(n_runs):
        data = growth_data(rng=gen)
        for name, res in growth_filters(data, n_particles, rng=gen).items():
            rmse.setdefault(name, []).append(float(np.sqrt(np.mean((res.x[:, 0] - data.x_true[:, 0]) ** 2))))
    return GrowthRuns(rmse={k: np.array(v) for k, v in rmse.items()}, n_runs=n_runs)
