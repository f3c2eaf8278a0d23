r"""Juger un pisteur multi-cibles : distances entre l'ensemble des positions vraies :math:`X` et celui des
estimations :math:`Y`, qui n'ont pas forcément le même nombre de points.

Avec :math:`d_{ij} = \lVert x_i - y_j\rVert` (euclidienne), la coupure :math:`c > 0` et l'ordre
:math:`1 \le p < \infty` :

* **OSPA** (Schuhmacher, Vo & Vo 2008), pour :math:`n_X \le n_Y` (sinon on échange :math:`X` et :math:`Y`) :

  .. math::

      \bar d^{(c)}_p(X, Y) = \Big(\frac{1}{n_Y}\Big(\min_\pi\sum_{i=1}^{n_X}\min(d_{i\pi(i)}, c)^p
      + c^p(n_Y - n_X)\Big)\Big)^{1/p}

  — une erreur **moyenne par point**, où chaque point en trop ou en moins coûte :math:`c`. Stone Soup
  (``OSPAMetric``, 1.9.1) minimise :math:`\sum\min(d, c)` au lieu de :math:`\sum\min(d, c)^p` : juste pour
  :math:`p = 1` seulement.
* **GOSPA** (Rahmathullah, García-Fernández & Svensson 2017), :math:`\alpha = 2` :

  .. math::

      d^{(c,2)}_p(X, Y) = \Big(\min_\gamma\sum_{(i,j)\in\gamma} d_{ij}^p
      + \frac{c^p}{2}\big(n_X + n_Y - 2|\gamma|\big)\Big)^{1/p},

  le minimum portant sur les couplages :math:`\gamma` de couples à :math:`d_{ij} < c`. La somme se
  **décompose** : localisation (:math:`\sum_\gamma d_{ij}^p`), cibles manquées
  (:math:`\frac{c^p}{2}(n_X - |\gamma|)`) et fausses pistes (:math:`\frac{c^p}{2}(n_Y - |\gamma|)`).
  Un couple à :math:`d \ge c` coûte au moins :math:`c^p`, autant qu'une cible manquée et une fausse
  piste : on peut donc chercher le couplage de :math:`\min(n_X, n_Y)` couples qui minimise
  :math:`\sum\min(d_{ij}, c)^p` (``scipy.optimize.linear_sum_assignment``) et n'en garder que les couples à
  :math:`d < c`.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
import scipy.optimize
import scipy.spatial.distance

from ..core.results import freeze
from ..core.validation import KalmanInputError, as_float_array, as_positive_number, shape_text

__all__ = ["GOSPA", "gospa", "ospa"]


class GOSPA(NamedTuple):
    r"""Résultat de :func:`gospa` : ``distance`` :math:`= (\text{localisation} + \text{missed} +
    \text{false})^{1/p}` ; ``localisation`` :math:`\sum d_{ij}^p` sur les couples retenus ; ``missed``
    :math:`\frac{c^p}{2}\times` cibles manquées ; ``false`` :math:`\frac{c^p}{2}\times` fausses pistes (les
    composantes sont des puissances :math:`p`-ièmes) ; ``assignment`` (n_X,) entier : l'indice dans
    :math:`Y` de l'estimation associée à chaque point vrai, ou −1."""

    distance: float
    localisation: float
    missed: float
    false: float
    assignment: np.ndarray


def _points(name: str, value: Any) -> np.ndarray:
    arr = as_float_array(name, value)
    if arr.size == 0 and arr.ndim <= 2:
        return arr.reshape(0, arr.shape[1] if arr.ndim == 2 else 0)
    if arr.ndim != 2:
        raise KalmanInputError(f"« {name} » doit être un tableau (n, d) de n points à d coordonnées (n ≥ 0) ; "
                               f"reçu {shape_text(arr.shape)}.")
    return arr


def _order(p: Any) -> float:
    p_val = as_positive_number("p", p, "un ordre 1 ≤ p < ∞")
    if p_val < 1.0:
        raise KalmanInputError(f"« p » doit être un ordre 1 ≤ p < ∞ ; reçu {p!r}.")
    return p_val


