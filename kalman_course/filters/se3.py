r"""EKF et EKF itéré sur SE(3) : pose d'une cible connue vue par une caméra à sténopé.

État : la pose :math:`T \in SE(3)` (repère de la cible dans celui de la caméra) et une covariance
:math:`P` (6, 6) dans l'espace tangent **à droite** : :math:`T = \hat T\,\mathrm{Exp}(\delta)`,
:math:`\delta \sim \mathcal N(0, P)`, :math:`\delta = [\rho;\theta]` (m, rad).

* Prédiction (:func:`se3_predict`) : :math:`\hat T_{k+1\mid k} = \hat T_{k\mid k}\mathrm{Exp}(u_k)`,
  :math:`P_{k+1\mid k} = FPF^T + GQG^T`, :math:`F = \mathrm{Ad}_{\mathrm{Exp}(u_k)}^{-1}`, :math:`G = \mathcal J_r(u_k)`.
* Correction itérée (:func:`se3_iekf_update`) : Gauss–Newton sur le coût MAP
  :math:`J(T) = \tfrac12\lVert\mathrm{Log}(\hat T_-^{-1}T)\rVert^2_{P_-^{-1}} + \tfrac12\lVert y - h(T)\rVert^2_{R^{-1}}`.
  Une seule itération est l'EKF sur la variété (:func:`se3_ekf_update`).

La correction est la boucle de Gauss–Newton commune (:func:`kalman_course.filters.iteration.gauss_newton_update`)
avec les opérations de SE(3) (:data:`SE3_SPACE` : :math:`T \oplus \delta = T\,\mathrm{Exp}(\delta)`,
:math:`T \ominus T_0 = \mathrm{Log}(T_0^{-1}T)`) ; la séquence d'images passe par le moteur commun
(:func:`kalman_course.filters.engine.run_filter`), comme tous les filtres du paquet.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
import scipy.linalg

from ..core.linalg import cholesky_factor, symmetrize
from ..core.results import FilterResult, PoseAliases
from ..core.validation import (
    KalmanInputError, as_float_array, as_square_matrix, as_vector, check_pd, check_psd, shape_text,
)
from ..geometry.camera import PinholeCamera, _check_camera, _measure, _measurement_jacobian, as_points
from ..geometry.lie import _se3_adjoint, _se3_exp, _se3_inverse, _se3_jl, _se3_log, as_pose
from .engine import Correction, FilterFamily, run_filter
from .iteration import DEFAULT_MAX_ITER, DEFAULT_TOL, StateSpace, check_iterations, gauss_newton_update

__all__ = [
    "CameraPoseModel",
    "SE3_SPACE",
    "se3_family",
    "SE3Prediction",
    "SE3Update",
    "SE3FilterResult",
    "se3_predict",
    "se3_iekf_update",
    "se3_ekf_update",
    "se3_map_cost",
    "se3_nees",
    "se3_iterated_filter",
]


def _se3_oplus(T: np.ndarray, delta: np.ndarray) -> np.ndarray:
    return T @ _se3_exp(delta)


def _se3_ominus(T: np.ndarray, T0: np.ndarray) -> np.ndarray:
    return _se3_log(_se3_inverse(T0) @ T)


def _right_jacobian(xi: np.ndarray) -> np.ndarray:
    return _se3_jl(-xi)  # J_r(ξ) = J_l(−ξ)


def _transport(P: np.ndarray, delta: np.ndarray) -> np.ndarray:
    J = _right_jacobian(delta)
    return J @ P @ J.T


#: SE(3) pour Gauss–Newton : :math:`T\oplus\delta = T\,\mathrm{Exp}(\delta)`,
#: :math:`T\ominus T_0 = \mathrm{Log}(T_0^{-1}T)`, a priori vu depuis :math:`T_i` avec
#: :math:`\mathcal J_r(\xi_i)`, covariance finale transportée par :math:`\mathcal J_r(\delta_{N-1})`.
SE3_SPACE = StateSpace(oplus=_se3_oplus, ominus=_se3_ominus, prior_jacobian=_right_jacobian, transport=_transport)


class SE3Prediction(NamedTuple):
    """Prédiction : pose ``T`` (4, 4) et covariance ``P`` (6, 6) (tangent à droite en ``T``)."""

    T: np.ndarray
    P: np.ndarray


class SE3Update(NamedTuple):
    r"""Résultat de :func:`se3_iekf_update`.

    ``T`` (4, 4) : :math:`\hat T_+ = T_N` ; ``P`` (6, 6) : covariance a posteriori (tangent à droite en
    :math:`\hat T_+`) ; ``n_iter`` : nombre :math:`N` d'itérations ; ``converged`` : arrêt par ``tol`` ;
    ``iterates`` (N+1, 4, 4) : :math:`T_0 = \hat T_-, \dots, T_N` ; ``xi`` (N+1, 6) :
    :math:`\xi_i = \mathrm{Log}(\hat T_-^{-1}T_i)` ; ``steps`` (N, 6) : les pas :math:`\delta_i` ;
    ``cost`` (N+1,) : :math:`J(T_i)` ; ``K`` (6, 2n), ``innovation`` (2n,) et ``S`` (2n, 2n) : gain,
    innovation linéarisée :math:`r_{N-1} + H_{N-1}\xi_{N-1}` et sa covariance, tous de la dernière
    itération (n points).
    """

    T: np.ndarray
    P: np.ndarray
    n_iter: int
    converged: bool
    iterates: np.ndarray
    xi: np.ndarray
    steps: np.ndarray
    cost: np.ndarray
    K: np.ndarray
    S: np.ndarray
    innovation: np.ndarray


@dataclass(frozen=True, eq=False, repr=False)
class SE3FilterResult(PoseAliases, FilterResult):
    r"""Sortie de :func:`se3_iterated_filter` sur ``F`` images : le résultat commun
    (:class:`~kalman_course.FilterResult`), temps en premier, dont l'estimation est une pose.

    ``x`` (F, 4, 4) (alias ``T``), ``x_pred`` (alias ``T_pred``) : poses a posteriori et prédites ;
    ``P``, ``P_pred`` (F, 6, 6) : covariances dans l'espace tangent à droite ; ``K`` (F, 6, 2N),
    ``innovation`` (F, 2N), ``S`` (F, 2N, 2N) : ceux de la dernière linéarisation de chaque correction
    (les outils de cohérence, NIS et blancheur, s'y appliquent) ; ``observed`` (F, 2N) ; ``n_iter`` (F,)."""


@dataclass(frozen=True, eq=False)
class CameraPoseModel:
    r"""Le modèle de l'EKF itéré sur SE(3) : pose :math:`T_{k+1} = T_k\,\mathrm{Exp}(u_k + w_k)`,
    :math:`w_k \sim \mathcal N(0, Q)`, mesure :math:`y = h(T) + v`, :math:`v \sim \mathcal N(0, \sigma^2 I_{2N})`
    (pixels des ``N`` points connus ``points`` (N, 3) vus par ``camera``).

    ``sigma_px`` : écart-type du bruit de pixel (px) ; ``Q`` (6, 6) : covariance du bruit d'incrément
    (``None`` : nulle). ``n_obs`` = 2N, ``n_control`` = 6 (incréments :math:`u_k = [\rho;\theta]`). C'est le
    premier argument de :func:`se3_iterated_filter`, comme le modèle de tous les filtres du paquet."""

    points: np.ndarray
    camera: PinholeCamera
    sigma_px: float
    Q: np.ndarray | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "points", as_points("points", self.points))
        object.__setattr__(self, "camera", _check_camera(self.camera))
        object.__setattr__(self, "sigma_px", _check_sigma(self.sigma_px))
        Q = np.zeros((6, 6)) if self.Q is None else check_psd("Q", as_square_matrix("Q", self.Q, 6))
        Q = np.array(Q, dtype=float)
        Q.setflags(write=False)
        object.__setattr__(self, "Q", Q)

    @property
    def n_state(self) -> int:
        """Dimension de l'espace tangent (6)."""
        return 6

    @property
    def n_obs(self) -> int:
        """Dimension de la mesure (2N)."""
        return 2 * self.points.shape[0]

    @property
    def n_control(self) -> int:
        """Dimension de l'incrément de commande (6)."""
        return 6


