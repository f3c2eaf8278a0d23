r"""Le filtre gaussien : une seule étape, dont les moments viennent d'une **règle d'intégration**.

Särkkä et Svensson (2023, ch. 8–9) : l'EKF, l'UKF, le filtre de Kalman à cubature (CKF) et le filtre de
Gauss–Hermite (GHKF) sont **un seul filtre**. Chacun suppose la loi de l'état gaussienne,
:math:`x \sim \mathcal N(\hat x, P)`, et ne diffère des autres que par la façon de calculer trois
intégrales gaussiennes d'une fonction :math:`g` (:math:`f` à la prédiction, :math:`h` à la correction) :

.. math::

    \mu = \mathbb E[g(x)],\qquad
    \Sigma = \operatorname{Cov}[g(x)],\qquad
    C = \operatorname{Cov}[x, g(x)] .

L'étape (bruits additifs ; l'EKF accepte aussi :math:`WQW^T`, :math:`VRV^T`) :

* prédiction : :math:`(\mu, \Sigma, C)` de :math:`f`, puis :math:`\hat x^- = \mu`,
  :math:`P^- = \Sigma + Q` ;
* correction : :math:`(\hat y, \Sigma_y, P_{xy})` de :math:`h` sous :math:`\mathcal N(\hat x^-, P^-)`,
  :math:`S = \Sigma_y + R`, :math:`K = P_{xy}S^{-1}` (résolution de Cholesky, jamais d'inverse),
  :math:`\hat x = \hat x^- + K(y - \hat y)`, :math:`P = P^- - KP_{xy}^T` (:math:`= P^- - KSK^T`) ;
  ``joseph=True`` : :math:`P = P^- - KP_{xy}^T - P_{xy}K^T + KSK^T`, la forme de Joseph écrite avec
  la covariance croisée (pour la linéarisation, c'est exactement :math:`(I-KH)P^-(I-KH)^T + KRK^T`).

Les règles (une :class:`GaussianRule` chacune) :

* **linéarisation** (EKF, :mod:`~kalman_course.filters.extended`) : :math:`\mu = g(\hat x)`,
  :math:`\Sigma = GPG^T`, :math:`C = PG^T`, :math:`G = \partial g/\partial x\,(\hat x)` ;
* **points sigma** (:class:`SigmaPointRule`) : des points :math:`\chi_i = \hat x + L\xi_i`
  (:math:`LL^T = P`) et des poids :math:`W^m_i`, :math:`W^c_i`,

  .. math::

      \mu = \sum_i W^m_i g(\chi_i),\quad
      \Sigma = \sum_i W^c_i (g(\chi_i) - \mu)(g(\chi_i) - \mu)^T,\quad
      C = \sum_i W^c_i (\chi_i - \hat x)(g(\chi_i) - \mu)^T ;

  transformée unscented (UKF, :mod:`~kalman_course.filters.unscented`), cubature sphérique–radiale
  (CKF, :mod:`~kalman_course.filters.cubature`), Gauss–Hermite en produit tensoriel (GHKF,
  :mod:`~kalman_course.filters.gauss_hermite`).

**Sommes centrées.** La moyenne pondérée est calculée en écarts au premier point,
:math:`\mu = g(\chi_0) + \sum_i W^m_i\,(g(\chi_i) - g(\chi_0))` (les :math:`W^m` somment à 1) : avec un
petit :math:`\alpha`, :math:`W^m_0 \approx 1 - 1/\alpha^2` est très négatif, et la somme directe
:math:`\sum_i W^m_i g(\chi_i)` d'un état loin de zéro (:math:`10^6`) perdait tous ses chiffres dans la
différence de termes de l'ordre de :math:`10^{12}`.

**Points redessinés ou non.** ``redraw=True`` (UKF de filterpy, défaut) : la correction tire de
nouveaux points de :math:`(\hat x^-, P^-)`, qui tiennent compte de :math:`Q`. ``redraw=False``
(``CubatureKalmanFilter`` de filterpy) : elle réutilise les points propagés :math:`f(\chi_i)` de la
prédiction (moins coûteux, mais aveugle à :math:`Q` : sur un modèle linéaire ce n'est plus le filtre de
Kalman).

**Tirages en lot** : les mêmes étapes sur ``N`` tirages (axe des tirages en tête), par
:func:`~kalman_course.filters.engine.run_filter_runs`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any, NamedTuple

import numpy as np
import scipy.linalg

from ..core.angles import wrap_angle
from ..core.linalg import psd_solve, symmetrize
from ..core.models import NonlinearModel
from ..core.results import FilterResult, FilterRuns
from ..core.validation import (
    KalmanInputError,
    as_gaussian,
    as_vector,
    check_control_allowed,
    check_instance,
    check_pd,
    number_text,
)
from .engine import Correction, FilterFamily, gaussian_prior_many, run_filter, run_filter_runs

__all__ = [
    "NONLINEAR_HINT",
    "Moments",
    "GaussianRule",
    "SigmaPointRule",
    "SymmetricSigmaRule",
    "GaussianState",
    "gaussian_family",
    "gaussian_filter",
    "gaussian_filter_runs",
    "gaussian_predict",
    "gaussian_update",
    "predict_gaussian",
    "correct_gaussian",
    "sigma_moments",
    "process_noises",
    "where_text",
    "measurement_noises",
    "residuals",
]

#: Piste donnée quand un filtre non linéaire reçoit un modèle linéaire.
NONLINEAR_HINT = "pour un modèle linéaire, utilisez kalman_filter ou NonlinearModel.from_linear"

class Moments(NamedTuple):
    r"""Les intégrales gaussiennes d'une fonction :math:`g` sous :math:`\mathcal N(\hat x, P)`, données par
    une règle : ``mean`` (m,) :math:`\mu \approx \mathbb E[g(x)]`, ``cov`` (m, m)
    :math:`\Sigma \approx \operatorname{Cov}[g(x)]` (sans bruit), ``cross`` (n, m)
    :math:`C \approx \operatorname{Cov}[x, g(x)]` ; pour une règle à points, ``points`` (N, n) les points
    :math:`\chi_i` et ``images`` (N, m) les :math:`g(\chi_i)` (``None`` pour la linéarisation). En lot, un
    axe des tirages en tête."""

    mean: np.ndarray
    cov: np.ndarray
    cross: np.ndarray
    points: np.ndarray | None = None
    images: np.ndarray | None = None


class GaussianState(NamedTuple):
    r"""État interne du filtre gaussien pour le moteur : :math:`(\hat x, P)`, ``k`` l'indice de la mesure
    visée (pour nommer le pas dans un message) et, après une prédiction sans nouveaux points
    (``redraw=False``), les points propagés :math:`f(\chi_i)` (N, n) que la correction réutilise. Les étapes
    de :func:`gaussian_family` en passent un tuple simple de même forme (moins coûteux à chaque pas)."""

    x: np.ndarray
    P: np.ndarray
    k: int
    points: np.ndarray | None = None


# --------------------------------------------------------------------------- évaluations communes


def where_text(where: Any) -> str:
    """Le pas nommé dans un message : ``where`` est un texte, ou un couple ``(action, k)`` mis en forme
    seulement quand une erreur est levée (« correction par y[12] ») — la boucle chaude ne formate rien."""
    if isinstance(where, tuple):
        action, k = where
        return f"{action} y[{k}]"
    return str(where)



def process_noises(model: NonlinearModel, X: np.ndarray, u: np.ndarray | None = None) -> np.ndarray:
    r""":math:`W_iQW_i^T` en chaque ligne de ``X`` (N, n) : (N, n, n), ou :math:`Q` (n, n) si le bruit est
    additif ou :math:`W` constante."""
    if model.f_noise_jacobian is None or not callable(model.f_noise_jacobian):
        return model.process_noise(X[0], u)
    return np.array([model.process_noise(x, u) for x in X])


def measurement_noises(model: NonlinearModel, X: np.ndarray, idx: np.ndarray | None = None) -> np.ndarray:
    r""":math:`V_iRV_i^T` en chaque ligne de ``X`` (N, n), restreinte aux composantes ``idx`` : (N, m, m),
    ou :math:`R` (m, m) si le bruit est additif ou :math:`V` constante."""
    if model.h_noise_jacobian is None or not callable(model.h_noise_jacobian):
        R = model.measurement_noise(X[0])
    else:
        R = np.array([model.measurement_noise(x) for x in X])
    return R if idx is None else R[..., idx[:, None], idx]


def observed_angles(model: NonlinearModel, idx: np.ndarray | None) -> list[int]:
    """Positions, parmi les composantes observées ``idx`` (``None`` : toutes), des composantes angulaires
    de la mesure (:meth:`NonlinearModel.observed_angles`)."""
    return model.observed_angles(idx)


def residuals(model: NonlinearModel, Y: np.ndarray, Y_hat: np.ndarray, idx: np.ndarray | None = None) -> np.ndarray:
    r"""Résidus :math:`y_i - \hat y_i` d'une pile (N, m_k), composantes angulaires ramenées dans
    :math:`(-\pi, \pi]` (``idx`` : composantes observées, comme :meth:`NonlinearModel.residual`)."""
    d = np.asarray(Y - Y_hat, dtype=float)
    angles = observed_angles(model, idx)
    if angles:
        d[..., angles] = wrap_angle(d[..., angles])
    return d


# --------------------------------------------------------------------------- sommes pondérées


def weighted_mean(Z: np.ndarray, Wm: np.ndarray, angles: list[int] | tuple = ()) -> np.ndarray:
    r"""Moyenne pondérée des images ``Z`` (…, N, m) (points sur l'avant-dernier axe), **centrée sur le
    premier point** : :math:`Z_0 + \sum_i W^m_i (Z_i - Z_0)` (les :math:`W^m` somment à 1). Composantes
    angulaires ``angles`` : moyenne circulaire :math:`\operatorname{atan2}(\sum W^m\sin, \sum W^m\cos)`."""
    if Z.ndim == 2:  # un seul état (la boucle chaude des filtres) : sans diffusion générale
        z = Z[0] + Wm.dot(Z - Z[0])
    else:
        Z0 = Z[..., :1, :]
        z = Z0[..., 0, :] + Wm @ (Z - Z0)
    if angles:
        angles = list(angles)
        z[..., angles] = np.arctan2(Wm @ np.sin(Z[..., angles]), Wm @ np.cos(Z[..., angles]))
    return z


def sigma_moments(X: np.ndarray, Z: np.ndarray, x: np.ndarray, Wm: np.ndarray, Wc: np.ndarray,
                  angles: list[int] | tuple = ()) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""Moyenne, covariance et covariance croisée pondérées de points ``X`` (…, N, n) centrés en ``x``
    (…, n) et de leurs images ``Z`` (…, N, m) :

    .. math::

        \mu = \sum_i W^m_i Z_i,\quad \Sigma = \sum_i W^c_i (Z_i - \mu)(Z_i - \mu)^T,\quad
        C = \sum_i W^c_i (X_i - x)(Z_i - \mu)^T

    (moyenne centrée sur le premier point, angles : moyenne circulaire et écarts ramenés dans
    :math:`(-\pi, \pi]`). Renvoie ``(mu (…, m), Sigma (…, m, m), C (…, n, m))``."""
    z = weighted_mean(Z, Wm, angles)
    if Z.ndim == 2:
        dZ = Z - z
        if angles:
            dZ[:, list(angles)] = wrap_angle(dZ[:, list(angles)])
        WdZ = Wc[:, None] * dZ
        return z, dZ.T.dot(WdZ), (X - x).T.dot(WdZ)
    dZ = Z - z[..., None, :]
    if angles:
        angles = list(angles)
        dZ[..., angles] = wrap_angle(dZ[..., angles])
    WdZ = Wc[:, None] * dZ
    dX = X - x[..., None, :]
    return z, np.swapaxes(dZ, -1, -2) @ WdZ, np.swapaxes(dX, -1, -2) @ WdZ


# --------------------------------------------------------------------------- règles


class GaussianRule:
    r"""Une règle d'intégration gaussienne : elle donne les :class:`Moments` de :math:`f` et de :math:`h`
    sous :math:`\mathcal N(\hat x, P)`, pour un état ou pour une pile de ``N`` tirages.

    Attributs : ``label`` (sigle du filtre, dans les messages : « EKF », « UKF »…), ``filter_name``
    (nom français du filtre), ``definite`` (les covariances doivent être définies positives : une racine
    de Cholesky en est prise), ``additive_only`` (bruits additifs seulement)."""

    label: str = "filtre gaussien"
    filter_name: str = "filtre gaussien"
    definite: bool = False
    additive_only: bool = False

    def check(self, model: NonlinearModel) -> None:
        """Vérifie que la règle s'applique à ``model`` (paramètres, bruits) ; lève une
        :class:`KalmanInputError` française sinon."""
        if self.additive_only and (model.f_noise_jacobian is not None or model.h_noise_jacobian is not None):
            raise KalmanInputError(
                f"Le {self.label} du paquet suppose des bruits additifs : le modèle ne doit avoir ni "
                "f_noise_jacobian ni h_noise_jacobian (pour un bruit non additif, ajoutez le bruit à l'état : "
                "état augmenté)."
            )

    def innovation_message(self) -> str:
        """Message quand :math:`S` n'est pas définie positive (le pas est ajouté à la fin, entre parenthèses)."""
        return (f"{self.label} : la covariance d'innovation S n'est pas définie positive : vérifiez les ordres de "
                "grandeur de P0, Q et R.")

    def innovation_error(self, where: str) -> str:
        """Message quand :math:`S` n'est pas définie positive au pas ``where``."""
        return f"{self.innovation_message()[:-1]} ({where_text(where)})."

    def transition(self, model, x, P, u, where: str) -> Moments:  # pragma: no cover - interface
        raise NotImplementedError

    def observation(self, model, x, P, idx, where: str, points=None) -> Moments:  # pragma: no cover
        raise NotImplementedError

    def transition_many(self, model, X, P, u, where: str) -> Moments:  # pragma: no cover
        raise NotImplementedError

    def observation_many(self, model, X, P, idx, where: str, points=None) -> Moments:  # pragma: no cover
        raise NotImplementedError


@dataclass(frozen=True)
class SigmaPointRule(GaussianRule):
    r"""Règle à points pondérés : :math:`\chi_i = \hat x + L\xi_i` avec :math:`LL^T = P` (Cholesky), des
    points unités :math:`\xi_i` et des poids :math:`W^m_i, W^c_i` fixés par la règle (:meth:`unit`).

    Une sous-classe donne :meth:`unit` ; les moments (:func:`sigma_moments`), la propagation et le mode en
    lot sont communs."""

    definite = True
    additive_only = True

    def build_unit(self, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover - interface
        r"""Points unités :math:`\xi` (N, n) et poids :math:`W^m`, :math:`W^c` (N,) pour la dimension ``n``."""
        raise NotImplementedError

    def unit(self, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        r"""Points unités :math:`\xi` (N, n) et poids :math:`W^m`, :math:`W^c` (N,) (calculés une fois par
        règle et par dimension, en lecture seule)."""
        return _unit(self, int(n))

    def n_points(self, n: int) -> int:
        """Nombre de points (d'évaluations de :math:`f` ou de :math:`h`) par étape, en dimension ``n``."""
        return self.unit(n)[0].shape[0]

    def advice(self) -> str:
        """Conseil donné quand une covariance cesse d'être définie positive."""
        return "Augmentez Q ou P0."

    def _factor_error(self, P: np.ndarray, where: str, what: str) -> KalmanInputError:
        lam_min = float(scipy.linalg.eigvalsh(P)[0])
        return KalmanInputError(
            f"{self.label}, {where_text(where)} : la covariance {what} n'est plus définie positive (plus petite valeur "
            f"propre {number_text(lam_min, '.3g')}) : la factorisation de Cholesky des points {self.point_name} "
            f"échoue. {self.advice()}"
        )

    point_name = "d'intégration"

    def points(self, x: np.ndarray, P: np.ndarray, where: str, what: str) -> np.ndarray:
        r"""Les points :math:`\chi_i = \hat x + L\xi_i` (N, n) de :math:`(\hat x, P)`."""
        try:
            L = scipy.linalg.cholesky(P, lower=True, check_finite=False)
        except np.linalg.LinAlgError:
            raise self._factor_error(P, where, what) from None
        xi, _, _ = self.unit(x.shape[0])
        return x + xi @ L.T

    def points_many(self, X: np.ndarray, P: np.ndarray, where: str, what: str) -> np.ndarray:
        r"""Les points de ``N`` tirages (N, N_points, n) : ``X`` (N, n), ``P`` (N, n, n)."""
        try:
            L = np.linalg.cholesky(P)
        except np.linalg.LinAlgError:
            for i in range(P.shape[0]):
                self.points(X[i], P[i], f"tirage {i}, {where_text(where)}", what)  # lève l'erreur du premier tirage fautif
            raise self._factor_error(P[0], where, what) from None
        xi, _, _ = self.unit(X.shape[1])
        return X[:, None, :] + xi @ np.swapaxes(L, -1, -2)

    # ------------------------------------------------------------------ moments

    def transition(self, model, x, P, u, where):
        X = self.points(x, P, where, "a posteriori P")
        _, Wm, Wc = self.unit(x.shape[0])
        Xf = model.transition_many(X, u)
        return Moments(*sigma_moments(X, Xf, x, Wm, Wc), X, Xf)

    def observation(self, model, x, P, idx, where, points=None):
        X = self.points(x, P, where, "prédite P⁻") if points is None else points
        _, Wm, Wc = self.unit(x.shape[0])
        Z = model.observe_many(X)
        if idx is not None:
            Z = Z[:, idx]
        return Moments(*sigma_moments(X, Z, x, Wm, Wc, observed_angles(model, idx)), X, Z)

    def transition_many(self, model, X, P, u, where):
        N, n = X.shape
        pts = self.points_many(X, P, where, "a posteriori P")
        _, Wm, Wc = self.unit(n)
        Xf = model.transition_many(pts.reshape(-1, n), u).reshape(pts.shape)
        return Moments(*sigma_moments(pts, Xf, X, Wm, Wc), pts, Xf)

    def observation_many(self, model, X, P, idx, where, points=None):
        N, n = X.shape
        pts = self.points_many(X, P, where, "prédite P⁻") if points is None else points
        _, Wm, Wc = self.unit(n)
        Z = model.observe_many(pts.reshape(-1, n)).reshape(N, pts.shape[1], model.n_obs)
        if idx is not None:
            Z = Z[..., idx]
        return Moments(*sigma_moments(pts, Z, X, Wm, Wc, observed_angles(model, idx)), pts, Z)


@dataclass(frozen=True)
class SymmetricSigmaRule(SigmaPointRule):
    r"""Règle symétrique à :math:`2n` (ou :math:`2n + 1`) points : :math:`\hat x \pm s_i`, où :math:`s_i`
    est la **ligne** :math:`i` du facteur de Cholesky supérieur :math:`U` de :math:`cP`
    (:math:`U^TU = cP`, la convention de filterpy), précédés de :math:`\chi_0 = \hat x` si la règle a un
    point central. Une sous-classe donne :meth:`scale` (:math:`c`), :meth:`weights` et ``central``.

    Les points sont **exactement symétriques** : :math:`\chi_i = \mathrm{fl}(\hat x + s_i)`, puis
    :math:`d_i = \chi_i - \hat x` (exact) et :math:`\chi_{n+i} = \hat x - d_i` (exact) ; leur moyenne
    pondérée est donc exactement :math:`\hat x`, même loin de zéro (:math:`\hat x \approx 10^6`), où
    :math:`\hat x + s_i` est arrondi."""

    central = True

    def scale(self, n: int) -> float:  # pragma: no cover - interface
        raise NotImplementedError

    def weights(self, n: int) -> tuple[np.ndarray, np.ndarray]:  # pragma: no cover - interface
        raise NotImplementedError

    def build_unit(self, n):
        c = np.sqrt(self.scale(n))
        xi = np.vstack([np.zeros((1, n))] * self.central + [c * np.eye(n), -c * np.eye(n)])
        return (xi, *self.weights(n))

    def points(self, x, P, where, what):
        n = x.shape[0]
        try:
            U = scipy.linalg.cholesky(self.scale(n) * P, lower=False, check_finite=False)
        except np.linalg.LinAlgError:
            raise self._factor_error(P, where, what) from None
        c = int(self.central)
        out = np.empty((2 * n + c, n))
        if c:
            out[0] = x
        plus = out[c:c + n]
        np.add(x, U, out=plus)
        np.subtract(x, plus - x, out=out[c + n:])  # x − d exact : points exactement symétriques
        return out

    def points_many(self, X, P, where, what):
        try:
            L = np.linalg.cholesky(self.scale(X.shape[1]) * P)
        except np.linalg.LinAlgError:
            for i in range(P.shape[0]):
                self.points(X[i], P[i], f"tirage {i}, {where_text(where)}", what)
            raise self._factor_error(P[0], where, what) from None
        Xc = X[:, None, :]
        plus = Xc + np.swapaxes(L, -1, -2)
        D = plus - Xc
        return np.concatenate([Xc] * self.central + [plus, Xc - D], axis=1)


@lru_cache(maxsize=64)
def _unit(rule: SigmaPointRule, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    arrays = tuple(np.array(a, dtype=float) for a in rule.build_unit(n))
    for a in arrays:
        a.setflags(write=False)
    return arrays


# --------------------------------------------------------------------------- étapes


def predict_gaussian(rule: GaussianRule, model: NonlinearModel, x: np.ndarray, P: np.ndarray,
                     u: np.ndarray | None, where: str = "prédiction") -> tuple[np.ndarray, np.ndarray, Moments]:
    r"""Prédiction du filtre gaussien (noyau, sans vérification) : :math:`\hat x^- = \mu`,
    :math:`P^- = \Sigma + WQW^T` pour les moments :math:`(\mu, \Sigma, C)` de :math:`f` donnés par
    ``rule``. Renvoie ``(x_pred (n,), P_pred (n, n), moments)`` (la covariance croisée
    :math:`C = \operatorname{Cov}[x, f(x)]` des moments sert au lisseur)."""
    mom = rule.transition(model, x, P, u, where)
    return mom.mean, symmetrize(mom.cov + model.process_noise(x, u)), mom


def correct_gaussian(rule: GaussianRule, model: NonlinearModel, x_pred: np.ndarray, P_pred: np.ndarray,
                     y: np.ndarray, idx: np.ndarray | None, joseph: bool = False, where: str = "correction",
                     points: np.ndarray | None = None):
    r"""Correction du filtre gaussien (noyau, sans vérification) : moments :math:`(\hat y, \Sigma_y, P_{xy})`
    de :math:`h` sous :math:`\mathcal N(\hat x^-, P^-)` (ou sur les points propagés ``points``),
    :math:`S = \Sigma_y + VRV^T`, :math:`K = P_{xy}S^{-1}`, :math:`\hat x = \hat x^- + K\nu`,
    :math:`P = P^- - KP_{xy}^T` (ou la forme de Joseph). ``y`` ne contient que les composantes observées
    ``idx`` (``None`` : toutes). Renvoie ``(x, P, K, nu, S)``."""
    mom = rule.observation(model, x_pred, P_pred, idx, where, points)
    R = model.measurement_noise(x_pred)
    if idx is not None:
        R = R[np.ix_(idx, idx)]
    C = mom.cross
    S = mom.cov + R
    K = psd_solve(S, C.T, message=rule.innovation_error(where)).T
    nu = model.residual(y, mom.mean, idx)
    x = x_pred + K.dot(nu)
    KCt = K.dot(C.T)
    if joseph:
        P = P_pred - KCt - KCt.T + K.dot(S).dot(K.T)
    else:
        P = P_pred - KCt
    return x, symmetrize(P), K, nu, S


def predict_gaussian_many(rule, model, X, P, u, where):
    mom = rule.transition_many(model, X, P, u, where)
    return mom.mean, symmetrize(mom.cov + process_noises(model, X, u)), mom


def correct_gaussian_many(rule, model, X_pred, P_pred, Y, idx, joseph, where, points=None):
    mom = rule.observation_many(model, X_pred, P_pred, idx, where, points)
    R = measurement_noises(model, X_pred, idx)
    C = mom.cross
    Ct = np.swapaxes(C, -1, -2)
    S = mom.cov + R
    K = np.swapaxes(psd_solve(S, Ct, message=rule.innovation_message(), where=where_text(where)), -1, -2)
    nu = residuals(model, Y, mom.mean, idx)
    X = X_pred + (K @ nu[..., None])[..., 0]
    KCt = K @ Ct
    if joseph:
        P = P_pred - KCt - np.swapaxes(KCt, -1, -2) + K @ S @ np.swapaxes(K, -1, -2)
    else:
        P = P_pred - KCt
    return X, symmetrize(P), K, nu, S


def gaussian_family(rule: GaussianRule, *, joseph: bool = False, redraw: bool = True,
                    name: str | None = None) -> FilterFamily:
    r"""Les étapes du filtre gaussien de règle ``rule`` pour le moteur
    (:func:`~kalman_course.filters.engine.run_filter`, :func:`~kalman_course.filters.engine.run_filter_runs`).

    État interne :class:`GaussianState` ; en lot, ``(X (N, n), P (N, n, n))`` et, si ``redraw=False``,
    les points propagés (N, N_points, n). ``name`` : nom du filtre dans les messages (``rule.filter_name``
    par défaut)."""
    if not isinstance(joseph, (bool, np.bool_)):
        raise KalmanInputError(f"« joseph » doit être un booléen (True ou False) ; reçu {joseph!r}.")
    if not isinstance(redraw, (bool, np.bool_)):
        raise KalmanInputError(f"« redraw » doit être un booléen (True ou False) ; reçu {redraw!r}.")
    keep = not redraw and isinstance(rule, SigmaPointRule)

    def prior(model, x0, P0):
        rule.check(model)
        x, P = as_gaussian(x0, P0, model.n_state, "x0", "P0")
        if rule.definite:
            P = check_pd("P0", P)  # les points demandent une racine de Cholesky de P0
        return (x, P, -1, None)

    def predict_step(model, state, u):
        x, P, k, _ = state
        x_pred, P_pred, mom = predict_gaussian(rule, model, x, P, u, ("prédiction vers", k + 1))
        return (x_pred, P_pred, k + 1, mom.images if keep else None)  # un GaussianState, en tuple simple

    def update_step(model, state, y, idx):
        x_pred, P_pred, k, points = state
        x, P, K, nu, S = correct_gaussian(rule, model, x_pred, P_pred, y, idx, joseph, ("correction par", k), points)
        return (x, P, k, None), Correction(K, nu, S)

    def prior_many(model, x0, P0, N):
        rule.check(model)
        return gaussian_prior_many(model, x0, P0, N, definite=rule.definite)

    def predict_many(model, state, u, k):
        X_pred, P_pred, mom = predict_gaussian_many(rule, model, state[0], state[1], u, ("prédiction vers", k))
        return (X_pred, P_pred, mom.images) if keep else (X_pred, P_pred)

    def update_many(model, state, Y, idx, k):
        points = state[2] if keep else None
        X, P, K, nu, S = correct_gaussian_many(rule, model, state[0], state[1], Y, idx, joseph, ("correction par", k),
                                               points)
        return (X, P), Correction(K, nu, S)

    def inflate(state, alpha):  # mémoire évanescente : P ← α² P avant la prédiction
        return (state[0], alpha * alpha * state[1]) + tuple(state[2:])

    def noise_image(model, predicted, idx):  # G = H Q Hᵀ, H linéarisée en x̂⁻ (adaptation de Q)
        x_pred = predicted[0]
        H = model.observation_jacobian(x_pred)
        if idx is not None:
            H = H[idx]
        return H.dot(model.process_noise(x_pred)).dot(H.T)

    return FilterFamily(
        name=name or rule.filter_name,
        model_type=NonlinearModel,
        model_hint=NONLINEAR_HINT,
        prior=prior,
        predict=predict_step,
        update=update_step,
        moments=_moments,
        prior_many=prior_many,
        predict_many=predict_many,
        update_many=update_many,
        inflate=inflate,
        gating=True,
        noise_image=noise_image,
    )


def _moments(state: GaussianState) -> tuple[np.ndarray, np.ndarray]:
    return state[0], state[1]


# --------------------------------------------------------------------------- API publique


def _check_rule(rule: Any) -> GaussianRule:
    if not isinstance(rule, GaussianRule):
        raise KalmanInputError(
            "« rule » doit être une règle d'intégration gaussienne (kc.Linearization(), kc.UnscentedRule(...), "
            f"kc.CubatureRule(), kc.GaussHermiteRule(order=...)) ; reçu {type(rule).__name__}."
        )
    return rule


def gaussian_filter(model: NonlinearModel, y: Any, x0: Any, P0: Any, u: Any = None, *, rule: GaussianRule,
                    redraw: bool = True, joseph: bool = False, gate: Any = None, fading: Any = None) -> FilterResult:
    r"""Le filtre gaussien de règle ``rule`` sur toutes les mesures (pour chaque ``y[k]`` : prédiction puis
    correction, dans l'ordre de :func:`~kalman_course.kalman_filter`).

    ``rule=kc.Linearization()`` donne l'EKF, ``kc.UnscentedRule(alpha, beta, kappa)`` l'UKF,
    ``kc.CubatureRule()`` le CKF, ``kc.GaussHermiteRule(order=p)`` le GHKF : mêmes résultats que
    :func:`~kalman_course.extended_kalman_filter`, :func:`~kalman_course.unscented_kalman_filter`,
    :func:`~kalman_course.cubature_kalman_filter` et :func:`~kalman_course.gauss_hermite_kalman_filter`.

    Paramètres
    ----------
    model : NonlinearModel (bruits additifs pour une règle à points).
    y : (T, m), ou (T,) si m = 1 — ``NaN`` : composante manquante.
    x0 : (n,) ; P0 : (n, n) (définie positive pour une règle à points).
    u : (T, p), ou (T,) si p = 1, optionnel — commandes (``u[k]``, qui contient :math:`u_{k-1}`, sert à prédire vers ``y[k]``).
    rule : la règle d'intégration.
    redraw : ``True`` : la correction tire de nouveaux points de :math:`(\hat x^-, P^-)` ; ``False`` :
        elle réutilise les points propagés par :math:`f` (sans effet pour la linéarisation).
    joseph : forme de Joseph (écrite avec la covariance croisée) pour :math:`P`.
    gate, fading : options du moteur (:mod:`~kalman_course.filters.gating`), comme pour
        :func:`~kalman_course.kalman_filter` : porte :math:`\chi^2_{m_k}(p)` sur la NIS
        :math:`\nu_k^TS_k^{-1}\nu_k` (``result.rejected``), mémoire évanescente :math:`P \leftarrow \alpha^2P`
        avant chaque prédiction.

    Renvoie un :class:`~kalman_course.FilterResult`.
    """
    return run_filter(gaussian_family(_check_rule(rule), joseph=joseph, redraw=redraw), model, y, x0, P0, u,
                      gate=gate, fading=fading)


def gaussian_filter_runs(model: NonlinearModel, Y: Any, x0: Any, P0: Any, u: Any = None, *, rule: GaussianRule,
                         redraw: bool = True, joseph: bool = False) -> FilterRuns:
    r""":func:`gaussian_filter` sur ``N`` tirages indépendants du même modèle, tous à la fois
    (:func:`~kalman_course.filters.engine.run_filter_runs`) : ``Y`` (N, T, m), ``x0`` (n,) ou (N, n),
    ``P0`` (n, n) ou (N, n, n), ``u`` (T, p) commune. Renvoie un :class:`~kalman_course.FilterRuns`."""
    return run_filter_runs(gaussian_family(_check_rule(rule), joseph=joseph, redraw=redraw), model, Y, x0, P0, u)


def _checked_model(model: Any, rule: GaussianRule) -> NonlinearModel:
    model = check_instance("model", model, NonlinearModel, NONLINEAR_HINT)
    rule.check(model)
    return model


def gaussian_predict(model: NonlinearModel, x: Any, P: Any, u: Any = None, *, rule: GaussianRule):
    r"""Une prédiction du filtre gaussien : :math:`\hat x^- = \mu`, :math:`P^- = \Sigma + Q`, pour les
    moments de :math:`f` donnés par ``rule``.

    Paramètres : ``x`` (n,), ``P`` (n, n), ``u`` (p,) ou ``None``. Renvoie
    :class:`~kalman_course.filters.kalman.Prediction` ``(x, P)``."""
    from .kalman import Prediction

    model = _checked_model(model, _check_rule(rule))
    x_arr, P_arr = as_gaussian(x, P, model.n_state, "x", "P")
    if rule.definite:
        P_arr = check_pd("P", P_arr)
    if u is not None:
        check_control_allowed("u", model.n_control)
        u = as_vector("u", u, model.n_control)
    x_pred, P_pred, _ = predict_gaussian(rule, model, x_arr, P_arr, u)
    return Prediction(x_pred, P_pred)


def gaussian_update(model: NonlinearModel, x_pred: Any, P_pred: Any, y: Any, *, rule: GaussianRule,
                    joseph: bool = False):
    r"""Une correction du filtre gaussien par la mesure ``y`` (m,) : :math:`K = P_{xy}S^{-1}`,
    :math:`\hat x = \hat x^- + K(y - \hat y)`, :math:`P = P^- - KP_{xy}^T`.

    Renvoie :class:`~kalman_course.filters.kalman.Update` ``(x, P, K, innovation, S)``."""
    from .kalman import Update

    model = _checked_model(model, _check_rule(rule))
    x_arr, P_arr = as_gaussian(x_pred, P_pred, model.n_state, "x_pred", "P_pred")
    if rule.definite:
        P_arr = check_pd("P_pred", P_arr)
    y_arr = as_vector("y", y, model.n_obs)
    return Update(*correct_gaussian(rule, model, x_arr, P_arr, y_arr, None, joseph))
