r"""Deux options du filtre de Kalman pour le pistage : la **porte** (rejet des mesures aberrantes) et la
**mémoire évanescente** (oubli du passé).

**Porte** (*gating*). Sous les hypothèses du filtre, l'innovation :math:`\nu_k = y_k - C\hat x_{k\mid k-1}`
suit :math:`\mathcal N(0, S_k)`, donc la NIS :math:`\epsilon_k = \nu_k^TS_k^{-1}\nu_k` suit une loi du
:math:`\chi^2` à :math:`m_k` degrés de liberté (:math:`m_k` : composantes observées au pas :math:`k`).
Avec ``gate=p``, une mesure dont la NIS dépasse le quantile :math:`\chi^2_{m_k}(p)` est **rejetée** : le pas
se réduit à la prédiction. Sur des données conformes au modèle, une proportion :math:`1 - p` des mesures
est rejetée à tort ; une mesure aberrante (à plusieurs :math:`\sqrt{S}` de la prédiction) l'est toujours.

**Mémoire évanescente** (*fading memory*, Sorenson & Sacks 1971). Avec ``fading=α`` (:math:`\alpha \ge 1`),
la prédiction gonfle la covariance propagée :

.. math:: P_{k\mid k-1} = \alpha^2\,A P_{k-1\mid k-1} A^T + Q ,

ce qui revient à pondérer les mesures anciennes par :math:`\alpha^{-2}` par pas : le filtre oublie le passé
et suit plus vite une cible qui change de régime (c'est le ``KalmanFilter.alpha`` de filterpy).
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any

import numpy as np
import scipy.linalg

from ..core.validation import KalmanInputError

__all__ = ["gate_probability", "gate_threshold", "fading_factor", "nis_value"]


def gate_probability(gate: Any) -> float | None:
    """Vérifie l'option ``gate`` : ``None`` (pas de porte) ou une probabilité :math:`0 < p < 1`."""
    if gate is None:
        return None
    if isinstance(gate, bool) or not isinstance(gate, (int, float, np.floating, np.integer)) \
            or not 0.0 < float(gate) < 1.0:
        raise KalmanInputError(
            f"« gate » doit être une probabilité strictement entre 0 et 1 (par exemple 0,99 : on garde 99 % "
            f"des mesures conformes au modèle) ; reçu {gate!r}."
        )
    return float(gate)


@lru_cache(maxsize=64)
def gate_threshold(p: float, m: int) -> float:
    r"""Seuil de la porte : le quantile :math:`\chi^2_m(p)`, :math:`m` composantes observées
    (:math:`2\,\Gamma^{-1}_{\text{inf}}(m/2, p)`, par ``scipy.special.gammaincinv``)."""
    import scipy.special

    return float(2.0 * scipy.special.gammaincinv(0.5 * m, p))


def fading_factor(fading: Any) -> float | None:
    r"""Vérifie l'option ``fading`` : ``None`` (pas d'oubli) ou :math:`\alpha \ge 1` ; renvoie
    :math:`\alpha^2` (``None`` si :math:`\alpha = 1` ou absent : la prédiction ordinaire)."""
    if fading is None:
        return None
    if isinstance(fading, bool) or not isinstance(fading, (int, float, np.floating, np.integer)) \
            or not np.isfinite(fading) or float(fading) < 1.0:
        raise KalmanInputError(
            f"« fading » doit être un facteur α ≥ 1 (1 : filtre ordinaire ; 1,02 : les mesures perdent "
            f"environ 4 % de poids par pas) ; reçu {fading!r}."
        )
    return None if float(fading) == 1.0 else float(fading) ** 2


def nis_value(nu: np.ndarray, S: np.ndarray) -> float:
    r"""NIS :math:`\nu^TS^{-1}\nu` d'une innovation ``nu`` (m,) de covariance ``S`` (m, m), par Cholesky."""
    if S.shape[0] == 1:
        return float(nu[0] * nu[0] / S[0, 0])
    c = scipy.linalg.cho_factor(S, lower=True, check_finite=False)
    return float(nu.dot(scipy.linalg.cho_solve(c, nu, check_finite=False)))
