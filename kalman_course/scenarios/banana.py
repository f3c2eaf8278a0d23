r"""Scénario « banane » : une loi gaussienne en coordonnées polaires (distance :math:`r`, azimut
:math:`\theta`) vue en coordonnées cartésiennes, :math:`g(r, \theta) = (r\cos\theta,\ r\sin\theta)`.

Quand l'azimut est incertain, l'image de la gaussienne est un croissant (une « banane ») : sa moyenne
est **à l'intérieur** de l'arc, plus près du capteur que le point :math:`g(\bar r, \bar\theta)`. On
compare trois façons d'en calculer la moyenne et la covariance :

* la vérité, en **forme close** : avec :math:`r \sim \mathcal N(\bar r, \sigma_r^2)` et
  :math:`\theta \sim \mathcal N(\bar\theta, \sigma_\theta^2)` indépendants,
  :math:`\mathbb E[\cos\theta] = \cos\bar\theta\, e^{-\sigma_\theta^2/2}`,
  :math:`\mathbb E[\cos^2\theta] = \tfrac12(1 + \cos 2\bar\theta\, e^{-2\sigma_\theta^2})`,
  :math:`\mathbb E[\sin\theta\cos\theta] = \tfrac12\sin 2\bar\theta\, e^{-2\sigma_\theta^2}`,
  :math:`\mathbb E[r^2] = \bar r^2 + \sigma_r^2` (un nuage de Monte-Carlo sert au dessin) ;
* la **linéarisation** (EKF) : :math:`g(\bar r, \bar\theta)` et :math:`JPJ^T` ;
* la **transformée unscented** (UKF) : :func:`~kalman_course.unscented_transform`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.results import freeze_fields
from ..core.simulation import as_generator, check_positive_int
from ..core.validation import KalmanInputError
from ..filters.unscented import unscented_transform
from .polar import polar_moments, polar_to_cartesian, polar_to_cartesian_jacobian

__all__ = [
    "BANANA_RANGE",
    "BANANA_BEARING",
    "BANANA_RANGE_STD",
    "BANANA_BEARING_STD",
    "BANANA_ALPHA",
    "BANANA_BETA",
    "BANANA_KAPPA",
    "BANANA_SEED",
    "Moments",
    "BananaComparison",
    "banana_truth",
    "banana_linearized",
    "banana_unscented",
    "banana_comparison",
    "banana_polar_sample",
    "banana_sample",
    "mean_error_orders",
]

#: Distance moyenne (m).
BANANA_RANGE = 1.0
#: Azimut moyen (rad) : la cible est droit devant, vers le haut.
BANANA_BEARING = float(np.pi / 2)
#: Écart-type de la distance (m).
BANANA_RANGE_STD = 0.02
#: Écart-type de l'azimut (rad) : 20° (0,349 rad).
BANANA_BEARING_STD = float(np.deg2rad(20.0))
#: Points sigma du chapitre : :math:`\alpha = 1`, :math:`\beta = 2`, :math:`\kappa = 3 - n = 1`.
BANANA_ALPHA = 1.0
BANANA_BETA = 2.0
BANANA_KAPPA = 1.0
#: Graine du nuage de Monte-Carlo.
BANANA_SEED = 11


@dataclass(frozen=True, eq=False)
class Moments:
    """Moyenne ``mean`` (2,) et covariance ``cov`` (2, 2) d'une loi dans le plan (m, m²)."""

    mean: np.ndarray
    cov: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, "mean", "cov")


def _check_std(name: str, value: Any) -> float:
    if isinstance(value, bool) or not np.isscalar(value) or not np.isfinite(value) or value <= 0:
        raise KalmanInputError(f"« {name} » doit être un écart-type strictement positif ; reçu {value!r}.")
    return float(value)


def banana_truth(
    range_std: float = BANANA_RANGE_STD, bearing_std: float = BANANA_BEARING_STD,
    r: float = BANANA_RANGE, bearing: float = BANANA_BEARING,
) -> Moments:
    r"""Moyenne et covariance exactes de :math:`g(r, \theta)` (formes closes de l'en-tête)."""
    sr, st = _check_std("range_std", range_std), _check_std("bearing_std", bearing_std)
    return Moments(*polar_moments(sr, st, r, bearing))


def banana_linearized(
    range_std: float = BANANA_RANGE_STD, bearing_std: float = BANANA_BEARING_STD,
    r: float = BANANA_RANGE, bearing: float = BANANA_BEARING,
) -> Moments:
    r"""Linéarisation en :math:`(\bar r, \bar\theta)` : :math:`g(\bar r, \bar\theta)` et :math:`J\,\mathrm{diag}(\sigma_r^2, \sigma_\theta^2)J^T`."""
    sr, st = _check_std("range_std", range_std), _check_std("bearing_std", bearing_std)
    J = polar_to_cartesian_jacobian([r, bearing])
    return Moments(polar_to_cartesian([r, bearing]), J @ np.diag([sr**2, st**2]) @ J.T)


