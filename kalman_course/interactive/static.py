r"""Curseurs statiques : une figure Bokeh dont deux curseurs choisissent parmi des exécutions précalculées.

La page publiée n'a pas de noyau : la figure embarque toute une :class:`~.grid.ParameterGrid`
(``float64``, donc les valeurs exactes du paquet) et un petit rappel JavaScript (``CustomJS``) qui,
à chaque mouvement d'un curseur, recopie l'exécution choisie dans la source de données tracée.

BokehJS n'est **pas** inclus dans la figure : le site le sert lui-même, une fois pour tout le site,
dans ``_static/bokeh/`` (copié du paquet Python ``bokeh`` installé par ``scripts/vendor_assets.py``,
donc à la même version). L'extension Sphinx :mod:`kalman_course.interactive.sphinx_ext` ajoute les
balises ``<script>`` dans l'en-tête des seules pages qui contiennent une telle figure (repérées par
l'attribut :data:`MARKER`), une fois par page, avec un chemin relatif qui marche en ``http://`` comme
en ``file://``. Hors du livre (dans Jupyter), la figure affiche un message qui renvoie vers les
curseurs vivants (:mod:`kalman_course.interactive.live`).

Le PDF du cours (constructeur LaTeX) ne peut pas animer de curseurs : la figure fournit aussi une
image PNG (matplotlib, mêmes panneaux, exécution de la position par défaut des curseurs) et une
légende (:meth:`StaticSliders.caption`, dans l'attribut HTML :data:`CAPTION_ATTRIBUTE`) ; l'extension
Sphinx place l'image dans une figure légendée du PDF. Le site, lui, affiche toujours le HTML.
"""

from __future__ import annotations

import hashlib
import html
import json
import re
from dataclasses import dataclass, field
from typing import Mapping

import bokeh
import numpy as np
from bokeh.embed import json_item
from bokeh.layouts import column, row
from bokeh.models import (
    ColumnDataSource,
    CustomJS,
    CustomJSTickFormatter,
    Div,
    Legend,
    LegendItem,
    Range1d,
    Slider,
)
from bokeh.plotting import figure

from ..core.validation import KalmanInputError, as_float_array
from ..book_typography import french_spacing
from ..numbers import bokeh_tick_formatter
from .grid import ParameterGrid
from .spec import Panel, check_columns

__all__ = ["MARKER", "CAPTION_ATTRIBUTE", "BOKEH_VERSION", "PLOTTED_SOURCE", "bokehjs_files", "StaticSliders"]

#: Attribut HTML qui signale une figure à curseurs statiques (lu par l'extension Sphinx).
MARKER = "data-kc-bokeh"
#: Attribut HTML qui porte la légende de la figure imprimée (PDF), lue par l'extension Sphinx.
CAPTION_ATTRIBUTE = "data-kc-caption"
#: Version de BokehJS attendue par les figures (celle du paquet Python ``bokeh`` installé).
BOKEH_VERSION = bokeh.__version__

#: Nom du ``ColumnDataSource`` tracé (les tests le relisent dans ``Bokeh.documents``).
PLOTTED_SOURCE = "kc-plotted"


def bokehjs_files() -> list[str]:
    """Fichiers BokehJS nécessaires, relatifs à ``_static/`` : noyau puis composants (curseurs)."""
    return [f"bokeh/bokeh-{BOKEH_VERSION}.min.js", f"bokeh/bokeh-widgets-{BOKEH_VERSION}.min.js"]


# Rappel exécuté par le navigateur à chaque mouvement d'un curseur : l'exécution (i, j) occupe
# les indices [(i·N1 + j)·T, (i·N1 + j + 1)·T) des séries aplaties de « grid ».
_CALLBACK = """
const i = Math.round(s0.value), j = Math.round(s1.value);
const start = (i * n1 + j) * n_time;
const data = {};
for (const name of Object.keys(source.data)) data[name] = source.data[name];
for (const name of names) data[name] = grid.data[name].slice(start, start + n_time);
source.data = data;
"""


