"""Une seule suite qui vérifie par perturbation **toutes** les jacobiennes analytiques du paquet (comme manif
le fait pour tous ses groupes) : modèles des scénarios, caméra, jacobiennes de SO(3)/SE(3)/SE(2), adjointes,
prédiction sur SE(3), prédictions de l'EKF invariant et de l'EKF standard sur SE(2).

La référence est indépendante du code testé : différences centrées écrites ici, et, pour les groupes,
l'exponentielle et le logarithme de matrices de scipy (``expm``, ``logm``) appliqués à des matrices
construites ici. Ajouter une jacobienne au paquet = ajouter une ligne à ``CASES``.
"""

from __future__ import annotations

from typing import Callable, NamedTuple

import numpy as np
import pytest
import scipy.linalg

import kalman_course as kc
from kalman_course.scenarios.polar import polar_to_cartesian, polar_to_cartesian_jacobian
from kalman_course.geometry import camera as cam
from kalman_course.geometry import lie
from kalman_course.filters import invariant as inv
from kalman_course.scenarios import radar, tag

H = 1e-6  # pas des différences centrées


def central_differences(g: Callable[[np.ndarray], np.ndarray], x: np.ndarray, h: float = H) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    cols = []
    for j in range(x.size):
        e = np.zeros_like(x)
        e[j] = h
        cols.append((np.asarray(g(x + e)) - np.asarray(g(x - e))) / (2 * h))
    return np.column_stack(cols)


# --------------------------------------------------------------------------- groupes, écrits ici


