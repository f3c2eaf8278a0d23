"""SRIF : contre le filtre de Kalman du paquet et filterpy (KalmanFilter, InformationFilter), invariants
(R_xx triangulaire supérieure, ‖z_r‖² = NIS), départ diffus = moindres carrés en bloc (scipy.linalg.lstsq),
démonstration du départ diffus (référence en précision étendue), forme sans A⁻¹, SRIF étendu = EKF,
entrées invalides."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
from conftest import filterpy_kf
from filterpy.kalman import InformationFilter

import kalman_course as kc
from kalman_course.filters import square_root_information as srif
from kalman_course.scenarios import diffuse

TOL = 1e-9


def random_system(seed: int, gamma_cols: int, T: int = 60, singular_A: bool = False):
    """Système à 4 états, commande scalaire, R pleine corrélée (m = 2), Q = Γ Γᵀ avec Γ (4, gamma_cols).

    A = expm(0.3 N) ramenée à un rayon spectral 0,98 (bornée sur 60 pas) ; ``singular_A`` : rang 3."""
    rng = np.random.default_rng(seed)
    n, m = 4, 2
    A = scipy.linalg.expm(0.3 * rng.standard_normal((n, n)))
    A /= np.abs(np.linalg.eigvals(A)).max() / 0.98
    if singular_A:
        U, s, Vt = np.linalg.svd(A)
        s[-1] = 0.0
        A = (U * s) @ Vt
    C = rng.standard_normal((m, n))
    G = 0.3 * rng.standard_normal((n, gamma_cols))
    Lr = 0.5 * rng.standard_normal((m, m))
    R = Lr @ Lr.T + 0.1 * np.eye(m)
    B = rng.standard_normal((n, 1))
    model = kc.LinearGaussianModel(A, C, G @ G.T, R, B=B)
    u = rng.standard_normal((T, 1))
    sim = kc.simulate(model, rng.standard_normal(n), T, u=u, rng=rng)
    return model, sim.y, u, G


# --------------------------------------------------------------------------- SRIF = KF


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("gamma_cols", [2, 4])
def test_srif_equals_kalman_filter_and_filterpy(seed, gamma_cols):
    model, y, u, G = random_system(seed, gamma_cols)
    assert np.linalg.matrix_rank(model.Q) == gamma_cols
    x0, P0 = np.array([0.5, -1.0, 0.2, 0.0]), np.diag([2.0, 1.0, 3.0, 0.5])
    kf = kc.kalman_filter(model, y, x0, P0, u=u)
    sr = kc.square_root_information_filter(model, y, x0, P0, u=u)
    for name in ("x", "P", "x_pred", "P_pred", "K", "innovation", "S"):
        np.testing.assert_allclose(getattr(sr, name), getattr(kf, name), atol=TOL, rtol=TOL, err_msg=name)
    fx, fP, fxp, fPp = filterpy_kf(model, y, x0, P0, u=u)
    np.testing.assert_allclose(sr.x, fx, atol=TOL, rtol=TOL)
    np.testing.assert_allclose(sr.P, fP, atol=TOL, rtol=TOL)
    np.testing.assert_allclose(sr.x_pred, fxp, atol=TOL, rtol=TOL)
    np.testing.assert_allclose(sr.P_pred, fPp, atol=TOL, rtol=TOL)
    assert sr.observed.all() and sr.x.shape == (60, 4)


def test_srif_equals_filterpy_information_filter():
    model, y, u, _ = random_system(7, 2)
    x0, P0 = np.zeros(4), 4.0 * np.eye(4)
    f = InformationFilter(dim_x=4, dim_z=2, dim_u=1, compute_log_likelihood=False)
    f.F = np.array(model.A)
    f.H = np.array(model.C)
    f.Q = np.array(model.Q)
    f.R_inv = np.linalg.inv(model.R)
    f.B = np.array(model.B)
    f.x = x0.reshape(4, 1).copy()
    f.P_inv = np.linalg.inv(P0)
    xs, Ps = [], []
    for k in range(len(y)):
        f.predict(u=u[k].reshape(1, 1))
        f.update(y[k].reshape(2, 1))
        xs.append(f.x.ravel().copy())
        Ps.append(np.linalg.inv(f.P_inv))
    sr = kc.square_root_information_filter(model, y, x0, P0, u=u)
    np.testing.assert_allclose(sr.x, np.array(xs), atol=TOL, rtol=TOL)
    np.testing.assert_allclose(sr.P, np.array(Ps), atol=TOL, rtol=TOL)


def test_missing_measurements_match_kalman_filter():
    model, y, u, _ = random_system(3, 2, T=30)
    y = y.copy()
    y[4] = np.nan           # mesure absente : prédiction seule
    y[9, 1] = np.nan        # composante absente
    y[15, 0] = np.nan
    x0, P0 = np.zeros(4), np.eye(4)
    kf = kc.kalman_filter(model, y, x0, P0, u=u)
    sr = kc.square_root_information_filter(model, y, x0, P0, u=u)
    for name in ("x", "P", "x_pred", "P_pred", "K", "innovation", "S"):
        np.testing.assert_allclose(getattr(sr, name), getattr(kf, name), atol=TOL, rtol=TOL, equal_nan=True,
                                   err_msg=name)
    np.testing.assert_array_equal(sr.observed, ~np.isnan(y))


def test_joint_form_without_inverse_handles_singular_A():
    """§ 4.4 : A de rang 3, bruit d'état de rang plein, forme « joint » = KF (§ 7 a″)."""
    model, y, u, _ = random_system(11, 4, T=50, singular_A=True)
    assert np.linalg.matrix_rank(model.A) == 3
    x0, P0 = np.ones(4), np.eye(4)
    kf = kc.kalman_filter(model, y, x0, P0, u=u)
    sr = kc.square_root_information_filter(model, y, x0, P0, u=u, method="joint")
    np.testing.assert_allclose(sr.x, kf.x, atol=TOL, rtol=TOL)
    np.testing.assert_allclose(sr.P, kf.P, atol=TOL, rtol=TOL)
    np.testing.assert_allclose(sr.P_pred, kf.P_pred, atol=TOL, rtol=TOL)
    with pytest.raises(kc.KalmanInputError, match=r"« A ».*singulière.*method=\"joint\""):
        kc.square_root_information_filter(model, y, x0, P0, u=u)


