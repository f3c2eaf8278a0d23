r"""Scénario « radar précis, a priori médiocre » : distance et azimut d'une cible vus de l'origine.

Une seule correction (notes, §1.5) : a priori :math:`\hat x^- = (10, 0)` m, :math:`P^- = 9\,I` m² (3 m
d'écart-type), cible vraie en :math:`(8, 3)` m, capteur précis :math:`\sigma_r = 5` cm,
:math:`\sigma_\theta = 0{,}5°`. La mesure est tirée une fois pour toutes (graine :data:`RADAR_SEED`).
Le capteur est si précis que la linéarisation de :math:`h` en :math:`\hat x^-` (EKF) est fausse là où la
mesure place la cible ; l'EKF itéré relinéarise jusqu'au maximum a posteriori.

Un second jeu, :func:`radar_tracking_data`, suit une cible à vitesse constante qui traverse l'axe
:math:`\theta = \pm\pi` (l'azimut doit être ramené dans :math:`(-\pi, \pi]`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.optimize

from ..filters.extended import ekf_update
from ..filters.iterated import iekf_update, map_cost, map_costs
from ..lecture.errata_iekf import no_correction_iterates, table_literal_iterates
from ..core.models import NonlinearModel
from ..core.results import freeze, freeze_fields
from ..core.simulation import as_generator
from ..tables import Table
from ..core.motion import constant_velocity
from ._motion import simulate_cv

__all__ = [
    "radar_cost_grid",
    "RADAR_PRIOR",
    "RADAR_PRIOR_COV",
    "RADAR_TRUTH",
    "RADAR_RANGE_STD",
    "RADAR_BEARING_STD",
    "RADAR_SEED",
    "range_bearing",
    "range_bearing_jacobian",
    "radar_model",
    "RadarUpdateProblem",
    "radar_update_problem",
    "radar_map_estimate",
    "RadarIterations",
    "radar_iterations",
    "radar_iteration_table",
    "radar_tracking_model",
    "radar_tracking_data",
]

#: A priori :math:`\hat x^-` (m).
RADAR_PRIOR = np.array([10.0, 0.0])
RADAR_PRIOR.setflags(write=False)
#: Covariance a priori :math:`P^-` (m²) : 3 m d'écart-type sur chaque axe.
RADAR_PRIOR_COV = 9.0 * np.eye(2)
RADAR_PRIOR_COV.setflags(write=False)
#: Position vraie de la cible (m).
RADAR_TRUTH = np.array([8.0, 3.0])
RADAR_TRUTH.setflags(write=False)
#: Écart-type de la distance mesurée (m).
RADAR_RANGE_STD = 0.05
#: Écart-type de l'azimut mesuré (rad) : 0,5°.
RADAR_BEARING_STD = float(np.deg2rad(0.5))
#: Graine du bruit de la mesure unique.
RADAR_SEED = 3


def range_bearing(x: np.ndarray) -> np.ndarray:
    r"""Distance et azimut de la position :math:`(x_0, x_1)` vus de l'origine : :math:`[\,\lVert p\rVert,\ \operatorname{atan2}(p_y, p_x)\,]` (m, rad).

    Forme (2,) pour un état, (N, 2) pour une pile d'états (N, n) (modèle vectorisé)."""
    x = np.asarray(x)
    if x.ndim == 1:  # un seul état : sans np.stack (appelée à chaque pas et à chaque itération des filtres)
        return np.array([np.hypot(x[0], x[1]), np.arctan2(x[1], x[0])])
    return np.stack([np.hypot(x[..., 0], x[..., 1]), np.arctan2(x[..., 1], x[..., 0])], axis=-1)


def range_bearing_jacobian(x: np.ndarray, n_state: int = 2) -> np.ndarray:
    r"""Jacobienne (2, n_state) de :func:`range_bearing` :
    :math:`\begin{bmatrix} p_x/r & p_y/r \\ -p_y/r^2 & p_x/r^2 \end{bmatrix}` (colonnes nulles au-delà de la position).

    Forme (2, n_state) pour un état, (N, 2, n_state) pour une pile d'états (N, n) (filtres en lot)."""
    x = np.asarray(x)
    if x.ndim == 1:  # un seul état : sans np.stack (appelée à chaque pas et à chaque itération des filtres)
        px, py = x[0], x[1]
        r2 = px * px + py * py
        r = np.sqrt(r2)
        H = np.zeros((2, n_state))
        H[0, :2] = [px / r, py / r]
        H[1, :2] = [-py / r2, px / r2]
        return H
    px, py = x[..., 0], x[..., 1]
    r2 = px * px + py * py
    r = np.sqrt(r2)
    H = np.zeros((*x.shape[:-1], 2, n_state))
    H[..., 0, 0], H[..., 0, 1] = px / r, py / r
    H[..., 1, 0], H[..., 1, 1] = -py / r2, px / r2
    return H


