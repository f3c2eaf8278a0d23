"""Lisseurs RTS : contre pykalman, filterpy, statsmodels (départ diffus) et la loi a posteriori calculée d'un bloc."""

from __future__ import annotations

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter
from pykalman import KalmanFilter as PyKalmanFilter

import kalman_course as kc
from conftest import random_model
from kalman_course.core.results import FilterRuns
from dense_oracle import batch_posterior

TOL = dict(rtol=1e-9, atol=1e-9)


def _data(seed, n, m, p, T=60, missing_rows=(4, 5, 20), partial=()):
    rng = np.random.default_rng(seed)
    model = random_model(rng, n, m, p)
    u = rng.standard_normal((T, p)) if p else None
    sim = kc.simulate(model, rng.standard_normal(n), T, u=u, rng=rng)
    y = np.array(sim.y)
    y[[k for k in missing_rows if k < T]] = np.nan
    for k, j in partial:
        y[k, j] = np.nan
    x0 = rng.standard_normal(n)
    P0 = 2.0 * np.eye(n)
    return model, y, u, x0, P0, sim


def _pykalman(model, y, u, x0, P0):
    """pykalman : son état 0 est celui de la mesure y[0] ; on lui donne la prédiction A x0 + B u0,
    A P0 Aᵀ + Q ; la commande des pas suivants est son ``transition_offsets`` (ligne t-1 pour l'état t)."""
    A, C, Q, R, B = (np.array(model.A), np.array(model.C), np.array(model.Q), np.array(model.R), model.B)
    mean0 = A @ x0 + (0.0 if B is None else np.asarray(B) @ u[0])
    offsets = np.zeros((len(y) - 1, model.n_state)) if B is None else u[1:] @ np.asarray(B).T
    pk = PyKalmanFilter(transition_matrices=A, observation_matrices=C, transition_covariance=Q,
                        observation_covariance=R, transition_offsets=offsets, initial_state_mean=mean0,
                        initial_state_covariance=A @ P0 @ A.T + Q)
    return pk.smooth(np.ma.masked_invalid(y))


# --------------------------------------------------------------------------- références


@pytest.mark.parametrize("n,m,p", [(1, 1, 0), (2, 1, 1), (3, 2, 1), (4, 2, 2), (5, 3, 0)])
def test_rts_equals_pykalman_with_control_and_missing_data(n, m, p):
    model, y, u, x0, P0, _ = _data(10 * n + m + p, n, m, p)
    ours = kc.rts_smoother(model, kc.kalman_filter(model, y, x0, P0, u))
    x_ref, P_ref = _pykalman(model, y, u, x0, P0)
    np.testing.assert_allclose(ours.x, x_ref, **TOL)
    np.testing.assert_allclose(ours.P, P_ref, **TOL)


@pytest.mark.parametrize("n,m", [(1, 1), (2, 1), (3, 2), (4, 3)])
def test_rts_equals_filterpy_without_control(n, m):
    model, y, _, x0, P0, _ = _data(7 * n + m, n, m, 0)
    result = kc.kalman_filter(model, y, x0, P0)
    ours = kc.rts_smoother(model, result)
    kf = KalmanFilter(dim_x=n, dim_z=m)
    kf.F, kf.H, kf.Q, kf.R = (np.array(model.A), np.array(model.C), np.array(model.Q), np.array(model.R))
    xs, Ps, Ks, _ = kf.rts_smoother(result.x[:, :, None], np.array(result.P))
    np.testing.assert_allclose(ours.x, xs[:, :, 0], **TOL)
    np.testing.assert_allclose(ours.P, Ps, **TOL)
    np.testing.assert_allclose(ours.G[:-1], Ks[:-1], **TOL)  # mêmes gains (filterpy : K[k] relie k à k+1)
    np.testing.assert_array_equal(ours.G[-1], 0.0)


