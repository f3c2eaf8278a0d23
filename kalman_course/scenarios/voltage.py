r"""Scénario « tension constante » (Welch & Bishop) : modèle et relevés reproductibles."""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import scipy.stats

from ..core.models import LinearGaussianModel
from ..core.simulation import as_generator
from ..core.results import FilterResult, freeze_fields
from ..diagnostics.monte_carlo import MonteCarlo, monte_carlo
from ..filters.kalman import kalman_filter
from ..lecture.errata import printed_recipe_filter

__all__ = [
    "TRUE_VOLTAGE",
    "VOLTAGE_NOISE_STD",
    "VOLTAGE_SEED",
    "constant_voltage_model",
    "constant_voltage_measurements",
    "voltage_run",
    "POSTERIOR_RUNS",
    "POSTERIOR_SEED",
    "posterior_experiment",
    "PosteriorCoverage",
    "posterior_coverage",
    "printed_recipe_comparison",
]

#: Tension vraie de l'exemple de Welch & Bishop (V).
TRUE_VOLTAGE = -0.37727
#: Écart-type du bruit du voltmètre (V) : :math:`\sigma = 0{,}1` V, donc :math:`\Psi = 0{,}01` V².
VOLTAGE_NOISE_STD = 0.1
#: Graine des mesures de l'exemple (toutes les figures du chapitre utilisent les mêmes relevés).
VOLTAGE_SEED = 20260


def constant_voltage_model(Q: float = 1e-5, R: float = VOLTAGE_NOISE_STD**2) -> LinearGaussianModel:
    r"""Modèle de la tension constante : :math:`A = C = 1`, pas de commande, :math:`\Phi = Q`, :math:`\Psi = R`."""
    return LinearGaussianModel(A=1.0, C=1.0, Q=Q, R=R)


def constant_voltage_measurements(n_steps: int = 50, rng=VOLTAGE_SEED) -> np.ndarray:
    r"""Relevés du voltmètre :math:`z_k = x + \psi_k`, :math:`\psi_k \sim \mathcal N(0, 0{,}1^2)`, forme (T,).

    La tension vraie est constante (:data:`TRUE_VOLTAGE`) : le bruit d'état :math:`\Phi = 10^{-5}` du
    filtre est une marge de modélisation, pas une dérive réelle (comme chez Welch & Bishop).
    """
    gen = as_generator(rng)
    return TRUE_VOLTAGE + VOLTAGE_NOISE_STD * gen.standard_normal(n_steps)


def voltage_run(R: float = VOLTAGE_NOISE_STD**2, Q: float = 1e-5, P0: float = 1.0,
                n_steps: int = 50) -> tuple[np.ndarray, FilterResult]:
    r"""Les relevés du chapitre (:func:`constant_voltage_measurements`) filtrés depuis :math:`\hat x_0 = 0`,
    :math:`P_0` = ``P0`` (V²), par le modèle :math:`\Phi` = ``Q``, :math:`\Psi` = ``R`` (V²). Renvoie
    ``(z, FilterResult)``."""
    z = constant_voltage_measurements(n_steps)
    return z, kalman_filter(constant_voltage_model(Q=Q, R=R), z, 0.0, P0)


#: Expérience de la loi a posteriori : tension constante tirée de N(0, 1), filtre exactement informé.
POSTERIOR_RUNS = 2000
POSTERIOR_SEED = 1961


def posterior_experiment(n_steps: int = 50, n_runs: int = POSTERIOR_RUNS):
    r"""Monte-Carlo de la loi a posteriori :math:`p(x_n\mid y_1\dots y_n) = \mathcal N(\hat x_n, P_n)`.

    Tension :math:`x_0 \sim \mathcal N(0, 1)` qui dérive avec :math:`\Phi = 10^{-5}`, mesures avec
    :math:`\Psi = 0{,}01` ; le filtre part de :math:`\hat x_0 = 0`, :math:`P_0 = 1` (son a priori est exact).
    Renvoie ``(monte_carlo, P)`` avec ``P`` (T,) les variances du filtre (identiques pour tous les tirages).
    """
    model = constant_voltage_model()
    mc = monte_carlo(model, None, n_steps, n_runs, x0_mean=0.0, x0_cov=1.0, x0_hat=0.0, P0=1.0, rng=POSTERIOR_SEED)
    P = kalman_filter(model, mc.y[0], 0.0, 1.0).P[:, 0, 0]
    return mc, P


@dataclass(frozen=True, eq=False)
class PosteriorCoverage:
    r"""L'expérience :func:`posterior_experiment` résumée : ``monte_carlo`` et ``P`` (T,) ; ``normalised``
    (R, T) erreurs normalisées :math:`(x_n - \hat x_n)/\sqrt{P_n}` ; ``coverage`` (T,) fraction des tirages
    dans l'intervalle à 95 % :math:`|x_n - \hat x_n| \le 1{,}96\sqrt{P_n}`."""

    monte_carlo: MonteCarlo
    P: np.ndarray
    normalised: np.ndarray
    coverage: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, "P", "normalised", "coverage")


@lru_cache(maxsize=2)
def posterior_coverage(n_steps: int = 50, n_runs: int = POSTERIOR_RUNS) -> PosteriorCoverage:
    """:func:`posterior_experiment` et le taux de couverture de l'intervalle à 95 % à chaque pas ; calculé
    une fois par processus pour des arguments donnés (le chapitre et sa figure le partagent)."""
    mc, P = posterior_experiment(n_steps, n_runs)
    normalised = (mc.x[:, :, 0] - mc.x_hat[:, :, 0]) / np.sqrt(P)[None, :]
    coverage = np.mean(np.abs(normalised) <= scipy.stats.norm.ppf(0.975), axis=0)
    return PosteriorCoverage(mc, P, normalised, coverage)


def printed_recipe_comparison(n_steps: int = 50) -> tuple[np.ndarray, FilterResult, FilterResult]:
    r"""Les relevés de la tension constante filtrés par la recette corrigée (le filtre de Kalman) et par la
    recette au gain imprimé (erratum 001-7, :func:`~kalman_course.errata.printed_recipe_filter`), depuis
    :math:`\hat x_0 = 0`, :math:`P_0 = 1` V². Renvoie ``(z, corrigée, imprimée)``."""
    model = constant_voltage_model()
    z = constant_voltage_measurements(n_steps)
    return z, kalman_filter(model, z, 0.0, 1.0), printed_recipe_filter(model, z, 0.0, 1.0)
