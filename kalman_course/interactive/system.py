r"""Curseurs du chapitre « Contrôle d'un système dynamique » : l'amplitude des deux bruits du moteur.

Les écarts-types du bruit d'état :math:`\phi` et du bruit de mesure :math:`\psi` sont multipliés par
:math:`k_\phi` et :math:`k_\psi` (:func:`~kalman_course.scenarios.noise_levels.engine_at_noise`, mêmes
tirages) ; la position par défaut (:math:`k_\phi = k_\psi = 1`) est la simulation de la figure du chapitre.
"""

from __future__ import annotations

import numpy as np

from ..scenarios.engine import ENGINE_DT, ENGINE_PHI, ENGINE_PSI, ENGINE_SENSITIVITY
from ..scenarios.noise_levels import NOISE_STEPS, engine_at_noise
from .figure import SliderSpec, number, register_sliders
from .grid import ParameterAxis
from .spec import Glyph, Panel

__all__ = ["STATE_FACTORS", "MEASUREMENT_FACTORS", "system_axes", "system_run", "system_spec"]

CHAPTER = "controle-systeme"

#: Facteurs des écarts-types du bruit d'état proposés (0 : pas de bruit ; 1 : le modèle du chapitre).
STATE_FACTORS = (0.0, 0.25, 0.5, 1.0, 2.0, 4.0)
#: Facteurs de l'écart-type du bruit de mesure (Ψ doit rester définie positive : pas de 0).
MEASUREMENT_FACTORS = (0.125, 0.25, 0.5, 1.0, 2.0, 4.0)


def system_axes() -> tuple[ParameterAxis, ParameterAxis]:
    r""":math:`k_\phi` et :math:`k_\psi` (1 par défaut)."""
    return tuple(
        ParameterAxis(name, symbol, description, "", np.array(factors), default=factors.index(1.0),
                      scale="linear", tick_labels=tuple(f"× {number(k)}" for k in factors))
        for name, symbol, description, factors in (
            ("phi_scale", "facteur de φ", "multiplie les écarts-types du bruit d'état φ", STATE_FACTORS),
            ("psi_scale", "facteur de ψ", "multiplie l'écart-type du bruit de mesure ψ", MEASUREMENT_FACTORS),
        )
    )


def system_run(phi_scale: float, psi_scale: float) -> dict[str, np.ndarray]:
    """États (°C) et mesures (mV) du moteur simulé avec ces facteurs."""
    sim = engine_at_noise(phi_scale, psi_scale)
    return {"theta_m": sim.x[:, 0], "theta_a": sim.x[:, 1], "y1": sim.y[:, 0], "y2": sim.y[:, 1]}


def _readout(series, values) -> str:
    k_phi, k_psi = values
    s_phi = np.sqrt(np.diag(ENGINE_PHI)) * k_phi
    s_psi = np.sqrt(ENGINE_PSI[0, 0]) * k_psi
    return (f"Bruit d'état : écarts-types {number(s_phi[0], '°C')} (moteur) et {number(s_phi[1], '°C')} (air) "
            f"par pas ; bruit de mesure : {number(s_psi, 'mV')} par thermocouple "
            f"(soit {number(s_psi / ENGINE_SENSITIVITY, '°C')}).")


@register_sliders("systeme-bruits", chapter=CHAPTER)
def system_spec() -> SliderSpec:
    """Le moteur simulé : ce que font les deux bruits."""
    return SliderSpec(
        name="systeme-bruits",
        chapter=CHAPTER,
        title="Moteur simulé (120 s, même commande, mêmes tirages) : changez l'amplitude des deux bruits",
        x_label="temps (s)",
        axes=system_axes(),
        run=system_run,
        time=ENGINE_DT * np.arange(1, NOISE_STEPS + 1),
        panels=(
            Panel(
                "État xₙ = (θₘ, θₐ) : le bruit d'état φ agite la dynamique",
                "échauffement (°C)",
                (
                    Glyph("theta_m", "line", "firebrick", "moteur θₘ"),
                    Glyph("theta_a", "line", "royalblue", "air θₐ"),
                ),
                height=250,
            ),
            Panel(
                "Mesures yₙ = C xₙ + ψₙ : le bruit de mesure ψ brouille la lecture",
                "tension mesurée (mV)",
                (
                    Glyph("y1", "scatter", "firebrick", "thermocouple du moteur y₁", marker="dot", size=7),
                    Glyph("y2", "scatter", "royalblue", "thermocouple dans l'air y₂", marker="dot", size=7),
                ),
                height=250,
            ),
        ),
        readout=_readout,
    )
