r"""Scénario du chapitre « Un seul filtre gaussien » : les règles d'intégration côte à côte.

* La « banane » (:mod:`~kalman_course.scenarios.banana`) : moyenne et covariance de
  :math:`g(r, \theta) = (r\cos\theta, r\sin\theta)` par chaque règle (linéarisation, unscented, cubature,
  Gauss–Hermite d'ordre :math:`p`) contre la forme close ; l'erreur de la moyenne en fonction de
  :math:`\sigma_\theta` donne l'ordre de chaque règle (pente log-log).
* :math:`h(x) = x^3` sous :math:`x \sim \mathcal N(m, s^2)` : la variance transformée par chaque règle
  contre la forme close :math:`\operatorname{Var}(x^3) = 9m^4s^2 + 36m^2s^4 + 15s^6`.
* Le nombre de points (d'évaluations de :math:`f` ou :math:`h`) par étape selon la dimension.

Tous les moments passent par les règles du filtre gaussien (:class:`~kalman_course.GaussianRule`, leur
méthode ``observation``) : c'est le code même des filtres.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.models import NonlinearModel
from ..core.results import freeze_fields
from ..filters.cubature import CUBATURE
from ..filters.extended import LINEARIZATION
from ..filters.gauss_hermite import GaussHermiteRule
from ..filters.gaussian import GaussianRule, SigmaPointRule
from ..filters.unscented import UnscentedRule
from .banana import (
    BANANA_ALPHA,
    BANANA_BEARING,
    BANANA_BETA,
    BANANA_BEARING_STD,
    BANANA_KAPPA,
    BANANA_RANGE,
    BANANA_RANGE_STD,
    Moments,
    banana_truth,
)
from .polar import polar_to_cartesian, polar_to_cartesian_jacobian as polar_jacobian

__all__ = [
    "CUBE_MEAN",
    "CUBE_STD",
    "GH_ORDER",
    "rules",
    "rule_moments",
    "RulePoints",
    "rule_points",
    "banana_rules",
    "banana_mean_errors",
    "cube_moments",
    "cube_variance_errors",
    "points_per_step",
]

#: Ordre de Gauss–Hermite par défaut du chapitre (et du curseur).
GH_ORDER = 3
#: Loi de :math:`x` pour :math:`h(x) = x^3` : moyenne et écart-type.
CUBE_MEAN = 1.0
CUBE_STD = float(np.sqrt(0.3))


def rules(order: int = GH_ORDER) -> dict[str, GaussianRule]:
    r"""Les règles comparées, par nom affiché : linéarisation (EKF), unscented (UKF, :math:`\alpha = 1`,
    :math:`\beta = 2`, :math:`\kappa = 3 - n = 1`, celle du chapitre de l'UKF), cubature (CKF) et
    Gauss–Hermite d'ordre ``order`` (GHKF)."""
    return {
        "linéarisation (EKF)": LINEARIZATION,
        "unscented (UKF)": UnscentedRule(BANANA_ALPHA, BANANA_BETA, BANANA_KAPPA),
        "cubature (CKF)": CUBATURE,
        f"Gauss–Hermite, p = {order} (GHKF)": GaussHermiteRule(order),
    }


def rule_moments(rule: GaussianRule, mean: Any, cov: Any, g, jacobian=None) -> Moments:
    r"""Moyenne et covariance de :math:`g(x)`, :math:`x \sim \mathcal N(\bar x, P)`, par la règle ``rule``
    (sa méthode ``observation``, celle des filtres). ``g`` accepte un état (n,) ou une pile (N, n) ;
    ``jacobian(x)`` (m, n) sert à la linéarisation (différences centrées si absente)."""
    mean = np.asarray(mean, dtype=float)
    cov = np.asarray(cov, dtype=float)
    m = np.atleast_1d(g(mean)).size
    model = NonlinearModel(lambda x, u: x, g, np.eye(mean.size), np.eye(m), h_jacobian=jacobian, vectorized=True)
    mom = rule.observation(model, mean, cov, None, "moments")
    return Moments(np.atleast_1d(mom.mean), np.atleast_2d(mom.cov))


@dataclass(frozen=True, eq=False)
class RulePoints:
    r"""Les points d'une règle pour :math:`\mathcal N(\bar x, P)` : ``points`` (N, n), poids ``Wm`` (N,)."""

    points: np.ndarray
    Wm: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, "points", "Wm")


