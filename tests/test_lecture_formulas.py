"""Les formules des chapitres linéaires du livre, vérifiées numériquement contre des calculs
indépendants (filterpy, formes closes écrites ici, scipy, simulation de Monte-Carlo).

Les errata (formules imprimées fausses) sont dans ``test_errata.py`` ; les équivalences générales du
filtre (formes de Joseph, information, recette une ligne) dans ``test_kf.py``.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

import kalman_course as kc
from conftest import filterpy_kf, random_model
from kalman_course.scenarios import engine, stability

# --------------------------------------------------------------------------- chapitre « Contrôle »


def test_engine_model_shapes_units_and_equilibrium():
    model = engine.engine_model()
    assert (model.n_state, model.n_obs, model.n_control) == (2, 2, 1)
    assert abs(np.linalg.det(model.C)) > 0 and not np.allclose(model.C, np.eye(2))
    calm = engine.engine_model(Phi=np.zeros((2, 2)))
    x_star = np.linalg.solve(np.eye(2) - calm.A, calm.B @ [5.0])
    run = kc.simulate(calm, np.zeros(2), 600, np.full((600, 1), 5.0), rng=0)
    np.testing.assert_allclose(run.x[-1], x_star, rtol=1e-4)
    u = engine.engine_commands(120)
    assert u.shape == (120, 1) and u[0, 0] == 0.0 and u[10, 0] == 5.0 and u[70, 0] == 2.0


def test_simulated_noises_follow_the_hypotheses():
    """φ_n = x_{n+1} − A x_n − B u_n et ψ_{n+1} = y_{n+1} − C x_{n+1} : covariances Φ, Ψ, indépendants."""
    model = engine.engine_model()
    T = 40_000
    u = np.full((T, 1), 3.0)
    sim = kc.simulate(model, np.zeros(2), T, u, rng=17)
    phi = sim.x[1:] - sim.x[:-1] @ model.A.T - u[1:] @ model.B.T
    psi = sim.y - sim.x @ model.C.T
    np.testing.assert_allclose(np.cov(phi.T), model.Q, rtol=0.05, atol=0.03 * model.Q.max())
    np.testing.assert_allclose(np.cov(psi.T), model.R, rtol=0.05, atol=0.03 * model.R.max())
    cross = np.corrcoef(phi.T, psi[1:].T)[:2, 2:]
    assert np.max(np.abs(cross)) < 4 / np.sqrt(T)


# --------------------------------------------------------------------------- chapitre « Estimateur »


def _simulate_with_noises(model, x0, T, u, seed):
    sim = kc.simulate(model, x0, T, u, rng=seed)
    xs = np.vstack([x0, sim.x])
    phi = xs[1:] - xs[:-1] @ model.A.T - (0 if u is None else u @ model.B.T)
    psi = sim.y - sim.x @ model.C.T
    return sim, xs, phi, psi


@pytest.mark.parametrize("conditions", [True, False])
def test_error_recursion_pathwise(conditions):
    """e_{n+1} = (I−KC)Ae_n + (A_f+KCA−A)x̂_n + (B_f+KCB−B)u_n + (KC−I)φ_n + Kψ_{n+1}, exactement,
    pour des gains variables et des A_f, B_f quelconques."""
    rng = np.random.default_rng(2)
    model = random_model(rng, 3, 2, 1)
    T = 25
    u = rng.standard_normal((T, 1))
    x0 = rng.standard_normal(3)
    sim, xs, phi, psi = _simulate_with_noises(model, x0, T, u, seed=4)
    Ks = 0.3 * rng.standard_normal((T, 3, 2))
    A_f = None if conditions else rng.standard_normal((3, 3)) * 0.3
    B_f = None if conditions else rng.standard_normal((3, 1))
    x0_hat = rng.standard_normal(3)
    x_hat = np.vstack([x0_hat, kc.linear_estimator(model, sim.y, x0_hat, Ks, u=u, A_f=A_f, B_f=B_f)])
    e = x_hat - xs
    A, B, C, I = model.A, model.B, model.C, np.eye(3)
    for k in range(T):
        K = Ks[k]
        Af = (I - K @ C) @ A if A_f is None else A_f
        Bf = (I - K @ C) @ B if B_f is None else B_f
        rhs = ((I - K @ C) @ A @ e[k] + (Af + K @ C @ A - A) @ x_hat[k] + (Bf + K @ C @ B - B) @ u[k]
               + (K @ C - I) @ phi[k] + K @ psi[k])
        np.testing.assert_allclose(e[k + 1], rhs, atol=1e-10)
        if conditions:  # forme simplifiée du chapitre « Gain optimal »
            np.testing.assert_allclose(e[k + 1], (I - K @ C) @ (A @ e[k] - phi[k]) + K @ psi[k], atol=1e-10)


def test_linear_estimator_runs_is_the_kalman_filter_on_each_run():
    rng = np.random.default_rng(7)
    model = random_model(rng, 3, 2, 1)
    u = rng.standard_normal((25, 1))
    Y = np.stack([kc.simulate(model, np.zeros(3), 25, u, rng=s).y for s in range(4)])
    x0, P0 = np.ones(3), 2.0 * np.eye(3)
    K = kc.kalman_filter(model, Y[0], x0, P0, u).K  # les gains ne dépendent pas des mesures
    est = kc.linear_estimator_runs(model, Y, x0, K, u=u)
    assert est.shape == (4, 25, 3)
    for i in range(4):
        np.testing.assert_allclose(est[i], kc.kalman_filter(model, Y[i], x0, P0, u).x, atol=1e-12)
    with pytest.raises(kc.KalmanInputError, match=r"« Y » doit être de forme \(N, T, 2\)"):
        kc.linear_estimator_runs(model, Y[0], x0, K, u=u)
    with pytest.raises(kc.KalmanInputError, match=r"« Y » contient des mesures manquantes"):
        kc.linear_estimator_runs(model, np.full((2, 25, 2), np.nan), x0, K, u=u)
    with pytest.raises(kc.KalmanInputError, match=r"« estimator » \(batch=True\) doit renvoyer .* \(5, 25, 3\)"):
        kc.monte_carlo(model, lambda Y: Y, 25, 5, x0_mean=x0, x0_cov=P0, x0_hat=x0, rng=1, u=u, batch=True)


@pytest.mark.parametrize("K", [0.4, 0.6])
def test_fixed_gain_experiment_follows_the_closed_form(K):
    """L'expérience de la figure « estimateur-stabilite » et des curseurs : erreur moyenne
    E[e_n] = ((1 − KC)A)ⁿ (forme close, e_0 = 1) ; moyenne de Monte-Carlo à moins de 4 erreurs types."""
    run = stability.fixed_gain_experiment(K)
    factor = (1.0 - K * stability.COUNTER_C) * stability.COUNTER_A
    closed = factor ** np.arange(stability.STABILITY_STEPS + 1)
    np.testing.assert_allclose(run.recursion.e[:, 0], closed, rtol=1e-12)
    assert run.radius == pytest.approx(abs(factor), rel=1e-12)
    assert run.printed_radius == pytest.approx(abs(1.0 - K), rel=1e-12)
    assert run.monte_carlo.n_runs == stability.STABILITY_RUNS
    mean, sem = run.monte_carlo.mean_error()[1:, 0], run.monte_carlo.mean_error_sem()[1:, 0]
    assert np.all(np.abs(mean - closed[1:]) < 4 * sem)


def test_linear_estimator_with_conditions_is_the_kalman_filter_and_filterpy():
    rng = np.random.default_rng(6)
    model = random_model(rng, 3, 2, 1)
    u = rng.standard_normal((30, 1))
    sim = kc.simulate(model, np.zeros(3), 30, u, rng=rng)
    x0, P0 = np.ones(3), 3.0 * np.eye(3)
    res = kc.kalman_filter(model, sim.y, x0, P0, u)
    xs, _, _, _ = filterpy_kf(model, sim.y, x0, P0, u)
    est = kc.linear_estimator(model, sim.y, x0, res.K, u=u)
    np.testing.assert_allclose(est, xs, atol=1e-10)
    np.testing.assert_allclose(est, res.x, atol=1e-12)
    # x̂_{n+1} = A x̂_n + B u_n + K[y − C(A x̂_n + B u_n)] (forme du filtre), écrite ici
    x = x0
    for k in range(30):
        pred = model.A @ x + model.B @ u[k]
        x = pred + res.K[k] @ (sim.y[k] - model.C @ pred)
        np.testing.assert_allclose(est[k], x, atol=1e-10)
    A_f, B_f = kc.filter_matrices(model, res.K[5])
    np.testing.assert_allclose(A_f + res.K[5] @ model.C @ model.A - model.A, 0, atol=1e-12)
    np.testing.assert_allclose(B_f + res.K[5] @ model.C @ model.B - model.B, 0, atol=1e-12)


@pytest.mark.parametrize("forget_command", [False, True])
def test_mean_error_recursion_matches_monte_carlo(forget_command):
    """L'expérience de la figure « estimateur-erreur-moyenne »."""
    from kalman_course.scenarios.engine import mean_error_experiment

    mc, rec = mean_error_experiment(forget_command)
    np.testing.assert_allclose(rec.e, rec.x_hat - rec.x, atol=1e-9)
    z = np.abs(mc.mean_error()[1:] - rec.e[1:]) / mc.mean_error_sem()[1:]
    assert z.max() < 4.5
    if forget_command:
        assert abs(rec.e[-1, 0]) > 2.0
    else:
        assert np.max(np.abs(rec.e[-1])) < 1e-6


