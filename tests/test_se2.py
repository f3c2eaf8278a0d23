"""SE(2) (kalman_course.geometry.lie) contre des références indépendantes, à 1e-12 à tout angle.

Références écrites ici, sans le module testé : le chapeau ξ^ et l'exponentielle de matrices de scipy
(``expm``, ``logm``) ; les formes closes de l'issue 35 (R = Exp(θ), V(θ)) ; l'adjointe comme matrice de
δ ↦ (T δ^ T⁻¹)^∨ ; les jacobiennes par leur intégrale J_r(ξ) = ∫₀¹ Ad(Exp(−sξ)) ds, J_l(ξ) = ∫₀¹ Ad(Exp(sξ)) ds
(quadrature de Gauss–Legendre à 40 nœuds sur des fonctions analytiques : exacte à l'arrondi près). Les angles
couvrent les branches de Taylor et leurs seuils, les angles ordinaires, les voisins de ±π et au-delà.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

import kalman_course as kc
from kalman_course.geometry import lie

RNG = np.random.default_rng(20261128)
TOL = 1e-12


def hat(xi):
    """ξ^ = [[θJ, ρ], [0, 0]] (3, 3), écrit ici."""
    return np.array([[0.0, -xi[2], xi[0]], [xi[2], 0.0, xi[1]], [0.0, 0.0, 0.0]])


def vee(X):
    return np.array([X[0, 2], X[1, 2], X[1, 0]])


def expm(xi):
    return scipy.linalg.expm(hat(xi))


def adjoint_matrix(T):
    """Matrice de δ ↦ (T δ^ T⁻¹)^∨ (linéaire en δ : ses colonnes sont les images de la base)."""
    Ti = np.linalg.inv(T)
    return np.column_stack([vee(T @ hat(e) @ Ti) for e in np.eye(3)])


_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(40)


def jacobian_integral(xi, sign):
    """∫₀¹ Ad(Exp(sign · s ξ)) ds par Gauss–Legendre (nœuds ramenés sur [0, 1])."""
    s = 0.5 * (_NODES + 1.0)
    return 0.5 * sum(w * adjoint_matrix(expm(sign * si * np.asarray(xi))) for si, w in zip(s, _WEIGHTS))


def _angles():
    """Angles de toutes les branches : nul, minuscules, seuils de Taylor (1e-3 et 0,05) de part et d'autre,
    ordinaires, voisins de ±π, π exactement, au-delà de π."""
    fixed = [0.0, 1e-15, -3e-9, 2e-6, 0.999e-3, 1.001e-3, -1e-3, 0.0499, 0.0501, -0.05, 0.3, -1.2, 2.0,
             np.pi - 1e-9, -(np.pi - 1e-7), np.pi, 3.0, 4.0, -5.5, 12.0]
    return fixed + list(RNG.uniform(-np.pi, np.pi, 10))


ANGLES = _angles()
TANGENTS = [np.r_[RNG.normal(size=2) * RNG.choice([0.01, 1.0, 5.0]), t] for t in ANGLES]


@pytest.mark.parametrize("xi", TANGENTS, ids=[f"θ={t:.3g}" for t in ANGLES])
def test_exp_matches_expm_and_the_closed_form(xi):
    T = kc.se2_exp(xi)
    assert np.max(np.abs(T - expm(xi))) <= TOL * max(1.0, np.linalg.norm(xi))
    t = xi[2]
    R = np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]])
    V = np.eye(2) if t == 0 else np.array([[np.sin(t) / t, (np.cos(t) - 1) / t], [(1 - np.cos(t)) / t, np.sin(t) / t]])
    assert np.max(np.abs(T[:2, :2] - R)) <= TOL
    if abs(t) > 1e-4:  # la forme close de l'issue perd ε/θ en dessous
        assert np.max(np.abs(T[:2, 2] - V @ xi[:2])) <= TOL * max(1.0, np.linalg.norm(xi[:2]))
    assert np.array_equal(T[2], [0.0, 0.0, 1.0])


@pytest.mark.parametrize("xi", TANGENTS, ids=[f"θ={t:.3g}" for t in ANGLES])
def test_log_inverts_exp_with_an_angle_in_minus_pi_pi(xi):
    T = expm(xi)
    out = kc.se2_log(T)
    assert -np.pi < out[2] <= np.pi
    assert np.max(np.abs(expm(out) - T)) <= TOL * max(1.0, np.linalg.norm(xi))  # le même élément du groupe
    if -np.pi < xi[2] <= np.pi:  # la branche principale : ξ lui-même
        assert np.max(np.abs(out - xi)) <= TOL * max(1.0, np.linalg.norm(xi))
    if abs(xi[2]) < 3.0:  # logm est mal conditionné près de π
        assert np.max(np.abs(hat(out) - np.real(scipy.linalg.logm(T)))) <= 1e-11 * max(1.0, np.linalg.norm(xi))


def test_log_at_pi_returns_plus_pi():
    T = np.array([[-1.0, 0.0, 2.0], [-0.0, -1.0, 1.0], [0.0, 0.0, 1.0]])  # atan2(−0, −1) = −π
    out = kc.se2_log(T)
    assert out[2] == np.pi
    assert np.max(np.abs(expm(out) - T)) <= TOL
    np.testing.assert_allclose(out[:2], [np.pi / 2 * 1.0, -np.pi / 2 * 2.0], atol=TOL)  # V(π)⁻¹ = [[0, π/2], [−π/2, 0]]


@pytest.mark.parametrize("xi", TANGENTS[::3])
def test_inverse_and_adjoint(xi):
    T = expm(xi)
    np.testing.assert_allclose(lie.se2_inverse(T), np.linalg.inv(T), atol=TOL)
    Ad = kc.se2_adjoint(T)
    np.testing.assert_allclose(Ad, adjoint_matrix(T), atol=TOL * max(1.0, np.abs(T).max()))
    for d in (RNG.normal(size=3), np.array([0.5, -2.0, 2.5])):  # exacte pour tout δ : T Exp(δ) T⁻¹ = Exp(Ad δ)
        lhs = T @ expm(d) @ np.linalg.inv(T)
        assert np.max(np.abs(lhs - expm(Ad @ d))) <= 1e-11 * max(1.0, np.abs(lhs).max())


@pytest.mark.parametrize("xi", TANGENTS, ids=[f"θ={t:.3g}" for t in ANGLES])
def test_jacobians_match_their_integral(xi):
    Jr, Jl = kc.se2_right_jacobian(xi), kc.se2_left_jacobian(xi)
    scale = max(1.0, np.linalg.norm(xi))
    assert np.max(np.abs(Jr - jacobian_integral(xi, -1.0))) <= TOL * scale
    assert np.max(np.abs(Jl - jacobian_integral(xi, +1.0))) <= TOL * scale
    assert np.array_equal(Jl, lie.se2_right_jacobian(-xi))
    assert np.max(np.abs(Jr @ xi - xi)) <= TOL * scale  # J_r(ξ) ξ = ξ
    assert np.max(np.abs(Jl - kc.se2_adjoint(expm(xi)) @ Jr)) <= TOL * scale ** 2  # J_l = Ad_Exp(ξ) J_r


def test_exponential_in_a_batch_is_the_exponential_of_each_row():
    xis = np.array(TANGENTS)
    batch = lie._se2_exp_many(xis)
    for xi, T in zip(xis, batch):
        assert np.max(np.abs(T - kc.se2_exp(xi))) <= 1e-15 * max(1.0, np.linalg.norm(xi))


def test_taylor_thresholds_are_continuous():
    """De part et d'autre des seuils, la branche de Taylor et la forme close se rejoignent à l'arrondi près."""
    rho = np.array([3.0, -4.0])
    for t in (lie.SMALL_ANGLE, lie.SE2_TAYLOR_C):
        below, above = np.nextafter(t, 0.0), np.nextafter(t, 1.0)
        for f in (lie.se2_exp, lie.se2_right_jacobian):
            assert np.max(np.abs(f(np.r_[rho, below]) - f(np.r_[rho, above]))) <= 1e-14
        T = expm(np.r_[rho, below])
        assert np.max(np.abs(kc.se2_log(T) - np.r_[rho, below])) <= 1e-14


def test_a_wrong_jacobian_fails_the_integral_check():
    """La référence n'est pas complaisante : J_l donnée pour J_r échoue (hors de θ = 0)."""
    xi = np.array([1.0, 2.0, 0.7])
    assert np.max(np.abs(kc.se2_left_jacobian(xi) - jacobian_integral(xi, -1.0))) > 0.1


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: kc.se2_log(np.diag([1.0, 2.0, 1.0])), r"« T » n'est pas une pose plane : son bloc T\[:2, :2\] n'est pas une rotation"),
        (lambda: kc.se2_log(np.diag([1.0, -1.0, 1.0])), r"det = −1"),
        (lambda: kc.se2_adjoint(np.array([[1.0, 0, 0], [0, 1, 0], [0, 1, 1]])), r"dernière ligne doit être \[0, 0, 1\]"),
        (lambda: lie.se2_inverse(np.eye(4)), r"« T » doit être une pose plane \(3, 3\) de SE\(2\)"),
        (lambda: kc.se2_log(np.full((3, 3), np.nan)), "non finies"),
        (lambda: kc.se2_exp(np.zeros(2)), r"« xi » doit être un vecteur de forme \(3,\)"),
        (lambda: kc.se2_right_jacobian(np.zeros((3, 1))), r"vecteur colonne"),
        (lambda: kc.se2_left_jacobian("a"), r"« xi » doit être un tableau de nombres réels"),
    ],
)
def test_bad_inputs_are_french_errors(call, message):
    with pytest.raises(kc.KalmanInputError, match=message):
        call()
