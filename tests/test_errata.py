"""Errata du cours (ALGORITHMS.md §6.2, identifiants 001-*) : chaque formule corrigée est vérifiée
numériquement contre une référence indépendante (filterpy, forme close écrite ici, scipy, simulation),
et chaque formule imprimée fausse est montrée fausse."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
import scipy.optimize

import kalman_course as kc
from conftest import filterpy_kf, random_model
from kalman_course.scenarios import engine

WB_PHI, WB_PSI = 1e-5, 0.01


def _wb():
    return kc.scenarios.constant_voltage_model(Q=WB_PHI, R=WB_PSI), kc.scenarios.constant_voltage_measurements(50)


# --------------------------------------------------------------------------- 001-1, 001-2 : E[x̂_n]


def test_001_1_mean_error_uses_expected_estimate_when_conditions_are_violated():
    """Avec A_f ≠ (I − KC)A, le terme (A_f + KCA − A) E[x̂_n] compte : la récurrence corrigée suit la
    simulation, et elle est identique à E[x̂_n] − E[x_n] propagés séparément."""
    model = engine.engine_model()
    u = engine.engine_commands(30)
    K = np.array([[8.0, 2.0], [-3.0, 12.0]])  # gain fixe quelconque (°C/mV)
    A_f = kc.error_transition(model, K) + 0.05 * np.eye(2)  # condition 2 violée
    x0_hat = np.array([5.0, -2.0])
    rec = kc.mean_error_recursion(model, K, x0_mean=engine.ENGINE_X0_MEAN, x0_hat=x0_hat, n_steps=30, u=u, A_f=A_f)
    np.testing.assert_allclose(rec.e, rec.x_hat - rec.x, atol=1e-9)
    assert np.max(np.abs(rec.e[-1])) > 1.0  # le biais ne disparaît pas
    mc = kc.monte_carlo(
        model, lambda y: kc.linear_estimator(model, y, x0_hat, K, u=u, A_f=A_f), 30, 600,
        x0_mean=engine.ENGINE_X0_MEAN, x0_cov=engine.ENGINE_X0_COV, x0_hat=x0_hat, rng=11, u=u,
    )
    z = np.abs(mc.mean_error()[1:] - rec.e[1:]) / mc.mean_error_sem()[1:]
    assert z.max() < 4.5


# --------------------------------------------------------------------------- 001-3 : (I − KC)A


def test_001_3_counter_example_printed_condition_holds_but_error_grows():
    model = kc.LinearGaussianModel(A=2.0, C=1.0, Q=0.01, R=0.01)
    K = [[0.4]]
    assert kc.errata.printed_stability_radius(model, K) == pytest.approx(0.6, abs=1e-12)
    assert kc.spectral_radius(kc.error_transition(model, K)) == pytest.approx(1.2, abs=1e-12)
    rec = kc.mean_error_recursion(model, K, x0_mean=[0.0], x0_hat=[1.0], n_steps=20)
    np.testing.assert_allclose(rec.e[:, 0], 1.2 ** np.arange(21), rtol=1e-12)
    mc = kc.monte_carlo(
        model, lambda y: kc.linear_estimator(model, y, [1.0], K), 20, 400,
        x0_mean=[0.0], x0_cov=[[0.0]], x0_hat=[1.0], rng=3,
    )
    assert mc.mean_error()[-1, 0] > 30.0  # 1,2²⁰ ≈ 38 : l'erreur moyenne diverge
    # et un gain qui rend le produit stable fait décroître l'erreur
    rec_ok = kc.mean_error_recursion(model, [[0.6]], x0_mean=[0.0], x0_hat=[1.0], n_steps=20)
    np.testing.assert_allclose(rec_ok.e[:, 0], 0.8 ** np.arange(21), rtol=1e-12)


def test_spectral_radius_against_numpy_and_errors():
    rng = np.random.default_rng(0)
    M = rng.standard_normal((4, 4))
    assert kc.spectral_radius(M) == pytest.approx(max(abs(np.linalg.eigvals(M))), rel=1e-12)
    with pytest.raises(kc.KalmanInputError, match="carrée"):
        kc.spectral_radius(np.ones((2, 3)))


# --------------------------------------------------------------------------- 001-4 : K → C⁻¹, pas I


def _final_gain(model, scale, n_steps=150):
    u = engine.engine_commands(n_steps)
    y = kc.simulate(model, engine.ENGINE_X0_MEAN, n_steps, u, rng=1).y
    assumed = kc.LinearGaussianModel(model.A, model.C, model.Q, scale * model.R, B=model.B)
    return kc.kalman_filter(assumed, y, engine.ENGINE_X0_HAT, engine.ENGINE_P0, u)


def test_001_4_gain_limits_on_invertible_non_identity_C():
    model = engine.engine_model()
    C_inv = np.linalg.inv(model.C)  # référence indépendante (numpy)
    K_small = _final_gain(model, 1e-8).K[-1]
    K_large = _final_gain(model, 1e8).K[-1]
    assert np.linalg.norm(K_small - C_inv) / np.linalg.norm(C_inv) < 1e-6
    assert np.linalg.norm(K_large) / np.linalg.norm(C_inv) < 1e-6
    # « K → I » (le schéma imprimé) est faux ici : K a les unités de C⁻¹ (°C/mV)
    assert np.linalg.norm(K_small - np.eye(2)) > 10.0


def test_001_4_gain_limit_is_a_right_inverse_for_non_square_C():
    model = engine.engine_model()
    one = kc.LinearGaussianModel(model.A, model.C[:1], model.Q, 1e-12 * model.R[:1, :1], B=model.B)
    u = engine.engine_commands(50)
    y = kc.simulate(model, engine.ENGINE_X0_MEAN, 50, u, rng=2).y[:, :1]
    res = kc.kalman_filter(one, y, engine.ENGINE_X0_HAT, engine.ENGINE_P0, u)
    K, P_pred = res.K[-1], res.P_pred[-1]
    np.testing.assert_allclose(one.C @ K, [[1.0]], atol=1e-7)
    right_inverse = P_pred @ one.C.T @ np.linalg.inv(one.C @ P_pred @ one.C.T)
    np.testing.assert_allclose(K, right_inverse, rtol=1e-6)


# --------------------------------------------------------------------------- 001-5, 001-6 : initialisation


def test_measurement_initialisation_covariance():
    """Errata 001-5 et 001-6."""
    # x̂₀ = C⁻¹y₀ a une erreur C⁻¹ψ₀ de covariance C⁻¹ΨC⁻ᵀ (vérifié par simulation) ; P₀ = Ψ ne l'est pas.
    model = engine.engine_model()
    rng = np.random.default_rng(7)
    x0 = np.array([20.0, 8.0])
    errors = []
    for _ in range(4000):
        y0 = model.C @ x0 + scipy.linalg.cholesky(model.R, lower=True) @ rng.standard_normal(2)
        x0_hat, P0 = kc.measurement_initialisation(model, y0)
        errors.append(x0_hat - x0)
    empirical = np.cov(np.array(errors).T)
    np.testing.assert_allclose(empirical, P0, rtol=0.08, atol=0.02 * np.max(P0))
    printed_x0, printed_P0 = kc.errata.printed_initialisation(model, y0)
    np.testing.assert_array_equal(printed_x0, y0)
    np.testing.assert_array_equal(printed_P0, model.R)
    assert np.max(np.abs(printed_P0)) < 1e-3 * np.max(np.abs(P0))  # des mV² au lieu de °C²



def test_measurement_initialisation_errors_in_french():
    model = engine.engine_model()
    one = kc.LinearGaussianModel(model.A, model.C[:1], model.Q, model.R[:1, :1])
    with pytest.raises(kc.KalmanInputError, match="carrée inversible"):
        kc.measurement_initialisation(one, [1.0])
    with pytest.raises(kc.KalmanInputError, match="dim y = dim x"):
        kc.errata.printed_initialisation(one, [1.0])
    singular = kc.LinearGaussianModel(np.eye(2), [[1.0, 1.0], [1.0, 1.0]], np.eye(2), np.eye(2))
    with pytest.raises(kc.KalmanInputError, match="singulière"):
        kc.measurement_initialisation(singular, [1.0, 1.0])
    with pytest.raises(kc.KalmanInputError, match="y0"):
        kc.measurement_initialisation(model, [1.0, 2.0, 3.0])


# --------------------------------------------------------------------------- 001-7, 001-8 : la recette


@pytest.mark.parametrize("n, m, p", [(2, 2, 1), (3, 2, 0), (2, 1, 1)])
def test_001_7_8_corrected_recipe_equals_filterpy(n, m, p):
    rng = np.random.default_rng(10 * n + m + p)
    model = random_model(rng, n, m, p)
    u = None if p == 0 else rng.standard_normal((40, p))
    sim = kc.simulate(model, np.zeros(n), 40, u, rng=rng)
    x0, P0 = rng.standard_normal(n), 2.0 * np.eye(n)
    xs, Ps, _, _ = filterpy_kf(model, sim.y, x0, P0, u)
    x, P = x0, P0
    for k in range(40):
        x, P, _ = kc.recipe_step(model, x, P, sim.y[k], None if u is None else u[k])
        np.testing.assert_allclose(x, xs[k], atol=1e-10, rtol=1e-10)
        np.testing.assert_allclose(P, Ps[k], atol=1e-10, rtol=1e-10)


def test_001_7_printed_gain_differs_from_kalman_gain_in_2x2():
    rng = np.random.default_rng(4)
    model = random_model(rng, 2, 2, 0)
    P = np.array([[1.0, 0.2], [0.2, 0.5]])
    _, _, K_good = kc.recipe_step(model, np.zeros(2), P, np.zeros(2))
    # gain de Kalman écrit ici indépendamment : P⁻Cᵀ(CP⁻Cᵀ + Ψ)⁻¹
    P_pred = model.A @ P @ model.A.T + model.Q
    K_ref = P_pred @ model.C.T @ np.linalg.inv(model.C @ P_pred @ model.C.T + model.R)
    np.testing.assert_allclose(K_good, K_ref, atol=1e-12)
    K_bad = kc.errata.printed_recipe_gain(model, P)
    assert np.max(np.abs(K_bad - K_ref)) > 0.01


def test_001_7_printed_recipe_tends_to_one_half_in_the_scalar_example():
    model, z = _wb()
    bad = kc.errata.printed_recipe_filter(model, z, 0.0, 1.0)
    good = kc.kalman_filter(model, z, 0.0, 1.0)
    assert bad.K[-1, 0, 0] == pytest.approx(0.500, abs=1e-3)
    assert good.K[-1, 0, 0] == pytest.approx(0.0339, abs=5e-5)
    # la recette imprimée, réécrite ici en scalaire : K = (P + Ψ)/(P + 2Ψ), P ← (1 − K)(P + Φ)
    P, x = 1.0, 0.0
    for k in range(50):
        K = (P + WB_PSI) / (P + 2 * WB_PSI)
        x = x + K * (z[k] - x)
        P = (1 - K) * (P + WB_PHI)
        assert bad.K[k, 0, 0] == pytest.approx(K, rel=1e-12)
        assert bad.x[k, 0] == pytest.approx(x, rel=1e-12, abs=1e-15)
        assert bad.P[k, 0, 0] == pytest.approx(P, rel=1e-12)


def test_001_7_printed_gain_is_dimensionally_invalid_when_dim_y_differs():
    model = random_model(np.random.default_rng(1), 3, 2, 0)
    with pytest.raises(kc.KalmanInputError, match="dim y = dim x"):
        kc.errata.printed_recipe_gain(model, np.eye(3))
    with pytest.raises(kc.KalmanInputError, match="dim y = dim x"):
        kc.errata.printed_recipe_filter(model, np.zeros((5, 2)), np.zeros(3), np.eye(3))


# --------------------------------------------------------------------------- 001-9 … 001-13 : gain optimal


def _joseph(P_pred, C, R, K):
    """Forme de Joseph écrite ici, indépendamment du paquet."""
    I_KC = np.eye(P_pred.shape[0]) - K @ C
    return I_KC @ P_pred @ I_KC.T + K @ R @ K.T


@pytest.mark.parametrize("seed", range(3))
def test_001_10_kalman_gain_minimises_trace_and_matches_filterpy(seed):
    rng = np.random.default_rng(100 + seed)
    model = random_model(rng, 3, 2, 0)
    sim = kc.simulate(model, np.zeros(3), 6, rng=rng)
    res = kc.kalman_filter(model, sim.y, np.zeros(3), np.eye(3))
    _, _, _, Pps = filterpy_kf(model, sim.y, np.zeros(3), np.eye(3))
    P_pred, K_star = res.P_pred[-1], res.K[-1]
    np.testing.assert_allclose(P_pred, Pps[-1], atol=1e-10)
    # covariance_for_gain = Joseph écrit à la main, pour des gains quelconques
    for _ in range(5):
        K = rng.standard_normal(K_star.shape)
        np.testing.assert_allclose(kc.covariance_for_gain(model, P_pred, K), _joseph(P_pred, model.C, model.R, K), atol=1e-12)
    best = scipy.optimize.minimize(
        lambda k: np.trace(_joseph(P_pred, model.C, model.R, k.reshape(3, 2))), np.zeros(6),
        method="BFGS", options={"gtol": 1e-12},
    )
    np.testing.assert_allclose(best.x.reshape(3, 2), K_star, atol=1e-6)
    base = np.trace(kc.covariance_for_gain(model, P_pred, K_star))
    for _ in range(20):
        D = rng.standard_normal(K_star.shape)
        assert np.trace(kc.covariance_for_gain(model, P_pred, K_star + 1e-3 * D)) > base


def test_completing_the_square_identity():
    """P(K) = P(K*) + (K − K*) S (K − K*)ᵀ pour tout K (chapitre « Gain optimal »)."""
    rng = np.random.default_rng(5)
    model = random_model(rng, 3, 2, 0)
    L = rng.standard_normal((3, 3))
    P_pred = L @ L.T + 0.1 * np.eye(3)
    S = model.C @ P_pred @ model.C.T + model.R
    K_star = P_pred @ model.C.T @ np.linalg.inv(S)
    for _ in range(10):
        K = rng.standard_normal((3, 2))
        lhs = _joseph(P_pred, model.C, model.R, K) - _joseph(P_pred, model.C, model.R, K_star)
        np.testing.assert_allclose(lhs, (K - K_star) @ S @ (K - K_star).T, atol=1e-10)
        assert np.min(np.linalg.eigvalsh(lhs)) > -1e-10


def test_001_11_innovation_is_the_vector_multiplying_K_pathwise():
    """ν_{n+1} = −CAe_n + Cφ_n + ψ_{n+1} (avec ψ_{n+1}, pas ψ_n), trajectoire par trajectoire."""
    model = engine.engine_model()
    u = engine.engine_commands(30)
    x0 = np.array([1.0, -1.0])
    sim = kc.simulate(model, x0, 30, u, rng=8)
    res = kc.kalman_filter(model, sim.y, engine.ENGINE_X0_HAT, engine.ENGINE_P0, u)
    xs = np.vstack([x0, sim.x])
    x_hat = np.vstack([engine.ENGINE_X0_HAT, res.x])
    phi = xs[1:] - xs[:-1] @ model.A.T - u @ model.B.T
    psi = sim.y - sim.x @ model.C.T
    e = x_hat - xs
    nu = -e[:-1] @ (model.C @ model.A).T + phi @ model.C.T + psi
    np.testing.assert_allclose(res.innovation, nu, atol=1e-9)
    printed = -e[1:-1] @ (model.C @ model.A).T + phi[1:] @ model.C.T + psi[:-1]  # avec ψ_n
    assert np.max(np.abs(printed - res.innovation[1:])) > 1e-3


def test_orthogonality_monte_carlo():
    """E[e_{n+1} ν_{n+1}] = K S − P⁻Cᵀ : nul pour le gain de Kalman, pas pour un gain fixe."""
    model = kc.scenarios.constant_voltage_model()
    n_runs, T = 3000, 20

    def stat(estimator):
        mc = kc.monte_carlo(model, estimator, T, n_runs, x0_mean=0.0, x0_cov=1.0, x0_hat=0.0, rng=21)
        x_prev = np.concatenate([np.zeros((n_runs, 1)), mc.x_hat[:, :-1, 0]], axis=1)
        nu = mc.y[:, :, 0] - x_prev  # A = C = 1 : x̂⁻_{n+1} = x̂_n
        e = mc.x_hat[:, :, 0] - mc.x[:, :, 0]
        prod = e[:, -1] * nu[:, -1]
        return prod.mean(), prod.std(ddof=1) / np.sqrt(n_runs)

    mean, sem = stat(lambda y: kc.kalman_filter(model, y, 0.0, 1.0).x)
    assert abs(mean) < 4 * sem
    K = 0.3
    mean_bad, sem_bad = stat(lambda y: kc.linear_estimator(model, y, [0.0], [[K]]))
    # valeur théorique pour un gain fixe : K S − P⁻, P suivant la forme de Joseph
    P = 1.0
    for _ in range(T):
        P_pred = P + model.Q[0, 0]
        P = (1 - K) ** 2 * P_pred + K**2 * model.R[0, 0]
    expected = K * (P_pred + model.R[0, 0]) - P_pred
    assert abs(mean_bad) > 10 * sem_bad
    assert mean_bad == pytest.approx(expected, abs=4 * sem_bad)


def test_001_12_printed_gain_from_P_is_wrong():
    model, z = _wb()
    good = kc.kalman_filter(model, z, 0.0, 1.0)
    printed = kc.errata.printed_gain_from_P(model, good.P[-1])[0, 0]
    # (P + Ψ)/(P + Φ + Ψ), calculé ici
    P = good.P[-1, 0, 0]
    assert printed == pytest.approx((P + WB_PSI) / (P + WB_PHI + WB_PSI), rel=1e-12)
    assert printed > 0.99 and good.K[-1, 0, 0] < 0.04


# --------------------------------------------------------------------------- 001-14, 001-17 : sans biais à chaque pas


def test_001_14_unbiased_at_every_step_with_exact_prior():
    model = engine.engine_model()
    u = engine.engine_commands(40)
    mean0, cov0 = np.array([3.0, 1.0]), np.diag([4.0, 1.0])
    mc = kc.monte_carlo(
        model, lambda y: kc.kalman_filter(model, y, mean0, cov0, u).x, 40, 800,
        x0_mean=mean0, x0_cov=cov0, x0_hat=mean0, rng=31, u=u,
    )
    z = np.abs(mc.mean_error()[1:]) / mc.mean_error_sem()[1:]
    assert z.max() < 4.5
    # avec une initialisation fausse, le biais est net au début (asymptotiquement nul seulement)
    wrong = kc.monte_carlo(
        model, lambda y: kc.kalman_filter(model, y, mean0 + 10.0, cov0, u).x, 40, 200,
        x0_mean=mean0, x0_cov=cov0, x0_hat=mean0 + 10.0, rng=31, u=u,
    )
    assert np.abs(wrong.mean_error()[1]).max() > 10 * wrong.mean_error_sem()[1].max()


# --------------------------------------------------------------------------- 001-15 : Φ n'est pas la climatologie


def test_001_15_stationary_state_covariance_is_not_phi():
    model = engine.engine_model()
    Sigma = scipy.linalg.solve_discrete_lyapunov(model.A, model.Q)
    sim = kc.simulate(model, np.zeros(2), 200_000, rng=5)
    empirical = np.cov(sim.x[1000:].T)
    np.testing.assert_allclose(empirical, Sigma, rtol=0.1, atol=0.05)
    assert Sigma[0, 0] > 5 * model.Q[0, 0]


# --------------------------------------------------------------------------- 001-16 : p(x_n | y_1..n)


def test_posterior_equals_batch_conditioning():
    """Erratum 001-16. Conditionnement gaussien du vecteur (x_T, y_1 … y_T), construit sans filtre : moyenne x̂_T et
    covariance P_T du filtre de Kalman."""
    model = engine.engine_model()
    T, n, m = 6, 2, 2
    u = engine.engine_commands(T)
    mean0, cov0 = np.array([2.0, 1.0]), np.diag([9.0, 4.0])
    A, B, C, Q, R = model.A, model.B, model.C, model.Q, model.R
    # z = (x0, φ_0 … φ_{T−1}, ψ_1 … ψ_T) ; x_k = M_k z + c_k, y_k = C x_k + ψ_k
    dim = n + T * n + T * m
    cov_z = scipy.linalg.block_diag(cov0, *([Q] * T), *([R] * T))
    mean_z = np.concatenate([mean0, np.zeros(T * n + T * m)])
    M = np.zeros((n, dim))
    M[:, :n] = np.eye(n)
    c = np.zeros(n)
    rows_y, offs_y = [], []
    for k in range(T):
        M = A @ M
        M[:, n + k * n : n + (k + 1) * n] += np.eye(n)
        c = A @ c + B @ u[k]
        Gy = C @ M
        Gy[:, n + T * n + k * m : n + T * n + (k + 1) * m] += np.eye(m)
        rows_y.append(Gy)
        offs_y.append(C @ c)
    Gy, cy = np.vstack(rows_y), np.concatenate(offs_y)
    mu_x, mu_y = M @ mean_z + c, Gy @ mean_z + cy
    S_xx, S_xy, S_yy = M @ cov_z @ M.T, M @ cov_z @ Gy.T, Gy @ cov_z @ Gy.T
    sim = kc.simulate(model, mean0, T, u, rng=9)
    y = sim.y.ravel()
    post_mean = mu_x + S_xy @ np.linalg.solve(S_yy, y - mu_y)
    post_cov = S_xx - S_xy @ np.linalg.solve(S_yy, S_xy.T)
    res = kc.kalman_filter(model, sim.y, mean0, cov0, u)
    np.testing.assert_allclose(res.x[-1], post_mean, atol=1e-8, rtol=1e-8)
    np.testing.assert_allclose(res.P[-1], post_cov, atol=1e-9, rtol=1e-8)



# --------------------------------------------------------------------------- 001-19 … 001-22 : tension constante


def test_001_19_voltage_filter_matrices_are_one_minus_K_and_no_control():
    model, z = _wb()
    res = kc.kalman_filter(model, z, 0.0, 1.0)
    A_f, B_f = kc.filter_matrices(model, res.K[10])
    assert A_f[0, 0] == pytest.approx(1 - res.K[10, 0, 0], rel=1e-14) and B_f is None
    # x̂_{n+1} = (1 − K) x̂_n + K y_{n+1}, écrit ici
    x = 0.0
    for k in range(50):
        x = (1 - res.K[k, 0, 0]) * x + res.K[k, 0, 0] * z[k]
        assert res.x[k, 0] == pytest.approx(x, rel=1e-12, abs=1e-15)


def test_001_22_third_welch_bishop_run_is_psi_1e_minus_4():
    z = kc.scenarios.constant_voltage_measurements(50)
    K50 = {R: kc.kalman_filter(kc.scenarios.constant_voltage_model(R=R), z, 0.0, 1.0).K[-1, 0, 0] for R in (1e-4, 1e-5)}
    assert K50[1e-4] == pytest.approx(0.270, abs=5e-4)  # ALGORITHMS.md §7(e)
    assert abs(K50[1e-5] - 0.270) > 0.2  # la valeur imprimée Ψ = 10⁻⁵ donne une autre figure


# =========================================================================== errata des autres documents
# 000 : tableaux du KF, de l'EKF et de l'EKF itéré ; 002 : notes du SRIF ; 004 : notes SE(3).
# Chaque formule corrigée est vérifiée contre une référence indépendante ; la formule imprimée est
# montrée fausse quand elle a un sens calculable.


def test_000_1_prior_covariance_uses_the_forward_transition_and_the_previous_noise():
    """P(k|k-1) = Φ(k,k-1) P Φᵀ(k,k-1) + G(k-1)Q(k-1)Gᵀ(k-1) : comparée à filterpy (predict) et à la
    covariance empirique de x(k) − Φ(k,k-1)x(k-1) quand Q varie d'un pas à l'autre."""
    from filterpy.kalman import KalmanFilter

    A = np.array([[1.0, 0.5], [0.0, 0.8]])  # Φ(k, k-1), non orthogonale
    P = np.array([[0.3, 0.1], [0.1, 0.2]])
    G = np.array([[0.5], [1.0]])
    Q_prev, Q_now = np.array([[0.04]]), np.array([[0.25]])  # Q(k-1) ≠ Q(k)
    correct = A @ P @ A.T + G @ Q_prev @ G.T
    f = KalmanFilter(dim_x=2, dim_z=1)
    f.F, f.P, f.Q, f.x = A, P.copy(), G @ Q_prev @ G.T, np.zeros((2, 1))
    f.predict()
    np.testing.assert_allclose(correct, f.P, rtol=1e-14, atol=0)
    A_back = np.linalg.inv(A)  # Φ(k-1, k) du tableau : la transition à rebours
    printed = A_back @ P @ A_back.T + G @ Q_now @ G.T
    assert np.abs(printed - correct).max() > 0.1
    # le bruit qui fait passer de k-1 à k est u(k-1), de covariance Q(k-1) : simulation
    rng = np.random.default_rng(0)
    x_prev = rng.multivariate_normal(np.zeros(2), P, size=200_000)
    noise = rng.standard_normal((200_000, 1)) * np.sqrt(Q_prev[0, 0])
    x_now = x_prev @ A.T + noise @ G.T
    empirical = np.cov(x_now.T)
    assert np.abs(empirical - correct).max() < 0.01
    assert np.abs(empirical - (A @ P @ A.T + G @ Q_now @ G.T)).max() > 0.1


def test_000_2_noise_covariance_needs_a_transpose():
    """E[v(k)vᵀ(l)] = R δ_kl (une matrice) ; le produit sans transposée, lu comme vᵀv, ne donne que le
    scalaire tr R."""
    R = np.array([[0.04, 0.015], [0.015, 0.02]])
    model = kc.LinearGaussianModel(A=np.eye(2), C=np.eye(2), Q=1e-4 * np.eye(2), R=R)
    sim = kc.simulate(model, np.zeros(2), 100_000, rng=3)
    v = sim.y - sim.x  # bruits de mesure
    same = v.T @ v / len(v)
    lagged = v[1:].T @ v[:-1] / (len(v) - 1)
    np.testing.assert_allclose(same, R, atol=2e-3)
    assert np.abs(lagged).max() < 2e-3  # δ_kl : rien entre deux instants
    inner = np.mean(np.sum(v * v, axis=1))
    assert inner == pytest.approx(np.trace(R), rel=0.02) and np.ndim(inner) == 0


def test_000_3_posterior_error_is_centred_given_the_measurements():
    """E[x(k-1) − x̂(k-1|k-1) | y(1), …, y(k-1)] = 0 : sur des tirages, l'erreur a posteriori est
    centrée et non corrélée à chacune des mesures passées (projection orthogonale)."""
    model = kc.scenarios.constant_voltage_model(Q=1e-3, R=0.01)
    runs, T = 4000, 8
    rng = np.random.default_rng(7)
    errors, ys = [], []
    for _ in range(runs):
        x0 = rng.normal(0.0, 1.0)
        sim = kc.simulate(model, [x0], T, rng=rng)
        res = kc.kalman_filter(model, sim.y, 0.0, 1.0)
        errors.append(sim.x[-1, 0] - res.x[-1, 0])
        ys.append(sim.y[:, 0])
    e, Y = np.array(errors), np.array(ys)
    P_T = kc.kalman_filter(model, Y[0], 0.0, 1.0).P[-1, 0, 0]
    assert abs(e.mean()) < 4 * np.sqrt(P_T / runs)
    corr = [np.corrcoef(e, Y[:, j])[0, 1] for j in range(T)]
    assert max(abs(c) for c in corr) < 4 / np.sqrt(runs)


def test_000_4_jacobian_of_the_observation_is_a_matrix():
    """∇g joue le rôle de la **matrice** H(k) : pour une mesure à m = 2 composantes, elle est m × n."""
    p = np.array([3.0, 4.0])
    J = kc.numerical_jacobian(kc.scenarios.radar.range_bearing, p)
    assert J.shape == (2, 2)
    np.testing.assert_allclose(J, kc.scenarios.radar.range_bearing_jacobian(p), atol=1e-8)


def test_000_11_ekf_prediction_applies_the_nonlinear_f():
    """La prédiction x̂(k|k-1) de l'EKF est f(x̂(k-1|k-1)) : on applique f elle-même, pas sa jacobienne."""
    model = kc.scenarios.radar.radar_tracking_model()
    x = np.array([40.0, -3.0, -2.0, 1.5])
    P = np.diag([4.0, 4.0, 1.0, 1.0])
    pred = kc.ekf_predict(model, x, P)
    np.testing.assert_allclose(pred.x, model.transition(x), rtol=0, atol=1e-12)


