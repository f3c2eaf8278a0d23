r"""Curseurs du chapitre « Lissage » : le Nil (années manquantes de Durbin & Koopman), filtré et lissé,
pour des variances :math:`R = \sigma^2_\varepsilon` et :math:`Q = \sigma^2_\eta` choisies au curseur.

Le modèle est le niveau local de :mod:`kalman_course.scenarios.nile`, à l'initialisation diffuse exacte. La position
par défaut des curseurs est l'estimation publiée par Durbin & Koopman,
:math:`(\sigma^2_\varepsilon, \sigma^2_\eta) = (15\,099 ; 1\,469{,}1)` (:math:`(10^8` m³)²).
"""

from __future__ import annotations

import numpy as np

from ..core.validation import KalmanInputError, as_float_array
from ..datasets.nile import nile
from ..scenarios.nile import NILE_DK_VARIANCES, nile_run
from .grid import ParameterAxis, ParameterGrid, log_grid, precompute_grid
from .spec import Glyph, Panel

__all__ = ["nile_axes", "nile_slider_run", "nile_grid", "nile_panels", "nile_readout", "nile_sliders",
           "live_nile_explorer"]

LIVE_HINT = "kc.interactive.live_nile_explorer()"
UNIT = "(10⁸ m³ par an)²"


def nile_axes(per_decade: int = 2) -> tuple[ParameterAxis, ParameterAxis]:
    r""":math:`R = \sigma^2_\varepsilon` de :math:`10^{-2}` à :math:`10` fois la valeur de Durbin & Koopman,
    :math:`Q = \sigma^2_\eta` de :math:`10^{-3}` à :math:`10^{2}` fois la sienne, ``per_decade`` points par
    décade (7 × 11 par défaut) ; la position par défaut est exactement la valeur publiée."""
    eps, eta = NILE_DK_VARIANCES
    return (
        ParameterAxis("R", "R = σ²ε", "bruit de mesure", UNIT, log_grid(eps, 2, 1, per_decade),
                      default=2 * per_decade),
        ParameterAxis("Q", "Q = σ²η", "dérive du niveau", UNIT,
                      log_grid(eta, 3, 2, per_decade), default=3 * per_decade),
    )


def nile_slider_run(R: float, Q: float) -> dict[str, np.ndarray]:
    r"""Le Nil à années manquantes filtré et lissé pour :math:`(R, Q)` ; séries (T,) en :math:`10^8` m³ :
    niveau filtré ``xf`` et lissé ``xs``, leurs écarts-types ``sf`` et ``ss``."""
    run = nile_run(R, Q, missing=True)
    return {"xf": run.filtered.x[:, 0], "xs": run.smoothed.x[:, 0],
            "sf": run.filtered.std()[:, 0], "ss": run.smoothed.std()[:, 0]}


def nile_readout(series, values) -> str:
    """Le texte sous les curseurs : le rapport Q/R et les écarts-types moyens du niveau filtré et lissé."""
    from .figure import number

    R, Q = values
    return (f"Rapport Q/R = {number(Q / R)} ; écart-type moyen du niveau : filtre {number(float(np.mean(series['sf'])))}, "
            f"lisseur {number(float(np.mean(series['ss'])))} (10⁸ m³) ; niveau lissé de "
            f"{number(float(np.min(series['xs'])))} à {number(float(np.max(series['xs'])))} (10⁸ m³).")


def nile_grid(per_decade: int = 2) -> ParameterGrid:
    """Toutes les exécutions de la grille des curseurs (séries ``xf``, ``xs``, ``sf``, ``ss``)."""
    return precompute_grid(nile_slider_run, *nile_axes(per_decade), time=nile(True).year.astype(float))


def nile_panels() -> tuple[Panel, ...]:
    """La figure : débits et niveaux filtré et lissé, puis leurs écarts-types (échelle log)."""
    return (
        Panel("Débit du Nil (années 1891–1910 et 1931–1950 retirées)", "débit (10⁸ m³ par an)",
              (Glyph("y", "scatter", "firebrick", "débit mesuré"),
               Glyph("xf", "line", "darkorange", "niveau filtré"),
               Glyph("xs", "line", "royalblue", "niveau lissé")),
              y_range=(400.0, 1450.0), height=280),
        Panel("Écart-type du niveau", "écart-type (10⁸ m³ par an)",
              (Glyph("sf", "line", "darkorange", "filtre"), Glyph("ss", "line", "royalblue", "lisseur")),
              y_log=True, y_range=(2.0, 2000.0)),
    )


def nile_sliders(per_decade: int = 2):
    r"""Figure à curseurs statiques :math:`R` et :math:`Q` (Bokeh) sur le Nil à années manquantes : toutes
    les exécutions de :func:`nile_grid` sont embarquées, la page publiée change de courbe sans noyau.
    Renvoie un :class:`~.static.StaticSliders`."""
    from .static import StaticSliders

    return StaticSliders(
        nile_grid(per_decade),
        nile_panels(),
        x_label="année",
        fixed={"y": nile(True).flow},
        name="nil-curseurs",
        title="Le Nil filtré et lissé : déplacez R et Q (niveau local, initialisation diffuse exacte)",
        live_hint=LIVE_HINT,
    )


def _positive(name: str, value) -> float:
    v = as_float_array(name, value)
    if v.ndim != 0 or not v > 0:
        raise KalmanInputError(f"« {name} » doit être un nombre strictement positif (une variance) ; reçu {value!r}.")
    return float(v)


def live_nile_explorer(R: float = NILE_DK_VARIANCES[0], Q: float = NILE_DK_VARIANCES[1]):
    r"""Curseurs interactifs (ipywidgets) :math:`R` et :math:`Q` sur le Nil à années manquantes, pour Jupyter,
    Binder ou Colab (un noyau doit tourner). Renvoie un :class:`~.live.LiveExplorer`."""
    from .live import LiveExplorer, LogParameter

    return LiveExplorer(
        run=nile_slider_run,
        parameters=(
            LogParameter("R", "R = σ²ε (bruit de mesure)", UNIT, _positive("R", R), 2.0, 6.0),
            LogParameter("Q", "Q = σ²η (bruit d'état)", UNIT, _positive("Q", Q), 0.0, 6.0),
        ),
        time=nile(True).year.astype(float),
        panels=nile_panels(),
        x_label="année",
        fixed={"y": nile(True).flow},
    )
