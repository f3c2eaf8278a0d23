r"""Groupes de Lie SO(3) et SE(3) : chapeau, exponentielle, logarithme, jacobiennes, adjointe, ⊕ et ⊖.

Conventions (Solà et al., 2018 ; Barfoot, 2017) :

* pose :math:`T = \begin{bmatrix} R & t \\ 0 & 1 \end{bmatrix} \in SE(3)`, vecteur tangent
  :math:`\xi = [\rho;\ \theta] \in \mathbb R^6` (**translation d'abord**),
  :math:`\xi^\wedge = \begin{bmatrix} [\theta]_\times & \rho \\ 0 & 0 \end{bmatrix}` ;
* perturbation **à droite** (locale) : :math:`T \oplus \delta = T\,\mathrm{Exp}(\delta)`,
  :math:`T_1 \ominus T_0 = \mathrm{Log}(T_0^{-1}T_1)` ;
* avec :math:`a = \lVert\theta\rVert` :

  .. math::

      \mathrm{Exp}(\theta) = I + \tfrac{\sin a}{a}[\theta]_\times + \tfrac{1-\cos a}{a^2}[\theta]_\times^2,\qquad
      J_l(\theta) = I + \tfrac{1-\cos a}{a^2}[\theta]_\times + \tfrac{a-\sin a}{a^3}[\theta]_\times^2,\qquad
      J_r(\theta) = J_l(-\theta),

      \mathrm{Exp}(\xi) = \begin{bmatrix} \mathrm{Exp}(\theta) & J_l(\theta)\rho \\ 0 & 1 \end{bmatrix},\qquad
      \mathcal J_l(\xi) = \begin{bmatrix} J_l(\theta) & Q(\rho,\theta) \\ 0 & J_l(\theta) \end{bmatrix},\qquad
      \mathcal J_r(\xi) = \mathcal J_l(-\xi),\qquad
      \mathrm{Ad}_T = \begin{bmatrix} R & [t]_\times R \\ 0 & R \end{bmatrix}.

Les coefficients en :math:`1/a^k` sont remplacés par leur développement de Taylor quand :math:`a` est petit
(:data:`SMALL_ANGLE`), le logarithme de SO(3) traite à part les angles proches de :math:`\pi`.
Toute matrice d'entrée est vérifiée (rotation : :math:`R^TR = I`, :math:`\det R = 1` ; pose : dernière
ligne :math:`[0, 0, 0, 1]`) ; une entrée invalide lève :class:`~kalman_course.KalmanInputError`.
Ce module n'importe pas matplotlib.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..core.validation import KalmanInputError, array_text, as_float_array, as_vector, number_text, shape_text

__all__ = [
    "hat3",
    "vee3",
    "hat",
    "vee",
    "as_rotation",
    "as_pose",
    "so3_exp",
    "so3_log",
    "so3_left_jacobian",
    "so3_right_jacobian",
    "so3_left_jacobian_inv",
    "so3_right_jacobian_inv",
    "se3_exp",
    "se3_log",
    "se3_inverse",
    "se3_adjoint",
    "se3_left_jacobian",
    "se3_right_jacobian",
    "se3_left_jacobian_inv",
    "se3_right_jacobian_inv",
    "oplus",
    "ominus",
    "as_se2_pose",
    "se2_exp",
    "se2_log",
    "se2_inverse",
    "se2_adjoint",
    "se2_right_jacobian",
    "se2_left_jacobian",
]

#: En dessous de cet angle (rad), les coefficients sont calculés par leur développement de Taylor
#: (erreur de troncature en :math:`a^6` : :math:`< 10^{-18}`).
SMALL_ANGLE = 1e-3
#: Tolérance sur :math:`\lVert R^TR - I\rVert_\infty` et :math:`|\det R - 1|` pour accepter une rotation.
ROTATION_TOL = 1e-8


# --------------------------------------------------------------------------- vérifications


def as_rotation(name: str, value: Any) -> np.ndarray:
    r"""Matrice de rotation (3, 3) : :math:`R^TR = I` et :math:`\det R = +1` (à :data:`ROTATION_TOL` près)."""
    R = as_float_array(name, value)
    if R.shape != (3, 3):
        raise KalmanInputError(f"« {name} » doit être une matrice de rotation (3, 3) ; reçu {shape_text(R.shape)}.")
    err = float(np.max(np.abs(R.T @ R - np.eye(3))))
    det = float(np.linalg.det(R))
    if err > ROTATION_TOL or abs(det - 1.0) > ROTATION_TOL:
        raise KalmanInputError(
            f"« {name} » n'est pas une matrice de rotation : |RᵀR − I| max = {number_text(err, '.2g')}, det R = {number_text(det, '.6g')} "
            "(attendu RᵀR = I et det R = +1)."
        )
    return R


def as_pose(name: str, value: Any) -> np.ndarray:
    r"""Transformation rigide (4, 4) :math:`\begin{bmatrix} R & t \\ 0 & 1\end{bmatrix}`, :math:`R` rotation."""
    T = as_float_array(name, value)
    if T.shape != (4, 4):
        raise KalmanInputError(
            f"« {name} » doit être une transformation rigide (4, 4) de SE(3) ; reçu {shape_text(T.shape)}."
        )
    if np.max(np.abs(T[3] - [0.0, 0.0, 0.0, 1.0])) > ROTATION_TOL:
        raise KalmanInputError(
            f"« {name} » n'est pas une transformation rigide : sa dernière ligne doit être [0, 0, 0, 1] ; "
            f"reçu {array_text(T[3], decimals=4)}."
        )
    try:
        as_rotation(name, T[:3, :3])
    except KalmanInputError:
        raise KalmanInputError(
            f"« {name} » n'est pas une transformation rigide : son bloc T[:3, :3] n'est pas une rotation "
            f"(|RᵀR − I| max = {number_text(np.max(np.abs(T[:3, :3].T @ T[:3, :3] - np.eye(3))), '.2g')}, "
            f"det = {number_text(np.linalg.det(T[:3, :3]), '.6g')})."
        ) from None
    return T


# --------------------------------------------------------------------------- chapeau / vee


def hat3(w: Any) -> np.ndarray:
    r"""Matrice antisymétrique :math:`[w]_\times` (3, 3), telle que :math:`[w]_\times v = w \times v`."""
    w = as_vector("w", w, 3)
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def vee3(W: Any) -> np.ndarray:
    r"""Inverse de :func:`hat3` : :math:`([w]_\times)^\vee = w` (3,) (partie antisymétrique de ``W``)."""
    W = as_float_array("W", W)
    if W.shape != (3, 3):
        raise KalmanInputError(f"« W » doit être une matrice (3, 3) ; reçu {shape_text(W.shape)}.")
    return 0.5 * np.array([W[2, 1] - W[1, 2], W[0, 2] - W[2, 0], W[1, 0] - W[0, 1]])


def hat(xi: Any) -> np.ndarray:
    r""":math:`\xi^\wedge = \begin{bmatrix}[\theta]_\times & \rho\\ 0 & 0\end{bmatrix}` (4, 4) pour
    :math:`\xi = [\rho;\theta]` (6,)."""
    xi = as_vector("xi", xi, 6)
    X = np.zeros((4, 4))
    X[:3, :3] = hat3(xi[3:])
    X[:3, 3] = xi[:3]
    return X


def vee(X: Any) -> np.ndarray:
    r"""Inverse de :func:`hat` : :math:`(\xi^\wedge)^\vee = [\rho;\theta]` (6,)."""
    X = as_float_array("X", X)
    if X.shape != (4, 4):
        raise KalmanInputError(f"« X » doit être une matrice (4, 4) de se(3) ; reçu {shape_text(X.shape)}.")
    return np.concatenate([X[:3, 3], vee3(X[:3, :3])])


# --------------------------------------------------------------------------- coefficients


def _coefficients(a: float):
    r"""Renvoie :math:`(\sin a/a,\ (1-\cos a)/a^2,\ (a-\sin a)/a^3)`, par Taylor si :math:`a` est petit."""
    if a < SMALL_ANGLE:
        a2 = a * a
        return (1.0 - a2 / 6.0 + a2 * a2 / 120.0,
                0.5 - a2 / 24.0 + a2 * a2 / 720.0,
                1.0 / 6.0 - a2 / 120.0 + a2 * a2 / 5040.0)
    s, c = np.sin(a), np.cos(a)
    return s / a, (1.0 - c) / (a * a), (a - s) / (a * a * a)


def _so3_exp(theta: np.ndarray) -> np.ndarray:
    a = float(np.linalg.norm(theta))
    A, B, _ = _coefficients(a)
    W = hat3(theta)
    return np.eye(3) + A * W + B * (W @ W)


def _so3_jl(theta: np.ndarray) -> np.ndarray:
    a = float(np.linalg.norm(theta))
    _, B, C = _coefficients(a)
    W = hat3(theta)
    return np.eye(3) + B * W + C * (W @ W)


def _so3_jl_inv(theta: np.ndarray) -> np.ndarray:
    r""":math:`J_l^{-1}(\theta) = I - \tfrac12[\theta]_\times + \big(\tfrac1{a^2} - \tfrac{1+\cos a}{2a\sin a}\big)[\theta]_\times^2`."""
    a = float(np.linalg.norm(theta))
    if a < SMALL_ANGLE:
        a2 = a * a
        D = 1.0 / 12.0 + a2 / 720.0 + a2 * a2 / 30240.0
    else:
        D = 1.0 / (a * a) - (1.0 + np.cos(a)) / (2.0 * a * np.sin(a))
    W = hat3(theta)
    return np.eye(3) - 0.5 * W + D * (W @ W)


def _so3_log(R: np.ndarray) -> np.ndarray:
    cos_a = float(np.clip(0.5 * (np.trace(R) - 1.0), -1.0, 1.0))
    a = float(np.arccos(cos_a))
    w = vee3(R)  # = (sin a) n
    if a < SMALL_ANGLE:
        # a / sin a = 1 + a²/6 + 7a⁴/360
        return (1.0 + a * a / 6.0 + 7.0 * a**4 / 360.0) * w
    if np.pi - a > 1e-4:
        return (a / np.sin(a)) * w
    # près de π : sin a → 0 ; l'axe vient de la partie symétrique R + Rᵀ = 2 cos a I + 2(1 − cos a) n nᵀ
    B = 0.5 * (R + R.T) - cos_a * np.eye(3)
    j = int(np.argmax(np.diag(B)))
    n = B[:, j] / np.sqrt(B[j, j] * (1.0 - cos_a))
    n /= np.linalg.norm(n)
    if float(n.dot(w)) < 0.0:
        n = -n
    return a * n


def _barfoot_q(rho: np.ndarray, theta: np.ndarray) -> np.ndarray:
    r"""Bloc :math:`Q(\rho,\theta)` de la jacobienne à gauche de SE(3) (Barfoot, 2017)."""
    a = float(np.linalg.norm(theta))
    Th = hat3(theta)
    Up = hat3(rho)
    if a < SMALL_ANGLE:
        a2 = a * a
        c1 = 1.0 / 6.0 - a2 / 120.0 + a2 * a2 / 5040.0
        c2 = 1.0 / 24.0 - a2 / 720.0 + a2 * a2 / 40320.0
        c3 = 1.0 / 120.0 - a2 / 2520.0 + a2 * a2 / 120960.0
    else:
        s, c = np.sin(a), np.cos(a)
        c1 = (a - s) / a**3
        c2 = (a * a + 2.0 * c - 2.0) / (2.0 * a**4)
        c3 = (2.0 * a - 3.0 * s + a * c) / (2.0 * a**5)
    ThUp = Th @ Up
    UpTh = Up @ Th
    ThUpTh = ThUp @ Th
    Th2 = Th @ Th
    return (0.5 * Up
            + c1 * (ThUp + UpTh + ThUpTh)
            + c2 * (Th2 @ Up + Up @ Th2 - 3.0 * ThUpTh)
            + c3 * (ThUpTh @ Th + Th2 @ UpTh))


# --------------------------------------------------------------------------- SO(3)


def so3_exp(theta: Any) -> np.ndarray:
    r""":math:`\mathrm{Exp}(\theta) = I + \frac{\sin a}{a}[\theta]_\times + \frac{1-\cos a}{a^2}[\theta]_\times^2`
    (formule de Rodrigues), ``theta`` (3,) en rad → rotation (3, 3)."""
    return _so3_exp(as_vector("theta", theta, 3))


def so3_log(R: Any) -> np.ndarray:
    r""":math:`\mathrm{Log}(R) = \frac{a}{2\sin a}(R - R^T)^\vee`, :math:`a = \arccos\frac{\operatorname{tr}R - 1}{2}`
    (3,), :math:`\lVert\theta\rVert \le \pi` ; ``R`` (3, 3) rotation."""
    return _so3_log(as_rotation("R", R))


def so3_left_jacobian(theta: Any) -> np.ndarray:
    r""":math:`J_l(\theta) = I + \frac{1-\cos a}{a^2}[\theta]_\times + \frac{a-\sin a}{a^3}[\theta]_\times^2` (3, 3)."""
    return _so3_jl(as_vector("theta", theta, 3))


def so3_right_jacobian(theta: Any) -> np.ndarray:
    r""":math:`J_r(\theta) = J_l(-\theta)` (3, 3) : :math:`\mathrm{Exp}(\theta+\delta) \approx \mathrm{Exp}(\theta)\mathrm{Exp}(J_r(\theta)\delta)`."""
    return _so3_jl(-as_vector("theta", theta, 3))


def so3_left_jacobian_inv(theta: Any) -> np.ndarray:
    r""":math:`J_l^{-1}(\theta)` (3, 3), forme fermée."""
    return _so3_jl_inv(as_vector("theta", theta, 3))


def so3_right_jacobian_inv(theta: Any) -> np.ndarray:
    r""":math:`J_r^{-1}(\theta) = J_l^{-1}(-\theta)` (3, 3)."""
    return _so3_jl_inv(-as_vector("theta", theta, 3))


# --------------------------------------------------------------------------- SE(3)


def _se3_exp(xi: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = _so3_exp(xi[3:])
    T[:3, 3] = _so3_jl(xi[3:]) @ xi[:3]
    return T


def _se3_log(T: np.ndarray) -> np.ndarray:
    theta = _so3_log(T[:3, :3])
    return np.concatenate([_so3_jl_inv(theta) @ T[:3, 3], theta])


def _se3_inverse(T: np.ndarray) -> np.ndarray:
    Ti = np.eye(4)
    Ti[:3, :3] = T[:3, :3].T
    Ti[:3, 3] = -T[:3, :3].T @ T[:3, 3]
    return Ti


def _se3_jl(xi: np.ndarray) -> np.ndarray:
    J = np.zeros((6, 6))
    Jl = _so3_jl(xi[3:])
    J[:3, :3] = Jl
    J[3:, 3:] = Jl
    J[:3, 3:] = _barfoot_q(xi[:3], xi[3:])
    return J


def _se3_jl_inv(xi: np.ndarray) -> np.ndarray:
    Ji = _so3_jl_inv(xi[3:])
    out = np.zeros((6, 6))
    out[:3, :3] = Ji
    out[3:, 3:] = Ji
    out[:3, 3:] = -Ji @ _barfoot_q(xi[:3], xi[3:]) @ Ji
    return out


def _se3_adjoint(T: np.ndarray) -> np.ndarray:
    R = T[:3, :3]
    Ad = np.zeros((6, 6))
    Ad[:3, :3] = R
    Ad[3:, 3:] = R
    Ad[:3, 3:] = hat3(T[:3, 3]) @ R
    return Ad


def se3_exp(xi: Any) -> np.ndarray:
    r""":math:`\mathrm{Exp}(\xi) = \begin{bmatrix}\mathrm{Exp}(\theta) & J_l(\theta)\rho\\0&1\end{bmatrix}` (4, 4),
    ``xi`` = :math:`[\rho;\theta]` (6,) (m, rad)."""
    return _se3_exp(as_vector("xi", xi, 6))


def se3_log(T: Any) -> np.ndarray:
    r""":math:`\mathrm{Log}(T) = [J_l(\theta)^{-1}t;\ \theta]` (6,), :math:`\theta = \mathrm{Log}(R)` ;
    ``T`` (4, 4) transformation rigide."""
    return _se3_log(as_pose("T", T))


def se3_inverse(T: Any) -> np.ndarray:
    r""":math:`T^{-1} = \begin{bmatrix} R^T & -R^Tt \\ 0 & 1\end{bmatrix}` (4, 4)."""
    return _se3_inverse(as_pose("T", T))


def se3_adjoint(T: Any) -> np.ndarray:
    r""":math:`\mathrm{Ad}_T = \begin{bmatrix} R & [t]_\times R\\ 0 & R\end{bmatrix}` (6, 6) :
    :math:`T\,\mathrm{Exp}(\xi)\,T^{-1} = \mathrm{Exp}(\mathrm{Ad}_T\,\xi)`."""
    return _se3_adjoint(as_pose("T", T))


def se3_left_jacobian(xi: Any) -> np.ndarray:
    r""":math:`\mathcal J_l(\xi) = \begin{bmatrix} J_l(\theta) & Q(\rho,\theta)\\ 0 & J_l(\theta)\end{bmatrix}` (6, 6),
    :math:`Q` de Barfoot (2017)."""
    return _se3_jl(as_vector("xi", xi, 6))


def se3_right_jacobian(xi: Any) -> np.ndarray:
    r""":math:`\mathcal J_r(\xi) = \mathcal J_l(-\xi)` (6, 6) :
    :math:`\mathrm{Exp}(\xi + \delta) \approx \mathrm{Exp}(\xi)\,\mathrm{Exp}(\mathcal J_r(\xi)\delta)` et
    :math:`\mathrm{Log}(\mathrm{Exp}(\xi)\mathrm{Exp}(\delta)) \approx \xi + \mathcal J_r^{-1}(\xi)\delta`."""
    return _se3_jl(-as_vector("xi", xi, 6))


def se3_left_jacobian_inv(xi: Any) -> np.ndarray:
    r""":math:`\mathcal J_l^{-1}(\xi) = \begin{bmatrix} J_l^{-1} & -J_l^{-1}QJ_l^{-1}\\ 0 & J_l^{-1}\end{bmatrix}` (6, 6)."""
    return _se3_jl_inv(as_vector("xi", xi, 6))


def se3_right_jacobian_inv(xi: Any) -> np.ndarray:
    r""":math:`\mathcal J_r^{-1}(\xi) = \mathcal J_l^{-1}(-\xi)` (6, 6)."""
    return _se3_jl_inv(-as_vector("xi", xi, 6))


def oplus(T: Any, delta: Any) -> np.ndarray:
    r""":math:`T \oplus \delta = T\,\mathrm{Exp}(\delta)` (4, 4) : perturbation à droite, ``delta`` (6,)."""
    return as_pose("T", T) @ _se3_exp(as_vector("delta", delta, 6))


def ominus(T1: Any, T0: Any) -> np.ndarray:
    r""":math:`T_1 \ominus T_0 = \mathrm{Log}(T_0^{-1}T_1)` (6,) : l'écart :math:`\delta` tel que
    :math:`T_1 = T_0 \oplus \delta`."""
    return _se3_log(_se3_inverse(as_pose("T0", T0)) @ as_pose("T1", T1))


# --------------------------------------------------------------------------- SE(2)
#
# Pose plane T = [[R, p], [0, 0, 1]] (3, 3), R = Exp(θ) rotation d'angle θ, vecteur tangent
# ξ = [ρx, ρy, θ] (translation d'abord, comme pour SE(3)), ξ^ = [[θ J, ρ], [0, 0, 0]], J = [[0, −1], [1, 0]].
# Les coefficients en 1/θᵏ s'écrivent par l'angle moitié (aucune soustraction de nombres voisins),
# sauf C(θ) = (θ − sin θ)/θ², remplacé par son développement de Taylor sous SE2_TAYLOR_C.

#: En dessous de cet angle (rad), :math:`C(\theta) = (\theta - \sin\theta)/\theta^2` est calculé par son
#: développement de Taylor (troncature en :math:`\theta^9/9! < 10^{-19}`) : la forme close y perdrait
#: :math:`\varepsilon/\theta` en absolu.
SE2_TAYLOR_C = 0.05


def as_se2_pose(name: str, value: Any) -> np.ndarray:
    r"""Pose plane (3, 3) :math:`\begin{bmatrix} R & p \\ 0 & 1\end{bmatrix}` de SE(2) : dernière ligne
    :math:`[0, 0, 1]`, :math:`R^TR = I` et :math:`\det R = +1` (à :data:`ROTATION_TOL` près)."""
    T = as_float_array(name, value)
    if T.shape != (3, 3):
        raise KalmanInputError(
            f"« {name} » doit être une pose plane (3, 3) de SE(2), [[R, p], [0, 0, 1]] ; reçu {shape_text(T.shape)}."
        )
    if np.max(np.abs(T[2] - [0.0, 0.0, 1.0])) > ROTATION_TOL:
        raise KalmanInputError(
            f"« {name} » n'est pas une pose plane : sa dernière ligne doit être [0, 0, 1] ; "
            f"reçu {array_text(T[2], decimals=4)}."
        )
    R = T[:2, :2]
    err = float(np.max(np.abs(R.T @ R - np.eye(2))))
    det = float(R[0, 0] * R[1, 1] - R[0, 1] * R[1, 0])
    if err > ROTATION_TOL or abs(det - 1.0) > ROTATION_TOL:
        raise KalmanInputError(
            f"« {name} » n'est pas une pose plane : son bloc T[:2, :2] n'est pas une rotation "
            f"(|RᵀR − I| max = {number_text(err, '.2g')}, det = {number_text(det, '.6g')} ; "
            "attendu RᵀR = I et det R = +1)."
        )
    return T


def _se2_coefficients(t: float) -> tuple[float, float, float, float]:
    r""":math:`A = \sin\theta/\theta`, :math:`B = (1-\cos\theta)/\theta`, :math:`C = (\theta-\sin\theta)/\theta^2`,
    :math:`D = (1-\cos\theta)/\theta^2`, exacts à l'arrondi près pour tout :math:`\theta`."""
    a = abs(t)
    if a < SMALL_ANGLE:
        t2 = t * t
        A = 1.0 - t2 / 6.0 + t2 * t2 / 120.0
        B = t * (0.5 - t2 / 24.0 + t2 * t2 / 720.0)
        D = 0.5 - t2 / 24.0 + t2 * t2 / 720.0
    else:
        h = 0.5 * t
        s = np.sin(h)
        A = np.sin(t) / t
        B = 2.0 * s * s / t  # 1 − cos θ = 2 sin²(θ/2)
        D = B / t
    if a < SE2_TAYLOR_C:
        t2 = t * t
        C = t * (1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0 - t2 * t2 * t2 / 362880.0)
    else:
        C = (t - np.sin(t)) / (t * t)
    return float(A), float(B), float(C), float(D)


