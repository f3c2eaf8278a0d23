r"""Caméra à sténopé (*pinhole*) : projection de points connus et jacobienne par rapport à la pose.

La pose :math:`T = \begin{bmatrix} R_{\mathrm{rot}} & t\\ 0 & 1\end{bmatrix}` place la cible dans le repère
de la caméra : un point connu :math:`p_i` (repère de la cible) devient
:math:`P_i' = R_{\mathrm{rot}}\,p_i + t = [X_i', Y_i', Z_i']^T` et se projette en

.. math::

    \pi(P') = \begin{bmatrix} f_x X'/Z' + c_x \\ f_y Y'/Z' + c_y \end{bmatrix},
    \qquad\text{soit}\qquad Z'\,[u;\ v;\ 1] = K_{\mathrm{cam}}\,P',\quad
    K_{\mathrm{cam}} = \begin{bmatrix} f_x & 0 & c_x\\ 0 & f_y & c_y\\ 0&0&1\end{bmatrix}.

La matrice des paramètres intrinsèques s'appelle ``K_cam`` (jamais ``K``, réservé au gain de Kalman) et
la rotation ``R_rot`` dans la prose (``R`` est la covariance du bruit de mesure). La mesure empile les
pixels des :math:`N` points : :math:`h(T) = [u_1; v_1; \dots; u_N; v_N] \in \mathbb R^{2N}`. Elle exige
:math:`Z_i' > 0` (point devant la caméra).

Jacobiennes (règle de la chaîne) :

.. math::

    \frac{\partial\pi}{\partial P'} = \begin{bmatrix} f_x/Z' & 0 & -f_xX'/Z'^2\\ 0 & f_y/Z' & -f_yY'/Z'^2\end{bmatrix},\qquad
    \frac{\partial P'}{\partial\delta}\Big|_{\text{droite}} = \begin{bmatrix} R_{\mathrm{rot}} & -R_{\mathrm{rot}}[p]_\times\end{bmatrix},\qquad
    \frac{\partial P'}{\partial\delta}\Big|_{\text{gauche}} = \begin{bmatrix} I_3 & -[P']_\times\end{bmatrix}

pour :math:`T\,\mathrm{Exp}(\delta)` (droite) et :math:`\mathrm{Exp}(\delta)\,T` (gauche), :math:`\delta = [\rho;\theta]`.
Ce module n'importe pas matplotlib.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.jacobians import JacobianCheck, numerical_jacobian
from .lie import _se3_exp, as_pose, hat3
from ..core.validation import KalmanInputError, as_float_array, number_text, shape_text

__all__ = [
    "PinholeCamera",
    "as_points",
    "transform_points",
    "project",
    "camera_measurement",
    "projection_jacobian",
    "camera_measurement_jacobian",
    "check_camera_jacobian",
]

#: Profondeur minimale (m) d'un point pour qu'il soit « devant » la caméra.
MIN_DEPTH = 1e-9


@dataclass(frozen=True)
class PinholeCamera:
    r"""Caméra à sténopé : focales ``fx``, ``fy`` (px), point principal ``cx``, ``cy`` (px), image
    ``width`` × ``height`` (px, pour les figures et :meth:`in_image`)."""

    fx: float
    fy: float
    cx: float
    cy: float
    width: int = 640
    height: int = 480

    def __post_init__(self) -> None:
        for name in ("fx", "fy", "cx", "cy"):
            value = getattr(self, name)
            try:
                v = float(value)
            except (TypeError, ValueError):
                raise KalmanInputError(f"« {name} » doit être un réel (pixels) ; reçu {value!r}.") from None
            if not np.isfinite(v):
                raise KalmanInputError(f"« {name} » doit être fini ; reçu {value!r}.")
            object.__setattr__(self, name, v)
        for name in ("fx", "fy"):
            if getattr(self, name) <= 0:
                raise KalmanInputError(
                    f"La focale « {name} » doit être strictement positive (pixels) ; reçu {getattr(self, name)!r}."
                )
        for name in ("width", "height"):
            value = getattr(self, name)
            if not isinstance(value, (int, np.integer)) or isinstance(value, bool) or value <= 0:
                raise KalmanInputError(f"« {name} » doit être un entier > 0 (pixels) ; reçu {value!r}.")
            object.__setattr__(self, name, int(value))

    @property
    def K_cam(self) -> np.ndarray:
        r"""Matrice des paramètres intrinsèques :math:`K_{\mathrm{cam}}` (3, 3)."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    intrinsics = K_cam

    def in_image(self, pixels: Any) -> np.ndarray:
        """Booléens (N,) : le pixel ``pixels[i]`` (N, 2) tombe-t-il dans l'image ?"""
        uv = np.asarray(pixels, dtype=float).reshape(-1, 2)
        return (uv[:, 0] >= 0) & (uv[:, 0] < self.width) & (uv[:, 1] >= 0) & (uv[:, 1] < self.height)


