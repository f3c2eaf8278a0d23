r"""Au registre des figures à curseurs : les figures écrites avant lui pour les chapitres « Le filtre de
Kalman *unscented* (UKF) », « Le filtre particulaire » et « Lissage ».

Chaque entrée reprend les axes, la fonction d'une exécution, les panneaux et les séries fixes de la
figure d'origine (:mod:`.unscented`, :mod:`.particle`, :mod:`.smoothing`) : même grille, mêmes tracés ;
le registre y ajoute les curseurs interactifs (``kc.interactive.live_explorer("nom")``) et les tests
communs à toutes les figures.
"""

from __future__ import annotations

import numpy as np

from ..datasets.nile import nile
from ..scenarios import banana
from ..scenarios.convergence import LINEAR_STEPS
from .figure import SliderSpec, register_sliders
from .particle import particle_axes, particle_panels, particle_readout, particle_run
from .smoothing import nile_axes, nile_panels, nile_readout, nile_slider_run
from .unscented import (
    N_POINTS,
    banana_parameter_axes,
    banana_parameter_panels,
    banana_parameter_readout,
    banana_parameter_run,
    banana_uncertainty_axes,
    banana_uncertainty_panels,
    banana_uncertainty_readout,
    banana_uncertainty_run,
)

__all__ = ["banana_uncertainty_spec", "banana_parameter_spec", "particle_spec", "nile_spec"]


@register_sliders("ukf-banane-incertitude", chapter="ukf")
def banana_uncertainty_spec() -> SliderSpec:
    r"""La banane : :math:`\sigma_\theta` et :math:`\sigma_r` (grille de :func:`~.unscented.banana_uncertainty_grid`)."""
    return SliderSpec(
        name="ukf-banane-incertitude", chapter="ukf",
        title="La banane (r = 1 m, θ = 90°) : déplacez les incertitudes d'azimut et de distance",
        x_label="x (m)", axes=banana_uncertainty_axes(), run=banana_uncertainty_run,
        time=np.arange(N_POINTS, dtype=float), panels=banana_uncertainty_panels(),
        readout=banana_uncertainty_readout,
    )


@register_sliders("ukf-banane-parametres", chapter="ukf")
def banana_parameter_spec() -> SliderSpec:
    r"""Les points sigma : :math:`\alpha` et :math:`\kappa` (grille de :func:`~.unscented.banana_parameter_grid`)."""
    sample = banana.banana_sample(N_POINTS)
    return SliderSpec(
        name="ukf-banane-parametres", chapter="ukf",
        title="Les paramètres des points sigma : α et κ (σθ = 20°, σᵣ = 2 cm)",
        x_label="x (m)", axes=banana_parameter_axes(), run=banana_parameter_run,
        time=np.arange(N_POINTS, dtype=float), panels=banana_parameter_panels(),
        fixed={"cloud_x": sample[:, 0], "cloud_y": sample[:, 1]}, readout=banana_parameter_readout,
    )


@register_sliders("filtre-particulaire-curseurs", chapter="filtre-particulaire")
def particle_spec() -> SliderSpec:
    r"""Le filtre particulaire : :math:`N` et :math:`R` (grille de :func:`~.particle.particle_grid`)."""
    return SliderSpec(
        name="filtre-particulaire-curseurs", chapter="filtre-particulaire",
        title="Filtre particulaire : nombre de particules N et variance de mesure R",
        x_label="pas de temps k", axes=particle_axes(), run=particle_run,
        time=np.arange(1, LINEAR_STEPS + 1, dtype=float), panels=particle_panels(), readout=particle_readout,
    )


@register_sliders("nil-curseurs", chapter="lissage")
def nile_spec() -> SliderSpec:
    r"""Le Nil filtré et lissé : :math:`R` et :math:`Q` (grille de :func:`~.smoothing.nile_grid`)."""
    return SliderSpec(
        name="nil-curseurs", chapter="lissage",
        title="Le Nil filtré et lissé : déplacez R et Q (niveau local, initialisation diffuse exacte)",
        x_label="année", axes=nile_axes(), run=nile_slider_run,
        time=nile(True).year.astype(float), panels=nile_panels(), fixed={"y": nile(True).flow},
        readout=nile_readout,
    )