# --------------------------------------------------------------------------- vérifications


def _check_sigma(sigma_px: Any) -> float:
    try:
        s = float(sigma_px)
    except (TypeError, ValueError):
        s = float("nan")
    if not (np.isfinite(s) and s > 0):
        raise KalmanInputError(
            f"« sigma_px » (écart-type du bruit de pixel) doit être un réel > 0 en pixels ; reçu {sigma_px!r}."
        )
    return s


def _check_update_inputs(T_pred, P_pred, y, points, camera, sigma_px):
    T = as_pose("T_pred", T_pred)
    P = check_pd("P_pred", as_square_matrix("P_pred", P_pred, 6))
    pts = as_points("points", points)
    cam = _check_camera(camera)
    y_arr = as_float_array("y", y)
    if y_arr.shape != (2 * pts.shape[0],):
        raise KalmanInputError(
            f"« y » doit empiler les pixels des {pts.shape[0]} points, [u₁, v₁, …, u_N, v_N], forme "
            f"({2 * pts.shape[0]},) ; reçu {shape_text(y_arr.shape)}."
        )
    return T, P, y_arr, pts, cam, _check_sigma(sigma_px)


# --------------------------------------------------------------------------- noyaux


def _cost(T, T_pred_inv, cP, y, points, camera, sigma):
    xi = _se3_log(T_pred_inv @ T)
    r = y - _measure(T, points, camera)
    return 0.5 * float(xi.dot(scipy.linalg.cho_solve(cP, xi))) + 0.5 * float(r.dot(r)) / sigma**2


