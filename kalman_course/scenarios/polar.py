r"""Une loi gaussienne en coordonnées polaires transformée en coordonnées cartésiennes (chapitre « Le
filtre de Kalman étendu »).

:math:`x = (r, \theta) \sim \mathcal N(\hat x, P)`, :math:`\hat x = (10\ \text{m}, 0)`,
:math:`P = \operatorname{diag}(\sigma_r^2, \sigma_\theta^2)`, transformée par
:math:`f(r, \theta) = (r\cos\theta, r\sin\theta)`. Deux approximations de la loi de :math:`f(x)` :

- **exacte** : moyenne et covariance en forme close, :math:`\mathbb E[f(x)] = \hat r\,e^{-\sigma_\theta^2/2}
  (\cos\hat\theta, \sin\hat\theta)` (:func:`polar_moments`, que :func:`~kalman_course.scenarios.banana.banana_truth` reprend) ; le nuage
  de Monte-Carlo (3000 tirages, graine fixe ; les mêmes tirages normaux mis à l'échelle de
  :math:`(\sigma_r, \sigma_\theta)`) les illustre, ses moments empiriques en restent à l'erreur de
  Monte-Carlo près ;
- **EKF** : :math:`f(\hat x)` et :math:`J P J^T` (:func:`~kalman_course.ekf_predict`, bruit d'état nul).

(La transformée *unscented* de la même loi est au chapitre de l'UKF, :mod:`.banana`.)

Avec :math:`\sigma_r = 0{,}5` m et :math:`\sigma_\theta = 20°`, c'est la figure de linéarisation du
chapitre de l'EKF.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.models import NonlinearModel
from ..core.results import freeze_fields
from ..core.validation import KalmanInputError, as_float_array
from ..filters.extended import ekf_predict

__all__ = [
    "POLAR_MEAN",
    "POLAR_RANGE_STD",
    "POLAR_BEARING_STD_DEG",
    "POLAR_SAMPLES",
    "POLAR_SEED",
    "polar_to_cartesian",
    "polar_to_cartesian_jacobian",
    "polar_moments",
    "PolarTransform",
    "polar_transform",
]

#: Moyenne en coordonnées polaires : 10 m, azimut 0.
POLAR_MEAN = np.array([10.0, 0.0])
POLAR_MEAN.setflags(write=False)
#: Écarts-types de la figure du chapitre : 0,5 m et 20°.
POLAR_RANGE_STD = 0.5
POLAR_BEARING_STD_DEG = 20.0
#: Nombre de tirages et graine du Monte-Carlo (ceux de la figure du chapitre).
POLAR_SAMPLES = 3000
POLAR_SEED = 11


def polar_to_cartesian(x, u=None):
    r""":math:`f(r, \theta) = (r\cos\theta,\ r\sin\theta)` (m) ; ``x`` (2,) ou pile (N, 2) ; ``u`` ignoré
    (signature d'une transition :math:`f(x, u)`)."""
    x = np.asarray(x, dtype=float)
    r, theta = x[..., 0], x[..., 1]
    return np.stack([r * np.cos(theta), r * np.sin(theta)], axis=-1)


def polar_to_cartesian_jacobian(x, u=None):
    r""":math:`J = \begin{bmatrix}\cos\theta & -r\sin\theta\\ \sin\theta & r\cos\theta\end{bmatrix}`."""
    c, s = np.cos(x[1]), np.sin(x[1])
    return np.array([[c, -x[0] * s], [s, x[0] * c]])


def polar_moments(range_std: float, bearing_std: float, r: float, bearing: float) -> tuple[np.ndarray, np.ndarray]:
    r"""Moyenne (2,) et covariance (2, 2) exactes de :math:`f(r, \theta)` pour :math:`r \sim \mathcal N(\bar r,
    \sigma_r^2)` et :math:`\theta \sim \mathcal N(\bar\theta, \sigma_\theta^2)` indépendants (m, m²) :
    :math:`\mathbb E[\cos\theta] = \cos\bar\theta\, e^{-\sigma_\theta^2/2}`,
    :math:`\mathbb E[\cos^2\theta] = \tfrac12(1 + \cos 2\bar\theta\, e^{-2\sigma_\theta^2})`,
    :math:`\mathbb E[\sin\theta\cos\theta] = \tfrac12\sin 2\bar\theta\, e^{-2\sigma_\theta^2}`,
    :math:`\mathbb E[r^2] = \bar r^2 + \sigma_r^2` ; ``bearing_std`` en radians."""
    e1, e2 = np.exp(-0.5 * bearing_std**2), np.exp(-2.0 * bearing_std**2)
    mean = r * e1 * np.array([np.cos(bearing), np.sin(bearing)])
    cc = 0.5 * (1.0 + np.cos(2 * bearing) * e2)
    ss = 0.5 * (1.0 - np.cos(2 * bearing) * e2)
    sc = 0.5 * np.sin(2 * bearing) * e2
    cov = (r**2 + range_std**2) * np.array([[cc, sc], [sc, ss]]) - np.outer(mean, mean)
    return mean, cov


@dataclass(frozen=True, eq=False)
class PolarTransform:
    r"""``samples`` (N, 2) tirages polaires (m, rad) ; ``mapped`` (N, 2) leurs images (m) ;
    ``exact_mean`` (2,), ``exact_cov`` (2, 2) : moments exacts de :math:`f(x)` (forme close) ;
    ``sample_mean``, ``sample_cov`` : moments empiriques des tirages ; ``ekf_mean``, ``ekf_cov``."""

    samples: np.ndarray
    mapped: np.ndarray
    exact_mean: np.ndarray
    exact_cov: np.ndarray
    ekf_mean: np.ndarray
    ekf_cov: np.ndarray
    sample_mean: np.ndarray
    sample_cov: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, "samples", "mapped", "exact_mean", "exact_cov", "ekf_mean", "ekf_cov",
                      "sample_mean", "sample_cov")

    @property
    def ekf_bias(self) -> float:
        """Distance (m) entre la moyenne de l'EKF et la moyenne exacte."""
        return float(np.linalg.norm(self.ekf_mean - self.exact_mean))


