"""Interactivité du cours : curseurs statiques (livre publié, sans noyau) et vivants (Jupyter).

- :func:`voltage_sliders` : figure Bokeh à deux curseurs (Φ, Ψ) sur des exécutions précalculées à la
  construction du livre ; la page publiée ne fait que choisir parmi elles (aucun noyau, aucun serveur).
- :func:`live_voltage_explorer` : curseurs ipywidgets (Φ, Ψ, P₀) qui relancent le filtre ; il faut un
  noyau (Jupyter, Binder, Colab).
- :func:`tag_sliders`, :func:`live_tag_explorer` : les mêmes pour l'EKF du tag UWB (σₐ, σᵣ).
- :func:`nile_sliders`, :func:`live_nile_explorer` : le Nil filtré et lissé (R, Q), chapitre « Lissage ».
- :func:`banana_uncertainty_sliders`, :func:`banana_parameter_sliders` : la « banane » de l'UKF (σθ, σᵣ ;
  α, κ) ; :func:`particle_sliders` : le filtre particulaire (N, R).
- :mod:`.grid` : les grilles précalculées (numpy seulement) ; :mod:`.sphinx_ext` : l'extension Sphinx
  qui sert BokehJS aux pages qui en ont besoin.

Seul ce sous-paquet importe bokeh et ipywidgets.
"""

from .grid import ParameterAxis, ParameterGrid, format_value, log_grid, precompute_grid
from .live import LiveExplorer, LogParameter
from .spec import Glyph, Panel
from .static import StaticSliders
from .smoothing import live_nile_explorer, nile_axes, nile_grid, nile_slider_run, nile_sliders
from .tag import live_tag_explorer, tag_axes, tag_grid, tag_run, tag_sliders
from .voltage import live_voltage_explorer, voltage_axes, voltage_grid, voltage_run, voltage_sliders
from .unscented import (
    banana_parameter_grid,
    banana_parameter_sliders,
    banana_uncertainty_grid,
    banana_uncertainty_sliders,
)
from .particle import particle_grid, particle_sliders

__all__ = [
    "banana_parameter_grid",
    "banana_parameter_sliders",
    "banana_uncertainty_grid",
    "banana_uncertainty_sliders",
    "particle_grid",
    "particle_sliders",
    "Glyph",
    "LiveExplorer",
    "LogParameter",
    "Panel",
    "ParameterAxis",
    "ParameterGrid",
    "StaticSliders",
    "format_value",
    "live_nile_explorer",
    "live_tag_explorer",
    "live_voltage_explorer",
    "log_grid",
    "nile_axes",
    "nile_grid",
    "nile_slider_run",
    "nile_sliders",
    "precompute_grid",
    "tag_axes",
    "tag_grid",
    "tag_run",
    "tag_sliders",
    "voltage_axes",
    "voltage_grid",
    "voltage_run",
    "voltage_sliders",
]
