r"""Les deux modèles chaotiques de l'assimilation de données, intégrés par Runge–Kutta d'ordre 4 (RK4).

**Lorenz-96** (Lorenz 1996) : :math:`n` variables sur un cercle (indices modulo :math:`n`),

.. math::

    \frac{dx_i}{dt} = (x_{i+1} - x_{i-2})\,x_{i-1} - x_i + F,

advection (terme quadratique), dissipation (:math:`-x_i`) et forçage :math:`F` ; chaotique pour
:math:`F = 8`. **Lorenz-63** (Lorenz 1963) : trois variables,

.. math::

    \dot x_1 = \sigma(x_2 - x_1),\quad \dot x_2 = x_1(\rho - x_3) - x_2,\quad \dot x_3 = x_1x_2 - \beta x_3.

Chaque modèle est un :class:`~kalman_course.NonlinearModel` **vectorisé** : :math:`f(x, u)` fait
``n_substeps`` pas RK4 classiques de taille ``dt``,

.. math::

    k_1 = g(x),\ k_2 = g(x + \tfrac{dt}2k_1),\ k_3 = g(x + \tfrac{dt}2k_2),\ k_4 = g(x + dt\,k_3),\quad
    x \leftarrow x + \tfrac{dt}6(k_1 + 2k_2 + 2k_3 + k_4),

sur un état (n,) ou sur tout un ensemble (N, n) à la fois (une ligne par membre) ; :math:`h(x) = x`
(jacobienne :math:`I`), :math:`Q = 0` (modèle parfait, comme dans les expériences jumelles de DAPPER) et
:math:`R = r I` pour un scalaire :math:`r`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .models import NonlinearModel
from .simulation import check_positive_int
from .validation import KalmanInputError, as_float_array, as_square_matrix, check_pd

__all__ = ["lorenz96", "lorenz63", "lorenz96_tendency", "rk4"]


def _finite(name: str, value: Any, positive: bool = False) -> float:
    """Un réel fini (strictement positif si ``positive``), ou une :class:`KalmanInputError` qui le nomme."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise KalmanInputError(f"« {name} » doit être un nombre réel ; reçu {value!r}.")
    v = float(value)
    if not math.isfinite(v) or (positive and v <= 0):
        what = "un nombre réel strictement positif" if positive else "un nombre réel fini"
        raise KalmanInputError(f"« {name} » doit être {what} ; reçu {value!r}.")
    return v


def _noise(R: Any, n: int) -> np.ndarray:
    """:math:`R = rI` (n, n) pour un scalaire :math:`r > 0`, sinon la matrice (n, n) donnée, définie positive."""
    arr = as_float_array("R", R)
    if arr.ndim == 0:
        if arr <= 0:
            raise KalmanInputError(f"« R » doit être une variance strictement positive ou une matrice ({n}, {n}) "
                                   f"définie positive ; reçu {float(arr)!r}.")
        return float(arr) * np.eye(n)
    return check_pd("R", as_square_matrix("R", arr, n))


def lorenz96_tendency(x: np.ndarray, forcing: float = 8.0) -> np.ndarray:
    r""":math:`dx_i/dt = (x_{i+1} - x_{i-2})x_{i-1} - x_i + F` (indices modulo :math:`n`) ; ``x`` (n,) ou
    (N, n), même forme en sortie."""
    n = x.shape[-1]
    ring = np.concatenate([x[..., n - 2:], x, x[..., :1]], axis=-1)  # x_{-2}, x_{-1}, x_0 … x_{n-1}, x_n
    return (ring[..., 3:] - ring[..., :n]) * ring[..., 1:n + 1] - x + forcing


