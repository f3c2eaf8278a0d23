r"""Le registre des figures à curseurs : une description par figure, deux rendus (statique et interactif).

Chaque chapitre décrit sa figure interactive **une fois** par une :class:`SliderSpec` : les axes des
curseurs (:class:`~.grid.ParameterAxis`), la fonction ``run`` qui calcule une exécution par le paquet
(elle appelle une expérience de :mod:`kalman_course.scenarios`), les panneaux (:class:`~.spec.Panel`)
et, au besoin, un texte de lecture (les nombres de l'exécution affichée, en français). La description
donne :

- la **figure statique** du livre publié (:meth:`SliderSpec.static`, Bokeh, toutes les exécutions
  précalculées sur la grille, aucun noyau) ;
- les **curseurs interactifs** de Jupyter (:meth:`SliderSpec.live`, ipywidgets, le filtre relancé pour
  n'importe quelle valeur).

Une fonction ``() -> SliderSpec`` s'inscrit au registre par :func:`register_sliders` ; un chapitre
affiche sa figure par ``kc.interactive.sliders("nom")``, et ``kc.interactive.live_explorer("nom")``
donne les curseurs interactifs.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Mapping

import numpy as np

from ..core.results import freeze
from ..core.validation import KalmanInputError, as_float_array
from .grid import ParameterAxis, ParameterGrid, precompute_grid
from .spec import Panel

__all__ = [
    "SliderSpec",
    "SLIDER_FIGURES",
    "register_sliders",
    "slider_names",
    "slider_spec",
    "slider_grid",
    "sliders",
    "live_explorer",
    "ellipse_outline",
    "number",
    "subscript",
]


@dataclass(eq=False)
class SliderSpec:
    """Une figure à curseurs, décrite une fois.

    ``name`` : identifiant court (attribut HTML) ; ``chapter`` : page du livre ; ``title`` : titre
    affiché au-dessus des curseurs ; ``x_label`` : abscisse commune, avec unité ; ``axes`` : un à trois
    :class:`~.grid.ParameterAxis` (un par curseur) ; ``run(*valeurs) -> dict nom → (L,)`` : une exécution
    du paquet ; ``time`` (T,) : abscisse commune ; ``panels`` : les panneaux ; ``fixed`` : séries
    indépendantes des curseurs ; ``readout(séries, valeurs) -> str`` : le texte affiché sous les
    curseurs (facultatif).
    """

    name: str
    chapter: str
    title: str
    x_label: str
    axes: tuple[ParameterAxis, ...]
    run: Callable[..., Mapping[str, np.ndarray]]
    time: np.ndarray
    panels: tuple[Panel, ...]
    fixed: Mapping[str, np.ndarray] = field(default_factory=dict)
    readout: Callable[[Mapping[str, np.ndarray], tuple[float, ...]], str] | None = None

    def __post_init__(self) -> None:
        self.axes = tuple(self.axes)
        if not 1 <= len(self.axes) <= 3 or not all(isinstance(a, ParameterAxis) for a in self.axes):
            raise KalmanInputError(f"« axes » de « {self.name} » : un à trois ParameterAxis attendus.")
        if not callable(self.run):
            raise KalmanInputError(f"« run » de « {self.name} » doit être une fonction.")
        self.time = as_float_array("time", self.time)
        self.panels = tuple(self.panels)
        self._grid: ParameterGrid | None = None
        self._runs: dict[tuple[int, ...], dict[str, np.ndarray]] = {}  # exécutions faites par run_at

    @property
    def live_hint(self) -> str:
        """L'appel qui donne les curseurs interactifs dans Jupyter."""
        return f'kc.interactive.live_explorer("{self.name}")'

    def grid(self) -> ParameterGrid:
        """Toutes les exécutions de la grille (calculées une fois, puis gardées : elles sont immuables).

        Avec la variable d'environnement :data:`GRID_CACHE` (un dossier neuf, créé par scripts/test.sh pour
        un lancement des tests), la grille calculée par un processus y est écrite et les autres la relisent :
        carnets, session du paquet et visites du navigateur la calculent une fois en tout."""
        if self._grid is None:
            folder = os.environ.get(GRID_CACHE)
            self._grid = (precompute_grid(self.run, *self.axes, time=self.time) if not folder
                          else _shared_grid(self, Path(folder)))
        return self._grid

    def cached_grid(self) -> ParameterGrid | None:
        """La grille si elle est déjà calculée, dans ce processus ou dans le dossier :data:`GRID_CACHE` ;
        sinon ``None`` (rien n'est calculé)."""
        folder = os.environ.get(GRID_CACHE)
        if self._grid is None and folder and (Path(folder) / f"{self.name}.npz").is_file():
            return self.grid()
        return self._grid

    def values_at(self, *index: int) -> tuple[float, ...]:
        """Les valeurs des paramètres au point de grille ``index`` (un indice par curseur)."""
        shape = tuple(axis.values.size for axis in self.axes)
        if len(index) != len(shape) or not all(
            isinstance(i, (int, np.integer)) and not isinstance(i, bool) and 0 <= i < n for i, n in zip(index, shape)
        ):
            raise KalmanInputError(
                f"Point de grille {tuple(index)} hors de la grille {' × '.join(map(str, shape))} de « {self.name} »."
            )
        return tuple(float(axis.values[i]) for axis, i in zip(self.axes, index))

    def run_at(self, *index: int) -> dict[str, np.ndarray]:
        """L'exécution au point de grille ``index`` : ``grid().run(*index)``, sans calculer toute la grille
        quand elle ne l'est pas encore (``run`` appelé avec les mêmes valeurs que pour la grille ; séries
        ``float64`` de forme (L,), en lecture seule). Chaque point est calculé une fois, puis gardé, comme
        la grille (:meth:`text_at` relit la même exécution)."""
        if self._grid is not None:
            return self._grid.run(*index)
        values = self.values_at(*index)  # (vérifie le point)
        key = tuple(int(i) for i in index)
        if key in self._runs:
            return self._runs[key]
        self._runs[key] = {name: freeze(series) for name, series in self.run(*values).items()}
        return self._runs[key]

    def text_at(self, *index: int) -> str:
        """Le texte de lecture au point de grille ``index`` (vide sans ``readout``)."""
        if self.readout is None:
            return ""
        return self.readout(self.run_at(*index), self.values_at(*index))

    def static(self):
        """La figure à curseurs statiques (Bokeh) du livre publié."""
        from .static import StaticSliders

        return StaticSliders(
            self.grid(),
            self.panels,
            x_label=self.x_label,
            fixed=dict(self.fixed),
            name=self.name,
            title=self.title,
            live_hint=self.live_hint,
            readout=None if self.readout is None else (lambda index: self.text_at(*index)),
        )

    def live_parameters(self) -> tuple:
        """Les curseurs interactifs équivalents aux axes : logarithmique, linéaire ou à positions."""
        from .live import ChoiceParameter, LinearParameter, LogParameter

        out = []
        for axis in self.axes:
            label = f"{axis.symbol} ({axis.description})"
            lo, hi = float(axis.values[0]), float(axis.values[-1])
            if axis.scale == "log":
                # bornes élargies d'un cheveu : 10**log10(v) peut différer de v au dernier bit
                out.append(LogParameter(axis.name, label, axis.unit, axis.default_value,
                                        math.log10(lo) - 1e-9, math.log10(hi) + 1e-9, step=0.05))
            elif axis.scale == "linear":
                out.append(LinearParameter(axis.name, label, axis.unit, axis.default_value, lo, hi,
                                           step=(hi - lo) / 200.0))
            else:
                out.append(ChoiceParameter(axis.name, label, tuple(float(v) for v in axis.values),
                                           tuple(axis.labels()), axis.default_value))
        return tuple(out)

    def live(self):
        """Les curseurs interactifs (ipywidgets) : ``run`` relancé à chaque relâchement (noyau requis)."""
        from .live import LiveExplorer

        names = [axis.name for axis in self.axes]
        readout = None
        if self.readout is not None:
            readout = lambda series, values: self.readout(series, tuple(values[n] for n in names))  # noqa: E731
        return LiveExplorer(
            run=lambda **values: self.run(*(values[n] for n in names)),
            parameters=self.live_parameters(),
            time=self.time,
            panels=self.panels,
            x_label=self.x_label,
            fixed=dict(self.fixed),
            readout=readout,
        )