def radar_model(range_std: float = RADAR_RANGE_STD, bearing_std: float = RADAR_BEARING_STD) -> NonlinearModel:
    r"""Modèle de la correction unique : état = position (2,), :math:`h` = distance et azimut (angle en
    composante 1). La dynamique (identité, bruit nul) ne sert pas. Modèle vectorisé."""
    return NonlinearModel(
        f=lambda x, u: x,
        h=range_bearing,
        Q=np.zeros((2, 2)),
        R=np.diag([range_std**2, bearing_std**2]),
        f_jacobian=np.eye(2),
        h_jacobian=range_bearing_jacobian,
        angle_indices=(1,),
        vectorized=True,
    )


@dataclass(frozen=True, eq=False)
class RadarUpdateProblem:
    r"""Une correction : ``model``, a priori ``x_pred`` (2,) et ``P_pred`` (2, 2), mesure ``y`` (2,)
    (m, rad) et position vraie ``truth`` (2,)."""

    model: NonlinearModel
    x_pred: np.ndarray
    P_pred: np.ndarray
    y: np.ndarray
    truth: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, "x_pred", "P_pred", "y", "truth")


def radar_update_problem(rng: Any = RADAR_SEED) -> RadarUpdateProblem:
    r"""La correction du chapitre : :math:`y = h(x_{\text{vrai}}) + (\sigma_r\varepsilon_1, \sigma_\theta\varepsilon_2)`,
    :math:`\varepsilon \sim \mathcal N(0, I_2)` tiré avec ``rng``."""
    gen = as_generator(rng)
    noise = gen.standard_normal(2) * np.array([RADAR_RANGE_STD, RADAR_BEARING_STD])
    return RadarUpdateProblem(
        model=radar_model(),
        x_pred=RADAR_PRIOR,
        P_pred=RADAR_PRIOR_COV,
        y=range_bearing(RADAR_TRUTH) + noise,
        truth=RADAR_TRUTH,
    )


def radar_map_estimate(problem: RadarUpdateProblem) -> np.ndarray:
    r"""Maximum a posteriori par ``scipy.optimize.least_squares`` sur les résidus blanchis
    :math:`[\,L_P^{-1}(x - \hat x^-);\ L_R^{-1}(y - h(x))\,]` (jacobienne par différences finies centrées de scipy) :
    une résolution indépendante du filtre, pour le comparer."""
    model = problem.model
    LP = np.linalg.cholesky(problem.P_pred)
    LR = np.linalg.cholesky(model.R)

    def residuals(x):
        return np.concatenate(
            [np.linalg.solve(LP, x - problem.x_pred), np.linalg.solve(LR, model.residual(problem.y, range_bearing(x)))]
        )

    sol = scipy.optimize.least_squares(
        residuals, problem.x_pred, jac="3-point", xtol=1e-15, ftol=1e-15, gtol=1e-15
    )
    return sol.x


@dataclass(frozen=True, eq=False)
class RadarIterations:
    r"""Itérés de l'EKF itéré et des variantes fausses, avec leur coût et leur erreur.

    ``iterates`` (N+1, 2) : :math:`x^{(0)} = \hat x^-, \dots, x^{(N)}` (Gauss–Newton) ; ``cost`` (N+1,) :
    :math:`J(x^{(i)})` ; ``error`` (N+1,) : distance à la cible vraie (m) ; ``distance_to_map`` (N+1,) :
    distance au MAP de :func:`radar_map_estimate` (m) ; ``map`` (2,), ``map_cost`` ; ``ekf`` (2,) : l'EKF ;
    ``table_literal`` (L+1, 2) : itérés du tableau des notes ; ``no_correction`` (D+1, 2) : itérés sans le terme
    de linéarisation ; ``converged`` : Gauss–Newton arrêté par le seuil."""

    problem: RadarUpdateProblem
    iterates: np.ndarray
    cost: np.ndarray
    error: np.ndarray
    distance_to_map: np.ndarray
    map: np.ndarray
    map_cost: float
    ekf: np.ndarray
    table_literal: np.ndarray
    no_correction: np.ndarray
    converged: bool

    @property
    def n_iter(self) -> int:
        """Nombre d'itérations de Gauss–Newton effectuées."""
        return self.iterates.shape[0] - 1

    def cost_of(self, x: Any) -> float:
        """Coût MAP :math:`J(x)` de la correction."""
        p = self.problem
        return map_cost(p.model, x, p.x_pred, p.P_pred, p.y)

    def error_of(self, x: Any) -> float:
        """Distance (m) de ``x`` à la cible vraie."""
        return float(np.linalg.norm(np.asarray(x, dtype=float)[:2] - self.problem.truth))


