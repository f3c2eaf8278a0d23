"""Filtre IMM : contre ``IMMEstimator`` de filterpy (predict() puis update(z) à chaque pas), un régime =
filtre de Kalman, mesures manquantes, régimes variables dans le temps, et entrées invalides."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from filterpy.kalman import IMMEstimator, KalmanFilter

import kalman_course as kc


def two_modes(dt=1.0, q_quiet=0.05, q_manoeuvre=20.0, sigma=5.0):
    C = np.eye(4)[:2]
    R = sigma**2 * np.eye(2)
    models = []
    for q in (q_quiet, q_manoeuvre):
        A, Q = kc.constant_velocity(dt, q, dim=2)
        models.append(kc.LinearGaussianModel(A, C, Q, R))
    return models


TRANSITION = np.array([[0.97, 0.03], [0.10, 0.90]])


def turning_track(T=120, seed=0, sigma=5.0):
    x = np.array([0.0, 0.0, 60.0, 0.0, 0.0])
    truth = np.zeros((T, 5))
    for k in range(T):
        x[4] = 0.1 if 40 <= k < 70 else 0.0
        x = kc.core.motion.turn_transition(x, 1.0)
        truth[k] = x
    y = truth[:, :2] + np.random.default_rng(seed).standard_normal((T, 2)) * sigma
    return truth, y


def _no_information(imm, m):
    for f in imm.filters:
        f.R_saved = f.R
        f.R = 1e20 * np.eye(m)
    imm.update(np.zeros((m, 1)))
    for f in imm.filters:
        f.R = f.R_saved


def filterpy_imm(models, y, x0, P0, transition, mu0):
    filters = []
    for model in models:
        f = KalmanFilter(dim_x=model.n_state, dim_z=model.n_obs)
        f.F, f.H, f.Q, f.R = (np.array(a) for a in (model.A, model.C, model.Q, model.R))
        f.x = np.asarray(x0, float).reshape(-1, 1).copy()
        f.P = np.asarray(P0, float).copy()
        filters.append(f)
    imm = IMMEstimator(filters, np.array(mu0, float), np.array(transition, float))
    xs, Ps, mus, modes = [], [], [], []
    for z in y:
        imm.predict()
        if np.isnan(z).all():
            # mesure absente : une mesure sans information (R = 10²⁰ I), seule façon de faire passer les
            # probabilités des régimes par la chaîne de Markov dans filterpy (qui, sans update(), garde μ)
            _no_information(imm, len(z))
        else:
            imm.update(z.reshape(-1, 1))
        xs.append(imm.x.ravel().copy())
        Ps.append(imm.P.copy())
        mus.append(np.array(imm.mu).copy())
        modes.append([f.x.ravel().copy() for f in imm.filters])
    return np.array(xs), np.array(Ps), np.array(mus), np.array(modes)


@pytest.mark.parametrize("seed", [0, 1])
def test_imm_equals_filterpy_immestimator(seed):
    models = two_modes()
    _, y = turning_track(seed=seed)
    x0, P0 = np.array([0.0, 0.0, 60.0, 0.0]), np.diag([25.0, 25.0, 10.0, 10.0])
    res = kc.imm_filter(models, y, x0, P0, transition=TRANSITION, mu0=[0.9, 0.1])
    x, P, mu, modes = filterpy_imm(models, y, x0, P0, TRANSITION, [0.9, 0.1])
    assert np.allclose(res.x, x, rtol=1e-9, atol=1e-9)
    assert np.allclose(res.P, P, rtol=1e-9, atol=1e-9)
    assert np.allclose(res.mu, mu, rtol=1e-9, atol=1e-12)
    assert np.allclose(res.x_modes, modes, rtol=1e-9, atol=1e-9)


def test_imm_with_missing_measurements_equals_filterpy():
    """Sans mesure, l'IMM du paquet ne fait que la prédiction et rend les probabilités prédites
    c̄ = μ Π. filterpy, si l'on saute update(), garderait μ et ses poids de mélange d'avant
    (la chaîne de Markov ne tourne pas) : on lui donne une mesure sans information (R = 10²⁰ I), qui ne
    change ni les estimations ni les probabilités au-delà des arrondis."""
    models = two_modes()
    _, y = turning_track(T=60, seed=3)
    y[[10, 11, 30]] = np.nan
    x0, P0 = np.array([0.0, 0.0, 60.0, 0.0]), np.eye(4) * 25.0
    res = kc.imm_filter(models, y, x0, P0, transition=TRANSITION, mu0=[0.5, 0.5])
    x, P, mu, modes = filterpy_imm(models, y, x0, P0, TRANSITION, [0.5, 0.5])
    assert np.allclose(res.x_modes, modes, rtol=1e-9, atol=1e-9)
    assert np.allclose(res.x, x, rtol=1e-9, atol=1e-9)
    assert np.allclose(res.P, P, rtol=1e-9, atol=1e-9)
    assert np.allclose(res.mu, mu, rtol=1e-9, atol=1e-12)
    assert np.allclose(res.mu[10], res.mu_pred[10]) and np.allclose(res.mu_pred[10], mu[9] @ TRANSITION)


def test_one_mode_is_the_kalman_filter():
    model = two_modes()[0]
    _, y = turning_track(T=50, seed=4)
    y[7] = np.nan
    y[12, 1] = np.nan
    x0, P0 = np.array([0.0, 0.0, 60.0, 0.0]), np.eye(4) * 25.0
    res = kc.imm_filter([model], y, x0, P0, transition=[[1.0]])
    kf = kc.kalman_filter(model, y, x0, P0)
    for field in ("x", "P", "x_pred", "P_pred", "K", "innovation", "S"):
        a, b = getattr(res, field), getattr(kf, field)
        assert np.allclose(a, b, rtol=1e-12, atol=1e-12, equal_nan=True), field
    assert np.all(res.mu == 1.0)


def test_two_identical_modes_are_the_kalman_filter_whatever_the_switching():
    model = two_modes()[0]
    _, y = turning_track(T=40, seed=5)
    x0, P0 = np.array([0.0, 0.0, 60.0, 0.0]), np.eye(4) * 25.0
    res = kc.imm_filter([model, model], y, x0, P0, transition=[[0.6, 0.4], [0.3, 0.7]], mu0=[0.2, 0.8])
    kf = kc.kalman_filter(model, y, x0, P0)
    assert np.allclose(res.x, kf.x, rtol=1e-10, atol=1e-10) and np.allclose(res.P, kf.P, rtol=1e-10, atol=1e-10)
    # vraisemblances égales : les probabilités ne font que suivre la chaîne de Markov, μ_k = μ₀ Πᵏ⁺¹
    Pi = np.array([[0.6, 0.4], [0.3, 0.7]])
    chain = np.array([[0.2, 0.8] @ np.linalg.matrix_power(Pi, k + 1) for k in range(40)])
    assert np.allclose(res.mu, chain, rtol=1e-12, atol=1e-14)


def test_the_manoeuvring_mode_wins_during_the_turn():
    models = two_modes()
    truth, y = turning_track(T=120, seed=6)
    res = kc.imm_filter(models, y, [0.0, 0.0, 60.0, 0.0], np.eye(4) * 25.0, transition=TRANSITION, mu0=[0.9, 0.1])
    assert res.mu[45:70, 1].mean() > 0.8     # pendant le virage
    assert res.mu[90:, 0].mean() > 0.8       # en ligne droite
    err = lambda r: np.sqrt(np.mean(np.sum((r.x[40:80, :2] - truth[40:80, :2]) ** 2, axis=1)))
    quiet = kc.kalman_filter(models[0], y, [0.0, 0.0, 60.0, 0.0], np.eye(4) * 25.0)
    assert err(res) < 0.5 * err(quiet)


def test_time_varying_modes_equal_filterpy_with_per_step_matrices():
    """Instants irréguliers : chaque régime est un modèle variable dans le temps ; filterpy reçoit les
    matrices du pas avant chaque predict()."""
    rng = np.random.default_rng(7)
    T = 50
    dts = rng.uniform(0.4, 6.0, T)
    C, R = np.eye(4)[:2], 16.0 * np.eye(2)
    models = []
    for q in (0.02, 8.0):
        A, Q = kc.constant_velocity(dts, q, dim=2)
        models.append(kc.LinearGaussianModel(A, C, Q, R))
    y = np.cumsum(rng.standard_normal((T, 2)) * 30.0, axis=0)
    x0, P0 = np.zeros(4), np.diag([100.0, 100.0, 400.0, 400.0])
    res = kc.imm_filter(models, y, x0, P0, transition=TRANSITION)
    filters = []
    for model in models:
        f = KalmanFilter(dim_x=4, dim_z=2)
        f.H, f.R = C.copy(), R.copy()
        f.x, f.P = x0.reshape(4, 1).copy(), P0.copy()
        filters.append(f)
    imm = IMMEstimator(filters, np.array([0.5, 0.5]), TRANSITION.copy())
    for k in range(T):
        for f, model in zip(imm.filters, models):
            f.F, f.Q = model.A[k], model.Q[k]
        imm.predict()
        imm.update(y[k].reshape(2, 1))
        assert np.allclose(res.x[k], imm.x.ravel(), rtol=1e-9, atol=1e-9)
        assert np.allclose(res.mu[k], imm.mu, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("kwargs, message", [
    (dict(transition=[[0.9, 0.2], [0.1, 0.9]]), "ligne 0 doit valoir 1"),
    (dict(transition=[[1.1, -0.1], [0.1, 0.9]]), "probabilités"),
    (dict(transition=np.eye(3)), r"\(2, 2\)"),
    (dict(transition=np.eye(2), mu0=[0.5, 0.6]), "somme doit valoir 1"),
    (dict(transition=np.eye(2), mu0=[1.0]), r"forme \(2,\)"),
])
def test_bad_imm_input_is_refused_in_french(kwargs, message):
    models = two_modes()
    with pytest.raises(kc.KalmanInputError, match=message):
        kc.imm_filter(models, np.zeros((3, 2)), np.zeros(4), np.eye(4), **kwargs)


def test_modes_of_different_dimensions_are_refused():
    a = two_modes()[0]
    b = kc.LinearGaussianModel(np.eye(2), np.eye(2), np.eye(2), np.eye(2))
    with pytest.raises(kc.KalmanInputError, match="partagent"):
        kc.imm_filter([a, b], np.zeros((3, 2)), np.zeros(4), np.eye(4), transition=np.eye(2))
    with pytest.raises(kc.KalmanInputError, match="liste"):
        kc.imm_filter(a, np.zeros((3, 2)), np.zeros(4), np.eye(4), transition=np.eye(1))


def test_imm_result_is_immutable_and_shaped():
    models = two_modes()
    _, y = turning_track(T=10)
    res = kc.imm_filter(models, y, np.zeros(4), np.eye(4) * 100.0, transition=TRANSITION)
    assert res.mu.shape == (10, 2) and res.x_modes.shape == (10, 2, 4) and res.P_modes.shape == (10, 2, 4, 4)
    assert res.mode.shape == (10,)
    with pytest.raises(ValueError):
        res.mu[0, 0] = 0.3
    copy.deepcopy(res)
