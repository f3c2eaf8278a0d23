r"""EKF et EKF itéré sur SE(3) : pose d'une cible connue vue par une caméra à sténopé.

État : la pose :math:`T \in SE(3)` (repère de la cible dans celui de la caméra) et une covariance
:math:`P` (6, 6) dans l'espace tangent **à droite** : :math:`T = \hat T\,\mathrm{Exp}(\delta)`,
:math:`\delta \sim \mathcal N(0, P)`, :math:`\delta = [\rho;\theta]` (m, rad).

* Prédiction (:func:`se3_predict`) : :math:`\hat T_{k+1\mid k} = \hat T_{k\mid k}\mathrm{Exp}(u_k)`,
  :math:`P_{k+1\mid k} = FPF^T + GQG^T`, :math:`F = \mathrm{Ad}_{\mathrm{Exp}(u_k)}^{-1}`, :math:`G = \mathcal J_r(u_k)`.
* Correction itérée (:func:`se3_iekf_update`) : Gauss–Newton sur le coût MAP
  :math:`J(T) = \tfrac12\lVert\mathrm{Log}(\hat T_-^{-1}T)\rVert^2_{P_-^{-1}} + \tfrac12\lVert y - h(T)\rVert^2_{R^{-1}}`.
  Une seule itération est l'EKF sur la variété (:func:`se3_ekf_update`).

Le gain et la covariance corrigée viennent de :func:`kalman_course.kf._correct` (le même code que le
filtre linéaire). Ce module n'importe pas matplotlib.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
import scipy.linalg

from .camera import PinholeCamera, _check_camera, _measure, _measurement_jacobian, as_points
from .ekf import _check_iterations
from .kf import _correct, _symmetrize
from .lie import (
    _se3_adjoint,
    _se3_exp,
    _se3_inverse,
    _se3_jl,
    _se3_log,
    as_pose,
)
from .results import freeze_fields
from .validation import KalmanInputError, as_float_array, as_square_matrix, as_vector, check_pd, check_psd

__all__ = [
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

DEFAULT_MAX_ITER = 20
DEFAULT_TOL = 1e-10


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
    ``cost`` (N+1,) : :math:`J(T_i)` ; ``K`` (6, 2n) et ``S`` (2n, 2n) : gain et covariance d'innovation
    de la dernière itération ; ``innovation`` (2n,) : :math:`y - h(\hat T_-)` (n points).
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


@dataclass(frozen=True, eq=False)
class SE3FilterResult:
    r"""Sortie de :func:`se3_iterated_filter` sur ``F`` images (temps en premier).

    ``T`` (F, 4, 4), ``P`` (F, 6, 6) : a posteriori ; ``T_pred``, ``P_pred`` : prédictions ;
    ``n_iter`` (F,) : itérations de la correction à chaque image."""

    T: np.ndarray
    P: np.ndarray
    T_pred: np.ndarray
    P_pred: np.ndarray
    n_iter: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, "T", "P", "T_pred", "P_pred")
        n = np.array(self.n_iter, dtype=int, copy=True)
        n.setflags(write=False)
        object.__setattr__(self, "n_iter", n)

    @property
    def n_steps(self) -> int:
        """Nombre d'images ``F``."""
        return self.T.shape[0]


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
            f"({2 * pts.shape[0]},) ; reçu la forme {y_arr.shape}."
        )
    return T, P, y_arr, pts, cam, _check_sigma(sigma_px)


# --------------------------------------------------------------------------- noyaux


def _cost(T, T_pred_inv, cP, y, points, camera, sigma):
    xi = _se3_log(T_pred_inv @ T)
    r = y - _measure(T, points, camera)
    return 0.5 * float(xi.dot(scipy.linalg.cho_solve(cP, xi))) + 0.5 * float(r.dot(r)) / sigma**2