def banana_unscented(
    range_std: float = BANANA_RANGE_STD, bearing_std: float = BANANA_BEARING_STD,
    *, alpha: float = BANANA_ALPHA, beta: float = BANANA_BETA, kappa: float = BANANA_KAPPA,
    r: float = BANANA_RANGE, bearing: float = BANANA_BEARING,
):
    r"""Transformée unscented de :math:`\mathcal N((\bar r, \bar\theta), \mathrm{diag}(\sigma_r^2, \sigma_\theta^2))`
    par :func:`polar_to_cartesian` ; renvoie l':class:`~kalman_course.UnscentedTransform` (avec les points sigma)."""
    sr, st = _check_std("range_std", range_std), _check_std("bearing_std", bearing_std)
    return unscented_transform(np.array([r, bearing]), np.diag([sr**2, st**2]), polar_to_cartesian,
                               alpha=alpha, beta=beta, kappa=kappa, vectorized=True)


def banana_polar_sample(
    n: int = 2000, range_std: float = BANANA_RANGE_STD, bearing_std: float = BANANA_BEARING_STD,
    rng: Any = BANANA_SEED, r: float = BANANA_RANGE, bearing: float = BANANA_BEARING,
) -> np.ndarray:
    r"""Tirages polaires (n, 2) :math:`(r_j, \theta_j)` (m, rad) de :math:`\mathcal N((\bar r, \bar\theta),
    \mathrm{diag}(\sigma_r^2, \sigma_\theta^2))`."""
    n = check_positive_int("n", n)
    sr, st = _check_std("range_std", range_std), _check_std("bearing_std", bearing_std)
    z = as_generator(rng).standard_normal((n, 2))
    return np.column_stack([r + sr * z[:, 0], bearing + st * z[:, 1]])


def banana_sample(
    n: int = 2000, range_std: float = BANANA_RANGE_STD, bearing_std: float = BANANA_BEARING_STD,
    rng: Any = BANANA_SEED, r: float = BANANA_RANGE, bearing: float = BANANA_BEARING,
) -> np.ndarray:
    r"""Nuage de Monte-Carlo (n, 2) : :math:`g(r_j, \theta_j)` pour les :math:`n` tirages polaires de
    :func:`banana_polar_sample`."""
    return polar_to_cartesian(banana_polar_sample(n, range_std, bearing_std, rng, r, bearing))


@dataclass(frozen=True, eq=False)
class BananaComparison:
    """Les trois réponses pour un couple d'écarts-types : ``truth``, ``linearized``, ``unscented``
    (:class:`Moments`), les points sigma polaires ``sigma_points`` (5, 2) et leurs images ``sigma_images``
    (5, 2), les poids ``Wm``, ``Wc`` (5,)."""

    truth: Moments
    linearized: Moments
    unscented: Moments
    sigma_points: np.ndarray
    sigma_images: np.ndarray
    Wm: np.ndarray
    Wc: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, "sigma_points", "sigma_images", "Wm", "Wc")

    def mean_errors(self) -> tuple[float, float]:
        """Distances (m) de la moyenne linéarisée et de la moyenne unscented à la vraie moyenne."""
        t = self.truth.mean
        return float(np.linalg.norm(self.linearized.mean - t)), float(np.linalg.norm(self.unscented.mean - t))


def banana_comparison(
    range_std: float = BANANA_RANGE_STD, bearing_std: float = BANANA_BEARING_STD,
    *, alpha: float = BANANA_ALPHA, beta: float = BANANA_BETA, kappa: float = BANANA_KAPPA,
) -> BananaComparison:
    r"""Vérité (forme close), linéarisation et transformée unscented pour :math:`(\sigma_r, \sigma_\theta)`."""
    ut = banana_unscented(range_std, bearing_std, alpha=alpha, beta=beta, kappa=kappa)
    return BananaComparison(
        truth=banana_truth(range_std, bearing_std),
        linearized=banana_linearized(range_std, bearing_std),
        unscented=Moments(ut.mean, ut.cov),
        sigma_points=ut.points,
        sigma_images=ut.transformed,
        Wm=ut.Wm,
        Wc=ut.Wc,
    )


def mean_error_orders(bearing_stds: Any, *, kappas: tuple[float, ...] = (0.0, 1.0), range_std: float = BANANA_RANGE_STD):
    r"""Erreur de la moyenne (m) en fonction de :math:`\sigma_\theta` : linéarisation, puis transformée sans
    parfum (:math:`\alpha = 1`, :math:`\beta = 2`) pour chaque :math:`\kappa` de ``kappas``. Renvoie un
    tableau (1 + len(kappas), len(bearing_stds)) ; les pentes log-log valent 2 (linéarisation), 4
    (:math:`\kappa = 0`) et 6 (:math:`\kappa = 3 - n = 1`, qui reproduit aussi le moment d'ordre 4 de la gaussienne)."""
    stds = np.atleast_1d(np.asarray(bearing_stds, dtype=float))
    out = np.empty((1 + len(kappas), stds.size))
    for j, s in enumerate(stds):
        truth = banana_truth(range_std, float(s)).mean
        out[0, j] = np.linalg.norm(banana_linearized(range_std, float(s)).mean - truth)
        for i, kappa in enumerate(kappas):
            out[1 + i, j] = np.linalg.norm(banana_unscented(range_std, float(s), kappa=kappa).mean - truth)
    return out
