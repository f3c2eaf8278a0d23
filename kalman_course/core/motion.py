r"""Modèles de mouvement en temps continu et leur discrétisation exacte (Van Loan, 1978).

Un mobile suivi par un radar ou par ses messages ADS-B ne vit pas au rythme d'une horloge : il obéit à
une équation différentielle stochastique linéaire

.. math::

    \mathrm dx = F\,x\,\mathrm dt + L\,\mathrm d\beta,\qquad
    \mathbb E[\mathrm d\beta\,\mathrm d\beta^T] = Q_c\,\mathrm dt ,

(:math:`\beta` : mouvement brownien de densité spectrale :math:`Q_c`), et ses mesures arrivent quand elles
arrivent. Entre deux instants séparés de :math:`\Delta t`, la solution est exactement le modèle discret
du cours, :math:`x_{k} = A x_{k-1} + \phi_{k-1}`, :math:`\phi_{k-1} \sim \mathcal N(0, Q)`, avec

.. math::

    A = e^{F\Delta t},\qquad Q = \int_0^{\Delta t} e^{Fs} L Q_c L^T e^{F^Ts}\,\mathrm ds .

:func:`discretize` calcule les deux par **une seule** exponentielle de matrice (Van Loan) : avec
:math:`M = \begin{bmatrix} -F & LQ_cL^T \\ 0 & F^T \end{bmatrix}\Delta t`,
:math:`e^{M} = \begin{bmatrix} \cdot & A^{-1}Q \\ 0 & A^T \end{bmatrix}`, d'où :math:`A` et
:math:`Q = A\,(A^{-1}Q)`. Un pas irrégulier n'est qu'un :math:`\Delta t` différent : ``dt`` peut être un
vecteur, et le modèle devient variable dans le temps (matrices empilées (T, n, n), acceptées par
:class:`~kalman_course.core.models.LinearGaussianModel`).

Modèles du cours (état rangé positions d'abord, puis vitesses : :math:`[p_1, \dots, p_d, v_1, \dots, v_d]`) :

* :func:`constant_velocity` — vitesse presque constante, accélération blanche de densité :math:`q`
  (m²/s³) sur chaque axe ;
* :func:`constant_acceleration` — accélération presque constante, *jerk* blanc de densité :math:`q`
  (m²/s⁵) ;
* :func:`coordinated_turn` — virage coordonné à vitesse de rotation :math:`\omega` inconnue (état
  :math:`[p_x, p_y, v_x, v_y, \omega]`), modèle **non linéaire** : transition exacte :func:`turn_transition`.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
import scipy.linalg

from .models import LinearGaussianModel, NonlinearModel
from .validation import (
    KalmanInputError,
    as_float_array,
    as_matrix,
    as_square_matrix,
    check_pd,
    check_psd,
    shape_text,
)

__all__ = [
    "Discretized",
    "discretize",
    "time_steps",
    "constant_velocity_sde",
    "constant_acceleration_sde",
    "constant_velocity",
    "constant_acceleration",
    "constant_velocity_model",
    "turn_transition",
    "turn_jacobian",
    "coordinated_turn",
]


class Discretized(NamedTuple):
    r"""Modèle discret exact : ``A`` :math:`= e^{F\Delta t}` et ``Q`` la covariance du bruit accumulé sur le
    pas ; formes (n, n) pour un pas, (T, n, n) pour ``T`` pas."""

    A: np.ndarray
    Q: np.ndarray


def time_steps(name: str, dt: Any) -> np.ndarray:
    r"""Un pas de temps (scalaire) ou une suite de pas (T,), tous finis et strictement positifs (s).

    Renvoie un tableau de dimension 0 ou 1 ; une erreur française nomme ``name`` sinon."""
    arr = as_float_array(name, dt)
    if arr.ndim > 1 or arr.size == 0:
        raise KalmanInputError(
            f"« {name} » doit être un pas de temps (nombre > 0, en s) ou une suite de pas de forme (T,) ; "
            f"reçu {shape_text(arr.shape)}."
        )
    if not (arr > 0).all():
        bad = float(arr.min())
        raise KalmanInputError(
            f"« {name} » doit être strictement positif (durée entre deux instants) ; reçu un pas de {bad!r} s. "
            f"Des instants égaux ou en désordre ? Triez-les et fusionnez les doublons."
        )
    return arr


def discretize(F: Any, L: Any, Qc: Any, dt: Any) -> Discretized:
    r"""Discrétisation exacte de :math:`\mathrm dx = Fx\,\mathrm dt + L\,\mathrm d\beta`,
    :math:`\mathbb E[\mathrm d\beta\,\mathrm d\beta^T] = Q_c\,\mathrm dt`, sur un pas :math:`\Delta t` :

    .. math::

        A = e^{F\Delta t},\qquad Q = \int_0^{\Delta t} e^{Fs} L Q_c L^T e^{F^Ts}\,\mathrm ds ,

    par la méthode de Van Loan (1978) : une exponentielle de la matrice (2n, 2n)
    :math:`\begin{bmatrix} -F & LQ_cL^T \\ 0 & F^T \end{bmatrix}\Delta t` (``scipy.linalg.expm``) donne
    :math:`A^T` (bloc bas droit) et :math:`A^{-1}Q` (bloc haut droit).

    Paramètres
    ----------
    F : (n, n) — matrice de la dynamique continue (s⁻¹).
    L : (n, q) — gain du bruit.
    Qc : (q, q) — densité spectrale du bruit, symétrique semi-définie positive (scalaire si q = 1).
    dt : nombre > 0, ou (T,) — pas de temps (s). Un vecteur de pas donne un modèle par pas.

    Renvoie :class:`Discretized` ``(A, Q)`` : (n, n) chacune, ou (T, n, n) pour ``T`` pas.
    """
    F_arr = as_square_matrix("F", F, None)
    n = F_arr.shape[0]
    L_arr = as_float_array("L", L)
    if L_arr.ndim == 1 and L_arr.shape == (n,):
        raise KalmanInputError(
            f"« L » doit être une matrice 2-D de forme ({n}, q) ; reçu un vecteur de forme {L_arr.shape}. "
            f"Pour un seul bruit, écrivez L en colonne (forme ({n}, 1))."
        )
    L_arr = as_matrix("L", L_arr, n, None, free_cols="q")
    q = L_arr.shape[1]
    Qc_arr = check_psd("Qc", as_square_matrix("Qc", Qc, q))
    steps = time_steps("dt", dt)
    G = L_arr @ Qc_arr @ L_arr.T
    M = np.zeros((2 * n, 2 * n))
    M[:n, :n] = -F_arr
    M[:n, n:] = G
    M[n:, n:] = F_arr.T
    E = scipy.linalg.expm(M * np.atleast_1d(steps)[:, None, None])  # une exponentielle par pas, en lot
    A = np.swapaxes(E[:, n:, n:], 1, 2)
    Q = A @ E[:, :n, n:]
    Q = 0.5 * (Q + np.swapaxes(Q, 1, 2))
    if steps.ndim == 0:
        return Discretized(A[0], Q[0])
    return Discretized(A, Q)


def _dimension(dim: Any) -> int:
    if isinstance(dim, bool) or not isinstance(dim, (int, np.integer)) or not 1 <= dim <= 3:
        raise KalmanInputError(f"« dim » doit être 1, 2 ou 3 (nombre d'axes du mouvement) ; reçu {dim!r}.")
    return int(dim)


def _density(name: str, value: Any) -> float:
    arr = as_float_array(name, value)
    if arr.ndim != 0 or not arr >= 0:
        raise KalmanInputError(f"« {name} » doit être une densité spectrale (nombre ≥ 0) ; reçu {value!r}.")
    return float(arr)


def constant_velocity_sde(dim: int = 2) -> tuple[np.ndarray, np.ndarray]:
    r"""Vitesse presque constante en temps continu, état :math:`[p, v]` (positions puis vitesses) :
    :math:`\dot p = v`, :math:`\dot v = w` (accélération blanche). Renvoie ``(F, L)`` :
    :math:`F = \begin{bmatrix} 0 & I \\ 0 & 0 \end{bmatrix}`, :math:`L = \begin{bmatrix} 0 \\ I \end{bmatrix}`
    ((2d, 2d) et (2d, d))."""
    d = _dimension(dim)
    F = np.zeros((2 * d, 2 * d))
    F[:d, d:] = np.eye(d)
    L = np.zeros((2 * d, d))
    L[d:] = np.eye(d)
    return F, L


def constant_acceleration_sde(dim: int = 2) -> tuple[np.ndarray, np.ndarray]:
    r"""Accélération presque constante, état :math:`[p, v, a]` : :math:`\dot p = v`, :math:`\dot v = a`,
    :math:`\dot a = w` (*jerk* blanc). Renvoie ``(F, L)``, (3d, 3d) et (3d, d)."""
    d = _dimension(dim)
    F = np.zeros((3 * d, 3 * d))
    F[:d, d:2 * d] = np.eye(d)
    F[d:2 * d, 2 * d:] = np.eye(d)
    L = np.zeros((3 * d, d))
    L[2 * d:] = np.eye(d)
    return F, L


def constant_velocity(dt: Any, accel_psd: Any, dim: int = 2) -> Discretized:
    r"""Modèle discret exact de la vitesse presque constante, accélération blanche de densité
    :math:`q` = ``accel_psd`` (m²/s³) sur chacun des ``dim`` axes. Sur un axe :

    .. math::

        A = \begin{bmatrix} 1 & \Delta t \\ 0 & 1 \end{bmatrix},\qquad
        Q = q\begin{bmatrix} \Delta t^3/3 & \Delta t^2/2 \\ \Delta t^2/2 & \Delta t \end{bmatrix}

    (ce que redonne :func:`discretize` ; c'est le ``Q_continuous_white_noise`` de filterpy). ``dt`` : un
    pas (s) ou une suite de pas (T,). État :math:`[p_1..p_d, v_1..v_d]`."""
    F, L = constant_velocity_sde(dim)
    return discretize(F, L, _density("accel_psd", accel_psd) * np.eye(F.shape[0] // 2), dt)


def constant_acceleration(dt: Any, jerk_psd: Any, dim: int = 2) -> Discretized:
    r"""Modèle discret exact de l'accélération presque constante, *jerk* blanc de densité
    :math:`q` = ``jerk_psd`` (m²/s⁵) : sur un axe,
    :math:`Q = q\begin{bmatrix} \Delta t^5/20 & \Delta t^4/8 & \Delta t^3/6 \\ \Delta t^4/8 & \Delta t^3/3 &
    \Delta t^2/2 \\ \Delta t^3/6 & \Delta t^2/2 & \Delta t \end{bmatrix}`. État
    :math:`[p_1..p_d, v_1..v_d, a_1..a_d]`."""
    F, L = constant_acceleration_sde(dim)
    return discretize(F, L, _density("jerk_psd", jerk_psd) * np.eye(F.shape[0] // 3), dt)


def constant_velocity_model(dt: Any, accel_psd: Any, C: Any, R: Any, dim: int = 2) -> LinearGaussianModel:
    r"""Le :class:`~kalman_course.core.models.LinearGaussianModel` de la vitesse presque constante :
    :func:`constant_velocity` pour ``A`` et ``Q``, la mesure :math:`y = Cx + \psi`, :math:`\psi \sim
    \mathcal N(0, R)`. ``dt`` vecteur (T,) (instants irréguliers) : ``A`` et ``Q`` empilées (T, n, n), la
    ligne ``k`` prédit vers la mesure ``y[k]`` ; ``C`` (m, n) ou (T, m, n), ``R`` (m, m) ou (T, m, m)."""
    A, Q = constant_velocity(dt, accel_psd, dim)
    return LinearGaussianModel(A, C, Q, R)


# --------------------------------------------------------------------------- virage coordonné


def _turn_terms(w: np.ndarray, dt: float):
    r""":math:`\sin(\omega\Delta t)/\omega`, :math:`(1-\cos\omega\Delta t)/\omega`, :math:`\cos`, :math:`\sin` et
    leurs dérivées en :math:`\omega`, prolongés par continuité en :math:`\omega = 0` (développements limités)."""
    wt = w * dt
    small = np.abs(wt) < 1e-4
    safe = np.where(small, 1.0, w)
    c, s = np.cos(wt), np.sin(wt)
    a = np.where(small, dt * (1 - wt**2 / 6), s / safe)                 # sin(ωΔt)/ω
    b = np.where(small, dt * (wt / 2 - wt**3 / 24), (1 - c) / safe)      # (1 − cos ωΔt)/ω
    da = np.where(small, -dt**3 * w / 3, (dt * c * safe - s) / safe**2)  # d/dω sin(ωΔt)/ω
    db = np.where(small, dt**2 / 2 - dt**4 * w**2 / 8, (dt * s * safe - (1 - c)) / safe**2)
    return a, b, c, s, da, db


def turn_transition(x: Any, dt: float) -> np.ndarray:
    r"""Transition exacte du virage coordonné sur :math:`\Delta t`, état :math:`[p_x, p_y, v_x, v_y, \omega]`
    (m, m/s, rad/s) : la vitesse tourne de :math:`\omega\Delta t` à norme constante,

    .. math::

        p^+ = p + \begin{bmatrix} \tfrac{\sin\omega\Delta t}{\omega} & -\tfrac{1-\cos\omega\Delta t}{\omega} \\
        \tfrac{1-\cos\omega\Delta t}{\omega} & \tfrac{\sin\omega\Delta t}{\omega}\end{bmatrix} v,\qquad
        v^+ = \begin{bmatrix} \cos\omega\Delta t & -\sin\omega\Delta t \\ \sin\omega\Delta t & \cos\omega\Delta t
        \end{bmatrix} v,\qquad \omega^+ = \omega

    (la ligne droite à :math:`\omega = 0`, par continuité). ``x`` : (5,) ou une pile (N, 5)."""
    X = np.asarray(x, dtype=float)
    px, py, vx, vy, w = (X[..., i] for i in range(5))
    a, b, c, s, _, _ = _turn_terms(w, dt)
    return np.stack([px + a * vx - b * vy, py + b * vx + a * vy, c * vx - s * vy, s * vx + c * vy, w], axis=-1)


def turn_jacobian(x: Any, dt: float) -> np.ndarray:
    r"""Jacobienne :math:`\partial f/\partial x` (5, 5) de :func:`turn_transition` en ``x`` (5,)."""
    px, py, vx, vy, w = np.asarray(x, dtype=float)
    a, b, c, s, da, db = (float(t) for t in _turn_terms(np.asarray(w), dt))
    return np.array([
        [1.0, 0.0, a, -b, da * vx - db * vy],
        [0.0, 1.0, b, a, db * vx + da * vy],
        [0.0, 0.0, c, -s, -dt * (s * vx + c * vy)],
        [0.0, 0.0, s, c, dt * (c * vx - s * vy)],
        [0.0, 0.0, 0.0, 0.0, 1.0],
    ])


def coordinated_turn(dt: Any, accel_psd: Any, turn_psd: Any, R: Any) -> NonlinearModel:
    r"""Le virage coordonné comme :class:`~kalman_course.core.models.NonlinearModel` (pas ``dt`` fixe) :
    transition exacte :func:`turn_transition` et sa jacobienne, mesure de la position
    :math:`y = [p_x, p_y] + \psi`, :math:`\psi \sim \mathcal N(0, R)` (R (2, 2)).

    Bruit d'état : accélération blanche de densité ``accel_psd`` (m²/s³) sur chaque axe, comme
    :func:`constant_velocity`, et vitesse de rotation en marche aléatoire de densité ``turn_psd``
    (rad²/s³) : :math:`Q = \operatorname{diag}(Q_{cv}, q_\omega\Delta t)` (l'approximation usuelle, qui
    ignore le couplage entre rotation et position pendant le pas)."""
    h = float(time_steps("dt", dt))
    _, Q_cv = constant_velocity(h, accel_psd, 2)
    Q = np.zeros((5, 5))
    Q[:4, :4] = Q_cv
    Q[4, 4] = _density("turn_psd", turn_psd) * h
    R_arr = check_pd("R", as_square_matrix("R", R, 2))
    C = np.zeros((2, 5))
    C[0, 0] = C[1, 1] = 1.0
    return NonlinearModel(
        lambda x, u: turn_transition(x, h),
        lambda x: x[..., :2] if np.ndim(x) > 1 else np.asarray(x)[:2],
        Q,
        R_arr,
        f_jacobian=lambda x, u: turn_jacobian(x, h),
        h_jacobian=C,
        vectorized=True,
    )
