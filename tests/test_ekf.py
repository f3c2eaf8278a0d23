"""EKF : contre filterpy (ExtendedKalmanFilter), contre le KF sur un modèle affine, angles, mesures
manquantes, entrées invalides (l'UKF est testé dans ``test_unscented.py``)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import random_model
from filterpy.kalman import ExtendedKalmanFilter

import kalman_course as kc
from kalman_course.scenarios import radar, tag


class _NonlinearEKF(ExtendedKalmanFilter):
    """L'EKF de filterpy prédit linéairement (x ← Fx + Bu) : on lui donne f, et F à chaque pas."""

    def __init__(self, f, F, dim_x, dim_z):
        super().__init__(dim_x, dim_z)
        self._f, self._F = f, F

    def predict_x(self, u=0):
        self.x = self._f(self.x.ravel()).reshape(-1, 1)


def filterpy_ekf(f, F, h, H, Q, R, y, x0, P0, residual=np.subtract):
    n, m = len(x0), y.shape[1]
    ekf = _NonlinearEKF(f, F, n, m)
    ekf.x = np.asarray(x0, float).reshape(n, 1)
    ekf.P = np.array(P0, float)
    ekf.Q = np.array(Q)
    ekf.R = np.array(R)
    xs, Ps, xps, Pps = [], [], [], []
    for z in y:
        ekf.F = F(ekf.x.ravel())  # jacobienne au point a posteriori précédent, avant predict_x
        ekf.predict()
        xps.append(ekf.x.ravel().copy())
        Pps.append(ekf.P.copy())
        ekf.update(z.reshape(m, 1), lambda x: H(x.ravel()), lambda x: h(x.ravel()).reshape(m, 1),
                   residual=residual)
        xs.append(ekf.x.ravel().copy())
        Ps.append(ekf.P.copy())
    return np.array(xs), np.array(Ps), np.array(xps), np.array(Pps)


# --------------------------------------------------------------------------- filterpy


def test_tag_ekf_equals_filterpy_extended_kalman_filter():
    data = tag.tag_data()
    model = tag.tag_model()
    assert data.y.shape[0] == 300
    res = kc.extended_kalman_filter(model, data.y, data.x0, data.P0)
    F = model.transition_jacobian(data.x0)
    xs, Ps, xps, Pps = filterpy_ekf(
        lambda x: F @ x, lambda x: F, tag.tag_ranges, tag.tag_ranges_jacobian, model.Q, model.R,
        data.y, data.x0, data.P0,
    )
    np.testing.assert_allclose(res.x, xs, atol=1e-9, rtol=0)
    np.testing.assert_allclose(res.P, Ps, atol=1e-9, rtol=0)
    np.testing.assert_allclose(res.x_pred, xps, atol=1e-9, rtol=0)
    np.testing.assert_allclose(res.P_pred, Pps, atol=1e-9, rtol=0)
    # la forme de Joseph (celle de filterpy) donne le même résultat
    res_j = kc.extended_kalman_filter(model, data.y, data.x0, data.P0, joseph=True)
    np.testing.assert_allclose(res_j.x, xs, atol=1e-9, rtol=0)


def _pendulum(dt=0.05, g_over_l=9.81, L=1.0):
    def f(x, u=None):
        return np.array([x[0] + dt * x[1], x[1] - dt * g_over_l * np.sin(x[0])])

    def F(x, u=None):
        return np.array([[1.0, dt], [-dt * g_over_l * np.cos(x[0]), 1.0]])

    def h(x):
        return np.array([L * np.sin(x[0]), -L * np.cos(x[0])])

    def H(x):
        return np.array([[L * np.cos(x[0]), 0.0], [L * np.sin(x[0]), 0.0]])

    return f, F, h, H


def _pendulum_data(n=200, seed=5):
    f, F, h, H = _pendulum()
    sim = kc.simulate(kc.NonlinearModel(f, h, np.diag([1e-3, 1e-2]) ** 2, 0.05**2 * np.eye(2)), [1.2, 0.0], n, rng=seed)
    return sim.x, sim.y


def test_nonlinear_dynamics_ekf_equals_filterpy():
    """Pendule : f et h non linéaires (filterpy reçoit f via predict_x et F à chaque pas)."""
    f, F, h, H = _pendulum()
    Q, R = np.diag([1e-6, 1e-4]), 0.05**2 * np.eye(2)
    _, y = _pendulum_data()
    x0, P0 = np.array([0.8, 0.5]), np.diag([0.3, 1.0])
    model = kc.NonlinearModel(f, h, Q, R, f_jacobian=F, h_jacobian=H)
    res = kc.extended_kalman_filter(model, y, x0, P0)
    xs, Ps, _, _ = filterpy_ekf(f, F, h, H, Q, R, y, x0, P0)
    np.testing.assert_allclose(res.x, xs, atol=1e-9, rtol=0)
    np.testing.assert_allclose(res.P, Ps, atol=1e-9, rtol=0)
    # jacobiennes numériques : même filtre à la précision des différences centrées
    res_num = kc.extended_kalman_filter(kc.NonlinearModel(f, h, Q, R), y, x0, P0)
    np.testing.assert_allclose(res_num.x, res.x, rtol=0, atol=1e-6)


