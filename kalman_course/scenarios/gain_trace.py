r"""La covariance a posteriori en fonction du gain, :math:`P_n(K)`, sur la tension constante (chapitre
« Dynamique de l'erreur et gain optimal »).

Pour un gain :math:`K` quelconque, :math:`P_n(K) = (1 - K)^2 P^-_n + K^2 \Psi` (forme de Joseph scalaire,
:func:`~kalman_course.covariance_for_gain`) : le premier terme est l'erreur de prédiction qui reste, le
second le bruit de mesure que l'on fait entrer. Leur somme est minimale pour le gain de Kalman
:math:`K^\star_n = P^-_n/(P^-_n + \Psi)`. :math:`P^-_n` vient du filtre du chapitre (50 relevés,
:math:`\hat x_0 = 0`, :math:`P_0 = 1` V²).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..core.validation import KalmanInputError, as_float_array
from ..filters.kalman import kalman_filter
from ..lecture.estimator import covariance_for_gain
from .engine import engine_model, engine_run
from .voltage import constant_voltage_measurements, constant_voltage_model

__all__ = ["TRACE_STEPS", "GainTrace", "gain_trace", "engine_trace_ratios"]

#: Nombre de relevés du filtre de référence.
TRACE_STEPS = 50


@dataclass(frozen=True)
class GainTrace:
    r"""Au pas ``n`` et pour le gain ``K`` : ``P_pred`` :math:`P^-_n`, ``K_star`` :math:`K^\star_n`,
    ``P`` :math:`P_n(K)`, ``prediction_part`` :math:`(1 - K)^2P^-_n`, ``measurement_part``
    :math:`K^2\Psi`, ``P_star`` :math:`P_n(K^\star_n)` (V² ; gains sans unité)."""

    n: int
    K: float
    P_pred: float
    K_star: float
    P: float
    prediction_part: float
    measurement_part: float
    P_star: float


@lru_cache(maxsize=4)
def _reference(n_steps: int):
    """Le filtre du chapitre (immuable : gardé entre deux appels)."""
    model = constant_voltage_model()
    return model, kalman_filter(model, constant_voltage_measurements(n_steps), 0.0, 1.0)


def gain_trace(n: int, K: float, n_steps: int = TRACE_STEPS) -> GainTrace:
    r""":math:`P_n(K)` et ses deux termes, au pas ``n`` (1 ≤ n ≤ ``n_steps``) du filtre de la tension constante."""
    if not isinstance(n, (int, np.integer)) or isinstance(n, bool) or not 1 <= n <= n_steps:
        raise KalmanInputError(f"« n » doit être un numéro de relevé entier entre 1 et {n_steps} ; reçu {n!r}.")
    k = as_float_array("K", K)
    if k.ndim != 0 or not np.isfinite(k):
        raise KalmanInputError(f"« K » doit être un gain scalaire fini ; reçu {K!r}.")
    k = float(k)
    model, run = _reference(int(n_steps))
    P_pred, K_star = float(run.P_pred[n - 1, 0, 0]), float(run.K[n - 1, 0, 0])
    R = float(model.R[0, 0])
    return GainTrace(
        n=int(n), K=k, P_pred=P_pred, K_star=K_star,
        P=float(covariance_for_gain(model, [[P_pred]], [[k]])[0, 0]),
        prediction_part=(1.0 - k) ** 2 * P_pred, measurement_part=k**2 * R,
        P_star=float(covariance_for_gain(model, [[P_pred]], [[K_star]])[0, 0]),
    )


def engine_trace_ratios(n_directions: int = 6, step: int = 5, seed: int = 7) -> tuple[np.ndarray, np.ndarray]:
    r"""Trace de :math:`P_{n}(K)` autour du gain de Kalman :math:`K^\star`, pour le moteur au pas ``step``
    (:func:`~kalman_course.scenarios.engine.engine_run`).

    Renvoie ``(t, ratios)`` : ``ratios[j, i]`` = :math:`\mathrm{tr}\,P(K^\star + t_i D_j)/\mathrm{tr}\,P(K^\star)`
    pour des directions aléatoires :math:`D_j` (graine ``seed``) de norme :math:`\|K^\star\|`.
    """
    _, res = engine_run(step)
    model = engine_model()
    P_pred, K_star = res.P_pred[-1], res.K[-1]
    rng = np.random.default_rng(seed)
    t = np.linspace(-1.0, 1.0, 81)
    base = np.trace(covariance_for_gain(model, P_pred, K_star))
    ratios = []
    for _ in range(n_directions):
        D = rng.standard_normal(K_star.shape)
        D *= np.linalg.norm(K_star) / np.linalg.norm(D)
        ratios.append([np.trace(covariance_for_gain(model, P_pred, K_star + ti * D)) / base for ti in t])
    return t, np.array(ratios)