def rk4(g, x: np.ndarray, dt: float, n_substeps: int) -> np.ndarray:
    r"""``n_substeps`` pas de Runge–Kutta classique (ordre 4) de taille ``dt`` de :math:`\dot x = g(x)` ;
    ``x`` (…, n), renvoie un nouveau tableau de même forme."""
    half = 0.5 * dt
    for _ in range(n_substeps):
        k1 = g(x)
        k2 = g(x + half * k1)
        k3 = g(x + half * k2)
        k4 = g(x + dt * k3)
        x = x + (dt / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    return x


def _rk4_lorenz63(x: np.ndarray, sigma: float, rho: float, beta: float, dt: float, n_substeps: int) -> np.ndarray:
    r"""Le schéma RK4 de :func:`rk4` pour Lorenz-63, écrit composante par composante : sur un état (3,), en
    flottants Python ; sur un ensemble (N, 3), sur ses trois colonnes (tableaux (N,) contigus). Trois
    composantes ne paient ainsi ni une fonction numpy par opération (un état seul : la vérité et 3D-Var en
    font 25 000 par expérience) ni un ``np.stack`` par évaluation ; les opérations sont les mêmes, dans le
    même ordre, donc les mêmes arrondis, pour un état et pour chaque membre d'un ensemble."""
    if x.ndim == 1:
        a, b, c = float(x[0]), float(x[1]), float(x[2])
    else:
        a, b, c = (np.ascontiguousarray(x[..., i]) for i in range(3))
    half, sixth = 0.5 * dt, dt / 6.0

    def g(a, b, c):
        return sigma * (b - a), a * (rho - c) - b, a * b - beta * c

    for _ in range(n_substeps):
        p1, q1, r1 = g(a, b, c)
        p2, q2, r2 = g(a + half * p1, b + half * q1, c + half * r1)
        p3, q3, r3 = g(a + half * p2, b + half * q2, c + half * r2)
        p4, q4, r4 = g(a + dt * p3, b + dt * q3, c + dt * r3)
        a = a + sixth * (p1 + 2.0 * p2 + 2.0 * p3 + p4)
        b = b + sixth * (q1 + 2.0 * q2 + 2.0 * q3 + q4)
        c = c + sixth * (r1 + 2.0 * r2 + 2.0 * r3 + r4)
    return np.array([a, b, c]) if x.ndim == 1 else np.stack([a, b, c], axis=-1)


def _identity_model(f, n: int, R: Any) -> NonlinearModel:
    """Le modèle parfait (:math:`Q = 0`) de dynamique ``f``, observé en entier : :math:`h(x) = x`."""
    return NonlinearModel(f, lambda x: np.array(x, dtype=float), np.zeros((n, n)), _noise(R, n),
                          h_jacobian=np.eye(n), vectorized=True)


def lorenz96(n: int = 40, forcing: float = 8.0, dt: float = 0.05, *, n_substeps: int = 1,
             R: Any = 1.0) -> NonlinearModel:
    r"""Le modèle de Lorenz-96 à :math:`n` variables, intégré par RK4, observé en entier.

    Paramètres
    ----------
    n : nombre de variables (≥ 4) ; forcing : :math:`F` (8 : régime chaotique) ; dt : pas RK4 (unités de
        temps du modèle ; 0,05 ≈ 6 h d'atmosphère selon Lorenz) ; n_substeps : pas RK4 par appel de ``f``
        (un cycle d'assimilation) ; R : variance :math:`r` des erreurs d'observation (:math:`R = rI`) ou
        matrice (n, n) définie positive.

    Renvoie un :class:`~kalman_course.NonlinearModel` vectorisé : ``f(x, u)`` (n,) ou (N, n) → même forme ;
    ``h(x) = x`` ; ``Q`` nulle (n, n) ; ``R`` (n, n).
    """
    n = check_positive_int("n", n, minimum=4)
    F = _finite("forcing", forcing)
    step = _finite("dt", dt, positive=True)
    substeps = check_positive_int("n_substeps", n_substeps)

    def f(x, u=None):
        return rk4(lambda z: lorenz96_tendency(z, F), np.asarray(x, dtype=float), step, substeps)

    return _identity_model(f, n, R)


def lorenz63(sigma: float = 10.0, rho: float = 28.0, beta: float = 8.0 / 3.0, dt: float = 0.01, *,
             n_substeps: int = 25, R: Any = 2.0) -> NonlinearModel:
    r"""Le modèle de Lorenz-63, intégré par RK4, observé en entier.

    Paramètres
    ----------
    sigma, rho, beta : :math:`\sigma, \rho, \beta` (10, 28, 8/3 : l'attracteur « papillon ») ; dt : pas
        RK4 ; n_substeps : pas RK4 par appel de ``f`` (25 pas de 0,01 : un cycle de 0,25 unité de temps,
        comme Sakov 2012) ; R : variance :math:`r` des erreurs d'observation (:math:`R = rI`) ou matrice
        (3, 3) définie positive.

    Renvoie un :class:`~kalman_course.NonlinearModel` vectorisé : ``f(x, u)`` (3,) ou (N, 3) → même forme ;
    ``h(x) = x`` ; ``Q`` nulle (3, 3) ; ``R`` (3, 3).
    """
    s, r, b = _finite("sigma", sigma), _finite("rho", rho), _finite("beta", beta)
    step = _finite("dt", dt, positive=True)
    substeps = check_positive_int("n_substeps", n_substeps)

    def f(x, u=None):
        return _rk4_lorenz63(np.asarray(x, dtype=float), s, r, b, step, substeps)

    return _identity_model(f, 3, R)
