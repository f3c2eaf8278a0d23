r"""Jacobiennes numériques (différences centrées) et vérification d'une jacobienne analytique.

Une jacobienne écrite à la main est l'erreur classique d'un filtre de Kalman étendu : un signe, un
indice ou une dérivée oubliée, et le filtre « marche » quand même, mais mal. :func:`check_jacobian`
la compare aux différences centrées

.. math::

    \frac{\partial g_i}{\partial x_j}(x) \approx \frac{g_i(x + h_j e_j) - g_i(x - h_j e_j)}{2h_j},
    \qquad h_j = \varepsilon^{1/3}\max(1, |x_j|),

dont l'erreur est en :math:`O(h^2)` (troncature) plus :math:`O(\varepsilon/h)` (arrondi), soit environ
:math:`10^{-10}` en relatif pour une fonction régulière (:math:`\varepsilon \approx 2{,}2\cdot10^{-16}`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Sequence

import numpy as np

from .angles import wrap_angle
from .validation import KalmanInputError, as_float_array, as_vector, call_user_function, check_finite_output, shape_text

__all__ = ["JacobianCheck", "numerical_jacobian", "check_jacobian"]

#: Pas relatif des différences centrées : :math:`\varepsilon^{1/3}` équilibre troncature et arrondi.
CENTRAL_STEP = float(np.finfo(float).eps ** (1.0 / 3.0))


def _evaluate(func: Callable[..., Any], x: np.ndarray, args: tuple, name: str) -> np.ndarray:
    arr = np.asarray(call_user_function(name, func, x, args), dtype=float)
    if arr.ndim == 0:
        arr = arr.reshape(1)
    if arr.ndim != 1:
        raise KalmanInputError(
            f"La fonction « {name} » doit renvoyer un vecteur 1-D ; elle a renvoyé la forme {arr.shape}."
        )
    return check_finite_output(name, arr, x)


def numerical_jacobian(
    func: Callable[..., Any],
    x: Any,
    args: tuple = (),
    *,
    step: float | None = None,
    angle_indices: Sequence[int] = (),
    name: str = "func",
) -> np.ndarray:
    r"""Jacobienne de ``func`` en ``x`` par différences centrées, forme ``(m, n)``.

    Paramètres
    ----------
    func : appelable ``func(x, *args) -> (m,)``
    x : (n,)
        Point de linéarisation.
    args : tuple
        Arguments supplémentaires (par exemple la commande ``u`` de :math:`f(x, u)`).
    step : float, optionnel
        Pas relatif :math:`h_j = \text{step}\cdot\max(1, |x_j|)` ; par défaut :math:`\varepsilon^{1/3}`.
    angle_indices : indices des sorties qui sont des angles : leurs différences sont ramenées dans
        :math:`(-\pi, \pi]` (sinon un angle qui franchit :math:`\pm\pi` donne une dérivée énorme).
    name : nom de la fonction dans les messages d'erreur.
    """
    x = as_float_array("x", x)
    if x.ndim != 1:
        raise KalmanInputError(f"« x » doit être un vecteur 1-D ; reçu {shape_text(x.shape)}.")
    rel = CENTRAL_STEP if step is None else float(step)
    if not rel > 0:
        raise KalmanInputError(f"« step » doit être strictement positif ; reçu {step!r}.")
    g0 = _evaluate(func, x, args, name)
    m, n = g0.size, x.size
    angles = np.asarray(angle_indices, dtype=int)
    J = np.empty((m, n))
    for j in range(n):
        h = rel * max(1.0, abs(x[j]))
        xp = x.copy()
        xm = x.copy()
        xp[j] += h
        xm[j] -= h
        gp = _evaluate(func, xp, args, name)
        gm = _evaluate(func, xm, args, name)
        if gp.size != m or gm.size != m:
            raise KalmanInputError(
                f"La fonction « {name} » ne renvoie pas toujours la même taille ({m} puis {gp.size})."
            )
        d = gp - gm
        if angles.size:
            d[angles] = wrap_angle(d[angles])
        J[:, j] = d / (xp[j] - xm[j])
    return J


@dataclass(frozen=True, eq=False)
class JacobianCheck:
    r"""Résultat de :func:`check_jacobian`.

    ``analytic`` et ``numerical`` (m, n) ; ``max_abs_error`` = :math:`\max|J_a - J_n|` ;
    ``max_rel_error`` = ``max_abs_error`` / :math:`\max(1, \max|J_n|)` ; ``worst`` = indice (i, j) de
    l'écart maximal ; ``ok`` : ``max_rel_error <= rtol``.
    """

    name: str
    analytic: np.ndarray
    numerical: np.ndarray
    max_abs_error: float
    max_rel_error: float
    worst: tuple[int, int]
    rtol: float

    @property
    def ok(self) -> bool:
        """``True`` si la jacobienne analytique est égale aux différences finies (à ``rtol`` près)."""
        return self.max_rel_error <= self.rtol

    def __bool__(self) -> bool:
        return self.ok

    def __repr__(self) -> str:
        from ..numbers import format_number, format_spec  # à la française (import local : pas de cycle)

        i, j = self.worst
        verdict = "correcte" if self.ok else "FAUSSE"
        return (
            f"Jacobienne « {self.name} » : {verdict}\n"
            f"  écart relatif max {format_number(self.max_rel_error, significant=2)} "
            f"(tolérance {format_number(self.rtol, significant=1)})\n"
            f"  pire élément ({i}, {j}) : analytique {format_spec(self.analytic[i, j], '.6g')} ; "
            f"différences finies {format_spec(self.numerical[i, j], '.6g')}"
        )


def check_jacobian(
    func: Callable[..., Any],
    jacobian: Callable[..., Any],
    x: Any,
    args: tuple = (),
    *,
    rtol: float = 1e-6,
    angle_indices: Sequence[int] = (),
    name: str = "jacobienne",
) -> JacobianCheck:
    r"""Compare une jacobienne analytique ``jacobian(x, *args)`` aux différences centrées de ``func``.

    L'écart est mesuré relativement à la plus grande dérivée, :math:`\max|J_a-J_n| / \max(1,\max|J_n|)`,
    et doit rester sous ``rtol`` (``1e-6`` par défaut : les différences centrées sont exactes à environ
    :math:`10^{-10}` près, une erreur de calcul donne un écart d'ordre 1).

    Exemple ::

        check_jacobian(model.h, model.h_jacobian, x)   # affiche « Jacobienne … correcte : … »

    Renvoie un :class:`JacobianCheck` (vrai si la jacobienne est correcte). Une jacobienne de mauvaise
    forme lève une :class:`KalmanInputError`.
    """
    x = as_float_array("x", x)
    x = as_vector("x", x, x.size)
    Jn = numerical_jacobian(func, x, args, angle_indices=angle_indices, name=name)
    Ja = np.asarray(call_user_function(f"jacobienne « {name} »", jacobian, x, args), dtype=float)
    if Ja.ndim == 0 and Jn.shape == (1, 1):
        Ja = Ja.reshape(1, 1)
    if Ja.shape != Jn.shape:
        raise KalmanInputError(
            f"La jacobienne « {name} » doit être de forme {Jn.shape} (sorties × états) ; "
            f"elle a la forme {Ja.shape}."
        )
    if not np.isfinite(Ja).all():
        raise KalmanInputError(f"La jacobienne « {name} » contient des valeurs non finies.")
    diff = np.abs(Ja - Jn)
    worst = np.unravel_index(int(np.argmax(diff)), diff.shape)
    max_abs = float(diff.max())
    max_rel = max_abs / max(1.0, float(np.abs(Jn).max()))
    return JacobianCheck(
        name=name,
        analytic=Ja,
        numerical=Jn,
        max_abs_error=max_abs,
        max_rel_error=max_rel,
        worst=(int(worst[0]), int(worst[1])),
        rtol=float(rtol),
    )