def _linearizer(y, points, camera, sigma, idx=None):
    r"""``linearize(T_i)`` pour Gauss–Newton : résidu :math:`y - h(T_i)`, jacobienne à droite, :math:`R = \sigma^2 I`."""
    R = sigma**2 * np.eye(y.size)

    def linearize(T_i):
        h = _measure(T_i, points, camera)
        H = _measurement_jacobian(T_i, points, camera, "right")
        if idx is not None:
            h, H = h[idx], H[idx]
        return y - h, H, R

    return linearize


def _iekf(T_pred, P_pred, y, points, camera, sigma, max_iter, tol, use_right_jacobian=True):
    space = SE3_SPACE if use_right_jacobian else StateSpace(_se3_oplus, _se3_ominus, None, _transport)
    c = gauss_newton_update(T_pred, P_pred, _linearizer(y, points, camera, sigma), space, max_iter, tol)
    T_pred_inv = _se3_inverse(T_pred)
    cP = (cholesky_factor(P_pred, "P_pred", "définie positive pour évaluer le coût MAP"), True)
    xis = np.array([_se3_log(T_pred_inv @ T_i) for T_i in c.iterates])
    costs = np.array([_cost(T_i, T_pred_inv, cP, y, points, camera, sigma) for T_i in c.iterates])
    return SE3Update(
        T=c.x, P=c.P, n_iter=c.n_iter, converged=c.converged, iterates=c.iterates,
        xi=xis, steps=c.steps, cost=costs, K=c.K, S=c.S, innovation=c.innovation,
    )


# --------------------------------------------------------------------------- étapes publiques


def se3_predict(T: Any, P: Any, u: Any, Q: Any) -> SE3Prediction:
    r"""Prédiction sur SE(3) pour :math:`T_{k+1} = T_k\,\mathrm{Exp}(u_k + w_k)`, :math:`w_k \sim \mathcal N(0, Q)`.

    .. math::

        \hat T_{k+1\mid k} = \hat T_{k\mid k}\,\mathrm{Exp}(u_k),\qquad
        P_{k+1\mid k} = F P_{k\mid k} F^T + G Q G^T,\qquad
        F = \mathrm{Ad}_{\mathrm{Exp}(u_k)}^{-1},\quad G = \mathcal J_r(u_k).

    Paramètres : ``T`` (4, 4), ``P`` (6, 6) covariance, ``u`` (6,) incrément connu :math:`[\rho;\theta]`
    (m, rad ; zéro : marche aléatoire), ``Q`` (6, 6) covariance du bruit d'incrément.
    """
    T = as_pose("T", T)
    P = check_psd("P", as_square_matrix("P", P, 6))
    u = as_vector("u", u, 6)
    Q = check_psd("Q", as_square_matrix("Q", Q, 6))
    E = _se3_exp(u)
    F = _se3_adjoint(_se3_inverse(E))
    G = _se3_jl(-u)
    return SE3Prediction(T @ E, symmetrize(F @ P @ F.T + G @ Q @ G.T))


