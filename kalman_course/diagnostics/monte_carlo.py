r"""Expériences de Monte-Carlo : beaucoup de trajectoires simulées, chacune estimée.

Pour un modèle linéaire filtré par le filtre de Kalman, les ``N`` tirages sont filtrés ensemble
(:func:`~kalman_course.kalman_filter_runs` : la récurrence des covariances une seule fois) ; la forme
« fonction » (``estimator(y)``) reste pour tout autre estimateur. Les tirages aléatoires se font
toujours dans le même ordre (états initiaux, puis pour chaque tirage ses bruits d'état et de mesure),
quelle que soit la forme : une graine donne les mêmes trajectoires.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg

from ..core.linalg import covariance_factor
from ..core.models import LinearGaussianModel
from ..core.results import freeze, freeze_fields
from ..core.simulation import as_generator, check_positive_int
from ..core.validation import (
    KalmanInputError,
    as_controls,
    as_square_matrix,
    as_vector,
    check_instance,
    check_pd,
    check_psd,
)
from ..filters.kalman import kalman_filter_runs
from .consistency import ChiSquareTest, chi2_mean_test, nees, nis

__all__ = ["MonteCarlo", "monte_carlo", "simulate_runs", "ConsistencyRuns", "monte_carlo_consistency"]


def simulate_runs(model: LinearGaussianModel, x0: Any, n_runs: int, n_steps: int, U: np.ndarray | None,
                  gen: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""``n_runs`` trajectoires du modèle linéaire, propagées en lot, avec les mêmes tirages, dans le même
    ordre, que des appels successifs à :func:`~kalman_course.simulate` avec le générateur ``gen``.

    ``x0`` : états initiaux (N, n) déjà tirés, ou fonction ``gen -> (n,)`` appelée pour chaque tirage juste
    avant ses bruits. Renvoie ``(x0 (N, n), x (N, T, n), y (N, T, m))``."""
    n, m = model.n_state, model.n_obs
    LQ, LR = covariance_factor(model.Q), covariance_factor(model.R)
    x0s = np.empty((n_runs, n)) if callable(x0) else np.asarray(x0, dtype=float)
    W = np.empty((n_runs, n_steps, n))
    V = np.empty((n_runs, n_steps, m))
    for r in range(n_runs):
        if callable(x0):
            x0s[r] = x0(gen)
        W[r] = gen.standard_normal((n_steps, n)) @ LQ.T
        V[r] = gen.standard_normal((n_steps, m)) @ LR.T
    BU = None if U is None else U @ model.B.T
    xs = np.empty((n_runs, n_steps, n))
    X = x0s
    for k in range(n_steps):
        X = X @ model.A.T + W[:, k]
        if BU is not None:
            X = X + BU[k]
        xs[:, k] = X
    return x0s, xs, xs @ model.C.T + V


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
        r"""Écart-type de la moyenne empirique (erreur type :math:`s/\sqrt R`), forme (T+1, n)."""
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
    P0: Any = None,
    batch: bool = False,
) -> MonteCarlo:
    r"""Expérience de Monte-Carlo : ``n_runs`` trajectoires indépendantes, chacune estimée.

    Pour chaque tirage : :math:`x_0 \sim \mathcal N(\bar x_0, \Sigma_0)` (``x0_mean``, ``x0_cov``), puis
    simulation de ``model`` sur ``n_steps`` pas (bruits :math:`\phi, \psi` tirés du même générateur), puis
    estimation :

    * ``estimator=None`` : le filtre de Kalman de ``model`` parti de :math:`(\hat x_0, P_0)` (``x0_hat``,
      ``P0``), pour tous les tirages à la fois (:func:`~kalman_course.kalman_filter_runs`) ;
    * ``estimator`` fonction : ``estimator(y)`` doit renvoyer les estimations :math:`\hat x_1 \dots \hat x_T`
      de forme (T, n) (tout autre estimateur, par exemple ``lambda y: linear_estimator(model, y, x0_hat, K)``) ;
      avec ``batch=True``, ``estimator(Y)`` reçoit les mesures de tous les tirages, (R, T, m), et renvoie
      (R, T, n) (par exemple ``lambda Y: linear_estimator_runs(model, Y, x0_hat, K)``).

    ``x0_hat`` (n,) est l'estimation initiale de l'estimateur ; elle sert aussi à calculer :math:`e_0`.
    ``rng`` : graine entière ou ``numpy.random.Generator`` (obligatoire).
    """
    check_instance("model", model, LinearGaussianModel, "les expériences de Monte-Carlo simulent un modèle linéaire")
    n_runs = check_positive_int("n_runs", n_runs, minimum=2)
    n_steps = check_positive_int("n_steps", n_steps)
    if estimator is not None and not callable(estimator):
        raise KalmanInputError(
            "« estimator » doit être une fonction y (T, m) → x̂ (T, n), ou None pour le filtre de Kalman "
            f"du modèle ; reçu {type(estimator).__name__}."
        )
    if estimator is None and P0 is None:
        raise KalmanInputError("Avec estimator=None (filtre de Kalman), donnez « P0 », la covariance initiale du filtre.")
    gen = as_generator(rng)
    n = model.n_state
    mean = as_vector("x0_mean", x0_mean, n)
    cov = check_psd("x0_cov", as_square_matrix("x0_cov", x0_cov, n))
    x0_hat_arr = as_vector("x0_hat", x0_hat, n)
    U = as_controls("u", u, n_steps, model.n_control)
    x0s = mean + gen.standard_normal((n_runs, n)) @ covariance_factor(cov).T
    _, xs, ys = simulate_runs(model, x0s, n_runs, n_steps, U, gen)
    if estimator is None:
        xhs = kalman_filter_runs(model, ys, x0_hat_arr, P0, U).x
    elif batch:
        xhs = np.asarray(estimator(ys), dtype=float)
        if xhs.shape != (n_runs, n_steps, n):
            raise KalmanInputError(
                f"« estimator » (batch=True) doit renvoyer un tableau de forme ({n_runs}, {n_steps}, {n}) ; "
                f"reçu {xhs.shape}."
            )
    else:
        xhs = np.empty((n_runs, n_steps, n))
        for r in range(n_runs):
            x_hat = np.asarray(estimator(ys[r]), dtype=float)
            if x_hat.shape != (n_steps, n):
                raise KalmanInputError(
                    f"« estimator » doit renvoyer un tableau de forme ({n_steps}, {n}) ; reçu {x_hat.shape}."
                )
            xhs[r] = x_hat
    return MonteCarlo(x0=x0s, x=xs, y=ys, x_hat=xhs, x0_hat=x0_hat_arr)


