r"""Filtre de Kalman à cubature (*cubature Kalman filter*, CKF ; Arasaratnam et Haykin, 2009).

La règle de cubature sphérique–radiale du troisième degré remplace l'intégrale gaussienne
:math:`\int g(x)\,\mathcal N(x; \hat x, P)\,dx` par la moyenne de :math:`g` sur :math:`2n` points :

.. math::

    \chi_i = \hat x + \sqrt n\, s_i,\qquad \chi_{n+i} = \hat x - \sqrt n\, s_i\quad (i = 1\dots n),
    \qquad W_i = \frac{1}{2n},

où :math:`s_i` est la ligne :math:`i` du facteur de Cholesky supérieur de :math:`P` (comme
``spherical_radial_sigmas`` de filterpy). Tous les poids sont positifs et égaux (c'est la transformée sans
parfum avec :math:`\alpha = 1, \beta = 0, \kappa = 0`, dont le point central a alors un poids nul) ; la
règle est exacte pour les polynômes de degré 3.

C'est le filtre gaussien (:mod:`kalman_course.filters.gaussian`) avec :class:`CubatureRule`.
``redraw=True`` (défaut) : la correction tire de nouveaux points de :math:`(\hat x^-, P^-)`, comme l'UKF ;
``redraw=False`` : elle réutilise les points propagés par :math:`f`, comme ``CubatureKalmanFilter`` de
filterpy (qui, de ce fait, ne redonne pas le filtre de Kalman sur un modèle linéaire : les points propagés
ignorent :math:`Q`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.models import NonlinearModel
from ..core.results import FilterResult, FilterRuns
from .engine import FilterFamily, run_filter, run_filter_runs
from .gaussian import SymmetricSigmaRule, gaussian_family

__all__ = ["CubatureRule", "CUBATURE", "cubature_family", "cubature_kalman_filter", "cubature_kalman_filter_runs"]


@dataclass(frozen=True)
class CubatureRule(SymmetricSigmaRule):
    r"""La règle de cubature sphérique–radiale du troisième degré : :math:`2n` points
    :math:`\hat x \pm \sqrt n\, s_i`, poids :math:`1/(2n)` (voir l'en-tête du module)."""

    label = "CKF"
    filter_name = "filtre de Kalman à cubature (CKF)"
    point_name = "de cubature"
    central = False

    def scale(self, n: int) -> float:
        return float(n)

    def weights(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        W = np.full(2 * n, 0.5 / n)
        return W, W.copy()


#: La règle de cubature (sans paramètre : une seule instance suffit).
CUBATURE = CubatureRule()


def cubature_family(*, redraw: bool = True) -> FilterFamily:
    r"""Les étapes du CKF pour le moteur : celles du filtre gaussien avec :class:`CubatureRule`."""
    return gaussian_family(CUBATURE, redraw=redraw)


def cubature_kalman_filter(model: NonlinearModel, y: Any, x0: Any, P0: Any, u: Any = None, *,
                           redraw: bool = True, gate: Any = None, fading: Any = None) -> FilterResult:
    r"""Filtre de Kalman à cubature sur toutes les mesures (pour chaque ``y[k]`` : prédiction puis correction,
    dans l'ordre de :func:`~kalman_course.kalman_filter`).

    .. math::

        \hat x^- = \frac{1}{2n}\sum_i f(\chi_i),\quad
        P^- = \frac{1}{2n}\sum_i (f(\chi_i) - \hat x^-)(f(\chi_i) - \hat x^-)^T + Q,

        \hat y = \frac{1}{2n}\sum_i h(\tilde\chi_i),\quad
        S = \frac{1}{2n}\sum_i (h(\tilde\chi_i) - \hat y)(\cdot)^T + R,\quad
        P_{xy} = \frac{1}{2n}\sum_i (\tilde\chi_i - \hat x^-)(h(\tilde\chi_i) - \hat y)^T,

        K = P_{xy}S^{-1},\quad \hat x = \hat x^- + K(y - \hat y),\quad P = P^- - KP_{xy}^T,

    avec :math:`\chi_i` les points de :math:`(\hat x, P)` et :math:`\tilde\chi_i` ceux de
    :math:`(\hat x^-, P^-)` (``redraw=True``) ou les points propagés :math:`f(\chi_i)` (``redraw=False``).

    Paramètres
    ----------
    model : NonlinearModel à bruits additifs (``vectorized=True`` : les :math:`2n` points passent par
        ``f`` et ``h`` en un appel).
    y : (T, m), ou (T,) si m = 1 — ``NaN`` : composante manquante.
    x0 : (n,) ; P0 : (n, n) symétrique **définie** positive.
    u : (T, p), ou (T,) si p = 1, optionnel — commandes (``u[k]``, qui contient :math:`u_{k-1}`, sert à prédire vers ``y[k]``).
    redraw : ``True`` (défaut) : nouveaux points à la correction — égal à
        ``unscented_kalman_filter(alpha=1, beta=0, kappa=0)`` et, sur un modèle linéaire, au filtre de
        Kalman ; ``False`` : points propagés réutilisés — égal à ``CubatureKalmanFilter`` de filterpy.
    gate, fading : porte et mémoire évanescente, options du moteur (:mod:`~kalman_course.filters.gating`),
        comme pour :func:`~kalman_course.kalman_filter`.

    Renvoie un :class:`~kalman_course.FilterResult`.
    """
    return run_filter(cubature_family(redraw=redraw), model, y, x0, P0, u, gate=gate, fading=fading)


def cubature_kalman_filter_runs(model: NonlinearModel, Y: Any, x0: Any, P0: Any, u: Any = None, *,
                                redraw: bool = True) -> FilterRuns:
    r""":func:`cubature_kalman_filter` sur ``N`` tirages indépendants du même modèle, tous à la fois :
    ``Y`` (N, T, m), ``x0`` (n,) ou (N, n), ``P0`` (n, n) ou (N, n, n), ``u`` (T, p) commune. Les
    :math:`2nN` points d'un pas passent par :math:`f` (ou :math:`h`) en un appel si le modèle est vectorisé.
    Renvoie un :class:`~kalman_course.FilterRuns`."""
    return run_filter_runs(cubature_family(redraw=redraw), model, Y, x0, P0, u)