@pytest.mark.parametrize("n,m,p", [(2, 1, 1), (3, 2, 1), (3, 3, 0)])
def test_rts_equals_the_batch_posterior_with_partial_rows(n, m, p):
    partial = [(8, 0), (9, m - 1)] if m > 1 else []
    model, y, u, x0, P0, _ = _data(31 * n + m, n, m, p, T=18, missing_rows=(3, 11), partial=partial)
    ours = kc.rts_smoother(model, kc.kalman_filter(model, y, x0, P0, u), x0, P0)
    ref = batch_posterior(model, y, u, x0, P0)
    np.testing.assert_allclose(ours.x, ref["x"], **TOL)
    np.testing.assert_allclose(ours.P, ref["P"], **TOL)
    np.testing.assert_allclose(ours.P_lag[1:], ref["P_lag"][1:], **TOL)  # Cov(x_k, x_{k-1} | y)
    np.testing.assert_allclose(ours.x_initial, ref["x_initial"], **TOL)
    np.testing.assert_allclose(ours.P_initial, ref["P_initial"], **TOL)
    np.testing.assert_allclose(ours.P_lag[0], ref["lag0"], **TOL)


def test_without_prior_the_initial_state_is_not_smoothed():
    model, y, u, x0, P0, _ = _data(3, 2, 1, 1, T=10)
    sm = kc.rts_smoother(model, kc.kalman_filter(model, y, x0, P0, u))
    assert sm.x_initial is None and sm.P_initial is None and np.isnan(sm.P_lag[0]).all()


def test_smoother_formulas_step_by_step():
    """Les formules du chapitre, recalculées pas à pas sur le résultat du filtre (lignes 0 et T−2)."""
    model, y, u, x0, P0, _ = _data(5, 3, 2, 1, T=12)
    res = kc.kalman_filter(model, y, x0, P0, u)
    sm = kc.rts_smoother(model, res)
    A = np.array(model.A)
    for k in (0, 5, res.n_steps - 2):
        G = res.P[k] @ A.T @ np.linalg.inv(res.P_pred[k + 1])
        np.testing.assert_allclose(sm.G[k], G, **TOL)
        np.testing.assert_allclose(sm.x[k], res.x[k] + G @ (sm.x[k + 1] - res.x_pred[k + 1]), **TOL)
        np.testing.assert_allclose(sm.P[k], res.P[k] + G @ (sm.P[k + 1] - res.P_pred[k + 1]) @ G.T, **TOL)
        np.testing.assert_allclose(sm.P_lag[k + 1], sm.P[k + 1] @ G.T, **TOL)
    np.testing.assert_array_equal(sm.x[-1], res.x[-1])


def test_smoothed_variance_never_exceeds_filtered_variance():
    model, y, u, x0, P0, _ = _data(9, 3, 2, 1, T=80, missing_rows=range(30, 45))
    res = kc.kalman_filter(model, y, x0, P0, u)
    sm = kc.rts_smoother(model, res)
    for k in range(res.n_steps):  # P_filtre − P_lissé semi-définie positive
        assert np.linalg.eigvalsh(res.P[k] - sm.P[k]).min() > -1e-10


def test_results_are_immutable():
    model, y, u, x0, P0, _ = _data(2, 2, 1, 0, T=5)
    sm = kc.rts_smoother(model, kc.kalman_filter(model, y, x0, P0, u))
    with pytest.raises(ValueError):
        sm.x[0, 0] = 1.0
    with pytest.raises(AttributeError):
        sm.x = None


# --------------------------------------------------------------------------- départ diffus


def _statsmodels_uc(y, trend, params):
    import statsmodels.api as sm

    mod = sm.tsa.UnobservedComponents(y, trend, use_exact_diffuse=True)
    return mod.smooth(params)


def _nile_model(trend, params):
    if trend == "llevel":
        return kc.LinearGaussianModel(1.0, 1.0, params[1], params[0])
    A = np.array([[1.0, 1.0], [0.0, 1.0]])
    return kc.LinearGaussianModel(A, [[1.0, 0.0]], np.diag(params[1:]), params[0])