@dataclass(frozen=True, eq=False)
class ConsistencyRuns:
    r"""Résultat de :func:`monte_carlo_consistency` : ``nees`` (R, T) et ``nis`` (R, T) de ``R``
    tirages indépendants ; ``n_state`` = :math:`n`, ``n_obs`` = :math:`m` (degrés de liberté)."""

    nees: np.ndarray
    nis: np.ndarray
    n_state: int
    n_obs: int

    def __post_init__(self) -> None:
        object.__setattr__(self, "nees", freeze(self.nees))
        object.__setattr__(self, "nis", freeze(self.nis))

    @property
    def n_runs(self) -> int:
        """Nombre de tirages ``R``."""
        return self.nees.shape[0]

    def nees_test(self, step: int = -1, *, level: float = 0.95) -> ChiSquareTest:
        r"""Test du :math:`\chi^2` sur la NEES moyenne des ``R`` tirages au pas ``step``
        (:math:`\sum_r \epsilon_k^{(r)} \sim \chi^2_{Rn}`)."""
        T = self.nees.shape[1]
        if isinstance(step, (bool, np.bool_)) or not isinstance(step, (int, np.integer)) or not -T <= step < T:
            raise KalmanInputError(f"« step » doit être un indice de pas entier entre {-T} et {T - 1} ; reçu {step!r}.")
        return chi2_mean_test(self.nees[:, step], self.n_state, level=level, quantity="NEES")


def monte_carlo_consistency(
    true_model: LinearGaussianModel,
    n_steps: int,
    n_runs: int,
    *,
    x0_hat: Any,
    P0: Any,
    rng: Any,
    filter_model: LinearGaussianModel | None = None,
    u: Any = None,
) -> ConsistencyRuns:
    r"""NEES et NIS de ``n_runs`` tirages indépendants : pour chaque tirage,
    :math:`x_0 \sim \mathcal N(\hat x_0, P_0)` (l'hypothèse d'initialisation du filtre), simulation de
    ``true_model`` sur ``n_steps`` pas (:func:`simulate`), filtre de Kalman avec ``filter_model``
    (``true_model`` par défaut, c'est-à-dire un filtre bien réglé) depuis :math:`(\hat x_0, P_0)`.

    Paramètres : ``x0_hat`` (n,), ``P0`` (n, n) définie positive, ``u`` (T, p) ou ``None``,
    ``rng`` graine entière ou ``numpy.random.Generator`` (obligatoire).
    Renvoie :class:`ConsistencyRuns` (``nees`` et ``nis`` de forme (R, T)).
    """
    for name, model in (("true_model", true_model), ("filter_model", filter_model)):
        if model is not None and not isinstance(model, LinearGaussianModel):
            raise KalmanInputError(f"« {name} » doit être un LinearGaussianModel ; reçu {type(model).__name__}.")
    fmodel = true_model if filter_model is None else filter_model
    dims = ("n_state", "n_obs", "n_control")
    if any(getattr(fmodel, d) != getattr(true_model, d) for d in dims):
        raise KalmanInputError(
            "« filter_model » doit avoir les dimensions de « true_model » (états, mesures, commandes) ; "
            f"reçu {tuple(getattr(fmodel, d) for d in dims)} au lieu de {tuple(getattr(true_model, d) for d in dims)}."
        )
    T = check_positive_int("n_steps", n_steps)
    R = check_positive_int("n_runs", n_runs, minimum=2)
    gen = as_generator(rng)
    n = true_model.n_state
    x0h = as_vector("x0_hat", x0_hat, n)
    P0_arr = check_pd("P0", as_square_matrix("P0", P0, n))
    U = as_controls("u", u, T, true_model.n_control)
    L0 = scipy.linalg.cholesky(P0_arr, lower=True)  # x0 = x̂0 + L0 ξ, ξ ~ N(0, I)
    # x0 tiré juste avant les bruits de son tirage (ordre des tirages de l'expérience)
    _, xs, ys = simulate_runs(true_model, lambda g: x0h + L0 @ g.standard_normal(n), R, T, U, gen)
    runs = kalman_filter_runs(fmodel, ys, x0h, P0_arr, U)
    nees_runs = np.array([nees(xs[r], runs.run(r)) for r in range(R)])
    nis_runs = np.array([nis(runs.run(r)) for r in range(R)])
    return ConsistencyRuns(nees=nees_runs, nis=nis_runs, n_state=n, n_obs=true_model.n_obs)


