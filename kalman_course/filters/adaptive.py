r"""Filtre de Kalman à bruit d'état adaptatif : :math:`Q` remise à l'échelle par **ajustement de covariance**
(*covariance matching*, Myers & Tapley 1976 ; Bar-Shalom, Li & Kirubarajan 2001, § 11.2).

Le modèle annonce :math:`\mathbb E[\nu_k\nu_k^T] = S_k = C_k(A_kP_{k-1}A_k^T + s\,Q_k)C_k^T + R_k` pour un
bruit d'état :math:`s\,Q_k`. Si la cible manœuvre, les innovations observées sont plus grandes que
:math:`S_k` ne le dit : on choisit l'échelle :math:`s` qui **égale les deux en moyenne** sur les
:math:`W` derniers pas. Chaque pas donne une estimation de :math:`s\operatorname{tr}(C_kQ_kC_k^T)`,

.. math:: d_k = \nu_k^T\nu_k - \operatorname{tr}(S_k) + s_{k-1}\operatorname{tr}(C_kQ_kC_k^T),

et l'échelle retenue pour prédire le pas suivant est

.. math:: s_k = \max\Big(s_{\min},\ \frac{\sum_{j=k-W+1}^{k} d_j}{\sum_{j=k-W+1}^{k}\operatorname{tr}(C_jQ_jC_j^T)}\Big).

Avec :math:`s_{\min} = 1` (par défaut), le filtre ne fait que **gonfler** :math:`Q` quand les innovations
l'exigent, et redevient le filtre de Kalman du modèle quand elles redeviennent conformes.

Quand :math:`Q` est petite devant :math:`R`, ce rapport est très bruité : sur une fenêtre de quelques pas,
des innovations ordinaires suffisent à le faire bondir de plusieurs ordres de grandeur. D'où un **test**
avant d'ajuster (``detect=p``, 0,99 par défaut ; Bar-Shalom et al., § 11.2) : tant que la somme des NIS
de la fenêtre reste sous le quantile :math:`\chi^2_{\sum m_j}(p)`, les innovations sont conformes au modèle
et :math:`s_k = s_{\min}`. Un pas sans
mesure ne change pas :math:`s`. Le filtre passe par le moteur commun (une famille de plus) ; le modèle
peut varier dans le temps.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from ..core.linalg import correct, symmetrize
from ..core.models import LinearGaussianModel
from ..core.results import FilterResult
from ..core.validation import KalmanInputError
from .engine import Correction, FilterFamily, gaussian_prior, run_filter
from .gating import gate_probability, gate_threshold, nis_value

__all__ = ["AdaptiveState", "AdaptiveResult", "adaptive_family", "adaptive_kalman_filter"]


class AdaptiveState(NamedTuple):
    r"""État interne : :math:`\hat x` (n,), :math:`P` (n, n), l'échelle :math:`s` de :math:`Q`, et les
    :math:`W` derniers :math:`d_j` et :math:`\operatorname{tr}(C_jQ_jC_j^T)` (tuples)."""

    x: np.ndarray
    P: np.ndarray
    scale: float
    d: tuple[float, ...]
    g: tuple[float, ...]
    nis: tuple[float, ...] = ()
    dof: tuple[int, ...] = ()


@dataclass(frozen=True, eq=False, repr=False)
class AdaptiveResult(FilterResult):
    """Sortie de :func:`adaptive_kalman_filter` : les champs de :class:`~kalman_course.FilterResult` et
    ``q_scale`` (T,), l'échelle :math:`s_k` de :math:`Q` retenue après la mesure ``y[k]`` (elle sert à
    prédire le pas suivant)."""

    q_scale: np.ndarray | None = None


def adaptive_family(window: int = 10, min_scale: float = 1.0, detect: float | None = 0.99) -> FilterFamily:
    r"""Les étapes du filtre à :math:`Q` adaptative pour le moteur (voir le module)."""
    if isinstance(window, bool) or not isinstance(window, (int, np.integer)) or window < 1:
        raise KalmanInputError(f"« window » doit être un entier ≥ 1 (nombre de pas moyennés) ; reçu {window!r}.")
    if isinstance(min_scale, bool) or not isinstance(min_scale, (int, float, np.floating, np.integer)) \
            or not np.isfinite(min_scale) or min_scale <= 0:
        raise KalmanInputError(f"« min_scale » doit être un nombre > 0 (plus petite échelle de Q) ; reçu {min_scale!r}.")
    W, s_min = int(window), float(min_scale)
    p_detect = gate_probability(detect) if detect is not None else None

    def prior(model, x0, P0):
        x, P = gaussian_prior(model, x0, P0)
        return AdaptiveState(x, P, s_min, (), ())

    def predict(model: LinearGaussianModel, state: AdaptiveState, u):
        x = model.A.dot(state.x)
        if u is not None:
            x = x + model.B.dot(u)
        P = symmetrize(model.A.dot(state.P).dot(model.A.T) + state.scale * model.Q)
        return state._replace(x=x, P=P)

    def update(model: LinearGaussianModel, state: AdaptiveState, y, idx):
        C, R = (model.C, model.R) if idx is None else (model.C[idx], model.R[np.ix_(idx, idx)])
        nu = y - C.dot(state.x)
        x, P, K, S = correct(state.x, state.P, nu, C, R)
        g = float(np.trace(C.dot(model.Q).dot(C.T)))
        d = float(nu.dot(nu) - np.trace(S) + state.scale * g)
        ds, gs = (state.d + (d,))[-W:], (state.g + (g,))[-W:]
        nis, dof = (state.nis + (nis_value(nu, S),))[-W:], (state.dof + (len(nu),))[-W:]
        total = sum(gs)
        if p_detect is not None and sum(nis) <= gate_threshold(p_detect, sum(dof)):
            scale = s_min  # innovations conformes au modèle (test du χ² sur la fenêtre) : Q nominale
        else:
            scale = max(s_min, sum(ds) / total) if total > 0 else state.scale
        return AdaptiveState(x, P, scale, ds, gs, nis, dof), Correction(K, nu, S)

    return FilterFamily(
        name="filtre de Kalman à Q adaptative",
        model_type=LinearGaussianModel,
        model_hint="le filtre adaptatif s'applique à un modèle linéaire gaussien",
        prior=prior,
        predict=predict,
        update=update,
        moments=lambda state: (state.x, state.P),
        result_type=AdaptiveResult,
        step_outputs=lambda state: {"q_scale": state.scale},
    )


def adaptive_kalman_filter(model: LinearGaussianModel, y: Any, x0: Any, P0: Any, u: Any = None, *,
                           window: int = 10, min_scale: float = 1.0, detect: float | None = 0.99) -> AdaptiveResult:
    r"""Filtre de Kalman dont le bruit d'état :math:`s_kQ` suit les innovations (ajustement de covariance
    sur ``window`` pas, échelle au moins ``min_scale``, seulement quand la somme des NIS de la fenêtre
    dépasse le quantile ``detect`` de sa loi du :math:`\chi^2` — ``None`` : toujours ; voir le module).

    Paramètres : comme :func:`~kalman_course.kalman_filter` (``model`` linéaire, éventuellement variable
    dans le temps ; ``y`` (T, m) avec ``NaN`` pour une mesure manquante ; ``x0`` (n,), ``P0`` (n, n)).
    Renvoie un :class:`AdaptiveResult` (``q_scale`` (T,) en plus).
    """
    return run_filter(adaptive_family(window, min_scale, detect), model, y, x0, P0, u)