def _check_camera(camera: Any) -> PinholeCamera:
    if not isinstance(camera, PinholeCamera):
        raise KalmanInputError(f"« camera » doit être une PinholeCamera ; reçu {type(camera).__name__}.")
    return camera


def as_points(name: str, points: Any) -> np.ndarray:
    """Points 3-D connus, forme (N, 3) avec N ≥ 1 (m)."""
    P = as_float_array(name, points)
    if P.ndim != 2 or P.shape[1] != 3 or P.shape[0] == 0:
        raise KalmanInputError(
            f"« {name} » doit être un tableau de points 3-D de forme (N, 3), N ≥ 1 ; reçu {shape_text(P.shape)}."
        )
    return P


def _check_depth(P_cam: np.ndarray) -> None:
    bad = np.flatnonzero(P_cam[:, 2] <= MIN_DEPTH)
    if bad.size:
        i = int(bad[0])
        raise KalmanInputError(
            f"Le point {i} est derrière la caméra ou dans son plan (Z' = {number_text(P_cam[i, 2], '.4g')} m) : la projection "
            f"à sténopé exige Z' > 0 pour tous les points ({bad.size} point(s) en défaut). Vérifiez la pose "
            "« T » (repère de la cible dans le repère de la caméra) et les points."
        )


def _transform(T: np.ndarray, points: np.ndarray) -> np.ndarray:
    return points @ T[:3, :3].T + T[:3, 3]


def _project(camera: PinholeCamera, P_cam: np.ndarray) -> np.ndarray:
    _check_depth(P_cam)
    Z = P_cam[:, 2]
    return np.column_stack([camera.fx * P_cam[:, 0] / Z + camera.cx, camera.fy * P_cam[:, 1] / Z + camera.cy])


def _projection_jacobian(camera: PinholeCamera, P_cam: np.ndarray) -> np.ndarray:
    _check_depth(P_cam)
    X, Y, Z = P_cam[:, 0], P_cam[:, 1], P_cam[:, 2]
    J = np.zeros((P_cam.shape[0], 2, 3))
    J[:, 0, 0] = camera.fx / Z
    J[:, 0, 2] = -camera.fx * X / Z**2
    J[:, 1, 1] = camera.fy / Z
    J[:, 1, 2] = -camera.fy * Y / Z**2
    return J


def _measure(T: np.ndarray, points: np.ndarray, camera: PinholeCamera) -> np.ndarray:
    return _project(camera, _transform(T, points)).ravel()


def _measurement_jacobian(T: np.ndarray, points: np.ndarray, camera: PinholeCamera, perturbation: str):
    P_cam = _transform(T, points)
    Jpi = _projection_jacobian(camera, P_cam)
    N = points.shape[0]
    dP = np.zeros((N, 3, 6))
    if perturbation == "right":
        R = T[:3, :3]
        dP[:, :, :3] = R
        for i in range(N):
            dP[i, :, 3:] = -R @ hat3(points[i])
    else:
        dP[:, :, :3] = np.eye(3)
        for i in range(N):
            dP[i, :, 3:] = -hat3(P_cam[i])
    return np.einsum("nij,njk->nik", Jpi, dP).reshape(2 * N, 6)


def transform_points(T: Any, points: Any) -> np.ndarray:
    r""":math:`P_i' = (T\tilde p_i)_{1:3} = R_{\mathrm{rot}}p_i + t`, forme (N, 3) ; ``T`` (4, 4), ``points`` (N, 3)."""
    return _transform(as_pose("T", T), as_points("points", points))


def project(camera: PinholeCamera, points_camera: Any) -> np.ndarray:
    r"""Projection :math:`\pi(P')` de points exprimés dans le repère de la caméra : (N, 3) → pixels (N, 2).

    Lève :class:`~kalman_course.KalmanInputError` si un point a :math:`Z' \le 0`."""
    return _project(_check_camera(camera), as_points("points_camera", points_camera))