def _controlled_drag_model(dt=0.5, c=0.05):
    """Dynamique non linéaire (traînée) avec une commande d'accélération u (2,)."""
    def f(x, u):
        p, v = x[:2], x[2:]
        return np.concatenate([p + dt * v, v - dt * c * np.linalg.norm(v) * v + dt * u])

    def h(x):
        return np.array([np.hypot(x[0], x[1]), np.arctan2(x[1], x[0])])

    return kc.NonlinearModel(f, h, Q=np.diag([1e-3, 1e-3, 1e-2, 1e-2]), R=np.diag([0.05**2, 0.01**2]),
                             n_control=2, angle_indices=(1,))


def test_002_1_srif_dynamics_takes_the_control_u():
    """x(k+1) = f(k, x(k), u(k), v(k)) : le SRIF étendu propage avec la commande u(k) et redonne l'EKF
    (même commande) ; sans la commande, l'estimation s'écarte."""
    model = _controlled_drag_model()
    rng = np.random.default_rng(4)
    T = 40
    u = 0.5 * np.column_stack([np.sin(0.2 * np.arange(T)), np.cos(0.3 * np.arange(T))])
    x = np.array([-20.0, 5.0, 4.0, 1.0])
    ys = []
    for k in range(T):
        x = model.transition(x, u[k]) + np.sqrt(np.diag(model.Q)) * rng.standard_normal(4)
        ys.append(model.observe(x) + np.sqrt(np.diag(model.R)) * rng.standard_normal(2))
    y = np.array(ys)
    x0, P0 = np.array([-19.0, 4.0, 3.5, 1.2]), np.diag([4.0, 4.0, 1.0, 1.0])
    esr = kc.extended_square_root_information_filter(model, y, x0, P0, u=u)
    ekf = kc.extended_kalman_filter(model, y, x0, P0, u=u)
    np.testing.assert_allclose(esr.x, ekf.x, rtol=1e-9, atol=1e-9)
    without = kc.extended_square_root_information_filter(model, y, x0, P0, u=np.zeros_like(u))
    assert np.abs(without.x - esr.x).max() > 0.1


