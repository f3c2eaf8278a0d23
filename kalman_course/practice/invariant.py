r"""Exercices du filtrage invariant sur SE(2) : l'exponentielle, la prédiction et la correction de l'EKF
invariant (chapitre « Filtrage invariant sur les groupes de Lie »).

Références indépendantes de ce qu'écrit l'étudiant : l'exponentielle de matrice de scipy
(:func:`scipy.linalg.expm`) pour ``se2-exp`` ; les étapes du paquet
(:func:`kalman_course.filters.invariant.se2_invariant_update`, et la prédiction écrite avec
:func:`kalman_course.se2_adjoint`) pour les deux autres. Les cas cachés couvrent les petits angles
(0, 10⁻⁹ rad), les angles moyens et les grands (π, au-delà d'un tour).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from ..filters.invariant import odometry_increment, se2_invariant_update
from ..geometry.lie import se2_adjoint, se2_inverse
from .grading import Case, Exercise, Mistake, Output
from .matrices import generator, spd

__all__ = ["SE2_EXP", "SE2_INVARIANT_PREDICT", "SE2_INVARIANT_UPDATE"]

CHAPTER = "filtrage-invariant"


def _hat(xi):
    return np.array([[0.0, -xi[2], xi[0]], [xi[2], 0.0, xi[1]], [0.0, 0.0, 0.0]])


def _rot(a):
    return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])


def _pose(theta, p):
    T = np.eye(3)
    T[:2, :2], T[:2, 2] = _rot(theta), p
    return T


# --------------------------------------------------------------------------- exponentielle de SE(2)


def se2_exp_reference(xi):
    r"""Exponentielle de matrice de :math:`\xi^\wedge` (scipy, indépendante de la forme close :math:`V(\theta)`)."""
    return scipy.linalg.expm(_hat(np.asarray(xi, dtype=float)))


def _exp_case(label, xi) -> Case:
    xi = np.asarray(xi, dtype=float)
    return Case(label, (xi,), (se2_exp_reference(xi),), ((3, 3),), {"theta": float(xi[2])})


def _exp_cases() -> list[Case]:
    return [
        _exp_case("angle moyen : ξ = (1 ; 0,5 ; 0,3)", [1.0, 0.5, 0.3]),
        _exp_case("θ = 0 (cas limite : translation pure)", [2.0, -1.0, 0.0]),
        _exp_case("petit angle : θ = 10⁻⁹ rad", [0.7, 0.2, 1e-9]),
        _exp_case("grand angle : θ = 2,5 rad", [-1.0, 2.0, 2.5]),
        _exp_case("θ = π (demi-tour)", [1.0, 1.0, np.pi]),
        _exp_case("angle négatif : θ = −1,2 rad", [0.5, 3.0, -1.2]),
        _exp_case("au-delà d'un tour : θ = 7 rad", [1.5, -0.5, 7.0]),
    ]


def se2_exp_solution(xi):
    """Solution de référence (exponentielle de matrice)."""
    return se2_exp_reference(xi)


def _closed_form(xi, V_of=None, R_sign=1.0):
    rho, t = np.asarray(xi[:2], float), float(xi[2])
    T = np.eye(3)
    T[:2, :2] = _rot(R_sign * t)
    T[:2, 2] = rho if V_of is None else V_of(t) @ rho
    return T


def _v(t):
    return np.array([[np.sin(t) / t, (np.cos(t) - 1) / t], [(1 - np.cos(t)) / t, np.sin(t) / t]])


def _v_safe(t):
    return np.eye(2) if abs(t) < 1e-12 else _v(t)


def _exp_v_forgotten(xi):
    return _closed_form(xi)  # translation ρ : V(θ) oubliée


def _exp_nan_at_zero(xi):
    return _closed_form(xi, _v)


def _exp_rotation_transposed(xi):
    return _closed_form(xi, lambda t: _v_safe(t), R_sign=-1.0)


def _exp_v_transposed(xi):
    return _closed_form(xi, lambda t: _v_safe(t).T)


SE2_EXP = Exercise(
    id="se2-exp",
    title="Exponentielle de SE(2)",
    chapter=CHAPTER,
    signature="se2_exp(xi) -> T",
    parameters=("xi",),
    outputs=(Output("T", "matrice"),),
    make_cases=_exp_cases,
    solution=se2_exp_solution,
    shapes_hint="xi (3,) = (ρₓ, ρ_y, θ) en m, m, rad ; T (3, 3), dernière ligne (0, 0, 1)",
    mistakes=(
        Mistake("v-forgotten", "translation ρ au lieu de V(θ) ρ",
                "Exp(ξ) n'avance pas en ligne droite : le robot tourne pendant qu'il avance, et arrive en V(θ) ρ, "
                "V(θ) = [[sin θ/θ, (cos θ − 1)/θ], [(1 − cos θ)/θ, sin θ/θ]]. Mettre ρ dans la dernière colonne "
                "revient à séparer rotation et translation (SO(2) × ℝ²), ce qui n'est pas l'exponentielle de SE(2).",
                _exp_v_forgotten, culprit=(r"\[:2,\s*2\]\s*=\s*(xi|rho)",)),
        Mistake("nan-at-zero", "division par θ = 0",
                "Pour θ = 0, sin θ/θ et (1 − cos θ)/θ valent 0/0 = NaN. Leur limite est 1 et 0 : V(0) = I. Quand "
                "|θ| est très petit (10⁻⁸ par exemple), prenez V = I + (θ/2) J (développement limité), ou "
                "testez θ = 0 à part.",
                _exp_nan_at_zero,
                detect=lambda outs, case: case.info["theta"] == 0.0 and not np.isfinite(outs[0]).all(),
                culprit=(r"/\s*theta", r"/\s*th\b", r"/\s*t\b", r"/\s*xi\[2\]")),
        Mistake("rotation-transposed", "rotation inverse (le signe de sin θ échangé)",
                "Exp(θ) = [[cos θ, −sin θ], [sin θ, cos θ]] : le −sin θ est en haut à droite. Avec le signe échangé, "
                "vous obtenez Exp(−θ), la rotation inverse.",
                _exp_rotation_transposed),
        Mistake("v-transposed", "V(θ) transposée (les termes en 1 − cos θ échangés)",
                "V(θ) = [[sin θ/θ, (cos θ − 1)/θ], [(1 − cos θ)/θ, sin θ/θ]] : en haut à droite (cos θ − 1)/θ, "
                "négatif pour θ > 0. Avec Vᵀ, l'arc tourne dans le mauvais sens : le robot tourne à gauche mais "
                "l'arc part à droite.",
                _exp_v_transposed),
    ),
)


# --------------------------------------------------------------------------- prédiction de l'EKF invariant


def invariant_predict_reference(T, P, u, dt, Q):
    r""":math:`\hat TU`, :math:`FPF^T + GQG^T` avec :math:`F = \mathrm{Ad}_{U^{-1}}` (l'adjointe du paquet, vérifiée
    par différences finies) et :math:`G = dt\,\mathrm{diag}(\mathrm{Exp}(\omega dt)^T, 1)`."""
    T, P, u, Q = (np.asarray(a, dtype=float) for a in (T, P, u, Q))
    U = odometry_increment(u, dt)
    F = se2_adjoint(se2_inverse(U))
    G = dt * np.eye(3)
    G[:2, :2] = dt * U[:2, :2].T
    Pp = F @ P @ F.T + G @ Q @ G.T
    return T @ U, 0.5 * (Pp + Pp.T)


def _predict_case(label, T, P, u, dt, Q) -> Case:
    ref = invariant_predict_reference(T, P, u, dt, Q)
    return Case(label, (T, P, np.asarray(u, float), float(dt), Q), ref, ((3, 3), (3, 3)),
                {"omega_dt": float(u[2] * dt)})


def _predict_cases() -> list[Case]:
    rng = generator(808)
    Q = np.diag([0.04, 0.01, 0.09])
    return [
        _predict_case("pas d'odométrie à 100 Hz, petit angle ω dt = 1,6 × 10⁻³ rad", _pose(0.4, [1.0, 2.0]),
                      spd(rng, 3, 0.2), [1.0, 0.0, 0.157], 0.01, Q),
        _predict_case("angle moyen : ω dt = 0,3 rad, vitesse latérale non nulle", _pose(-1.0, [3.0, -1.0]),
                      spd(rng, 3, 0.5), [2.0, 0.5, 1.5], 0.2, np.diag([0.09, 0.25, 0.04])),
        _predict_case("grand angle : ω dt = 2 rad", _pose(2.5, [-2.0, 0.5]), spd(rng, 3, 1.0),
                      [1.0, -0.3, 4.0], 0.5, np.diag([0.01, 0.04, 0.16])),
        _predict_case("sans rotation (ω = 0), covariance pleine", _pose(0.0, [0.0, 0.0]), spd(rng, 3, 0.3),
                      [1.5, 0.0, 0.0], 0.1, Q),
        _predict_case("recul en tournant : v < 0, ω dt = −1 rad", _pose(np.pi, [5.0, 5.0]), spd(rng, 3, 0.7),
                      [-1.0, 0.2, -2.0], 0.5, np.diag([0.02, 0.02, 0.01])),
    ]


def invariant_predict_solution(T, P, u, dt, Q):
    """Solution de référence."""
    return invariant_predict_reference(T, P, u, dt, Q)


def _with(F_of=None, G_of=None, pose_left=False, transpose=True):
    def predict(T, P, u, dt, Q):
        T, P, u, Q = (np.asarray(a, dtype=float) for a in (T, P, u, Q))
        U = odometry_increment(u, dt)
        F = se2_adjoint(se2_inverse(U)) if F_of is None else F_of(U)
        G = dt * np.eye(3)
        G[:2, :2] = dt * U[:2, :2].T
        if G_of is not None:
            G = G_of(U, dt)
        Pp = (F @ P @ F.T if transpose else F @ P @ F) + G @ Q @ G.T
        return (U @ T if pose_left else T @ U), Pp
    return predict


_predict_adjoint = _with(F_of=lambda U: se2_adjoint(U))
_predict_noise_not_rotated = _with(G_of=lambda U, dt: dt * np.eye(3))
_predict_dt_forgotten = _with(G_of=lambda U, dt: np.block([[U[:2, :2].T, np.zeros((2, 1))], [np.zeros((1, 2)), np.ones((1, 1))]]))
_predict_pose_left = _with(pose_left=True)
_predict_no_transpose = _with(transpose=False)


SE2_INVARIANT_PREDICT = Exercise(
    id="se2-invariant-predict",
    title="Prédiction de l'EKF invariant sur SE(2)",
    chapter=CHAPTER,
    signature="predict(T, P, u, dt, Q) -> (T_pred, P_pred)",
    parameters=("T", "P", "u", "dt", "Q"),
    outputs=(Output("T_pred", "matrice"), Output("P_pred", "covariance")),
    make_cases=_predict_cases,
    solution=invariant_predict_solution,
    shapes_hint="T (3, 3), P (3, 3), u (3,) = (vₓ, v_y, ω), dt (s), Q (3, 3) ; T_pred (3, 3), P_pred (3, 3)",
    mistakes=(
        Mistake("adjoint-not-inverted", "F = Ad(U) au lieu de Ad(U⁻¹)",
                "L'erreur à gauche suit ξ' = Ad(U⁻¹) ξ : de T̂ Exp(ξ) U = T̂ U (U⁻¹ Exp(ξ) U), c'est U⁻¹ qui "
                "conjugue l'erreur. Ad(U) la tourne dans le mauvais sens (et déplace le bras de levier) : prenez "
                "l'adjointe de l'inverse, Ad(U⁻¹) = [[Rᵀ, −J p'], [0, 1]] avec U⁻¹ = [[Rᵀ, p'], [0, 1]].",
                _predict_adjoint, outputs=(1,), output=1, culprit=(r"adjoint\(\s*U\s*\)", r"^\s*F\w*\s*=")),
        Mistake("noise-not-rotated", "G = dt I : le bruit de vitesse n'est pas tourné par Exp(ω dt)ᵀ",
                "Le bruit d'odométrie entre dans U, à droite : U⁻¹ Ũ = [[Exp(w_ω dt), Exp(ω dt)ᵀ w_v dt], [0, 1]]. "
                "Le bruit de vitesse est donc tourné par Exp(ω dt)ᵀ : G = dt diag(Exp(ω dt)ᵀ, 1).",
                _predict_noise_not_rotated, outputs=(1,), output=1, culprit=(r"^\s*G\w*\s*=",)),
        Mistake("dt-forgotten", "G sans le facteur dt",
                "u est une vitesse : son bruit déplace la pose de w dt pendant un pas. G = dt diag(Exp(ω dt)ᵀ, 1), "
                "et la covariance ajoutée est G Q Gᵀ = dt² (…).",
                _predict_dt_forgotten, outputs=(1,), output=1, culprit=(r"^\s*G\w*\s*=",)),
        Mistake("pose-left", "T_pred = U T au lieu de T U",
                "L'odométrie est mesurée dans le repère du robot : l'incrément se compose à droite, T_{k+1} = T_k U_k. "
                "U T appliquerait le déplacement dans le repère du monde.",
                _predict_pose_left, outputs=(0,), output=0, culprit=(r"U\w*\s*@\s*T",)),
        Mistake("no-transpose", "F P F au lieu de F P Fᵀ",
                "La covariance de F ξ est F P Fᵀ : la transposée est indispensable (F n'est pas symétrique).",
                _predict_no_transpose, outputs=(1,), output=1, culprit=(r"F\w*\s*@\s*P\w*\s*@\s*F\w*(?!\s*\.T)",)),
    ),
)


# --------------------------------------------------------------------------- correction de l'EKF invariant


def _update_case(label, theta, p, P, y, sigma) -> Case:
    T = _pose(theta, p)
    ref = se2_invariant_update(T, P, y, sigma)
    return Case(label, (T, P, np.asarray(y, float), float(sigma)), (ref.T, ref.P), ((3, 3), (3, 3)),
                {"theta": float(theta), "correction_angle": float((ref.K @ ref.innovation)[2])})


def _update_cases() -> list[Case]:
    rng = generator(909)
    P1 = spd(rng, 3, 0.5)
    P1[2, 2] += 0.5
    return [
        _update_case("cap de 60°, petite correction d'angle", np.pi / 3, [2.0, 1.0], spd(rng, 3, 0.1),
                     [2.3, 1.4], 1.0),
        _update_case("cap de 170°, grande correction d'angle", np.radians(170.0), [-3.0, 4.0], P1, [-5.0, 2.0], 0.5),
        _update_case("le TD 6 : cap 90°, correction de 90°", np.pi / 2, [3.0, 1.0],
                     np.array([[1.0, 0.0, np.pi / 2], [0.0, 1.0, 0.0], [np.pi / 2, 0.0, 4.0]]), [3.0, 3.0], 1.0),
        _update_case("cap de −2 rad, GNSS précis (σ = 0,1 m)", -2.0, [10.0, -5.0], spd(rng, 3, 2.0),
                     [10.5, -4.2], 0.1),
        _update_case("cap presque nul (10⁻⁹ rad)", 1e-9, [0.0, 0.0], spd(rng, 3, 1.0), [1.0, -1.0], 2.0),
    ]


def invariant_update_solution(T_pred, P_pred, y, gnss_std):
    """Solution de référence (appelle le paquet)."""
    ref = se2_invariant_update(T_pred, P_pred, y, gnss_std)
    return ref.T, ref.P


def _update_with(rotate=True, where="right", gain_r=False, update_P=True):
    def update(T_pred, P_pred, y, gnss_std):
        T_pred, P_pred, y = (np.asarray(a, dtype=float) for a in (T_pred, P_pred, y))
        d = y - T_pred[:2, 2]
        z = T_pred[:2, :2].T @ d if rotate else d
        H = np.hstack([np.eye(2), np.zeros((2, 1))])
        R = gnss_std**2 * np.eye(2)
        S = H @ P_pred @ H.T + R
        K = P_pred @ H.T @ np.linalg.inv(R if gain_r else S)
        dx = K @ z
        if where == "right":
            T = T_pred @ scipy.linalg.expm(_hat(dx))
        elif where == "left":
            T = scipy.linalg.expm(_hat(dx)) @ T_pred
        else:  # [p ; θ] += K z dans le repère du monde
            theta = np.arctan2(T_pred[1, 0], T_pred[0, 0]) + dx[2]
            T = _pose(theta, T_pred[:2, 2] + dx[:2])
        P = (np.eye(3) - K @ H) @ P_pred if update_P else P_pred
        return T, P
    return update


_update_world_innovation = _update_with(rotate=False)
_update_left = _update_with(where="left")
_update_additive = _update_with(where="add")
_update_gain_r = _update_with(gain_r=True)
_update_p_not_updated = _update_with(update_P=False)


SE2_INVARIANT_UPDATE = Exercise(
    id="se2-invariant-update",
    title="Correction de l'EKF invariant sur SE(2) par une position GNSS",
    chapter=CHAPTER,
    signature="update(T_pred, P_pred, y, gnss_std) -> (T, P)",
    parameters=("T_pred", "P_pred", "y", "gnss_std"),
    outputs=(Output("T", "matrice"), Output("P", "covariance")),
    make_cases=_update_cases,
    solution=invariant_update_solution,
    shapes_hint="T_pred (3, 3), P_pred (3, 3), y (2,) position GNSS (m), gnss_std (m) ; T (3, 3), P (3, 3)",
    mistakes=(
        Mistake("world-innovation", "innovation y − p̂ dans le repère du monde",
                "L'erreur invariante ξ est exprimée dans le repère du robot : p − p̂ = R̂ V(ξ_θ) ξ_ρ. L'innovation qui "
                "ne dépend que de ξ est z = R̂ᵀ (y − p̂) ; avec y − p̂ (repère du monde), H = [I 0] est fausse dès "
                "que le cap estimé n'est pas nul.",
                _update_world_innovation, outputs=(0,), output=0, culprit=(r"^\s*z\w*\s*=", r"^\s*nu\w*\s*=")),
        Mistake("left-correction", "correction à gauche, Exp(K z) T̂",
                "L'erreur est à droite, T = T̂ Exp(ξ) : la correction aussi, T̂₊ = T̂ Exp(K z). Exp(K z) T̂ "
                "appliquerait la correction dans le repère du monde.",
                _update_left, outputs=(0,), output=0),
        Mistake("additive-correction", "[p̂ ; θ̂] += K z, comme l'EKF standard",
                "K z est un vecteur tangent, exprimé dans le repère du robot : il s'applique par l'exponentielle, "
                "T̂₊ = T̂ Exp(K z). L'ajouter à la position et au cap du monde mélange les repères et oublie V(θ).",
                _update_additive, outputs=(0,), output=0),
        Mistake("gain-r", "gain P Hᵀ R⁻¹ au lieu de P Hᵀ S⁻¹",
                "Comme pour tout filtre de Kalman, le gain divise par la covariance de l'innovation "
                "S = H P Hᵀ + σ² I, pas par la seule covariance du GNSS.",
                _update_gain_r, culprit=(r"^\s*K\w*\s*=",)),
        Mistake("p-not-updated", "la covariance n'est pas corrigée",
                "P₊ = (I − K H) P⁻ : la position GNSS réduit l'incertitude. Votre fonction renvoie P⁻ telle quelle.",
                _update_p_not_updated, outputs=(1,), output=1),
    ),
)
