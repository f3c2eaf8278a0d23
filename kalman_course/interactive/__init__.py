"""Interactivité du cours : curseurs statiques (livre publié, sans noyau) et interactifs (Jupyter).

Chaque chapitre a au moins une figure à curseurs, décrite une fois (:class:`SliderSpec`, inscrite au
registre par :func:`register_sliders`) et rendue de deux façons :

- :func:`sliders` (``kc.interactive.sliders("nom")``) : figure Bokeh sur des exécutions précalculées à la
  construction du livre ; la page publiée ne fait que choisir parmi elles (aucun noyau, aucun serveur) ;
- :func:`live_explorer` (``kc.interactive.live_explorer("nom")``) : curseurs ipywidgets qui relancent le
  calcul du paquet ; il faut un noyau (Jupyter, Binder, Colab).

Les figures écrites avant le registre gardent leurs noms : :func:`voltage_sliders`,
:func:`live_voltage_explorer` (tension constante), :func:`tag_sliders`, :func:`live_tag_explorer` (tag
UWB), :func:`nile_sliders`, :func:`live_nile_explorer` (le Nil, chapitre « Lissage »),
:func:`banana_uncertainty_sliders`, :func:`banana_parameter_sliders` (la « banane » de l'UKF) et
:func:`particle_sliders` (le filtre particulaire) ; elles sont aussi au registre.

:mod:`.grid` : les grilles précalculées (numpy seulement). Le livre sert BokehJS aux pages qui en ont
besoin par l'extension Sphinx :mod:`kalman_course.sphinx.sliders` (aucun code Sphinx ici).

Seul ce sous-paquet importe bokeh et ipywidgets.
"""

from .figure import (
    SLIDER_FIGURES,
    SliderSpec,
    live_explorer,
    register_sliders,
    slider_grid,
    slider_names,
    slider_spec,
    sliders,
)
from .grid import ParameterAxis, ParameterGrid, format_value, log_grid, precompute_grid
from .live import ChoiceParameter, LinearParameter, LiveExplorer, LogParameter
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

# une figure à curseurs par chapitre (chaque module inscrit les siennes au registre)
from . import intro  # noqa: F401  (introduction)
from . import intuition  # noqa: F401  (« Le filtre de Kalman en images »)
from . import system  # noqa: F401  (« Contrôle d'un système dynamique »)
from . import estimator  # noqa: F401  (« Construction d'un estimateur »)
from . import predictor  # noqa: F401  (« Le filtre prédicteur–correcteur »)
from . import gain  # noqa: F401  (« Dynamique de l'erreur et gain optimal »)
from . import practice  # noqa: F401  (« Implémentation pratique et synthèse »)
from . import consistency  # noqa: F401  (« Vérifier les hypothèses : tests statistiques »)
from . import ekf  # noqa: F401  (« Le filtre de Kalman étendu »)
from . import iekf  # noqa: F401  (« Filtre de Kalman étendu itéré »)
from . import registered  # noqa: F401  (UKF, filtre particulaire, lissage : figures d'avant le registre)
from . import ensemble  # noqa: F401  (« Le filtre de Kalman d'ensemble »)
from . import likelihood  # noqa: F401  (« Apprendre Q et R »)
from . import srif  # noqa: F401  (« Filtre d'information en racine carrée »)
from . import se3  # noqa: F401  (« EKF itéré sur SE(3) »)
from . import tracking  # noqa: F401  (« Plusieurs capteurs, temps irrégulier », « Cibles qui manœuvrent »)
from . import gaussian  # noqa: F401  (« Un seul filtre gaussien »)
from . import filter_choice  # noqa: F401  (« Quel filtre choisir ? »)
from . import parallel  # noqa: F401  (« Filtrer en parallèle dans le temps »)
from . import invariant  # noqa: F401  (« Filtrage invariant sur les groupes de Lie »)
from . import assimilation  # noqa: F401  (« Le filtre d'ensemble en grande dimension », « Méthodes variationnelles »)
from . import multitarget  # noqa: F401  (« Fouillis et association », « Gérer les pistes » : issue 37)

__all__ = [
    "ChoiceParameter",
    "Glyph",
    "LinearParameter",
    "LiveExplorer",
    "LogParameter",
    "Panel",
    "ParameterAxis",
    "ParameterGrid",
    "SLIDER_FIGURES",
    "SliderSpec",
    "StaticSliders",
    "banana_parameter_grid",
    "banana_parameter_sliders",
    "banana_uncertainty_grid",
    "banana_uncertainty_sliders",
    "format_value",
    "live_explorer",
    "live_nile_explorer",
    "live_tag_explorer",
    "live_voltage_explorer",
    "log_grid",
    "nile_axes",
    "nile_grid",
    "nile_slider_run",
    "nile_sliders",
    "particle_grid",
    "particle_sliders",
    "precompute_grid",
    "register_sliders",
    "slider_grid",
    "slider_names",
    "slider_spec",
    "sliders",
    "tag_axes",
    "tag_grid",
    "tag_run",
    "tag_sliders",
    "voltage_axes",
    "voltage_grid",
    "voltage_run",
    "voltage_sliders",
]
