"""Temps continu : la discrétisation par élévation au carré contre filterpy, les formes closes (calculées en
décimales à 80 chiffres) et une intégrale numérique ; le virage coordonné contre sa définition (rotation de la
vitesse) ; sa jacobienne est vérifiée par perturbation avec toutes les autres (tests/test_jacobian_suite.py)."""

from __future__ import annotations

from decimal import Decimal, getcontext

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


# --------------------------------------------------------------------------- formes closes, tous les pas
# Les formes closes sont calculées en arithmétique décimale à 80 chiffres (module decimal) : elles sont
# exactes à la double près, même où la formule soustrait des nombres presque égaux (petit Δt/τ).

getcontext().prec = 80
RATIOS = 10.0 ** np.arange(-6.0, 3.01, 0.5)  # Δt/τ de 10⁻⁶ à 10³


def _relative(got, ref):
    """Écart relatif coefficient par coefficient (un coefficient nul de la référence doit l'être aussi)."""
    ref = np.asarray(ref, dtype=float)
    zero = ref == 0.0
    assert np.all(np.asarray(got)[zero] == 0.0)
    if zero.all():
        return 0.0
    return float(np.max(np.abs(np.asarray(got)[~zero] - ref[~zero]) / np.abs(ref[~zero])))


@pytest.mark.parametrize("ratio", RATIOS)
def test_ornstein_uhlenbeck_is_exact_for_every_step(ratio):
    """dx = −λx dt + σ dβ : A = e^{−λΔt}, Q = σ²(1 − e^{−2λΔt})/(2λ), pour λΔt de 10⁻⁶ à 10³ (avant :
    NaN à λΔt = 1 000, la méthode de Van Loan formant e^{+λΔt})."""
    lam, sigma2 = 3.0, 0.7
    dt = ratio / lam
    A, Q = kc.discretize([[-lam]], [[1.0]], sigma2, dt)
    l_, s_, t_ = Decimal(lam), Decimal(sigma2), Decimal(dt)
    a = float((-l_ * t_).exp())
    q = float(s_ * (1 - (-2 * l_ * t_).exp()) / (2 * l_))
    assert _relative(A, [[a]]) <= 1e-12 and _relative(Q, [[q]]) <= 1e-12


@pytest.mark.parametrize("dt", 10.0 ** np.arange(-6.0, 3.01, 1.0))
def test_constant_velocity_is_exact_for_every_step(dt):
    """Vitesse presque constante : A = [[1, Δt], [0, 1]], Q = q [[Δt³/3, Δt²/2], [Δt²/2, Δt]], Δt de 10⁻⁶ s à
    10³ s, coefficient par coefficient."""
    q = 2.0
    A, Q = kc.constant_velocity(dt, q, dim=1)
    t_ = Decimal(dt)
    ref = [[float(Decimal(q) * t_**3 / 3), float(Decimal(q) * t_**2 / 2)],
           [float(Decimal(q) * t_**2 / 2), float(Decimal(q) * t_)]]
    assert _relative(A, [[1.0, dt], [0.0, 1.0]]) <= 1e-12 and _relative(Q, ref) <= 1e-12


def _singer_closed_form(alpha, qc, dt):
    r"""Modèle de Singer (1970 ; Bar-Shalom, Li & Kirubarajan 2001, § 8.2.3), état [p, v, a],
    ȧ = −αa + w, densité qc : A et Q en forme close (décimales)."""
    a, T, q = Decimal(alpha), Decimal(dt), Decimal(qc)
    e1, e2 = (-a * T).exp(), (-2 * a * T).exp()
    A = [[1, T, (a * T - 1 + e1) / a**2], [0, 1, (1 - e1) / a], [0, 0, e1]]
    q11 = (1 - e2 + 2 * a * T + 2 * a**3 * T**3 / 3 - 2 * a**2 * T**2 - 4 * a * T * e1) / (2 * a**5)
    q12 = (e2 + 1 - 2 * e1 + 2 * a * T * e1 - 2 * a * T + a**2 * T**2) / (2 * a**4)
    q13 = (1 - e2 - 2 * a * T * e1) / (2 * a**3)
    q22 = (4 * e1 - 3 - e2 + 2 * a * T) / (2 * a**3)
    q23 = (e2 + 1 - 2 * e1) / (2 * a**2)
    q33 = (1 - e2) / (2 * a)
    Q = [[q11, q12, q13], [q12, q22, q23], [q13, q23, q33]]
    return (np.array([[float(v) for v in row] for row in A]),
            np.array([[float(q * v) for v in row] for row in Q]))


