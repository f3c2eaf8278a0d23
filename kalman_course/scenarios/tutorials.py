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
* :func:`cv_noise_example`, :func:`gate_example`, :func:`imm_step` — TD 4 : le bruit du modèle à vitesse
  presque constante, la porte pour m = 2, un pas d'IMM scalaire ;
* :func:`parallel_elements`, :func:`information_step` — TD 5 : éléments et combinaisons du filtre
  parallèle, un pas du filtre d'information ;
* :func:`exam_stationary`, :func:`exam_range_update`, :func:`exam_smoothing`, :func:`exam_tracking` — le
  sujet d'examen.
* :func:`se2_by_hand` — TD 7 : une exponentielle et une adjointe de SE(2), puis une correction de l'EKF
  invariant.
* :func:`pda_by_hand` — TD 8 : une correction PDA scalaire avec deux détections ;
* :func:`jpda_by_hand` — TD 8 : les probabilités JPDA de deux pistes et deux détections, par énumération.
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
    "CV_EXAMPLE", "GATE_EXAMPLE", "IMM_EXAMPLE", "INFORMATION_EXAMPLE", "EXAM_RANDOM_WALK", "EXAM_RANGE",
    "EXAM_SMOOTHING", "EXAM_TRACKING", "cv_noise_example", "gate_example", "imm_step", "parallel_elements",
    "information_step", "exam_stationary", "exam_range_update", "exam_smoothing", "exam_tracking",
    "SE2_BY_HAND", "SE2ByHand", "se2_by_hand",
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
#: TD 8 : une piste scalaire (a priori 0, variance 3), R = 1, deux détections ; P_D, P_G et λ (par unité de
#: longueur).
PDA_BY_HAND = {"x_prior": 0.0, "P_prior": 3.0, "R": 1.0, "detections": (1.0, -2.0), "P_D": 0.8, "P_G": 0.9,
               "lambda": 0.1}
#: TD 8 : poids PDA (divisés par w₀) de deux pistes pour deux détections : colonne 0, aucune détection.
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


def _scalar_smoothing(c: dict) -> ThreeSteps:
    """Filtre, lisseur RTS et étape M de R (paquet) sur le modèle scalaire A = C = 1 décrit par ``c``
    (Q, R, y, x0, P0)."""
    model = LinearGaussianModel(1.0, 1.0, c["Q"], c["R"])
    y = np.array(c["y"])[:, None]
    res = kalman_filter(model, y, [c["x0"]], [[c["P0"]]])
    sm = rts_smoother(model, res)
    new = em_step(model, y, [c["x0"]], [[c["P0"]]], None)[1]
    return ThreeSteps(res.x[:, 0], res.P[:, 0, 0], res.x_pred[:, 0], res.P_pred[:, 0, 0], sm.x[:, 0],
                      sm.P[:, 0, 0], sm.G[:-1, 0, 0], float(new.R[0, 0]))


def three_step_smoothing() -> ThreeSteps:
    """Les trois pas du TD 3 : :func:`kalman_filter`, :func:`rts_smoother` et l'étape M du paquet."""
    return _scalar_smoothing(THREE_STEPS)


# --------------------------------------------------------------------------- TD 4 : pister des cibles réelles

#: TD 4 : pas de temps (s) et densité (m²/s³) du modèle à vitesse presque constante sur un axe.
CV_EXAMPLE = {"dt": 2.0, "q": 3.0}
#: TD 4 : probabilités des portes, et deux innovations (m) de covariance S = diag(4, 4) m².
GATE_EXAMPLE = {"p": (0.99, 0.999), "S": ((4.0, 0.0), (0.0, 4.0)), "nu": ((3.0, 4.0), (6.0, 8.0))}
#: TD 4 : un pas d'IMM scalaire à deux régimes (marche aléatoire, C = 1) : estimations et probabilités d'avant,
#: transition, densités de bruit d'état des régimes calme et agité, bruit de mesure, mesure.
IMM_EXAMPLE = {"x": (0.0, 4.0), "P": (1.0, 1.0), "mu": (0.5, 0.5), "transition": ((0.9, 0.1), (0.3, 0.7)),
               "Q": (0.0, 1.25), "R": 1.0, "y": 3.0}