def camera_measurement(T: Any, points: Any, camera: PinholeCamera) -> np.ndarray:
    r"""Mesure sans bruit :math:`h(T) = [u_1; v_1; \dots; u_N; v_N]` (2N,) en pixels."""
    return _measure(as_pose("T", T), as_points("points", points), _check_camera(camera))


def projection_jacobian(camera: PinholeCamera, points_camera: Any) -> np.ndarray:
    r""":math:`\partial\pi/\partial P'` pour chaque point, forme (N, 2, 3)."""
    return _projection_jacobian(_check_camera(camera), as_points("points_camera", points_camera))


def camera_measurement_jacobian(
    T: Any, points: Any, camera: PinholeCamera, perturbation: str = "right"
) -> np.ndarray:
    r"""Jacobienne :math:`H = \partial h/\partial\delta` (2N, 6), :math:`\delta = [\rho;\theta]`.

    ``perturbation="right"`` : :math:`T\,\mathrm{Exp}(\delta)`, blocs
    :math:`\frac{\partial\pi}{\partial P'}\,[R_{\mathrm{rot}},\ -R_{\mathrm{rot}}[p_i]_\times]` (celle du filtre) ;
    ``"left"`` : :math:`\mathrm{Exp}(\delta)\,T`, blocs :math:`\frac{\partial\pi}{\partial P'}\,[I,\ -[P_i']_\times]`
    (celle des notes). Les deux sont liées par :math:`H^R = H^L\,\mathrm{Ad}_T`.
    """
    if perturbation not in ("right", "left"):
        raise KalmanInputError(
            f"« perturbation » doit valoir \"right\" (droite) ou \"left\" (gauche) ; reçu {perturbation!r}."
        )
    return _measurement_jacobian(as_pose("T", T), as_points("points", points), _check_camera(camera), perturbation)


def _retracted_measurement(T: np.ndarray, points: np.ndarray, camera: PinholeCamera, perturbation: str):
    """``delta ↦ h(T Exp(delta))`` (ou ``h(Exp(delta) T)``) : la fonction que la jacobienne dérive en 0."""
    if perturbation == "right":
        return lambda d: _measure(T @ _se3_exp(d), points, camera)
    return lambda d: _measure(_se3_exp(d) @ T, points, camera)


def check_camera_jacobian(
    T: Any,
    points: Any,
    camera: PinholeCamera,
    perturbation: str = "right",
    jacobian: Any = None,
    *,
    step: float = 1e-6,
    rtol: float = 1e-6,
):
    r"""Compare la jacobienne des pixels aux différences centrées **sur la rétraction** :
    :math:`\delta \mapsto h(T\,\mathrm{Exp}(\delta))` (droite) ou :math:`h(\mathrm{Exp}(\delta)\,T)` (gauche),
    dérivée en :math:`\delta = 0` avec le pas ``step`` (:func:`kalman_course.core.jacobians.numerical_jacobian`).

    ``jacobian`` (2n, 6) : la matrice à vérifier (par défaut :func:`camera_measurement_jacobian`).
    Renvoie un :class:`~kalman_course.core.jacobians.JacobianCheck` (vrai si l'écart relatif au plus grand
    élément est sous ``rtol``)."""
    if perturbation not in ("right", "left"):
        raise KalmanInputError(
            f"« perturbation » doit valoir \"right\" (droite) ou \"left\" (gauche) ; reçu {perturbation!r}."
        )
    T = as_pose("T", T)
    pts = as_points("points", points)
    cam = _check_camera(camera)
    Ja = _measurement_jacobian(T, pts, cam, perturbation) if jacobian is None else as_float_array("jacobian", jacobian)
    Jn = numerical_jacobian(_retracted_measurement(T, pts, cam, perturbation), np.zeros(6), step=step,
                            name=f"h(T ⊕ δ) ({perturbation})")
    if Ja.shape != Jn.shape:
        raise KalmanInputError(f"« jacobian » doit être de forme {Jn.shape} ; reçu {shape_text(Ja.shape)}.")
    diff = np.abs(Ja - Jn)
    worst = np.unravel_index(int(np.argmax(diff)), diff.shape)
    max_abs = float(diff.max())
    return JacobianCheck(
        name=f"pixels / perturbation {'à droite' if perturbation == 'right' else 'à gauche'}",
        analytic=Ja, numerical=Jn, max_abs_error=max_abs,
        max_rel_error=max_abs / max(1.0, float(np.abs(Jn).max())),
        worst=(int(worst[0]), int(worst[1])), rtol=float(rtol),
    )
