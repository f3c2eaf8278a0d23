r"""Scénario « tension constante » (Welch & Bishop) : modèle et relevés reproductibles."""

from __future__ import annotations

import numpy as np

from ..core.models import LinearGaussianModel
from ..core.simulation import as_generator
from ..diagnostics.monte_carlo import monte_carlo
from ..filters.kalman import kalman_filter

__all__ = [
    "TRUE_VOLTAGE",
    "VOLTAGE_NOISE_STD",
    "VOLTAGE_SEED",
    "constant_voltage_model",
    "constant_voltage_measurements",
    "POSTERIOR_RUNS",
    "POSTERIOR_SEED",
    "posterior_experiment",
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