def cv_noise_example():
    """TD 4 : ``(A, Q)`` de :func:`kalman_course.constant_velocity` (Van Loan) sur un axe, pour
    :data:`CV_EXAMPLE`."""
    from ..core.motion import constant_velocity

    return constant_velocity(CV_EXAMPLE["dt"], CV_EXAMPLE["q"], dim=1)


def gate_example() -> dict:
    """TD 4 : seuils :math:`\\chi^2_2(p)` de la porte du paquet (``gate_threshold``) et NIS des deux innovations."""
    from ..filters.gating import gate_threshold, nis_value

    S = np.array(GATE_EXAMPLE["S"])
    return {"thresholds": [gate_threshold(p, 2) for p in GATE_EXAMPLE["p"]],
            "nis": [nis_value(np.array(nu), S) for nu in GATE_EXAMPLE["nu"]]}


def imm_step():
    """TD 4 : le pas d'IMM par :func:`kalman_course.imm_filter` (une mesure, un a priori par régime) :
    ``IMMResult`` (``mu_pred`` = c̄, ``x_pred``… du pas, ``x_modes``, ``P_modes``, ``mu``, ``x``, ``P``)."""
    from ..filters.imm import imm_filter

    c = IMM_EXAMPLE
    modes = [LinearGaussianModel(1.0, 1.0, q, c["R"]) for q in c["Q"]]
    return imm_filter(modes, [[c["y"]]], np.array(c["x"])[:, None], np.array(c["P"])[:, None, None],
                      transition=np.array(c["transition"]), mu0=np.array(c["mu"]))


# --------------------------------------------------------------------------- TD 5 : autres formes du filtre

#: TD 5 : un pas du filtre d'information, état [position, vitesse] : a priori, covariance, mesure de la
#: position, sa variance.
INFORMATION_EXAMPLE = {"x": (1.0, 0.0), "P": ((2.0, 1.0), (1.0, 2.0)), "C": ((1.0, 0.0),), "R": 1.0, "y": 3.0}


def parallel_elements() -> dict:
    """TD 5 : les trois éléments du filtre parallèle sur la marche aléatoire du TD 3
    (:func:`kalman_course.filters.parallel.filtering_elements`), les combinaisons
    :math:`a_1 \\otimes a_2`, :math:`a_2 \\otimes a_3`, :math:`a_1 \\otimes (a_2 \\otimes a_3)`
    (:func:`~kalman_course.filters.parallel.combine_filtering`) et le filtre de Kalman sur les mêmes mesures.
    Chaque élément : ``(F, b, Σ, η, J)`` en scalaires."""
    from ..filters.parallel import combine_filtering, filtering_elements

    c = THREE_STEPS
    model = LinearGaussianModel(1.0, 1.0, c["Q"], c["R"])
    y = np.array(c["y"])[:, None]
    elements = filtering_elements(model, y, np.array([c["x0"]]), np.array([[c["P0"]]]), None)
    pick = lambda e, k: tuple(a[..., k:k + 1] for a in e)  # noqa: E731 (éléments en colonnes : axe du pas en dernier)
    scalar = lambda e: tuple(float(np.asarray(a).reshape(-1)[0]) for a in e)  # noqa: E731
    a1, a2, a3 = (pick(elements, k) for k in range(3))
    a12 = combine_filtering(a1, a2)
    a23 = combine_filtering(a2, a3)
    kf = kalman_filter(model, y, [c["x0"]], [[c["P0"]]])
    return {"a1": scalar(a1), "a2": scalar(a2), "a3": scalar(a3), "a12": scalar(a12), "a23": scalar(a23),
            "a1_23": scalar(combine_filtering(a1, a23)), "kalman_x": kf.x[:, 0], "kalman_P": kf.P[:, 0, 0]}


