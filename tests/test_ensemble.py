"""EnKF stochastique : convergence vers le filtre de Kalman en 1/√N sur un modèle linéaire gaussien, rôle
des observations perturbées (une analyse contre la forme close), reproductibilité, mesures manquantes,
modèle non linéaire, entrées invalides."""

from __future__ import annotations

import numpy as np
import pytest

import kalman_course as kc
from kalman_course.scenarios import convergence, pendulum


def test_mean_and_covariance_tend_to_the_kalman_filter_as_one_over_root_n():
    conv = convergence.ensemble_convergence(sizes=(25, 100, 400, 1600), n_runs=4)
    assert -0.65 < conv.mean_slope < -0.35, conv.mean_error
    assert -0.65 < conv.cov_slope < -0.35, conv.cov_error
    assert conv.mean_error[-1] < 0.1 and conv.cov_error[-1] < 0.1


def test_one_analysis_has_the_kalman_covariance_only_with_perturbed_observations():
    r"""Un seul pas, 200 000 membres : avec perturbations, la covariance analysée vaut (I − KH)P⁻ (forme
    close du filtre de Kalman) ; sans (v = 0, même gain), elle vaudrait (I − KH)P⁻(I − KH)ᵀ, trop petite."""
    bench = convergence.linear_benchmark(n_steps=1)
    ref = kc.kalman_filter(bench.model, bench.y, bench.x0, bench.P0)
    res = kc.ensemble_kalman_filter(bench.nonlinear, bench.y, bench.x0, bench.P0, n_members=200_000, rng=0)
    np.testing.assert_allclose(res.P[0], ref.P[0], rtol=0.02)
    np.testing.assert_allclose(res.x[0], ref.x[0], atol=0.01)
    np.testing.assert_allclose(res.K[0], ref.K[0], atol=0.01)
    I_KH = np.eye(2) - ref.K[0] @ np.array(bench.model.C)
    too_small = I_KH @ ref.P_pred[0] @ I_KH.T
    assert too_small[0, 0] < 0.8 * ref.P[0, 0, 0]  # la différence que les perturbations corrigent est visible
    assert abs(res.P[0, 0, 0] - too_small[0, 0]) > 10 * abs(res.P[0, 0, 0] - ref.P[0, 0, 0])


def test_same_seed_same_output_and_members_kept():
    data = pendulum.pendulum_data(30)
    model = pendulum.pendulum_model()
    a = kc.ensemble_kalman_filter(model, data.y, data.x0, data.P0, n_members=50, rng=5, keep_members=True)
    b = kc.ensemble_kalman_filter(model, data.y, data.x0, data.P0, n_members=50, rng=np.random.default_rng(5))
    np.testing.assert_array_equal(a.x, b.x)
    np.testing.assert_array_equal(a.P, b.P)
    assert a.members.shape == (30, 50, 2) and b.members is None
    np.testing.assert_allclose(a.members.mean(axis=1), a.x, rtol=0, atol=1e-12)
    assert isinstance(a, kc.EnsembleFilterResult)


def test_missing_rows_are_forecast_only():
    data = pendulum.pendulum_data(30)
    y = np.array(data.y)
    y[[2, 3, 17]] = np.nan
    res = kc.ensemble_kalman_filter(pendulum.pendulum_model(), y, data.x0, data.P0, n_members=100, rng=1)
    for k in (2, 3, 17):
        np.testing.assert_array_equal(res.x[k], res.x_pred[k])
        assert np.all(res.K[k] == 0) and np.isnan(res.innovation[k]).all()