def _cut_distances(X: np.ndarray, Y: np.ndarray, c: float, p: float) -> tuple[np.ndarray, np.ndarray]:
    """Les distances (n_X, n_Y) et le couplage de :math:`\\min(n_X, n_Y)` couples qui minimise
    :math:`\\sum\\min(d, c)^p` (lignes, colonnes)."""
    if X.shape[1] != Y.shape[1]:
        raise KalmanInputError(f"« X » et « Y » doivent avoir le même nombre de coordonnées ; reçu {X.shape[1]} "
                               f"et {Y.shape[1]}.")
    D = scipy.spatial.distance.cdist(X, Y)
    rows, cols = scipy.optimize.linear_sum_assignment(np.minimum(D, c) ** p)
    return D, rows, cols


def gospa(X: Any, Y: Any, *, c: Any, p: Any = 1, alpha: Any = 2) -> GOSPA:
    r"""La distance GOSPA (:math:`\alpha = 2`) entre les points vrais ``X`` (n_X, d) et les estimations ``Y``
    (n_Y, d), et sa décomposition :

    .. math::

        d^{(c,2)}_p(X, Y)^p = \underbrace{\sum_{(i,j)\in\gamma} d_{ij}^p}_{\text{localisation}}
        + \underbrace{\tfrac{c^p}{2}(n_X - |\gamma|)}_{\text{manquées}}
        + \underbrace{\tfrac{c^p}{2}(n_Y - |\gamma|)}_{\text{fausses}},

    :math:`\gamma` le couplage optimal, de couples à :math:`d_{ij} < c`. ``c`` > 0 : coupure ; ``p`` ≥ 1 :
    ordre ; ``alpha`` : seul 2 est accepté. ``X`` ou ``Y`` peut être vide ; tous deux vides : tout est nul.

    Renvoie :class:`GOSPA` ``(distance, localisation, missed, false, assignment)``.
    """
    c_val = as_positive_number("c", c, "une distance de coupure strictement positive")
    p_val = _order(p)
    if isinstance(alpha, bool) or alpha != 2:
        raise KalmanInputError(f"« alpha » doit valoir 2 (seule la GOSPA à α = 2 se décompose en localisation, "
                               f"cibles manquées et fausses pistes) ; reçu {alpha!r}.")
    X_arr, Y_arr = _points("X", X), _points("Y", Y)
    n_X, n_Y = X_arr.shape[0], Y_arr.shape[0]
    assignment = np.full(n_X, -1, dtype=np.intp)
    localisation = 0.0
    if n_X and n_Y:
        D, rows, cols = _cut_distances(X_arr, Y_arr, c_val, p_val)
        kept = D[rows, cols] < c_val
        assignment[rows[kept]] = cols[kept]
        localisation = float(np.sum(D[rows[kept], cols[kept]] ** p_val))
    matched = int(np.sum(assignment >= 0))
    half = c_val ** p_val / 2.0
    missed, false = half * (n_X - matched), half * (n_Y - matched)
    return GOSPA(float((localisation + missed + false) ** (1.0 / p_val)), localisation, missed, false,
                 freeze(assignment, np.intp))


def ospa(X: Any, Y: Any, *, c: Any, p: Any = 1) -> float:
    r"""La distance OSPA entre ``X`` (n_X, d) et ``Y`` (n_Y, d) :

    .. math::

        \bar d^{(c)}_p(X, Y) = \Big(\frac{\min_\pi\sum\min(d_{i\pi(i)}, c)^p + c^p\,|n_X - n_Y|}
        {\max(n_X, n_Y)}\Big)^{1/p},

    le minimum portant sur les couplages de :math:`\min(n_X, n_Y)` couples ; 0 si les deux sont vides.
    ``c`` > 0 : coupure ; ``p`` ≥ 1 : ordre.
    """
    c_val = as_positive_number("c", c, "une distance de coupure strictement positive")
    p_val = _order(p)
    X_arr, Y_arr = _points("X", X), _points("Y", Y)
    n_X, n_Y = X_arr.shape[0], Y_arr.shape[0]
    if n_X == 0 and n_Y == 0:
        return 0.0
    total = c_val ** p_val * abs(n_X - n_Y)
    if n_X and n_Y:
        D, rows, cols = _cut_distances(X_arr, Y_arr, c_val, p_val)
        total += float(np.sum(np.minimum(D[rows, cols], c_val) ** p_val))
    return float((total / max(n_X, n_Y)) ** (1.0 / p_val))
