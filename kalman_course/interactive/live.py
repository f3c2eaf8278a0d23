r"""Curseurs interactifs (ipywidgets) : relancent le filtre du paquet à chaque relâchement de curseur.

À utiliser dans Jupyter, sur Binder ou sur Colab (un noyau Python doit tourner). Les curseurs sont
logarithmiques (``FloatLogSlider``) et affichent la vraie valeur du paramètre ; ``continuous_update``
est désactivé : le calcul n'a lieu qu'au relâchement. La figure est une figure matplotlib du paquet
(:func:`~kalman_course.figures.new_figure`, sans pyplot), rendue en PNG dans un widget ``Image``.

Dans le livre publié (sans noyau), ces curseurs seraient morts : le livre montre à leur place la
figure à curseurs statiques (:mod:`kalman_course.interactive.static`).
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass
from typing import Callable, Mapping

import ipywidgets as widgets
import numpy as np

from ..core.validation import KalmanInputError, as_float_array
from ..numbers import format_spec
from .grid import format_value
from .spec import Panel, check_columns, draw_panels, fill_glyph, panel_y_range

__all__ = ["LogParameter", "LinearParameter", "ChoiceParameter", "LiveExplorer"]

#: Résolution du PNG affiché (pixels par pouce).
LIVE_DPI = 100


@dataclass(frozen=True)
class LogParameter:
    r"""Un curseur logarithmique : ``name`` (argument de ``run``), ``description`` (français), ``unit``,
    valeur initiale ``value`` et bornes en décades ``min_exp``, ``max_exp`` (valeurs
    :math:`10^{\min}` à :math:`10^{\max}`), pas ``step`` en décades."""

    name: str
    description: str
    unit: str
    value: float
    min_exp: float
    max_exp: float
    step: float = 0.1

    def __post_init__(self) -> None:
        if not self.min_exp < self.max_exp:
            raise KalmanInputError(
                f"Curseur « {self.name} » : « min_exp » ({self.min_exp}) doit être < « max_exp » ({self.max_exp})."
            )
        v = float(self.value)
        low, high = 10.0**self.min_exp, 10.0**self.max_exp
        if not (math.isfinite(v) and low <= v <= high):
            raise KalmanInputError(
                f"« {self.name} » = {self.value!r} est hors de la plage du curseur [{format_spec(low, '.3g')} ; {format_spec(high, '.3g')}] {self.unit}."
            )

    def slider(self) -> widgets.FloatLogSlider:
        """Le ``FloatLogSlider`` : la valeur lue et affichée est la vraie valeur (pas son logarithme)."""
        return widgets.FloatLogSlider(
            value=float(self.value),
            base=10.0,
            min=self.min_exp,
            max=self.max_exp,
            step=self.step,
            description=f"{self.description} ({self.unit})",
            readout=False,  # valeur écrite en français à côté (LiveExplorer.readouts)
            continuous_update=False,
            style={"description_width": "14em"},
            layout=widgets.Layout(width="36em"),
        )


@dataclass(frozen=True)
class LinearParameter:
    """Un curseur linéaire (``FloatSlider``) : ``name``, ``description``, ``unit``, valeur initiale
    ``value``, bornes ``low`` et ``high``, pas ``step``."""

    name: str
    description: str
    unit: str
    value: float
    low: float
    high: float
    step: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.low) and math.isfinite(self.high) and self.low < self.high):
            raise KalmanInputError(
                f"Curseur « {self.name} » : « low » ({self.low}) doit être < « high » ({self.high})."
            )
        if not (isinstance(self.step, (int, float)) and self.step > 0):
            raise KalmanInputError(f"Curseur « {self.name} » : « step » doit être > 0 ; reçu {self.step!r}.")
        v = float(self.value)
        if not (math.isfinite(v) and self.low <= v <= self.high):
            raise KalmanInputError(
                f"« {self.name} » = {self.value!r} est hors de la plage du curseur [{format_spec(self.low, '.3g')} ; {format_spec(self.high, '.3g')}] {self.unit}."
            )

    def slider(self) -> widgets.FloatSlider:
        """Le ``FloatSlider`` (la valeur lue est la vraie valeur)."""
        return widgets.FloatSlider(
            value=float(self.value), min=self.low, max=self.high, step=self.step,
            description=f"{self.description} ({self.unit})" if self.unit else self.description,
            readout=False, continuous_update=False,  # valeur écrite en français à côté
            style={"description_width": "14em"}, layout=widgets.Layout(width="36em"),
        )


@dataclass(frozen=True)
class ChoiceParameter:
    """Un curseur à positions discrètes (``SelectionSlider``) : une itération, une étape de la boucle.

    ``values`` : les valeurs passées à ``run`` ; ``labels`` : le texte affiché à chaque position ;
    ``value`` : la valeur initiale (une des ``values``)."""

    name: str
    description: str
    values: tuple[float, ...]
    labels: tuple[str, ...]
    value: float

    def __post_init__(self) -> None:
        if len(self.values) < 2 or len(self.values) != len(self.labels):
            raise KalmanInputError(
                f"Curseur « {self.name} » : au moins deux valeurs, et un libellé par valeur "
                f"({len(self.values)} valeurs, {len(self.labels)} libellés)."
            )
        if float(self.value) not in [float(v) for v in self.values]:
            raise KalmanInputError(f"« {self.name} » = {self.value!r} n'est pas une des positions du curseur.")

    def slider(self) -> widgets.SelectionSlider:
        """Le ``SelectionSlider`` : affiche le libellé, renvoie la valeur."""
        return widgets.SelectionSlider(
            options=list(zip(self.labels, [float(v) for v in self.values])), value=float(self.value),
            description=self.description, continuous_update=False,
            style={"description_width": "14em"}, layout=widgets.Layout(width="36em"),
        )


_PARAMETERS = (LogParameter, LinearParameter, ChoiceParameter)


class LiveExplorer:
    """Curseurs ipywidgets + figure matplotlib redessinée par le filtre du paquet.

    Paramètres
    ----------
    run : fonction ``run(**valeurs) -> dict nom → (T,)``
        Relance le filtre pour les valeurs des curseurs (une clé par ``LogParameter.name``).
    parameters : suite de LogParameter, LinearParameter ou ChoiceParameter
        Les curseurs, dans l'ordre d'affichage.
    time : (T,)
        Abscisse commune.
    panels : suite de Panel
        La figure (la même description que pour les curseurs statiques).
    x_label : str
        Libellé de l'abscisse, avec unité.
    fixed : dict nom → (L,), optionnel
        Séries indépendantes des curseurs (mesures, courbe de référence).
    readout : fonction ``(séries, valeurs) -> str``, optionnelle
        Texte affiché au-dessus de la figure (les nombres de l'exécution courante).

    Attributs utiles : ``sliders`` (dict nom → ``FloatLogSlider``), ``readouts`` (dict nom → ``Label`` :
    la valeur d'un curseur numérique écrite en français), ``series`` (la dernière
    exécution), ``lines`` (dict nom de série → liste de ``Line2D`` tracées), ``figure``, ``widget``.
    """

    def __init__(
        self,
        run: Callable[..., Mapping[str, np.ndarray]],
        parameters,
        time,
        panels,
        x_label: str,
        fixed: Mapping[str, np.ndarray] | None = None,
        readout: Callable[[Mapping[str, np.ndarray], Mapping[str, float]], str] | None = None,
    ) -> None:
        if not callable(run):
            raise KalmanInputError(f"« run » doit être une fonction ; reçu {type(run).__name__}.")
        self.parameters = tuple(parameters)
        if not self.parameters or not all(isinstance(p, _PARAMETERS) for p in self.parameters):
            raise KalmanInputError(
                "« parameters » doit être une suite non vide de LogParameter, LinearParameter ou ChoiceParameter."
            )
        self.panels = tuple(panels)
        if not self.panels or not all(isinstance(p, Panel) for p in self.panels):
            raise KalmanInputError("« panels » doit être une suite non vide de Panel.")
        self.run = run
        self.time = as_float_array("time", time)
        self.fixed = {k: as_float_array(f"fixed[{k!r}]", v, allow_nan=True) for k, v in (fixed or {}).items()}
        self.sliders = {p.name: p.slider() for p in self.parameters}
        self.series = self._compute()
        self._lengths = {"t": self.time.size, **{k: v.size for k, v in self.fixed.items()},
                         **{k: v.size for k, v in self.series.items()}}
        check_columns(self.panels, set(self.series) | set(self.fixed), self._lengths)
        self._fills: list = []
        self.figure, self.lines, self._axes = self._draw(x_label)
        self.image = widgets.Image(format="png", value=self._png())
        self.readout = readout
        self.text = widgets.HTML(value=self._text())
        # la valeur lue d'un curseur numérique, écrite en français (le widget écrirait « 0.003 ») ;
        # un curseur à positions discrètes affiche déjà son libellé
        self._units = {p.name: p.unit for p in self.parameters if not isinstance(p, ChoiceParameter)}
        self.readouts = {name: widgets.Label(value=format_value(self.sliders[name].value, unit))
                         for name, unit in self._units.items()}
        for slider in self.sliders.values():
            slider.observe(self._on_change, names="value")
        rows = [widgets.HBox([slider, self.readouts[name]]) if name in self.readouts else slider
                for name, slider in self.sliders.items()]
        self.widget = widgets.VBox([*rows, self.text, self.image])

    # ------------------------------------------------------------------ calcul et dessin

    def values(self) -> dict[str, float]:
        """Les valeurs actuelles des curseurs (vraies valeurs, pas leurs logarithmes)."""
        return {name: float(s.value) for name, s in self.sliders.items()}

    def _compute(self) -> dict[str, np.ndarray]:
        out = self.run(**self.values())
        T = self.time.size
        series = {}
        known = getattr(self, "_lengths", None)
        for name, values in out.items():
            if name == "t":
                raise KalmanInputError("« run » ne doit pas renvoyer de série nommée « t » (réservé au temps).")
            arr = np.asarray(values, dtype=float)
            expected = known[name] if known and name in known else None
            if arr.ndim != 1 or (expected is not None and arr.size != expected):
                raise KalmanInputError(
                    f"La série « {name} » doit avoir la forme ({expected or T},) ; reçu {arr.shape}."
                )
            series[name] = arr
        return series

    def _draw(self, x_label: str):
        data = {"t": self.time, **self.fixed, **self.series}
        fig, drawn, axes = draw_panels(self.panels, data, x_label)
        lines: dict[str, list] = {}  # seules les courbes qui dépendent des curseurs sont redessinées
        for column, found in drawn.items():
            moving = [line for line in found if column in self.series or line.kc_columns[0] in self.series]
            if moving:
                lines[column] = moving
        self._fills = list(fig.kc_fills)
        return fig, lines, axes

    def _text(self) -> str:
        return "" if self.readout is None else str(self.readout(self.series, self.values()))

    def _png(self) -> bytes:
        buffer = io.BytesIO()
        self.figure.savefig(buffer, format="png", dpi=LIVE_DPI)
        return buffer.getvalue()

    def redraw(self) -> None:
        """Relance le filtre avec les valeurs des curseurs et redessine les courbes."""
        self.series = self._compute()
        data = {"t": self.time, **self.fixed, **self.series}
        for lines in self.lines.values():
            for line in lines:
                x, y = line.kc_columns
                line.set_data(data[x], data[y])
        fills = []
        for ax, glyph, collection in self._fills:
            collection.remove()
            fills.append((ax, glyph, fill_glyph(ax, glyph, data)))
        self._fills = fills
        for ax, panel in zip(self._axes, self.panels):
            if panel.follows:
                ax.set_ylim(*panel_y_range(panel, data))
            elif panel.y_range is None:
                ax.relim()
                ax.autoscale_view(scalex=False)
        self.image.value = self._png()
        self.text.value = self._text()

    def _on_change(self, change) -> None:
        for name, label in self.readouts.items():
            label.value = format_value(self.sliders[name].value, self._units[name])
        self.redraw()

    # ------------------------------------------------------------------ affichage Jupyter

    def _repr_mimebundle_(self, **kwargs):
        return self.widget._repr_mimebundle_(**kwargs)

    def __repr__(self) -> str:
        values = " ; ".join(f"{k} = {format_spec(v, '.3g')}" for k, v in self.values().items())
        return f"<Curseurs interactifs ({values}) : exige un noyau Jupyter en marche>"
