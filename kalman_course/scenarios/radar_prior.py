r"""La correction du radar précis (chapitre « Filtre de Kalman étendu itéré ») avec un a priori plus ou
moins précis.

Même mesure que le chapitre (graine :data:`~.radar.RADAR_SEED`), même a priori :math:`\hat x^- = (10, 0)` m,
mais une covariance a priori :math:`P^- = \sigma_0^2 I` : avec :math:`\sigma_0 = 3` m, c'est le problème du
chapitre. Quand l'a priori est précis, la correction reste près de :math:`\hat x^-` et l'EKF (première
itération) est déjà au maximum a posteriori ; quand il est vague, la mesure déplace l'estimation loin de
:math:`\hat x^-` et il faut relinéariser.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.results import freeze_fields
from ..core.validation import KalmanInputError, as_float_array
from ..filters.iterated import iekf_update, map_cost
from .radar import RADAR_PRIOR, RadarUpdateProblem, radar_map_estimate, radar_update_problem

__all__ = ["RADAR_PRIOR_STD", "radar_problem_with_prior", "PriorIterations", "prior_iterations"]

#: Écart-type a priori du chapitre (m).
RADAR_PRIOR_STD = 3.0


def radar_problem_with_prior(prior_std: float = RADAR_PRIOR_STD, rng: Any = None) -> RadarUpdateProblem:
    r"""Le problème du chapitre avec :math:`P^- = \sigma_0^2 I` (``prior_std`` = :math:`\sigma_0`, m)."""
    v = as_float_array("prior_std", prior_std)
    if v.ndim != 0 or not (np.isfinite(v) and v > 0):
        raise KalmanInputError(f"« prior_std » doit être un écart-type strictement positif (m) ; reçu {prior_std!r}.")
    base = radar_update_problem() if rng is None else radar_update_problem(rng)
    return RadarUpdateProblem(model=base.model, x_pred=RADAR_PRIOR, P_pred=float(v) ** 2 * np.eye(2), y=base.y,
                              truth=base.truth)


@dataclass(frozen=True, eq=False)
class PriorIterations:
    r"""``problem`` ; ``iterates`` (N+1, 2) itérés de Gauss–Newton (:math:`x^{(0)} = \hat x^-`,
    :math:`x^{(1)}` = EKF) ; ``map`` (2,) maximum a posteriori indépendant (``least_squares``) ; ``cost``
    (N+1,) ; ``distance_to_map`` (N+1,) (m) ; ``error`` (N+1,) distance à la cible (m) ; ``converged``."""

    problem: RadarUpdateProblem
    iterates: np.ndarray
    map: np.ndarray
    cost: np.ndarray
    distance_to_map: np.ndarray
    error: np.ndarray
    converged: bool

    def __post_init__(self) -> None:
        freeze_fields(self, "iterates", "map", "cost", "distance_to_map", "error")


def prior_iterations(prior_std: float = RADAR_PRIOR_STD, max_iter: int = 20, tol: float = 1e-10) -> PriorIterations:
    """Les itérés de l'EKF itéré (:func:`~kalman_course.iekf_update`) et le MAP du problème à :math:`\\sigma_0`."""
    p = radar_problem_with_prior(prior_std)
    out = iekf_update(p.model, p.x_pred, p.P_pred, p.y, max_iter=max_iter, tol=tol)
    x_map = radar_map_estimate(p)
    its = out.iterates
    cost = np.array([map_cost(p.model, x, p.x_pred, p.P_pred, p.y) for x in its])
    return PriorIterations(p, its, x_map, cost, np.linalg.norm(its - x_map, axis=1),
                           np.linalg.norm(its - p.truth, axis=1), bool(out.converged))
