r"""Filtre de Kalman de Gauss–Hermite (GHKF ; Ito et Xiong, 2000 ; Särkkä et Svensson, 2023, §8.3).

En dimension 1, la quadrature de Gauss–Hermite d'ordre :math:`p` donne :math:`p` nœuds :math:`\xi_j` et
poids :math:`w_j` (numpy : ``numpy.polynomial.hermite_e.hermegauss``, poids divisés par
:math:`\sqrt{2\pi}`) tels que

.. math::

    \int g(\xi)\,\mathcal N(\xi; 0, 1)\,d\xi \approx \sum_{j=1}^{p} w_j\, g(\xi_j),

**exacte pour les polynômes de degré** :math:`\le 2p - 1`. En dimension :math:`n`, le produit tensoriel
donne :math:`p^n` points :math:`\xi_{j_1\dots j_n} = (\xi_{j_1}, \dots, \xi_{j_n})` de poids
:math:`w_{j_1}\cdots w_{j_n}`, puis :math:`\chi = \hat x + L\xi` (:math:`LL^T = P`, Cholesky). Tous les poids
sont positifs ; le coût, :math:`p^n` évaluations de :math:`f` et de :math:`h` par pas, croît
exponentiellement avec la dimension (:math:`3^4 = 81`, :math:`3^{10} = 59\,049`) : c'est pourquoi les règles
de cubature (:math:`2n` points) et unscented (:math:`2n + 1`) existent.

C'est le filtre gaussien (:mod:`kalman_course.filters.gaussian`) avec :class:`GaussHermiteRule`. Sur un
modèle linéaire, il redonne le filtre de Kalman dès l'ordre 2.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.models import NonlinearModel
from ..core.results import FilterResult, FilterRuns
from ..core.validation import KalmanInputError
from .engine import FilterFamily, run_filter, run_filter_runs
from .gaussian import SigmaPointRule, gaussian_family

__all__ = [
    "MAX_POINTS",
    "GaussHermiteRule",
    "gauss_hermite_points",
    "gauss_hermite_family",
    "gauss_hermite_kalman_filter",
    "gauss_hermite_kalman_filter_runs",
]

#: Nombre maximal de points :math:`p^n` accepté (au-delà, un pas demanderait plus de cent mille évaluations).
MAX_POINTS = 100_000


def _check_order(order: Any) -> int:
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or order < 2:
        raise KalmanInputError(
            f"« order » doit être un entier ≥ 2 (nombre de nœuds de Gauss–Hermite par dimension ; avec un seul nœud, "
            f"la covariance transformée serait nulle) ; reçu {order!r}."
        )
    return int(order)


def gauss_hermite_points(n: int, order: int) -> tuple[np.ndarray, np.ndarray]:
    r"""Points unités :math:`\xi` (:math:`p^n`, n) et poids (:math:`p^n`,) de la règle de Gauss–Hermite
    d'ordre :math:`p` = ``order`` en dimension ``n`` (produit tensoriel, loi :math:`\mathcal N(0, I)` ;
    les poids somment à 1)."""
    p = _check_order(order)
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise KalmanInputError(f"« n » doit être un entier ≥ 1 (dimension de l'état) ; reçu {n!r}.")
    if p ** int(n) > MAX_POINTS:
        raise KalmanInputError(
            f"Gauss–Hermite d'ordre {p} en dimension {n} : {p}^{n} = {p ** int(n)} points par étape, plus que "
            f"{MAX_POINTS} : baissez « order » ou prenez la règle de cubature (2n = {2 * int(n)} points) ou sans "
            "parfum (2n + 1 points)."
        )
    from numpy.polynomial.hermite_e import hermegauss  # chargé au premier usage (import léger du paquet)

    nodes, w = hermegauss(p)
    w = w / np.sqrt(2.0 * np.pi)
    xi = np.array(list(itertools.product(nodes, repeat=int(n))), dtype=float)
    W = np.prod(np.array(list(itertools.product(w, repeat=int(n))), dtype=float), axis=1)
    return xi, W


@dataclass(frozen=True)
class GaussHermiteRule(SigmaPointRule):
    r"""La règle de Gauss–Hermite d'ordre ``order`` (:math:`p`), en produit tensoriel : :math:`p^n` points,
    exacte pour les polynômes de degré :math:`\le 2p - 1` en chaque variable (voir l'en-tête du module)."""

    order: int = 3

    label = "GHKF"
    filter_name = "filtre de Kalman de Gauss–Hermite (GHKF)"
    point_name = "de Gauss–Hermite"

    def check(self, model: NonlinearModel) -> None:
        super().check(model)
        gauss_hermite_points(model.n_state, self.order)

    def build_unit(self, n):
        xi, W = gauss_hermite_points(n, self.order)
        return xi, W, W.copy()


def gauss_hermite_family(*, order: int = 3, redraw: bool = True) -> FilterFamily:
    r"""Les étapes du GHKF pour le moteur : celles du filtre gaussien avec :class:`GaussHermiteRule`."""
    return gaussian_family(GaussHermiteRule(_check_order(order)), redraw=redraw)


def gauss_hermite_kalman_filter(model: NonlinearModel, y: Any, x0: Any, P0: Any, u: Any = None, *,
                                order: int = 3, redraw: bool = True, gate: Any = None,
                                fading: Any = None) -> FilterResult:
    r"""Filtre de Kalman de Gauss–Hermite sur toutes les mesures (pour chaque ``y[k]`` : prédiction puis
    correction, dans l'ordre de :func:`~kalman_course.kalman_filter`) : les formules du filtre gaussien, les
    moments calculés sur les :math:`p^n` points de Gauss–Hermite.

    Paramètres
    ----------
    model : NonlinearModel à bruits additifs.
    y : (T, m), ou (T,) si m = 1 — ``NaN`` : composante manquante.
    x0 : (n,) ; P0 : (n, n) symétrique **définie** positive.
    u : (T, p), ou (T,) si p = 1, optionnel — commandes (``u[k]``, qui contient :math:`u_{k-1}`, sert à prédire vers ``y[k]``).
    order : nombre :math:`p \ge 2` de nœuds par dimension (3 par défaut) ; les intégrales de polynômes de
        degré :math:`\le 2p - 1` sont exactes : la moyenne d'une :math:`h` de degré :math:`d` dès
        :math:`2p - 1 \ge d`, sa covariance (degré :math:`2d`) dès :math:`2p - 1 \ge 2d` — pour
        :math:`h(x) = x^3`, dès :math:`p = 4`. Au plus :data:`MAX_POINTS` points :math:`p^n`.
    redraw : nouveaux points à la correction (défaut) ou points propagés réutilisés.
    gate, fading : porte et mémoire évanescente, options du moteur (:mod:`~kalman_course.filters.gating`),
        comme pour :func:`~kalman_course.kalman_filter`.

    Renvoie un :class:`~kalman_course.FilterResult`.
    """
    return run_filter(gauss_hermite_family(order=order, redraw=redraw), model, y, x0, P0, u, gate=gate,
                      fading=fading)


def gauss_hermite_kalman_filter_runs(model: NonlinearModel, Y: Any, x0: Any, P0: Any, u: Any = None, *,
                                     order: int = 3, redraw: bool = True) -> FilterRuns:
    r""":func:`gauss_hermite_kalman_filter` sur ``N`` tirages indépendants du même modèle, tous à la fois :
    ``Y`` (N, T, m), ``x0`` (n,) ou (N, n), ``P0`` (n, n) ou (N, n, n), ``u`` (T, p) commune.
    Renvoie un :class:`~kalman_course.FilterRuns`."""
    return run_filter_runs(gauss_hermite_family(order=order, redraw=redraw), model, Y, x0, P0, u)