def test_estimator_input_errors_in_french():
    model = engine.engine_model()
    y = np.zeros((5, 2))
    with pytest.raises(kc.KalmanInputError, match="« K »"):
        kc.linear_estimator(model, y, np.zeros(2), np.zeros((5, 3, 2)))
    with pytest.raises(kc.KalmanInputError, match="un gain par pas"):
        kc.linear_estimator(model, y, np.zeros(2), np.zeros((4, 2, 2)))
    with pytest.raises(kc.KalmanInputError, match="n_steps"):
        kc.mean_error_recursion(model, np.zeros((2, 2)), x0_mean=np.zeros(2), x0_hat=np.zeros(2))
    with pytest.raises(kc.KalmanInputError, match="manquantes"):
        kc.linear_estimator(model, np.full((5, 2), np.nan), np.zeros(2), np.zeros((2, 2)))
    no_b = kc.LinearGaussianModel(model.A, model.C, model.Q, model.R)
    with pytest.raises(kc.KalmanInputError, match="B_f"):
        kc.linear_estimator(no_b, y, np.zeros(2), np.zeros((2, 2)), B_f=np.zeros((2, 1)))
    with pytest.raises(kc.KalmanInputError, match="model"):
        kc.filter_matrices("moteur", np.zeros((2, 2)))
    with pytest.raises(kc.KalmanInputError, match="« A_f »"):
        kc.linear_estimator(model, y, np.zeros(2), np.zeros((2, 2)), A_f=np.zeros((3, 3)))