#: Variable d'environnement : dossier où les processus d'un même lancement des tests partagent les grilles.
GRID_CACHE = "KALMAN_GRID_CACHE"


def _shared_grid(spec: SliderSpec, folder: Path) -> ParameterGrid:
    """La grille de ``spec`` lue dans ``folder`` (``NOM.npz`` : une série par nom), ou calculée puis écrite
    (fichier temporaire renommé : un lecteur ne voit jamais un fichier à moitié écrit)."""
    path = folder / f"{spec.name}.npz"
    if path.is_file():
        with np.load(path) as data:
            series = {name: freeze(data[name]) for name in data.files}
        shape = tuple(axis.values.size for axis in spec.axes)
        if all(values.shape[:-1] == shape for values in series.values()):
            return ParameterGrid(axes=spec.axes, time=spec.time, series=series)
    grid = precompute_grid(spec.run, *spec.axes, time=spec.time)
    folder.mkdir(parents=True, exist_ok=True)
    partial = folder / f".{spec.name}.{os.getpid()}.npz"
    np.savez(partial, **grid.series)
    os.replace(partial, path)
    return grid


#: Le registre : nom → (chapitre, fonction qui construit la description).
SLIDER_FIGURES: dict[str, tuple[str, Callable[[], SliderSpec]]] = {}
_SPECS: dict[str, SliderSpec] = {}