def information_step() -> dict:
    """TD 5 : la correction du filtre d'information par le SRIF du paquet (:func:`kalman_course.srif_update`,
    information :math:`Y = \\mathcal R^T\\mathcal R`, :math:`\\zeta = Y\\hat x`) et par :func:`kalman_course.update`."""
    from ..filters.square_root_information import information_to_state, srif_update, state_to_information

    c = INFORMATION_EXAMPLE
    model = LinearGaussianModel(np.eye(2), np.array(c["C"]), np.zeros((2, 2)), c["R"])
    R_prior, z_prior = state_to_information(np.array(c["x"]), np.array(c["P"]))
    up = srif_update(model, R_prior, z_prior, [c["y"]])
    post = information_to_state(up.R, up.z)
    kf = update(model, np.array(c["x"]), np.array(c["P"]), [c["y"]])
    Y_prior = R_prior.T @ R_prior
    Y = up.R.T @ up.R
    return {"Y_prior": Y_prior, "zeta_prior": Y_prior @ np.array(c["x"]), "Y": Y, "zeta": Y @ post.x,
            "x": post.x, "P": post.P, "kalman_x": kf.x, "kalman_P": kf.P, "gain": kf.K[:, 0]}


# --------------------------------------------------------------------------- sujet d'examen

#: Examen, exercice 1 : marche aléatoire scalaire x_k = x_{k−1} + w_k, y_k = x_k + v_k, Q = R = 1.
EXAM_RANDOM_WALK = {"Q": 1.0, "R": 1.0, "steps": 12, "P0": 10.0}
#: Examen, exercice 2 : a priori (m), variance commune (m²), variance de la distance (m²), distance mesurée (m).
EXAM_RANGE = {"x": (3.0, 4.0), "sigma2": 1.0, "R": 0.25, "y": 5.5}
#: Examen, exercice 3 : marche aléatoire, Q = R = 1, a priori N(0, 1), deux mesures.
EXAM_SMOOTHING = {"Q": 1.0, "R": 1.0, "x0": 0.0, "P0": 1.0, "y": (2.0, 0.0)}
#: Examen, exercice 4 : modèle à vitesse presque constante (Δt en s, q en m²/s³), innovations (km) de
#: covariance S (km²), transition de l'IMM et probabilités des régimes.
EXAM_TRACKING = {"dt": 1.0, "q": 6.0, "S": ((4.0, 0.0), (0.0, 1.0)), "nu": ((2.0, -1.0), (6.0, 2.0)),
                 "p": (0.99, 0.999), "transition": ((0.95, 0.05), (0.1, 0.9)), "mu": (0.6, 0.4)}


def exam_stationary() -> dict:
    """Examen, exercice 1 : le filtre de Kalman du paquet sur :data:`EXAM_RANDOM_WALK` (mesures nulles :
    P et K ne dépendent pas des mesures) ; ``P_pred``, ``K``, ``P`` (T,) et les limites."""
    c = EXAM_RANDOM_WALK
    model = LinearGaussianModel(1.0, 1.0, c["Q"], c["R"])
    res = kalman_filter(model, np.zeros((c["steps"], 1)), [0.0], [[c["P0"]]])
    return {"P_pred": res.P_pred[:, 0, 0], "K": res.K[:, 0, 0], "P": res.P[:, 0, 0], "S": res.S[:, 0, 0]}


def exam_range_update():
    """Examen, exercice 2 : la correction de l'EKF du paquet (:func:`kalman_course.ekf_update`) par une
    distance au radar placé à l'origine."""
    from ..core.models import NonlinearModel
    from ..filters.extended import ekf_update

    c = EXAM_RANGE
    model = NonlinearModel(lambda x, u: x, lambda x: np.array([np.hypot(x[0], x[1])]), np.zeros((2, 2)),
                           c["R"], np.eye(2), lambda x: np.array([x / np.hypot(x[0], x[1])]))
    return ekf_update(model, np.array(c["x"]), c["sigma2"] * np.eye(2), [c["y"]])


