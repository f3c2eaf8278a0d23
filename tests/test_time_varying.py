"""Modèles variables dans le temps (matrices (T, ·, ·)) : filtre contre la boucle predict()/update() de
filterpy pas à pas, lisseur contre ``KalmanFilter.rts_smoother(Fs, Qs)`` de filterpy, vraisemblance contre
la loi gaussienne de toute la série calculée d'un bloc, lot de tirages, simulation, plusieurs capteurs
(mise à jour séquentielle = mise à jour empilée) et entrées invalides."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
import scipy.stats
from filterpy.kalman import KalmanFilter

import kalman_course as kc

T = 40


def irregular_two_sensor_model(rng, T=T):
    """Cible plane à vitesse presque constante, instants irréguliers ; capteur de position (écart-type
    variable d'un pas à l'autre) et capteur de vitesse, chacun silencieux à certains pas."""
    dts = rng.uniform(0.3, 4.0, T)
    A, Q = kc.constant_velocity(dts, 0.8, dim=2)
    C = np.zeros((T, 4, 4))
    C[:] = np.eye(4)
    C[:, 0, 2] = 0.05 * rng.standard_normal(T)  # un capteur un peu couplé, qui change à chaque pas
    R = np.zeros((T, 4, 4))
    for k in range(T):
        s = rng.uniform(5.0, 40.0)
        R[k] = np.diag([s**2, s**2, 1.5, 1.5])
    model = kc.LinearGaussianModel(A, C, Q, R)
    x0 = np.array([0.0, 0.0, 40.0, -10.0])
    sim = kc.simulate(model, x0, T, rng=rng)
    y = np.array(sim.y)
    y[rng.random(T) < 0.4, 2:] = np.nan   # vitesse absente
    y[rng.random(T) < 0.2, :2] = np.nan   # position absente
    y[[5, 17]] = np.nan                    # aucun capteur
    return model, y, sim, x0


def per_step(a, T):
    """La matrice de chaque pas, (T, …) : une pile telle quelle, une matrice constante répétée."""
    a = np.asarray(a)
    return a if a.ndim == 3 else np.broadcast_to(a, (T, *a.shape))


def filterpy_per_step(model, y, x0, P0):
    """filterpy, pas k : predict(F=A[k], Q=Q[k]) puis update(y[k], R=R[k], H=C[k]) (composantes observées)."""
    n, m = model.n_state, model.n_obs
    A, Q, C, R = (per_step(a, len(y)) for a in (model.A, model.Q, model.C, model.R))
    f = KalmanFilter(dim_x=n, dim_z=m)
    f.x = np.asarray(x0, float).reshape(n, 1)
    f.P = np.asarray(P0, float).copy()
    xs, Ps = [], []
    for k in range(len(y)):
        f.predict(F=A[k], Q=Q[k])
        o = ~np.isnan(y[k])
        if o.any():
            f.update(y[k, o].reshape(-1, 1), R=R[k][np.ix_(o, o)], H=C[k][o])
        xs.append(f.x.ravel().copy())
        Ps.append(f.P.copy())
    return np.array(xs), np.array(Ps)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_time_varying_filter_equals_filterpy_step_by_step(seed):
    rng = np.random.default_rng(seed)
    model, y, _, x0 = irregular_two_sensor_model(rng)
    P0 = np.diag([100.0, 100.0, 25.0, 25.0])
    res = kc.kalman_filter(model, y, x0 + 5.0, P0)
    x_ref, P_ref = filterpy_per_step(model, y, x0 + 5.0, P0)
    assert np.allclose(res.x, x_ref, rtol=1e-9, atol=1e-9)
    assert np.allclose(res.P, P_ref, rtol=1e-9, atol=1e-9)


def test_a_constant_model_written_as_a_stack_is_the_constant_model():
    rng = np.random.default_rng(4)
    A, Q = kc.constant_velocity(1.0, 0.5, dim=1)
    const = kc.LinearGaussianModel(A, [[1.0, 0.0]], Q, [[4.0]])
    stacked = kc.LinearGaussianModel(np.repeat(A[None], 25, axis=0), [[1.0, 0.0]], Q, np.full((25, 1, 1), 4.0))
    assert stacked.time_varying and stacked.n_steps == 25 and not const.time_varying
    y = rng.standard_normal(25).cumsum()
    a = kc.kalman_filter(const, y, [0.0, 0.0], np.eye(2))
    b = kc.kalman_filter(stacked, y, [0.0, 0.0], np.eye(2))
    for field in ("x", "P", "x_pred", "P_pred", "K", "innovation", "S"):
        assert np.allclose(getattr(a, field), getattr(b, field), rtol=1e-12, atol=1e-12), field


def test_time_varying_smoother_equals_filterpy_rts_with_per_step_matrices():
    """filterpy : KalmanFilter.rts_smoother(Xs, Ps, Fs, Qs) relie les lignes k et k+1 par Fs[k+1], Qs[k+1]."""
    rng = np.random.default_rng(5)
    model, y, _, x0 = irregular_two_sensor_model(rng)
    P0 = np.eye(4) * 50.0
    res = kc.kalman_filter(model, y, x0, P0)
    sm = kc.rts_smoother(model, res, x0, P0)
    f = KalmanFilter(dim_x=4, dim_z=4)
    xs, Ps, _, _ = f.rts_smoother(res.x[:, :, None], np.array(res.P), Fs=list(model.A), Qs=list(model.Q))
    assert np.allclose(sm.x, xs[:, :, 0], rtol=1e-9, atol=1e-8)
    assert np.allclose(sm.P, Ps, rtol=1e-9, atol=1e-8)


def test_time_varying_smoother_refuses_a_result_of_another_model():
    rng = np.random.default_rng(6)
    model, y, _, x0 = irregular_two_sensor_model(rng)
    res = kc.kalman_filter(model, y, x0, np.eye(4))
    A2, Q2 = kc.constant_velocity(np.full(T, 1.0), 0.8, dim=2)
    other = kc.LinearGaussianModel(A2, model.C, Q2, model.R)
    with pytest.raises(kc.KalmanInputError, match="ne vient pas|P_pred"):
        kc.rts_smoother(other, res)


def dense_log_likelihood(model, y, x0, P0):
    """log p(y_1..T) de la loi gaussienne jointe des états, calculée d'un bloc (aucune récurrence de
    Kalman) : Cov(x_k, x_j) = A_k Cov(x_{k-1}, x_j), Var(x_k) = A_k Var(x_{k-1}) A_kᵀ + Q_k."""
    n, Tn = model.n_state, len(y)
    mean = np.zeros((Tn, n))
    cov = np.zeros((Tn * n, Tn * n))
    m_prev, V_prev = np.asarray(x0, float), np.asarray(P0, float)
    cross_prev = np.zeros((n, 0))  # Cov(x_{k-1}, x_{0..k-2}) en colonnes
    As, Qs, Cs, Rs_all = (per_step(a, Tn) for a in (model.A, model.Q, model.C, model.R))
    for k in range(Tn):
        A, Q = As[k], Qs[k]
        mean[k] = A @ m_prev
        V = A @ V_prev @ A.T + Q
        cross = np.hstack([A @ cross_prev, A @ V_prev]) if k else np.zeros((n, 0))
        cov[k * n:(k + 1) * n, :k * n] = cross
        cov[:k * n, k * n:(k + 1) * n] = cross.T
        cov[k * n:(k + 1) * n, k * n:(k + 1) * n] = V
        m_prev, V_prev, cross_prev = mean[k], V, cross
    rows, mus, Rs, ys = [], [], [], []
    for k in range(Tn):
        o = ~np.isnan(y[k])
        if not o.any():
            continue
        H = np.zeros((o.sum(), Tn * n))
        H[:, k * n:(k + 1) * n] = Cs[k][o]
        rows.append(H)
        mus.append(Cs[k][o] @ mean[k])
        Rs.append(Rs_all[k][np.ix_(o, o)])
        ys.append(y[k, o])
    H = np.vstack(rows)
    Sigma = H @ cov @ H.T + scipy.linalg.block_diag(*Rs)
    return scipy.stats.multivariate_normal(np.concatenate(mus), Sigma).logpdf(np.concatenate(ys))


def test_time_varying_log_likelihood_equals_the_dense_gaussian():
    rng = np.random.default_rng(7)
    model, y, _, x0 = irregular_two_sensor_model(rng, T=25)
    P0 = np.diag([30.0, 30.0, 4.0, 4.0])
    ours = kc.log_likelihood(model, y, x0, P0)
    assert ours == pytest.approx(dense_log_likelihood(model, y, x0, P0), rel=1e-10)


def test_time_varying_runs_equal_each_run_alone():
    rng = np.random.default_rng(8)
    model, _, _, x0 = irregular_two_sensor_model(rng, T=20)
    Y = np.array([kc.simulate(model, x0, 20, rng=rng).y for _ in range(5)])
    Y[2, 3, 1:3] = np.nan
    for missing in (False, True):
        Yk = Y if missing else np.nan_to_num(Y)
        runs = kc.kalman_filter_runs(model, Yk, x0, np.eye(4) * 9.0)
        for i in range(5):
            one = kc.kalman_filter(model, Yk[i], x0, np.eye(4) * 9.0)
            assert np.allclose(runs.run(i).x, one.x, rtol=1e-10, atol=1e-10)
            assert np.allclose(runs.run(i).P, one.P, rtol=1e-10, atol=1e-10)


def test_simulation_of_a_stacked_constant_model_draws_like_the_constant_model():
    A, Q = kc.constant_velocity(0.5, 2.0, dim=1)
    const = kc.LinearGaussianModel(A, [[1.0, 0.0]], Q, [[0.25]])
    stacked = kc.LinearGaussianModel(np.repeat(A[None], 30, axis=0), [[1.0, 0.0]], np.repeat(Q[None], 30, axis=0),
                                     [[0.25]])
    a = kc.simulate(const, [0.0, 1.0], 30, rng=11)
    b = kc.simulate(stacked, [0.0, 1.0], 30, rng=11)
    assert np.allclose(a.x, b.x, atol=1e-12) and np.allclose(a.y, b.y, atol=1e-12)


def test_sequential_updates_equal_the_stacked_update():
    """Deux capteurs au même instant : corriger avec l'un puis avec l'autre (sans prédiction entre les
    deux) donne exactement la correction avec la mesure empilée (bruits de mesure indépendants)."""
    rng = np.random.default_rng(9)
    n = 4
    A, Q = kc.constant_velocity(1.3, 0.5, dim=2)
    C_pos, C_vel = np.eye(4)[:2], np.eye(4)[2:]
    R_pos, R_vel = np.diag([25.0, 16.0]), np.diag([1.0, 2.0])
    stacked = kc.LinearGaussianModel(A, np.vstack([C_pos, C_vel]), Q, scipy.linalg.block_diag(R_pos, R_vel))
    x, P = rng.standard_normal(n), np.eye(n) * 10.0
    y = rng.standard_normal(4) * 3.0
    pred = kc.predict(stacked, x, P)
    one = kc.update(stacked, pred.x, pred.P, y)
    first = kc.update(kc.LinearGaussianModel(A, C_pos, Q, R_pos), pred.x, pred.P, y[:2])
    second = kc.update(kc.LinearGaussianModel(A, C_vel, Q, R_vel), first.x, first.P, y[2:])
    assert np.allclose(second.x, one.x, rtol=1e-12, atol=1e-12)
    assert np.allclose(second.P, one.P, rtol=1e-12, atol=1e-12)


def test_two_rates_as_partial_rows_equal_filterpy_with_its_own_sensor_at_each_step():
    """Capteur de position à 1 Hz, de vitesse à 1/3 Hz : une seule suite de mesures avec NaN où un
    capteur se tait, filtrée par le modèle empilé ; filterpy corrige avec le seul capteur présent."""
    rng = np.random.default_rng(10)
    A, Q = kc.constant_velocity(1.0, 0.3, dim=2)
    C = np.eye(4)
    R = np.diag([9.0, 9.0, 0.5, 0.5])
    model = kc.LinearGaussianModel(A, C, Q, R)
    sim = kc.simulate(model, [0.0, 0.0, 10.0, 5.0], 30, rng=rng)
    y = np.array(sim.y)
    y[np.arange(30) % 3 != 0, 2:] = np.nan
    res = kc.kalman_filter(model, y, [0.0, 0.0, 10.0, 5.0], np.eye(4))
    stacked = kc.LinearGaussianModel(np.repeat(A[None], 30, 0), C, np.repeat(Q[None], 30, 0), R)
    x_ref, P_ref = filterpy_per_step(stacked, y, [0.0, 0.0, 10.0, 5.0], np.eye(4))
    assert np.allclose(res.x, x_ref, rtol=1e-10, atol=1e-10) and np.allclose(res.P, P_ref, rtol=1e-10, atol=1e-10)


# --------------------------------------------------------------------------- entrées invalides


def test_time_varying_model_refuses_a_series_of_another_length():
    A, Q = kc.constant_velocity(np.ones(10), 1.0, dim=1)
    model = kc.LinearGaussianModel(A, [[1.0, 0.0]], Q, [[1.0]])
    with pytest.raises(kc.KalmanInputError, match="10 pas.*reçu 12 mesures"):
        kc.kalman_filter(model, np.zeros(12), [0.0, 0.0], np.eye(2))


def test_time_varying_matrices_must_share_their_length():
    A, Q = kc.constant_velocity(np.ones(10), 1.0, dim=1)
    with pytest.raises(kc.KalmanInputError, match="même nombre de pas"):
        kc.LinearGaussianModel(A, [[1.0, 0.0]], Q[:8], [[1.0]])


def test_a_bad_step_is_named():
    A, Q = kc.constant_velocity(np.ones(6), 1.0, dim=1)
    R = np.ones((6, 1, 1))
    R[3] = -1.0
    with pytest.raises(kc.KalmanInputError, match=r"R\[3\]"):
        kc.LinearGaussianModel(A, [[1.0, 0.0]], Q, R)


def test_em_refuses_a_time_varying_noise_covariance():
    """EM estime une Q et une R constantes (A, B, C peuvent varier : tests/test_family.py) ; une Q variable
    (pas irréguliers) est refusée en français."""
    A, Q = kc.constant_velocity(np.ones(6), 1.0, dim=1)
    model = kc.LinearGaussianModel(A, [[1.0, 0.0]], Q, [[1.0]])
    with pytest.raises(kc.KalmanInputError, match="covariance « Q » variable dans le temps : EM estime une seule"):
        kc.expectation_maximization(model, np.zeros(6), [0.0, 0.0], np.eye(2))


def test_at_gives_the_constant_model_of_a_step():
    A, Q = kc.constant_velocity(np.array([1.0, 2.0, 3.0]), 1.0, dim=1)
    model = kc.LinearGaussianModel(A, [[1.0, 0.0]], Q, [[1.0]])
    step = model.at(2)
    assert not step.time_varying and np.array_equal(step.A, A[2]) and np.array_equal(step.Q, Q[2])
    with pytest.raises(kc.KalmanInputError, match="indice de pas"):
        model.at(3)


def test_diffuse_likelihood_of_a_stacked_constant_model_is_the_constant_one():
    """Départ diffus exact (sans a priori) : un modèle constant écrit en pile (T, ·, ·) donne la même
    vraisemblance que le modèle constant ; un vrai modèle variable est accepté aussi."""
    rng = np.random.default_rng(12)
    A, Q = kc.constant_velocity(1.0, 0.4, dim=1)
    const = kc.LinearGaussianModel(A, [[1.0, 0.0]], Q, [[2.0]])
    y = np.array(kc.simulate(const, [0.0, 1.0], 30, rng=rng).y)
    y[5] = np.nan
    stacked = kc.LinearGaussianModel(np.repeat(A[None], 30, 0), [[1.0, 0.0]], np.repeat(Q[None], 30, 0), [[2.0]])
    assert kc.log_likelihood(stacked, y) == pytest.approx(kc.log_likelihood(const, y), rel=1e-11)
    A2, Q2 = kc.constant_velocity(rng.uniform(0.5, 2.0, 30), 0.4, dim=1)
    varying = kc.LinearGaussianModel(A2, [[1.0, 0.0]], Q2, [[2.0]])
    assert np.isfinite(kc.log_likelihood(varying, y))