@pytest.mark.parametrize("ratio", RATIOS)
def test_singer_model_is_exact_for_every_step(ratio):
    """Singer, τ = 0,5 s : Δt/τ de 10⁻⁶ à 10³, écart relatif ≤ 10⁻¹² coefficient par coefficient (avant :
    1,5 × 10⁻⁹ à Δt = 10 s, Q fausse de 10³³ à 60 s, NaN à 400 s). Mesuré : au plus 1,2 × 10⁻¹³ (sur A,
    dont le coefficient e^{−Δt/τ} élevé au carré s fois accumule 2ˢ arrondis), 4 × 10⁻¹⁵ sur Q."""
    tau, qc = 0.5, 2.0
    F = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0 / tau]])
    A, Q = kc.discretize(F, [[0.0], [0.0], [1.0]], qc, ratio * tau)
    A_ref, Q_ref = _singer_closed_form(1.0 / tau, qc, ratio * tau)
    assert _relative(A, A_ref) <= 1e-12 and _relative(Q, Q_ref) <= 1e-12
    assert np.linalg.eigvalsh(Q)[0] >= -1e-15 * np.abs(Q).max()


def test_long_irregular_gaps_stay_exact():
    """Des trous d'une minute entre messages ADS-B, d'autres de 0,1 s, dans un même vecteur de pas."""
    tau = 0.5
    F = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0 / tau]])
    dts = np.array([0.1, 60.0, 1.0, 400.0, 1e-4])
    A, Q = kc.discretize(F, [[0.0], [0.0], [1.0]], 1.0, dts)
    for k, h in enumerate(dts):
        A_ref, Q_ref = _singer_closed_form(1.0 / tau, 1.0, h)
        assert _relative(A[k], A_ref) <= 1e-12 and _relative(Q[k], Q_ref) <= 1e-12


def test_piecewise_constant_acceleration_is_the_same_builder():
    """constant_velocity(dt, accel_std=σ) : Q = σ²GGᵀ, G = [Δt²/2 I; Δt I] (Bar-Shalom § 6.3.2) ; contre
    Q_discrete_white_noise de filterpy (ordre [p, v] par axe) ; un seul des deux bruits."""
    from filterpy.common import Q_discrete_white_noise

    A, Q = kc.constant_velocity(0.7, accel_std=1.3, dim=1)
    assert np.allclose(Q, Q_discrete_white_noise(dim=2, dt=0.7, var=1.3**2), rtol=1e-14, atol=0)
    assert np.array_equal(A, [[1.0, 0.7], [0.0, 1.0]])
    with pytest.raises(kc.KalmanInputError, match="un seul"):
        kc.constant_velocity(1.0, 2.0, accel_std=1.0)
    with pytest.raises(kc.KalmanInputError, match="accel_std"):
        kc.constant_velocity(1.0, accel_std=-1.0)


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


def test_coordinated_turn_model_is_vectorized_and_consistent():
    model = kc.coordinated_turn(1.0, 0.5, 1e-4, np.eye(2) * 25.0)
    X = np.array([[0.0, 0.0, 50.0, 0.0, 0.1], [5.0, 1.0, -20.0, 3.0, 0.0]])
    stacked = model.transition_many(X)
    for i in range(2):
        assert np.allclose(stacked[i], model.transition(X[i]))
        assert np.allclose(model.observe(X[i]), X[i, :2])
    assert model.Q[4, 4] == pytest.approx(1e-4)