def hat_so3(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def vee_so3(W):
    return np.array([W[2, 1], W[0, 2], W[1, 0]])


def hat_se3(xi):  # xi = [rho; theta]
    X = np.zeros((4, 4))
    X[:3, :3] = hat_so3(xi[3:])
    X[:3, 3] = xi[:3]
    return X


def vee_se3(X):
    return np.concatenate([X[:3, 3], vee_so3(X[:3, :3])])


def Exp3(w):
    return scipy.linalg.expm(hat_so3(w))


def Log3(R):
    return vee_so3(np.real(scipy.linalg.logm(R)))


def Exp6(xi):
    return scipy.linalg.expm(hat_se3(xi))


def Log6(T):
    return vee_se3(np.real(scipy.linalg.logm(T)))


class Case(NamedTuple):
    name: str
    analytic: Callable[[np.ndarray], np.ndarray]   # point → jacobienne analytique
    perturbed: Callable[[np.ndarray, np.ndarray], np.ndarray]  # (point, δ) → fonction dont la dérivée en δ = 0 est la jacobienne
    points: list
    tol: float                                      # tolérance relative à max|J|


def _vector_case(name, f, jac, points, tol=1e-7):
    return Case(name, jac, lambda x, d: f(x + d), points, tol)


RNG = np.random.default_rng(20261123)
XI = [RNG.normal(size=6) * s for s in (0.3, 0.3, 1.0, 1.0, 2.0)] + [np.array([0.1, -0.2, 0.3, 1e-5, -2e-5, 1e-5])]
W3 = [x[3:] for x in XI]
POSES = [Exp6(x) for x in XI]
TAG_X = [np.array([2.0, 6.0, 0.3, -0.1]), np.array([8.5, 1.5, -0.4, 0.2]), np.array([5.0, 4.0, 0.0, 0.0])]
RADAR_X = [np.array([3.0, 4.0, 0.1, 0.2]), np.array([-7.0, 0.5, 0.3, -0.1]), np.array([10.0, -2.0, 0.0, 0.0])]
TARGET = np.array([[0.1, -0.2, 0.05], [-0.3, 0.25, 0.0], [0.2, 0.3, -0.1], [0.0, 0.0, 0.2]])
CAMERA = cam.PinholeCamera(fx=520.0, fy=500.0, cx=320.0, cy=240.0)
CAM_POSES = [Exp6(np.array([0.1, -0.05, 3.5, 0.1, -0.2, 0.05])), Exp6(np.array([-0.2, 0.1, 2.0, -0.3, 0.1, 0.4]))]
U_INCR = [np.array([0.05, 0.0, 0.02, 0.0, 0.01, 0.03]), XI[2]]

_tag = tag.tag_model()
_radar2, _radar4 = radar.radar_model(), radar.radar_tracking_model()

CASES = [
    # modèles des scénarios et des figures
    _vector_case("tag : H = ∂h/∂x (distances aux ancres)", _tag.observe, _tag.observation_jacobian, TAG_X),
    _vector_case("tag : F = ∂f/∂x", lambda x: _tag.transition(x, None), lambda x: _tag.transition_jacobian(x, None), TAG_X),
    _vector_case("radar : H = ∂(r, θ)/∂x (2 états)", radar.range_bearing, radar.range_bearing_jacobian,
                 [x[:2] for x in RADAR_X[:1] + RADAR_X[2:]]),
    _vector_case("radar : H (4 états)", _radar4.observe, _radar4.observation_jacobian, RADAR_X[:1] + RADAR_X[2:]),
    _vector_case("radar : F (4 états)", lambda x: _radar4.transition(x, None),
                 lambda x: _radar4.transition_jacobian(x, None), RADAR_X),
    _vector_case("EKF : coordonnées polaires → cartésiennes", polar_to_cartesian, polar_to_cartesian_jacobian,
                 [np.array([8.0, 0.3]), np.array([2.0, -2.5])]),
    # SO(3) : Exp(w + δ) = Exp(w) Exp(J_r δ) = Exp(J_l δ) Exp(w)
    Case("SO(3) : J_r", lie.so3_right_jacobian, lambda w, d: Log3(Exp3(w).T @ Exp3(w + d)), W3, 1e-7),
    Case("SO(3) : J_l", lie.so3_left_jacobian, lambda w, d: Log3(Exp3(w + d) @ Exp3(w).T), W3, 1e-7),
    # SE(3)
    Case("SE(3) : J_r", lie.se3_right_jacobian, lambda x, d: Log6(np.linalg.inv(Exp6(x)) @ Exp6(x + d)), XI, 1e-7),
    Case("SE(3) : J_l", lie.se3_left_jacobian, lambda x, d: Log6(Exp6(x + d) @ np.linalg.inv(Exp6(x))), XI, 1e-7),
    Case("SE(3) : Ad_T (T Exp(δ) T⁻¹ = Exp(Ad_T δ))", lie.se3_adjoint,
         lambda T, d: Log6(T @ Exp6(d) @ np.linalg.inv(T)), POSES, 1e-7),
    # caméra : h(T Exp(δ)) et h(Exp(δ) T)
    Case("caméra : ∂h/∂δ à droite", lambda T: cam.camera_measurement_jacobian(T, TARGET, CAMERA, "right"),
         lambda T, d: cam.camera_measurement(T @ Exp6(d), TARGET, CAMERA), CAM_POSES, 1e-7),
    Case("caméra : ∂h/∂δ à gauche", lambda T: cam.camera_measurement_jacobian(T, TARGET, CAMERA, "left"),
         lambda T, d: cam.camera_measurement(Exp6(d) @ T, TARGET, CAMERA), CAM_POSES, 1e-7),
    Case("caméra : ∂π/∂P' (projection)", lambda P: np.vstack(cam.projection_jacobian(CAMERA, P[None])),
         lambda P, d: cam.project(CAMERA, (P + d)[None])[0], [np.array([0.5, -0.2, 2.0]), np.array([-1.0, 0.7, 4.5])],
         1e-7),
]


def _prediction_F(u):
    """Jacobienne F de la prédiction sur SE(3) lue dans le filtre : erreur propagée d'un pas sans bruit."""
    return lie.se3_adjoint(lie.se3_inverse(lie.se3_exp(u)))


# prédiction sur SE(3) : T̂ Exp(δ) Exp(u + w) = T̂ Exp(u) Exp(δ'), δ' ≈ F δ + G w
CASES += [
    Case("SE(3) prédiction : F = Ad_{Exp(u)}⁻¹", _prediction_F,
         lambda u, d: Log6(np.linalg.inv(Exp6(u)) @ Exp6(d) @ Exp6(u)), U_INCR, 1e-7),
    Case("SE(3) prédiction : G = J_r(u)", lie.se3_right_jacobian,
         lambda u, d: Log6(np.linalg.inv(Exp6(u)) @ Exp6(u + d)), U_INCR, 1e-7),
]


# --------------------------------------------------------------------------- SE(2) et filtrage invariant (issue 35)


def hat_se2(xi):  # xi = [rho_x, rho_y, theta]
    return np.array([[0.0, -xi[2], xi[0]], [xi[2], 0.0, xi[1]], [0.0, 0.0, 0.0]])


def Exp3s(xi):
    return scipy.linalg.expm(hat_se2(xi))


def Log3s(T):
    X = np.real(scipy.linalg.logm(T))
    return np.array([X[0, 2], X[1, 2], X[1, 0]])


XI2 = [RNG.normal(size=3) * s for s in (0.3, 1.0, 2.0)] + [np.array([0.4, -0.3, 1e-5]), np.array([2.0, 1.0, 0.04])]
POSES2 = [Exp3s(x) for x in XI2]
_odo = kc.OdometryGnssModel(0.05, [0.01, 0.02, 0.02], 1.0)
U_ODO = [np.array([1.2, 0.1, 0.3]), np.array([0.8, -0.2, -2.0]), np.array([2.0, 0.0, 0.0])]
POSE_ODO = Exp3s(np.array([1.0, -2.0, 2.5]))


def _increment(u):
    """U = [[Exp(ω dt), v dt], [0, 1]], écrit ici."""
    a = u[2] * _odo.dt
    return np.array([[np.cos(a), -np.sin(a), u[0] * _odo.dt], [np.sin(a), np.cos(a), u[1] * _odo.dt], [0, 0, 1.0]])


def _pose_state(T):
    return np.array([T[0, 2], T[1, 2], np.arctan2(T[1, 0], T[0, 0])])


def _state_pose(x):
    c, s = np.cos(x[2]), np.sin(x[2])
    return np.array([[c, -s, x[0]], [s, c, x[1]], [0, 0, 1.0]])


def _jac(kind, which, point):
    F, G = inv.se2_prediction_jacobians(_odo, POSE_ODO, point, kind)
    return F if which == "F" else G


CASES += [
    Case("SE(2) : J_r", lie.se2_right_jacobian, lambda x, d: Log3s(np.linalg.inv(Exp3s(x)) @ Exp3s(x + d)), XI2, 1e-7),
    Case("SE(2) : J_l", lie.se2_left_jacobian, lambda x, d: Log3s(Exp3s(x + d) @ np.linalg.inv(Exp3s(x))), XI2, 1e-7),
    Case("SE(2) : Ad_T (T Exp(δ) T⁻¹ = Exp(Ad_T δ))", lie.se2_adjoint,
         lambda T, d: Log3s(T @ Exp3s(d) @ np.linalg.inv(T)), POSES2, 1e-7),
    # EKF invariant : T̂ Exp(ξ) U(u + w) = T̂ U(u) Exp(ξ'), ξ' ≈ F ξ + G w
    Case("SE(2) EKF invariant : F = Ad(U⁻¹)", lambda u: _jac("invariant", "F", u),
         lambda u, d: Log3s(np.linalg.inv(_increment(u)) @ Exp3s(d) @ _increment(u)), U_ODO, 1e-7),
    Case("SE(2) EKF invariant : G = dt diag(Exp(ω dt)ᵀ, 1)", lambda u: _jac("invariant", "G", u),
         lambda u, d: Log3s(np.linalg.inv(_increment(u)) @ _increment(u + d)), U_ODO, 1e-7),
    # EKF standard : x' = f(x, u + w), x = [p; θ] ; F = ∂f/∂x, G = ∂f/∂w
    Case("SE(2) EKF standard : F = [[I, R̂ J v dt], [0, 1]]", lambda u: _jac("standard", "F", u),
         lambda u, d: _pose_state(_state_pose(_pose_state(POSE_ODO) + d) @ _increment(u)), U_ODO, 1e-7),
    Case("SE(2) EKF standard : G = dt diag(R̂, 1)", lambda u: _jac("standard", "G", u),
         lambda u, d: _pose_state(POSE_ODO @ _increment(u + d)), U_ODO, 1e-7),
]


@pytest.mark.parametrize("kind", ["invariant", "standard"])
def test_se2_prediction_steps_use_these_jacobians(kind):
    """La covariance prédite des deux filtres sur SE(2) (un tirage et en lot) est F P Fᵀ + G Q Gᵀ, F et G par
    différences centrées de l'erreur propagée (écrites ici) ; la pose prédite est T̂ U."""
    u = U_ODO[1]
    P = np.array([[0.04, 0.01, -0.02], [0.01, 0.09, 0.03], [-0.02, 0.03, 0.25]])
    if kind == "invariant":
        F = central_differences(lambda d: Log3s(np.linalg.inv(_increment(u)) @ Exp3s(d) @ _increment(u)), np.zeros(3))
        G = central_differences(lambda d: Log3s(np.linalg.inv(_increment(u)) @ _increment(u + d)), np.zeros(3))
        step = inv.se2_invariant_predict
    else:
        x = _pose_state(POSE_ODO)
        F = central_differences(lambda d: _pose_state(_state_pose(x + d) @ _increment(u)), np.zeros(3))
        G = central_differences(lambda d: _pose_state(POSE_ODO @ _increment(u + d)), np.zeros(3))
        step = inv.se2_standard_predict
    T, Pp = step(_odo, POSE_ODO, P, u)
    expected = F @ P @ F.T + G @ _odo.Q @ G.T
    np.testing.assert_allclose(Pp, expected, rtol=1e-7, atol=1e-10)
    np.testing.assert_allclose(T, POSE_ODO @ _increment(u), rtol=1e-12, atol=1e-12)
    family = inv.se2_family(kind)
    Tb, Pb = family.predict_many(_odo, (POSE_ODO[None], P[None]), u[None], 0)
    np.testing.assert_allclose(Pb[0], expected, rtol=1e-7, atol=1e-10)
    np.testing.assert_allclose(Tb[0], T, rtol=1e-12, atol=1e-12)


# assimilation de données (issue 33) : h(x) = x de Lorenz-63 et Lorenz-96, jacobienne I
_l63, _l96 = kc.lorenz63(), kc.lorenz96(8)
CASES += [
    _vector_case("Lorenz-63 : H = I", _l63.observe, _l63.observation_jacobian, [np.array([1.5, -1.5, 25.0])]),
    _vector_case("Lorenz-96 : H = I", _l96.observe, _l96.observation_jacobian, [np.linspace(-3.0, 8.0, 8)]),
]


@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_analytic_jacobian_matches_perturbation(case):
    for point in case.points:
        J = np.asarray(case.analytic(point), dtype=float)
        dim = J.shape[1]
        J_num = central_differences(lambda d: case.perturbed(point, d), np.zeros(dim))
        scale = max(1.0, float(np.max(np.abs(J))))
        assert np.max(np.abs(J - J_num)) <= case.tol * scale, (case.name, point, J - J_num)


def test_prediction_step_uses_these_jacobians():
    """La covariance prédite de ``se3_predict`` est F P Fᵀ + G Q Gᵀ avec les jacobiennes vérifiées ci-dessus."""
    u = U_INCR[1]
    P = np.diag(RNG.uniform(0.01, 0.1, 6))
    Q = np.diag(RNG.uniform(0.001, 0.01, 6))
    F = central_differences(lambda d: Log6(np.linalg.inv(Exp6(u)) @ Exp6(d) @ Exp6(u)), np.zeros(6))
    G = central_differences(lambda d: Log6(np.linalg.inv(Exp6(u)) @ Exp6(u + d)), np.zeros(6))
    pred = kc.se3_predict(np.eye(4), P, u, Q)
    np.testing.assert_allclose(pred.P, F @ P @ F.T + G @ Q @ G.T, rtol=1e-7, atol=1e-10)
    np.testing.assert_allclose(pred.T, Exp6(u), rtol=1e-12, atol=1e-12)


def test_a_wrong_jacobian_fails_this_suite():
    """La suite n'est pas complaisante : une jacobienne de caméra à gauche donnée pour la droite échoue."""
    T = CAM_POSES[0]
    wrong = cam.camera_measurement_jacobian(T, TARGET, CAMERA, "left")
    J_num = central_differences(lambda d: cam.camera_measurement(T @ Exp6(d), TARGET, CAMERA), np.zeros(6))
    assert np.max(np.abs(wrong - J_num)) > 1e-2 * np.max(np.abs(J_num))


# --------------------------------------------------------------------------- issue 32 : le virage coordonné
# turn_jacobian (∂f/∂x de la transition exacte du virage, motion.py) et celle du modèle coordinated_turn qui
# la reprend, aux vitesses de rotation où ses développements limités prennent le relais (|ωΔt| < 10⁻⁴)
from kalman_course.core import motion  # noqa: E402

TURN_X = [np.array([10.0, -4.0, 30.0, 12.0, w]) for w in (0.35, -0.8, 3e-5, 0.0, 2e-4)]
_turn_model = kc.coordinated_turn(1.7, 0.5, 1e-4, np.eye(2) * 25.0)
CASES_TURN = [
    _vector_case("virage coordonné : ∂f/∂x (turn_jacobian)", lambda x: motion.turn_transition(x, 1.7),
                 lambda x: motion.turn_jacobian(x, 1.7), TURN_X),
    _vector_case("virage coordonné : F du modèle coordinated_turn", lambda x: _turn_model.transition(x, None),
                 lambda x: _turn_model.transition_jacobian(x, None), TURN_X),
]


@pytest.mark.parametrize("case", CASES_TURN, ids=[c.name for c in CASES_TURN])
def test_turn_jacobians_match_perturbation(case):
    test_analytic_jacobian_matches_perturbation(case)


# --------------------------------------------------------------------------- issue 37 : virage coordonné à pas variable
# coordinated_turn(None, …) et straight_flight(None, …) lisent Δt dans la commande u = [Δt] (instants irréguliers de
# l'hélicoptère) : leur F à des pas courts et longs, et aux vitesses de rotation des développements limités.
_turn_u = kc.coordinated_turn(None, 0.5, 1e-4, np.eye(4), C=np.eye(5)[:4])
_straight_u = kc.straight_flight(None, 0.5, np.eye(2) * 25.0)
CASES_TURN_STEP = [
    _vector_case(f"virage coordonné à pas variable : F pour Δt = {h} s", lambda x, h=h: _turn_u.transition(x, [h]),
                 lambda x, h=h: _turn_u.transition_jacobian(x, [h]), TURN_X)
    for h in (0.4, 3.1, 8.0)
] + [
    _vector_case("ligne droite sur l'état du virage : F pour Δt = 2,3 s", lambda x: _straight_u.transition(x, [2.3]),
                 lambda x: _straight_u.transition_jacobian(x, [2.3]), TURN_X),
]


@pytest.mark.parametrize("case", CASES_TURN_STEP, ids=[c.name for c in CASES_TURN_STEP])
def test_variable_step_turn_jacobians_match_perturbation(case):
    test_analytic_jacobian_matches_perturbation(case)