def test_noise_jacobians_W_V_equal_additive_covariances():
    r"""Bruits non additifs linéarisés : W Φ Wᵀ et V Ψ Vᵀ remplacent Q et R (formules du cours)."""
    f, F, h, H = _pendulum()
    _, y = _pendulum_data(80)
    W = np.array([[0.0], [0.05]])  # un seul bruit (couple) sur la vitesse angulaire
    V = np.array([[1.0, 0.2], [0.0, 1.0]])
    Qw, Rv = np.array([[0.04]]), np.diag([2e-3, 1e-3])
    x0, P0 = np.array([0.8, 0.5]), np.diag([0.3, 1.0])
    general = kc.NonlinearModel(f, h, Qw, Rv, F, H, f_noise_jacobian=lambda x, u: W, h_noise_jacobian=V,
                                n_state=2)
    additive = kc.NonlinearModel(f, h, W @ Qw @ W.T, V @ Rv @ V.T, F, H)
    a = kc.extended_kalman_filter(general, y, x0, P0)
    b = kc.extended_kalman_filter(additive, y, x0, P0)
    np.testing.assert_allclose(a.x, b.x, rtol=0, atol=1e-12)
    np.testing.assert_allclose(a.P, b.P, rtol=0, atol=1e-12)


# --------------------------------------------------------------------------- EKF affine = KF


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_ekf_on_affine_model_equals_kalman_filter(seed):
    rng = np.random.default_rng(seed)
    lin = random_model(rng, n=3, m=2, p=1)
    A, B, C = lin.A, lin.B, lin.C
    sim = kc.simulate(lin, np.zeros(3), 60, u=rng.normal(size=60), rng=seed)
    u = rng.normal(size=60)
    x0, P0 = rng.normal(size=3), np.eye(3)
    ref = kc.kalman_filter(lin, sim.y, x0, P0, u=u)
    affine = kc.NonlinearModel(
        lambda x, u: A @ x + B @ u + 0.0, lambda x: C @ x, lin.Q, lin.R,
        f_jacobian=lambda x, u: A, h_jacobian=lambda x: C, n_control=1,
    )
    for model, tol in ((affine, 1e-10), (kc.NonlinearModel.from_linear(lin), 1e-10)):
        res = kc.extended_kalman_filter(model, sim.y, x0, P0, u=u)
        np.testing.assert_allclose(res.x, ref.x, rtol=0, atol=tol)
        np.testing.assert_allclose(res.P, ref.P, rtol=0, atol=tol)
        np.testing.assert_allclose(res.K, ref.K, rtol=0, atol=tol)
        np.testing.assert_allclose(res.innovation, ref.innovation, rtol=0, atol=tol)
    numeric = kc.NonlinearModel(affine.f, affine.h, lin.Q, lin.R, n_control=1)
    res = kc.extended_kalman_filter(numeric, sim.y, x0, P0, u=u)
    np.testing.assert_allclose(res.x, ref.x, rtol=0, atol=1e-7)


def test_ekf_missing_measurements_like_kalman_filter():
    rng = np.random.default_rng(4)
    lin = random_model(rng, n=3, m=3, p=0)
    y = np.array(kc.simulate(lin, np.zeros(3), 40, rng=4).y)
    y[5] = np.nan
    y[9, 1] = np.nan
    y[20, [0, 2]] = np.nan
    ref = kc.kalman_filter(lin, y, np.zeros(3), np.eye(3))
    res = kc.extended_kalman_filter(kc.NonlinearModel.from_linear(lin), y, np.zeros(3), np.eye(3))
    np.testing.assert_allclose(res.x, ref.x, rtol=0, atol=1e-10)
    np.testing.assert_allclose(res.P, ref.P, rtol=0, atol=1e-10)
    np.testing.assert_array_equal(res.observed, ref.observed)
    np.testing.assert_allclose(res.K, ref.K, rtol=0, atol=1e-10)
    np.testing.assert_array_equal(np.isnan(res.S), np.isnan(ref.S))
    assert res.n_iter[5] == 0 and res.n_iter[6] == 1


