r"""NEES et NIS d'un filtre dont on multiplie :math:`\Phi` et :math:`\Psi` (chapitre « Vérifier les
hypothèses : tests statistiques »).

Le moteur est simulé avec le vrai modèle et filtré avec :math:`a\,\Phi` et :math:`b\,\Psi`
(:func:`~kalman_course.monte_carlo_consistency`, mêmes tirages, même graine et même initialisation que
le chapitre). :math:`(a, b) = (1, 1)` est le modèle juste ; :math:`(1, 1/10)` le filtre optimiste du chapitre,
:math:`(10, 1)` le filtre pessimiste.
"""

from __future__ import annotations

import numpy as np

from ..core.validation import KalmanInputError, as_float_array
from ..diagnostics.monte_carlo import ConsistencyRuns, monte_carlo_consistency
from .engine import (
    CONSISTENCY_MC_RUNS,
    CONSISTENCY_MC_SEED,
    CONSISTENCY_MC_STEPS,
    ENGINE_PHI,
    ENGINE_PSI,
    ENGINE_X0_COV,
    ENGINE_X0_MEAN,
    engine_commands,
    engine_model,
)

__all__ = ["scaled_consistency"]


def _factor(name: str, value) -> float:
    v = as_float_array(name, value)
    if v.ndim != 0 or not (np.isfinite(v) and v > 0):
        raise KalmanInputError(f"« {name} » doit être un facteur strictement positif ; reçu {value!r}.")
    return float(v)


def scaled_consistency(phi_factor: float = 1.0, psi_factor: float = 1.0, n_runs: int = CONSISTENCY_MC_RUNS,
                       n_steps: int = CONSISTENCY_MC_STEPS) -> ConsistencyRuns:
    r"""NEES et NIS (R, T) de ``n_runs`` tirages filtrés avec ``phi_factor`` :math:`\times\Phi` et
    ``psi_factor`` :math:`\times\Psi`."""
    a, b = _factor("phi_factor", phi_factor), _factor("psi_factor", psi_factor)
    filter_model = engine_model(Phi=ENGINE_PHI if a == 1.0 else a * ENGINE_PHI,
                                Psi=ENGINE_PSI if b == 1.0 else b * ENGINE_PSI)
    return monte_carlo_consistency(engine_model(), n_steps, n_runs, x0_hat=ENGINE_X0_MEAN, P0=ENGINE_X0_COV,
                                   rng=CONSISTENCY_MC_SEED, filter_model=filter_model, u=engine_commands(n_steps))
