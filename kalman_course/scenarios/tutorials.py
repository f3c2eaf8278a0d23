r"""Les exemples des travaux dirigés (calculs à la main), recalculés par le paquet.

Les pages TD donnent les réponses exactes, obtenues à la main (fractions, racines) ; ces fonctions les
recalculent avec les filtres du paquet, pour les cellules « vérification » des pages, leurs figures
et les tests (qui comparent les deux).

* :func:`thermometer_update` — TD 1 : une correction scalaire (a priori 20 °C, variance 4 °C² ;
  mesure 23 °C, variance 1 °C²) ;
* :func:`square_transform` — TD 2 : la transformée unscented de N(0, 1) par x² (α = 1, β = 0, κ = 2)
  et sa linéarisation ;
* :func:`four_particles` — TD 2 : le rééchantillonnage systématique de quatre particules ;
* :func:`ensemble_spread` — TD 2 : la dispersion de l'analyse d'un EnKF scalaire, avec et sans
  perturbation des observations ;
* :func:`three_step_smoothing` — TD 3 : trois pas de filtre et de lisseur RTS sur une marche aléatoire,
  puis l'étape M de R ;
* :func:`pda_by_hand` — TD 4 : une correction PDA scalaire avec deux détections ;
* :func:`jpda_by_hand` — TD 4 : les probabilités JPDA de deux pistes et deux détections, par énumération.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.models import LinearGaussianModel
from ..filters.kalman import kalman_filter, update
from ..filters.particle import systematic_resample
from ..filters.smoothers import rts_smoother
from ..filters.unscented import unscented_transform
from ..likelihood import em_step
from ..multitarget.jpda import joint_marginals
from ..multitarget.pda import PDAUpdate, pda_update

__all__ = [
    "THERMOMETER", "SQUARE_UT", "FOUR_WEIGHTS", "FOUR_U", "ENSEMBLE_EXAMPLE", "THREE_STEPS",
    "thermometer_update", "square_transform", "four_particles", "ensemble_spread", "three_step_smoothing",
    "PDA_BY_HAND", "JPDA_WEIGHTS", "pda_by_hand", "jpda_by_hand",
]

#: TD 1 : a priori (°C), sa variance (°C²), mesure (°C), variance de la mesure (°C²).
THERMOMETER = {"x_prior": 20.0, "P_prior": 4.0, "y": 23.0, "R": 1.0}
#: TD 2 : paramètres des points sigma (α, β, κ) de la transformée de N(0, 1) par x².
SQUARE_UT = (1.0, 0.0, 2.0)
#: TD 2 : poids des quatre particules et tirage u du rééchantillonnage systématique.
FOUR_WEIGHTS = np.array([0.1, 0.2, 0.3, 0.4])
FOUR_WEIGHTS.setflags(write=False)
FOUR_U = 0.5
#: TD 2 : EnKF scalaire, P⁻ = 4, R = 1, C = 1 ; taille de l'ensemble et graine de la vérification.
ENSEMBLE_EXAMPLE = {"P_prior": 4.0, "R": 1.0, "members": 200_000, "seed": 5}
#: TD 3 : marche aléatoire x_{k+1} = x_k + w_k, y_k = x_k + v_k, Q = R = 1, a priori N(0, 1), mesures.
THREE_STEPS = {"Q": 1.0, "R": 1.0, "x0": 0.0, "P0": 1.0, "y": (1.0, 3.0, 2.0)}
#: TD 4 : une piste scalaire (a priori 0, variance 3), R = 1, deux détections ; P_D, P_G et λ (par unité de
#: longueur).
PDA_BY_HAND = {"x_prior": 0.0, "P_prior": 3.0, "R": 1.0, "detections": (1.0, -2.0), "P_D": 0.8, "P_G": 0.9,
               "lambda": 0.1}
#: TD 4 : poids PDA (divisés par w₀) de deux pistes pour deux détections : colonne 0, aucune détection.
JPDA_WEIGHTS = np.array([[1.0, 4.0, 1.0], [1.0, 2.0, 3.0]])
JPDA_WEIGHTS.setflags(write=False)


def thermometer_update():
    """La correction du TD 1 par :func:`kalman_course.update` : ``Update`` (``x``, ``P``, ``K``)."""
    c = THERMOMETER
    model = LinearGaussianModel(1.0, 1.0, 0.0, c["R"])
    return update(model, [c["x_prior"]], [[c["P_prior"]]], [c["y"]])


@dataclass(frozen=True)
class SquareTransform:
    """TD 2 : points sigma, poids, images, moyenne et variance de x² pour x ~ N(0, 1), et la
    linéarisation (moyenne f(0), variance f'(0)² · 1)."""

    points: np.ndarray
    Wm: np.ndarray
    Wc: np.ndarray
    images: np.ndarray
    mean: float
    variance: float
    linearised_mean: float
    linearised_variance: float


def square_transform() -> SquareTransform:
    """La transformée unscented du TD 2 par :func:`kalman_course.unscented_transform`."""
    alpha, beta, kappa = SQUARE_UT
    ut = unscented_transform([0.0], [[1.0]], lambda x: x**2, alpha=alpha, beta=beta, kappa=kappa)
    slope = 2.0 * 0.0  # f'(0) pour f(x) = x²
    return SquareTransform(ut.points[:, 0], ut.Wm, ut.Wc, ut.transformed[:, 0], float(ut.mean[0]),
                           float(ut.cov[0, 0]), 0.0**2, slope**2 * 1.0)


def four_particles() -> np.ndarray:
    """Les indices (à partir de 0) du rééchantillonnage systématique du TD 2 (:func:`systematic_resample`)."""
    return systematic_resample(FOUR_WEIGHTS, FOUR_U)


def ensemble_spread() -> dict[str, float]:
    """TD 2 : variance de l'analyse d'un ensemble scalaire (C = 1) avec observations perturbées et sans,
    pour un grand ensemble tiré exactement de N(0, P⁻), et les valeurs exactes correspondantes
    (:func:`kalman_course.update` pour (1 − K) P⁻ ; (1 − K)² P⁻ sans perturbation)."""
    c = ENSEMBLE_EXAMPLE
    rng = np.random.default_rng(c["seed"])
    P, R, N = c["P_prior"], c["R"], c["members"]
    x = rng.standard_normal(N) * np.sqrt(P)
    v = rng.standard_normal(N) * np.sqrt(R)
    K = np.var(x) / (np.var(x) + R)
    y = 0.0
    perturbed = x + K * (y + v - x)
    unperturbed = x + K * (y - x)
    exact = update(LinearGaussianModel(1.0, 1.0, 0.0, R), [0.0], [[P]], [y])
    k = float(exact.K[0, 0])
    return {"perturbed": float(np.var(perturbed)), "unperturbed": float(np.var(unperturbed)),
            "exact": float(exact.P[0, 0]), "exact_unperturbed": (1 - k) ** 2 * P, "gain": k}


@dataclass(frozen=True)
class ThreeSteps:
    """TD 3 : filtre (``x``, ``P``, ``x_pred``, ``P_pred``), lisseur (``xs``, ``Ps``, ``G``) et nouvelle
    variance de mesure ``R_new`` de l'étape M, sur les trois pas."""

    x: np.ndarray
    P: np.ndarray
    x_pred: np.ndarray
    P_pred: np.ndarray
    xs: np.ndarray
    Ps: np.ndarray
    G: np.ndarray
    R_new: float


def three_step_smoothing() -> ThreeSteps:
    """Les trois pas du TD 3 : :func:`kalman_filter`, :func:`rts_smoother` et l'étape M du paquet."""
    c = THREE_STEPS
    model = LinearGaussianModel(1.0, 1.0, c["Q"], c["R"])
    y = np.array(c["y"])[:, None]
    res = kalman_filter(model, y, [c["x0"]], [[c["P0"]]])
    sm = rts_smoother(model, res)
    new = em_step(model, y, [c["x0"]], [[c["P0"]]], None)[1]
    return ThreeSteps(res.x[:, 0], res.P[:, 0, 0], res.x_pred[:, 0], res.P_pred[:, 0, 0], sm.x[:, 0],
                      sm.P[:, 0, 0], sm.G[:-1, 0, 0], float(new.R[0, 0]))


def pda_by_hand() -> PDAUpdate:
    """La correction PDA du TD 4 par :func:`kalman_course.pda_update` (modèle scalaire, C = 1)."""
    c = PDA_BY_HAND
    model = LinearGaussianModel(1.0, 1.0, 0.0, c["R"])
    return pda_update(model, [c["x_prior"]], [[c["P_prior"]]], np.array(c["detections"])[:, None],
                      detection_probability=c["P_D"], clutter_density=c["lambda"], gate_probability=c["P_G"])


def jpda_by_hand() -> np.ndarray:
    """Les probabilités JPDA (2, 3) du TD 4, par l'énumération du paquet
    (:func:`kalman_course.multitarget.jpda.joint_marginals`) sur les poids :data:`JPDA_WEIGHTS`."""
    return joint_marginals(np.array(JPDA_WEIGHTS), np.array(JPDA_WEIGHTS)[:, 1:] > 0)
