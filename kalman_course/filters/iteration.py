r"""La seule boucle d'itération du paquet : Gauss–Newton sur le coût MAP de la correction.

Une boucle générique (:func:`iterate`) enchaîne :math:`x^{(i+1)} = \mathrm{pas}(x^{(i)})` avec **une**
règle d'arrêt et **un** jeu de valeurs par défaut : arrêt dès que la taille du pas
:math:`\lVert\delta_i\rVert` est inférieure ou égale à ``tol`` (:data:`DEFAULT_TOL`), ou après
``max_iter`` itérations (:data:`DEFAULT_MAX_ITER`). L'EKF itéré, l'EKF itéré sur SE(3) et les variantes
littérales (fausses) des notes ne diffèrent que par le pas qu'ils itèrent.

Le pas de Gauss–Newton (:func:`gauss_newton_update`) est écrit une fois, paramétré par les opérations
:math:`\oplus` / :math:`\ominus` de l'espace d'état (:class:`StateSpace`) : :math:`+` et :math:`-` pour un
vecteur, :math:`T\,\mathrm{Exp}(\delta)` et :math:`\mathrm{Log}(T_0^{-1}T)` pour une pose de SE(3). Au
point :math:`x_i`, avec :math:`\xi_i = x_i \ominus \hat x^-`, :math:`P_i = \mathcal J_iP^-\mathcal J_i^T`
(:math:`\mathcal J_i = I` pour un vecteur, :math:`\mathcal J_r(\xi_i)` sur SE(3)), le résidu
:math:`r_i = y - h(x_i)` et la jacobienne :math:`H_i` :

.. math::

    \nu_i = r_i + H_i\xi_i,\quad K_i = P_iH_i^T(H_iP_iH_i^T + R)^{-1},\quad
    \delta_i = -\xi_i + K_i\nu_i,\quad x_{i+1} = x_i \oplus \delta_i .

Pour un vecteur, c'est :math:`x^{(i+1)} = \hat x^- + K_i\,[y - h(x^{(i)}) - H_i(\hat x^- - x^{(i)})]`
(Bell & Cathey, 1993).

:func:`gauss_newton_update_many` fait la même boucle sur ``N`` tirages à la fois (espace des vecteurs) :
chaque tirage s'arrête par **la même règle**, à sa propre itération ; un tirage arrêté est figé pendant que
les autres itèrent, si bien que chacun est égal, aux arrondis près, à :func:`gauss_newton_update` seul.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, NamedTuple

import numpy as np

from ..core.linalg import correct, correct_many, symmetrize
from ..core.validation import KalmanInputError

__all__ = [
    "DEFAULT_MAX_ITER",
    "DEFAULT_TOL",
    "Iteration",
    "IteratedCorrection",
    "StateSpace",
    "VECTOR_SPACE",
    "check_iterations",
    "iterate",
    "gauss_newton_update",
    "IteratedCorrections",
    "gauss_newton_update_many",
]

#: Nombre maximal d'itérations par défaut.
DEFAULT_MAX_ITER = 20
#: Seuil d'arrêt par défaut sur la taille du pas :math:`\lVert\delta_i\rVert` (unités de l'état).
DEFAULT_TOL = 1e-10


def check_iterations(max_iter: Any, tol: Any) -> tuple[int, float]:
    """Vérifie ``max_iter`` (entier ≥ 1) et ``tol`` (réel fini ≥ 0)."""
    if not isinstance(max_iter, (int, np.integer)) or isinstance(max_iter, bool) or max_iter < 1:
        raise KalmanInputError(f"« max_iter » doit être un entier ≥ 1 ; reçu {max_iter!r}.")
    try:
        tol_f = float(tol)
    except (TypeError, ValueError):
        tol_f = float("nan")
    if not tol_f >= 0 or not np.isfinite(tol_f):
        raise KalmanInputError(f"« tol » doit être un réel ≥ 0 ; reçu {tol!r}.")
    return int(max_iter), tol_f


class Iteration(NamedTuple):
    """Trace de :func:`iterate` : ``x`` dernier itéré, ``iterates`` (N+1, …) de :math:`x^{(0)}` à
    :math:`x^{(N)}`, ``n_iter`` = N, ``converged`` (arrêt par ``tol``), ``last`` : ce que le dernier pas
    a renvoyé en plus de l'itéré."""

    x: Any
    iterates: np.ndarray
    n_iter: int
    converged: bool
    last: Any