def test_steps_equal_runner():
    data = tag.tag_data(5)
    model = tag.tag_model()
    res = kc.extended_kalman_filter(model, data.y, data.x0, data.P0)
    pred = kc.ekf_predict(model, data.x0, data.P0)
    upd = kc.ekf_update(model, pred.x, pred.P, data.y[0])
    np.testing.assert_array_equal(pred.x, res.x_pred[0])
    np.testing.assert_allclose(upd.x, res.x[0], rtol=0, atol=1e-14)
    np.testing.assert_allclose(upd.P, res.P[0], rtol=0, atol=1e-14)
    np.testing.assert_allclose(upd.innovation, data.y[0] - tag.tag_ranges(pred.x), rtol=0, atol=1e-14)


# --------------------------------------------------------------------------- angles


def test_bearing_innovation_is_wrapped():
    """La cible franchit θ = ±π : sans repli, l'innovation d'azimut vaut ≈ 2π et le filtre décroche."""
    x_true, y, x0, P0 = radar.radar_tracking_data()
    crossing = np.abs(np.diff(y[:, 1])) > np.pi
    assert crossing.any(), "le scénario doit franchir l'axe θ = ±π"
    model = radar.radar_tracking_model()
    res = kc.extended_kalman_filter(model, y, x0, P0)
    nu = res.innovation[:, 1]
    assert np.all(np.abs(nu) < 3 * np.sqrt(res.S[:, 1, 1]))  # mesuré : 2,02 σ au plus
    err = np.linalg.norm(res.x[:, :2] - x_true[:, :2], axis=1)
    assert err[10:].max() < 0.6  # mesuré : 0,505 m
    # filterpy avec un résidu replié donne le même filtre
    F = model.transition_jacobian(x0)

    def residual(a, b):
        return model.residual(np.ravel(a), np.ravel(b)).reshape(-1, 1)

    xs, Ps, _, _ = filterpy_ekf(lambda x: F @ x, lambda x: F, radar.range_bearing,
                                lambda x: radar.range_bearing_jacobian(x, 4), model.Q, model.R, y, x0, P0,
                                residual=residual)
    np.testing.assert_allclose(res.x, xs, rtol=0, atol=1e-9)
    # sans angle_indices : l'innovation d'azimut n'est plus repliée et l'estimation décroche
    unwrapped = kc.NonlinearModel(model.f, model.h, model.Q, model.R, model.f_jacobian, model.h_jacobian)
    bad = kc.extended_kalman_filter(unwrapped, y, x0, P0)
    assert np.abs(bad.innovation[:, 1]).max() > 6.0  # un saut de 2π non replié (mesuré : 6,28)
    assert np.linalg.norm(bad.x[:, :2] - x_true[:, :2], axis=1).max() > 50.0  # mesuré : 77,6 m


# --------------------------------------------------------------------------- scénario du tag


def test_tag_scenario_stays_in_the_room_and_is_consistent():
    data = tag.tag_data()
    p = data.x_true[:, :2]
    assert p.min() > 0 and p[:, 0].max() < tag.TAG_ROOM[0] and p[:, 1].max() < tag.TAG_ROOM[1]
    res = tag.run_tag_ekf(data=data)
    outside = np.abs(res.x - data.x_true) > 3 * res.std()
    assert outside.mean() < 0.02  # erreurs dans ±3σ (à quelques pas près)
    # régler le filtre loin du nominal dégrade l'erreur (les curseurs ont un effet)
    assert tag.position_rmse(tag.run_tag_ekf(0.05, 0.1, data).x, data.x_true) > 1.5 * tag.position_rmse(
        res.x, data.x_true)


# --------------------------------------------------------------------------- entrées invalides


def _good():
    return dict(f=lambda x, u: x, h=lambda x: x[:1], Q=np.eye(2), R=np.eye(1))


def _run(model, y=np.ones((3, 1))):
    return kc.extended_kalman_filter(model, y, np.zeros(2), np.eye(2))


def test_error_f_wrong_size():
    kw = _good() | dict(f=lambda x, u: np.zeros(3))
    with pytest.raises(kc.KalmanInputError, match=r"fonction « f » doit renvoyer un vecteur de forme \(2,\)"):
        _run(kc.NonlinearModel(**kw))


def test_error_h_wrong_size_and_nan():
    with pytest.raises(kc.KalmanInputError, match=r"fonction « h » doit renvoyer un vecteur de forme \(1,\)"):
        _run(kc.NonlinearModel(**(_good() | dict(h=lambda x: x))))
    with pytest.raises(kc.KalmanInputError, match=r"« h » a renvoyé des valeurs non finies"):
        _run(kc.NonlinearModel(**(_good() | dict(h=lambda x: np.array([np.nan])))))
    with pytest.raises(kc.KalmanInputError, match=r"« f » a renvoyé des valeurs non finies"):
        _run(kc.NonlinearModel(**(_good() | dict(f=lambda x, u: np.full(2, np.inf)))))