@pytest.mark.parametrize("trend,params", [("llevel", [15099.0, 1469.1]), ("lltrend", [15000.0, 1300.0, 5.0])])
@pytest.mark.parametrize("missing", [False, True])
def test_diffuse_smoother_equals_statsmodels_on_the_nile(trend, params, missing):
    y = kc.datasets.nile(missing=missing).flow
    model = _nile_model(trend, params)
    res = kc.diffuse_kalman_filter(model, y)
    sm = kc.rts_smoother(model, res)
    ref = _statsmodels_uc(y, trend, params)
    d = res.n_diffuse
    assert d == (1 if trend == "llevel" else 2)
    scale = np.max(np.abs(y[~np.isnan(y)]))
    np.testing.assert_allclose(sm.x, ref.smoothed_state.T, rtol=1e-9, atol=1e-9 * scale)
    np.testing.assert_allclose(sm.P, np.moveaxis(ref.smoothed_state_cov, -1, 0), rtol=1e-9, atol=1e-9 * scale**2)
    # statsmodels : smoothed_state_autocov[..., t] = Cov(x_{t+1}, x_t), calculée après la période diffuse
    acov = np.moveaxis(ref.smoother_results.smoothed_state_autocov, -1, 0)
    np.testing.assert_allclose(sm.P_lag[d + 1:], acov[d:-1], rtol=1e-8, atol=1e-9 * scale**2)
    # filtre : estimations déterminées à partir de la ligne d − 1, NaN avant
    np.testing.assert_allclose(res.x[d - 1:], ref.filtered_state.T[d - 1:], rtol=1e-9, atol=1e-9 * scale)
    np.testing.assert_allclose(res.P[d - 1:], np.moveaxis(ref.filtered_state_cov, -1, 0)[d - 1:], rtol=1e-9,
                               atol=1e-9 * scale**2)
    np.testing.assert_allclose(res.x_pred[d:], ref.predicted_state.T[d:-1], rtol=1e-9, atol=1e-9 * scale)
    assert np.isnan(res.x_pred[:d]).all() and np.isnan(res.x[: d - 1]).all()


