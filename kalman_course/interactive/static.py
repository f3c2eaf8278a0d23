r"""Curseurs statiques : une figure Bokeh dont des curseurs (un à trois) choisissent parmi des exécutions précalculées.

La page publiée n'a pas de noyau : la figure embarque toute une :class:`~.grid.ParameterGrid`
(``float64``, donc les valeurs exactes du paquet) et un petit rappel JavaScript (``CustomJS``) qui,
à chaque mouvement d'un curseur, recopie l'exécution choisie dans la source de données tracée.

BokehJS n'est **pas** inclus dans la figure : le site le sert lui-même, une fois pour tout le site,
dans ``_static/bokeh/`` (copié du paquet Python ``bokeh`` installé par ``scripts/vendor_assets.py``,
donc à la même version). L'extension Sphinx :mod:`kalman_course.sphinx.sliders` ajoute les
balises ``<script>`` dans l'en-tête des seules pages qui contiennent une telle figure (repérées par
l'attribut :data:`MARKER`), une fois par page, avec un chemin relatif qui marche en ``http://`` comme
en ``file://``. Hors du livre (dans Jupyter), la figure affiche un message qui renvoie vers les
curseurs interactifs (:mod:`kalman_course.interactive.live`).

Le PDF du cours (constructeur LaTeX) ne peut pas animer de curseurs : la figure fournit aussi une
image PNG (matplotlib, mêmes panneaux, exécution de la position par défaut des curseurs) et une
légende (:meth:`StaticSliders.caption`, dans l'attribut HTML :data:`CAPTION_ATTRIBUTE`) ; l'extension
Sphinx place l'image dans une figure légendée du PDF. Le site, lui, affiche toujours le HTML.
"""

from __future__ import annotations

import hashlib
import html
import itertools
import json
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Mapping

import bokeh
import numpy as np
from bokeh.layouts import column, row
from bokeh.models import (
    ColumnDataSource,
    CustomJS,
    CustomJSTickFormatter,
    Legend,
    LegendItem,
    Range1d,
    Slider,
)
from bokeh.plotting import figure

from ..core.validation import KalmanInputError, as_float_array
from ..typography import french_spacing, italic_latin_html
from ..numbers import bokeh_tick_formatter
from .grid import ParameterGrid
from .spec import Panel, check_columns, panel_ranges, panel_y_range

__all__ = ["MARKER", "CAPTION_ATTRIBUTE", "BOKEH_VERSION", "PLOTTED_SOURCE", "bokehjs_files", "plotted_source_name",
           "StaticSliders"]

#: Attribut HTML qui signale une figure à curseurs statiques (lu par l'extension Sphinx).
MARKER = "data-kc-bokeh"
#: Attribut HTML qui porte la légende de la figure imprimée (PDF), lue par l'extension Sphinx.
CAPTION_ATTRIBUTE = "data-kc-caption"
#: Version de BokehJS attendue par les figures (celle du paquet Python ``bokeh`` installé).
BOKEH_VERSION = bokeh.__version__

#: Nom du ``ColumnDataSource`` tracé (les tests le relisent dans ``Bokeh.documents``).
PLOTTED_SOURCE = "kc-plotted"


def _is_year_axis(label) -> bool:
    """Vrai pour une abscisse d'années (libellé « année » ou « années », avec ou sans unité) : ses
    graduations s'écrivent sans séparateur de milliers (« 1880 »)."""
    text = label if isinstance(label, str) else ""
    return text.split("(")[0].strip().lower() in {"année", "années", "an"}


def bokehjs_files() -> list[str]:
    """Fichiers BokehJS nécessaires, relatifs à ``_static/`` : noyau puis composants (curseurs)."""
    return [f"bokeh/bokeh-{BOKEH_VERSION}.min.js", f"bokeh/bokeh-widgets-{BOKEH_VERSION}.min.js"]


def installed_bokehjs() -> dict[str, Path]:
    """Fichiers BokehJS du paquet Python ``bokeh`` installé : nom servi (:func:`bokehjs_files`) → chemin
    source (copiés par ``scripts/vendor_assets.py``, vérifiés par l'extension du livre)."""
    from bokeh.util.paths import bokehjs_path

    js = Path(bokehjs_path()) / "js"
    return dict(zip(bokehjs_files(), [js / "bokeh.min.js", js / "bokeh-widgets.min.js"]))


