r"""Filtre de Kalman unscented (*unscented Kalman filter*, UKF) : points sigma, transformée unscented,
étapes pures et famille pour le moteur.

Points sigma de van der Merwe (Wan & van der Merwe, 2000), pour un état de dimension :math:`n`, de
moyenne :math:`\bar x` et de covariance :math:`P` :

.. math::

    \lambda = \alpha^2(n + \kappa) - n,\qquad
    \chi_0 = \bar x,\quad \chi_i = \bar x + s_i,\quad \chi_{n+i} = \bar x - s_i\quad (i = 1\dots n),

où :math:`s_i` est la **ligne** :math:`i` du facteur de Cholesky supérieur :math:`U` de
:math:`(n+\lambda)P` (:math:`U^TU = (n+\lambda)P`, comme ``MerweScaledSigmaPoints`` de filterpy), et les poids

.. math::

    W^m_0 = \frac{\lambda}{n+\lambda},\quad W^c_0 = W^m_0 + 1 - \alpha^2 + \beta,\quad
    W^m_i = W^c_i = \frac{1}{2(n+\lambda)}\ (i = 1\dots 2n).

Les poids :math:`W^m` somment à 1 ; :math:`W^m_0` est négatif dès que :math:`\alpha^2(n+\kappa) < n`.

Le filtre (bruits additifs) :

* prédiction : :math:`\chi^-_i = f(\chi_i, u)`, :math:`\hat x^- = \sum_i W^m_i\chi^-_i`,
  :math:`P^- = \sum_i W^c_i(\chi^-_i - \hat x^-)(\chi^-_i - \hat x^-)^T + Q` ;
* correction : **nouveaux** points sigma :math:`\tilde\chi_i` de :math:`(\hat x^-, P^-)` (ils tiennent
  compte de :math:`Q`), :math:`Z_i = h(\tilde\chi_i)`, :math:`\hat y = \sum_i W^m_i Z_i`,
  :math:`S = \sum_i W^c_i(Z_i - \hat y)(Z_i - \hat y)^T + R`,
  :math:`P_{xy} = \sum_i W^c_i(\tilde\chi_i - \hat x^-)(Z_i - \hat y)^T`, :math:`K = P_{xy}S^{-1}`,
  :math:`\hat x = \hat x^- + K(y - \hat y)`, :math:`P = P^- - KSK^T`.

C'est l'algorithme de ``filterpy.kalman.UnscentedKalmanFilter`` 2.0.0 (qui, lui aussi, retire des points
sigma de la loi prédite à la fin de ``predict``). Les composantes angulaires de la mesure
(``model.angle_indices``) ont une moyenne circulaire :math:`\operatorname{atan2}(\sum W^m\sin, \sum W^m\cos)`
et des écarts ramenés dans :math:`(-\pi, \pi]`.

**Tirages en lot** (:func:`unscented_kalman_filter_runs`) : les mêmes formules sur ``N`` tirages à la fois ;
les :math:`N(2n+1)` points sigma d'un pas passent par :math:`f` ou :math:`h` en **un** appel si le modèle
est vectorisé (:meth:`~kalman_course.NonlinearModel.transition_many`), un appel par point sinon.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, NamedTuple

import numpy as np

from ..core.models import NonlinearModel
from ..core.results import FilterResult, FilterRuns
from ..core.validation import (
    KalmanInputError,
    as_float_array,
    as_gaussian,
    call_user_function,
    check_finite_output,
    check_pd,
)
from .engine import FilterFamily, run_filter, run_filter_runs
from .gaussian import SymmetricSigmaRule, gaussian_family, sigma_moments

__all__ = [
    "UnscentedRule",
    "SigmaPoints",
    "UnscentedTransform",
    "sigma_weights",
    "sigma_points",
    "unscented_transform",
    "unscented_kalman_filter",
    "unscented_kalman_filter_runs",
    "unscented_family",
]

class SigmaPoints(NamedTuple):
    r"""Points sigma et poids : ``points`` (2n+1, n) — ligne 0 : :math:`\chi_0 = \bar x`, lignes 1…n :
    :math:`\bar x + s_i`, lignes n+1…2n : :math:`\bar x - s_i` ; ``Wm`` (2n+1,) poids de la moyenne ;
    ``Wc`` (2n+1,) poids de la covariance ; ``lam`` : :math:`\lambda`."""

    points: np.ndarray
    Wm: np.ndarray
    Wc: np.ndarray
    lam: float


class UnscentedTransform(NamedTuple):
    r"""Résultat de :func:`unscented_transform` : ``mean`` (m,) :math:`\sum W^m_i g(\chi_i)`,
    ``cov`` (m, m) :math:`\sum W^c_i (g(\chi_i) - \bar y)(g(\chi_i) - \bar y)^T`, ``cross`` (n, m)
    :math:`\sum W^c_i(\chi_i - \bar x)(g(\chi_i) - \bar y)^T`, ``points`` (2n+1, n) les points sigma,
    ``transformed`` (2n+1, m) leurs images, ``Wm``, ``Wc`` (2n+1,) les poids."""

    mean: np.ndarray
    cov: np.ndarray
    cross: np.ndarray
    points: np.ndarray
    transformed: np.ndarray
    Wm: np.ndarray
    Wc: np.ndarray


# --------------------------------------------------------------------------- paramètres et poids


def _check_parameters(n: int, alpha: Any, beta: Any, kappa: Any) -> tuple[float, float, float]:
    for name, value in (("alpha", alpha), ("kappa", kappa)):
        if value is None:  # le filtre et son lisseur n'ont pas de valeur par défaut pour α et κ
            raise KalmanInputError(
                f"« {name} » est obligatoire : le bon écartement des points sigma dépend du problème (chapitre UKF). "
                "Donnez alpha et kappa, par exemple alpha=1.0, kappa=0.0 (le filtre de Kalman sur un modèle "
                "linéaire), ou alpha=0.1, kappa=3 − n."
            )
    values = []
    for name, value in (("alpha", alpha), ("beta", beta), ("kappa", kappa)):
        if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
                or not np.isfinite(value):
            raise KalmanInputError(f"« {name} » doit être un nombre réel fini ; reçu {value!r}.")
        values.append(float(value))
    a, b, k = values
    if a <= 0:
        raise KalmanInputError(f"« alpha » doit être strictement positif (écartement des points sigma) ; reçu {alpha!r}.")
    if n + k <= 0:
        raise KalmanInputError(
            f"« kappa » doit vérifier n + kappa > 0 (ici n = {n}) : sinon n + λ = α²(n + κ) ≤ 0 et les points "
            f"sigma n'existent pas ; reçu kappa = {kappa!r}. Essayez kappa = 0 ou kappa = 3 − n."
        )
    return a, b, k


def sigma_weights(n: int, *, alpha: float, beta: float, kappa: float) -> tuple[np.ndarray, np.ndarray, float]:
    r"""Poids :math:`W^m`, :math:`W^c` (2n+1,) et :math:`\lambda = \alpha^2(n+\kappa) - n` des points
    sigma de van der Merwe (voir l'en-tête du module)."""
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise KalmanInputError(f"« n » doit être un entier ≥ 1 (dimension de l'état) ; reçu {n!r}.")
    return _weights(int(n), *_check_parameters(int(n), alpha, beta, kappa))


def _weights(n: int, alpha: float, beta: float, kappa: float) -> tuple[np.ndarray, np.ndarray, float]:
    lam = alpha**2 * (n + kappa) - n
    c = 0.5 / (n + lam)
    Wm = np.full(2 * n + 1, c)
    Wc = np.full(2 * n + 1, c)
    Wm[0] = lam / (n + lam)
    Wc[0] = lam / (n + lam) + (1.0 - alpha**2 + beta)
    return Wm, Wc, lam


def sigma_points(mean: Any, cov: Any, *, alpha: float, beta: float = 2.0, kappa: float = 0.0) -> SigmaPoints:
    r"""Les :math:`2n+1` points sigma de van der Merwe de la loi :math:`(\bar x, P)` et leurs poids.

    ``mean`` (n,), ``cov`` (n, n) symétrique définie positive. Ces points ont exactement la moyenne
    :math:`\sum W^m_i\chi_i = \bar x` et la covariance :math:`\sum W^c_i(\chi_i - \bar x)(\chi_i - \bar x)^T = P`
    (le terme :math:`1 - \alpha^2 + \beta` de :math:`W^c_0` multiplie un écart nul).
    """
    x = as_float_array("mean", mean)
    if x.ndim == 0:
        x = x.reshape(1)
    if x.ndim != 1:
        raise KalmanInputError(f"« mean » doit être un vecteur (n,) ; reçu la forme {x.shape}.")
    n = x.shape[0]
    x, P = as_gaussian(x, cov, n, "mean", "cov")
    P = check_pd("cov", P)
    a, b, k = _check_parameters(n, alpha, beta, kappa)
    rule = UnscentedRule(a, b, k)
    Wm, Wc = rule.weights(n)
    return SigmaPoints(rule.points(x, P, "points sigma", "« cov »"), Wm, Wc, rule.scale(n) - n)


def unscented_transform(
    mean: Any,
    cov: Any,
    fn: Callable[[np.ndarray], Any],
    *,
    alpha: float,
    beta: float = 2.0,
    kappa: float = 0.0,
    vectorized: bool = False,
    angle_indices: tuple[int, ...] = (),
) -> UnscentedTransform:
    r"""Transformée unscented de la loi :math:`(\bar x, P)` par la fonction ``fn`` :

    .. math::

        \bar y = \sum_i W^m_i\, g(\chi_i),\qquad
        P_y = \sum_i W^c_i\,(g(\chi_i) - \bar y)(g(\chi_i) - \bar y)^T,\qquad
        P_{xy} = \sum_i W^c_i\,(\chi_i - \bar x)(g(\chi_i) - \bar y)^T .

    ``fn(x)`` : (n,) → (m,) ; avec ``vectorized=True``, ``fn`` reçoit tous les points d'un coup,
    (2n+1, n) → (2n+1, m). ``angle_indices`` : composantes de la sortie qui sont des angles (moyenne
    circulaire, écarts ramenés dans :math:`(-\pi, \pi]`). Exacte (moyenne et covariance) pour ``fn`` affine.
    Renvoie :class:`UnscentedTransform` (avec les points sigma et leurs images, pour les figures).
    """
    sp = sigma_points(mean, cov, alpha=alpha, beta=beta, kappa=kappa)
    if not callable(fn):
        raise KalmanInputError(f"« fn » doit être une fonction ; reçu {type(fn).__name__}.")
    if vectorized:
        Y = np.asarray(call_user_function("fn", fn, sp.points), dtype=float)
        if Y.ndim == 1:
            Y = Y.reshape(-1, 1)
        if Y.ndim != 2 or Y.shape[0] != sp.points.shape[0]:
            raise KalmanInputError(
                f"« fn » vectorisée doit renvoyer une ligne par point sigma, forme ({sp.points.shape[0]}, m) ; "
                f"elle a renvoyé la forme {Y.shape}."
            )
    else:
        rows = [np.atleast_1d(np.asarray(call_user_function("fn", fn, p), dtype=float)) for p in sp.points]
        if any(r.ndim != 1 or r.shape != rows[0].shape for r in rows):
            raise KalmanInputError("« fn » doit renvoyer un vecteur (m,) de même taille pour chaque point.")
        Y = np.array(rows)
    for i in range(Y.shape[0]):
        check_finite_output("fn", Y[i], sp.points[i])
    angles = [int(i) for i in angle_indices]
    y_mean, cov_y, cross = sigma_moments(sp.points, Y, sp.points[0], sp.Wm, sp.Wc, angles)
    return UnscentedTransform(y_mean, cov_y, cross, sp.points, Y, sp.Wm, sp.Wc)


# --------------------------------------------------------------------------- famille et boucle


@dataclass(frozen=True)
class UnscentedRule(SymmetricSigmaRule):
    r"""La **transformée unscented** comme règle du filtre gaussien (l'UKF) : les :math:`2n + 1` points
    sigma de van der Merwe, :math:`c = n + \lambda = \alpha^2(n + \kappa)`, et leurs poids (voir
    l'en-tête du module). Exacte pour :math:`g` affine ; avec :math:`\alpha = 1, \beta = 0, \kappa = 0`,
    :math:`W_0 = 0` et c'est la règle de cubature (:class:`~kalman_course.filters.cubature.CubatureRule`)."""

    alpha: float
    beta: float = 2.0
    kappa: float = 0.0

    label = "UKF"
    filter_name = "filtre de Kalman unscented (UKF)"
    point_name = "sigma"

    def check(self, model: NonlinearModel) -> None:
        super().check(model)
        _check_parameters(model.n_state, self.alpha, self.beta, self.kappa)

    def scale(self, n: int) -> float:
        return n + (self.alpha**2 * (n + self.kappa) - n)  # n + λ, calculé comme filterpy

    def weights(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        Wm, Wc, _ = _weights(n, self.alpha, self.beta, self.kappa)
        return Wm, Wc

    def advice(self) -> str:
        return "Essayez un α plus grand (poids W₀ moins négatifs), κ ≥ 0, ou augmentez Q ou P0."

    def innovation_message(self) -> str:
        return ("UKF : la covariance d'innovation S n'est pas définie positive (des poids W^c négatifs peuvent la "
                "rendre indéfinie) : essayez un α plus grand ou κ ≥ 0.")


def unscented_family(alpha: float, beta: float = 2.0, kappa: float = 0.0) -> FilterFamily:
    r"""Les étapes de l'UKF pour le moteur : celles du filtre gaussien
    (:func:`~kalman_course.filters.gaussian.gaussian_family`) avec la règle :class:`UnscentedRule` (points
    redessinés à la correction)."""
    return gaussian_family(UnscentedRule(alpha, beta, kappa))


def unscented_kalman_filter(
    model: NonlinearModel,
    y: Any,
    x0: Any,
    P0: Any,
    u: Any = None,
    *,
    alpha: float | None = None,
    beta: float = 2.0,
    kappa: float | None = None,
    gate: Any = None,
    fading: Any = None,
) -> FilterResult:
    r"""Filtre de Kalman unscented sur toutes les mesures (pour chaque ``y[k]`` : prédiction puis
    correction, dans l'ordre de :func:`~kalman_course.kalman_filter`).

    Paramètres
    ----------
    model : NonlinearModel à bruits additifs (``vectorized=True`` : les :math:`2n+1` points passent par
        ``f`` et ``h`` en un appel).
    y : (T, m), ou (T,) si m = 1 — ``NaN`` : composante manquante (ligne entière : prédiction seule ;
        ligne partielle : correction avec les seules composantes observées).
    x0 : (n,) ; P0 : (n, n) symétrique **définie** positive (les points sigma en prennent une racine).
    u : (T, p), ou (T,) si p = 1, optionnel — commandes (``u[k]``, qui contient :math:`u_{k-1}`, sert à prédire vers ``y[k]``).
    alpha, beta, kappa : paramètres des points sigma de van der Merwe (sans valeur par défaut pour
        ``alpha`` et ``kappa`` : le bon choix dépend du problème ; :math:`\beta = 2` est optimal pour une
        loi gaussienne). :math:`\alpha = 1, \beta = 2, \kappa = 0` redonne exactement le filtre de Kalman
        sur un modèle linéaire.
    gate, fading : porte et mémoire évanescente, options du moteur (:mod:`~kalman_course.filters.gating`),
        comme pour :func:`~kalman_course.kalman_filter`.

    Renvoie un :class:`~kalman_course.FilterResult` (``x``, ``P``, ``x_pred``, ``P_pred``, ``K``,
    ``innovation`` :math:`y - \hat y`, ``S``). Une covariance qui cesse d'être définie positive lève une
    :class:`~kalman_course.KalmanInputError` qui nomme l'étape et la mesure.
    """
    return run_filter(unscented_family(alpha, beta, kappa), model, y, x0, P0, u, gate=gate, fading=fading)


def unscented_kalman_filter_runs(
    model: NonlinearModel,
    Y: Any,
    x0: Any,
    P0: Any,
    u: Any = None,
    *,
    alpha: float | None = None,
    beta: float = 2.0,
    kappa: float | None = None,
) -> FilterRuns:
    r"""Filtre de Kalman unscented sur ``N`` tirages indépendants du même modèle, tous à la fois
    (:func:`~kalman_course.filters.engine.run_filter_runs`) : les formules de :func:`unscented_kalman_filter`
    appliquées à la pile des tirages ; les :math:`N(2n+1)` points sigma d'un pas passent par :math:`f` (ou
    :math:`h`) en un appel si le modèle est vectorisé.

    Paramètres : ``Y`` (N, T, m) (ou (N, T) si m = 1 ; ``NaN`` : composante manquante, tirage par tirage),
    ``x0`` (n,) ou (N, n), ``P0`` (n, n) ou (N, n, n) définie(s) positive(s), ``u`` (T, p) commune ;
    ``alpha``, ``beta``, ``kappa`` comme :func:`unscented_kalman_filter`.

    Renvoie un :class:`~kalman_course.FilterRuns` (``x`` (N, T, n), ``P`` (N, T, n, n)…) ;
    ``result.run(i)`` est égal à ``unscented_kalman_filter(model, Y[i], …)`` aux arrondis près. Une
    covariance qui cesse d'être définie positive lève une :class:`~kalman_course.KalmanInputError` qui
    nomme le tirage, l'étape et la mesure.
    """
    return run_filter_runs(unscented_family(alpha, beta, kappa), model, Y, x0, P0, u)
