r"""Exercices du filtrage non linéaire : correction de l'EKF, jacobienne des distances du tag, exponentielle
de SO(3).

Références : :func:`kalman_course.ekf_update` (le paquet), la jacobienne close des distances (vérifiée
par différences finies dans les tests) et l'exponentielle de matrice de scipy
(:func:`scipy.linalg.expm`), indépendantes de ce qu'écrit l'étudiant.
"""

from __future__ import annotations

import re

import numpy as np
import scipy.linalg

from ..core.models import NonlinearModel
from ..core.validation import KalmanInputError
from ..filters.extended import ekf_update
from .grading import Case, Exercise, Mistake, Output, close
from .matrices import generator, spd

__all__ = ["EKF_UPDATE", "TAG_JACOBIAN", "SO3_EXP", "point_function"]


def point_function(name: str, func, n: int, what: str = "x"):
    """``func`` qui refuse autre chose qu'un point (n,), avec un message en français (l'étudiant qui
    passe une colonne (n, 1) ou tous les points d'un coup le sait tout de suite)."""

    def wrapped(x):
        arr = np.asarray(x, dtype=float)
        if arr.shape != (n,):
            raise KalmanInputError(
                f"« {name} » s'applique à un seul point, un vecteur ({n},) ; reçu la forme {arr.shape}. "
                f"Appelez-la sur un point (`{name}({what})`), par exemple sur chaque ligne d'un tableau de points."
            )
        return func(arr)

    wrapped.__name__ = name
    wrapped.__qualname__ = name
    return wrapped


# --------------------------------------------------------------------------- EKF


def _range_bearing(x):
    return np.array([np.hypot(x[0], x[1]), np.arctan2(x[1], x[0])])


def _range_bearing_jacobian(x):
    r2 = x[0] ** 2 + x[1] ** 2
    r = np.sqrt(r2)
    return np.array([[x[0] / r, x[1] / r], [-x[1] / r2, x[0] / r2]])


_ANCHORS = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 8.0], [0.0, 8.0]])


def _ranges(x, anchors=_ANCHORS):
    return np.linalg.norm(x[:2] - anchors, axis=1)


def _ranges_jacobian(x, anchors=_ANCHORS):
    d = x[:2] - anchors
    H = np.zeros((anchors.shape[0], x.shape[0]))
    H[:, :2] = d / np.linalg.norm(d, axis=1, keepdims=True)
    return H


def _ekf_case(label, x, P, y, h, H, R) -> Case:
    n = x.shape[0]
    model = NonlinearModel(lambda z, u: z, h, np.eye(n), R, np.eye(n), H)
    ref = ekf_update(model, x, P, y)
    return Case(label, (x, P, y, point_function("h", h, n, "x_pred"), point_function("H", H, n, "x_pred"), R),
                (ref.x, ref.P), (x.shape, P.shape), {"h": h, "H": H})


def _ekf_cases() -> list[Case]:
    rng = generator(505)
    cases = []
    x = np.array([3.0, 4.0])
    cases.append(_ekf_case("radar : distance et azimut, n = 2, m = 2", x, np.diag([0.5, 0.8]),
                           _range_bearing(x) + np.array([0.3, -0.05]), _range_bearing, _range_bearing_jacobian,
                           np.diag([0.05**2, 0.01**2])))
    x = np.array([5.0, 4.0, 0.5, -0.2])
    cases.append(_ekf_case("distances à 4 ancres (le tag), n = 4, m = 4", x, np.diag([9.0, 9.0, 1.0, 1.0]),
                           _ranges(np.array([6.0, 3.0])) + 0.1 * rng.standard_normal(4), _ranges, _ranges_jacobian,
                           0.01 * np.eye(4)))
    C = rng.standard_normal((2, 3))
    x = rng.standard_normal(3)
    cases.append(_ekf_case("h linéaire (l'EKF est alors le filtre de Kalman), n = 3, m = 2", x, spd(rng, 3),
                           C @ x + rng.standard_normal(2), lambda z: C @ z, lambda z: C, spd(rng, 2, 0.5)))
    cases.append(_ekf_case("n = 1, m = 1 : h(x) = x³/3 + x", np.array([0.8]), np.array([[0.3]]), np.array([1.5]),
                           lambda z: z**3 / 3 + z, lambda z: np.array([[z[0] ** 2 + 1.0]]), np.array([[0.1]])))
    x = rng.standard_normal(3)
    cases.append(_ekf_case("n = 3, m = 1 : h(x) = sin x₀ + x₁ x₂", x, spd(rng, 3), np.array([0.7]),
                           lambda z: np.array([np.sin(z[0]) + z[1] * z[2]]),
                           lambda z: np.array([[np.cos(z[0]), z[2], z[1]]]), np.array([[0.2]])))
    return cases