# Rappel exécuté par le navigateur à chaque mouvement d'un curseur : l'exécution d'indice plat
# k = (i·N1 + j)·N2 + … occupe, pour une série de longueur L, les indices [k·L, (k + 1)·L) de sa
# version aplatie ; les séries sont groupées par longueur (une source tracée par longueur). Les
# panneaux dont l'ordonnée suit l'exécution (Follow) reçoivent leurs bornes précalculées.
_CALLBACK = """
let k = 0;
for (let a = 0; a < sliders.length; a++) k = k * dims[a] + Math.round(sliders[a].value);
for (let g = 0; g < sources.length; g++) {
  const source = sources[g], grid = grids[g], n = lengths[g];
  const data = {};
  for (const name of Object.keys(source.data)) data[name] = source.data[name];
  for (const name of names[g]) data[name] = grid.data[name].slice(k * n, (k + 1) * n);
  source.data = data;
}
for (let p = 0; p < follow.length; p++) {
  const b = bounds[p];
  if (b[4 * k] !== null) follow[p].x_range.setv({start: b[4 * k], end: b[4 * k + 1]});
  follow[p].y_range.setv({start: b[4 * k + 2], end: b[4 * k + 3]});
}
if (texts.length) {
  const el = document.getElementById(readout);
  if (el) el.textContent = texts[k];
}
if (window.kcFigures) window.kcFigures.announce(readout.slice(0, -8));
"""


#: Largeur (px) que l'on peut compter pour une ligne de légende dans la colonne du livre.
LEGEND_WIDTH = 600
#: … et sur un téléphone (390 px de large, moins les marges et la barre d'outils) : la légende, dessinée
#: par Bokeh à taille fixe au-dessus du panneau, y serait coupée ; elle prend autant de lignes qu'il faut
#: pour tenir dans cette largeur.
PHONE_LEGEND_WIDTH = 320
#: Hauteur (px) d'une ligne de légende (9 pt) : un panneau de hauteur fixe grandit d'autant par ligne de
#: légende ajoutée pour le téléphone, pour garder la même aire de tracé.
LEGEND_ROW_HEIGHT = 19


def _legend_rows(items, width: float = LEGEND_WIDTH) -> int:
    """Nombre de lignes de la légende pour qu'elle tienne dans ``width`` pixels (la colonne du livre, la
    moitié pour deux panneaux côte à côte, ou un téléphone). Bokeh range les éléments ligne par ligne dans
    une grille de ``ceil(n / lignes)`` colonnes, chaque colonne aussi large que son plus long élément
    (largeur estimée : 6,3 px par caractère en 9 pt, plus le symbole)."""
    import math

    widths = [6.3 * len(item.label.value if hasattr(item.label, "value") else str(item.label)) + 40 for item in items]
    n = len(widths)
    for rows in range(1, n + 1):
        columns = math.ceil(n / rows)
        if sum(max(widths[c::columns]) for c in range(columns)) <= width:
            return rows
    return max(n, 1)


def plotted_source_name(length: int, time_length: int) -> str:
    """Nom de la source tracée des séries de longueur ``length`` : :data:`PLOTTED_SOURCE` pour celles
    du temps commun, ``kc-plotted-<longueur>`` pour les autres."""
    return PLOTTED_SOURCE if length == time_length else f"{PLOTTED_SOURCE}-{length}"


def _setting(axis) -> str:
    """« symbole = valeur » d'un axe à sa position par défaut ; l'étiquette qui porte déjà son symbole
    (« n = 6 : correction ») est reprise telle quelle."""
    label = axis.labels()[axis.default]
    return label if label.startswith(f"{axis.symbol} =") else f"{axis.symbol} = {label}"