def exam_smoothing() -> ThreeSteps:
    """Examen, exercice 3 : deux pas de filtre, le lisseur RTS et l'étape M de R (paquet)."""
    return _scalar_smoothing(EXAM_SMOOTHING)


def exam_tracking() -> dict:
    """Examen, exercice 4 : Q de :func:`kalman_course.constant_velocity`, seuils et NIS de la porte du paquet,
    probabilités prédites de l'IMM (:func:`kalman_course.filters.imm.mode_mixing`)."""
    from ..core.motion import constant_velocity
    from ..filters.gating import gate_threshold, nis_value
    from ..filters.imm import mode_mixing

    c = EXAM_TRACKING
    S = np.array(c["S"])
    cbar, W = mode_mixing(np.array(c["transition"]), np.array(c["mu"]))
    return {"Q": constant_velocity(c["dt"], c["q"], dim=1).Q, "thresholds": [gate_threshold(p, 2) for p in c["p"]],
            "nis": [nis_value(np.array(nu), S) for nu in c["nu"]], "cbar": cbar, "weights": W}


#: TD 7 : le vecteur tangent ξ de l'exponentielle, la pose prédite T̂ (cap 90°, position (3, 1)), sa covariance
#: P⁻ (erreur invariante à gauche ξ = [ρₓ, ρ_y, θ]), la position GNSS y et son écart-type σ.
SE2_BY_HAND = {
    "xi": (1.0, 0.0, np.pi / 2),
    "T_pred": ((0.0, -1.0, 3.0), (1.0, 0.0, 1.0), (0.0, 0.0, 1.0)),
    "P_pred": ((1.0, 0.0, np.pi / 2), (0.0, 1.0, 0.0), (np.pi / 2, 0.0, 4.0)),
    "y": (3.0, 3.0),
    "gnss_std": 1.0,
}


@dataclass(frozen=True)
class SE2ByHand:
    """TD 7 : ``exp`` = Exp(ξ) (3, 3), ``adjoint`` = Ad de T̂ (3, 3), et la correction de l'EKF invariant
    (:class:`~kalman_course.filters.invariant.SE2Update` : ``T``, ``P``, ``K``, ``innovation``, ``S``)."""

    exp: np.ndarray
    adjoint: np.ndarray
    update: object


def se2_by_hand() -> SE2ByHand:
    """Les calculs du TD 7 par le paquet : :func:`~kalman_course.se2_exp`, :func:`~kalman_course.se2_adjoint`
    et :func:`~kalman_course.filters.invariant.se2_invariant_update`."""
    from ..filters.invariant import se2_invariant_update
    from ..geometry.lie import se2_adjoint, se2_exp

    c = SE2_BY_HAND
    return SE2ByHand(se2_exp(c["xi"]), se2_adjoint(c["T_pred"]),
                     se2_invariant_update(c["T_pred"], c["P_pred"], c["y"], c["gnss_std"]))


# --------------------------------------------------------------------------- TD 8 : plusieurs cibles


def pda_by_hand() -> PDAUpdate:
    """La correction PDA du TD 8 par :func:`kalman_course.pda_update` (modèle scalaire, C = 1)."""
    c = PDA_BY_HAND
    model = LinearGaussianModel(1.0, 1.0, 0.0, c["R"])
    return pda_update(model, [c["x_prior"]], [[c["P_prior"]]], np.array(c["detections"])[:, None],
                      detection_probability=c["P_D"], clutter_density=c["lambda"], gate_probability=c["P_G"])


def jpda_by_hand() -> np.ndarray:
    """Les probabilités JPDA (2, 3) du TD 8, par l'énumération du paquet
    (:func:`kalman_course.multitarget.jpda.joint_marginals`) sur les poids :data:`JPDA_WEIGHTS`."""
    return joint_marginals(np.array(JPDA_WEIGHTS), np.array(JPDA_WEIGHTS)[:, 1:] > 0)