def rule_points(rule: SigmaPointRule, mean: Any, cov: Any) -> RulePoints:
    r"""Les points et les poids de moyenne d'une règle à points pour :math:`\mathcal N(\bar x, P)`."""
    mean = np.asarray(mean, dtype=float)
    X = rule.points(mean, np.asarray(cov, dtype=float), "points", "« cov »")
    return RulePoints(X, np.array(rule.unit(mean.size)[1]))


def banana_rules(range_std: float = BANANA_RANGE_STD, bearing_std: float = BANANA_BEARING_STD,
                 order: int = GH_ORDER) -> dict[str, Moments]:
    r"""La banane par chaque règle de :func:`rules` et la vérité (clé ``"vérité"``, forme close)."""
    P = np.diag([range_std**2, bearing_std**2])
    out = {"vérité": banana_truth(range_std, bearing_std)}
    for name, rule in rules(order).items():
        out[name] = rule_moments(rule, [BANANA_RANGE, BANANA_BEARING], P, polar_to_cartesian, polar_jacobian)
    return out


def banana_mean_errors(bearing_stds: Any, orders: tuple[int, ...] = (3, 5),
                       range_std: float = BANANA_RANGE_STD) -> dict[str, np.ndarray]:
    r"""Distance (m) de la moyenne de chaque règle à la vraie moyenne de la banane, pour chaque
    :math:`\sigma_\theta` de ``bearing_stds`` (rad) : linéarisation, unscented, cubature et Gauss–Hermite
    pour chaque ordre de ``orders``. Les pentes log-log donnent l'ordre de chaque règle."""
    stds = np.atleast_1d(np.asarray(bearing_stds, dtype=float))
    names = list(rules(orders[0]))[:3] + [f"Gauss–Hermite, p = {p} (GHKF)" for p in orders]
    out = {name: np.empty(stds.size) for name in names}
    for j, s in enumerate(stds):
        truth = banana_truth(range_std, float(s)).mean
        for p in orders:
            for name, mom in banana_rules(range_std, float(s), p).items():
                if name in out:
                    out[name][j] = np.linalg.norm(mom.mean - truth)
    return out


def cube_moments(m: float = CUBE_MEAN, s: float = CUBE_STD) -> tuple[float, float, float]:
    r"""Moments exacts de :math:`x^3`, :math:`x \sim \mathcal N(m, s^2)` : :math:`\mathbb E[x^3] = m^3 + 3ms^2`,
    :math:`\operatorname{Var}(x^3) = 9m^4s^2 + 36m^2s^4 + 15s^6`, :math:`\operatorname{Cov}(x, x^3) = 3m^2s^2 + 3s^4`."""
    s2 = s * s
    return m**3 + 3 * m * s2, 9 * m**4 * s2 + 36 * m**2 * s2**2 + 15 * s2**3, 3 * m**2 * s2 + 3 * s2**2


def cube_variance_errors(orders: Any = (2, 3, 4, 5), m: float = CUBE_MEAN, s: float = CUBE_STD) -> dict[str, float]:
    r"""Erreur relative de :math:`\operatorname{Var}(x^3)` par chaque règle (linéarisation, unscented,
    cubature, Gauss–Hermite de chaque ordre de ``orders``) contre :func:`cube_moments`."""
    _, var, _ = cube_moments(m, s)
    cube = lambda x: np.asarray(x) ** 3  # noqa: E731
    out = {}
    for name, rule in list(rules().items())[:3]:
        mom = rule_moments(rule, [m], [[s * s]], cube, lambda x: np.array([[3 * x[0] ** 2]]))
        out[name] = abs(float(mom.cov[0, 0]) - var) / var
    for p in np.atleast_1d(orders):
        mom = rule_moments(GaussHermiteRule(int(p)), [m], [[s * s]], cube)
        out[f"Gauss–Hermite, p = {int(p)}"] = abs(float(mom.cov[0, 0]) - var) / var
    return out


def points_per_step(dimensions: Any = tuple(range(1, 11)), orders: tuple[int, ...] = (3, 5)) -> dict[str, np.ndarray]:
    r"""Nombre de points (d'évaluations de :math:`f` ou de :math:`h`) par étape selon la dimension :math:`n`
    de l'état : unscented :math:`2n + 1`, cubature :math:`2n`, Gauss–Hermite :math:`p^n`."""
    ns = np.atleast_1d(np.asarray(dimensions, dtype=int))
    out = {"unscented (UKF) : 2n + 1": 2 * ns + 1, "cubature (CKF) : 2n": 2 * ns}
    for p in orders:
        out[f"Gauss–Hermite, p = {p} : {p}ⁿ"] = np.array([float(p) ** n for n in ns])
    return out