def iterate(x0: Any, step: Callable[[Any], tuple[Any, float, Any]], max_iter: int = DEFAULT_MAX_ITER,
            tol: float = DEFAULT_TOL) -> Iteration:
    r"""La boucle : :math:`x^{(i+1)}, s_i, \text{extra} = \mathrm{step}(x^{(i)})`, arrêt dès que
    :math:`s_i = \lVert\delta_i\rVert \le` ``tol`` ou après ``max_iter`` pas."""
    max_iter, tol = check_iterations(max_iter, tol)
    x_i = x0
    iterates = [x0]
    converged = False
    last = None
    for _ in range(max_iter):
        x_i, size, last = step(x_i)
        iterates.append(x_i)
        if size <= tol:
            converged = True
            break
    return Iteration(x_i, np.array(iterates), len(iterates) - 1, converged, last)


@dataclass(frozen=True)
class StateSpace:
    r"""Les opérations d'un espace d'état pour Gauss–Newton.

    ``oplus(x, δ)`` : :math:`x \oplus \delta` ; ``ominus(x, x0)`` : :math:`x \ominus x_0` (coordonnées de
    :math:`x` dans l'espace tangent en :math:`x_0`) ; ``prior_jacobian(ξ)`` : :math:`\mathcal J` tel que
    l'a priori, vu depuis :math:`x_i`, ait la covariance :math:`\mathcal JP^-\mathcal J^T` (``None`` :
    identité) ; ``transport(P, δ)`` : covariance ramenée de l'espace tangent en :math:`x_{N-1}` à celui en
    :math:`x_N = x_{N-1}\oplus\delta` (``None`` : inchangée)."""

    oplus: Callable[[Any, np.ndarray], Any]
    ominus: Callable[[Any, Any], np.ndarray]
    prior_jacobian: Callable[[np.ndarray], np.ndarray] | None = None
    transport: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None


#: L'espace des vecteurs : :math:`\oplus = +`, :math:`\ominus = -`.
VECTOR_SPACE = StateSpace(oplus=np.add, ominus=np.subtract)


class IteratedCorrection(NamedTuple):
    r"""Résultat de :func:`gauss_newton_update`.

    ``x`` : :math:`x^{(N)}` ; ``P`` (d, d) : :math:`(I - K_{N-1}H_{N-1})P_{N-1}` (transportée en
    :math:`x^{(N)}` sur une variété) ; ``K`` (d, m), ``innovation`` (m,), ``S`` (m, m) : gain,
    innovation linéarisée :math:`\nu_{N-1} = r_{N-1} + H_{N-1}\xi_{N-1}` et sa covariance
    :math:`H_{N-1}P_{N-1}H_{N-1}^T + R`, tous trois de la **dernière linéarisation** (au point
    :math:`x^{(N-1)}`) : ils vont ensemble, :math:`x^{(N)} = \hat x^- \oplus K\nu` pour un vecteur, et la
    NIS :math:`\nu^TS^{-1}\nu` est celle du filtre linéarisé en ce point ; ``iterates`` (N+1, …) ;
    ``steps`` (N, d) : les pas :math:`\delta_i` ; ``n_iter`` : N ; ``converged`` : arrêt par ``tol``."""

    x: Any
    P: np.ndarray
    K: np.ndarray
    innovation: np.ndarray
    S: np.ndarray
    iterates: np.ndarray
    steps: np.ndarray
    n_iter: int
    converged: bool


def gauss_newton_update(
    x_pred: Any,
    P_pred: np.ndarray,
    linearize: Callable[[Any], tuple[np.ndarray, np.ndarray, np.ndarray]],
    space: StateSpace = VECTOR_SPACE,
    max_iter: int = DEFAULT_MAX_ITER,
    tol: float = DEFAULT_TOL,
    joseph: bool = False,
) -> IteratedCorrection:
    r"""Correction itérée de Gauss–Newton (voir l'en-tête du module).

    ``linearize(x_i)`` renvoie :math:`(r_i, H_i, R)` : résidu :math:`y \ominus h(x_i)` (m,), jacobienne
    :math:`\partial h / \partial\delta` en :math:`x_i` (m, d) et covariance de mesure (m, m).
    Une seule itération (``max_iter=1``) est exactement la correction de l'EKF.
    """
    steps: list[np.ndarray] = []

    def step(x_i):
        xi = space.ominus(x_i, x_pred)
        if space.prior_jacobian is None:
            P_i = P_pred
        else:
            J = space.prior_jacobian(xi)
            P_i = symmetrize(J.dot(P_pred).dot(J.T))
        r, H, R = linearize(x_i)
        nu = r + H.dot(xi)
        delta, P_post, K, S = correct(-xi, P_i, nu, H, R, joseph)
        steps.append(delta)
        return space.oplus(x_i, delta), float(np.linalg.norm(delta)), (P_post, K, S, nu, delta)

    out = iterate(x_pred, step, max_iter, tol)
    P_post, K, S, nu, delta = out.last
    if space.transport is not None:
        P_post = symmetrize(space.transport(P_post, delta))
    return IteratedCorrection(out.x, P_post, K, nu, S, out.iterates, np.array(steps), out.n_iter, out.converged)


