"""Temps continu : la discrétisation de Van Loan contre filterpy, les formes closes et une intégrale
numérique ; le virage coordonné contre sa définition (rotation de la vitesse) et sa jacobienne contre des
différences finies."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.integrate
import scipy.linalg
from filterpy.common import Q_continuous_white_noise

import kalman_course as kc
from kalman_course.core import motion


@pytest.mark.parametrize("dt", [0.01, 0.4, 1.0, 7.9])
@pytest.mark.parametrize("q", [0.05, 3.0])
def test_constant_velocity_equals_filterpy_q_continuous_white_noise(dt, q):
    A, Q = kc.constant_velocity(dt, q, dim=1)
    ref = Q_continuous_white_noise(dim=2, dt=dt, spectral_density=q)
    assert np.allclose(Q, ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())
    assert np.allclose(A, [[1.0, dt], [0.0, 1.0]], rtol=1e-14, atol=1e-14)


def test_constant_velocity_in_the_plane_is_filterpy_reordered():
    """filterpy range l'état par axe ([x, vx, y, vy], block_size=2) ; le paquet, positions puis vitesses."""
    dt, q = 1.3, 0.7
    _, Q = kc.constant_velocity(dt, q, dim=2)
    ref = Q_continuous_white_noise(dim=2, dt=dt, spectral_density=q, block_size=2)
    order = [0, 2, 1, 3]  # [x, y, vx, vy] dans l'ordre de filterpy
    assert np.allclose(Q, ref[np.ix_(order, order)], rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("dt", [0.3, 2.0])
def test_constant_acceleration_equals_filterpy(dt):
    _, Q = kc.constant_acceleration(dt, 0.9, dim=1)
    ref = Q_continuous_white_noise(dim=3, dt=dt, spectral_density=0.9)
    assert np.allclose(Q, ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())


def test_discretize_matches_the_defining_integral_on_a_damped_model():
    """Un modèle qui n'est pas nilpotent (vitesse amortie, Ornstein–Uhlenbeck) : A = expm(FΔt) et Q
    comparée à l'intégrale ∫ e^{Fs} L Qc Lᵀ e^{Fᵀs} ds calculée par quadrature adaptative."""
    F = np.array([[0.0, 1.0, 0.0], [0.0, -0.4, 0.3], [0.0, -0.2, -1.1]])
    L = np.array([[0.0, 0.0], [1.0, 0.2], [0.0, 1.0]])
    Qc = np.array([[2.0, 0.3], [0.3, 0.5]])
    dt = 1.7
    A, Q = kc.discretize(F, L, Qc, dt)
    assert np.allclose(A, scipy.linalg.expm(F * dt), rtol=1e-13, atol=1e-14)
    integrand = lambda s: (scipy.linalg.expm(F * s) @ L @ Qc @ L.T @ scipy.linalg.expm(F.T * s)).ravel()
    ref = scipy.integrate.quad_vec(integrand, 0.0, dt, epsabs=1e-13, epsrel=1e-12)[0].reshape(3, 3)
    assert np.allclose(Q, ref, rtol=1e-10, atol=1e-12)


def test_ornstein_uhlenbeck_closed_form():
    """dx = −θx dt + σ dβ : A = e^{−θΔt}, Q = σ²(1 − e^{−2θΔt})/(2θ)."""
    theta, sigma, dt = 0.8, 1.5, 0.6
    A, Q = kc.discretize([[-theta]], [[1.0]], sigma**2, dt)
    assert A[0, 0] == pytest.approx(np.exp(-theta * dt), rel=1e-14)
    assert Q[0, 0] == pytest.approx(sigma**2 * (1 - np.exp(-2 * theta * dt)) / (2 * theta), rel=1e-12)


def test_irregular_steps_are_one_discretization_per_step():
    dts = np.array([0.4, 1.0, 7.9, 2.2])
    A, Q = kc.constant_velocity(dts, 0.5, dim=2)
    assert A.shape == Q.shape == (4, 4, 4)
    for k, h in enumerate(dts):
        Ak, Qk = kc.constant_velocity(h, 0.5, dim=2)
        assert np.array_equal(A[k], Ak) and np.array_equal(Q[k], Qk)


def test_two_half_steps_compose_to_one_step():
    """Propriété de semi-groupe du modèle exact : deux pas de Δt/2 font un pas de Δt."""
    F, L = kc.constant_acceleration_sde(dim=1)
    A1, Q1 = kc.discretize(F, L, 0.8, 2.0)
    Ah, Qh = kc.discretize(F, L, 0.8, 1.0)
    assert np.allclose(Ah @ Ah, A1, atol=1e-13)
    assert np.allclose(Ah @ Qh @ Ah.T + Qh, Q1, rtol=1e-12, atol=1e-13)


@pytest.mark.parametrize("bad, message", [
    (dict(dt=0.0), "strictement positif"),
    (dict(dt=[1.0, -0.5]), "strictement positif"),
    (dict(dt=[[1.0]]), "suite de pas"),
    (dict(Qc=[[-1.0]]), "semi-définie positive"),
    (dict(L=[0.0, 1.0]), "matrice 2-D"),
    (dict(F=[[0.0, 1.0]]), "carrée"),
])
def test_discretize_refuses_bad_input_in_french(bad, message):
    args = dict(F=[[0.0, 1.0], [0.0, 0.0]], L=[[0.0], [1.0]], Qc=1.0, dt=1.0)
    args.update(bad)
    with pytest.raises(kc.KalmanInputError, match=message):
        kc.discretize(**args)


def test_constant_velocity_refuses_a_negative_density():
    with pytest.raises(kc.KalmanInputError, match="accel_psd"):
        kc.constant_velocity(1.0, -1.0)
    with pytest.raises(kc.KalmanInputError, match="dim"):
        kc.constant_velocity(1.0, 1.0, dim=4)


@pytest.mark.parametrize("w", [0.35, -0.2, 1e-7, 0.0])
def test_turn_transition_rotates_the_velocity_and_integrates_the_position(w):
    """Vitesse tournée de ωΔt à norme constante ; position : intégrale de la vitesse (quadrature)."""
    x = np.array([10.0, -4.0, 30.0, 12.0, w])
    dt = 2.5
    out = motion.turn_transition(x, dt)
    c, s = np.cos(w * dt), np.sin(w * dt)
    assert np.allclose(out[2:4], [c * 30.0 - s * 12.0, s * 30.0 + c * 12.0], rtol=1e-13)
    vel = lambda t: np.array([np.cos(w * t) * 30.0 - np.sin(w * t) * 12.0, np.sin(w * t) * 30.0 + np.cos(w * t) * 12.0])
    disp = scipy.integrate.quad_vec(vel, 0.0, dt, epsabs=1e-12)[0]
    assert np.allclose(out[:2], x[:2] + disp, atol=1e-9)
    assert out[4] == w


@pytest.mark.parametrize("w", [0.35, -0.8, 3e-5, 0.0])
def test_turn_jacobian_matches_central_differences(w):
    x = np.array([10.0, -4.0, 30.0, 12.0, w])
    check = kc.check_jacobian(lambda z: motion.turn_transition(z, 1.7), lambda z: motion.turn_jacobian(z, 1.7), x,
                              rtol=1e-7)
    assert check.ok and check.max_rel_error < 1e-7, check


def test_coordinated_turn_model_is_vectorized_and_consistent():
    model = kc.coordinated_turn(1.0, 0.5, 1e-4, np.eye(2) * 25.0)
    X = np.array([[0.0, 0.0, 50.0, 0.0, 0.1], [5.0, 1.0, -20.0, 3.0, 0.0]])
    stacked = model.transition_many(X)
    for i in range(2):
        assert np.allclose(stacked[i], model.transition(X[i]))
        assert np.allclose(model.observe(X[i]), X[i, :2])
    assert model.Q[4, 4] == pytest.approx(1e-4)