def test_monte_carlo_errors_and_reproducibility():
    model = kc.scenarios.constant_voltage_model()

    def est(y):
        return kc.kalman_filter(model, y, 0.0, 1.0).x

    a = kc.monte_carlo(model, est, 10, 5, x0_mean=0.0, x0_cov=1.0, x0_hat=0.0, rng=1)
    b = kc.monte_carlo(model, est, 10, 5, x0_mean=0.0, x0_cov=1.0, x0_hat=0.0, rng=np.random.default_rng(1))
    np.testing.assert_array_equal(a.errors, b.errors)
    assert a.errors.shape == (5, 11, 1)
    with pytest.raises(kc.KalmanInputError, match="rng"):
        kc.monte_carlo(model, est, 10, 5, x0_mean=0.0, x0_cov=1.0, x0_hat=0.0, rng=None)
    with pytest.raises(kc.KalmanInputError, match="n_runs"):
        kc.monte_carlo(model, est, 10, 1, x0_mean=0.0, x0_cov=1.0, x0_hat=0.0, rng=1)
    with pytest.raises(kc.KalmanInputError, match="estimator"):
        kc.monte_carlo(model, "kalman", 10, 5, x0_mean=0.0, x0_cov=1.0, x0_hat=0.0, rng=1)
    with pytest.raises(kc.KalmanInputError, match="x0_cov"):
        kc.monte_carlo(model, est, 10, 5, x0_mean=0.0, x0_cov=-1.0, x0_hat=0.0, rng=1)
    with pytest.raises(kc.KalmanInputError, match="forme"):
        kc.monte_carlo(model, lambda y: np.zeros((3, 1)), 10, 5, x0_mean=0.0, x0_cov=1.0, x0_hat=0.0, rng=1)


# --------------------------------------------------------------------------- chapitre « Gain optimal »


def test_joseph_covariance_monte_carlo():
    """Pour un gain fixe quelconque, Cov(e_n) suit P ← (I−KC)(APAᵀ+Φ)(I−KC)ᵀ + KΨKᵀ."""
    model = engine.engine_model()
    K = np.array([[10.0, 2.0], [-4.0, 15.0]])
    T, R = 15, 4000
    x0_hat, P0 = np.array([1.0, 0.5]), np.diag([4.0, 2.0])
    mc = kc.monte_carlo(model, lambda Y: kc.linear_estimator_runs(model, Y, x0_hat, K), T, R,
                        x0_mean=x0_hat, x0_cov=P0, x0_hat=x0_hat, rng=13, batch=True)
    P = P0
    for _ in range(T):
        P = kc.covariance_for_gain(model, model.A @ P @ model.A.T + model.Q, K)
    empirical = np.cov(mc.errors[:, -1, :].T)
    np.testing.assert_allclose(empirical, P, rtol=0.1, atol=0.05 * np.max(P))
    # et ce n'est pas la covariance du filtre de Kalman (plus petite)
    res = kc.kalman_filter(model, mc.y[0], x0_hat, P0)
    assert np.trace(res.P[-1]) < 0.9 * np.trace(P)