def test_enkf_tracks_a_pendulum_measured_by_its_angle():
    """Dynamique non linéaire, mesure monotone (l'angle, par un codeur) : l'EnKF fait aussi bien que l'EKF et
    l'UKF. (Avec la mesure ambiguë sin θ, des membres restent sur la mauvaise branche θ ↔ π − θ : l'EnKF
    ne repondère pas ses membres, contrairement au filtre particulaire.)"""
    base = pendulum.pendulum_model()
    model = kc.NonlinearModel(base.f, lambda x: x[..., :1], base.Q, base.R, vectorized=True)
    sim = kc.simulate(model, pendulum.PENDULUM_X_TRUE0, 500, rng=1)
    rmse = {}
    for name, res in (
        ("EnKF", kc.ensemble_kalman_filter(model, sim.y, pendulum.PENDULUM_X0, pendulum.PENDULUM_P0,
                                           n_members=500, rng=3)),
        ("EKF", kc.extended_kalman_filter(model, sim.y, pendulum.PENDULUM_X0, pendulum.PENDULUM_P0)),
        ("UKF", kc.unscented_kalman_filter(model, sim.y, pendulum.PENDULUM_X0, pendulum.PENDULUM_P0,
                                           alpha=1.0, kappa=0.0)),
    ):
        rmse[name] = np.sqrt(np.mean((res.x[100:, 0] - sim.x[100:, 0]) ** 2))
    assert rmse["EnKF"] < 1.1 * rmse["EKF"] and rmse["EnKF"] < 1.1 * rmse["UKF"], rmse


@pytest.mark.parametrize("bad, message", [
    (dict(n_members=1), "« n_members » doit être un entier ≥ 2 ; reçu 1"),
    (dict(n_members=10.0), "« n_members » doit être un entier ≥ 2"),
    (dict(rng="graine"), "« rng » doit être une graine entière ou un numpy.random.Generator"),
])
def test_bad_arguments_are_named_in_french(bad, message):
    data = pendulum.pendulum_data(5)
    args = dict(n_members=10, rng=0)
    args.update(bad)
    with pytest.raises(kc.KalmanInputError, match=message):
        kc.ensemble_kalman_filter(pendulum.pendulum_model(), data.y, data.x0, data.P0, **args)


def test_non_additive_noise_is_refused():
    m = pendulum.pendulum_model()
    noisy = kc.NonlinearModel(m.f, m.h, [[1.0]], m.R, f_noise_jacobian=[[0.0], [1.0]])
    with pytest.raises(kc.KalmanInputError, match="bruits additifs"):
        kc.ensemble_kalman_filter(noisy, np.zeros((3, 1)), [0.0, 0.0], np.eye(2), n_members=10, rng=0)


def test_perturbed_analysis_covariance_identity_of_the_chapter():
    """(I − KH)P(I − KH)ᵀ + KRKᵀ = (I − KH)P pour le gain optimal (et pas pour un autre gain)."""
    rng = np.random.default_rng(0)
    L = rng.standard_normal((3, 3))
    P, H = L @ L.T + np.eye(3), rng.standard_normal((2, 3))
    R = np.diag([0.5, 2.0])
    K = P @ H.T @ np.linalg.inv(H @ P @ H.T + R)
    I_KH = np.eye(3) - K @ H
    np.testing.assert_allclose(I_KH @ P @ I_KH.T + K @ R @ K.T, I_KH @ P, atol=1e-12)
    K2 = 1.1 * K
    assert not np.allclose((np.eye(3) - K2 @ H) @ P @ (np.eye(3) - K2 @ H).T + K2 @ R @ K2.T, (np.eye(3) - K2 @ H) @ P)


def test_unperturbed_analysis_has_the_too_small_covariance():
    bench = convergence.linear_benchmark(n_steps=1)
    ref = kc.kalman_filter(bench.model, bench.y, bench.x0, bench.P0)
    res = kc.ensemble_kalman_filter(bench.nonlinear, bench.y, bench.x0, bench.P0, n_members=200_000, rng=0,
                                    perturb=False)
    I_KH = np.eye(2) - ref.K[0] @ np.array(bench.model.C)
    np.testing.assert_allclose(res.P[0], I_KH @ ref.P_pred[0] @ I_KH.T, rtol=0.02, atol=1e-3)
    spread = convergence.ensemble_spread()
    assert spread.unperturbed[-10:].mean() < 0.7 * spread.kalman[-10:].mean()
    assert abs(spread.perturbed[-10:].mean() / spread.kalman[-10:].mean() - 1) < 0.25
    with pytest.raises(kc.KalmanInputError, match="« perturb » doit être un booléen"):
        kc.ensemble_kalman_filter(bench.nonlinear, bench.y, bench.x0, bench.P0, n_members=5, rng=0, perturb="non")
