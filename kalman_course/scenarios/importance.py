r"""Les poids des particules : un exemple d'échantillonnage d'importance à une dimension, et la
dégénérescence des poids sans rééchantillonnage.

**Importance.** A priori :math:`x \sim \mathcal N(0, 1)`, mesure :math:`y = x + v`, :math:`v \sim \mathcal N(0, r^2)`.
Les particules tirées de l'a priori reçoivent les poids :math:`w^i \propto \mathcal N(y;\,x^i,\,r^2)` ; la loi a
posteriori exacte est :math:`\mathcal N\big(y/(1 + r^2),\ r^2/(1 + r^2)\big)`. Plus la mesure est précise
(:math:`r` petit), moins de particules comptent : la taille effective :math:`\mathrm{ESS} = 1/\sum (w^i)^2`
s'effondre.

**Dégénérescence.** Le filtre particulaire sans rééchantillonnage (:math:`\tau = 0`, « SIS ») sur le banc
d'essai linéaire : l'ESS décroît jusqu'à une seule particule ; avec rééchantillonnage (:math:`\tau = 0{,}5`)
elle remonte à :math:`N` après chaque rééchantillonnage.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.results import freeze_fields
from ..core.simulation import as_generator, check_positive_int
from ..core.validation import KalmanInputError
from ..filters.particle import particle_filter
from .convergence import linear_benchmark

__all__ = [
    "IMPORTANCE_Y",
    "IMPORTANCE_R_STD",
    "IMPORTANCE_N",
    "IMPORTANCE_SEED",
    "ImportanceExample",
    "importance_example",
    "Degeneracy",
    "degeneracy",
]

#: Mesure de l'exemple.
IMPORTANCE_Y = 1.5
#: Écart-type de la mesure.
IMPORTANCE_R_STD = 0.5
#: Nombre de particules de l'exemple.
IMPORTANCE_N = 40
#: Graine des particules.
IMPORTANCE_SEED = 3


@dataclass(frozen=True, eq=False)
class ImportanceExample:
    r"""``particles`` (N,) tirées de l'a priori, ``weights`` (N,) normalisés, ``ess``, estimation pondérée
    ``estimate`` :math:`\sum w^i x^i`, moyenne et variance exactes ``posterior_mean``, ``posterior_var``,
    mesure ``y`` et écart-type ``r_std``."""

    particles: np.ndarray
    weights: np.ndarray
    ess: float
    estimate: float
    posterior_mean: float
    posterior_var: float
    y: float
    r_std: float

    def __post_init__(self) -> None:
        freeze_fields(self, "particles", "weights")


def importance_example(n: int = IMPORTANCE_N, r_std: float = IMPORTANCE_R_STD, y: float = IMPORTANCE_Y,
                       rng: Any = IMPORTANCE_SEED) -> ImportanceExample:
    r"""L'exemple de l'en-tête : :math:`N` particules de :math:`\mathcal N(0, 1)`, poids par la vraisemblance
    (calculés en logarithme puis normalisés)."""
    n = check_positive_int("n", n)
    if isinstance(r_std, bool) or not np.isscalar(r_std) or not np.isfinite(r_std) or r_std <= 0:
        raise KalmanInputError(f"« r_std » doit être un écart-type strictement positif ; reçu {r_std!r}.")
    x = as_generator(rng).standard_normal(n)
    logw = -0.5 * ((y - x) / r_std) ** 2
    w = np.exp(logw - logw.max())
    w /= w.sum()
    return ImportanceExample(
        particles=x, weights=w, ess=float(1.0 / np.dot(w, w)), estimate=float(w @ x),
        posterior_mean=y / (1.0 + r_std**2), posterior_var=r_std**2 / (1.0 + r_std**2), y=float(y), r_std=float(r_std),
    )


@dataclass(frozen=True, eq=False)
class Degeneracy:
    r"""ESS relative :math:`\mathrm{ESS}/N` (T,) sans rééchantillonnage (``without``) et avec (``with_``),
    pas où le nuage a été rééchantillonné (``resampled``, booléens (T,)), ``n_particles``."""

    without: np.ndarray
    with_: np.ndarray
    resampled: np.ndarray
    n_particles: int

    def __post_init__(self) -> None:
        freeze_fields(self, "without", "with_")


def degeneracy(n_particles: int = 1000, rng: Any = 0, R: float = 0.25) -> Degeneracy:
    r"""Filtre particulaire sur le banc d'essai linéaire (variance de mesure ``R``) avec :math:`\tau = 0`
    puis :math:`\tau = 0{,}5`, mêmes mesures, même graine."""
    bench = linear_benchmark(R=R)
    runs = [particle_filter(bench.nonlinear, bench.y, bench.x0, bench.P0, n_particles=n_particles, rng=rng,
                            ess_threshold=tau) for tau in (0.0, 0.5)]
    return Degeneracy(without=runs[0].ess / n_particles, with_=runs[1].ess / n_particles,
                      resampled=np.array(runs[1].resampled), n_particles=int(n_particles))
