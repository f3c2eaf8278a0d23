r"""EKF invariant sur SE(2) (Barrau & Bonnabel, 2017) et EKF standard sur le même robot.

Le robot plan de Barrau & Bonnabel (IEEE TAC 62(4), § IV) : pose :math:`T = \begin{bmatrix} R & p\\ 0 & 1
\end{bmatrix} \in SE(2)`, odométrie :math:`u_k = [v_x, v_y, \omega] + w_k`, :math:`w_k \sim \mathcal N(0, Q)`,
position GNSS :math:`y = p + v`, :math:`v \sim \mathcal N(0, \sigma^2 I_2)` :

.. math::

    T_{k+1} = T_k\,U_k,\qquad U_k = \begin{bmatrix}\mathrm{Exp}(\omega_k\,dt) & v_k\,dt\\ 0 & 1\end{bmatrix}
    \quad(R_{k+1} = R_k\mathrm{Exp}(\omega_k dt),\ p_{k+1} = p_k + R_kv_kdt).

**EKF invariant** (erreur invariante à gauche, :math:`T = \hat T\,\mathrm{Exp}(\xi)`, la perturbation à
droite du paquet ; :math:`\xi = [\rho_x, \rho_y, \theta]`) :

* prédiction : :math:`\hat T \leftarrow \hat TU_k`, :math:`P \leftarrow FPF^T + GQG^T`,
  :math:`F = \mathrm{Ad}_{U_k^{-1}}`, :math:`G = dt\,\mathrm{diag}(\mathrm{Exp}(\omega_kdt)^T, 1)` ;
* correction : :math:`z = \hat R^T(y - \hat p)`, :math:`H = [I_2\ 0]`, :math:`S = HPH^T + \sigma^2I_2`,
  :math:`K = PH^TS^{-1}`, :math:`\hat T \leftarrow \hat T\,\mathrm{Exp}(Kz)`, :math:`P \leftarrow (I - KH)P`.

:math:`F`, :math:`G` et :math:`H` ne dépendent que de l'odométrie : :math:`P` et :math:`K` ne dépendent pas de
l'estimation (erreur log-linéaire : sans bruit, :math:`\xi_{k+1} = \mathrm{Ad}_{U_k^{-1}}\xi_k` exactement).

**EKF standard** (état :math:`[p; \theta]`, erreur :math:`[p - \hat p;\ \theta - \hat\theta]`) : même
prédiction de la moyenne ; :math:`F = \begin{bmatrix} I_2 & \hat RJv_kdt\\ 0 & 1\end{bmatrix}`,
:math:`J = \begin{bmatrix}0 & -1\\ 1 & 0\end{bmatrix}`, :math:`G = dt\,\mathrm{diag}(\hat R, 1)` ; correction
:math:`\nu = y - \hat p`, mêmes :math:`H, S, K`, :math:`[\hat p; \hat\theta] \mathrel{+}= K\nu`,
:math:`P \leftarrow (I - KH)P`. Les deux filtres portent la pose :math:`\hat T` (l'angle corrigé entre dans
:math:`\hat R` par :math:`\hat R\,\mathrm{Exp}(\delta\theta)`, donc toujours ramené).

Les deux familles passent par le moteur commun (:func:`~kalman_course.filters.engine.run_filter`, un tirage ;
:func:`~kalman_course.filters.engine.run_filter_runs`, ``N`` tirages à la fois) : positions GNSS manquantes
(ligne ``NaN`` : prédiction seule), porte (``gate``) et mémoire évanescente (``fading``) pour un tirage, et la
log-vraisemblance :func:`~kalman_course.filter_log_likelihood` de leurs innovations. Une ligne GNSS à moitié
manquante, un pas de temps ou des bruits variables dans le temps sont refusés (``KalmanInputError``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from ..core.angles import wrap_angle
from ..core.results import FilterResult, FilterRuns, PoseAliases
from ..core.validation import (
    KalmanInputError,
    as_batch_measurements,
    as_float_array,
    as_measurements,
    as_square_matrix,
    as_vector,
    check_psd,
    number_text,
    shape_text,
)
from ..geometry.lie import ROTATION_TOL, _se2_exp, _se2_exp_many, as_se2_pose
from .engine import Correction, FilterFamily, gaussian_moments, run_filter, run_filter_runs

__all__ = [
    "OdometryGnssModel",
    "SE2FilterResult",
    "SE2FilterRuns",
    "SE2Update",
    "odometry_increment",
    "se2_prediction_jacobians",
    "se2_invariant_predict",
    "se2_invariant_update",
    "se2_standard_predict",
    "se2_standard_update",
    "se2_family",
    "se2_invariant_ekf",
    "se2_standard_ekf",
    "se2_invariant_ekf_runs",
    "se2_standard_ekf_runs",
    "world_covariance",
]

#: Les deux familles : erreur invariante à gauche, ou erreur [p − p̂ ; θ − θ̂].
KINDS = ("invariant", "standard")
_NAMES = {"invariant": "EKF invariant sur SE(2)", "standard": "EKF standard sur SE(2)"}


# --------------------------------------------------------------------------- le modèle


def _positive(name: str, value: Any, unit: str, what: str) -> float:
    arr = np.asarray(value, dtype=object)
    if arr.ndim != 0:
        raise KalmanInputError(
            f"« {name} » ({what}) doit être un réel > 0 en {unit} ; reçu {shape_text(np.shape(value))} "
            "(un modèle variable dans le temps n'est pas pris en charge par les filtres sur SE(2))."
        )
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = float("nan")
    if isinstance(value, bool) or not (math.isfinite(v) and v > 0.0):
        raise KalmanInputError(f"« {name} » ({what}) doit être un réel > 0 en {unit} ; reçu {value!r}.")
    return v


@dataclass(frozen=True, eq=False)
class OdometryGnssModel:
    r"""Robot plan à odométrie et GNSS (Barrau & Bonnabel, 2017, § IV), figé.

    ``dt`` (s) > 0 : période de l'odométrie ; ``odometry_std`` (3,) ≥ 0 :
    :math:`[\sigma_{v_x}, \sigma_{v_y}, \sigma_\omega]` (m/s, m/s, rad/s) ; ``gnss_std`` (m) > 0. Attributs
    calculés : ``Q`` = :math:`\mathrm{diag}(\sigma^2)` (3, 3), ``R`` = :math:`\sigma_{\mathrm{GNSS}}^2 I_2`.

    .. math::

        T_{k+1} = T_k\begin{bmatrix}\mathrm{Exp}(\omega_kdt) & v_kdt\\ 0 & 1\end{bmatrix},\quad
        u_k = [v_x, v_y, \omega] + w_k,\ w_k \sim \mathcal N(0, Q),\qquad y = p + v,\ v \sim \mathcal N(0, R).

    ``n_state`` = 3 (dimension de l'erreur), ``n_obs`` = 2, ``n_control`` = 3.
    """

    dt: float
    odometry_std: np.ndarray
    gnss_std: float
    Q: np.ndarray = field(init=False, repr=False)
    R: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "dt", _positive("dt", self.dt, "s", "période de l'odométrie"))
        std = as_float_array("odometry_std", self.odometry_std)
        if std.shape != (3,):
            hint = (" (un modèle variable dans le temps n'est pas pris en charge par les filtres sur SE(2))"
                    if std.ndim == 2 and std.shape[-1:] == (3,) else "")
            raise KalmanInputError(
                "« odometry_std » doit être le vecteur (3,) des écarts-types [σ_vx, σ_vy, σ_ω] (m/s, m/s, rad/s) ; "
                f"reçu {shape_text(std.shape)}{hint}."
            )
        if (std < 0).any():
            raise KalmanInputError(
                f"« odometry_std » doit être ≥ 0 (des écarts-types) ; reçu {number_text(float(std.min()), '.3g')}."
            )
        std.setflags(write=False)
        object.__setattr__(self, "odometry_std", std)
        object.__setattr__(self, "gnss_std", _positive("gnss_std", self.gnss_std, "m", "écart-type du GNSS"))
        Q = np.diag(std**2)
        R = self.gnss_std**2 * np.eye(2)
        for M in (Q, R):
            M.setflags(write=False)
        object.__setattr__(self, "Q", Q)
        object.__setattr__(self, "R", R)
        q = (self.dt * std) ** 2  # dt² σ², lus à chaque prédiction
        object.__setattr__(self, "_step_noise", (float(q[0]), float(q[1]), float(q[2])))

    @property
    def n_state(self) -> int:
        """Dimension de l'erreur (3 : :math:`\\rho_x, \\rho_y, \\theta` ou :math:`p_x, p_y, \\theta`)."""
        return 3

    @property
    def n_obs(self) -> int:
        """Dimension de la mesure GNSS (2)."""
        return 2

    @property
    def n_control(self) -> int:
        """Dimension de l'odométrie (3 : :math:`v_x, v_y, \\omega`)."""
        return 3


# --------------------------------------------------------------------------- résultats


def world_covariance(T: np.ndarray, P: np.ndarray, kind: str) -> np.ndarray:
    r"""Covariance de :math:`[p - \hat p;\ \theta - \hat\theta]` : :math:`APA^T`, :math:`A = \mathrm{diag}(\hat R, 1)`
    pour l'EKF invariant (:math:`p - \hat p \approx \hat R\rho`), :math:`P` elle-même pour l'EKF standard.
    ``T`` (…, 3, 3), ``P`` (…, 3, 3)."""
    if kind == "standard":
        return np.array(P, dtype=float)
    A = np.zeros(np.shape(T))
    A[..., :2, :2] = T[..., :2, :2]
    A[..., 2, 2] = 1.0
    return A @ P @ np.swapaxes(A, -1, -2)


def _heading(T: np.ndarray) -> np.ndarray:
    return wrap_angle(np.arctan2(T[..., 1, 0], T[..., 0, 0]))


@dataclass(frozen=True, eq=False, repr=False)
class SE2FilterResult(PoseAliases, FilterResult):
    r"""Sortie de :func:`se2_invariant_ekf` ou :func:`se2_standard_ekf` sur ``K`` pas (ligne ``k`` : instant
    ``k + 1``), le résultat commun (:class:`~kalman_course.FilterResult`) dont l'estimation est une pose.

    ``x`` (K, 3, 3) (alias ``T``), ``x_pred`` (alias ``T_pred``) : poses a posteriori et prédites ;
    ``P``, ``P_pred`` (K, 3, 3) : covariances dans les coordonnées d'erreur du filtre (:math:`\xi` pour
    l'EKF invariant, :math:`[p - \hat p; \theta - \hat\theta]` pour l'EKF standard) ; ``P_world`` (K, 3, 3) :
    covariance de :math:`[p - \hat p;\ \theta - \hat\theta]` pour les deux (:func:`world_covariance`) ;
    ``K`` (K, 3, 2), ``innovation`` (K, 2) (:math:`z = \hat R^T(y - \hat p)` ou :math:`\nu = y - \hat p`),
    ``S`` (K, 2, 2), ``observed`` (K, 2), ``n_iter`` (K,)."""

    P_world: np.ndarray | None = None

    @property
    def heading(self) -> np.ndarray:
        r"""Caps estimés :math:`\hat\theta` (K,) dans :math:`(-\pi, \pi]` (rad)."""
        return _heading(self.x)

    @property
    def position(self) -> np.ndarray:
        """Positions estimées :math:`\\hat p` (K, 2) (m)."""
        return self.x[..., :2, 2]


@dataclass(frozen=True, eq=False, repr=False)
class SE2FilterRuns(PoseAliases, FilterRuns):
    r"""``N`` tirages filtrés ensemble (:func:`se2_invariant_ekf_runs`, :func:`se2_standard_ekf_runs`) : les
    champs de :class:`SE2FilterResult` avec un axe des tirages en tête (``x`` (N, K, 3, 3), ``P`` et
    ``P_world`` (N, K, 3, 3)…) ; ``run(i)`` rend le :class:`SE2FilterResult` du tirage ``i``."""

    P_world: np.ndarray | None = None

    heading = SE2FilterResult.heading
    position = SE2FilterResult.position

    def run(self, i: int) -> SE2FilterResult:
        one = super().run(i)
        return SE2FilterResult(x=one.x, P=one.P, x_pred=one.x_pred, P_pred=one.P_pred, K=one.K,
                               innovation=one.innovation, S=one.S, observed=one.observed, n_iter=one.n_iter,
                               P_world=self.P_world[i])


# --------------------------------------------------------------------------- étapes pures


def odometry_increment(u: Any, dt: float) -> np.ndarray:
    r""":math:`U = \begin{bmatrix}\mathrm{Exp}(\omega\,dt) & v\,dt\\ 0 & 1\end{bmatrix}` (3, 3) pour
    ``u`` = :math:`[v_x, v_y, \omega]` (3,), ou (N, 3, 3) pour ``u`` (N, 3)."""
    u = np.asarray(u, dtype=float)
    a = u[..., 2] * dt
    c, s = np.cos(a), np.sin(a)
    U = np.zeros(u.shape[:-1] + (3, 3))
    U[..., 0, 0], U[..., 0, 1], U[..., 0, 2] = c, -s, u[..., 0] * dt
    U[..., 1, 0], U[..., 1, 1], U[..., 1, 2] = s, c, u[..., 1] * dt
    U[..., 2, 2] = 1.0
    return U


def _step_increment(u, dt):
    """(c, s, v_x dt, v_y dt) en flottants Python (boucle d'un tirage)."""
    vx, vy, w = u.tolist()
    a = w * dt
    return math.cos(a), math.sin(a), vx * dt, vy * dt


def _add_noise(Pp, c, s, q1, q2, q3):
    r"""Ajoute :math:`dt^2\,\mathrm{diag}(\mathcal R\,\mathrm{diag}(q_1, q_2)\mathcal R^T, q_3)` à ``Pp`` (sur place),
    :math:`\mathcal R = [[c, -s], [s, c]]`, en rendant le bloc 2 × 2 exactement symétrique."""
    m = c * s * (q1 - q2)
    Pp[0, 0] += c * c * q1 + s * s * q2
    Pp[1, 1] += s * s * q1 + c * c * q2
    Pp[0, 1] = Pp[1, 0] = 0.5 * (Pp[0, 1] + Pp[1, 0]) + m
    Pp[0, 2] = Pp[2, 0] = 0.5 * (Pp[0, 2] + Pp[2, 0])
    Pp[1, 2] = Pp[2, 1] = 0.5 * (Pp[1, 2] + Pp[2, 1])
    Pp[2, 2] += q3
    return Pp


def _invariant_predict(model, T, P, u):
    c, s, tx, ty = _step_increment(u, model.dt)
    q1, q2, q3 = model._step_noise
    F = np.array(((c, s, s * tx - c * ty), (-s, c, c * tx + s * ty), (0.0, 0.0, 1.0)))  # Ad(U⁻¹)
    Pp = F.dot(P).dot(F.T)
    # G Q Gᵀ = dt² diag(Rᵀ diag(q₁, q₂) R, q₃), R = Exp(ω dt) : Rᵀ = [[c, s], [−s, c]]
    _add_noise(Pp, c, -s, q1, q2, q3)
    # T̂ U : (R̂ Exp(ω dt), p̂ + R̂ v dt)
    (a, b, x), (d, e, y_) = T[:2].tolist()
    T_new = np.array(((a * c + b * s, b * c - a * s, x + a * tx + b * ty),
                      (d * c + e * s, e * c - d * s, y_ + d * tx + e * ty), (0.0, 0.0, 1.0)))
    return T_new, Pp


def _standard_predict(model, T, P, u):
    c, s, tx, ty = _step_increment(u, model.dt)
    q1, q2, q3 = model._step_noise
    (a, b, x), (d, e, y_) = T[:2].tolist()  # R̂ = [[a, b], [d, e]] avant la prédiction
    F = np.array(((1.0, 0.0, b * tx - a * ty), (0.0, 1.0, e * tx - d * ty), (0.0, 0.0, 1.0)))  # R̂ J v dt
    Pp = F.dot(P).dot(F.T)
    _add_noise(Pp, a, d, q1, q2, q3)  # G Q Gᵀ = dt² diag(R̂ diag(q₁, q₂) R̂ᵀ, q₃)
    T_new = np.array(((a * c + b * s, b * c - a * s, x + a * tx + b * ty),
                      (d * c + e * s, e * c - d * s, y_ + d * tx + e * ty), (0.0, 0.0, 1.0)))
    return T_new, Pp


def _gain(P, r2):
    """:math:`S = HPH^T + \\sigma^2I_2`, :math:`K = PH^TS^{-1}` pour :math:`H = [I_2\\ 0]`."""
    S = P[:2, :2] + r2 * np.eye(2)
    K = np.linalg.solve(S, P[:2, :]).T  # (S⁻¹ H P)ᵀ, S et P symétriques
    return S, K


def _innovation(kind, T, y):
    d = y - T[:2, 2]
    return T[:2, :2].T.dot(d) if kind == "invariant" else d


def _correct(kind, T, P, z, K):
    dx = K.dot(z)
    if kind == "invariant":
        T_new = T.dot(_se2_exp(dx))
    else:
        c, s = math.cos(dx[2]), math.sin(dx[2])
        T_new = T.dot(np.array(((c, -s, 0.0), (s, c, 0.0), (0.0, 0.0, 1.0))))  # R̂ Exp(δθ)
        T_new[:2, 2] = T[:2, 2] + dx[:2]
    Pn = P - K.dot(P[:2, :])
    return T_new, 0.5 * (Pn + Pn.T)


class SE2Update(NamedTuple):
    """Une correction GNSS : pose ``T`` (3, 3) et covariance ``P`` (3, 3) a posteriori, gain ``K`` (3, 2),
    innovation (2,) et sa covariance ``S`` (2, 2)."""

    T: np.ndarray
    P: np.ndarray
    K: np.ndarray
    innovation: np.ndarray
    S: np.ndarray


def _check_step(T, P, name_T, name_P):
    return as_se2_pose(name_T, T), check_psd(name_P, as_square_matrix(name_P, P, 3))


def _check_model(model):
    if not isinstance(model, OdometryGnssModel):
        raise KalmanInputError(
            f"« model » doit être un OdometryGnssModel ; reçu {type(model).__name__} "
            "(construisez-le avec OdometryGnssModel(dt, odometry_std, gnss_std))."
        )
    return model


def se2_invariant_predict(model: OdometryGnssModel, T: Any, P: Any, u: Any) -> tuple[np.ndarray, np.ndarray]:
    r"""Prédiction de l'EKF invariant : :math:`\hat T U_k` et :math:`FPF^T + GQG^T`,
    :math:`F = \mathrm{Ad}_{U_k^{-1}}`, :math:`G = dt\,\mathrm{diag}(\mathrm{Exp}(\omega_kdt)^T, 1)`.
    ``T`` (3, 3), ``P`` (3, 3), ``u`` (3,) ; renvoie ``(T, P)``."""
    T, P = _check_step(T, P, "T", "P")
    return _invariant_predict(_check_model(model), T, P, as_vector("u", u, 3))


def se2_standard_predict(model: OdometryGnssModel, T: Any, P: Any, u: Any) -> tuple[np.ndarray, np.ndarray]:
    r"""Prédiction de l'EKF standard : :math:`\hat T U_k` et :math:`FPF^T + GQG^T`,
    :math:`F = \begin{bmatrix} I_2 & \hat RJv_kdt\\ 0 & 1\end{bmatrix}`, :math:`G = dt\,\mathrm{diag}(\hat R, 1)`."""
    T, P = _check_step(T, P, "T", "P")
    return _standard_predict(_check_model(model), T, P, as_vector("u", u, 3))


def _update(kind, T, P, y, gnss_std):
    T, P = _check_step(T, P, "T_pred", "P_pred")
    y = as_vector("y", y, 2)
    r = _positive("gnss_std", gnss_std, "m", "écart-type du GNSS")
    z = _innovation(kind, T, y)
    S, K = _gain(P, r * r)
    T_new, P_new = _correct(kind, T, P, z, K)
    return SE2Update(T_new, P_new, K, z, S)


def se2_invariant_update(T_pred: Any, P_pred: Any, y: Any, gnss_std: float) -> SE2Update:
    r"""Correction de l'EKF invariant par une position GNSS ``y`` (2,) :

    .. math::

        z = \hat R^T(y - \hat p),\quad S = P_{\rho\rho} + \sigma^2I_2,\quad K = PH^TS^{-1},\quad
        \hat T_+ = \hat T\,\mathrm{Exp}(Kz),\quad P_+ = (I - KH)P,\qquad H = [I_2\ 0]."""
    return _update("invariant", T_pred, P_pred, y, gnss_std)


def se2_standard_update(T_pred: Any, P_pred: Any, y: Any, gnss_std: float) -> SE2Update:
    r"""Correction de l'EKF standard : :math:`\nu = y - \hat p`, mêmes :math:`S` et :math:`K`,
    :math:`[\hat p; \hat\theta] \mathrel{+}= K\nu`, :math:`P_+ = (I - KH)P`."""
    return _update("standard", T_pred, P_pred, y, gnss_std)


# --------------------------------------------------------------------------- étapes en lot


def _batch_jacobians(kind, dt, T, u):
    r"""(c, s, v_x dt, v_y dt) (N,) et :math:`F` (N, 3, 3) de la prédiction, plus la rotation
    :math:`(\cos, \sin)` qui porte le bruit de vitesse dans :math:`G = dt\,\mathrm{diag}(\mathcal R, 1)` :
    :math:`\mathcal R = \mathrm{Exp}(\omega dt)^T` (invariant) ou :math:`\hat R` (standard)."""
    N = T.shape[0]
    u = np.asarray(u, dtype=float)
    if u.ndim == 1:  # odométrie commune à tous les tirages
        u = np.broadcast_to(u, (N, 3))
    a = u[:, 2] * dt
    c, s = np.cos(a), np.sin(a)
    tx, ty = u[:, 0] * dt, u[:, 1] * dt
    F = np.zeros((N, 3, 3))
    F[:, 2, 2] = 1.0
    if kind == "invariant":  # Ad(U⁻¹)
        F[:, 0, 0], F[:, 0, 1], F[:, 0, 2] = c, s, s * tx - c * ty
        F[:, 1, 0], F[:, 1, 1], F[:, 1, 2] = -s, c, c * tx + s * ty
        rc, rs = c, -s
    else:  # [[I, R̂ J v dt], [0, 1]]
        rc, rs = T[:, 0, 0], T[:, 1, 0]
        F[:, 0, 0] = F[:, 1, 1] = 1.0
        F[:, 0, 2], F[:, 1, 2] = -rc * ty - rs * tx, rc * tx - rs * ty
    return (c, s, tx, ty), F, (rc, rs)


def se2_prediction_jacobians(model: OdometryGnssModel, T: Any, u: Any, kind: str = "invariant"):
    r"""Jacobiennes :math:`F` (3, 3) et :math:`G` (3, 3) de la prédiction depuis la pose ``T`` avec
    l'odométrie ``u`` (3,), pour l'erreur du filtre ``kind`` (l'erreur prédite vaut :math:`F\xi + Gw`) :

    * ``"invariant"`` : :math:`F = \mathrm{Ad}_{U^{-1}}`, :math:`G = dt\,\mathrm{diag}(\mathrm{Exp}(\omega dt)^T, 1)`
      (indépendantes de ``T``) ;
    * ``"standard"`` : :math:`F = \begin{bmatrix} I_2 & \hat RJv\,dt\\ 0 & 1\end{bmatrix}`,
      :math:`G = dt\,\mathrm{diag}(\hat R, 1)`."""
    model = _check_model(model)
    T = as_se2_pose("T", T)
    _, F, (rc, rs) = _batch_jacobians(_check_kind(kind), model.dt, T[None], as_vector("u", u, 3))
    G = model.dt * np.array([[rc[0], -rs[0], 0.0], [rs[0], rc[0], 0.0], [0.0, 0.0, 1.0]])
    return F[0], G


_DIAG = np.arange(3)


def _batch_predict(kind, model, T, P, u):
    (c, s, tx, ty), F, (rc, rs) = _batch_jacobians(kind, model.dt, T, u)
    N = T.shape[0]
    Pp = F @ P @ np.swapaxes(F, 1, 2)
    q1, q2, q3 = model._step_noise
    if q1 == q2:  # bruit de vitesse isotrope : R diag(q, q) Rᵀ = q I, quelle que soit la rotation
        Pp[:, _DIAG, _DIAG] += (q1, q1, q3)
    else:  # G Q Gᵀ = dt² diag(R diag(q₁, q₂) Rᵀ, q₃)
        m = rc * rs * (q1 - q2)
        Pp[:, 0, 0] += rc * rc * q1 + rs * rs * q2
        Pp[:, 1, 1] += rs * rs * q1 + rc * rc * q2
        Pp[:, 0, 1] += m
        Pp[:, 1, 0] += m
        Pp[:, 2, 2] += q3
    U = np.zeros((N, 3, 3))
    U[:, 0, 0], U[:, 0, 1], U[:, 0, 2] = c, -s, tx
    U[:, 1, 0], U[:, 1, 1], U[:, 1, 2] = s, c, ty
    U[:, 2, 2] = 1.0
    return T @ U, Pp


def _batch_update(kind, model, T, P, Y):
    d = Y - T[:, :2, 2]
    z = np.einsum("nji,nj->ni", T[:, :2, :2], d) if kind == "invariant" else d
    S = P[:, :2, :2] + model.gnss_std**2 * np.eye(2)
    K = np.swapaxes(np.linalg.solve(S, P[:, :2, :]), 1, 2)
    dx = np.einsum("nij,nj->ni", K, z)
    if kind == "invariant":
        T_new = T @ _se2_exp_many(dx)
    else:
        c, s = np.cos(dx[:, 2]), np.sin(dx[:, 2])
        E = np.zeros_like(T)
        E[:, 0, 0], E[:, 0, 1], E[:, 1, 0], E[:, 1, 1], E[:, 2, 2] = c, -s, s, c, 1.0
        T_new = T @ E
        T_new[:, :2, 2] = T[:, :2, 2] + dx[:, :2]
    Pn = P - K @ P[:, :2, :]
    return (T_new, 0.5 * (Pn + np.swapaxes(Pn, 1, 2))), Correction(K, z, S, np.ones(len(T), dtype=int))


# --------------------------------------------------------------------------- familles et filtres


def _per_run(name: str, value: Any, N: int, check, fine) -> np.ndarray:
    """``value`` (3, 3) commune à tous les tirages ou (N, 3, 3) une par tirage, chacune vérifiée par
    ``check(nom, matrice)`` ; ``fine(pile)`` dit, en bloc, quelles matrices passent sans examen (les autres
    passent par ``check``, qui lève l'erreur qui les nomme). Renvoie (N, 3, 3)."""
    arr = as_float_array(name, value)
    if arr.ndim != 3:
        return np.broadcast_to(check(name, arr), (N, 3, 3)).copy()
    if arr.shape != (N, 3, 3):
        raise KalmanInputError(
            f"« {name} » doit être de forme (3, 3) (commune) ou ({N}, 3, 3) (une par tirage) ; reçu {shape_text(arr.shape)}."
        )
    ok = fine(arr)
    out = arr.copy()
    for i in np.flatnonzero(~ok):
        out[i] = check(f"{name}[{i}]", arr[i])
    return out


def _fine_poses(T: np.ndarray) -> np.ndarray:
    """Poses planes valides (dernière ligne, rotation), en bloc : même tolérance que :func:`as_se2_pose`."""
    R = T[:, :2, :2]
    err = np.abs(np.swapaxes(R, 1, 2) @ R - np.eye(2)).max(axis=(1, 2))
    det = R[:, 0, 0] * R[:, 1, 1] - R[:, 0, 1] * R[:, 1, 0]
    last = np.abs(T[:, 2] - [0.0, 0.0, 1.0]).max(axis=1)
    return (err <= ROTATION_TOL) & (np.abs(det - 1.0) <= ROTATION_TOL) & (last <= ROTATION_TOL)


def _fine_covariances(P: np.ndarray) -> np.ndarray:
    """Covariances symétriques et semi-définies positives, en bloc : mêmes tolérances que :func:`check_psd`."""
    scale = np.maximum(1.0, np.abs(P).max(axis=(1, 2)))
    sym = np.abs(P - np.swapaxes(P, 1, 2)).max(axis=(1, 2)) <= 1e-9 * scale
    lam = np.linalg.eigvalsh(0.5 * (P + np.swapaxes(P, 1, 2)))[:, 0]
    return sym & (lam >= -1e-10 * scale)


def _check_kind(kind: Any) -> str:
    if kind not in KINDS:
        raise KalmanInputError(f"« kind » doit valoir {' ou '.join(map(repr, KINDS))} ; reçu {kind!r}.")
    return kind


def se2_family(kind: str = "invariant") -> FilterFamily:
    r"""Les étapes de l'EKF invariant (``kind="invariant"``) ou standard (``"standard"``) sur SE(2) pour le
    moteur ; état interne :math:`(\hat T, P)` ((3, 3) et (3, 3), ou (N, 3, 3) et (N, 3, 3) en lot).

    Les options du moteur (:func:`~kalman_course.filters.engine.run_filter`) s'appliquent comme à tout
    filtre gaussien : la porte (``gate=p`` : une position dont la NIS :math:`z^TS^{-1}z` dépasse
    :math:`\chi^2_2(p)` est rejetée, prédiction seule) et la mémoire évanescente (``fading=α`` :
    :math:`P_{k+1\mid k} = \alpha^2FPF^T + GQG^T`), pour un tirage."""
    kind = _check_kind(kind)
    step_predict = _invariant_predict if kind == "invariant" else _standard_predict

    def prior(model, T0, P0):
        return _check_step(T0, P0, "T0", "P0")

    def predict(model, state, u):
        return step_predict(model, state[0], state[1], u)

    def update(model, state, y, idx):
        T, P = state
        z = _innovation(kind, T, y)
        S, K = _gain(P, model.gnss_std**2)
        return _correct(kind, T, P, z, K), Correction(K, z, S)

    def prior_many(model, T0, P0, N, shared=False):
        P = _per_run("P0", P0, N, lambda name, M: check_psd(name, as_square_matrix(name, M, 3)), _fine_covariances)
        return _per_run("T0", T0, N, as_se2_pose, _fine_poses), 0.5 * (P + np.swapaxes(P, 1, 2))

    def predict_many(model, state, u, k):
        return _batch_predict(kind, model, state[0], state[1], u)

    def update_many(model, state, Y, idx, k):
        return _batch_update(kind, model, state[0], state[1], Y)

    return FilterFamily(
        name=_NAMES[kind],
        model_type=OdometryGnssModel,
        model_hint="construisez-le avec OdometryGnssModel(dt, odometry_std, gnss_std)",
        prior=prior,
        predict=predict,
        update=update,
        moments=gaussian_moments,
        result_type=SE2FilterResult,
        state_shape=lambda model: (3, 3),
        tangent_dim=lambda model: 3,
        prior_many=prior_many,
        predict_many=predict_many,
        update_many=update_many,
        batch_controls=True,
        inflate=lambda state, alpha: (state[0], alpha * alpha * state[1]),
        gating=True,
    )


def _check_whole_rows(name: str, Y: np.ndarray) -> None:
    """Une position GNSS est observée entière (deux composantes) ou manquante (ligne NaN)."""
    missing = np.isnan(Y)
    half = missing.any(axis=-1) & ~missing.all(axis=-1)
    if half.any():
        where = tuple(int(i) for i in np.argwhere(half)[0])
        raise KalmanInputError(
            f"« {name} » a une position GNSS à moitié manquante (ligne {where if len(where) > 1 else where[0]}) : "
            "un récepteur donne les deux coordonnées ou aucune ; mettez la ligne entière à NaN."
        )


def _check_odometry(u: Any) -> Any:
    if u is None:
        raise KalmanInputError(
            "« u » (odométrie [v_x, v_y, ω] à chaque pas, forme (K, 3)) est obligatoire : c'est elle qui "
            "fait avancer la pose."
        )
    return u


def _filter(kind, model, y, T0, P0, u, gate, fading) -> SE2FilterResult:
    family = se2_family(kind)
    _check_model(model)
    Y = as_measurements("y", y, 2)
    _check_whole_rows("y", Y)
    res = run_filter(family, model, Y, T0, P0, _check_odometry(u), gate=gate, fading=fading)
    return _with_world(res, SE2FilterResult, kind)


def _with_world(res, cls, kind):
    values = {f: getattr(res, f) for f in ("x", "P", "x_pred", "P_pred", "K", "innovation", "S", "observed",
                                           "n_iter")}
    return cls(**values, P_world=world_covariance(res.x, res.P, kind))


def se2_invariant_ekf(model: OdometryGnssModel, y: Any, T0: Any, P0: Any, u: Any, *,
                      gate: Any = None, fading: Any = None) -> SE2FilterResult:
    r"""EKF invariant (erreur invariante à gauche :math:`T = \hat T\,\mathrm{Exp}(\xi)`) sur ``K`` pas :
    pour chaque ligne ``k`` (instant ``k + 1``), prédiction avec ``u[k]`` puis correction par ``y[k]`` s'il
    est présent (voir le module pour les équations).

    Paramètres
    ----------
    model : :class:`OdometryGnssModel`.
    y : (K, 2) — positions GNSS (m) ; une ligne ``NaN`` : pas de position (prédiction seule).
    T0 : (3, 3) — pose estimée à l'instant 0 ; P0 : (3, 3) semi-définie positive (éventuellement
        singulière), covariance de :math:`\xi` à l'instant 0.
    u : (K, 3) — odométrie :math:`[v_x, v_y, \omega]` (m/s, m/s, rad/s).
    gate, fading : porte et mémoire évanescente (:func:`se2_family`).

    Renvoie un :class:`SE2FilterResult` (``P`` en coordonnées :math:`\xi`, ``P_world`` en
    :math:`[p - \hat p;\ \theta - \hat\theta]`).
    """
    return _filter("invariant", model, y, T0, P0, u, gate, fading)


def se2_standard_ekf(model: OdometryGnssModel, y: Any, T0: Any, P0: Any, u: Any, *,
                     gate: Any = None, fading: Any = None) -> SE2FilterResult:
    r"""EKF standard sur l'état :math:`[p; \theta]`, mêmes entrées et même convention que
    :func:`se2_invariant_ekf` ; ``P0`` et ``P`` sont les covariances de :math:`[p - \hat p;\ \theta - \hat\theta]`
    (``P_world`` = ``P``)."""
    return _filter("standard", model, y, T0, P0, u, gate, fading)


def _filter_runs(kind, model, Y, T0, P0, u) -> SE2FilterRuns:
    _check_model(model)
    Yarr = as_batch_measurements("Y", Y, 2)
    _check_whole_rows("Y", Yarr)
    res = run_filter_runs(se2_family(kind), model, Yarr, T0, P0, _check_odometry(u))
    return _with_world(res, SE2FilterRuns, kind)


def se2_invariant_ekf_runs(model: OdometryGnssModel, Y: Any, T0: Any, P0: Any, u: Any) -> SE2FilterRuns:
    r""":func:`se2_invariant_ekf` sur ``N`` tirages à la fois (un pas du moteur pour toute la pile) :
    ``Y`` (N, K, 2), ``T0`` (3, 3) ou (N, 3, 3), ``P0`` (3, 3) ou (N, 3, 3), ``u`` (K, 3) ou (N, K, 3).
    Chaque tirage égale :func:`se2_invariant_ekf` sur ses données, aux arrondis près."""
    return _filter_runs("invariant", model, Y, T0, P0, u)


def se2_standard_ekf_runs(model: OdometryGnssModel, Y: Any, T0: Any, P0: Any, u: Any) -> SE2FilterRuns:
    r""":func:`se2_standard_ekf` sur ``N`` tirages à la fois (voir :func:`se2_invariant_ekf_runs`)."""
    return _filter_runs("standard", model, Y, T0, P0, u)