def _se2_exp(xi: np.ndarray) -> np.ndarray:
    rx, ry, t = float(xi[0]), float(xi[1]), float(xi[2])
    A, B, _, _ = _se2_coefficients(t)
    c, s = np.cos(t), np.sin(t)
    # V(θ) = [[A, −B], [B, A]]
    return np.array([[c, -s, A * rx - B * ry], [s, c, B * rx + A * ry], [0.0, 0.0, 1.0]])


def _se2_exp_many(xi: np.ndarray) -> np.ndarray:
    r""":func:`se2_exp` de chaque ligne de ``xi`` (N, 3) → (N, 3, 3), en bloc (mêmes formules, même branche de
    Taylor sous :data:`SMALL_ANGLE`)."""
    t = xi[:, 2]
    small = np.abs(t) < SMALL_ANGLE
    ts = np.where(small, 1.0, t)
    t2 = t * t
    h = np.sin(0.5 * t)
    A = np.where(small, 1.0 - t2 / 6.0 + t2 * t2 / 120.0, np.sin(t) / ts)
    B = np.where(small, t * (0.5 - t2 / 24.0 + t2 * t2 / 720.0), 2.0 * h * h / ts)
    c, s = np.cos(t), np.sin(t)
    T = np.zeros((xi.shape[0], 3, 3))
    T[:, 0, 0], T[:, 0, 1], T[:, 0, 2] = c, -s, A * xi[:, 0] - B * xi[:, 1]
    T[:, 1, 0], T[:, 1, 1], T[:, 1, 2] = s, c, B * xi[:, 0] + A * xi[:, 1]
    T[:, 2, 2] = 1.0
    return T