def se3_iekf_update(
    T_pred: Any,
    P_pred: Any,
    y: Any,
    points: Any,
    camera: PinholeCamera,
    sigma_px: float,
    *,
    max_iter: int = DEFAULT_MAX_ITER,
    tol: float = DEFAULT_TOL,
    use_right_jacobian: bool = True,
) -> SE3Update:
    r"""Correction itérée sur SE(3) (Gauss–Newton sur le coût MAP, perturbation à droite).

    Avec :math:`T_0 = \hat T_-`, :math:`R = \sigma^2 I_{2n}`, pour :math:`i = 0, 1, \dots` :

    .. math::

        \xi_i = \mathrm{Log}(\hat T_-^{-1}T_i),\quad \mathcal J_i = \mathcal J_r(\xi_i),\quad
        P_i = \mathcal J_iP_-\mathcal J_i^T,\quad H_i = \frac{\partial h}{\partial\delta}\Big|_{T_i},\quad
        r_i = y - h(T_i),

        K_i = P_iH_i^T(H_iP_iH_i^T + R)^{-1},\quad \delta_i = -\xi_i + K_i(r_i + H_i\xi_i),\quad
        T_{i+1} = T_i\,\mathrm{Exp}(\delta_i),

    arrêt quand :math:`\lVert\delta_i\rVert <` ``tol`` ou après ``max_iter`` itérations ; puis
    :math:`P_+ = \mathcal J_r(\delta_{N-1})(I - K_{N-1}H_{N-1})P_{N-1}\mathcal J_r(\delta_{N-1})^T`.
    ``max_iter=1`` donne l'EKF sur la variété. ``use_right_jacobian=False`` remplace :math:`\mathcal J_i`
    par :math:`I` (simplification courante, qui déplace légèrement le point fixe hors du MAP).

    Paramètres : ``T_pred`` (4, 4), ``P_pred`` (6, 6) définie positive, ``y`` (2n,) pixels
    :math:`[u_1, v_1, \dots]`, ``points`` (n, 3) points connus de la cible (m), ``camera``
    (:class:`~kalman_course.geometry.camera.PinholeCamera`), ``sigma_px`` (px).
    Renvoie :class:`SE3Update` (pose, covariance, nombre d'itérations et historique).
    """
    max_iter, tol = check_iterations(max_iter, tol)
    T, P, y_arr, pts, cam, sigma = _check_update_inputs(T_pred, P_pred, y, points, camera, sigma_px)
    return _iekf(T, P, y_arr, pts, cam, sigma, max_iter, tol, bool(use_right_jacobian))


def se3_ekf_update(T_pred: Any, P_pred: Any, y: Any, points: Any, camera: PinholeCamera, sigma_px: float) -> SE3Update:
    r"""EKF sur la variété : une seule itération de :func:`se3_iekf_update` (:math:`\xi_0 = 0`,
    :math:`\delta_0 = K_0 r_0`, :math:`\hat T_+ = \hat T_-\mathrm{Exp}(\delta_0)`)."""
    return se3_iekf_update(T_pred, P_pred, y, points, camera, sigma_px, max_iter=1)


def se3_map_cost(T: Any, T_pred: Any, P_pred: Any, y: Any, points: Any, camera: PinholeCamera, sigma_px: float) -> float:
    r"""Coût MAP :math:`J(T) = \tfrac12\lVert\mathrm{Log}(\hat T_-^{-1}T)\rVert^2_{P_-^{-1}} + \tfrac1{2\sigma^2}\lVert y - h(T)\rVert^2`."""
    Tp, P, y_arr, pts, cam, sigma = _check_update_inputs(T_pred, P_pred, y, points, camera, sigma_px)
    cP = scipy.linalg.cho_factor(P, lower=True)
    return _cost(as_pose("T", T), _se3_inverse(Tp), cP, y_arr, pts, cam, sigma)


