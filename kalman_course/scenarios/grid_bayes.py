r"""Le filtre bayésien exact sur une grille (chapitre « Le filtre particulaire ») : pour un état scalaire,
les deux intégrales de la récurrence bayésienne se calculent par la méthode des rectangles sur une grille
fine de :math:`M` points :math:`\xi_1 < \dots < \xi_M` (pas :math:`\Delta`),

.. math::

    p^-_k(\xi_i) = \sum_j p(\xi_i \mid \xi_j)\, p_{k-1}(\xi_j)\,\Delta,\qquad
    p_k(\xi_i) = \frac{p(y_k \mid \xi_i)\, p^-_k(\xi_i)}{\sum_j p(y_k \mid \xi_j)\, p^-_k(\xi_j)\,\Delta},

et le dénominateur est le facteur :math:`p(y_k \mid y_{1:k-1})` de la vraisemblance. C'est la référence
« exacte » (à la discrétisation près) des filtres non linéaires du chapitre ; elle coûte :math:`M^2`
opérations par pas, et :math:`M^{2d}` en dimension :math:`d` : c'est pourquoi on ne l'utilise qu'en
dimension 1 ou 2, et pourquoi le filtre particulaire place ses points là où la loi vit.

:func:`grid_bayes_filter` traite un modèle scalaire à bruits additifs gaussiens,
:math:`x_k = f(x_{k-1}, u_{k-1}) + w`, :math:`y_k = h(x_k) + v` ; :func:`growth_grid_posteriors`
l'applique au modèle de croissance (:mod:`.growth`), dont la loi a posteriori a souvent deux modes.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from ..core.models import NonlinearModel
from ..core.results import freeze_fields
from ..core.validation import KalmanInputError, as_float_array
from . import growth

__all__ = ["GROWTH_GRID", "GridPosteriors", "grid_bayes_filter", "growth_grid_posteriors", "bimodal_step"]

#: Grille du modèle de croissance : [−32, 32] en 801 points (pas 0,08 ; les états restent sous 25 en
#: valeur absolue ; une grille 3,5 fois plus fine change les moyennes de moins de 10⁻¹¹).
GROWTH_GRID = np.linspace(-32.0, 32.0, 801)
GROWTH_GRID.setflags(write=False)


def _gauss(z: np.ndarray, var: float) -> np.ndarray:
    return np.exp(-0.5 * z**2 / var) / np.sqrt(2.0 * np.pi * var)


@dataclass(frozen=True, eq=False)
class GridPosteriors:
    r"""Le filtre bayésien sur une grille : ``grid`` (M,) ; ``density`` (T, M) densités a posteriori
    :math:`p(x_k \mid y_{1:k})` ; ``predicted`` (T, M) densités prédites :math:`p(x_k \mid y_{1:k-1})` ;
    ``mean`` (T,), ``var`` (T,) leurs moments ; ``log_likelihood`` :math:`\log p(y_{1:T})` (nats)."""

    grid: np.ndarray
    density: np.ndarray
    predicted: np.ndarray
    mean: np.ndarray
    var: np.ndarray
    log_likelihood: float

    def __post_init__(self) -> None:
        freeze_fields(self, "grid", "density", "predicted", "mean", "var")

    def mass_near(self, k: int, center: float, half_width: float) -> float:
        """Probabilité a posteriori, au pas ``k``, que :math:`|x_k - \\text{center}| \\le` ``half_width``."""
        dx = self.grid[1] - self.grid[0]
        inside = np.abs(self.grid - center) <= half_width
        return float(np.sum(self.density[k, inside]) * dx)


def grid_bayes_filter(model: NonlinearModel, y: Any, x0: float, P0: float, u: Any = None,
                      grid: Any = GROWTH_GRID) -> GridPosteriors:
    r"""Récurrence bayésienne exacte (à la discrétisation près) d'un modèle **scalaire** à bruits
    additifs : a priori :math:`\mathcal N(x_0, P_0)`, transition :math:`\mathcal N(f(x, u), Q)`, mesure
    :math:`\mathcal N(h(x), R)`. ``y`` (T, 1) (NaN : pas de mesure), ``u`` (T, p) ou ``None`` (``u[k]``
    sert à prédire vers ``y[k]``, comme dans les filtres du paquet), ``grid`` (M,) croissante et régulière."""
    if model.n_state != 1 or model.n_obs != 1:
        raise KalmanInputError(
            f"grid_bayes_filter : un état et une mesure scalaires sont attendus (reçu n = {model.n_state}, "
            f"m = {model.n_obs})."
        )
    grid = as_float_array("grid", grid)
    steps = np.diff(grid) if grid.ndim == 1 and grid.size >= 3 else np.array([])
    if steps.size == 0 or not np.all(steps > 0) or not np.allclose(steps, steps[0]):
        raise KalmanInputError("« grid » doit être une grille (M,) régulière et croissante, M ≥ 3.")
    y = as_float_array("y", y, allow_nan=True).reshape(-1, 1)
    T = y.shape[0]
    u = None if u is None else as_float_array("u", u).reshape(T, -1)
    dx = float(steps[0])
    Q, R = float(model.Q[0, 0]), float(model.R[0, 0])
    post = _gauss(grid - float(x0), float(P0))
    column = grid[:, None]
    h = model.observe_many(column)[:, 0]
    density, predicted, means, variances = [], [], [], []
    log_lik = 0.0
    for k in range(T):
        uk = None if u is None else u[k]
        moved = model.transition_many(column, uk)[:, 0]
        prior = _gauss(grid[:, None] - moved[None, :], Q) @ post * dx   # ∫ p(x_k | x_k−1) p(x_k−1 | y) dx
        if np.isnan(y[k, 0]):
            post = prior
        else:
            like = _gauss(y[k, 0] - h, R)
            evidence = float(np.sum(like * prior) * dx)                  # p(y_k | y_1:k−1)
            post = like * prior / evidence
            log_lik += np.log(evidence)
        mean = float(np.sum(grid * post) * dx)
        predicted.append(prior)
        density.append(post)
        means.append(mean)
        variances.append(float(np.sum((grid - mean) ** 2 * post) * dx))
    return GridPosteriors(grid=np.array(grid), density=np.array(density), predicted=np.array(predicted),
                          mean=np.array(means), var=np.array(variances), log_likelihood=float(log_lik))


def growth_grid_posteriors(data: growth.GrowthData | None = None) -> GridPosteriors:
    """Le filtre bayésien sur grille du modèle de croissance, sur les données du chapitre (ou ``data``)."""
    if data is None:
        return _chapter_grid_posteriors()
    return grid_bayes_filter(growth.growth_model(), data.y, growth.GROWTH_X0, growth.GROWTH_P0, data.u)


@lru_cache(maxsize=1)
def _chapter_grid_posteriors() -> GridPosteriors:
    """Celui des données du chapitre, calculé une fois (le résultat est immuable)."""
    data = growth.growth_data()
    return grid_bayes_filter(growth.growth_model(), data.y, growth.GROWTH_X0, growth.GROWTH_P0, data.u)


def bimodal_step(post: GridPosteriors) -> int:
    r"""Le pas où la loi a posteriori est la plus partagée entre :math:`x > 0` et :math:`x < 0` (masse du
    côté le moins probable la plus grande), hors du premier pas."""
    dx = post.grid[1] - post.grid[0]
    positive = np.sum(post.density[:, post.grid > 0], axis=1) * dx
    minority = np.minimum(positive, 1.0 - positive)
    minority[0] = -1.0
    return int(np.argmax(minority))