def ekf_update_solution(x_pred, P_pred, y, h, H, R):
    """Solution de référence (appelle le paquet)."""
    n, R = len(x_pred), np.asarray(R, float)
    model = NonlinearModel(lambda z, u: z, h, np.eye(n), R, np.eye(n), H)
    ref = ekf_update(model, x_pred, P_pred, y)
    return ref.x, ref.P


def _ekf_hx_innovation(x_pred, P_pred, y, h, H, R):
    Hx = H(x_pred)
    S = Hx @ P_pred @ Hx.T + R
    K = P_pred @ Hx.T @ np.linalg.inv(S)
    x = x_pred + K @ (y - Hx @ x_pred)
    return x, (np.eye(len(x_pred)) - K @ Hx) @ P_pred


def _ekf_gain_r(x_pred, P_pred, y, h, H, R):
    Hx = H(x_pred)
    K = P_pred @ Hx.T @ np.linalg.inv(R)
    x = x_pred + K @ (y - h(x_pred))
    return x, (np.eye(len(x_pred)) - K @ Hx) @ P_pred


def _ekf_function_as_array(x_pred, P_pred, y, h, H, R):
    S = H @ P_pred @ H.T + R
    K = P_pred @ H.T @ np.linalg.inv(S)
    return x_pred + K @ (y - h(x_pred)), P_pred - K @ H @ P_pred


def _ekf_innovation_sign(x_pred, P_pred, y, h, H, R):
    Hx = H(x_pred)
    S = Hx @ P_pred @ Hx.T + R
    K = P_pred @ Hx.T @ np.linalg.inv(S)
    x = x_pred + K @ (h(x_pred) - y)
    return x, (np.eye(len(x_pred)) - K @ Hx) @ P_pred


def _ekf_h_at_corrected(x_pred, P_pred, y, h, H, R):
    Hx = H(x_pred)
    K = P_pred @ Hx.T @ np.linalg.inv(Hx @ P_pred @ Hx.T + R)
    x = x_pred + K @ (y - h(x_pred))
    return x, (np.eye(len(x_pred)) - K @ H(x)) @ P_pred


def _ekf_p_not_updated(x_pred, P_pred, y, h, H, R):
    Hx = H(x_pred)
    K = P_pred @ Hx.T @ np.linalg.inv(Hx @ P_pred @ Hx.T + R)
    return x_pred + K @ (y - h(x_pred)), P_pred


def _function_used_as_array(exc: BaseException, line: str) -> bool:
    """``H @ P`` (H la fonction) : numpy voit un objet sans dimension ; ``H.T`` : pas d'attribut ``T``."""
    message = str(exc)
    if isinstance(exc, (TypeError, AttributeError)) and "function" in message:
        return True
    used_bare = re.search(r"(?<![\w.])[hH]\b(?!\s*\()", line.split("#")[0]) is not None
    return isinstance(exc, ValueError) and "does not have enough dimensions" in message and used_bare