def radar_iterations(
    problem: RadarUpdateProblem | None = None, max_iter: int = 20, tol: float = 1e-10, wrong_max_iter: int = 200
) -> RadarIterations:
    """Calcule les itérés de Gauss–Newton, l'EKF, le MAP indépendant et les itérés des deux variantes fausses."""
    p = radar_update_problem() if problem is None else problem
    out = iekf_update(p.model, p.x_pred, p.P_pred, p.y, max_iter=max_iter, tol=tol)
    x_map = radar_map_estimate(p)
    its = out.iterates
    cost = np.array([map_cost(p.model, x, p.x_pred, p.P_pred, p.y) for x in its])
    return RadarIterations(
        problem=p,
        iterates=freeze(its),
        cost=freeze(cost),
        error=freeze(np.linalg.norm(its - p.truth, axis=1)),
        distance_to_map=freeze(np.linalg.norm(its - x_map, axis=1)),
        map=freeze(x_map),
        map_cost=map_cost(p.model, x_map, p.x_pred, p.P_pred, p.y),
        ekf=freeze(ekf_update(p.model, p.x_pred, p.P_pred, p.y).x),
        table_literal=freeze(table_literal_iterates(p.model, p.x_pred, p.P_pred, p.y, max_iter=wrong_max_iter)),
        no_correction=freeze(no_correction_iterates(p.model, p.x_pred, p.P_pred, p.y, max_iter=wrong_max_iter)),
        converged=bool(out.converged),
    )


def radar_cost_grid(problem: RadarUpdateProblem | None = None, n: int = 100):
    r"""Le coût MAP :math:`J(x)` du problème radar sur une grille de ``n`` × ``n`` points (4 cm pour
    ``n = 100``) du plan :math:`[7; 10{,}6] \times [-0{,}5; 3{,}9]` m, pour ses courbes de niveau.
    Renvoie ``(xs (n,), ys (n,), J (n, n))``, ligne : ``ys``, colonne : ``xs``."""
    p = radar_update_problem() if problem is None else problem
    xs = np.linspace(7.0, 10.6, n)
    ys = np.linspace(-0.5, 3.9, n)
    X = np.stack(np.meshgrid(xs, ys), axis=-1).reshape(-1, 2)
    return xs, ys, map_costs(p.model, X, p.x_pred, p.P_pred, p.y).reshape(n, n)


# --------------------------------------------------------------------------- suivi d'une cible


#: Période (s), écart-type d'accélération (m/s²) et longueur du suivi.
RADAR_TRACK_DT = 1.0
RADAR_TRACK_ACCEL_STD = 0.05
RADAR_TRACK_STEPS = 50
RADAR_TRACK_TRUE_X0 = np.array([-25.0, 12.0, 0.2, -0.5])


def radar_tracking_model(
    dt: float = RADAR_TRACK_DT,
    accel_std: float = RADAR_TRACK_ACCEL_STD,
    range_std: float = RADAR_RANGE_STD,
    bearing_std: float = RADAR_BEARING_STD,
) -> NonlinearModel:
    r"""Cible à vitesse constante (état :math:`[p_x, p_y, v_x, v_y]`) vue par le radar (distance, azimut) ;
    modèle vectorisé (``f`` et ``h`` acceptent une pile d'états (N, 4))."""
    F, Q = constant_velocity(dt, accel_std=accel_std)
    return NonlinearModel(
        f=lambda x, u: x.dot(F.T),  # un état (4,) ou une pile (N, 4)
        h=range_bearing,
        Q=Q,
        R=np.diag([range_std**2, bearing_std**2]),
        f_jacobian=F,
        h_jacobian=lambda x: range_bearing_jacobian(x, 4),
        angle_indices=(1,),
        vectorized=True,
    )


def radar_tracking_data(n_steps: int = RADAR_TRACK_STEPS, rng: Any = 7):
    r"""Cible partant de :math:`(-25, 12)` m vers le bas : elle franchit l'axe :math:`\theta = \pm\pi`.

    Renvoie ``(x_true (T, 4), y (T, 2), x0 (4,), P0 (4, 4))`` ; l'a priori initial est décalé de 3 m.
    """
    gen = as_generator(rng)
    x_true = simulate_cv(RADAR_TRACK_TRUE_X0, n_steps, RADAR_TRACK_DT, RADAR_TRACK_ACCEL_STD, gen)
    noise = gen.standard_normal((n_steps, 2)) * np.array([RADAR_RANGE_STD, RADAR_BEARING_STD])
    y = np.array([range_bearing(x) for x in x_true]) + noise
    y[:, 1] = np.arctan2(np.sin(y[:, 1]), np.cos(y[:, 1]))  # azimut mesuré dans (−π, π]
    x0 = RADAR_TRACK_TRUE_X0 + np.array([2.0, -2.0, 0.3, 0.3])
    P0 = np.diag([9.0, 9.0, 1.0, 1.0])
    return x_true, y, x0, P0


def radar_iteration_table(it: RadarIterations | None = None) -> Table:
    r"""Tableau par itération : :math:`i`, coût :math:`J(x^{(i)})`, distance au MAP (m), erreur (m).

    La ligne 0 est l'a priori :math:`\hat x^-`, la ligne 1 l'EKF (première itération)."""
    it = radar_iterations() if it is None else it
    labels = ["0 (a priori)", "1 (EKF)"] + [str(i) for i in range(2, it.iterates.shape[0])]
    return Table(
        ["itération $i$", "coût $J(x^{(i)})$", r"$\lVert x^{(i)} - x_{\mathrm{MAP}}\rVert$ (m)",
         r"erreur $\lVert x^{(i)} - x_{\mathrm{vrai}}\rVert$ (m)"],
        [labels, it.cost, it.distance_to_map, it.error],
        [None, "{:.6g}", "{:.2e}", "{:.4f}"],
    )
