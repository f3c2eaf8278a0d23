r"""Grilles de paramètres précalculées pour les curseurs statiques (numpy seulement, aucun tracé).

Une page HTML publiée n'a pas de noyau Python : pour qu'un curseur y change la figure, toutes les
exécutions possibles sont calculées à la construction du livre, sur une grille logarithmique de deux
paramètres (par exemple :math:`\Phi` et :math:`\Psi`), et la page ne fait que choisir la bonne.

Ce module ne connaît aucun filtre : :func:`precompute_grid` appelle, pour chaque point de la grille,
une fonction ``run(a, b)`` fournie par le chapitre (qui appelle le filtre du paquet) et empile ses
séries. Les séries sont gardées en ``float64`` : la page affiche exactement les valeurs du paquet.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Mapping

import numpy as np

from ..core.results import freeze
from ..core.validation import KalmanInputError, as_float_array, shape_text
from ..numbers import format_number

__all__ = ["ParameterAxis", "ParameterGrid", "log_grid", "precompute_grid", "format_value"]

def format_value(value: float, unit: str = "") -> str:
    r"""Écriture française d'une valeur de paramètre : « 0,01 V² », « 3,16 × 10⁻⁵ V² », « 1 × 10⁻⁹ V² ».

    Trois chiffres significatifs (zéros finals retirés), par :func:`kalman_course.numbers.format_number` ;
    écriture :math:`m \times 10^{n}` hors de :math:`[10^{-2}, 10^{3})` ; unité après une espace insécable.
    """
    v = float(value)
    scientific = v != 0.0 and not 1e-2 <= abs(v) < 1e3
    return format_number(v, significant=3, trim=True, scientific=scientific, unit=unit or None)


@dataclass(frozen=True, eq=False)
class ParameterAxis:
    """Un axe de la grille : le paramètre que déplace un curseur.

    ``name`` : identifiant (``"Q"``) ; ``symbol`` : notation du cours (``"Φ"``) ; ``description`` :
    libellé français du curseur ; ``unit`` : unité (``"V²"``) ; ``values`` : (N,) valeurs croissantes,
    strictement positives ; ``default`` : indice de la valeur par défaut (celle de la figure statique).
    """

    name: str
    symbol: str
    description: str
    unit: str
    values: np.ndarray
    default: int

    def __post_init__(self) -> None:
        values = as_float_array(f"valeurs de {self.name}", self.values)
        if values.ndim != 1 or values.size < 2:
            raise KalmanInputError(
                f"Les valeurs de « {self.name} » doivent former un vecteur d'au moins 2 valeurs ; "
                f"reçu {shape_text(values.shape)}."
            )
        if not (values > 0).all() or not (np.diff(values) > 0).all():
            raise KalmanInputError(
                f"Les valeurs de « {self.name} » doivent être strictement positives et croissantes "
                f"(grille logarithmique)."
            )
        if not (isinstance(self.default, (int, np.integer)) and 0 <= self.default < values.size):
            raise KalmanInputError(
                f"L'indice par défaut de « {self.name} » doit être un entier entre 0 et {values.size - 1} ; "
                f"reçu {self.default!r}."
            )
        object.__setattr__(self, "values", freeze(values))
        object.__setattr__(self, "default", int(self.default))

    @property
    def default_value(self) -> float:
        """La valeur du paramètre à la position par défaut du curseur."""
        return float(self.values[self.default])

    def labels(self) -> list[str]:
        """Les valeurs réelles, écrites en français avec l'unité (ce qu'affiche le curseur)."""
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
    """Exécutions précalculées sur la grille ``axes[0] × axes[1]``.

    ``series[nom]`` a la forme ``(N0, N1, T)`` : ``series[nom][i, j]`` est la série ``nom`` de
    l'exécution avec ``axes[0].values[i]`` et ``axes[1].values[j]``. ``time`` (T,) : abscisse commune
    (numéro d'itération ou temps). Tableaux en lecture seule, ``float64``.
    """

    axes: tuple[ParameterAxis, ParameterAxis]
    time: np.ndarray
    series: Mapping[str, np.ndarray]

    @property
    def shape(self) -> tuple[int, int]:
        """``(N0, N1)`` : nombre de positions de chaque curseur."""
        return (self.axes[0].values.size, self.axes[1].values.size)

    @property
    def default_index(self) -> tuple[int, int]:
        """Position par défaut des deux curseurs."""
        return (self.axes[0].default, self.axes[1].default)

    def run(self, i: int, j: int) -> dict[str, np.ndarray]:
        """Les séries de l'exécution ``(i, j)`` (chacune de forme (T,))."""
        n0, n1 = self.shape
        if not (0 <= i < n0 and 0 <= j < n1):
            raise KalmanInputError(f"Point de grille ({i}, {j}) hors de la grille {n0} × {n1}.")
        return {name: values[i, j] for name, values in self.series.items()}

    def flat(self, name: str) -> np.ndarray:
        """La série ``name`` aplatie en ``(N0·N1·T,)`` (ordre C : l'exécution ``(i, j)`` commence à
        ``(i·N1 + j)·T``) : c'est la forme envoyée au navigateur."""
        return np.ascontiguousarray(self.series[name]).reshape(-1)


def precompute_grid(
    run: Callable[[float, float], Mapping[str, np.ndarray]],
    first: ParameterAxis,
    second: ParameterAxis,
    time: np.ndarray,
) -> ParameterGrid:
    """Appelle ``run(a, b)`` pour chaque couple ``(a, b)`` de ``first.values × second.values``.

    ``run`` renvoie un dictionnaire de séries 1-D de même longueur ``T = len(time)`` (les mêmes
    noms à chaque appel). Renvoie la :class:`ParameterGrid` de ces séries, de forme ``(N0, N1, T)``.
    """
    if not callable(run):
        raise KalmanInputError(f"« run » doit être une fonction run(a, b) ; reçu {type(run).__name__}.")
    for label, axis in (("first", first), ("second", second)):
        if not isinstance(axis, ParameterAxis):
            raise KalmanInputError(f"« {label} » doit être un ParameterAxis ; reçu {type(axis).__name__}.")
    t = as_float_array("time", time)
    if t.ndim != 1 or t.size == 0:
        raise KalmanInputError(f"« time » doit être un vecteur non vide ; reçu {shape_text(t.shape)}.")
    n0, n1, T = first.values.size, second.values.size, t.size
    series: dict[str, np.ndarray] = {}
    for i, a in enumerate(first.values):
        for j, b in enumerate(second.values):
            out = run(float(a), float(b))
            if i == 0 and j == 0:
                if not out:
                    raise KalmanInputError("« run » doit renvoyer au moins une série (dictionnaire non vide).")
                series = {name: np.empty((n0, n1, T)) for name in out}
            if set(out) != set(series):
                raise KalmanInputError(
                    f"« run » doit renvoyer les mêmes séries à chaque appel : {sorted(series)} attendu, "
                    f"{sorted(out)} reçu pour ({format_number(a, significant=6, trim=True)} ; {format_number(b, significant=6, trim=True)})."
                )
            for name, values in out.items():
                arr = np.asarray(values, dtype=float)
                if arr.shape != (T,):
                    raise KalmanInputError(
                        f"La série « {name} » doit avoir la forme ({T},) (une valeur par instant) ; "
                        f"reçu {arr.shape}."
                    )
                series[name][i, j] = arr
    return ParameterGrid(
        axes=(first, second), time=freeze(t), series={k: freeze(v) for k, v in series.items()}
    )