EKF_UPDATE = Exercise(
    id="ekf-update",
    title="Correction du filtre de Kalman étendu",
    chapter="ekf",
    signature="update(x_pred, P_pred, y, h, H, R) -> (x, P)",
    parameters=("x_pred", "P_pred", "y", "h", "H", "R"),
    outputs=(Output("x"), Output("P", "covariance")),
    make_cases=_ekf_cases,
    solution=ekf_update_solution,
    shapes_hint="x_pred (n,), P_pred (n, n), y (m,), h(x) (m,), H(x) (m, n), R (m, m)",
    mistakes=(
        Mistake("hx-innovation", "innovation y − H x⁻ au lieu de y − h(x⁻)",
                "L'EKF ne linéarise h que pour propager l'incertitude (S, K, P) ; l'innovation compare la mesure à "
                "sa prédiction par le vrai modèle : ν = y − h(x⁻). H x⁻ n'est pas la mesure prédite dès que h "
                "n'est pas linéaire (pour des distances, H x n'est même pas une distance).",
                _ekf_hx_innovation, outputs=(0,), culprit=(r"H\w*(\([^)]*\))?\s*@\s*x", r"dot\(\s*x_pred\s*\)")),
        Mistake("gain-r", "gain P Hᵀ R⁻¹ au lieu de P⁻ Hᵀ S⁻¹",
                "Comme pour le filtre linéaire, le gain divise par la covariance de l'innovation "
                "S = H P⁻ Hᵀ + R, pas par R seule.",
                _ekf_gain_r, culprit=(r"^\s*K\w*\s*=",), confirm=(r"\bR",), refute=(r"\bS\b",)),
        Mistake("function-as-array", "H utilisée comme une matrice sans l'évaluer",
                "`H` est une fonction : la jacobienne au point de linéarisation est la matrice `H(x_pred)`, de forme "
                "(m, n). Calculez-la une fois (`Hx = H(x_pred)`) puis utilisez `Hx` dans S, K et P.",
                _ekf_function_as_array, exception=_function_used_as_array),
        Mistake("innovation-sign", "innovation h(x⁻) − y au lieu de y − h(x⁻)",
                "L'innovation est la mesure moins sa prédiction, ν = y − h(x⁻) ; le signe opposé éloigne "
                "l'estimation de la mesure.",
                _ekf_innovation_sign, outputs=(0,), culprit=(r"h\(\s*x\w*\s*\)\s*-\s*y",)),
        Mistake("p-not-updated", "la covariance n'est pas corrigée",
                "P = (I − K H) P⁻ : la mesure réduit l'incertitude. Votre fonction renvoie P⁻ telle quelle.",
                _ekf_p_not_updated, outputs=(1,), output=1),
        Mistake("h-at-corrected", "jacobienne évaluée au point corrigé dans P",
                "La jacobienne se calcule une fois, au point de linéarisation x⁻ (`H(x_pred)`), et sert dans S, K "
                "et P = (I − K H) P⁻. Réévaluée au point corrigé x, elle ne correspond plus au gain : P n'est plus "
                "la covariance du filtre (ni même symétrique).",
                _ekf_h_at_corrected, outputs=(1,), output=1, culprit=(r"\bH\(\s*x\s*\)",)),
    ),
)


# --------------------------------------------------------------------------- jacobienne du tag


def ranges_jacobian_reference(x, anchors):
    r"""Forme close : ligne :math:`i` = :math:`[(p - a_i)^T/\lVert p - a_i\rVert,\ 0,\ 0]`, forme (m, 4)."""
    d = x[:2] - anchors
    H = np.zeros((anchors.shape[0], 4))
    H[:, :2] = d / np.linalg.norm(d, axis=1, keepdims=True)
    return H


def _jacobian_case(label, x, anchors) -> Case:
    H = ranges_jacobian_reference(x, anchors)
    return Case(label, (x, anchors), (H,), (H.shape,))


def _jacobian_cases() -> list[Case]:
    rng = generator(606)
    return [
        _jacobian_case("les 4 ancres de la pièce, tag au repos", np.array([6.0, 3.0, 0.0, 0.0]), _ANCHORS),
        _jacobian_case("3 ancres, tag en mouvement", np.array([2.5, 6.0, 1.0, -0.5]), _ANCHORS[:3]),
        _jacobian_case("une seule ancre", np.array([1.0, 2.0, 0.3, 0.3]), np.array([[4.0, -1.0]])),
        _jacobian_case("tag à 1 mm d'une ancre", np.array([10.0 - 1e-3, 8.0, 0.0, 0.0]), _ANCHORS),
        _jacobian_case("6 ancres au hasard", np.concatenate([rng.uniform(0, 10, 2), rng.standard_normal(2)]),
                       rng.uniform(-5, 15, (6, 2))),
    ]


def ranges_jacobian_solution(x, anchors):
    """Solution de référence (forme close)."""
    return ranges_jacobian_reference(np.asarray(x, float), np.asarray(anchors, float))


def _jac_sign(x, anchors):
    d = anchors - x[:2]
    H = np.zeros((len(anchors), 4))
    H[:, :2] = d / np.linalg.norm(d, axis=1, keepdims=True)
    return H


def _jac_not_normalised(x, anchors):
    H = np.zeros((len(anchors), 4))
    H[:, :2] = x[:2] - anchors
    return H


