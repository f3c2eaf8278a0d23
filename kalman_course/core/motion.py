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
  :math:`[p_x, p_y, v_x, v_y, \omega]`), modèle **non linéaire** : transition exacte :func:`turn_transition` ;
  :func:`straight_flight` — la ligne droite sur le même état (:math:`\omega^+ = 0`), l'autre régime d'un IMM
  vitesse constante / virage. Les deux acceptent un pas variable (``dt=None`` : :math:`\Delta t_k` lu dans
  la commande :math:`u_k = [\Delta t_k]`, bruit par le gain :func:`turn_noise_gain`).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

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
    "acceleration_gain",
    "turn_transition",
    "turn_jacobian",
    "coordinated_turn",
    "straight_flight",
    "turn_noise_gain",
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

    par **élévation au carré** (*scaling and squaring*) sur le couple :math:`(A, Q)` : le pas est d'abord
    divisé, :math:`h = \Delta t / 2^s` avec :math:`\lVert F\rVert_1 h \le 1/4`, puis

    .. math::

        A_h = \sum_{k\ge 0} \frac{(Fh)^k}{k!},\qquad
        Q_h = \sum_{k\ge 0} \frac{h^{k+1}}{(k+1)!}\,\mathcal L^k(G),\quad
        \mathcal L(X) = FX + XF^T,\quad G = LQ_cL^T

    (séries de Taylor de :math:`e^{Fs}` et de :math:`\int_0^h e^{\mathcal Ls}(G)\,\mathrm ds`, arrêtées quand
    le terme ne compte plus en double précision), et enfin :math:`s` fois, la composition exacte de deux pas
    égaux :

    .. math:: A_{2h} = A_h^2,\qquad Q_{2h} = A_hQ_hA_h^T + Q_h .

    Seules des exponentielles :math:`e^{Fh}` d'un petit pas apparaissent : pour un mode stable (Singer,
    Ornstein–Uhlenbeck), rien n'explose quand :math:`\Delta t` est long devant la constante de temps (la
    méthode de Van Loan, qui forme :math:`e^{-F\Delta t}`, perd alors tous ses chiffres) ; :math:`Q` reste
    une somme de termes semi-définis positifs. Mesuré (``tests/test_motion.py``) contre les formes closes
    d'Ornstein–Uhlenbeck, de la vitesse presque constante et du modèle de Singer calculées en arithmétique
    décimale à 80 chiffres : écart relatif au plus de l'ordre de :math:`10^{-14}` pour
    :math:`\Delta t/\tau` de :math:`10^{-6}` à :math:`10^{3}`.

    Paramètres
    ----------
    F : (n, n) — matrice de la dynamique continue (s⁻¹).
    L : (n, q) — gain du bruit.
    Qc : (q, q) — densité spectrale du bruit, symétrique semi-définie positive (scalaire si q = 1).
    dt : nombre > 0, ou (T,) — pas de temps (s). Un vecteur de pas donne un modèle par pas (calculés en lot).

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
    A, Q = _scaling_and_squaring(F_arr, 0.5 * (G + G.T), np.atleast_1d(steps))
    if steps.ndim == 0:
        return Discretized(A[0], Q[0])
    return Discretized(A, Q)


#: Pas réduit de l'élévation au carré : :math:`\lVert F\rVert_1 h \le` ``_THETA``.
_THETA = 0.25