@pytest.mark.parametrize("n,m,p", [(2, 1, 1), (3, 2, 0), (2, 2, 1)])
def test_diffuse_smoother_equals_the_batch_posterior_without_prior(n, m, p):
    partial = [(6, 0)] if m > 1 else []
    model, y, u, _, _, _ = _data(41 * n + m, n, m, p, T=16, missing_rows=(2, 9), partial=partial)
    res = kc.diffuse_kalman_filter(model, y, u)
    sm = kc.rts_smoother(model, res)
    ref = batch_posterior(model, y, u)
    np.testing.assert_allclose(sm.x, ref["x"], rtol=1e-8, atol=1e-8)
    np.testing.assert_allclose(sm.P, ref["P"], rtol=1e-8, atol=1e-8)
    np.testing.assert_allclose(sm.P_lag[1:], ref["P_lag"][1:], rtol=1e-8, atol=1e-8)
    # le filtre exact, une fois l'état déterminé, est le filtre de Kalman parti de son estimation
    d = res.n_diffuse
    rest = kc.kalman_filter(model, y[d:], res.x[d - 1], res.P[d - 1], None if u is None else u[d:])
    np.testing.assert_allclose(res.x[d:], rest.x, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(res.P[d:], rest.P, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(res.innovation[d:], rest.innovation, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(np.nan_to_num(res.S[d:]), np.nan_to_num(rest.S), rtol=1e-9, atol=1e-9)


def test_diffuse_filter_equals_srif_started_without_information():
    y = kc.datasets.nile(missing=True).flow
    model = _nile_model("lltrend", [15000.0, 1300.0, 5.0])
    res = kc.diffuse_kalman_filter(model, y)
    srif = kc.square_root_information_filter(model, y)
    np.testing.assert_array_equal(np.isnan(res.x), np.isnan(srif.x))
    np.testing.assert_allclose(res.x, srif.x, rtol=1e-9, equal_nan=True)
    np.testing.assert_allclose(res.P, srif.P, rtol=1e-7, equal_nan=True)


# --------------------------------------------------------------------------- lisseur étendu


def test_extended_rts_equals_rts_on_a_linear_model():
    model, y, u, x0, P0, _ = _data(17, 3, 2, 1, partial=[(30, 1)])
    lin = kc.rts_smoother(model, kc.kalman_filter(model, y, x0, P0, u), x0, P0)
    nonlinear = kc.NonlinearModel.from_linear(model)
    ext = kc.extended_rts_smoother(nonlinear, kc.extended_kalman_filter(nonlinear, y, x0, P0, u), x0, P0, u=u)
    for name in ("x", "P", "G", "x_initial", "P_initial"):
        np.testing.assert_allclose(getattr(ext, name), getattr(lin, name), **TOL)
    np.testing.assert_allclose(ext.P_lag, lin.P_lag, **TOL)


DT, GRAVITY = 0.05, 9.81


def _pendulum():
    def f(x, u):
        return np.array([x[0] + DT * x[1], x[1] - DT * GRAVITY * np.sin(x[0])])

    def F(x, u):
        return np.array([[1.0, DT], [-DT * GRAVITY * np.cos(x[0]), 1.0]])

    return kc.NonlinearModel(f, lambda x: np.array([np.sin(x[0])]), np.diag([1e-5, 4e-4]), [[0.04]],
                             f_jacobian=F, h_jacobian=lambda x: np.array([[np.cos(x[0]), 0.0]])), F


def test_extended_rts_on_a_pendulum_follows_the_formulas_and_beats_the_filter():
    model, F = _pendulum()
    rng = np.random.default_rng(4)
    T = 200
    x = np.empty((T, 2))
    state = np.array([1.0, 0.0])
    for k in range(T):
        state = model.f(state, None) + rng.multivariate_normal(np.zeros(2), model.Q)
        x[k] = state
    y = np.sin(x[:, :1]) + 0.2 * rng.standard_normal((T, 1))
    y[80:100] = np.nan
    res = kc.extended_kalman_filter(model, y, [0.8, 0.0], np.diag([0.1, 0.1]))
    sm = kc.extended_rts_smoother(model, res)
    # boucle indépendante, jacobienne analytique (ALGORITHMS § 11.4 : A → F_k)
    xs, Ps = res.x[-1].copy(), res.P[-1].copy()
    for k in range(T - 2, -1, -1):
        G = res.P[k] @ F(res.x[k], None).T @ np.linalg.inv(res.P_pred[k + 1])
        xs = res.x[k] + G @ (xs - res.x_pred[k + 1])
        Ps = res.P[k] + G @ (Ps - res.P_pred[k + 1]) @ G.T
        np.testing.assert_allclose(sm.x[k], xs, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(sm.P[k], Ps, rtol=1e-9, atol=1e-12)
    err_f = np.sqrt(np.mean((res.x[:, 0] - x[:, 0]) ** 2))
    err_s = np.sqrt(np.mean((sm.x[:, 0] - x[:, 0]) ** 2))
    assert err_s < 0.8 * err_f


def test_extended_rts_accepts_the_iterated_ekf():
    """L'EKF itéré prédit comme l'EKF : son résultat se lisse avec les mêmes formules (F_k en x̂_{k|k})."""
    model, F = _pendulum()
    rng = np.random.default_rng(8)
    y = np.sin(1.0 + 0.1 * rng.standard_normal((60, 1))) + 0.2 * rng.standard_normal((60, 1))
    res = kc.iterated_extended_kalman_filter(model, y, [0.8, 0.0], np.diag([0.5, 0.5]))
    assert (res.n_iter > 1).any()
    sm = kc.extended_rts_smoother(model, res)
    k = 30
    G = res.P[k] @ F(res.x[k], None).T @ np.linalg.inv(res.P_pred[k + 1])
    np.testing.assert_allclose(sm.x[k], res.x[k] + G @ (sm.x[k + 1] - res.x_pred[k + 1]), rtol=1e-9, atol=1e-12)


# --------------------------------------------------------------------------- entrées invalides


def test_result_of_another_model_is_refused():
    model, y, u, x0, P0, _ = _data(8, 2, 1, 0)
    res = kc.kalman_filter(model, y, x0, P0)
    other_Q = kc.LinearGaussianModel(model.A, model.C, 1.01 * np.asarray(model.Q), model.R)
    with pytest.raises(kc.KalmanInputError, match="« result » ne vient pas du filtre de Kalman"):
        kc.rts_smoother(other_Q, res)
    other_R = kc.LinearGaussianModel(model.A, model.C, model.Q, 2.0 * np.asarray(model.R))
    with pytest.raises(kc.KalmanInputError, match="covariance d'innovation"):
        kc.rts_smoother(other_R, res)
    bigger = random_model(np.random.default_rng(0), 3, 1, 0)
    with pytest.raises(kc.KalmanInputError, match="n = 3"):
        kc.rts_smoother(bigger, res)


def test_result_of_another_filter_is_refused():
    """Le résultat de l'UKF n'est pas celui de l'EKF : prédictions différentes."""
    data = kc.scenarios.tag_data(n_steps=40)
    model = kc.scenarios.tag_model()
    ukf = kc.unscented_kalman_filter(kc.scenarios.tag_model(), data.y, data.x0, data.P0, alpha=0.1, kappa=-1.0)
    ekf = kc.extended_kalman_filter(model, data.y, data.x0, data.P0)
    kc.extended_rts_smoother(model, ekf)  # accepté
    with pytest.raises(kc.KalmanInputError, match="ne vient pas du filtre de Kalman étendu"):
        kc.extended_rts_smoother(model, ukf)


def test_wrong_controls_for_the_extended_smoother_are_refused():
    model, y, u, x0, P0, _ = _data(12, 2, 1, 1)
    nonlinear = kc.NonlinearModel.from_linear(model)
    res = kc.extended_kalman_filter(nonlinear, y, x0, P0, u)
    with pytest.raises(kc.KalmanInputError, match="x_pred"):
        kc.extended_rts_smoother(nonlinear, res, u=2.0 * u)


def test_models_of_the_wrong_kind_are_refused():
    model, y, u, x0, P0, _ = _data(13, 2, 1, 0)
    res = kc.kalman_filter(model, y, x0, P0)
    with pytest.raises(kc.KalmanInputError, match="extended_rts_smoother"):
        kc.rts_smoother(kc.NonlinearModel.from_linear(model), res)
    with pytest.raises(kc.KalmanInputError, match="« model » doit être un NonlinearModel"):
        kc.extended_rts_smoother(model, res)
    with pytest.raises(kc.KalmanInputError, match="« result » doit être un FilterResult"):
        kc.rts_smoother(model, {"x": res.x})


def test_batches_undetermined_results_and_diffuse_results_are_routed():
    model, y, u, x0, P0, _ = _data(14, 2, 1, 0)
    res = kc.kalman_filter(model, y, x0, P0)
    runs = FilterRuns(**{name: np.stack([getattr(res, name)] * 2) for name in
                         ("x", "P", "x_pred", "P_pred", "K", "innovation", "S", "observed", "n_iter")})
    with pytest.raises(kc.KalmanInputError, match=r"runs\.run\(0\)"):
        kc.rts_smoother(model, runs)
    srif = kc.square_root_information_filter(model, y)  # sans a priori : premières lignes NaN
    with pytest.raises(kc.KalmanInputError, match="diffuse_kalman_filter"):
        kc.rts_smoother(model, srif)
    diffuse = kc.diffuse_kalman_filter(model, y)
    with pytest.raises(kc.KalmanInputError, match="rts_smoother"):
        kc.extended_rts_smoother(kc.NonlinearModel.from_linear(model), diffuse)
    with pytest.raises(kc.KalmanInputError, match="n'a pas d'a priori"):
        kc.rts_smoother(model, diffuse, x0, P0)


def test_prior_must_be_the_filters_prior():
    model, y, u, x0, P0, _ = _data(15, 2, 1, 0)
    res = kc.kalman_filter(model, y, x0, P0)
    with pytest.raises(kc.KalmanInputError, match="vont ensemble"):
        kc.rts_smoother(model, res, x0=x0)
    with pytest.raises(kc.KalmanInputError, match="« P0 » n'est pas l'a priori du filtre"):
        kc.rts_smoother(model, res, x0, 3.0 * P0)
    with pytest.raises(kc.KalmanInputError, match="« x0 » n'est pas l'a priori du filtre"):
        kc.rts_smoother(model, res, x0 + 1.0, P0)


def test_unobservable_model_cannot_be_smoothed_without_prior():
    model = kc.LinearGaussianModel(np.eye(2), [[1.0, 0.0]], 0.1 * np.eye(2), [[1.0]])
    res = kc.diffuse_kalman_filter(model, np.arange(10.0))
    assert np.isnan(res.x).all()  # la seconde composante n'est jamais observée
    with pytest.raises(kc.KalmanInputError, match="ne déterminent pas l'état"):
        kc.rts_smoother(model, res)


# --------------------------------------------------------------------------- curseurs du Nil (chapitre « Lissage »)


@pytest.fixture(scope="module")
def nile_grid():
    import kalman_course.interactive as ki

    return ki.nile_grid()


def test_nile_slider_grid_equals_statsmodels_smoother(nile_grid):
    import statsmodels.api as sm

    y = kc.datasets.nile(missing=True).flow
    R_axis, Q_axis = nile_grid.axes
    assert (R_axis.default_value, Q_axis.default_value) == kc.scenarios.nile.NILE_DK_VARIANCES
    for i, j in [nile_grid.default_index, (0, 0), (6, 10), (1, 7)]:
        R, Q = R_axis.values[i], Q_axis.values[j]
        ref = sm.tsa.UnobservedComponents(y, "llevel", use_exact_diffuse=True).smooth([R, Q])
        run = nile_grid.run(i, j)
        np.testing.assert_allclose(run["xs"], ref.smoothed_state[0], rtol=1e-9)
        np.testing.assert_allclose(run["ss"] ** 2, ref.smoothed_state_cov[0, 0], rtol=1e-8)
        np.testing.assert_allclose(run["xf"], ref.filtered_state[0], rtol=1e-9)


def test_nile_slider_prose_claims(nile_grid):
    """Les affirmations de l'encadré « À observer » du chapitre « Lissage »."""
    y = kc.datasets.nile(missing=True).flow
    seen = ~np.isnan(y)
    i0, j0 = nile_grid.default_index
    # Q au minimum : niveau lissé presque plat, proche de la moyenne des mesures
    flat = nile_grid.run(i0, 0)
    assert np.ptp(flat["xs"]) < 0.1 * np.nanstd(y)
    assert abs(flat["xs"].mean() - np.nanmean(y)) < 0.01 * np.nanmean(y)
    # Q au maximum : le niveau filtré suit les mesures
    wild = nile_grid.run(i0, nile_grid.shape[1] - 1)
    assert np.max(np.abs(wild["xf"][seen] - y[seen])) < 0.15 * np.max(np.abs(flat["xf"][seen] - y[seen]))
    # années retirées : niveau filtré figé, écart-type croissant ; écart-type lissé en lentille
    base = nile_grid.run(i0, j0)
    gap = slice(20, 40)
    assert np.ptp(base["xf"][gap]) == 0.0 and (np.diff(base["sf"][gap]) > 0).all()
    k_max = 20 + int(np.argmax(base["ss"][gap]))
    assert 27 <= k_max <= 32
    # un cran de chaque curseur : mêmes niveaux, écarts-types × 10^(1/4)
    a, b = nile_grid.run(2, 5), nile_grid.run(3, 6)
    np.testing.assert_allclose(b["xs"], a["xs"], rtol=1e-10)
    np.testing.assert_allclose(b["ss"] / a["ss"], 10 ** 0.25, rtol=1e-10)


def test_target_scenario_claims():
    """Les affirmations du chapitre « Lissage » sur la cible : le lisseur bat le filtre, surtout dans le trou."""
    run = kc.scenarios.smoothing.target_run()
    assert run.rmse_smoother < 0.7 * run.rmse_filter
    assert run.rmse_smoother_gap < 0.7 * run.rmse_filter_gap
    g0, g1 = run.gap
    sd_f, sd_s = run.filtered.std()[:, 0], run.smoothed.std()[:, 0]
    assert (np.diff(sd_f[g0:g1]) > 0).all()  # le filtre ne fait que perdre confiance dans le trou
    k = g0 + int(np.argmax(sd_s[g0:g1]))
    assert g0 + 5 <= k <= g1 - 5  # lentille : maximum loin des bords
    assert sd_s[-1] == sd_f[-1]


# --------------------------------------------------------------------------- lisseur RTS unscented


@pytest.mark.parametrize("alpha, beta, kappa", [(0.1, 2.0, -1.0), (1.0, 2.0, 0.0), (0.5, 0.0, 3.0)])
def test_unscented_smoother_equals_filterpy_rts_smoother(alpha, beta, kappa):
    """Tag UWB : le lisseur unscented du paquet contre ``UnscentedKalmanFilter.rts_smoother`` de filterpy,
    appliqué aux mêmes estimations filtrées."""
    from filterpy.kalman import MerweScaledSigmaPoints, UnscentedKalmanFilter

    data = kc.scenarios.tag_data(n_steps=120)
    model = kc.scenarios.tag_model()
    res = kc.unscented_kalman_filter(model, data.y, data.x0, data.P0, alpha=alpha, beta=beta, kappa=kappa)
    ours = kc.unscented_rts_smoother(model, res, alpha=alpha, beta=beta, kappa=kappa)
    points = MerweScaledSigmaPoints(4, alpha=alpha, beta=beta, kappa=kappa)
    ukf = UnscentedKalmanFilter(dim_x=4, dim_z=4, dt=1.0, hx=lambda x: model.observe(np.asarray(x)),
                                fx=lambda x, dt: model.transition(np.asarray(x), None), points=points)
    ukf.Q = np.array(model.Q)
    xs, Ps, Ks = ukf.rts_smoother(np.array(res.x), np.array(res.P))
    np.testing.assert_allclose(ours.x, xs, rtol=0, atol=1e-9)
    np.testing.assert_allclose(ours.P, Ps, rtol=0, atol=1e-9)
    np.testing.assert_allclose(ours.G[:-1], Ks[:-1], rtol=0, atol=1e-9)
    # le lissage sert : erreur de position plus petite que celle du filtre
    err_f = np.linalg.norm(res.x[20:, :2] - data.x_true[20:, :2], axis=1).mean()
    err_s = np.linalg.norm(ours.x[20:, :2] - data.x_true[20:, :2], axis=1).mean()
    assert err_s < 0.8 * err_f


def test_unscented_smoother_on_a_linear_model_is_the_rts_smoother():
    model, y, u, x0, P0, _ = _data(31, 3, 2, 0)
    lin = kc.unscented_kalman_filter(kc.NonlinearModel.from_linear(model), y, x0, P0, alpha=1.0, beta=2.0, kappa=0.0)
    ours = kc.unscented_rts_smoother(kc.NonlinearModel.from_linear(model), lin, alpha=1.0, beta=2.0, kappa=0.0)
    ref = kc.rts_smoother(model, kc.kalman_filter(model, y, x0, P0))
    np.testing.assert_allclose(ours.x, ref.x, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(ours.P, ref.P, rtol=1e-9, atol=1e-9)


def test_unscented_smoother_refuses_other_parameters_or_filters():
    """Pendule (dynamique non linéaire) : une prédiction faite avec d'autres paramètres ou par l'EKF se voit."""
    data = kc.scenarios.pendulum.pendulum_data(n_steps=200)
    model = kc.scenarios.pendulum.pendulum_model()
    res = kc.unscented_kalman_filter(model, data.y, data.x0, data.P0, alpha=0.5, kappa=0.0)
    kc.unscented_rts_smoother(model, res, alpha=0.5, kappa=0.0)  # accepté
    with pytest.raises(kc.KalmanInputError, match="ne vient pas du filtre de Kalman unscented"):
        kc.unscented_rts_smoother(model, res, alpha=0.1, kappa=-1.0)
    ekf = kc.extended_kalman_filter(model, data.y, data.x0, data.P0)
    with pytest.raises(kc.KalmanInputError, match="ne vient pas du filtre de Kalman unscented"):
        kc.unscented_rts_smoother(model, ekf, alpha=0.5, kappa=0.0)


# --------------------------------------------------------------------------- a priori vague


@pytest.mark.parametrize("exponent", [10, 12, 14])
def test_vague_prior_smoother_reaches_the_exact_diffuse_smoother(exponent):
    """Lisseur de RTS en racine carrée : parti d'un filtre à a priori vague (P₀ = 10ᵏ I), il retrouve le lissage
    diffus exact (vérifié contre statsmodels ci-dessus) à toutes les lignes, la première comprise (son
    P_{0|T} exige la différence de deux nombres de l'ordre de P₀ sous la forme usuelle), de même que les
    covariances de décalage un (EM)."""
    model, y = kc.scenarios.diffuse.diffuse_model(), kc.scenarios.diffuse.diffuse_data()[1]
    exact = kc.rts_smoother(model, kc.diffuse_kalman_filter(model, y))
    sm = kc.rts_smoother(model, kc.kalman_filter(model, y, np.zeros(4), 10.0**exponent * np.eye(4)))
    np.testing.assert_allclose(sm.x, exact.x, rtol=0, atol=1e-9)
    scale = np.abs(exact.P).max()
    np.testing.assert_allclose(sm.P, exact.P, rtol=0, atol=1e-6 * scale)
    np.testing.assert_allclose(sm.P_lag[1:], exact.P_lag[1:], rtol=0, atol=1e-6 * scale)
    # la forme usuelle (gains par résolution, P_{k|T} = P_k + G(P_{k+1|T} − P⁻_{k+1})Gᵀ) perd P_{0|T}
    from kalman_course.filters.smoothers import rts_pass, smoother_gains

    res = kc.kalman_filter(model, y, np.zeros(4), 10.0**exponent * np.eye(4))
    G = np.zeros_like(res.P)
    G[:-1] = smoother_gains(res.P[:-1], res.P_pred[1:], model.A)
    _, Ps, _ = rts_pass(res.x, res.P, res.x_pred, res.P_pred, G)
    assert np.abs(Ps[0] - exact.P[0]).max() > 1e-3 * np.abs(exact.P[0]).max()


@pytest.mark.parametrize("exponent, rtol", [(12, 1e-5), (14, 1e-4)])
def test_vague_prior_initial_state_is_smoothed_to_the_batch_posterior(exponent, rtol):
    """L'état initial lissé (instant 0) sous un a priori vague : le postérieur exact en bloc (dense_oracle,
    indépendant des filtres) avec le même a priori. Mesuré : écart relatif 8 × 10⁻⁷ (10¹²) et 3 × 10⁻⁵ (10¹⁴),
    limité par la covariance filtrée P[0] rangée dans le résultat ; la forme usuelle
    P₀ + G₀(P_{1|T} − P⁻₁)G₀ᵀ s'écarte de 1,3 × 10⁻⁴ et 8 × 10⁻³."""
    rng = np.random.default_rng(5)
    A = np.array([[0.9, 0.2, 0.0], [0.0, 0.8, 0.3], [0.1, 0.0, 0.7]])
    model = kc.LinearGaussianModel(A, rng.standard_normal((2, 3)), 0.1 * np.eye(3), np.diag([0.5, 0.2]))
    y = kc.simulate(model, np.ones(3), 12, rng=4).y
    P0 = 10.0**exponent * np.eye(3)
    sm = kc.rts_smoother(model, kc.kalman_filter(model, y, np.zeros(3), P0), np.zeros(3), P0)
    ref = batch_posterior(model, y, x0=np.zeros(3), P0=P0)
    scale = np.abs(ref["P_initial"]).max()
    np.testing.assert_allclose(sm.x_initial, ref["x_initial"], rtol=0, atol=rtol * np.abs(ref["x_initial"]).max())
    np.testing.assert_allclose(sm.P_initial, ref["P_initial"], rtol=0, atol=rtol * scale)
    np.testing.assert_allclose(sm.P_lag[0], ref["lag0"], rtol=0, atol=rtol * scale)