def _jac_squared(x, anchors):
    d = x[:2] - anchors
    H = np.zeros((len(anchors), 4))
    H[:, :2] = d / np.sum(d**2, axis=1, keepdims=True)
    return H


def _jac_no_velocity(x, anchors):
    d = x[:2] - anchors
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def _jac_transposed(x, anchors):
    d = x[:2] - anchors
    H = np.zeros((4, len(anchors)))
    H[:2] = (d / np.linalg.norm(d, axis=1, keepdims=True)).T
    return H


TAG_JACOBIAN = Exercise(
    id="tag-jacobian",
    title="Jacobienne des distances du tag aux ancres",
    chapter="suivi-tag",
    signature="ranges_jacobian(x, anchors) -> H",
    parameters=("x", "anchors"),
    outputs=(Output("H", "matrice"),),
    make_cases=_jacobian_cases,
    solution=ranges_jacobian_solution,
    shapes_hint="x (4,) = (pₓ, p_y, vₓ, v_y), anchors (m, 2) ; H (m, 4)",
    mistakes=(
        Mistake("sign", "vecteurs tag → ancre (a − p) au lieu de ancre → tag (p − a)",
                "La distance rᵢ = ‖p − aᵢ‖ croît quand le tag s'éloigne de l'ancre : ∂rᵢ/∂p = (p − aᵢ)ᵀ / rᵢ, "
                "le vecteur unitaire qui va de l'ancre vers le tag. Le signe opposé fait corriger à l'envers.",
                _jac_sign),
        Mistake("not-normalised", "p − a sans diviser par la distance",
                "La dérivée de ‖d‖ est dᵀ/‖d‖ : chaque ligne de H est un vecteur unitaire (de norme 1). "
                "Divisez par la distance rᵢ.",
                _jac_not_normalised),
        Mistake("squared", "division par le carré de la distance",
                "∂‖d‖/∂d = dᵀ/‖d‖ (la dérivée de ‖d‖² = dᵀd est 2dᵀ, celle de ‖d‖ = √(dᵀd) en découle). "
                "Divisez par rᵢ, pas par rᵢ².",
                _jac_squared),
        Mistake("no-velocity-columns", "colonnes de la vitesse oubliées",
                "L'état a quatre composantes (pₓ, p_y, vₓ, v_y) : H a une colonne par composante, forme (m, 4). "
                "Les distances ne dépendent pas de la vitesse : ses deux colonnes sont nulles, mais elles existent.",
                _jac_no_velocity,
                detect=lambda outs, case: close(outs[0], case.expected[0][:, :2])),
        Mistake("transposed", "jacobienne transposée (4, m)",
                "La jacobienne de h : ℝ⁴ → ℝᵐ a une ligne par mesure et une colonne par composante de l'état : "
                "forme (m, 4), H[i, j] = ∂hᵢ/∂xⱼ.",
                _jac_transposed,
                detect=lambda outs, case: close(outs[0], case.expected[0].T)),
    ),
)


# --------------------------------------------------------------------------- exponentielle de SO(3)