def test_error_function_raises():
    def boom(x, u):
        raise ZeroDivisionError("division par zéro")

    with pytest.raises(kc.KalmanInputError, match=r"fonction « f » a échoué .*ZeroDivisionError"):
        _run(kc.NonlinearModel(**(_good() | dict(f=boom))))


def test_error_jacobian_wrong_shape():
    with pytest.raises(kc.KalmanInputError, match=r"jacobienne « h_jacobian » doit être de forme \(1, 2\)"):
        _run(kc.NonlinearModel(**_good(), h_jacobian=lambda x: np.eye(2)))
    with pytest.raises(kc.KalmanInputError, match=r"jacobienne « f_jacobian » doit être de forme \(2, 2\)"):
        _run(kc.NonlinearModel(**_good(), f_jacobian=lambda x, u: np.eye(3)))
    with pytest.raises(kc.KalmanInputError, match=r"« f_jacobian » doit être de forme \(2, 2\)"):
        kc.NonlinearModel(**_good(), f_jacobian=np.eye(3))
    with pytest.raises(kc.KalmanInputError, match=r"jacobienne « h_jacobian » contient des valeurs non finies"):
        _run(kc.NonlinearModel(**_good(), h_jacobian=lambda x: np.array([[np.nan, 0.0]])))
    with pytest.raises(kc.KalmanInputError, match=r"« f_noise_jacobian » doit être de forme \(2, 2\)"):
        _run(kc.NonlinearModel(**_good(), f_noise_jacobian=lambda x, u: np.eye(3), n_state=2))


def test_error_model_construction():
    with pytest.raises(kc.KalmanInputError, match=r"« f » doit être une fonction"):
        kc.NonlinearModel(**(_good() | dict(f=np.eye(2))))
    with pytest.raises(kc.KalmanInputError, match=r"« R » doit être définie positive"):
        kc.NonlinearModel(**(_good() | dict(R=np.zeros((1, 1)))))
    with pytest.raises(kc.KalmanInputError, match=r"« angle_indices »"):
        kc.NonlinearModel(**_good(), angle_indices=(3,))
    with pytest.raises(kc.KalmanInputError, match=r"donnez aussi « n_state »"):
        kc.NonlinearModel(**_good(), f_noise_jacobian=lambda x, u: np.eye(2))
    with pytest.raises(kc.KalmanInputError, match=r"« Q » doit être de forme \(3, 3\)"):
        kc.NonlinearModel(**_good(), n_state=3)


def test_error_runner_arguments():
    model = kc.NonlinearModel(**_good())
    with pytest.raises(kc.KalmanInputError, match=r"« model » doit être un NonlinearModel"):
        kc.extended_kalman_filter(kc.LinearGaussianModel(1.0, 1.0, 1.0, 1.0), np.ones(3), 0.0, 1.0)
    with pytest.raises(kc.KalmanInputError, match=r"« y » doit être de forme \(T, 1\)"):
        kc.extended_kalman_filter(model, np.ones((3, 2)), np.zeros(2), np.eye(2))
    with pytest.raises(kc.KalmanInputError, match=r"« x0 » doit être un vecteur de forme \(2,\)"):
        kc.extended_kalman_filter(model, np.ones(3), np.zeros(3), np.eye(2))
    with pytest.raises(kc.KalmanInputError, match=r"matrice de commande"):
        kc.extended_kalman_filter(model, np.ones(3), np.zeros(2), np.eye(2), u=np.ones(3))
    with pytest.raises(kc.KalmanInputError, match=r"« u » est fourni"):
        kc.ekf_predict(model, np.zeros(2), np.eye(2), u=np.ones(1))


# --------------------------------------------------------------------------- formules du chapitre


def test_tag_process_noise_is_the_chapter_formula():
    r"""Q = σ_a² [[Δt⁴/4, Δt³/2], [Δt³/2, Δt²]] ⊗ I₂ (accélération blanche constante par morceaux)."""
    dt, s = 0.1, 0.7
    Q = kc.scenarios.tag_model(accel_std=s, dt=dt).Q
    blk = s**2 * np.array([[dt**4 / 4, dt**3 / 2], [dt**3 / 2, dt**2]])
    expected = np.zeros((4, 4))
    for axis in (0, 1):
        idx = [axis, axis + 2]
        expected[np.ix_(idx, idx)] = blk
    np.testing.assert_allclose(Q, expected, rtol=0, atol=1e-15)