def _std(name: str, value) -> float:
    v = as_float_array(name, value)
    if v.ndim != 0 or not (np.isfinite(v) and v > 0):
        raise KalmanInputError(f"« {name} » doit être un écart-type strictement positif ; reçu {value!r}.")
    return float(v)


def polar_transform(range_std: float = POLAR_RANGE_STD, bearing_std_deg: float = POLAR_BEARING_STD_DEG,
                    n_samples: int = POLAR_SAMPLES, seed: int = POLAR_SEED) -> PolarTransform:
    r"""Les deux approximations de la loi de :math:`f(x)` pour :math:`\sigma_r` = ``range_std`` (m) et
    :math:`\sigma_\theta` = ``bearing_std_deg`` (degrés)."""
    std = np.array([_std("range_std", range_std), np.deg2rad(_std("bearing_std_deg", bearing_std_deg))])
    P = np.diag(std**2)
    model = NonlinearModel(polar_to_cartesian, lambda x: x[:1], np.zeros((2, 2)), np.eye(1),
                           f_jacobian=polar_to_cartesian_jacobian)
    pred = ekf_predict(model, POLAR_MEAN, P)  # x⁻ = f(x̂), P⁻ = J P Jᵀ (bruit d'état nul)
    rng = np.random.default_rng(seed)
    samples = POLAR_MEAN + rng.standard_normal((n_samples, 2)) * std
    mapped = np.array([polar_to_cartesian(s) for s in samples])
    exact_mean, exact_cov = polar_moments(std[0], std[1], float(POLAR_MEAN[0]), float(POLAR_MEAN[1]))
    return PolarTransform(samples, mapped, exact_mean, exact_cov, pred.x, pred.P,
                          mapped.mean(axis=0), np.cov(mapped.T))
