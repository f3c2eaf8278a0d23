r"""Simulation de trajectoires et de mesures, reproductible (graine ou ``numpy.random.Generator``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .linalg import covariance_factor
from .models import LinearGaussianModel, NonlinearModel
from .results import freeze_fields
from .validation import KalmanInputError, as_controls, as_vector, check_instance

__all__ = ["Simulation", "as_generator", "covariance_factor", "simulate", "check_positive_int"]


@dataclass(frozen=True, eq=False)
class Simulation:
    """Trajectoire simulée : ``x`` (T, n) états vrais :math:`x_1…x_T`, ``y`` (T, m) mesures :math:`y_1…y_T`."""

    x: np.ndarray
    y: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, "x", "y")


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


def check_positive_int(name: str, value: Any, minimum: int = 1) -> int:
    """Un entier ≥ ``minimum`` (un booléen est refusé)."""
    if not isinstance(value, (int, np.integer)) or isinstance(value, bool) or value < minimum:
        raise KalmanInputError(f"« {name} » doit être un entier ≥ {minimum} ; reçu {value!r}.")
    return int(value)


def simulate(model: Any, x0: Any, n_steps: int, u: Any = None, *, rng: Any) -> Simulation:
    r"""Simule le système pendant ``n_steps`` pas, linéaire (:class:`~kalman_course.LinearGaussianModel`)

    .. math::

        x_{k} = A x_{k-1} + B u_{k-1} + \phi_{k-1},\quad \phi \sim \mathcal N(0, Q),\qquad
        y_{k} = C x_{k} + \psi_{k},\quad \psi \sim \mathcal N(0, R)

    ou non linéaire (:class:`~kalman_course.NonlinearModel`, bruits de jacobiennes :math:`W`, :math:`V`) :

    .. math::

        x_{k} = f(x_{k-1}, u_{k-1}) + W\phi_{k-1},\qquad y_{k} = h(x_{k}) + V\psi_{k}.

    ``x0`` (n,) est l'état vrai initial (non aléatoire) ; ``u`` (T, p) ou (T,) si p = 1 ;
    ``rng`` est obligatoire : une graine entière ou un ``numpy.random.Generator``. Les bruits d'état puis
    de mesure sont tirés en bloc, dans cet ordre.
    Renvoie :class:`Simulation` avec ``x`` (T, n) et ``y`` (T, m), alignés sur les filtres.
    """
    check_instance("model", model, (LinearGaussianModel, NonlinearModel))
    n_steps = check_positive_int("n_steps", n_steps)
    gen = as_generator(rng)
    n, m = model.n_state, model.n_obs
    x = as_vector("x0", x0, n)
    U = as_controls("u", u, n_steps, model.n_control)
    if isinstance(model, LinearGaussianModel) and model.time_varying:
        return _simulate_time_varying(model, x, n_steps, U, gen)
    w = gen.standard_normal((n_steps, model.Q.shape[0])) @ covariance_factor(model.Q).T
    v = gen.standard_normal((n_steps, model.R.shape[0])) @ covariance_factor(model.R).T
    xs = np.empty((n_steps, n))
    if isinstance(model, LinearGaussianModel):
        for k in range(n_steps):
            x = model.A @ x + w[k]
            if U is not None:
                x = x + model.B @ U[k]
            xs[k] = x
        return Simulation(x=xs, y=xs @ model.C.T + v)
    ys = np.empty((n_steps, m))
    for k in range(n_steps):
        u_k = None if U is None else U[k]
        x = model.transition(x, u_k) + model.process_noise_gain(x, u_k) @ w[k]
        xs[k] = x
        ys[k] = model.observe(x) + model.measurement_noise_gain(x) @ v[k]
    return Simulation(x=xs, y=ys)


def _simulate_time_varying(model: LinearGaussianModel, x: np.ndarray, n_steps: int, U, gen) -> Simulation:
    r"""Simulation d'un modèle variable dans le temps : le pas ``k`` avec :math:`A_k, B_k, Q_k` puis la mesure
    avec :math:`C_k, R_k` (``n_steps`` doit valoir ``model.n_steps``). Bruits tirés en bloc, comme
    :func:`simulate`, puis mis à l'échelle pas par pas."""
    steps = model.steps(n_steps)
    z_w = gen.standard_normal((n_steps, model.n_state))
    z_v = gen.standard_normal((n_steps, model.n_obs))
    xs = np.empty((n_steps, model.n_state))
    ys = np.empty((n_steps, model.n_obs))
    for k, mk in enumerate(steps):
        x = mk.A @ x + covariance_factor(mk.Q) @ z_w[k]
        if U is not None:
            x = x + mk.B @ U[k]
        xs[k] = x
        ys[k] = mk.C @ x + covariance_factor(mk.R) @ z_v[k]
    return Simulation(x=xs, y=ys)
