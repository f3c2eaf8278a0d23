r"""Le moteur d'avion simulé à plusieurs niveaux de bruit (chapitre « Contrôle d'un système dynamique »).

Les mêmes tirages gaussiens :math:`\varepsilon` sont gardés d'un niveau à l'autre : multiplier les
écarts-types par :math:`k_\phi` et :math:`k_\psi` revient à simuler avec :math:`k_\phi^2\,\Phi` et
:math:`k_\psi^2\,\Psi` (:func:`~kalman_course.simulate`, graine du scénario), si bien que l'on voit
l'**amplitude** des bruits changer, pas leur dessin. À :math:`k_\phi = k_\psi = 1`, c'est la simulation
de la figure du chapitre.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..core.simulation import Simulation, simulate
from ..core.validation import KalmanInputError, as_float_array
from .engine import ENGINE_PHI, ENGINE_PSI, ENGINE_SEED, engine_commands, engine_model

__all__ = ["NOISE_STEPS", "noise_scale", "engine_at_noise"]

#: Durée de la simulation (s), celle de la figure du chapitre.
NOISE_STEPS = 120


def noise_scale(name: str, value: Any) -> float:
    """Un facteur d'écart-type : un nombre fini ≥ 0."""
    v = as_float_array(name, value)
    if v.ndim != 0 or not (np.isfinite(v) and v >= 0):
        raise KalmanInputError(f"« {name} » doit être un facteur d'écart-type fini et positif ou nul ; reçu {value!r}.")
    return float(v)


def engine_at_noise(phi_scale: float = 1.0, psi_scale: float = 1.0, n_steps: int = NOISE_STEPS) -> Simulation:
    r"""Le moteur (état initial nul, commande du scénario) simulé avec :math:`k_\phi^2\Phi` et :math:`k_\psi^2\Psi`.

    ``phi_scale`` :math:`k_\phi`, ``psi_scale`` :math:`k_\psi` : facteurs des écarts-types des bruits d'état et
    de mesure (0 : pas de bruit). Renvoie la :class:`~kalman_course.Simulation` (``x`` (T, 2) en °C, ``y``
    (T, 2) en mV).
    """
    k_phi, k_psi = noise_scale("phi_scale", phi_scale), noise_scale("psi_scale", psi_scale)
    model = engine_model(Phi=ENGINE_PHI if k_phi == 1.0 else k_phi**2 * ENGINE_PHI,
                         Psi=ENGINE_PSI if k_psi == 1.0 else k_psi**2 * ENGINE_PSI)
    u = engine_commands(n_steps)
    return simulate(model, np.zeros(2), n_steps, u, rng=ENGINE_SEED)