def _se2_log(T: np.ndarray) -> np.ndarray:
    t = float(np.arctan2(T[1, 0], T[0, 0]))
    if t <= -np.pi:  # atan2(−0, −1) = −π : on rend π, dans (−π, π]
        t = np.pi
    h = 0.5 * t
    # V(θ)⁻¹ = [[h cot h, h], [−h, h cot h]], h = θ/2
    if abs(h) < SMALL_ANGLE:
        h2 = h * h
        g = 1.0 - h2 / 3.0 - h2 * h2 / 45.0
    else:
        g = h * np.cos(h) / np.sin(h)
    px, py = float(T[0, 2]), float(T[1, 2])
    return np.array([g * px + h * py, -h * px + g * py, t])


def _se2_inverse(T: np.ndarray) -> np.ndarray:
    Ti = np.eye(3)
    Rt = T[:2, :2].T
    Ti[:2, :2] = Rt
    Ti[:2, 2] = -Rt @ T[:2, 2]
    return Ti


def _se2_adjoint(T: np.ndarray) -> np.ndarray:
    Ad = np.eye(3)
    Ad[:2, :2] = T[:2, :2]
    Ad[0, 2] = T[1, 2]   # −J p = [p_y, −p_x]
    Ad[1, 2] = -T[0, 2]
    return Ad