def se3_nees(T_est: Any, P: Any, T_true: Any) -> float:
    r"""NEES :math:`e^TP^{-1}e` avec :math:`e = T_{\mathrm{vrai}} \ominus \hat T = \mathrm{Log}(\hat T^{-1}T_{\mathrm{vrai}})`
    (6,) ; suit une loi :math:`\chi^2_6` si le filtre est cohérent."""
    Te = as_pose("T_est", T_est)
    P = check_pd("P", as_square_matrix("P", P, 6))
    e = _se3_log(_se3_inverse(Te) @ as_pose("T_true", T_true))
    return float(e.dot(scipy.linalg.cho_solve(scipy.linalg.cho_factor(P, lower=True), e)))


def se3_iterated_filter(
    model: CameraPoseModel,
    y: Any,
    T0: Any,
    P0: Any,
    u: Any = None,
    *,
    max_iter: int = DEFAULT_MAX_ITER,
    tol: float = DEFAULT_TOL,
) -> SE3FilterResult:
    r"""Suivi sur ``F`` images : pour chaque image ``k``, :func:`se3_predict` avec ``u[k]`` puis
    :func:`se3_iekf_update` avec ``y[k]`` (``max_iter=1`` : EKF sur la variété), par le moteur commun.

    Paramètres : ``model`` (:class:`CameraPoseModel` : points de la cible, caméra, bruit de pixel, bruit
    d'incrément :math:`Q`) ; ``y`` (F, 2n) pixels ; ``T0`` (4, 4), ``P0`` (6, 6) : estimation avant la
    première image ; ``u`` (F, 6) incréments connus (``None`` : nuls) ; ``max_iter``, ``tol`` : arrêt de
    Gauss–Newton à chaque image.
    """
    if not isinstance(model, CameraPoseModel):
        hint = ""
        if np.ndim(model) == 2:  # l'ancien ordre : les pixels d'abord
            hint = (" : le modèle vient d'abord, se3_iterated_filter(CameraPoseModel(points, camera, sigma_px, Q), "
                    "y, T0, P0, u)")
        raise KalmanInputError(f"« model » doit être un CameraPoseModel ; reçu {type(model).__name__}{hint}.")
    return run_filter(se3_family(max_iter, tol), model, y, T0, P0, u)


def _pose_prior(model: CameraPoseModel, T0: Any, P0: Any):
    return as_pose("T0", T0), check_psd("P0", as_square_matrix("P0", P0, 6))


def se3_family(max_iter: int = DEFAULT_MAX_ITER, tol: float = DEFAULT_TOL) -> FilterFamily:
    r"""Les étapes de l'EKF itéré sur SE(3) pour le moteur (état interne :math:`(\hat T, P)`)."""
    max_iter, tol = check_iterations(max_iter, tol)

    def predict_step(model: CameraPoseModel, state, u):
        T, P = state
        if u is None:
            return T, symmetrize(P + model.Q)
        E = _se3_exp(u)
        F = _se3_adjoint(_se3_inverse(E))
        G = _right_jacobian(u)
        return T @ E, symmetrize(F @ P @ F.T + G @ model.Q @ G.T)

    def update_step(model: CameraPoseModel, state, y, idx):
        T_pred, P_pred = state
        linearize = _linearizer(y, model.points, model.camera, model.sigma_px, idx)
        c = gauss_newton_update(T_pred, P_pred, linearize, SE3_SPACE, max_iter, tol)
        return (c.x, c.P), Correction(c.K, c.innovation, c.S, c.n_iter)

    return FilterFamily(
        name="EKF itéré sur SE(3)",
        model_type=CameraPoseModel,
        model_hint="construisez-le avec CameraPoseModel(points, camera, sigma_px, Q)",
        prior=_pose_prior,
        predict=predict_step,
        update=update_step,
        moments=lambda state: state,
        result_type=SE3FilterResult,
        state_shape=lambda model: (4, 4),
        tangent_dim=lambda model: 6,
    )
