r"""Un thermocouple dont le bruit réel diffère de celui que suppose le filtre (chapitre « Implémentation
pratique et synthèse »).

Le moteur est simulé avec un bruit de mesure d'écart-type réel :math:`\sigma_{\text{vrai}}` (en °C ramenés
en mV par la sensibilité des thermocouples) et filtré en supposant :math:`\sigma_{\text{supposé}}`. Ce que
voit l'ingénieur, ce sont les innovations normalisées :math:`\tilde y_{n,1}/\sqrt{S_{n,11}}` ; ce qu'il ne
voit pas, c'est l'erreur :math:`\hat\theta_m - \theta_m` et sa comparaison à l'écart-type annoncé
:math:`\sqrt{P_{n,11}}`. Pour :math:`\sigma_{\text{vrai}} = \sigma_{\text{supposé}} = 0{,}5` °C, c'est le
« bon modèle » du chapitre.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.results import FilterResult
from ..core.simulation import Simulation
from ..core.validation import KalmanInputError, as_float_array
from ..diagnostics.consistency import whitened_innovations
from .engine import ENGINE_PSI, engine_model, engine_run

__all__ = ["SENSOR_STD", "TUNING_STEPS", "SensorTuning", "sensor_tuning"]

#: Écart-type nominal du bruit des thermocouples (°C), celui de :data:`~.engine.ENGINE_PSI`.
SENSOR_STD = 0.5
#: Durée (s).
TUNING_STEPS = 120


def _std(name: str, value) -> float:
    v = as_float_array(name, value)
    if v.ndim != 0 or not (np.isfinite(v) and v > 0):
        raise KalmanInputError(f"« {name} » doit être un écart-type strictement positif (°C) ; reçu {value!r}.")
    return float(v)


def _psi(std: float) -> np.ndarray:
    return ENGINE_PSI if std == SENSOR_STD else (std / SENSOR_STD) ** 2 * ENGINE_PSI


@dataclass(frozen=True, eq=False)
class SensorTuning:
    r"""``simulation`` et ``result`` ; ``normalised`` (T,) innovations normalisées du premier capteur ;
    ``error`` (T,) :math:`\hat\theta_m - \theta_m` (°C) ; ``std`` (T,) :math:`\sqrt{P_{n,11}}` (°C)."""

    simulation: Simulation
    result: FilterResult
    normalised: np.ndarray
    error: np.ndarray
    std: np.ndarray


def sensor_tuning(true_std: float = SENSOR_STD, assumed_std: float = SENSOR_STD,
                  n_steps: int = TUNING_STEPS) -> SensorTuning:
    r"""Le moteur simulé avec :math:`\sigma_{\text{vrai}}` = ``true_std`` et filtré avec
    :math:`\sigma_{\text{supposé}}` = ``assumed_std`` (°C)."""
    true_std, assumed_std = _std("true_std", true_std), _std("assumed_std", assumed_std)
    sim, result = engine_run(n_steps, true_model=engine_model(Psi=_psi(true_std)),
                             filter_model=engine_model(Psi=_psi(assumed_std)))
    normalised = whitened_innovations(result)[:, 0]
    return SensorTuning(sim, result, normalised, result.x[:, 0] - sim.x[:, 0], np.sqrt(result.P[:, 0, 0]))
