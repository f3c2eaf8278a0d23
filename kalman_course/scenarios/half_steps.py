r"""La boucle du filtre de Kalman demi-pas par demi-pas : départ, prédiction, correction, prédiction…

Un :class:`~kalman_course.FilterResult` range séparément les prédictions (``x_pred``, ``P_pred``) et
les corrections (``x``, ``P``) ; :func:`half_steps` les entrelace dans l'ordre où le filtre les calcule,
pour suivre la gaussienne qui s'élargit (prédiction) puis se resserre (correction).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.results import FilterResult, freeze_fields
from ..core.validation import as_gaussian, check_instance

__all__ = ["HalfSteps", "half_steps", "STAGE_KINDS"]

#: Nature de chaque étape.
STAGE_KINDS = ("départ", "prédiction", "correction")


@dataclass(frozen=True, eq=False)
class HalfSteps:
    r"""``2T + 1`` étapes : l'étape 0 est la loi initiale :math:`(\hat x_0, P_0)`, l'étape :math:`2n - 1` la
    prédiction :math:`(\hat x^-_n, P^-_n)`, l'étape :math:`2n` la correction :math:`(\hat x_n, P_n)`.
    ``mean`` (2T+1, n), ``cov`` (2T+1, n, n), ``kind`` : nature de chaque étape."""

    mean: np.ndarray
    cov: np.ndarray
    kind: tuple[str, ...]

    def __post_init__(self) -> None:
        freeze_fields(self, "mean", "cov")

    @staticmethod
    def step_of(stage: int) -> int:
        """Numéro :math:`n` de la mesure concernée par l'étape ``stage`` (0 pour le départ)."""
        return (int(stage) + 1) // 2


def half_steps(result: FilterResult, x0: Any, P0: Any) -> HalfSteps:
    r"""Entrelace la loi initiale ``(x0, P0)`` et les prédictions et corrections de ``result``."""
    check_instance("result", result, FilterResult)
    n = result.x.shape[1]
    x0, P0 = as_gaussian(x0, P0, n, "x0", "P0")
    T = result.x.shape[0]
    mean = np.empty((2 * T + 1, n))
    cov = np.empty((2 * T + 1, n, n))
    mean[0], cov[0] = x0, P0
    mean[1::2], cov[1::2] = result.x_pred, result.P_pred
    mean[2::2], cov[2::2] = result.x, result.P
    return HalfSteps(mean, cov, ("départ",) + ("prédiction", "correction") * T)
