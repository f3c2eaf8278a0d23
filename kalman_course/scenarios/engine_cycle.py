r"""La boucle prédicteur–correcteur du moteur, demi-pas par demi-pas (chapitre « Le filtre
prédicteur–correcteur »).

Les cinq premières secondes du moteur (simulation du chapitre : graine du scénario, estimation
initiale fausse :math:`\hat x_0 = (15, 5)` °C, :math:`P_0 = 15^2 I` °C²) sont filtrées par un filtre qui
suppose la covariance de mesure :math:`s\,\Psi`. Pour :math:`s = 1`, c'est le filtre du chapitre ; quand
:math:`s` grandit, le gain tend vers 0 et la correction ne resserre plus rien ; quand :math:`s` tend vers 0,
l'estimation recopie la mesure inversée :math:`C^{-1}y_n`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from ..core.simulation import Simulation
from ..core.validation import KalmanInputError, as_float_array
from .engine import ENGINE_P0, ENGINE_PSI, ENGINE_X0_HAT, engine_model, engine_run
from .half_steps import HalfSteps, half_steps

__all__ = ["CYCLE_STEPS", "EngineCycle", "engine_cycle"]

#: Nombre de mesures (celles de la première cellule du chapitre).
CYCLE_STEPS = 5


@dataclass(frozen=True, eq=False)
class EngineCycle:
    r"""``steps`` : les demi-pas (:class:`~kalman_course.scenarios.half_steps.HalfSteps`, °C et °C²) ;
    ``simulation`` : états vrais et mesures ; ``inverted`` (T, 2) : mesures inversées :math:`C^{-1}y_n` (°C) ;
    ``K`` (T, 2, 2) : gains (°C/mV)."""

    steps: HalfSteps
    simulation: Simulation
    inverted: np.ndarray
    K: np.ndarray


def engine_cycle(psi_scale: float = 1.0, n_steps: int = CYCLE_STEPS) -> EngineCycle:
    r"""Le moteur simulé avec le vrai :math:`\Psi`, filtré en supposant :math:`s\,\Psi` (``psi_scale`` = :math:`s`)."""
    s = as_float_array("psi_scale", psi_scale)
    if s.ndim != 0 or not (np.isfinite(s) and s > 0):
        raise KalmanInputError(f"« psi_scale » doit être un facteur strictement positif ; reçu {psi_scale!r}.")
    model = engine_model()
    assumed = model if float(s) == 1.0 else engine_model(Psi=float(s) * ENGINE_PSI)
    sim, result = engine_run(n_steps, filter_model=assumed)
    inverted = scipy.linalg.solve(model.C, sim.y.T).T
    return EngineCycle(half_steps(result, ENGINE_X0_HAT, ENGINE_P0), sim, inverted, result.K)