def test_002_2_linearisation_carries_the_noise_not_the_state():
    """f(x, u) + Γv ≈ f(x̂, u) + F(x − x̂) + Γv, à l'ordre 2 près ; le terme « Γx » des notes laisse une
    erreur d'ordre 1 (elle ne diminue pas avec l'écart x − x̂)."""
    model = _controlled_drag_model()
    Gamma = np.array([[0.0, 0.0], [0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    x_hat, u, v = np.array([3.0, 1.0, 2.0, -1.0]), np.array([0.2, -0.1]), np.array([0.3, -0.2])
    F = kc.numerical_jacobian(lambda x: model.transition(x, u), x_hat)
    direction = np.array([1.0, -0.5, 0.3, 0.2])
    errors_ok, errors_printed = [], []
    for eps in (1e-1, 1e-2, 1e-3):
        x = x_hat + eps * direction
        truth = model.transition(x, u) + Gamma @ v
        corrected = model.transition(x_hat, u) + F @ (x - x_hat) + Gamma @ v
        printed = model.transition(x_hat, u) + F @ (x - x_hat) + Gamma @ x[2:]
        errors_ok.append(np.abs(truth - corrected).max())
        errors_printed.append(np.abs(truth - printed).max())
    assert errors_ok[1] / errors_ok[0] < 0.02 and errors_ok[2] / errors_ok[1] < 0.02  # ordre 2
    assert min(errors_printed) > 0.5


def test_002_6_the_noise_is_rotated_by_the_same_orthogonal_T_a():
    """[w̄_v(k); w̄_x(k+1)] = T_a(k) [w_v(k); w_x(k)] : la QR qui triangularise le pré-tableau, appliquée
    au bruit unitaire, le laisse de covariance I, et son bloc a priori est celui de kc.srif_predict."""
    rng = np.random.default_rng(5)
    n, q = 3, 2
    A = np.eye(n) + 0.2 * rng.standard_normal((n, n))
    Gamma = rng.standard_normal((n, q))
    model = kc.LinearGaussianModel(A, np.eye(n)[:1], Gamma @ Gamma.T, [[0.1]])
    R_xx = np.triu(rng.standard_normal((n, n))) + 3 * np.eye(n)
    z_x = rng.standard_normal(n)
    M = R_xx @ np.linalg.inv(A)
    pre = np.block([[np.eye(q), np.zeros((q, n))], [-M @ Gamma, M]])
    Qm, Rm = scipy.linalg.qr(pre)
    T_a = Qm.T  # T_a · pré-tableau = triangulaire
    np.testing.assert_allclose(T_a @ pre, Rm, atol=1e-12)
    w = rng.standard_normal((q + n, 200_000))
    w_bar = T_a @ w
    np.testing.assert_allclose(np.cov(w_bar), np.eye(q + n), atol=0.02)
    R_bar = kc.srif_predict(model, R_xx, z_x, method="inverse")[0]
    # même information a priori (à des signes de lignes près) : R̄ᵀR̄ identiques
    np.testing.assert_allclose(Rm[q:, q:].T @ Rm[q:, q:], R_bar.T @ R_bar, rtol=1e-10, atol=1e-10)


def test_002_8_whitening_with_the_transposed_factor_is_wrong_unless_inverse():
    """Blanchir par R_a^{-T} donne une covariance I ; par R_a^T, la covariance R_aᵀ R R_a n'est ni I ni,
    en général, R² (elle vaut R² seulement si R est diagonale)."""
    R = np.array([[0.04, 0.012], [0.012, 0.02]])
    Ra = scipy.linalg.cholesky(R, lower=False)  # R = Raᵀ Ra
    white = np.linalg.solve(Ra.T, np.linalg.solve(Ra.T, R).T)  # Ra^{-T} R Ra^{-1}
    np.testing.assert_allclose(white, np.eye(2), atol=1e-12)
    printed = Ra.T @ R @ Ra
    assert np.abs(printed - np.eye(2)).max() > 0.9
    assert np.abs(printed - R @ R).max() > 1e-5
    np.testing.assert_allclose(printed, Ra.T @ Ra.T @ Ra @ Ra, rtol=1e-12)
    D = np.diag([0.04, 0.02])
    Da = scipy.linalg.cholesky(D, lower=False)
    np.testing.assert_allclose(Da.T @ D @ Da, D @ D, rtol=1e-12)


def test_004_5_rotation_derivative_is_a_limit_at_zero():
    """∂(R Exp(θ) p)/∂θ = −R[p]× est la limite du quotient quand θ → 0 ; quand |θ| grandit, le quotient
    ne converge pas (Exp(θ) est périodique : à |θ| = 2π il revient à I)."""
    from kalman_course.geometry.lie import hat3, so3_exp

    R = so3_exp([0.3, -0.4, 0.2])
    p = np.array([0.5, -1.0, 2.0])
    expected = -R @ hat3(p)
    for k in range(3):
        e = np.eye(3)[k]
        for t in (1e-6, 1e-7):
            quotient = (R @ so3_exp(t * e) @ p - R @ p) / t
            np.testing.assert_allclose(quotient, expected[:, k], atol=1e-5)
        full_turn = (R @ so3_exp(2 * np.pi * e) @ p - R @ p) / (2 * np.pi)
        assert np.abs(full_turn).max() < 1e-12  # rien à voir avec −R[p]×
        assert np.abs(expected[:, k]).max() > 0.3


def test_004_6_lie_jacobian_uses_ominus():
    """J = lim (f(X ⊕ τ) ⊖ f(X))/τ : pour la mesure de la caméra (valeurs dans ℝ^2N, ⊖ = −), le quotient
    avec ⊖ redonne camera_measurement_jacobian ; avec ⊕ (= +) il diverge quand τ → 0."""
    p = kc.scenarios.camera_target.camera_target_problem()
    T, pts, cam = p.T_true, p.points, p.camera
    H = kc.camera_measurement_jacobian(T, pts, cam, "right")
    h0 = kc.camera_measurement(T, pts, cam)
    for j in range(6):
        tau = 1e-6
        step = np.zeros(6)
        step[j] = tau
        moved = kc.camera_measurement(kc.oplus(T, step), pts, cam)
        np.testing.assert_allclose((moved - h0) / tau, H[:, j], rtol=1e-4, atol=1e-3)
        assert np.abs((moved + h0) / tau).min() > 1e6  # « ⊕ » : pas de limite