@dataclass(eq=False)
class StaticSliders:
    """Figure Bokeh à curseurs (un à trois) sur une grille précalculée (aucun noyau nécessaire).

    Paramètres
    ----------
    grid : ParameterGrid
        Les exécutions précalculées ; le curseur ``k`` parcourt ``grid.axes[k].values``.
    panels : suite de Panel
        Les panneaux, empilés verticalement ; abscisse commune ``grid.time`` (série ``"t"``), sauf
        pour un panneau dont les tracés ont leur propre abscisse (``Glyph.x``).
    x_label : str
        Libellé de l'abscisse, avec unité.
    fixed : dict nom → (L,), optionnel
        Séries qui ne dépendent pas des curseurs (mesures, vérité, courbe de référence).
    name : str
        Identifiant court de la figure (attribut HTML, identifiant d'élément).
    title : str
        Titre affiché au-dessus des curseurs.
    live_hint : str
        L'appel qui donne les curseurs interactifs équivalents dans Jupyter (cité hors du livre).
    readout : fonction ``index -> str``, optionnelle
        Le texte affiché sous les curseurs au point de grille ``index`` (tuple d'indices) : les
        nombres de cette exécution, écrits en français (:func:`kalman_course.numbers.format_number`).
    """

    grid: ParameterGrid
    panels: tuple[Panel, ...]
    x_label: str
    fixed: Mapping[str, np.ndarray] = field(default_factory=dict)
    name: str = "curseurs"
    title: str = ""
    live_hint: str = ""
    readout: Callable[[tuple[int, ...]], str] | None = None

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
            if arr.ndim != 1 or arr.size == 0:
                raise KalmanInputError(f"La série fixe « {key} » doit être un vecteur non vide ; reçu {arr.shape}.")
            if key in self.grid.series:
                raise KalmanInputError(f"La série fixe « {key} » porte le nom d'une série calculée.")
            fixed[key] = arr
        self.fixed = fixed
        lengths = {"t": T, **{k: v.size for k, v in fixed.items()}}
        lengths.update({k: self.grid.length(k) for k in self.grid.series})
        check_columns(self.panels, set(self.grid.series) | set(fixed), lengths)
        for panel in self.panels:
            for glyph in panel.glyphs:
                if glyph.x == "t" and glyph.columns and lengths[glyph.column] != T:
                    raise KalmanInputError(
                        f"Le tracé « {glyph.legend} » a pour abscisse le temps commun : la série « {glyph.column} » "
                        f"doit avoir la forme ({T},) ; reçu ({lengths[glyph.column]},)."
                    )
        if self.readout is not None and not callable(self.readout):
            raise KalmanInputError("« readout » doit être une fonction index → texte.")
        self._lengths = lengths
        self.layout = self._build()

    # ------------------------------------------------------------------ construction Bokeh

    @property
    def columns(self) -> int:
        """Panneaux par ligne sur un grand écran : deux si la figure a un plan (``equal_aspect``) et
        plusieurs panneaux, sinon un (la page passe à un par ligne sur un écran étroit)."""
        return 2 if any(p.equal_aspect for p in self.panels) and len(self.panels) > 1 else 1

    def _sliders(self) -> list[Slider]:
        sliders = []
        for k, axis in enumerate(self.grid.axes):
            labels = [french_spacing(label) for label in axis.labels()]
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
        return sliders

    def _column_values(self, name: str) -> np.ndarray:
        if name in self.grid.series:
            return self.grid.series[name].ravel()
        return self.fixed[name]

    def _y_range(self, panel: Panel) -> tuple[float, float]:
        """Bornes de l'ordonnée communes à toute la grille : en déplaçant un curseur, on voit la courbe
        bouger, pas l'axe (échelle log : décades entières ; sinon marge de 5 %). Un panneau
        :class:`~.spec.Follow` a ses bornes à chaque exécution (:meth:`follow_ranges`) ; ici, leur union."""
        if panel.follows:
            bounds = self.follow_ranges()[self.panels.index(panel)]
            return float(bounds[:, 2].min()), float(bounds[:, 3].max())
        return panel_y_range(panel, {name: self._column_values(name) for name in panel.range_columns()})

    def follow_ranges(self) -> list[np.ndarray | None]:
        """Bornes de chaque panneau :class:`~.spec.Follow` à chaque exécution : tableau ``(N0·N1·…, 4)``
        ``(x0, x1, y0, y1)`` dans l'ordre plat de la grille (``x0 = x1 = NaN`` si l'abscisse ne suit pas) ;
        ``None`` pour un panneau à bornes fixes."""
        if getattr(self, "_follow_ranges", None) is None:
            grid = self.grid
            runs = [{"t": grid.time, **self.fixed, **grid.run(*index)}
                    for index in itertools.product(*(range(n) for n in grid.shape))]
            out = []
            for panel in self.panels:
                if not panel.follows:
                    out.append(None)
                    continue
                rows = []
                for run in runs:
                    x, y = panel_ranges(panel, run)
                    rows.append((*(x if x is not None else (np.nan, np.nan)), *y))
                out.append(np.array(rows))
            self._follow_ranges = out
        return self._follow_ranges

    def y_range_at(self, panel: int, *index: int) -> tuple[float, float]:
        """Bornes de l'ordonnée du panneau n° ``panel`` quand les curseurs sont au point ``index``."""
        return self.ranges_at(panel, *index)[1]

    def ranges_at(self, panel: int, *index: int) -> tuple[tuple[float, float], tuple[float, float]]:
        """``(abscisse, ordonnée)`` du panneau n° ``panel`` quand les curseurs sont au point ``index`` (abscisse
        du temps commun pour un panneau qui n'a pas la sienne)."""
        p = self.panels[panel]
        ranges = self.follow_ranges()[panel]
        x = tuple(p.x_range) if p.own_x else (float(self.grid.time[0]) - 0.5, float(self.grid.time[-1]) + 0.5)
        if ranges is None:
            return x, self._y_range(p)
        row = ranges[int(np.ravel_multi_index(index, self.grid.shape))]
        if np.isfinite(row[0]):
            x = (float(row[0]), float(row[1]))
        return x, (float(row[2]), float(row[3]))

    def _sources(self):
        """Une source tracée par longueur de série (« t » et séries du temps commun ensemble), et la
        grille aplatie correspondante ; renvoie ``(sources, grids, names, lengths, source_of)``."""
        grid = self.grid
        T = grid.time.size
        current = grid.run(*grid.default_index)
        by_length: dict[int, dict[str, np.ndarray]] = {T: {"t": np.array(grid.time)}}
        for key, values in self.fixed.items():
            by_length.setdefault(values.size, {})[key] = np.array(values)
        for key, values in current.items():
            by_length.setdefault(values.size, {})[key] = np.array(values)
        sources, grids, names, lengths, source_of = [], [], [], [], {}
        for length, columns in by_length.items():
            source = ColumnDataSource(columns, name=plotted_source_name(length, T))
            for key in columns:
                source_of[key] = source
            computed = [key for key in columns if key in grid.series]
            if computed:
                sources.append(source)
                grids.append(ColumnDataSource({key: grid.flat(key) for key in computed},
                                              name=f"kc-grid-{length}"))
                names.append(computed)
                lengths.append(length)
        return sources, grids, names, lengths, source_of

    def _build(self):
        grid = self.grid
        sources, grids, names, lengths, source_of = self._sources()

        figures = []
        time_range = Range1d(float(grid.time[0]) - 0.5, float(grid.time[-1]) + 0.5)
        follow, bounds = [], []
        for p, panel in enumerate(self.panels):
            x_range, y_range = self.ranges_at(p, *grid.default_index)
            legends = [LegendItem(label=french_spacing(g.legend)) for g in panel.glyphs if g.legend]
            rows = _legend_rows(legends, min(PHONE_LEGEND_WIDTH, LEGEND_WIDTH / self.columns))
            extra = rows - _legend_rows(legends, LEGEND_WIDTH / self.columns) if legends else 0
            size = {"height": panel.height + LEGEND_ROW_HEIGHT * extra, "sizing_mode": "stretch_width"}
            if panel.equal_aspect:
                # même échelle en x et en y : rapport largeur/hauteur fixé par les bornes
                ratio = panel.aspect(y_range)
                size = {"aspect_ratio": ratio, "sizing_mode": "scale_width"}
                if panel.width is not None:  # au plus sa largeur (la page la lui donne), moins sur un téléphone
                    size = {"aspect_ratio": ratio, "sizing_mode": "scale_width", "max_width": panel.width}
            fig = figure(
                # le titre du panneau est écrit par la page (HTML, il passe à la ligne) : pas dans le canevas
                tools="pan,box_zoom,wheel_zoom,reset,save",
                toolbar_location="right",
                x_range=Range1d(*x_range) if panel.own_x else time_range,
                y_range=Range1d(*y_range),
                y_axis_type="log" if panel.y_log else "linear",
                x_axis_type="log" if panel.x_log else "linear",
                **size,
            )
            fig.toolbar.logo = None  # pas de lien sortant vers bokeh.org
            fig.toolbar.autohide = True
            fig.xaxis.axis_label = french_spacing(panel.x_label or self.x_label)
            fig.yaxis.axis_label = french_spacing(panel.y_label)
            # graduations en français (virgule décimale, × 10ⁿ), sur les axes linéaires et logarithmiques
            fig.xaxis.formatter = bokeh_tick_formatter(group_thousands=not _is_year_axis(fig.xaxis.axis_label))
            if self.columns == 2 and not panel.equal_aspect:  # demi-colonne : moins de graduations, lisibles
                fig.xaxis.ticker.desired_num_ticks = 4
            fig.yaxis.formatter = bokeh_tick_formatter()
            items = []
            for glyph in panel.glyphs:
                r = self._glyph(fig, panel, glyph, source_of)
                if glyph.legend:
                    items.append(LegendItem(label=french_spacing(glyph.legend), renderers=[r]))
            # légende au-dessus du tracé : elle ne cache jamais les courbes
            if items:
                fig.add_layout(
                    Legend(items=items, orientation="horizontal", location="top_left", label_text_font_size="9pt",
                           border_line_alpha=0, margin=0, padding=2,
                           nrows=rows),
                    "above",
                )
            figures.append(fig)
            if panel.follows:
                follow.append(fig)
                bounds.append([None if not np.isfinite(v) else float(v)
                               for v in np.ascontiguousarray(self.follow_ranges()[p]).reshape(-1)])

        sliders = self._sliders()
        texts: list[str] = []
        if self.readout is not None:
            texts = [french_spacing(str(self.readout(index)))
                     for index in itertools.product(*(range(n) for n in grid.shape))]
        self._texts = texts
        callback = CustomJS(
            args={
                "sliders": sliders,
                "dims": [int(n) for n in grid.shape],
                "sources": sources,
                "grids": grids,
                "names": names,
                "lengths": lengths,
                "readout": f"{self.element_id}-readout",
                "texts": texts,
                "follow": follow,
                "bounds": bounds,
            },
            code=_CALLBACK,
        )
        for slider in sliders:
            slider.js_on_change("value", callback)
        self.sliders, self.figures = sliders, figures
        return column(row(*sliders, sizing_mode="stretch_width"), *figures, sizing_mode="stretch_width")

    @property
    def element_id(self) -> str:
        """Identifiant HTML de la figure (stable : il ne dépend que du nom et de la grille)."""
        if getattr(self, "_element_id", None) is None:
            h = hashlib.sha1(self.name.encode())
            for name in sorted(self.grid.series):
                h.update(name.encode())
                h.update(np.ascontiguousarray(self.grid.series[name]).tobytes())
            self._element_id = f"kc-{self.name}-{h.hexdigest()[:10]}"
        return self._element_id

    def document_json(self) -> dict:
        """Le document Bokeh de la figure, prêt pour ``Bokeh.embed.embed_items`` : ``{"docs_json", "render_items"}``.

        Une racine par élément de la page : chaque curseur (``<id>-slider-<s>``) et chaque panneau
        (``<id>-panel-<k>``). La page place elle-même ces éléments (CSS) : curseurs et panneaux côte à
        côte sur un grand écran, l'un sous l'autre sur un téléphone.
        """
        from bokeh.document import Document

        roots = {slider: f"{self.element_id}-slider-{k}" for k, slider in enumerate(self.sliders)}
        roots.update({fig: f"{self.element_id}-panel-{k}" for k, fig in enumerate(self.figures)})
        controls = self.layout.children[0]
        saved = (list(self.layout.children), list(controls.children))
        self.layout.children, controls.children = [], []  # chaque élément devient une racine du document
        doc = Document()
        for model in roots:
            doc.add_root(model)
        docid = f"{self.element_id}-doc"
        out = {
            "docs_json": {docid: doc.to_json(deferred=False)},
            "render_items": [{"docid": docid, "roots": {m.id: e for m, e in roots.items()},
                              "root_ids": [m.id for m in roots]}],
        }
        for model in roots:
            doc.remove_root(model)
        self.layout.children, controls.children = saved
        return out

    def _glyph(self, fig, panel: Panel, glyph, source_of):
        """Dessine un tracé ; renvoie son « renderer » Bokeh."""
        style = {"color": glyph.color, "alpha": glyph.alpha}
        if glyph.kind in ("hline", "vline"):
            x0, x1 = panel.x_range if panel.own_x else (float(self.grid.time[0]), float(self.grid.time[-1]))
            if glyph.kind == "hline":
                xs, ys = [x0, x1], [glyph.value, glyph.value]
            else:
                xs, ys = [glyph.value, glyph.value], list(self._y_range(panel))
            return fig.line(xs, ys, color=glyph.color, line_width=glyph.width, line_dash=glyph.dash,
                            alpha=glyph.alpha)
        source = source_of[glyph.column]
        if glyph.kind == "line":
            return fig.line(glyph.x, glyph.column, source=source, line_width=glyph.width, line_dash=glyph.dash,
                            **style)
        if glyph.kind == "scatter":
            return fig.scatter(glyph.x, glyph.column, source=source, marker=glyph.marker, size=glyph.size, **style)
        if glyph.kind == "area":
            return fig.varea(x=glyph.x, y1=0.0, y2=glyph.column, source=source, fill_color=glyph.color,
                             fill_alpha=0.25 * glyph.alpha)
        return fig.varea(x=glyph.x, y1=glyph.column, y2=glyph.upper, source=source, fill_color=glyph.color,
                         fill_alpha=0.25 * glyph.alpha)

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
        values = ", ".join(map(_setting, self.grid.axes))
        sizes = " × ".join(map(str, self.grid.shape))
        title = self.title or f"Figure à curseurs « {self.name} »"
        one = len(self.grid.axes) == 1
        return french_spacing(
            f"{title}. {'Curseur à sa' if one else 'Curseurs à leur'} position par défaut ({values}) ; dans le "
            f"livre en ligne, {'il parcourt' if one else 'ils parcourent'} les {sizes} exécutions précalculées."
        )

    def _repr_mimebundle_(self, include=None, exclude=None):
        """HTML (figure Bokeh, pour le site) et PNG de repli (position par défaut, pour le PDF)."""
        png, size = self.default_figure()._repr_png_()
        return {"text/html": self.html(), "image/png": png}, {"image/png": size}

    # ------------------------------------------------------------------ sortie HTML

    def panel_label(self, k: int) -> str:
        """Texte de remplacement du panneau ``k`` (lecteurs d'écran) : son titre, ses axes et ses tracés."""
        panel = self.panels[k]
        legends = [french_spacing(g.legend) for g in panel.glyphs if g.legend]
        x_label = french_spacing(panel.x_label or self.x_label)
        text = (f"Graphique : {french_spacing(panel.title)}. Abscisse : {x_label} ; ordonnée : "
                f"{french_spacing(panel.y_label)}.")
        if legends:
            text += f" Tracés : {' ; '.join(legends)}."
        return text

    def html(self) -> str:
        """Le fragment HTML de la figure : titre, emplacements des curseurs, du texte de lecture et des
        panneaux, données (JSON) et script d'insertion.

        Dans le livre, le script de la page (``kc-pages.js``, extension :mod:`kalman_course.sphinx.pages`)
        charge BokehJS et dessine la figure quand elle approche de l'écran ; sans lui, le script de la
        figure la dessine aussitôt si BokehJS est déjà chargé, et sinon le message reste affiché.
        """
        item = json.dumps(self.document_json(), separators=(",", ":"), allow_nan=False)
        # « </ » fermerait la balise <script> : échappement JSON équivalent
        item = item.replace("</", "<\\/").replace("<!--", "<\\!--")
        root_id = self.element_id
        hint = f" (<code>{html.escape(self.live_hint)}</code>)" if self.live_hint else ""
        # Message visible seulement si BokehJS manque (carnet ouvert dans Jupyter, par exemple) :
        # dans le livre, le script l'efface avant d'insérer la figure.
        # (HTML brut : l'extension de typographie du livre ne le voit pas, d'où french_spacing ici)
        missing = french_spacing(
            "Figure à curseurs précalculés : elle s’affiche dans le livre publié, qui sert BokehJS. "
            "Dans Jupyter, utilisez les curseurs interactifs"
        ) + f"{hint}."
        title = italic_latin_html(html.escape(french_spacing(self.title or f"Figure à curseurs « {self.name} »")))
        texts = getattr(self, "_texts", [])
        default = int(np.ravel_multi_index(self.grid.default_index, self.grid.shape))
        readout = (f'<p class="kc-readout" id="{root_id}-readout" aria-live="polite">'
                   f'{italic_latin_html(html.escape(texts[default]))}</p>\n') if texts else ""
        columns = self.columns
        sliders = "".join(f'<div class="kc-bokeh-slider" id="{root_id}-slider-{k}"></div>'
                          for k in range(len(self.grid.axes)))
        described = json.dumps([{"name": french_spacing(f"{a.symbol} — {a.description}"),
                                 "values": [french_spacing(v) for v in a.labels()]} for a in self.grid.axes],
                               ensure_ascii=False, separators=(",", ":")).replace("</", "<\\/")
        panels = "".join(
            f'<div class="kc-bokeh-panel{" kc-bokeh-plane" if p.equal_aspect else ""}" id="{root_id}-panel-{k}-box" '
            # un plan de largeur donnée : cette largeur au plus, la colonne entière sur un téléphone
            + (f'style="flex: 0 1 {p.width}px; max-width: {p.width}px" ' if p.equal_aspect and p.width else "")
            + f'role="figure" aria-label="{html.escape(self.panel_label(k), quote=True)}">'
            f'<p class="kc-panel-title" aria-hidden="true">{italic_latin_html(html.escape(french_spacing(p.title)))}</p>'
            f'<div class="kc-bokeh-canvas" id="{root_id}-panel-{k}"></div></div>'
            for k, p in enumerate(self.panels)
        )
        return (
            f'<div class="kc-bokeh-figure" id="{root_id}-figure" {MARKER}="{self.name}" '
            f'data-bokeh-version="{BOKEH_VERSION}" {CAPTION_ATTRIBUTE}="{html.escape(self.caption(), quote=True)}" '
            f'role="group" aria-labelledby="{root_id}-title" tabindex="-1">\n'
            f'<p class="kc-bokeh-title" id="{root_id}-title"><strong>{title}</strong></p>\n'
            f'<div id="{root_id}" class="kc-bokeh-root" data-columns="{columns}">'
            f'<p class="kc-bokeh-missing">{missing}</p>'
            f'<div class="kc-bokeh-controls" id="{root_id}-controls">{sliders}{readout}</div>\n'
            f'<div class="kc-bokeh-panels">{panels}</div></div>\n'
            f'<script type="application/json" id="{root_id}-sliders">{described}</script>\n'
            f'<script type="application/json" id="{root_id}-item">{item}</script>\n'
            "<script>(function () {\n"
            f'  var id = "{root_id}";\n'
            "  if (window.kcFigures) { window.kcFigures.register(id); return; }\n"
            '  if (typeof window.Bokeh === "undefined" || !window.Bokeh.embed) return;\n'
            '  var root = document.getElementById(id);\n'
            '  root.removeChild(root.querySelector(".kc-bokeh-missing"));\n'
            '  var item = JSON.parse(document.getElementById(id + "-item").textContent);\n'
            "  window.Bokeh.embed.embed_items(item.docs_json, item.render_items);\n"
            "})();</script>\n"
            "</div>\n"
        )

    def _repr_html_(self) -> str:
        return self.html()

    def __repr__(self) -> str:
        symbols = " × ".join(a.symbol for a in self.grid.axes)
        sizes = " × ".join(map(str, self.grid.shape))
        return f"<Figure à curseurs statiques « {self.name} » : {symbols}, {sizes} exécutions précalculées>"