@dataclass(eq=False)
class StaticSliders:
    """Figure Bokeh à deux curseurs sur une grille précalculée (aucun noyau nécessaire).

    Paramètres
    ----------
    grid : ParameterGrid
        Les exécutions précalculées ; le curseur ``k`` parcourt ``grid.axes[k].values``.
    panels : suite de Panel
        Les panneaux, empilés verticalement ; abscisse commune ``grid.time`` (série ``"t"``), sauf
        pour un panneau dont les tracés ont leur propre abscisse (``Glyph.x``).
    x_label : str
        Libellé de l'abscisse, avec unité.
    fixed : dict nom → (T,), optionnel
        Séries qui ne dépendent pas des curseurs (mesures, vérité).
    name : str
        Identifiant court de la figure (attribut HTML, identifiant d'élément).
    title : str
        Titre affiché au-dessus des curseurs.
    live_hint : str
        L'appel qui donne les curseurs vivants équivalents dans Jupyter (cité hors du livre).
    """

    grid: ParameterGrid
    panels: tuple[Panel, ...]
    x_label: str
    fixed: Mapping[str, np.ndarray] = field(default_factory=dict)
    name: str = "curseurs"
    title: str = ""
    live_hint: str = ""

    def __post_init__(self) -> None:
        if not (isinstance(self.name, str) and re.fullmatch(r"[a-z0-9][a-z0-9-]*", self.name)):
            raise KalmanInputError(
                f"« name » doit être un identifiant court en minuscules, chiffres et tirets ; reçu {self.name!r}."
            )
        if not isinstance(self.grid, ParameterGrid):
            raise KalmanInputError(f"« grid » doit être une ParameterGrid ; reçu {type(self.grid).__name__}.")
        if "t" in self.grid.series or "t" in self.fixed:
            raise KalmanInputError("Aucune série ne doit s'appeler « t » : ce nom est réservé au temps commun.")
        self.panels = tuple(self.panels)
        if not self.panels or not all(isinstance(p, Panel) for p in self.panels):
            raise KalmanInputError("« panels » doit être une suite non vide de Panel.")
        T = self.grid.time.size
        fixed = {}
        for key, values in self.fixed.items():
            arr = as_float_array(f"fixed[{key!r}]", values, allow_nan=True)
            if arr.shape != (T,):
                raise KalmanInputError(f"La série fixe « {key} » doit avoir la forme ({T},) ; reçu {arr.shape}.")
            fixed[key] = arr
        self.fixed = fixed
        check_columns(self.panels, set(self.grid.series) | set(fixed))
        self.layout = self._build()

    # ------------------------------------------------------------------ construction Bokeh

    def _sliders(self) -> tuple[Slider, Slider]:
        sliders = []
        for k, axis in enumerate(self.grid.axes):
            labels = axis.labels()
            sliders.append(
                Slider(
                    start=0,
                    end=axis.values.size - 1,
                    step=1,
                    value=axis.default,
                    # Bokeh écrit « titre: valeur » : l'espace insécable finale donne « titre : valeur »
                    title=french_spacing(f"{axis.symbol} — {axis.description}") + "\u00a0",
                    # le curseur se déplace sur les indices de la grille et affiche la vraie valeur
                    format=CustomJSTickFormatter(args={"labels": labels}, code="return labels[Math.round(tick)];"),
                    sizing_mode="stretch_width",
                    name=f"kc-slider-{k}",
                )
            )
        return sliders[0], sliders[1]

    def _y_range(self, panel: Panel) -> tuple[float, float]:
        """Bornes fixes de l'ordonnée, communes à toute la grille : en déplaçant un curseur, on voit
        la courbe bouger, pas l'axe. Échelle log : décades entières ; sinon marge de 5 %."""
        if panel.y_range is not None:
            return panel.y_range
        values = []
        for glyph in panel.glyphs:
            if glyph.kind == "hline":
                values.append(np.array([glyph.value], dtype=float))
            elif glyph.column in self.grid.series:
                values.append(self.grid.series[glyph.column].ravel())
            else:
                values.append(self.fixed[glyph.column])
        v = np.concatenate(values)
        v = v[np.isfinite(v)]
        if panel.y_log:
            v = v[v > 0]
            if v.size == 0:
                raise KalmanInputError(f"Panneau « {panel.title} » : échelle log sans valeur strictement positive.")
            return 10.0 ** np.floor(np.log10(v.min())), 10.0 ** np.ceil(np.log10(v.max()))
        lo, hi = float(v.min()), float(v.max())
        pad = 0.05 * (hi - lo) if hi > lo else max(abs(hi), 1.0) * 0.05
        return lo - pad, hi + pad

    def _build(self):
        grid = self.grid
        i0, j0 = grid.default_index
        plotted = {"t": np.array(grid.time)}
        plotted.update(self.fixed)
        plotted.update({key: np.array(values) for key, values in grid.run(i0, j0).items()})
        source = ColumnDataSource(plotted, name=PLOTTED_SOURCE)
        flat = ColumnDataSource({key: grid.flat(key) for key in grid.series}, name="kc-grid")

        figures = []
        time_range = Range1d(float(grid.time[0]) - 0.5, float(grid.time[-1]) + 0.5)
        for panel in self.panels:
            y_range = self._y_range(panel)
            size = {"height": panel.height, "sizing_mode": "stretch_width"}
            if panel.equal_aspect:
                # même échelle en x et en y : rapport largeur/hauteur fixé par les bornes
                (x0, x1), (y0, y1) = panel.x_range, y_range
                size = {"aspect_ratio": (x1 - x0) / (y1 - y0), "sizing_mode": "scale_width"}
            fig = figure(
                title=french_spacing(panel.title),
                tools="pan,box_zoom,wheel_zoom,reset,save",
                toolbar_location="right",
                x_range=Range1d(*panel.x_range) if panel.own_x else time_range,
                y_range=Range1d(*y_range),
                y_axis_type="log" if panel.y_log else "linear",
                **size,
            )
            fig.toolbar.logo = None  # pas de lien sortant vers bokeh.org
            fig.toolbar.autohide = True
            fig.xaxis.axis_label = french_spacing(panel.x_label or self.x_label)
            fig.yaxis.axis_label = french_spacing(panel.y_label)
            # graduations en français (virgule décimale, × 10ⁿ), sur les axes linéaires et logarithmiques
            fig.xaxis.formatter = bokeh_tick_formatter()
            fig.yaxis.formatter = bokeh_tick_formatter()
            items = []
            for glyph in panel.glyphs:
                if glyph.kind == "line":
                    r = fig.line(glyph.x, glyph.column, source=source, color=glyph.color, line_width=2)
                elif glyph.kind == "scatter":
                    r = fig.scatter(glyph.x, glyph.column, source=source, color=glyph.color, marker="cross", size=8)
                else:
                    x0, x1 = panel.x_range if panel.own_x else (float(grid.time[0]), float(grid.time[-1]))
                    r = fig.line([x0, x1], [glyph.value, glyph.value], color=glyph.color, line_width=1.5)
                items.append(LegendItem(label=french_spacing(glyph.legend), renderers=[r]))
            # légende au-dessus du tracé : elle ne cache jamais les courbes
            fig.add_layout(
                Legend(items=items, orientation="horizontal", location="top_left", label_text_font_size="9pt",
                       border_line_alpha=0, margin=0, padding=2),
                "above",
            )
            figures.append(fig)

        s0, s1 = self._sliders()
        callback = CustomJS(
            args={
                "s0": s0,
                "s1": s1,
                "source": source,
                "grid": flat,
                "names": list(grid.series),
                "n1": int(grid.shape[1]),
                "n_time": int(grid.time.size),
            },
            code=_CALLBACK,
        )
        s0.js_on_change("value", callback)
        s1.js_on_change("value", callback)
        header = [Div(text=f"<strong>{html.escape(french_spacing(self.title))}</strong>")] if self.title else []
        return column(*header, row(s0, s1, sizing_mode="stretch_width"), *figures, sizing_mode="stretch_width")

    # ------------------------------------------------------------------ image fixe (PDF)

    def default_figure(self):
        """La figure matplotlib des mêmes panneaux, à la position par défaut des curseurs : les mêmes
        séries que la figure Bokeh à son ouverture (exécution ``grid.default_index``)."""
        from .spec import draw_panels

        data = {"t": np.array(self.grid.time), **self.fixed, **self.grid.run(*self.grid.default_index)}
        fig, _, _ = draw_panels(self.panels, data, self.x_label)
        return fig

    def caption(self) -> str:
        """Légende de la figure imprimée : titre et valeurs des curseurs à leur position par défaut."""
        values = ", ".join(
            f"{axis.symbol} = {axis.labels()[axis.default]}" for axis in self.grid.axes
        )
        n0, n1 = self.grid.shape
        title = self.title or f"Figure à curseurs « {self.name} »"
        return (
            f"{title}. Curseurs à leur position par défaut ({values}) ; dans le livre en ligne, ils "
            f"parcourent les {n0} × {n1} exécutions précalculées."
        )

    def _repr_mimebundle_(self, include=None, exclude=None):
        """HTML (figure Bokeh, pour le site) et PNG de repli (position par défaut, pour le PDF)."""
        png, size = self.default_figure()._repr_png_()
        return {"text/html": self.html(), "image/png": png}, {"image/png": size}

    # ------------------------------------------------------------------ sortie HTML

    def html(self) -> str:
        """Le fragment HTML de la figure : conteneur, données (JSON) et script d'insertion.

        Le script suppose BokehJS déjà chargé (``window.Bokeh``) ; sinon il affiche un message.
        """
        item = json.dumps(json_item(self.layout), separators=(",", ":"), allow_nan=False)
        # « </ » fermerait la balise <script> : échappement JSON équivalent
        item = item.replace("</", "<\\/").replace("<!--", "<\\!--")
        digest = hashlib.sha1(item.encode()).hexdigest()[:10]
        root_id = f"kc-{self.name}-{digest}"
        hint = f" (<code>{html.escape(self.live_hint)}</code>)" if self.live_hint else ""
        # Message visible seulement si BokehJS manque (carnet ouvert dans Jupyter, par exemple) :
        # dans le livre, le script l'efface avant d'insérer la figure.
        missing = (
            "Figure à curseurs précalculés : elle s’affiche dans le livre publié, qui sert BokehJS. "
            f"Dans Jupyter, utilisez les curseurs vivants{hint}."
        )
        return (
            f'<div class="kc-bokeh-figure" {MARKER}="{self.name}" data-bokeh-version="{BOKEH_VERSION}" '
            f'{CAPTION_ATTRIBUTE}="{html.escape(self.caption(), quote=True)}">\n'
            f'<div id="{root_id}" class="kc-bokeh-root"><p class="kc-bokeh-missing">{missing}</p></div>\n'
            f'<script type="application/json" id="{root_id}-item">{item}</script>\n'
            "<script>(function () {\n"
            '  if (typeof window.Bokeh === "undefined" || !window.Bokeh.embed) return;\n'
            f'  var root = document.getElementById("{root_id}");\n'
            '  root.textContent = "";\n'
            f'  var item = JSON.parse(document.getElementById("{root_id}-item").textContent);\n'
            f'  window.Bokeh.embed.embed_item(item, root);\n'
            "})();</script>\n"
            "</div>\n"
        )

    def _repr_html_(self) -> str:
        return self.html()

    def __repr__(self) -> str:
        n0, n1 = self.grid.shape
        a0, a1 = self.grid.axes
        return (
            f"<Figure à curseurs statiques « {self.name} » : {a0.symbol} × {a1.symbol}, "
            f"{n0} × {n1} exécutions précalculées>"
        )