class IteratedCorrections(NamedTuple):
    r"""Résultat de :func:`gauss_newton_update_many` : les champs de :class:`IteratedCorrection` (sans la
    suite des itérés) avec un axe des tirages en tête — ``x`` (N, n), ``P`` (N, n, n), ``K`` (N, n, m),
    ``innovation`` (N, m), ``S`` (N, m, m), ``n_iter`` (N,) entier, ``converged`` (N,) booléen."""

    x: np.ndarray
    P: np.ndarray
    K: np.ndarray
    innovation: np.ndarray
    S: np.ndarray
    n_iter: np.ndarray
    converged: np.ndarray


def gauss_newton_update_many(
    X_pred: np.ndarray,
    P_pred: np.ndarray,
    linearize: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]],
    max_iter: int = DEFAULT_MAX_ITER,
    tol: float = DEFAULT_TOL,
    joseph: bool = False,
    where: str = "",
) -> IteratedCorrections:
    r"""Correction itérée de Gauss–Newton sur ``N`` tirages à la fois (espace des vecteurs,
    :math:`\oplus = +`) : pour chaque tirage :math:`j` encore actif, avec :math:`\xi_{j,i} = x_{j,i} - \hat x^-_j`,

    .. math::

        \nu_{j,i} = r_{j,i} + H_{j,i}\xi_{j,i},\quad K_{j,i} = P^-_jH_{j,i}^T(H_{j,i}P^-_jH_{j,i}^T + R_j)^{-1},\quad
        \delta_{j,i} = -\xi_{j,i} + K_{j,i}\nu_{j,i},\quad x_{j,i+1} = x_{j,i} + \delta_{j,i} ;

    le tirage :math:`j` s'arrête dès que :math:`\lVert\delta_{j,i}\rVert \le` ``tol`` (ou après ``max_iter``
    itérations) : c'est la règle de :func:`iterate`, appliquée tirage par tirage ; les tirages arrêtés ne
    sont plus linéarisés.

    ``X_pred`` (N, n), ``P_pred`` (N, n, n) ; ``linearize(X_a, runs)`` reçoit les itérés (g, n) des tirages
    encore actifs ``runs`` (indices dans 0…N−1) et renvoie :math:`(r, H, R)` : résidus (g, m), jacobiennes
    (g, m, n) ou (m, n) commune, covariance de mesure (g, m, m) ou (m, m) commune. ``where`` nomme le pas
    dans un message d'erreur. Renvoie :class:`IteratedCorrections`.
    """
    max_iter, tol = check_iterations(max_iter, tol)
    N, n = X_pred.shape
    X = np.array(X_pred, dtype=float)
    n_iter = np.zeros(N, dtype=int)
    converged = np.zeros(N, dtype=bool)
    P_post = K = S = nu = None
    active = np.arange(N)
    for _ in range(max_iter):
        X_a = X[active]
        xi = X_a - X_pred[active]
        r, H, R = linearize(X_a, active)
        nu_a = r + (H @ xi[..., None])[..., 0]
        delta, P_a, K_a, S_a = correct_many(-xi, P_pred[active], nu_a, H, R, joseph, where)
        if P_post is None:
            m = nu_a.shape[-1]
            P_post, K, S, nu = np.empty((N, n, n)), np.empty((N, n, m)), np.empty((N, m, m)), np.empty((N, m))
        X[active] = X_a + delta
        P_post[active], K[active], S[active], nu[active] = P_a, K_a, S_a, nu_a
        n_iter[active] += 1
        done = np.linalg.norm(delta, axis=1) <= tol
        converged[active[done]] = True
        active = active[~done]
        if active.size == 0:
            break
    return IteratedCorrections(X, P_post, K, nu, S, n_iter, converged)
