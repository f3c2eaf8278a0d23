"""SO(3) et SE(3) (kalman_course.lie) contre des références indépendantes.

Oracles (ALGORITHMS.md §8, ligne SE(3)) : Exp/Log contre ``scipy.linalg.expm``/``logm`` (1e-9) ;
jacobiennes à droite et à gauche contre les différences centrées de la rétraction (1e-8) ;
:math:`\\mathcal J_r(\\xi)\\xi = \\xi` ; adjointe : :math:`T\\,\\mathrm{Exp}(\\delta)T^{-1} = \\mathrm{Exp}(\\mathrm{Ad}_T\\delta)`
(par ``expm``). Entrées invalides : KalmanInputError en français.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

import kalman_course as kc
from kalman_course.geometry import lie

RNG = np.random.default_rng(20240611)


def _hat(xi):
    """ξ^ écrit ici à la main (indépendant du module testé)."""
    r, w = xi[:3], xi[3:]
    return np.array([[0, -w[2], w[1], r[0]], [w[2], 0, -w[0], r[1]], [-w[1], w[0], 0, r[2]], [0, 0, 0, 0.0]])


def _tangents(n=60):
    """Vecteurs tangents variés : angles ordinaires, petits (branche de Taylor), minuscules, proches de π."""
    out = []
    for k in range(n):
        xi = RNG.normal(size=6)
        w = xi[3:] / np.linalg.norm(xi[3:])
        scale = [RNG.uniform(0.05, 2.5), 10 ** RNG.uniform(-9, -3), RNG.uniform(0.9e-3, 1.1e-3),
                 np.pi - 10 ** RNG.uniform(-3, -1)][k % 4]
        xi[3:] = scale * w
        out.append(xi)
    return out


TANGENTS = _tangents()


@pytest.mark.parametrize("xi", TANGENTS)
def test_exp_matches_scipy_expm(xi):
    assert np.max(np.abs(lie.se3_exp(xi) - scipy.linalg.expm(_hat(xi)))) <= 1e-9
    W = _hat(xi)[:3, :3]
    assert np.max(np.abs(lie.so3_exp(xi[3:]) - scipy.linalg.expm(W))) <= 1e-9


@pytest.mark.parametrize("xi", TANGENTS)
def test_log_matches_scipy_logm_and_inverts_exp(xi):
    T = scipy.linalg.expm(_hat(xi))
    xi_log = lie.se3_log(T)
    assert np.max(np.abs(xi_log - xi)) <= 1e-9 * max(1.0, 1.0 / (np.pi - np.linalg.norm(xi[3:])))
    if np.linalg.norm(xi[3:]) < 3.0:  # logm est mal conditionné près de π
        L = np.real(scipy.linalg.logm(T))
        assert np.max(np.abs(_hat(xi_log) - L)) <= 1e-9
    assert np.max(np.abs(lie.vee(lie.hat(xi)) - xi)) == 0.0


def test_log_at_angle_pi_picks_the_axis():
    n = np.array([1.0, 2.0, 2.0]) / 3.0
    R = 2 * np.outer(n, n) - np.eye(3)  # rotation de π autour de n
    theta = lie.so3_log(R)
    assert abs(np.linalg.norm(theta) - np.pi) <= 1e-12
    assert np.max(np.abs(scipy.linalg.expm(_hat(np.r_[0, 0, 0, theta])[:3, :3]) - R)) <= 1e-9





@pytest.mark.parametrize("xi", TANGENTS)
def test_right_jacobian_fixes_xi_and_inverses(xi):
    assert np.max(np.abs(lie.se3_right_jacobian(xi) @ xi - xi)) <= 1e-12
    assert np.max(np.abs(lie.se3_left_jacobian(xi) @ xi - xi)) <= 1e-12
    for J, Ji in ((lie.se3_right_jacobian, lie.se3_right_jacobian_inv), (lie.se3_left_jacobian, lie.se3_left_jacobian_inv)):
        assert np.max(np.abs(J(xi) @ Ji(xi) - np.eye(6))) <= 1e-9 * np.linalg.cond(J(xi))
    assert np.max(np.abs(lie.se3_right_jacobian(xi) - lie.se3_left_jacobian(-xi))) == 0.0


@pytest.mark.parametrize("a", [0.999e-3])
def test_taylor_branch_is_accurate(a, monkeypatch):
    # branche de Taylor (a < SMALL_ANGLE) : Exp contre expm, Log∘Exp = identité, et jacobiennes égales à
    # la forme fermée juste sous le seuil (celle-ci perd ~ε/a² par annulation dans Q : on le tolère)
    xi = np.r_[0.3, -1.0, 0.5, a * np.array([0.6, 0.0, 0.8])]
    assert np.max(np.abs(lie.se3_exp(xi) - scipy.linalg.expm(_hat(xi)))) <= 1e-14
    assert np.max(np.abs(lie.se3_log(lie.se3_exp(xi)) - xi)) <= 1e-15
    funcs = (lie.se3_right_jacobian, lie.se3_right_jacobian_inv, lie.se3_left_jacobian)
    taylor = [f(xi) for f in funcs]
    monkeypatch.setattr(lie, "SMALL_ANGLE", 0.0)
    closed = [f(xi) for f in funcs]
    for t, c in zip(taylor, closed):
        assert np.max(np.abs(t - c)) <= 10 * np.finfo(float).eps / a**2


@pytest.mark.parametrize("seed", range(5))
def test_adjoint_moves_a_perturbation_across_the_pose(seed):
    gen = np.random.default_rng(seed)
    T = scipy.linalg.expm(_hat(gen.normal(size=6)))
    d = gen.normal(size=6)
    lhs = T @ scipy.linalg.expm(_hat(d)) @ np.linalg.inv(T)
    assert np.max(np.abs(lhs - scipy.linalg.expm(_hat(lie.se3_adjoint(T) @ d)))) <= 1e-9


def test_oplus_ominus_round_trip():
    T0 = lie.se3_exp([1.0, -2.0, 3.0, 0.3, 0.2, -0.1])
    d = np.array([0.1, 0.2, -0.3, 0.5, -0.4, 0.2])
    T1 = kc.oplus(T0, d)
    assert np.max(np.abs(T1 - T0 @ scipy.linalg.expm(_hat(d)))) <= 1e-12
    assert np.max(np.abs(kc.ominus(T1, T0) - d)) <= 1e-12


# --------------------------------------------------------------------------- entrées invalides


@pytest.mark.parametrize(
    "T, message",
    [
        (np.diag([1.0, 1.0, 2.0, 1.0]), "n'est pas une transformation rigide.*rotation"),
        (np.diag([1.0, 1.0, -1.0, 1.0]), "det = −1"),
        (np.vstack([np.eye(4)[:3], [0, 0, 1.0, 1.0]]), r"dernière ligne doit être \[0, 0, 0, 1\]"),
        (np.eye(3), r"transformation rigide \(4, 4\)"),
        (np.full((4, 4), np.nan), "non finies"),
    ],
)
def test_non_rigid_transform_is_a_french_error(T, message):
    with pytest.raises(kc.KalmanInputError, match=message):
        lie.se3_log(T)


def test_bad_tangent_and_rotation_are_french_errors():
    with pytest.raises(kc.KalmanInputError, match=r"« xi » doit être un vecteur de forme \(6,\)"):
        lie.se3_exp(np.zeros(5))
    with pytest.raises(kc.KalmanInputError, match="« R » n'est pas une matrice de rotation"):
        lie.so3_log(2 * np.eye(3))
    with pytest.raises(kc.KalmanInputError, match="« T0 » n'est pas une transformation rigide"):
        kc.ominus(np.eye(4), 2 * np.eye(4))
    with pytest.raises(kc.KalmanInputError, match=r"« delta » doit être un vecteur de forme \(6,\)"):
        kc.oplus(np.eye(4), np.zeros((6, 1)))
