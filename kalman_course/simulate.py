r"""Simulation de trajectoires et de mesures, reproductible (graine ou ``numpy.random.Generator``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg

from .models import LinearGaussianModel
from .results import freeze
from .validation import KalmanInputError, as_controls, as_vector

__all__ = ["Simulation", "simulate", "as_generator", "covariance_factor"]


@dataclass(frozen=True, eq=False)
class Simulation:
    """Trajectoire simulée : ``x`` (T, n) états vrais :math:`x_1…x_T`, ``y`` (T, m) mesures :math:`y_1…y_T`."""

    x: np.ndarray
    y: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "x", freeze(self.x))
        object.__setattr__(self, "y", freeze(self.y))


def as_generator(rng: Any) -> np.random.Generator:
    """Une graine entière ou un ``Generator`` ; ``None`` est refusé (tout tirage doit être reproductible)."""
    if isinstance(rng, np.random.Generator):
        return rng
    if isinstance(rng, (int, np.integer)) and not isinstance(rng, bool):
        return np.random.default_rng(int(rng))
    raise KalmanInputError(
        "« rng » doit être une graine entière ou un numpy.random.Generator "
        f"(tirages reproductibles) ; reçu {type(rng).__name__}."
    )


def covariance_factor(M: np.ndarray) -> np.ndarray:
    r"""Facteur :math:`L` tel que :math:`LL^T = M` pour une covariance semi-définie positive (par ``eigh``,
    donc valable aussi pour une covariance singulière, par exemple :math:`Q = 0`)."""
    lam, V = scipy.linalg.eigh(M)
    return V * np.sqrt(np.clip(lam, 0.0, None))


def simulate(model: LinearGaussianModel, x0: Any, n_steps: int, u: Any = None, *, rng: Any) -> Simulation:
    r"""Simule le système du cours pendant ``n_steps`` pas :

    .. math::

        x_{k} = A x_{k-1} + B u_{k-1} + \phi_{k-1},\quad \phi \sim \mathcal N(0, Q),\qquad
        y_{k} = C x_{k} + \psi_{k},\quad \psi \sim \mathcal N(0, R)

    ``x0`` (n,) est l'état vrai initial (non aléatoire) ; ``u`` (T, p) ou (T,) si p = 1 ;
    ``rng`` est obligatoire : une graine entière ou un ``numpy.random.Generator``.
    Renvoie :class:`Simulation` avec ``x`` (T, n) et ``y`` (T, m), alignés sur ``kalman_filter``.
    """
    if not isinstance(n_steps, (int, np.integer)) or isinstance(n_steps, bool) or n_steps < 1:
        raise KalmanInputError(f"« n_steps » doit être un entier ≥ 1 ; reçu {n_steps!r}.")
    gen = as_generator(rng)
    n, m = model.n_state, model.n_obs
    x = as_vector("x0", x0, n)
    U = as_controls("u", u, int(n_steps), model.n_control)
    w = gen.standard_normal((n_steps, n)) @ covariance_factor(model.Q).T
    v = gen.standard_normal((n_steps, m)) @ covariance_factor(model.R).T
    xs = np.empty((n_steps, n))
    for k in range(n_steps):
        x = model.A @ x + w[k]
        if U is not None:
            x = x + model.B @ U[k]
        xs[k] = x
    ys = xs @ model.C.T + v
    return Simulation(x=xs, y=ys)
