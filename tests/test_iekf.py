"""EKF itéré (Gauss–Newton) : une itération = EKF, point fixe = MAP indépendant (scipy least_squares),
cas affine, variantes fausses des notes, nombres de référence d'ALGORITHMS.md §7(b)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.optimize
from conftest import random_model

import kalman_course as kc
from kalman_course.lecture.errata_iekf import (
    measurement_only_iterates,
    no_correction_iterates,
    table_literal_iterates,
)
from kalman_course.scenarios import radar, tag


def independent_map(h, y, x_pred, P_pred, R, angle=None):
    """MAP par least_squares sur les résidus blanchis (jacobienne par différences finies de scipy)."""
    LP = np.linalg.cholesky(P_pred)
    LR = np.linalg.cholesky(R)

    def res(x):
        r = y - h(x)
        if angle is not None:
            r[angle] = np.arctan2(np.sin(r[angle]), np.cos(r[angle]))
        return np.concatenate([np.linalg.solve(LP, x - x_pred), np.linalg.solve(LR, r)])

    sol = scipy.optimize.least_squares(res, x_pred, xtol=1e-15, ftol=1e-15, gtol=1e-15)
    return sol.x, 0.5 * float(sol.fun @ sol.fun)


# --------------------------------------------------------------------------- une itération = EKF


def test_one_iteration_is_the_ekf_exactly():
    data = tag.tag_data()
    model = tag.tag_model()
    ekf = kc.extended_kalman_filter(model, data.y, data.x0, data.P0)
    it1 = kc.iterated_extended_kalman_filter(model, data.y, data.x0, data.P0, max_iter=1)
    np.testing.assert_array_equal(it1.x, ekf.x)
    np.testing.assert_array_equal(it1.P, ekf.P)
    np.testing.assert_array_equal(it1.n_iter, 1)

    p = radar.radar_update_problem()
    a = kc.ekf_update(p.model, p.x_pred, p.P_pred, p.y)
    b = kc.iekf_update(p.model, p.x_pred, p.P_pred, p.y, max_iter=1)
    np.testing.assert_array_equal(a.x, b.x)
    np.testing.assert_array_equal(a.P, b.P)
    np.testing.assert_array_equal(a.innovation, b.innovation)
    assert b.n_iter == 1 and not b.converged


# --------------------------------------------------------------------------- radar précis (§7 b)


def test_radar_single_update_reaches_the_independent_map():
    p = radar.radar_update_problem()
    out = kc.iekf_update(p.model, p.x_pred, p.P_pred, p.y)
    x_map, J_map = independent_map(radar.range_bearing, p.y, p.x_pred, p.P_pred, p.model.R, angle=1)
    assert out.converged
    np.testing.assert_allclose(out.x, x_map, rtol=0, atol=1e-6)
    J = kc.map_cost(p.model, out.x, p.x_pred, p.P_pred, p.y)
    assert J == pytest.approx(J_map, rel=1e-9)
    # gradient du coût nul au point fixe : (P⁻)⁻¹(x − x⁻) = Hᵀ R⁻¹ (y − h(x))
    H = radar.range_bearing_jacobian(out.x)
    r = p.model.residual(p.y, radar.range_bearing(out.x))
    grad = np.linalg.solve(p.P_pred, out.x - p.x_pred) - H.T @ np.linalg.solve(p.model.R, r)
    assert np.linalg.norm(grad) < 1e-8 * np.linalg.norm(H.T @ np.linalg.solve(p.model.R, r)) + 1e-8
    # covariance a posteriori : (I − K H) P⁻ au point de convergence
    K = p.P_pred @ H.T @ np.linalg.inv(H @ p.P_pred @ H.T + p.model.R)
    np.testing.assert_allclose(out.P, (np.eye(2) - K @ H) @ p.P_pred, rtol=0, atol=1e-10)


def test_radar_reference_numbers():
    """Nombres mesurés par une implémentation indépendante (ALGORITHMS.md §7 b)."""
    it = radar.radar_iterations()
    assert it.cost_of(it.ekf) == pytest.approx(88.10, abs=0.01)
    assert it.cost[-1] == pytest.approx(0.6401, abs=1e-4)
    assert it.map_cost == pytest.approx(0.6401, abs=1e-4)
    assert it.error_of(it.ekf) == pytest.approx(0.741, abs=1e-3)
    assert it.error[-1] == pytest.approx(0.219, abs=1e-3)
    np.testing.assert_allclose(it.distance_to_map[1:4], [0.70, 2.3e-2, 3.3e-5], rtol=0.05)
    assert 5 <= it.n_iter <= 8
    # le tableau des notes (seul le gain relinéarisé) converge 0,61 m à côté du MAP
    assert np.linalg.norm(it.table_literal[-1] - it.table_literal[-2]) < 1e-8
    assert np.linalg.norm(it.table_literal[-1] - it.map) == pytest.approx(0.608, abs=2e-3)
    # innovation à l'itéré sans terme de linéarisation : diverge
    assert np.linalg.norm(it.no_correction[-1] - it.map) > 100.0


def test_measurement_only_loop_forgets_the_prior():
    p = radar.radar_update_problem()
    its = measurement_only_iterates(p.model, p.x_pred, p.P_pred, p.y)
    np.testing.assert_allclose(radar.range_bearing(its[-1]), p.y, rtol=0, atol=1e-12)
    x_map, _ = independent_map(radar.range_bearing, p.y, p.x_pred, p.P_pred, p.model.R, angle=1)
    assert np.linalg.norm(its[-1] - x_map) > 1e-3


def test_cost_decreases_along_gauss_newton_here():
    it = radar.radar_iterations()
    assert np.all(np.diff(it.cost) <= 1e-12)
    assert it.cost[1] > 100 * it.cost[-1]


# --------------------------------------------------------------------------- cas affine


def test_affine_measurement_first_iterate_is_kf_and_second_equals_first():
    rng = np.random.default_rng(2)
    lin = random_model(rng, n=3, m=2, p=0)
    model = kc.NonlinearModel.from_linear(lin)
    x_pred, P_pred, y = rng.normal(size=3), np.eye(3) * 2.0, rng.normal(size=2)
    kf = kc.update(lin, x_pred, P_pred, y)
    out = kc.iekf_update(model, x_pred, P_pred, y)
    np.testing.assert_allclose(out.iterates[1], kf.x, rtol=0, atol=1e-12)
    np.testing.assert_allclose(out.iterates[2], out.iterates[1], rtol=0, atol=1e-12)
    assert out.n_iter == 2 and out.converged
    np.testing.assert_allclose(out.P, kf.P, rtol=0, atol=1e-12)


# --------------------------------------------------------------------------- suivi : MAP à chaque pas


def test_tracking_iekf_equals_per_step_map():
    x_true, y, x0, P0 = radar.radar_tracking_data()
    model = radar.radar_tracking_model()
    res = kc.iterated_extended_kalman_filter(model, y, x0, P0)
    assert res.n_iter.min() >= 2 and res.n_iter.max() < 20
    for k in range(0, len(y), 7):
        h = radar.range_bearing
        x_map, J_map = independent_map(h, y[k], res.x_pred[k], res.P_pred[k], model.R, angle=1)
        np.testing.assert_allclose(res.x[k], x_map, rtol=0, atol=1e-6)
        J = kc.map_cost(model, res.x[k], res.x_pred[k], res.P_pred[k], y[k])
        assert J == pytest.approx(J_map, rel=1e-9, abs=1e-12)


def test_iterate_count_is_reported_and_bounded():
    x_true, y, x0, P0 = radar.radar_tracking_data()
    res = kc.iterated_extended_kalman_filter(radar.radar_tracking_model(), y, x0, P0, max_iter=3)
    assert res.n_iter.dtype.kind == "i" and res.n_iter.max() == 3


# --------------------------------------------------------------------------- entrées invalides


@pytest.mark.parametrize("max_iter", [0, -1, 2.5, True])
def test_error_max_iter(max_iter):
    p = radar.radar_update_problem()
    with pytest.raises(kc.KalmanInputError, match=r"« max_iter » doit être un entier ≥ 1"):
        kc.iekf_update(p.model, p.x_pred, p.P_pred, p.y, max_iter=max_iter)


@pytest.mark.parametrize("tol", [-1.0, float("nan"), "petit"])
def test_error_tol(tol):
    p = radar.radar_update_problem()
    with pytest.raises(kc.KalmanInputError, match=r"« tol » doit être un réel ≥ 0"):
        kc.iekf_update(p.model, p.x_pred, p.P_pred, p.y, tol=tol)


def test_error_map_cost_needs_positive_definite_prior():
    p = radar.radar_update_problem()
    with pytest.raises(kc.KalmanInputError, match=r"« P_pred » doit être définie positive"):
        kc.map_cost(p.model, p.x_pred, p.x_pred, np.diag([1.0, 0.0]), p.y)


def test_errata_functions_reject_bad_model():
    with pytest.raises(kc.KalmanInputError, match=r"« model » doit être un NonlinearModel"):
        table_literal_iterates(None, [0.0], [[1.0]], [0.0])
    p = radar.radar_update_problem()
    assert no_correction_iterates(p.model, p.x_pred, p.P_pred, p.y, max_iter=3).shape == (4, 2)


# --------------------------------------------------------------------------- innovation et S cohérents


def test_stored_innovation_and_S_come_from_the_last_linearisation():
    """ν et S rangés par la correction itérée sont ceux de la dernière linéarisation (au point x^(N−1)),
    recalculés ici à la main : la NIS νᵀS⁻¹ν est celle du filtre linéarisé en ce point, et x^(N) = x⁻ + Kν."""
    p = radar.radar_update_problem()
    out = kc.iekf_update(p.model, p.x_pred, p.P_pred, p.y)
    x_last = out.iterates[-2]
    H = radar.range_bearing_jacobian(x_last)
    R = np.array(p.model.R)
    r = p.y - radar.range_bearing(x_last)
    r[1] = np.arctan2(np.sin(r[1]), np.cos(r[1]))
    nu = r - H @ (p.x_pred - x_last)
    S = H @ p.P_pred @ H.T + R
    K = np.linalg.solve(S, H @ p.P_pred).T
    np.testing.assert_allclose(out.innovation, nu, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(out.S, S, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(out.K, K, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(out.x, p.x_pred + K @ nu, rtol=1e-12, atol=1e-12)
    # sur une poursuite : chaque pas vérifie x = x⁻ + Kν, et la NIS se calcule sur le résultat
    x_true, y, x0, P0 = radar.radar_tracking_data()
    res = kc.iterated_extended_kalman_filter(radar.radar_tracking_model(), y, x0, P0)
    np.testing.assert_allclose(res.x, res.x_pred + np.einsum("kij,kj->ki", res.K, res.innovation), atol=1e-9)
    nis = kc.nis(res)
    assert np.isfinite(nis).all() and 1.0 < nis.mean() < 3.0  # χ²₂ : moyenne 2


def test_map_costs_on_a_grid_equal_the_cost_point_by_point():
    """Le lot (courbes de niveau de la figure) contre la formule point par point, et contre le calcul
    direct ½dᵀP⁻¹d + ½rᵀR⁻¹r par inverses explicites (angles ramenés dans (−π, π])."""
    p = radar.radar_update_problem()
    xs, ys, J = radar.radar_cost_grid(p, n=7)
    Pi, Ri = np.linalg.inv(p.P_pred), np.linalg.inv(p.model.R)
    for i in (0, 3, 6):
        for j in (0, 2, 6):
            x = np.array([xs[j], ys[i]])
            assert J[i, j] == pytest.approx(kc.map_cost(p.model, x, p.x_pred, p.P_pred, p.y), rel=1e-12)
            r = p.y - np.array([np.hypot(*x), np.arctan2(x[1], x[0])])
            r[1] = (r[1] + np.pi) % (2 * np.pi) - np.pi
            d = x - p.x_pred
            assert J[i, j] == pytest.approx(0.5 * d @ Pi @ d + 0.5 * r @ Ri @ r, rel=1e-9)


def test_error_map_costs_needs_points_in_rows():
    p = radar.radar_update_problem()
    with pytest.raises(kc.KalmanInputError, match="« X »"):
        kc.filters.iterated.map_costs(p.model, [1.0, 2.0], p.x_pred, p.P_pred, p.y)