def test_joint_and_inverse_forms_agree_when_both_apply():
    model, y, u, _ = random_system(12, 4, T=40)
    a = kc.square_root_information_filter(model, y, u=u)  # départ diffus, les deux formes
    b = kc.square_root_information_filter(model, y, u=u, method="joint")
    np.testing.assert_allclose(a.x, b.x, atol=TOL, rtol=TOL, equal_nan=True)
    np.testing.assert_allclose(a.P, b.P, atol=TOL, rtol=TOL, equal_nan=True)


# --------------------------------------------------------------------------- invariants


def test_steps_keep_R_upper_triangular_and_match_the_runner():
    model, y, u, _ = random_system(5, 2, T=50)
    R, z = np.zeros((4, 4)), np.zeros(4)
    xs = []
    for k in range(len(y)):
        R, z = kc.srif_predict(model, R, z, u=u[k])
        assert np.array_equal(np.tril(R, -1), np.zeros((4, 4))), f"pas {k} (prédiction)"
        assert (np.diag(R) >= 0).all()
        R, z, zr = kc.srif_update(model, R, z, y[k])
        assert np.array_equal(np.tril(R, -1), np.zeros((4, 4))), f"pas {k} (correction)"
        assert (np.diag(R) >= 0).all() and zr.shape == (2,)
        xs.append(np.full(4, np.nan) if srif.information_rank(R) < 4 else kc.information_to_state(R, z).x)
    run = kc.square_root_information_filter(model, y, u=u)
    np.testing.assert_allclose(run.x, np.array(xs), atol=1e-12, rtol=1e-12, equal_nan=True)


