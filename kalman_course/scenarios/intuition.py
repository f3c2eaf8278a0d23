r"""Scénario « un chariot sur un rail » : le filtre de Kalman en une dimension, en images.

Un chariot roule sur un rail rectiligne ; on cherche sa position :math:`x` (m). Ce que l'on sait avant
la mesure est une **loi a priori** gaussienne :math:`\mathcal N(\hat x^-, P^-)` ; un capteur renvoie
:math:`y = x + \psi`, :math:`\psi \sim \mathcal N(0, R)`, c'est-à-dire une **vraisemblance**
:math:`x \mapsto \mathcal N(y;\, x, R)`. Leur produit, normalisé, est la **loi a posteriori** :

.. math::

    \mathcal N(x;\, \hat x^-, P^-)\,\mathcal N(y;\, x, R)
    = \mathcal N(y;\, \hat x^-, P^- + R)\;\mathcal N(x;\, \hat x, P),\qquad
    K = \frac{P^-}{P^- + R},\quad \hat x = \hat x^- + K\,(y - \hat x^-),\quad P = (1 - K)\,P^- .

Entre deux mesures, le chariot avance de :math:`v\,\Delta t` à une vitesse mal connue : la
**prédiction** décale la gaussienne et l'élargit, :math:`\hat x^-_{n+1} = \hat x_n + v\,\Delta t`,
:math:`P^-_{n+1} = P_n + Q`. Toutes ces grandeurs sont calculées par les étapes du paquet
(:func:`~kalman_course.predict`, :func:`~kalman_course.update`) sur le modèle scalaire
:math:`A = C = 1`, :math:`B = \Delta t`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.models import LinearGaussianModel
from ..core.results import freeze_fields
from ..core.simulation import simulate
from ..core.validation import KalmanInputError, as_float_array
from ..filters.kalman import kalman_filter, update
from .half_steps import HalfSteps, half_steps

__all__ = [
    "PRIOR_MEAN",
    "PRIOR_VAR",
    "MEASUREMENT",
    "MEASUREMENT_VAR",
    "POSITIONS",
    "gaussian_density",
    "GaussianProduct",
    "gaussian_product",
    "Correction1D",
    "correction_1d",
    "product_experiment",
    "CART_SPEED",
    "CART_DT",
    "CART_Q",
    "CART_R",
    "CART_P0",
    "CART_STEPS",
    "CART_SEED",
    "cart_model",
    "cart_data",
    "CartCycle",
    "cart_cycle",
    "TRACKING_STEPS",
    "CartTracking",
    "cart_tracking",
]

#: Loi a priori de l'exemple : :math:`\hat x^- = 10` m, :math:`P^- = 4` m² (écart-type 2 m).
PRIOR_MEAN = 10.0
PRIOR_VAR = 4.0
#: Mesure de l'exemple : :math:`y = 13` m, :math:`R = 1` m² (écart-type 1 m).
MEASUREMENT = 13.0
MEASUREMENT_VAR = 1.0
#: Positions (m) où les densités sont tracées.
POSITIONS = np.linspace(0.0, 25.0, 501)
POSITIONS.setflags(write=False)


def _variance(name: str, value: Any) -> float:
    v = as_float_array(name, value)
    if v.ndim != 0 or not (math.isfinite(float(v)) and float(v) > 0):
        raise KalmanInputError(f"« {name} » doit être une variance strictement positive (un nombre) ; reçu {value!r}.")
    return float(v)


def _scalar(name: str, value: Any) -> float:
    v = as_float_array(name, value)
    if v.ndim != 0:
        raise KalmanInputError(f"« {name} » doit être un nombre ; reçu un tableau de forme {v.shape}.")
    return float(v)


def gaussian_density(x: Any, mean: float, var: float) -> np.ndarray:
    r"""Densité gaussienne :math:`\mathcal N(x;\, m, v) = \exp(-(x - m)^2 / 2v) / \sqrt{2\pi v}`, de la même
    forme que ``x``."""
    x = as_float_array("x", x)
    m, v = _scalar("mean", mean), _variance("var", var)
    return np.exp(-0.5 * (x - m) ** 2 / v) / math.sqrt(2.0 * math.pi * v)


@dataclass(frozen=True)
class GaussianProduct:
    r"""Produit :math:`\mathcal N(x;\, m_1, v_1)\,\mathcal N(x;\, m_2, v_2) = s\;\mathcal N(x;\, m, v)` :
    ``mean`` :math:`m`, ``var`` :math:`v`, ``gain`` :math:`K = v_1/(v_1 + v_2)` (poids de la seconde),
    ``scale`` :math:`s = \mathcal N(m_1;\, m_2, v_1 + v_2)`."""

    mean: float
    var: float
    gain: float
    scale: float


def gaussian_product(mean1: float, var1: float, mean2: float, var2: float) -> GaussianProduct:
    r"""Le produit de deux densités gaussiennes en :math:`x` est une gaussienne (à un facteur près) :

    .. math::

        K = \frac{v_1}{v_1 + v_2},\qquad m = m_1 + K\,(m_2 - m_1),\qquad v = (1 - K)\,v_1 = \frac{v_1 v_2}{v_1 + v_2},

    et le facteur vaut :math:`s = \mathcal N(m_1;\, m_2, v_1 + v_2)`.
    """
    m1, m2 = _scalar("mean1", mean1), _scalar("mean2", mean2)
    v1, v2 = _variance("var1", var1), _variance("var2", var2)
    K = v1 / (v1 + v2)
    return GaussianProduct(
        mean=m1 + K * (m2 - m1),
        var=(1.0 - K) * v1,
        gain=K,
        scale=float(gaussian_density(m1, m2, v1 + v2)),
    )


@dataclass(frozen=True)
class Correction1D:
    r"""Une correction scalaire faite par le paquet : ``x`` :math:`\hat x`, ``P``, ``K``, ``innovation``
    :math:`y - \hat x^-`, ``S`` :math:`= P^- + R`."""

    x: float
    P: float
    K: float
    innovation: float
    S: float


def correction_1d(prior_mean: float, prior_var: float, y: float, R: float) -> Correction1D:
    r"""La correction du filtre de Kalman (:func:`~kalman_course.update`) sur le modèle scalaire
    :math:`C = 1` : a priori :math:`\mathcal N(\hat x^-, P^-)`, mesure ``y`` de variance ``R``."""
    prior_var, R = _variance("prior_var", prior_var), _variance("R", R)
    model = LinearGaussianModel(A=1.0, C=1.0, Q=0.0, R=R)
    out = update(model, [_scalar("prior_mean", prior_mean)], [[prior_var]], [_scalar("y", y)])
    return Correction1D(
        x=float(out.x[0]), P=float(out.P[0, 0]), K=float(out.K[0, 0]),
        innovation=float(out.innovation[0]), S=float(out.S[0, 0]),
    )


def product_experiment(prior_var: float = PRIOR_VAR, meas_var: float = MEASUREMENT_VAR,
                       prior_mean: float = PRIOR_MEAN, y: float = MEASUREMENT,
                       positions: Any = POSITIONS) -> dict[str, np.ndarray]:
    r"""L'a priori, la vraisemblance et la loi a posteriori sur la grille ``positions`` (m).

    Renvoie un dictionnaire de séries : ``x`` (positions, m) ; ``prior``, ``likelihood`` (densités,
    1/m) ; ``product`` : le produit point à point, normalisé numériquement (méthode des trapèzes) ;
    ``posterior`` : la densité :math:`\mathcal N(\hat x, P)` de la correction du paquet ; et des séries
    d'un point : ``K``, ``x_post``, ``P_post``, ``x_prior``, ``P_prior``, ``y``, ``R``.
    """
    x = as_float_array("positions", positions)
    prior = gaussian_density(x, prior_mean, prior_var)
    likelihood = gaussian_density(x, y, meas_var)  # N(y; x, R) = N(x; y, R)
    raw = prior * likelihood
    product = raw / np.trapezoid(raw, x)
    post = correction_1d(prior_mean, prior_var, y, meas_var)
    one = lambda v: np.array([float(v)])  # noqa: E731
    return {
        "x": x, "prior": prior, "likelihood": likelihood, "product": product,
        "posterior": gaussian_density(x, post.x, post.P),
        "K": one(post.K), "x_post": one(post.x), "P_post": one(post.P),
        "x_prior": one(prior_mean), "P_prior": one(prior_var), "y": one(y), "R": one(meas_var),
    }


# --------------------------------------------------------------------------- la boucle, pas à pas

#: Vitesse du chariot (m/s) et durée d'un pas (s) : la commande :math:`u = v` fait avancer de :math:`v\,\Delta t`.
CART_SPEED = 1.0
CART_DT = 1.0
#: Variance du bruit d'état (m²) : l'incertitude ajoutée par un pas de déplacement.
CART_Q = 0.5
#: Variance du bruit de mesure (m²).
CART_R = 1.0
#: Loi initiale du filtre : :math:`\hat x_0 = 0` m, :math:`P_0 = 1` m².
CART_X0 = 0.0
CART_P0 = 1.0
#: Nombre de mesures et graine des tirages.
CART_STEPS = 6
CART_SEED = 1960


def cart_model(Q: float = CART_Q, R: float = CART_R) -> LinearGaussianModel:
    r"""Le chariot : :math:`x_{n+1} = x_n + \Delta t\,u_n + \phi_n`, :math:`y_{n+1} = x_{n+1} + \psi_{n+1}`
    (:math:`A = C = 1`, :math:`B = \Delta t`), :math:`\Phi = Q`, :math:`\Psi = R` (m²)."""
    return LinearGaussianModel(A=1.0, C=1.0, Q=_variance("Q", Q), R=_variance("R", R), B=CART_DT)


def cart_data(n_steps: int = CART_STEPS):
    r"""Trajet simulé avec le vrai modèle (:data:`CART_Q`, :data:`CART_R`, graine :data:`CART_SEED`) :
    renvoie ``(simulation, u)``, ``u`` (T, 1) la vitesse (m/s)."""
    u = np.full((n_steps, 1), CART_SPEED)
    sim = simulate(cart_model(), [CART_X0], n_steps, u, rng=CART_SEED)
    return sim, u


@dataclass(frozen=True, eq=False)
class CartCycle:
    r"""La boucle prédiction–correction, demi-pas par demi-pas (``2T + 1`` étapes) : l'étape 0 est la
    loi initiale, l'étape :math:`2n - 1` la prédiction :math:`(\hat x^-_n, P^-_n)`, l'étape :math:`2n` la
    correction :math:`(\hat x_n, P_n)`. ``mean`` (2T+1,) (m), ``var`` (2T+1,) (m²), ``kind`` : ``"départ"``,
    ``"prédiction"`` ou ``"correction"`` ; ``y`` (T,) mesures et ``truth`` (T,) positions vraies (m) ;
    ``K`` (T,) gains."""

    mean: np.ndarray
    var: np.ndarray
    kind: tuple[str, ...]
    y: np.ndarray
    truth: np.ndarray
    K: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, "mean", "var", "y", "truth", "K")

    step_of = staticmethod(HalfSteps.step_of)


def cart_cycle(Q: float = CART_Q, R: float = CART_R, n_steps: int = CART_STEPS) -> CartCycle:
    r"""Le filtre de Kalman du paquet (:func:`~kalman_course.kalman_filter`) sur le trajet de
    :func:`cart_data`, avec le bruit d'état ``Q`` et le bruit de mesure ``R`` supposés par le filtre ;
    renvoie les demi-pas :class:`CartCycle`."""
    sim, u = cart_data(n_steps)
    result = kalman_filter(cart_model(Q, R), sim.y, [CART_X0], [[CART_P0]], u)
    steps = half_steps(result, [CART_X0], [[CART_P0]])
    return CartCycle(steps.mean[:, 0], steps.cov[:, 0, 0], steps.kind, sim.y[:, 0], sim.x[:, 0], result.K[:, 0, 0])


# --------------------------------------------------------------------------- le suivi (introduction)

#: Durée du suivi de l'introduction (nombre de mesures, une par seconde).
TRACKING_STEPS = 40


@dataclass(frozen=True, eq=False)
class CartTracking:
    r"""Le chariot simulé avec ``Q`` et ``R``, filtré avec les mêmes : ``truth``, ``y``, ``x`` (estimation),
    ``std`` (:math:`\sqrt{P_n}`), formes (T,), en m."""

    truth: np.ndarray
    y: np.ndarray
    x: np.ndarray
    std: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, "truth", "y", "x", "std")


def cart_tracking(Q: float = CART_Q, R: float = CART_R, n_steps: int = TRACKING_STEPS) -> CartTracking:
    r"""Le chariot simulé (graine :data:`CART_SEED`) avec le bruit d'état ``Q`` et le bruit de mesure ``R``
    (m²), puis filtré par le filtre de Kalman du paquet, qui connaît ``Q`` et ``R``. Les mêmes tirages
    gaussiens servent pour tous les réglages : seule l'amplitude des bruits change."""
    model = cart_model(Q, R)
    u = np.full((n_steps, 1), CART_SPEED)
    sim = simulate(model, [CART_X0], n_steps, u, rng=CART_SEED)
    result = kalman_filter(model, sim.y, [CART_X0], [[CART_P0]], u)
    return CartTracking(sim.x[:, 0], sim.y[:, 0], result.x[:, 0], np.sqrt(result.P[:, 0, 0]))