def register_sliders(name: str, *, chapter: str):
    """Décorateur : inscrit une fonction ``() -> SliderSpec`` sous ``name`` (unique)."""

    def decorator(func: Callable[[], SliderSpec]) -> Callable[[], SliderSpec]:
        if name in SLIDER_FIGURES:
            raise RuntimeError(f"Figure à curseurs « {name} » déjà enregistrée.")
        SLIDER_FIGURES[name] = (chapter, func)
        return func

    return decorator


def slider_names(chapter: str | None = None) -> list[str]:
    """Noms des figures à curseurs (toutes, ou celles d'un chapitre)."""
    return [n for n, (c, _) in SLIDER_FIGURES.items() if chapter is None or c == chapter]


def slider_spec(name: str) -> SliderSpec:
    """La description de la figure ``name`` (construite une fois)."""
    if name not in SLIDER_FIGURES:
        raise KalmanInputError(
            f"Figure à curseurs inconnue « {name} ». Figures disponibles : {', '.join(SLIDER_FIGURES)}."
        )
    if name not in _SPECS:
        spec = SLIDER_FIGURES[name][1]()
        if spec.name != name:
            raise RuntimeError(f"La figure inscrite sous « {name} » se nomme « {spec.name} ».")
        _SPECS[name] = spec
    return _SPECS[name]


def slider_grid(name: str) -> ParameterGrid:
    """La grille précalculée de la figure ``name``."""
    return slider_spec(name).grid()


def sliders(name: str):
    """La figure à curseurs statiques ``name`` (à afficher dans le livre : aucun noyau nécessaire)."""
    return slider_spec(name).static()


def live_explorer(name: str):
    """Les curseurs interactifs de la figure ``name`` (Jupyter, Binder, Colab : un noyau doit tourner)."""
    return slider_spec(name).live()


_SUBSCRIPT = str.maketrans("0123456789-", "₀₁₂₃₄₅₆₇₈₉₋")


def subscript(n: int) -> str:
    """Un entier en indice : ``subscript(12)`` → « ₁₂ »."""
    return str(int(n)).translate(_SUBSCRIPT)


def number(value: float, unit: str | None = None, significant: int = 3) -> str:
    """Un nombre du paquet écrit en français (:func:`kalman_course.numbers.format_number`), sans les zéros
    finals de la partie décimale : « 0,8 », « 4 », « 3,2 × 10⁻⁴ »."""
    from ..numbers import format_number

    text = format_number(float(value), significant=significant)
    head, sep, tail = text.partition("\u202f×")
    if "," in head:
        head = head.rstrip("0").rstrip(",")
    text = head + sep + tail
    return text if unit is None else f"{text}\u00a0{unit}"


def ellipse_outline(mean, cov, scale: float = 2.0, n_points: int = 73) -> tuple[np.ndarray, np.ndarray]:
    r"""Contour de l'ellipse :math:`\{m + \text{scale}\,L(\cos t, \sin t)\}`, :math:`LL^T` = ``cov`` (2, 2) :
    l'ellipse à ``scale`` écarts-types d'une loi gaussienne plane. Renvoie ``(x, y)``, formes (n_points,)."""
    mean = as_float_array("mean", mean).reshape(2)
    cov = as_float_array("cov", cov).reshape(2, 2)
    lam, V = np.linalg.eigh(0.5 * (cov + cov.T))
    L = V * np.sqrt(np.clip(lam, 0.0, None))
    t = np.linspace(0.0, 2.0 * np.pi, n_points)
    pts = mean[:, None] + scale * L @ np.vstack([np.cos(t), np.sin(t)])
    return pts[0], pts[1]
