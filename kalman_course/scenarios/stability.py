r"""Un estimateur à gain fixe sur le contre-exemple scalaire de l'erratum 001-3 (chapitre « Construction
d'un estimateur »).

Système :math:`x_{n+1} = A x_n + \phi_n`, :math:`y_{n+1} = x_{n+1} + \psi_{n+1}` (:math:`C = 1`,
:math:`\Phi = \Psi = 0{,}01`), estimateur :math:`\hat x_{n+1} = (1 - KC)A\,\hat x_n + K y_{n+1}` parti d'une
erreur :math:`\hat x_0 - x_0 = 1`. L'erreur moyenne est multipliée par :math:`(1 - KC)A` à chaque pas :
elle décroît si et seulement si :math:`|(1 - KC)A| < 1` ; la condition imprimée :math:`|1 - KC| < 1` ne
suffit pas. Avec :math:`A = 2`, :math:`K = 0{,}4` et :math:`K = 0{,}6`, 20 pas, 400 tirages et la graine 3,
ce sont les courbes de la figure du chapitre.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.models import LinearGaussianModel
from ..core.validation import KalmanInputError, as_float_array
from ..diagnostics.monte_carlo import MonteCarlo, monte_carlo
from ..lecture.errata import printed_stability_radius
from ..lecture.estimator import (MeanError, error_transition, linear_estimator_runs, mean_error_recursion,
                                 spectral_radius)

__all__ = ["COUNTER_A", "COUNTER_C", "COUNTER_NOISE", "STABILITY_STEPS", "STABILITY_RUNS", "STABILITY_SEED",
           "counter_example_model", "FixedGainRun", "fixed_gain_experiment"]

#: Le contre-exemple : système instable :math:`A = 2`, mesure directe :math:`C = 1`, bruits de variance 0,01.
COUNTER_A = 2.0
COUNTER_C = 1.0
COUNTER_NOISE = 0.01
#: Durée, nombre de tirages et graine de l'expérience de Monte-Carlo.
STABILITY_STEPS = 20
STABILITY_RUNS = 400
STABILITY_SEED = 3


def counter_example_model(A: float = COUNTER_A) -> LinearGaussianModel:
    r"""Le système scalaire :math:`A` (2 par défaut), :math:`C = 1`, :math:`\Phi = \Psi = 0{,}01`."""
    a = as_float_array("A", A)
    if a.ndim != 0 or not np.isfinite(a):
        raise KalmanInputError(f"« A » doit être un nombre fini (système scalaire) ; reçu {A!r}.")
    return LinearGaussianModel(A=float(a), C=COUNTER_C, Q=COUNTER_NOISE, R=COUNTER_NOISE)


@dataclass(frozen=True, eq=False)
class FixedGainRun:
    r"""Un gain fixe : ``monte_carlo`` (moyenne des tirages), ``recursion`` (récurrence du cours),
    ``radius`` :math:`|(1 - KC)A|`, ``printed_radius`` :math:`|1 - KC|` (condition imprimée)."""

    monte_carlo: MonteCarlo
    recursion: MeanError
    radius: float
    printed_radius: float


def fixed_gain_experiment(K: float, A: float = COUNTER_A, n_steps: int = STABILITY_STEPS,
                          n_runs: int = STABILITY_RUNS, rng: Any = STABILITY_SEED) -> FixedGainRun:
    r"""Gain fixe ``K`` sur le contre-exemple : ``n_runs`` tirages (:math:`x_0 = 0` exactement,
    :math:`\hat x_0 = 1`) estimés en lot par :func:`~kalman_course.linear_estimator_runs`, et la récurrence
    :func:`~kalman_course.mean_error_recursion` de l'erreur moyenne. Calcul de la figure
    « estimateur-stabilite » et des curseurs du chapitre."""
    k = as_float_array("K", K)
    if k.ndim != 0 or not np.isfinite(k):
        raise KalmanInputError(f"« K » doit être un gain scalaire fini ; reçu {K!r}.")
    model = counter_example_model(A)
    Kmat = np.array([[float(k)]])

    def estimator(Y):
        return linear_estimator_runs(model, Y, [1.0], Kmat)

    mc = monte_carlo(model, estimator, n_steps, n_runs, x0_mean=[0.0], x0_cov=[[0.0]], x0_hat=[1.0], rng=rng,
                     batch=True)
    rec = mean_error_recursion(model, Kmat, x0_mean=[0.0], x0_hat=[1.0], n_steps=n_steps)
    return FixedGainRun(mc, rec, spectral_radius(error_transition(model, Kmat)),
                        float(printed_stability_radius(model, Kmat)))