def _iekf(T_pred, P_pred, y, points, camera, sigma, max_iter, tol, use_right_jacobian=True):
    R = sigma**2 * np.eye(y.size)
    T_pred_inv = _se3_inverse(T_pred)
    cP = scipy.linalg.cho_factor(P_pred, lower=True)
    T_i = T_pred
    iterates, xis, steps, costs = [T_pred], [], [], []
    converged = False
    nu0 = None
    for _ in range(max_iter):
        xi = _se3_log(T_pred_inv @ T_i)
        J = _se3_jl(-xi) if use_right_jacobian else np.eye(6)
        P_i = _symmetrize(J @ P_pred @ J.T)
        H = _measurement_jacobian(T_i, points, camera, "right")
        r = y - _measure(T_i, points, camera)
        if nu0 is None:
            nu0 = r
        xis.append(xi)
        costs.append(_cost(T_i, T_pred_inv, cP, y, points, camera, sigma))
        # correction linéaire de l'a priori δ ~ N(−ξ_i, P_i) par la « mesure » r_i + H_i ξ_i
        delta, P_post, K, S = _correct(-xi, P_i, r + H @ xi, H, R, False)
        T_i = T_i @ _se3_exp(delta)
        iterates.append(T_i)
        steps.append(delta)
        if float(np.linalg.norm(delta)) < tol:
            converged = True
            break
    xis.append(_se3_log(T_pred_inv @ T_i))
    costs.append(_cost(T_i, T_pred_inv, cP, y, points, camera, sigma))
    Jd = _se3_jl(-delta)  # transport de l'espace tangent en T_{N-1} vers T_N : J_r(δ_{N-1})
    P_plus = _symmetrize(Jd @ P_post @ Jd.T)
    return SE3Update(
        T=T_i, P=P_plus, n_iter=len(steps), converged=converged, iterates=np.array(iterates),
        xi=np.array(xis), steps=np.array(steps), cost=np.array(costs), K=K, S=S, innovation=nu0,
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
    return SE3Prediction(T @ E, _symmetrize(F @ P @ F.T + G @ Q @ G.T))


def se3_iekf_update(
    T_pred: Any,
    P_pred: Any,
    y: Any,
    points: Any,
    camera: PinholeCamera,
    sigma_px: float,
    max_iter: int = DEFAULT_MAX_ITER,
    tol: float = DEFAULT_TOL,
    *,
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
    (:class:`~kalman_course.camera.PinholeCamera`), ``sigma_px`` (px).
    Renvoie :class:`SE3Update` (pose, covariance, nombre d'itérations et historique).
    """
    max_iter, tol = _check_iterations(max_iter, tol)
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
    y: Any,
    T0: Any,
    P0: Any,
    points: Any,
    camera: PinholeCamera,
    sigma_px: float,
    u: Any = None,
    Q: Any = None,
    max_iter: int = DEFAULT_MAX_ITER,
    tol: float = DEFAULT_TOL,
) -> SE3FilterResult:
    r"""Suivi sur ``F`` images : pour chaque image ``k``, :func:`se3_predict` avec ``u[k]`` puis
    :func:`se3_iekf_update` avec ``y[k]`` (``max_iter=1`` : EKF sur la variété).

    Paramètres : ``y`` (F, 2n) pixels ; ``T0`` (4, 4), ``P0`` (6, 6) : estimation avant la première image ;
    ``u`` (F, 6) incréments connus (``None`` : nuls) ; ``Q`` (6, 6) bruit d'incrément (``None`` : nul).
    """
    max_iter, tol = _check_iterations(max_iter, tol)
    pts = as_points("points", points)
    Y = as_float_array("y", y)
    if Y.ndim != 2 or Y.shape[1] != 2 * pts.shape[0] or Y.shape[0] == 0:
        raise KalmanInputError(
            f"« y » doit être de forme (F, {2 * pts.shape[0]}) : une ligne de pixels par image ; "
            f"reçu la forme {Y.shape}."
        )
    F_steps = Y.shape[0]
    if u is None:
        U = np.zeros((F_steps, 6))
    else:
        U = as_float_array("u", u)
        if U.shape != (F_steps, 6):
            raise KalmanInputError(f"« u » doit être de forme ({F_steps}, 6) ; reçu la forme {U.shape}.")
    Qm = np.zeros((6, 6)) if Q is None else check_psd("Q", as_square_matrix("Q", Q, 6))
    T = as_pose("T0", T0)
    P = check_psd("P0", as_square_matrix("P0", P0, 6))
    cam = _check_camera(camera)
    sigma = _check_sigma(sigma_px)
    out_T, out_P, out_Tp, out_Pp, n_iter = [], [], [], [], []
    for k in range(F_steps):
        Tp, Pp = se3_predict(T, P, U[k], Qm)
        res = _iekf(Tp, check_pd("P_pred", Pp), Y[k], pts, cam, sigma, max_iter, tol)
        T, P = res.T, res.P
        out_T.append(T)
        out_P.append(P)
        out_Tp.append(Tp)
        out_Pp.append(Pp)
        n_iter.append(res.n_iter)
    return SE3FilterResult(T=np.array(out_T), P=np.array(out_P), T_pred=np.array(out_Tp),
                           P_pred=np.array(out_Pp), n_iter=np.array(n_iter))