def _se2_jr(xi: np.ndarray) -> np.ndarray:
    rx, ry, t = float(xi[0]), float(xi[1]), float(xi[2])
    A, B, C, D = _se2_coefficients(t)
    return np.array([[A, B, C * rx - D * ry], [-B, A, D * rx + C * ry], [0.0, 0.0, 1.0]])


def se2_exp(xi: Any) -> np.ndarray:
    r""":math:`\mathrm{Exp}(\xi) = \begin{bmatrix}\mathrm{Exp}(\theta) & V(\theta)\rho\\0&1\end{bmatrix}` (3, 3),
    ``xi`` = :math:`[\rho_x, \rho_y, \theta]` (3,) (m, m, rad), avec

    .. math::

        \mathrm{Exp}(\theta) = \begin{bmatrix}\cos\theta & -\sin\theta\\ \sin\theta & \cos\theta\end{bmatrix},\qquad
        V(\theta) = \begin{bmatrix}\frac{\sin\theta}{\theta} & \frac{\cos\theta - 1}{\theta}\\
        \frac{1-\cos\theta}{\theta} & \frac{\sin\theta}{\theta}\end{bmatrix}

    (:math:`V(0) = I`, développement de Taylor pour :math:`|\theta|` petit)."""
    return _se2_exp(as_vector("xi", xi, 3))


