r"""Grilles de paramètres précalculées pour les curseurs statiques (numpy seulement, aucun tracé).

Une page HTML publiée n'a pas de noyau Python : pour qu'un curseur y change la figure, toutes les
exécutions possibles sont calculées à la construction du livre, sur une grille d'un à trois
paramètres (par exemple :math:`\Phi` et :math:`\Psi` sur une grille logarithmique, un gain sur une
grille linéaire, un numéro d'itération), et la page ne fait que choisir la bonne.

Ce module ne connaît aucun filtre : :func:`precompute_grid` appelle, pour chaque point de la grille,
une fonction ``run(a, b, …)`` fournie par le chapitre (qui appelle le filtre du paquet) et empile ses
séries. Les séries sont gardées en ``float64`` : la page affiche exactement les valeurs du paquet.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Callable, Mapping

import numpy as np

from ..core.results import freeze
from ..core.validation import KalmanInputError, as_float_array, shape_text
from ..numbers import format_number

__all__ = ["AXIS_SCALES", "ParameterAxis", "ParameterGrid", "log_grid", "precompute_grid", "format_value"]

def format_value(value: float, unit: str = "") -> str:
    r"""Écriture française d'une valeur de paramètre : « 0,01 V² », « 3,16 × 10⁻⁵ V² », « 1 × 10⁻⁹ V² ».

    Trois chiffres significatifs (zéros finals retirés), par :func:`kalman_course.numbers.format_number` ;
    écriture :math:`m \times 10^{n}` hors de :math:`[10^{-2}, 10^{3})` ; unité après une espace insécable.
    """
    v = float(value)
    scientific = v != 0.0 and not 1e-2 <= abs(v) < 1e3
    return format_number(v, significant=3, trim=True, scientific=scientific, unit=unit or None)


#: Échelles possibles d'un axe : logarithmique (valeurs > 0, une variance), linéaire (un gain, un
#: angle), ou suite de positions (un numéro d'itération, une étape de la boucle).
AXIS_SCALES = ("log", "linear", "index")


@dataclass(frozen=True, eq=False)
class ParameterAxis:
    """Un axe de la grille : le paramètre que déplace un curseur.

    ``name`` : identifiant (``"Q"``) ; ``symbol`` : notation du cours (``"Φ"``) ; ``description`` :
    libellé français du curseur ; ``unit`` : unité (``"V²"``) ; ``values`` : (N,) valeurs strictement
    croissantes ; ``default`` : indice de la valeur par défaut (celle de la figure statique).
    ``scale`` : ``"log"`` (valeurs strictement positives, grille logarithmique, par défaut),
    ``"linear"`` ou ``"index"`` (positions discrètes : itération, étape). ``tick_labels`` : texte
    affiché par le curseur à chaque position (par défaut, la valeur écrite en français avec l'unité).
    """

    name: str
    symbol: str
    description: str
    unit: str
    values: np.ndarray
    default: int
    scale: str = "log"
    tick_labels: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        values = as_float_array(f"valeurs de {self.name}", self.values)
        if values.ndim != 1 or values.size < 2:
            raise KalmanInputError(
                f"Les valeurs de « {self.name} » doivent former un vecteur d'au moins 2 valeurs ; "
                f"reçu {shape_text(values.shape)}."
            )
        if self.scale not in AXIS_SCALES:
            raise KalmanInputError(
                f"« scale » de « {self.name} » doit valoir {', '.join(map(repr, AXIS_SCALES))} ; reçu {self.scale!r}."
            )
        if self.scale == "log" and not (values > 0).all() or not (np.diff(values) > 0).all():
            raise KalmanInputError(
                f"Les valeurs de « {self.name} » doivent être strictement positives et croissantes "
                f"(grille logarithmique)." if self.scale == "log" else
                f"Les valeurs de « {self.name} » doivent être strictement croissantes."
            )
        if not (isinstance(self.default, (int, np.integer)) and 0 <= self.default < values.size):
            raise KalmanInputError(
                f"L'indice par défaut de « {self.name} » doit être un entier entre 0 et {values.size - 1} ; "
                f"reçu {self.default!r}."
            )
        if self.tick_labels is not None:
            labels = tuple(self.tick_labels)
            if len(labels) != values.size or not all(isinstance(t, str) and t for t in labels):
                raise KalmanInputError(
                    f"« tick_labels » de « {self.name} » doit donner un texte non vide par valeur "
                    f"({values.size} attendus) ; reçu {len(labels)}."
                )
            object.__setattr__(self, "tick_labels", labels)
        object.__setattr__(self, "values", freeze(values))
        object.__setattr__(self, "default", int(self.default))

    @property
    def default_value(self) -> float:
        """La valeur du paramètre à la position par défaut du curseur."""
        return float(self.values[self.default])

    def labels(self) -> list[str]:
        """Les valeurs réelles, écrites en français avec l'unité (ce qu'affiche le curseur)."""
        if self.tick_labels is not None:
            return list(self.tick_labels)
        return [format_value(v, self.unit) for v in self.values]

    def index_of(self, value: float) -> int:
        """Indice de ``value`` dans la grille (égalité exacte exigée)."""
        hits = np.flatnonzero(self.values == float(value))
        if hits.size != 1:
            raise KalmanInputError(
                f"« {self.name} » = {value!r} n'est pas un point de la grille ; valeurs possibles : "
                f"{', '.join(self.labels())}."
            )
        return int(hits[0])


def log_grid(center: float, decades_below: int, decades_above: int, per_decade: int = 2) -> np.ndarray:
    r"""Valeurs logarithmiquement espacées autour de ``center`` (qui est un point **exact** de la grille).

    Valeurs :math:`c\cdot 10^{k/d}` pour :math:`k = -d\,b, \dots, d\,a` (``b = decades_below``,
    ``a = decades_above``, ``d = per_decade``) ; ``k = 0`` donne ``center`` au bit près, pour que la
    position par défaut du curseur reproduise la figure statique du chapitre. Forme
    ``(per_decade·(decades_below + decades_above) + 1,)``.
    """
    c = float(as_float_array("center", center))
    if not (math.isfinite(c) and c > 0):
        raise KalmanInputError(f"« center » doit être un nombre strictement positif ; reçu {center!r}.")
    for name, value, low in (("decades_below", decades_below, 0), ("decades_above", decades_above, 0),
                             ("per_decade", per_decade, 1)):
        if not isinstance(value, (int, np.integer)) or isinstance(value, bool) or value < low:
            raise KalmanInputError(f"« {name} » doit être un entier ≥ {low} ; reçu {value!r}.")
    if decades_below + decades_above == 0:
        raise KalmanInputError("La grille doit couvrir au moins une décade (decades_below + decades_above ≥ 1).")
    ks = range(-per_decade * decades_below, per_decade * decades_above + 1)
    # puissance scalaire de Python (10.0 ** 0 == 1.0 exactement) : le centre est reproduit au bit près
    return np.array([c if k == 0 else c * 10.0 ** (k / per_decade) for k in ks])


@dataclass(frozen=True, eq=False)
class ParameterGrid:
    """Exécutions précalculées sur la grille ``axes[0] × … × axes[d-1]`` (un à trois curseurs).

    ``series[nom]`` a la forme ``(N0, …, N_{d-1}, L)`` : ``series[nom][i, j]`` est la série ``nom`` de
    l'exécution avec ``axes[0].values[i]`` et ``axes[1].values[j]``. ``time`` (T,) : abscisse commune
    (numéro d'itération ou temps) des séries de longueur ``L = T`` ; une série peut avoir une autre
    longueur (un point, un segment, une courbe sur une autre abscisse), la même à chaque exécution.
    Tableaux en lecture seule, ``float64``.
    """

    axes: tuple[ParameterAxis, ...]
    time: np.ndarray
    series: Mapping[str, np.ndarray]

    @property
    def shape(self) -> tuple[int, ...]:
        """``(N0, N1, …)`` : nombre de positions de chaque curseur."""
        return tuple(axis.values.size for axis in self.axes)

    @property
    def size(self) -> int:
        """Nombre d'exécutions de la grille."""
        return int(np.prod(self.shape))

    @property
    def default_index(self) -> tuple[int, ...]:
        """Position par défaut des curseurs."""
        return tuple(axis.default for axis in self.axes)

    def length(self, name: str) -> int:
        """Longueur ``L`` de la série ``name`` (nombre de points d'une exécution)."""
        return int(self.series[name].shape[-1])

    def values_at(self, *index: int) -> tuple[float, ...]:
        """Les valeurs des paramètres au point de grille ``index``."""
        self._check(index)
        return tuple(float(axis.values[i]) for axis, i in zip(self.axes, index))

    def _check(self, index) -> None:
        shape = self.shape
        if len(index) != len(shape) or not all(
            isinstance(i, (int, np.integer)) and 0 <= i < n for i, n in zip(index, shape)
        ):
            raise KalmanInputError(
                f"Point de grille {tuple(index)} hors de la grille {' × '.join(map(str, shape))}."
            )

    def run(self, *index: int) -> dict[str, np.ndarray]:
        """Les séries de l'exécution ``index`` (une par curseur)."""
        self._check(index)
        return {name: values[tuple(index)] for name, values in self.series.items()}

    def flat(self, name: str) -> np.ndarray:
        """La série ``name`` aplatie en ``(N0·N1·…·L,)`` (ordre C : l'exécution ``(i, j)`` commence à
        ``(i·N1 + j)·L``) : c'est la forme envoyée au navigateur."""
        return np.ascontiguousarray(self.series[name]).reshape(-1)


def _split_time(axes: tuple, time) -> tuple[tuple, object]:
    """Ancienne forme ``precompute_grid(run, a, b, time)`` : le dernier argument positionnel est le temps."""
    if time is None and axes and not isinstance(axes[-1], ParameterAxis):
        return axes[:-1], axes[-1]
    return axes, time


def precompute_grid(
    run: Callable[..., Mapping[str, np.ndarray]],
    *axes: ParameterAxis,
    time: np.ndarray | None = None,
) -> ParameterGrid:
    """Appelle ``run(a, b, …)`` pour chaque point ``(a, b, …)`` de ``axes[0].values × axes[1].values × …``.

    ``run`` renvoie un dictionnaire de séries 1-D (les mêmes noms et les mêmes longueurs à chaque
    appel). ``time`` (T,) : abscisse commune des séries de longueur T. Renvoie la
    :class:`ParameterGrid` de ces séries, de forme ``(N0, …, L)``.
    """
    axes, time = _split_time(axes, time)
    if not callable(run):
        raise KalmanInputError(f"« run » doit être une fonction run(a, b, …) ; reçu {type(run).__name__}.")
    if not 1 <= len(axes) <= 3:
        raise KalmanInputError(f"Une grille a un, deux ou trois axes (curseurs) ; reçu {len(axes)}.")
    for k, axis in enumerate(axes):
        if not isinstance(axis, ParameterAxis):
            raise KalmanInputError(f"L'axe n° {k + 1} doit être un ParameterAxis ; reçu {type(axis).__name__}.")
    if time is None:
        raise KalmanInputError("Donnez « time », l'abscisse commune des séries (vecteur non vide).")
    t = as_float_array("time", time)
    if t.ndim != 1 or t.size == 0:
        raise KalmanInputError(f"« time » doit être un vecteur non vide ; reçu {shape_text(t.shape)}.")
    shape = tuple(axis.values.size for axis in axes)
    series: dict[str, np.ndarray] = {}
    for index in itertools.product(*(range(n) for n in shape)):
        point = tuple(float(axis.values[i]) for axis, i in zip(axes, index))
        out = run(*point)
        if not series:
            if not out:
                raise KalmanInputError("« run » doit renvoyer au moins une série (dictionnaire non vide).")
            for name, values in out.items():
                arr = np.asarray(values, dtype=float)
                if arr.ndim != 1 or arr.size == 0:
                    raise KalmanInputError(
                        f"La série « {name} » doit être un vecteur non vide (une valeur par point) ; "
                        f"reçu la forme {arr.shape}."
                    )
                series[name] = np.empty(shape + (arr.size,))
        if set(out) != set(series):
            raise KalmanInputError(
                f"« run » doit renvoyer les mêmes séries à chaque appel : {sorted(series)} attendu, "
                f"{sorted(out)} reçu pour {_point_text(point)}."
            )
        for name, values in out.items():
            arr = np.asarray(values, dtype=float)
            expected = (series[name].shape[-1],)
            if arr.shape != expected:
                raise KalmanInputError(
                    f"La série « {name} » doit avoir la forme {_shape(expected)} à chaque exécution ; "
                    f"reçu {_shape(arr.shape)} pour {_point_text(point)}."
                )
            series[name][index] = arr
    return ParameterGrid(axes=tuple(axes), time=freeze(t), series={k: freeze(v) for k, v in series.items()})


def _shape(shape: tuple) -> str:
    return "(" + ", ".join(map(str, shape)) + ("," if len(shape) == 1 else "") + ")"


def _point_text(point: tuple[float, ...]) -> str:
    return "(" + " ; ".join(format_value(v) for v in point) + ")"