def test_residual_norm_is_the_nis_from_an_exact_prior():
    model, y, _, _ = random_system(9, 2, T=1)
    rng = np.random.default_rng(4)
    M = rng.standard_normal((4, 4))
    x_pred, P_pred = rng.standard_normal(4), M @ M.T + 0.5 * np.eye(4)
    R, z = kc.state_to_information(x_pred, P_pred)
    out = kc.srif_update(model, R, z, y[0])
    nu = y[0] - model.C @ x_pred
    S = model.C @ P_pred @ model.C.T + model.R
    nis = float(nu @ scipy.linalg.solve(S, nu, assume_a="pos"))
    assert float(out.residual @ out.residual) == pytest.approx(nis, rel=1e-10)
    ref = kc.update(model, x_pred, P_pred, y[0])
    est = kc.information_to_state(out.R, out.z)
    np.testing.assert_allclose(est.x, ref.x, atol=1e-12)
    np.testing.assert_allclose(est.P, ref.P, atol=1e-12)


def test_conversions_round_trip_without_general_inverse():
    rng = np.random.default_rng(8)
    M = rng.standard_normal((5, 5))
    P, x = M @ M.T + 0.1 * np.eye(5), rng.standard_normal(5)
    R, z = kc.state_to_information(x, P)
    assert np.array_equal(np.tril(R, -1), np.zeros((5, 5))) and (np.diag(R) > 0).all()
    np.testing.assert_allclose(R.T @ R, np.linalg.inv(P), rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(z, R @ x, rtol=1e-12)
    back = kc.information_to_state(R, z)
    np.testing.assert_allclose(back.x, x, atol=1e-12)
    np.testing.assert_allclose(back.P, P, atol=1e-12)


# --------------------------------------------------------------------------- départ diffus


def test_diffuse_start_equals_batch_weighted_least_squares():
    model, y, u, G = random_system(21, 2, T=25)
    sr = kc.square_root_information_filter(model, y, u=u)
    ref = diffuse.batch_least_squares(model.A, model.C, np.linalg.cholesky(model.R), G, y, B=model.B, u=u)
    defined = np.isfinite(sr.x).all(axis=1)
    np.testing.assert_array_equal(defined, np.isfinite(ref).all(axis=1))
    assert not defined[0] and defined[1:].all()  # m = 2 < n = 4 : il faut deux relevés
    np.testing.assert_allclose(sr.x[defined], ref[defined], atol=TOL, rtol=TOL)
    # avant le rang plein : NaN partout, mais la mesure est bien comptée et le gain n'est pas défini
    assert np.isnan(sr.x[0]).all() and np.isnan(sr.P[0]).all() and np.isnan(sr.x_pred[:2]).all()
    assert sr.observed[0].all() and np.isnan(sr.K[0]).all()
    # ensuite, c'est le filtre de Kalman parti de l'estimation du 2ᵉ relevé (gain compris)
    kf = kc.kalman_filter(model, y[2:], sr.x[1], sr.P[1], u=u[2:])
    for name in ("x", "P", "K", "S", "innovation"):
        np.testing.assert_allclose(getattr(sr, name)[2:], getattr(kf, name), atol=TOL, rtol=TOL, err_msg=name)


def test_diffuse_demo_srif_exact_kalman_filter_off():
    """§ 7 (f) : SRIF sans a priori à la précision machine, KF avec P0 = 1e10 I faux de plus de 1e-5 m."""
    model = diffuse.diffuse_model()
    _, y = diffuse.diffuse_data()
    ref = diffuse.extended_precision_estimates(model, y)  # vérifiée contre les moindres carrés en bloc ci-dessous
    sr = kc.square_root_information_filter(model, y)
    srif_err = np.abs(sr.x[1:, :2] - ref[1:, :2]).max()
    kf = kc.kalman_filter(model, y, np.zeros(4), 1e10 * np.eye(4), form="textbook")
    kf_err = np.abs(kf.x[1:, :2] - ref[1:, :2]).max()
    assert srif_err < 1e-12
    assert kf_err > 1e-5
    errors = diffuse.diffuse_errors()
    assert errors.srif_max < 1e-12 and errors.kf_max_at(10) > 1e-5 and errors.kf_max_at(6) < 1e-7
    assert errors.kf_failed.any()  # P0 trop grande : S n'est plus définie positive numériquement


def test_batch_estimates_of_the_scenario_match_extended_precision():
    model = diffuse.diffuse_model()
    _, y = diffuse.diffuse_data()
    np.testing.assert_allclose(diffuse.batch_estimates(y)[1:], diffuse.extended_precision_estimates(model, y)[1:],
                               atol=1e-9)


# --------------------------------------------------------------------------- SRIF étendu


def _drag_model(dt=0.5, c=0.05):
    def f(x, u):
        p, v = x[:2], x[2:]
        return np.concatenate([p + dt * v, v - dt * c * np.linalg.norm(v) * v])

    def F(x, u):
        v = x[2:]
        s = np.linalg.norm(v)
        J = np.eye(4)
        J[:2, 2:] = dt * np.eye(2)
        J[2:, 2:] -= dt * c * (s * np.eye(2) + np.outer(v, v) / s)
        return J

    def h(x):
        return np.array([np.hypot(x[0], x[1]), np.arctan2(x[1], x[0])])

    def H(x):
        r2 = x[0] ** 2 + x[1] ** 2
        r = np.sqrt(r2)
        return np.array([[x[0] / r, x[1] / r, 0, 0], [-x[1] / r2, x[0] / r2, 0, 0]])

    Q = np.diag([1e-4, 1e-4, 1e-2, 1e-2])
    R = np.diag([0.05**2, np.deg2rad(0.5) ** 2])
    return kc.NonlinearModel(f, h, Q, R, f_jacobian=F, h_jacobian=H, angle_indices=[1])


def test_extended_srif_equals_ekf():
    model = _drag_model()
    rng = np.random.default_rng(2)
    x = np.array([-20.0, 5.0, 4.0, 1.0])
    ys = []
    for _ in range(50):
        x = model.transition(x) + np.sqrt(np.diag(model.Q)) * rng.standard_normal(4)
        ys.append(model.observe(x) + np.sqrt(np.diag(model.R)) * rng.standard_normal(2))
    y = np.array(ys)
    y[20, 0] = np.nan
    x0, P0 = np.array([-19.0, 4.0, 3.5, 1.2]), np.diag([4.0, 4.0, 1.0, 1.0])
    ekf = kc.extended_kalman_filter(model, y, x0, P0)
    esr = kc.extended_square_root_information_filter(model, y, x0, P0)
    for name in ("x", "P", "x_pred", "P_pred", "K", "innovation", "S"):
        np.testing.assert_allclose(getattr(esr, name), getattr(ekf, name), atol=TOL, rtol=TOL, equal_nan=True,
                                   err_msg=name)


def test_extended_srif_on_a_linear_model_is_the_srif():
    model, y, u, _ = random_system(4, 2, T=30)
    nl = kc.NonlinearModel.from_linear(model)
    x0, P0 = np.zeros(4), np.eye(4)
    a = kc.extended_square_root_information_filter(nl, y, x0, P0, u=u)
    b = kc.square_root_information_filter(model, y, x0, P0, u=u)
    np.testing.assert_allclose(a.x, b.x, atol=TOL, rtol=TOL)
    np.testing.assert_allclose(a.P, b.P, atol=TOL, rtol=TOL)


# --------------------------------------------------------------------------- entrées invalides


def _linear():
    return kc.LinearGaussianModel(np.eye(2), [[1.0, 0.0]], 0.01 * np.eye(2), [[0.1]])


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda m: kc.srif_predict(m, np.eye(3), np.zeros(3)), r"« R_xx » doit être de forme \(2, 2\)"),
        (lambda m: kc.srif_predict(m, [[1.0, 0.0], [0.5, 1.0]], np.zeros(2)),
         r"« R_xx » doit être triangulaire supérieure.*\(1, 0\)"),
        (lambda m: kc.srif_predict(m, np.eye(2), np.zeros(3)), r"« z_x » doit être un vecteur de forme \(2,\)"),
        (lambda m: kc.srif_predict(m, np.eye(2), np.zeros(2), method="qr"), r"« method » doit valoir"),
        (lambda m: kc.srif_predict(m, np.eye(2), np.zeros(2), u=[1.0]), r"pas de matrice de commande B"),
        (lambda m: kc.srif_update(m, np.eye(2), np.zeros(2), [1.0, 2.0]), r"« y » doit être un vecteur de forme \(1,\)"),
        (lambda m: kc.srif_update(m, np.full((2, 2), np.nan), np.zeros(2), [1.0]), r"« R_xx » contient des valeurs non finies"),
        (lambda m: kc.information_to_state(np.diag([1.0, 0.0]), np.zeros(2)),
         r"« R_xx » est singulière \(rang numérique 1 < n = 2\)"),
        (lambda m: kc.state_to_information(np.zeros(2), np.diag([1.0, 0.0])), r"« P » doit être définie positive"),
        (lambda m: kc.square_root_information_filter(m, [1.0, 2.0], x0=np.zeros(2)),
         r"« x0 » et « P0 » vont ensemble"),
        (lambda m: kc.square_root_information_filter(m, [1.0], R0=np.eye(2)), r"« R0 » et « z0 » vont ensemble"),
        (lambda m: kc.square_root_information_filter(m, [1.0], np.zeros(2), np.eye(2), R0=np.eye(2), z0=np.zeros(2)),
         r"soit par \(x0, P0\), soit par \(R0, z0\)"),
        (lambda m: kc.square_root_information_filter(m, [1.0], R0=np.ones((2, 2)), z0=np.zeros(2)),
         r"« R0 » doit être triangulaire supérieure"),
        (lambda m: kc.square_root_information_filter(m, [1.0], np.zeros(2), np.diag([1.0, -1.0])),
         r"« P0 » doit être"),
        (lambda m: kc.square_root_information_filter(m, [[1.0, 2.0]]), r"« y » doit être de forme \(T, 1\)"),
        (lambda m: kc.square_root_information_filter(kc.NonlinearModel.from_linear(m), [1.0]),
         r"« model » doit être un LinearGaussianModel"),
        (lambda m: kc.extended_square_root_information_filter(m, [1.0], np.zeros(2), np.eye(2)),
         r"« model » doit être un NonlinearModel"),
        (lambda m: kc.extended_srif_predict(kc.NonlinearModel.from_linear(m), np.zeros((2, 2)), np.zeros(2)),
         r"SRIF étendu linéarise.*a priori \(x0, P0\)"),
    ],
)
def test_bad_input_raises_french_error(call, message):
    with pytest.raises(kc.KalmanInputError, match=message):
        call(_linear())


def test_singular_A_and_singular_Q_errors():
    singular = kc.LinearGaussianModel([[1.0, 1.0], [0.0, 0.0]], [[1.0, 0.0]], 0.01 * np.eye(2), [[0.1]])
    with pytest.raises(kc.KalmanInputError, match=r"« A » \(F des notes\) est singulière"):
        kc.srif_predict(singular, np.eye(2), np.zeros(2))
    rank_one_Q = kc.LinearGaussianModel(np.eye(2), [[1.0, 0.0]], np.diag([0.01, 0.0]), [[0.1]])
    with pytest.raises(kc.KalmanInputError, match=r"method=\"joint\".*« Q » défini positif"):
        kc.srif_predict(rank_one_Q, np.eye(2), np.zeros(2), method="joint")
    # la forme des notes accepte un bruit d'état de rang déficient (et nul)
    for Q in (np.diag([0.01, 0.0]), np.zeros((2, 2))):
        model = kc.LinearGaussianModel(np.eye(2), [[1.0, 0.0]], Q, [[0.1]])
        R, z = kc.srif_predict(model, np.eye(2), np.ones(2))
        np.testing.assert_allclose(kc.information_to_state(R, z).P, np.eye(2) + Q, atol=1e-14)