def _hat(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def so3_exp_reference(omega):
    r"""Exponentielle de matrice de :math:`[\omega]_\times` (scipy, indépendante de la formule de Rodrigues)."""
    return scipy.linalg.expm(_hat(np.asarray(omega, dtype=float)))


def _so3_case(label, omega) -> Case:
    return Case(label, (omega,), (so3_exp_reference(omega),), ((3, 3),), {"theta": float(np.linalg.norm(omega))})


def _so3_cases() -> list[Case]:
    rng = generator(707)
    axis = rng.standard_normal(3)
    axis /= np.linalg.norm(axis)
    other = rng.standard_normal(3)
    other /= np.linalg.norm(other)
    # chaque régime d'une implémentation à deux branches (petit angle, formule de Rodrigues) : nul, presque nul,
    # petit (10⁻⁵ : le développement I + [ω]× y est juste, I seule ne l'est plus), moyen, grand, au-delà de π
    return [
        _so3_case("ω = (0,3 ; −0,2 ; 0,1) rad, angle moyen (θ ≈ 0,37 rad)", np.array([0.3, -0.2, 0.1])),
        _so3_case("θ = 2,5 rad autour d'un axe quelconque (grand angle)", 2.5 * axis),
        _so3_case("ω = 0 (cas limite : aucune rotation)", np.zeros(3)),
        _so3_case("θ = 10⁻⁹ rad (presque nul)", 1e-9 * axis),
        _so3_case("θ = 10⁻⁵ rad (petit angle)", 1e-5 * other),
        _so3_case("θ = 0,05 rad (petit angle, au-delà d'un seuil de quelques 10⁻²)", 0.05 * other),
        _so3_case("θ = 1 rad autour d'un axe de coordonnées", np.array([0.0, 0.0, 1.0])),
        _so3_case("θ = π (demi-tour)", np.pi * np.array([0.0, 0.6, 0.8])),
        _so3_case("θ = 4 rad (au-delà de π)", 4.0 * other),
    ]


def so3_exp_solution(omega):
    """Solution de référence (exponentielle de matrice)."""
    return so3_exp_reference(omega)


def _so3_naive(omega):
    theta = np.linalg.norm(omega)
    K = _hat(omega / theta)
    return np.eye(3) + np.sin(theta) * K + (1 - np.cos(theta)) * K @ K


def _so3_transposed(omega):
    theta = np.linalg.norm(omega)
    if theta < 1e-12:
        return np.eye(3)
    K = _hat(omega / theta).T
    return np.eye(3) + np.sin(theta) * K + (1 - np.cos(theta)) * K @ K


def _so3_first_order(omega):
    theta = np.linalg.norm(omega)
    if theta < 1e-12:
        return np.eye(3)
    return np.eye(3) + np.sin(theta) * _hat(omega / theta)


def _so3_not_normalised(omega):
    theta = np.linalg.norm(omega)
    K = _hat(omega)
    return np.eye(3) + np.sin(theta) * K + (1 - np.cos(theta)) * K @ K


def _so3_taylor(omega):
    K = _hat(omega)
    return np.eye(3) + K + K @ K / 2


SO3_EXP = Exercise(
    id="so3-exp",
    title="Exponentielle de SO(3) (formule de Rodrigues)",
    chapter="ekf-itere-se3",
    signature="so3_exp(omega) -> R",
    parameters=("omega",),
    outputs=(Output("R", "matrice"),),
    make_cases=_so3_cases,
    solution=so3_exp_solution,
    shapes_hint="omega (3,) en radians ; R (3, 3), rotation (Rᵀ R = I, det R = 1)",
    mistakes=(
        Mistake("nan-at-zero", "division par θ = 0",
                "Pour ω = 0, l'axe ω/θ n'est pas défini : la formule donne 0/0 = NaN. Quand θ est très petit "
                "(θ < 10⁻⁸ par exemple), renvoyez I + [ω]× (développements limités sin θ/θ ≈ 1 et "
                "(1 − cos θ)/θ² ≈ 1/2), ou écrivez la formule avec sin θ/θ et (1 − cos θ)/θ² calculés sans "
                "diviser par zéro.",
                _so3_naive,
                detect=lambda outs, case: case.info["theta"] == 0.0 and not np.isfinite(outs[0]).all(),
                culprit=(r"/\s*theta", r"/\s*th\b", r"/\s*np\.linalg\.norm")),
        Mistake("transposed", "rotation inverse ([ω]× de signe opposé)",
                "La matrice antisymétrique est [ω]× = [[0, −ω₃, ω₂], [ω₃, 0, −ω₁], [−ω₂, ω₁, 0]] (de sorte que "
                "[ω]× v = ω × v). Avec le signe opposé, vous obtenez Rᵀ, la rotation inverse.",
                _so3_transposed),
        Mistake("first-order", "terme (1 − cos θ)[u]×² oublié",
                "La formule de Rodrigues a trois termes : R = I + sin θ [u]× + (1 − cos θ)[u]×², avec u = ω/θ. "
                "Sans le dernier, R n'est plus une rotation (Rᵀ R ≠ I).",
                _so3_first_order),
        Mistake("not-normalised", "axe non normé ([ω]× au lieu de [ω/θ]×)",
                "Dans R = I + sin θ [u]× + (1 − cos θ)[u]×², u = ω/θ est l'axe unitaire. Avec [ω]× (axe non "
                "normé), il faut sin θ/θ et (1 − cos θ)/θ² comme coefficients.",
                _so3_not_normalised),
        Mistake("taylor", "développement limité I + [ω]× + [ω]×²/2 utilisé pour tout θ",
                "Le développement limité ne vaut que pour θ petit ; pour θ quelconque il faut les coefficients "
                "exacts sin θ et 1 − cos θ de la formule de Rodrigues.",
                _so3_taylor),
    ),
)
