r"""Simulation de trajectoires et de mesures, reproductible (graine ou ``numpy.random.Generator``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg

from .models import LinearGaussianModel
from .results import freeze_fields
from .validation import KalmanInputError, as_controls, as_square_matrix, as_vector, check_psd

__all__ = ["MonteCarlo", "Simulation", "as_generator", "covariance_factor", "monte_carlo", "simulate"]


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


@dataclass(frozen=True, eq=False)
class MonteCarlo:
    r"""Résultat de :func:`monte_carlo` sur ``R`` tirages indépendants de ``T`` pas.

    ``x0`` (R, n) : états initiaux vrais :math:`x_0` ; ``x`` (R, T, n) : :math:`x_1 \dots x_T` ;
    ``y`` (R, T, m) : mesures ; ``x_hat`` (R, T, n) : estimations :math:`\hat x_1 \dots \hat x_T` ;
    ``x0_hat`` (n,) : l'estimation initiale :math:`\hat x_0` commune à tous les tirages.
    """

    x0: np.ndarray
    x: np.ndarray
    y: np.ndarray
    x_hat: np.ndarray
    x0_hat: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, "x0", "x", "y", "x_hat", "x0_hat")

    @property
    def n_runs(self) -> int:
        """Nombre de tirages ``R``."""
        return self.x.shape[0]

    @property
    def errors(self) -> np.ndarray:
        r"""Erreurs :math:`e_n = \hat x_n - x_n` (signe du cours) pour :math:`n = 0 \dots T`, forme (R, T+1, n)."""
        e0 = self.x0_hat[None, :] - self.x0
        return np.concatenate([e0[:, None, :], self.x_hat - self.x], axis=1)

    def mean_error(self) -> np.ndarray:
        r"""Moyenne empirique :math:`\overline{e_n}` sur les tirages, forme (T+1, n)."""
        return self.errors.mean(axis=0)

    def mean_error_sem(self) -> np.ndarray:
        r"""Écart-type de la moyenne empirique (erreur standard :math:`s/\sqrt R`), forme (T+1, n)."""
        return self.errors.std(axis=0, ddof=1) / np.sqrt(self.n_runs)


def monte_carlo(
    model: LinearGaussianModel,
    estimator: Any,
    n_steps: int,
    n_runs: int,
    *,
    x0_mean: Any,
    x0_cov: Any,
    x0_hat: Any,
    rng: Any,
    u: Any = None,
) -> MonteCarlo:
    r"""Expérience de Monte-Carlo : ``n_runs`` trajectoires indépendantes, chacune estimée.

    Pour chaque tirage : :math:`x_0 \sim \mathcal N(\bar x_0, \Sigma_0)` (``x0_mean``, ``x0_cov``), puis
    :func:`simulate` sur ``n_steps`` pas (bruits :math:`\phi, \psi` tirés du même générateur), puis
    ``estimator(y)`` qui doit renvoyer les estimations :math:`\hat x_1 \dots \hat x_T` de forme (T, n),
    par exemple ``lambda y: kalman_filter(model, y, x0_hat, P0).x``.

    ``x0_hat`` (n,) est l'estimation initiale utilisée par ``estimator`` ; elle ne sert ici qu'à
    calculer :math:`e_0`. ``rng`` : graine entière ou ``numpy.random.Generator`` (obligatoire).
    """
    if not isinstance(n_runs, (int, np.integer)) or isinstance(n_runs, bool) or n_runs < 2:
        raise KalmanInputError(f"« n_runs » doit être un entier ≥ 2 ; reçu {n_runs!r}.")
    if not callable(estimator):
        raise KalmanInputError(
            f"« estimator » doit être une fonction y (T, m) → x̂ (T, n) ; reçu {type(estimator).__name__}."
        )
    gen = as_generator(rng)
    n = model.n_state
    mean = as_vector("x0_mean", x0_mean, n)
    cov = check_psd("x0_cov", as_square_matrix("x0_cov", x0_cov, n))
    x0_hat_arr = as_vector("x0_hat", x0_hat, n)
    L0 = covariance_factor(cov)
    x0s = mean + gen.standard_normal((n_runs, n)) @ L0.T
    xs, ys, xhs = [], [], []
    for r in range(n_runs):
        sim = simulate(model, x0s[r], n_steps, u, rng=gen)
        x_hat = np.asarray(estimator(sim.y), dtype=float)
        if x_hat.shape != (n_steps, n):
            raise KalmanInputError(
                f"« estimator » doit renvoyer un tableau de forme ({n_steps}, {n}) ; reçu {x_hat.shape}."
            )
        xs.append(sim.x)
        ys.append(sim.y)
        xhs.append(x_hat)
    return MonteCarlo(x0=x0s, x=np.array(xs), y=np.array(ys), x_hat=np.array(xhs), x0_hat=x0_hat_arr)