def test_gains_do_not_depend_on_measurements():
    model = engine.engine_model()
    u = engine.engine_commands(30)
    runs = [kc.kalman_filter(model, kc.simulate(model, np.zeros(2), 30, u, rng=s).y, np.ones(2), np.eye(2), u)
            for s in (1, 2)]
    np.testing.assert_array_equal(runs[0].K, runs[1].K)
    np.testing.assert_array_equal(runs[0].P, runs[1].P)


def test_posterior_coverage_experiment():
    """L'expérience de la figure « gain-loi-a-posteriori » : N(x̂_n, P_n) couvre à 95 %."""
    from kalman_course.scenarios.voltage import posterior_experiment

    mc, P = posterior_experiment(n_steps=50, n_runs=2000)
    z = (mc.x[:, :, 0] - mc.x_hat[:, :, 0]) / np.sqrt(P)
    coverage = np.mean(np.abs(z) <= 1.959963984540054)
    assert coverage == pytest.approx(0.95, abs=0.006)  # 100 000 valeurs corrélées : large marge
    assert np.var(z) == pytest.approx(1.0, abs=0.05)


# --------------------------------------------------------------------------- chapitre « Tension constante »


def _scalar_voltage(Q, R, z, P0=1.0):
    """Les formules scalaires du chapitre, écrites ici sans le paquet : renvoie (x, P, K) finals."""
    x, P = 0.0, P0
    for zk in z:
        P_pred = P + Q
        K = P_pred / (P_pred + R)
        x = x + K * (zk - x)
        P = (1 - K) * P_pred
    return x, P, K


def test_voltage_scalar_recursion():
    z = kc.scenarios.constant_voltage_measurements(50)
    x, P, K = _scalar_voltage(1e-5, 0.01, z)
    assert P == pytest.approx(3.392e-4, abs=5e-7) and K == pytest.approx(0.0339, abs=5e-5)  # §7(e)
    res = kc.kalman_filter(kc.scenarios.constant_voltage_model(), z, 0.0, 1.0)
    assert res.x[-1, 0] == pytest.approx(x, rel=1e-12)
    assert res.P[-1, 0, 0] == pytest.approx(P, rel=1e-12)
    assert _scalar_voltage(0.0, 0.01, z)[1] == pytest.approx(2.0e-4, rel=0.01)  # Φ = 0 : « environ 0,0002 »
    assert _scalar_voltage(1e-5, 1.0, z)[2] == pytest.approx(0.0198, abs=5e-5)
    assert _scalar_voltage(1e-5, 1e-4, z)[2] == pytest.approx(0.270, abs=5e-4)


def test_voltage_steady_state_closed_form_and_riccati():
    Phi, Psi = 1e-5, 0.01
    P_pred_inf = 0.5 * (Phi + np.sqrt(Phi**2 + 4 * Phi * Psi))
    one = np.eye(1)
    dare = scipy.linalg.solve_discrete_are(one, one, Phi * one, Psi * one)[0, 0]
    assert dare == pytest.approx(P_pred_inf, rel=1e-10)
    res = kc.kalman_filter(kc.scenarios.constant_voltage_model(), kc.scenarios.constant_voltage_measurements(2000), 0.0, 1.0)
    assert res.P_pred[-1, 0, 0] == pytest.approx(P_pred_inf, rel=1e-6)
    assert res.P[-1, 0, 0] == pytest.approx(P_pred_inf - Phi, rel=1e-6)


# --------------------------------------------------------------------------- chapitre « Pratique »


def test_normalised_innovations_are_standard_normal_only_with_the_right_model():
    model = engine.engine_model()
    u = engine.engine_commands(120)
    no_command = kc.LinearGaussianModel(model.A, model.C, model.Q, model.R)
    good, bad = [], []
    for seed in range(30):
        y = kc.simulate(model, engine.ENGINE_X0_MEAN, 120, u, rng=seed).y
        r = kc.kalman_filter(model, y, engine.ENGINE_X0_MEAN, engine.ENGINE_X0_COV, u)
        good.append(r.innovation / np.sqrt(np.diagonal(r.S, axis1=1, axis2=2)))
        r = kc.kalman_filter(no_command, y, engine.ENGINE_X0_MEAN, engine.ENGINE_X0_COV)
        bad.append(r.innovation / np.sqrt(np.diagonal(r.S, axis1=1, axis2=2)))
    good, bad = np.concatenate(good), np.concatenate(bad)
    assert abs(good.mean()) < 4 / np.sqrt(good.size) and good.var() == pytest.approx(1.0, abs=0.05)
    assert abs(bad[:, 0].mean()) > 2.0
