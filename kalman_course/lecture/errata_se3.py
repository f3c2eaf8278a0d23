r"""Les formules des notes « IEKF sur SE(3) » **telles qu'écrites** (fausses), pour montrer les errata 004-*.

Ne pas utiliser pour filtrer : la forme correcte est :func:`kalman_course.filters.se3.se3_iekf_update`.

* :func:`notes_residual` — erratum 004-2 : :math:`e = [u - f_xX'/Z' + c_x;\ v - f_yY'/Z' + c_y]` (signe de
  :math:`c_x, c_y`).
* :func:`notes_point_jacobian` — erratum 004-3 : :math:`\partial P'/\partial\delta` (perturbation à gauche)
  dont la 3ᵉ ligne imprimée est :math:`[0\ 0\ 1\ Y'\ -Y'\ 0]`.
* :func:`notes_residual_jacobian` — erratum 004-4 : la matrice 2 × 6 de :math:`\partial e/\partial\delta`
  écrite dans les notes, 6ᵉ colonne de la 2ᵉ ligne rétablie (``restore_missing=True``) ou nulle.
* :func:`notes_literal_iterates` — erratum 004-9 : :math:`x^{i+1} = x^i \oplus K^i(z - h(x^i))` avec
  :math:`K^i = P^-H_i^T(H_iP^-H_i^T + R)^{-1}` : l'a priori est oublié, la boucle converge vers
  l'ajustement aux seules mesures.
* :func:`embedded_step` — erratum 004-12 : le pas de Gauss–Newton sur les résidus empilés, pondérés par
  les racines matricielles :math:`P^{-1/2}, R^{-1/2}` (``weights="whitened"``, égal au pas de l'EKF itéré)
  ou par les scalaires des notes :math:`\alpha = \beta = 1/\mathrm{tr}(R)` (``weights="notes"``).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.linalg

from ..geometry.camera import PinholeCamera, _check_camera, _measure, _measurement_jacobian, _transform, as_points
from ..core.linalg import kalman_gain
from ..filters.iteration import DEFAULT_MAX_ITER, DEFAULT_TOL, iterate
from ..geometry.lie import _se3_exp, _se3_inverse, _se3_jl_inv, _se3_log, as_pose
from ..filters.se3 import _check_update_inputs
from ..core.validation import KalmanInputError

__all__ = [
    "notes_residual",
    "notes_point_jacobian",
    "notes_residual_jacobian",
    "notes_literal_iterates",
    "embedded_step",
]


def notes_residual(T: Any, points: Any, camera: PinholeCamera, y: Any) -> np.ndarray:
    r"""Résidu des notes (l. 29) : :math:`[u - f_xX'/Z' + c_x;\ v - f_yY'/Z' + c_y]` empilé (2n,)."""
    cam = _check_camera(camera)
    Pc = _transform(as_pose("T", T), as_points("points", points))
    uv = np.asarray(y, dtype=float).reshape(-1, 2)
    return np.column_stack([uv[:, 0] - cam.fx * Pc[:, 0] / Pc[:, 2] + cam.cx,
                            uv[:, 1] - cam.fy * Pc[:, 1] / Pc[:, 2] + cam.cy]).ravel()


def notes_point_jacobian(P_cam: Any, as_printed: bool = True) -> np.ndarray:
    r""":math:`\partial P'/\partial\delta` (3, 6) des notes, perturbation à gauche, :math:`P' = [X', Y', Z']`.

    ``as_printed=True`` : 3ᵉ ligne :math:`[0, 0, 1, Y', -Y', 0]` (l. 66) ; ``False`` : :math:`[0, 0, 1, Y', -X', 0]`,
    soit :math:`[I, -[P']_\times]`."""
    X, Y, Z = np.asarray(P_cam, dtype=float).reshape(3)
    return np.array([[1.0, 0, 0, 0, Z, -Y], [0, 1.0, 0, -Z, 0, X], [0, 0, 1.0, Y, -Y if as_printed else -X, 0]])


def notes_residual_jacobian(P_cam: Any, camera: PinholeCamera, restore_missing: bool = True) -> np.ndarray:
    r"""La matrice 2 × 6 :math:`\partial e/\partial\delta` des notes (l. 36), :math:`e = u - \pi(P')`,
    perturbation à gauche, :math:`\delta = [\rho;\phi]` :

    .. math::

        \begin{bmatrix} -\frac{f_x}{Z'} & 0 & \frac{f_xX'}{Z'^2} & \frac{f_xX'Y'}{Z'^2} & -f_x-\frac{f_xX'^2}{Z'^2} & \frac{f_xY'}{Z'}\\
        0 & -\frac{f_y}{Z'} & \frac{f_yY'}{Z'^2} & f_y+\frac{f_yY'^2}{Z'^2} & -\frac{f_yX'Y'}{Z'^2} & -\frac{f_yX'}{Z'}\end{bmatrix}

    ``restore_missing=False`` laisse la 6ᵉ entrée de la 2ᵉ ligne vide (0), comme dans les notes."""
    cam = _check_camera(camera)
    X, Y, Z = np.asarray(P_cam, dtype=float).reshape(3)
    fx, fy = cam.fx, cam.fy
    return np.array([
        [-fx / Z, 0.0, fx * X / Z**2, fx * X * Y / Z**2, -fx - fx * X**2 / Z**2, fx * Y / Z],
        [0.0, -fy / Z, fy * Y / Z**2, fy + fy * Y**2 / Z**2, -fy * X * Y / Z**2, -fy * X / Z if restore_missing else 0.0],
    ])


def notes_literal_iterates(
    T_pred: Any, P_pred: Any, y: Any, points: Any, camera: PinholeCamera, sigma_px: float,
    max_iter: int = DEFAULT_MAX_ITER, tol: float = DEFAULT_TOL,
) -> np.ndarray:
    r"""Boucle des notes (l. 58–64), inverse du gain rétablie (004-8) et « + » lu comme :math:`\oplus` :
    :math:`T_{i+1} = T_i\,\mathrm{Exp}\big(K_i(y - h(T_i))\big)`, :math:`K_i = P_-H_i^T(H_iP_-H_i^T + R)^{-1}`.
    Renvoie les itérés (N+1, 4, 4)."""
    T, P, y_arr, pts, cam, sigma = _check_update_inputs(T_pred, P_pred, y, points, camera, sigma_px)
    R = sigma**2 * np.eye(y_arr.size)

    def step(T_i):
        K = kalman_gain(P, _measurement_jacobian(T_i, pts, cam, "right"), R)[0]
        d = K @ (y_arr - _measure(T_i, pts, cam))
        return T_i @ _se3_exp(d), float(np.linalg.norm(d)), None

    return iterate(T, step, max_iter, tol).iterates


def embedded_step(
    T_i: Any, T_pred: Any, P_pred: Any, y: Any, points: Any, camera: PinholeCamera, sigma_px: float,
    weights: str = "whitened",
) -> np.ndarray:
    r"""Pas de Gauss–Newton :math:`\delta` (6,) sur les résidus empilés de la forme « embarquée » des notes,

    .. math::

        r(\delta) = \begin{bmatrix} W_P\,(\xi_i + \mathcal J_r^{-1}(\xi_i)\delta) \\ W_R\,(r_i - H_i\delta)\end{bmatrix},
        \qquad \delta = \arg\min \lVert r(\delta)\rVert^2,

    avec ``weights="whitened"`` : :math:`W_P = L_P^{-1}` (:math:`P_- = L_PL_P^T`), :math:`W_R = R^{-1/2} = I/\sigma`
    (égal au pas :math:`\delta_i` de l'EKF itéré) ; ``weights="notes"`` : :math:`W_P = \sqrt\alpha\,I`,
    :math:`W_R = \sqrt\beta\,I`, :math:`\alpha = \beta = 1/\mathrm{tr}(R)` (l. 90)."""
    if weights not in ("whitened", "notes"):
        raise KalmanInputError(f"« weights » doit valoir \"whitened\" ou \"notes\" ; reçu {weights!r}.")
    Tp, P, y_arr, pts, cam, sigma = _check_update_inputs(T_pred, P_pred, y, points, camera, sigma_px)
    Ti = as_pose("T_i", T_i)
    xi = _se3_log(_se3_inverse(Tp) @ Ti)
    Jinv = _se3_jl_inv(-xi)  # J_r^{-1}(ξ) = J_l^{-1}(−ξ)
    H = _measurement_jacobian(Ti, pts, cam, "right")
    r = y_arr - _measure(Ti, pts, cam)
    if weights == "whitened":
        LP = np.linalg.cholesky(P)
        WP = scipy.linalg.solve_triangular(LP, np.eye(6), lower=True)
        WR = 1.0 / sigma
    else:
        a = 1.0 / (sigma**2 * y_arr.size)  # 1/tr(R), R = σ² I
        WP = np.sqrt(a) * np.eye(6)
        WR = np.sqrt(a)
    # r(δ) = b + A δ  →  δ = argmin ‖A δ + b‖²
    A = np.vstack([WP @ Jinv, -WR * H])
    b = np.concatenate([WP @ xi, WR * r])
    return scipy.linalg.lstsq(A, -b)[0]