def se2_log(T: Any) -> np.ndarray:
    r""":math:`\mathrm{Log}(T) = [V(\theta)^{-1}p;\ \theta]` (3,), :math:`\theta = \operatorname{atan2}(R_{21}, R_{11})
    \in (-\pi, \pi]`, :math:`V(\theta)^{-1} = \begin{bmatrix} h\cot h & h\\ -h & h\cot h\end{bmatrix}`,
    :math:`h = \theta/2` ; ``T`` (3, 3) pose plane."""
    return _se2_log(as_se2_pose("T", T))


def se2_inverse(T: Any) -> np.ndarray:
    r""":math:`T^{-1} = \begin{bmatrix} R^T & -R^Tp \\ 0 & 1\end{bmatrix}` (3, 3)."""
    return _se2_inverse(as_se2_pose("T", T))


def se2_adjoint(T: Any) -> np.ndarray:
    r""":math:`\mathrm{Ad}_T = \begin{bmatrix} R & -Jp\\ 0 & 1\end{bmatrix}` (3, 3),
    :math:`J = \begin{bmatrix}0 & -1\\ 1 & 0\end{bmatrix}` (donc :math:`-Jp = [p_y, -p_x]^T`) :
    :math:`T\,\mathrm{Exp}(\delta)\,T^{-1} = \mathrm{Exp}(\mathrm{Ad}_T\,\delta)`."""
    return _se2_adjoint(as_se2_pose("T", T))


def se2_right_jacobian(xi: Any) -> np.ndarray:
    r"""Jacobienne à droite (3, 3) : :math:`\mathrm{Exp}(\xi + \delta) \approx \mathrm{Exp}(\xi)\,\mathrm{Exp}(J_r(\xi)\delta)`,

    .. math::

        J_r(\xi) = \begin{bmatrix} A & B & C\rho_x - D\rho_y\\ -B & A & D\rho_x + C\rho_y\\ 0 & 0 & 1\end{bmatrix},
        \quad A = \frac{\sin\theta}{\theta},\ B = \frac{1-\cos\theta}{\theta},\
        C = \frac{\theta - \sin\theta}{\theta^2},\ D = \frac{1-\cos\theta}{\theta^2}."""
    return _se2_jr(as_vector("xi", xi, 3))


def se2_left_jacobian(xi: Any) -> np.ndarray:
    r"""Jacobienne à gauche (3, 3), :math:`J_l(\xi) = J_r(-\xi)` :
    :math:`\mathrm{Exp}(\xi + \delta) \approx \mathrm{Exp}(J_l(\xi)\delta)\,\mathrm{Exp}(\xi)`."""
    return _se2_jr(-as_vector("xi", xi, 3))