def _scaling_and_squaring(F: np.ndarray, G: np.ndarray, dt: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r""":math:`(A, Q)` de :func:`discretize` pour chaque pas de ``dt`` (T,) : séries de Taylor sur le pas réduit
    :math:`h_t = \Delta t_t/2^{s_t}`, puis :math:`s_t` compositions (en lot : à chaque passe, les pas qui
    ont encore à doubler)."""
    n = F.shape[0]
    norm = float(np.abs(F).sum(axis=0).max()) if n else 0.0
    if norm > 0.0:
        s = np.maximum(0, np.ceil(np.log2(dt * norm / _THETA))).astype(int)
    else:
        s = np.zeros(dt.shape, dtype=int)
    h = np.ldexp(dt, -s)  # Δt / 2^s, exact
    T = dt.shape[0]
    Ft = F.T
    # A_h = Σ (Fh)^k / k! ; Q_h = Σ h^{k+1}/(k+1)! 𝓛^k(G), 𝓛(X) = FX + XFᵀ
    A = np.broadcast_to(np.eye(n), (T, n, n)).copy()
    Q = h[:, None, None] * G
    Fk = np.broadcast_to(np.eye(n), (T, n, n)).copy()  # (Fh)^k / k!
    Lk = np.broadcast_to(G, (T, n, n)).copy()           # 𝓛^k(G) h^{k+1}/(k+1)!, commencé à k = 0
    Lk = Lk * h[:, None, None]
    for k in range(1, 60):
        Fk = (Fk @ F) * (h / k)[:, None, None]
        Lk = (F @ Lk + Lk @ Ft) * (h / (k + 1))[:, None, None]
        A += Fk
        Q += Lk
        # arrêt quand le terme ne change plus aucun coefficient (critère par coefficient : les petits
        # coefficients, comme Δt³/3 pour un petit pas, gardent tous leurs chiffres)
        if (np.abs(Fk) <= 1e-17 * np.abs(A)).all() and (np.abs(Lk) <= 1e-17 * np.abs(Q)).all():
            break
    Q = 0.5 * (Q + np.swapaxes(Q, 1, 2))
    for i in range(int(s.max()) if T else 0):  # Q₂ₕ = A_h Q_h A_hᵀ + Q_h, A₂ₕ = A_h²
        rows = np.flatnonzero(s > i)
        Ar, Qr = A[rows], Q[rows]
        Q2 = Ar @ Qr @ np.swapaxes(Ar, 1, 2) + Qr
        Q[rows] = 0.5 * (Q2 + np.swapaxes(Q2, 1, 2))
        A[rows] = Ar @ Ar
    return A, Q


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


def constant_velocity(dt: Any, accel_psd: Any = None, dim: int = 2, *, accel_std: Any = None) -> Discretized:
    r"""Le modèle discret de la vitesse presque constante sur ``dim`` axes, état
    :math:`[p_1..p_d, v_1..v_d]` — **le** constructeur du paquet, pour ses deux bruits d'accélération :

    * ``accel_psd`` = :math:`q` (m²/s³) : accélération **blanche en temps continu** ; modèle exact pour tout
      pas (:func:`discretize`), sur un axe

      .. math::

          A = \begin{bmatrix} 1 & \Delta t \\ 0 & 1 \end{bmatrix},\qquad
          Q = q\begin{bmatrix} \Delta t^3/3 & \Delta t^2/2 \\ \Delta t^2/2 & \Delta t \end{bmatrix}

      (le ``Q_continuous_white_noise`` de filterpy) ;
    * ``accel_std`` = :math:`\sigma_a` (m/s²) : accélération **constante pendant le pas**, tirée à chaque pas
      (Bar-Shalom, Li et Kirubarajan 2001, § 6.3.2 ; ``Q_discrete_white_noise`` de filterpy) :
      :math:`x_k = Ax_{k-1} + Ga_{k-1}`, :math:`a \sim \mathcal N(0, \sigma_a^2I)`,
      :math:`G = [\tfrac{\Delta t^2}{2}I;\ \Delta t\, I]` (:func:`acceleration_gain`), :math:`Q = \sigma_a^2GG^T`.
      Raisonnable à pas fixe ; deux pas de :math:`\Delta t/2` n'y font pas un pas de :math:`\Delta t`.

    Un seul des deux est donné. ``dt`` : un pas (s) ou une suite de pas (T,) (matrices (T, n, n))."""
    if (accel_psd is None) == (accel_std is None):
        raise KalmanInputError(
            "Donnez soit « accel_psd » (accélération blanche en temps continu, m²/s³), soit « accel_std » "
            "(accélération constante pendant le pas, m/s²), et un seul : constant_velocity(dt, accel_psd) ou "
            "constant_velocity(dt, accel_std=…)."
        )
    F, L = constant_velocity_sde(dim)
    if accel_psd is not None:
        return discretize(F, L, _density("accel_psd", accel_psd) * np.eye(F.shape[0] // 2), dt)
    sigma = as_float_array("accel_std", accel_std)
    if sigma.ndim != 0 or not sigma >= 0:
        raise KalmanInputError(f"« accel_std » doit être un écart-type d'accélération (nombre ≥ 0, m/s²) ; reçu {accel_std!r}.")
    steps = time_steps("dt", dt)
    d = F.shape[0] // 2
    A = np.broadcast_to(np.eye(2 * d), steps.shape + (2 * d, 2 * d)).copy()
    A[..., :d, d:] = steps[..., None, None] * np.eye(d)
    G = acceleration_gain(steps, d)
    return Discretized(A, float(sigma) ** 2 * G @ np.swapaxes(G, -1, -2))


def acceleration_gain(dt: Any, dim: int = 2) -> np.ndarray:
    r"""Gain :math:`G = [\tfrac{\Delta t^2}{2}I_d;\ \Delta t\, I_d]` (2d, d) d'une accélération constante
    pendant le pas (voir :func:`constant_velocity`, ``accel_std``) ; (T, 2d, d) pour une suite de pas."""
    steps = time_steps("dt", dt)
    d = _dimension(dim)
    eye = np.eye(d)
    t = steps[..., None, None]
    return np.concatenate([0.5 * t**2 * eye, t * eye], axis=-2)


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


def _turn_measurement(C: Any) -> np.ndarray:
    r"""La matrice de mesure (m, 5) des modèles sur l'état du virage : :math:`[I_2\ 0]` (la position) par
    défaut ; ``C`` (m, 5) sinon (par exemple :math:`[I_4\ 0]` : positions et vitesses)."""
    if C is None:
        return np.eye(5)[:2]
    return as_matrix("C", C, None, 5)


def _command_step(u: Any) -> float:
    r"""Le pas :math:`\Delta t` (s) lu dans la commande ``u`` = :math:`[\Delta t]` d'un modèle à pas variable."""
    h = float(np.asarray(u, dtype=float).reshape(-1)[0]) if u is not None else float("nan")
    if not h > 0.0 or not np.isfinite(h):
        got = "aucune commande" if u is None else f"Δt = {h!r} s"
        raise KalmanInputError(
            "« u » doit contenir le pas de temps Δt (s, > 0) de chaque prédiction : avec dt=None, le modèle "
            f"lit son pas dans la commande, u = dt[:, None] ; reçu {got}."
        )
    return h


def turn_noise_gain(dt: float) -> np.ndarray:
    r"""Gain :math:`W(\Delta t)` (5, 5) du bruit d'état des modèles à pas variable (:func:`coordinated_turn`,
    :func:`straight_flight` avec ``dt=None``) : le bruit :math:`W\phi`, :math:`\phi \sim
    \mathcal N(0, \operatorname{diag}(q, q, q, q, q_\omega))`, a la covariance du modèle à pas fixe,
    :math:`WQW^T = \operatorname{diag}(Q_{cv}(\Delta t), q_\omega\Delta t)`. Sur chaque axe, :math:`W` est
    le facteur de Cholesky, en forme close, de la covariance de densité 1 de :func:`constant_velocity` :

    .. math::

        \begin{bmatrix} \Delta t^3/3 & \Delta t^2/2 \\ \Delta t^2/2 & \Delta t \end{bmatrix}
        = \begin{bmatrix} a & 0 \\ b & c \end{bmatrix}\begin{bmatrix} a & b \\ 0 & c \end{bmatrix},\quad
        a = \sqrt{\Delta t^3/3},\ b = \tfrac{\sqrt 3}{2}\sqrt{\Delta t},\ c = \tfrac12\sqrt{\Delta t}

    (état :math:`[p_x, p_y, v_x, v_y, \omega]`, bruit rangé de même), et :math:`\sqrt{\Delta t}` pour
    :math:`\omega`."""
    r = np.sqrt(dt)
    a, b, c = r * dt / np.sqrt(3.0), 0.5 * np.sqrt(3.0) * r, 0.5 * r
    W = np.zeros((5, 5))
    W[0, 0] = W[1, 1] = a
    W[2, 0] = W[3, 1] = b
    W[2, 2] = W[3, 3] = c
    W[4, 4] = r
    return W


def _straight_matrix(dt: float) -> np.ndarray:
    r""":math:`A_0(\Delta t)` (5, 5) de :func:`straight_flight` : vitesse constante, :math:`\omega^+ = 0`."""
    A = np.eye(5)
    A[0, 2] = A[1, 3] = dt
    A[4, 4] = 0.0
    return A


def coordinated_turn(dt: Any, accel_psd: Any, turn_psd: Any, R: Any, *, C: Any = None) -> NonlinearModel:
    r"""Le virage coordonné comme :class:`~kalman_course.core.models.NonlinearModel` : transition exacte
    :func:`turn_transition` et sa jacobienne :func:`turn_jacobian`, mesure linéaire
    :math:`y = Cx + \psi`, :math:`\psi \sim \mathcal N(0, R)`, avec par défaut :math:`C = [I_2\ 0]` (la
    position, R (2, 2)) ; ``C`` (m, 5) pour d'autres capteurs (:math:`[I_4\ 0]` : positions et vitesses).

    Bruit d'état : accélération blanche de densité ``accel_psd`` (m²/s³) sur chaque axe, comme
    :func:`constant_velocity`, et vitesse de rotation en marche aléatoire de densité ``turn_psd``
    (rad²/s³) : :math:`Q = \operatorname{diag}(Q_{cv}(\Delta t), q_\omega\Delta t)` (l'approximation
    usuelle, qui ignore le couplage entre rotation et position pendant le pas).

    ``dt`` : le pas (s), fixe ; ou ``None`` : **pas variable**, lu dans la commande
    :math:`u_k = [\Delta t_k]` (``n_control = 1`` : passez ``u = dt[:, None]`` au filtre, la ligne ``k``
    menant à la mesure ``y[k]``). Un :class:`NonlinearModel` n'a pas d'axe des temps : :math:`f(x, u)` et
    sa jacobienne lisent :math:`\Delta t` dans :math:`u`, et le bruit passe par le gain
    :math:`W(\Delta t)` = :func:`turn_noise_gain` (``f_noise_jacobian``), avec
    :math:`Q = \operatorname{diag}(q, q, q, q, q_\omega)` constante : :math:`WQW^T` est la covariance du
    pas fixe, pour chaque :math:`\Delta t`."""
    C_arr = _turn_measurement(C)
    R_arr = check_pd("R", as_square_matrix("R", R, C_arr.shape[0]))
    q, q_w = _density("accel_psd", accel_psd), _density("turn_psd", turn_psd)
    h = (lambda x: np.asarray(x).dot(C_arr.T))
    if dt is None:
        return NonlinearModel(
            lambda x, u: turn_transition(x, _command_step(u)), h, np.diag([q] * 4 + [q_w]), R_arr,
            f_jacobian=lambda x, u: turn_jacobian(x, _command_step(u)), h_jacobian=C_arr,
            f_noise_jacobian=lambda x, u: turn_noise_gain(_command_step(u)), n_state=5, n_control=1,
            vectorized=True,
        )
    step = float(time_steps("dt", dt))
    _, Q_cv = constant_velocity(step, q, 2)
    Q = np.zeros((5, 5))
    Q[:4, :4] = Q_cv
    Q[4, 4] = q_w * step
    return NonlinearModel(
        lambda x, u: turn_transition(x, step),
        h,
        Q,
        R_arr,
        f_jacobian=lambda x, u: turn_jacobian(x, step),
        h_jacobian=C_arr,
        vectorized=True,
    )


def straight_flight(dt: Any, accel_psd: Any, R: Any, *, C: Any = None) -> NonlinearModel:
    r"""La vitesse presque constante **sur l'état du virage coordonné** :math:`[p_x, p_y, v_x, v_y, \omega]` :
    le régime « ligne droite » d'un IMM vitesse constante / virage coordonné, dont les régimes doivent
    partager leur état. La vitesse de rotation y est **remise à zéro** à chaque pas :

    .. math::

        p^+ = p + \Delta t\, v,\qquad v^+ = v,\qquad \omega^+ = 0,\qquad
        Q = \operatorname{diag}(Q_{cv}(\Delta t), 0)

    (:math:`x^+ = A_0x + \phi` : linéaire, et c'est :func:`turn_transition` en :math:`\omega = 0` pour
    :math:`p` et :math:`v`). Choix : dans ce régime la cible ne tourne pas, :math:`\omega = 0` exactement
    (variance nulle) ; l'estimation combinée de l'IMM vaut alors :math:`\hat\omega = \mu_{ct}\hat\omega_{ct}`,
    et le régime virage, qui repart du mélange, voit sa vitesse de rotation tirée vers 0 tant que la ligne
    droite domine. (L'autre choix usuel, :math:`\omega^+ = \omega` gelée et inutilisée, garde une vitesse de
    rotation que rien n'observe dans ce régime.)

    Mêmes arguments que :func:`coordinated_turn` (``dt=None`` : pas lu dans la commande
    :math:`u_k = [\Delta t_k]`, bruit par le gain :func:`turn_noise_gain`, :math:`Q = \operatorname{diag}
    (q, q, q, q, 0)`). Un :class:`NonlinearModel` (linéaire en fait) pour qu'il se joigne aux régimes non
    linéaires de l'IMM, qui les veut tous constants ou tous du même type."""
    C_arr = _turn_measurement(C)
    R_arr = check_pd("R", as_square_matrix("R", R, C_arr.shape[0]))
    q = _density("accel_psd", accel_psd)
    h = (lambda x: np.asarray(x).dot(C_arr.T))
    if dt is None:
        return NonlinearModel(
            lambda x, u: np.asarray(x).dot(_straight_matrix(_command_step(u)).T), h, np.diag([q] * 4 + [0.0]),
            R_arr, f_jacobian=lambda x, u: _straight_matrix(_command_step(u)), h_jacobian=C_arr,
            f_noise_jacobian=lambda x, u: turn_noise_gain(_command_step(u)), n_state=5, n_control=1,
            vectorized=True,
        )
    step = float(time_steps("dt", dt))
    A = _straight_matrix(step)
    Q = np.zeros((5, 5))
    Q[:4, :4] = constant_velocity(step, q, 2).Q
    return NonlinearModel(lambda x, u: np.asarray(x).dot(A.T), h, Q, R_arr, f_jacobian=A, h_jacobian=C_arr,
                          vectorized=True)
