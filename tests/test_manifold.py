"""Caméra à sténopé et EKF itéré sur SE(3) (kalman_course.geometry.camera, filters.se3, lecture.errata_se3, scénario).

Oracles (ALGORITHMS.md §8) : jacobiennes des pixels contre les différences centrées de la rétraction
(h = 1e-6, relatif 1e-6) ; :math:`J^R = J^L\\mathrm{Ad}_T` (1e-10) ; pose convergée contre un MAP calculé ici
par ``scipy.optimize.least_squares`` sur :math:`\\hat T_-\\mathrm{expm}(\\xi^\\wedge)` (1e-6) ; une itération =
EKF sur la variété recalculé ici (1e-12) ; boucle des notes = ajustement aux seules mesures ; NEES de
Monte-Carlo dans la bande du χ² ; entrées invalides : KalmanInputError en français.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
import scipy.optimize
import scipy.stats

import kalman_course as kc
from kalman_course.lecture import errata_se3
from kalman_course.geometry import lie
from kalman_course.geometry.camera import (
    PinholeCamera,
    camera_measurement,
    camera_measurement_jacobian,
    check_camera_jacobian,
    project,
    transform_points,
)
from kalman_course.scenarios import camera_target as ct

CAM = PinholeCamera(fx=520.0, fy=500.0, cx=320.0, cy=240.0)


@pytest.fixture(scope="module")
def problem():
    return ct.camera_target_problem()


@pytest.fixture(scope="module")
def solved(problem):
    return problem.iekf()


# --------------------------------------------------------------------------- oracles indépendants


def _hat(xi):
    r, w = xi[:3], xi[3:]
    return np.array([[0, -w[2], w[1], r[0]], [w[2], 0, -w[0], r[1]], [-w[1], w[0], 0, r[2]], [0, 0, 0, 0.0]])


def _distance(T1, T0):
    return float(np.linalg.norm(lie.se3_log(np.linalg.inv(T0) @ T1)))


def _random_pose_and_points(gen, n=4):
    """Pose et points tels que Z' ∈ [1, 6] m."""
    T = lie.se3_exp(np.r_[gen.normal(size=3) * 0.3, gen.normal(size=3)])
    Pc = np.column_stack([gen.uniform(-1, 1, n), gen.uniform(-1, 1, n), gen.uniform(1, 6, n)])
    points = (Pc - T[:3, 3]) @ T[:3, :3]  # p = Rᵀ(P' − t)
    return T, points


# --------------------------------------------------------------------------- caméra


def test_projection_and_intrinsics():
    P = np.array([[0.5, -0.2, 2.0]])
    uv = project(CAM, P)
    np.testing.assert_allclose(uv, [[320 + 520 * 0.25, 240 - 500 * 0.1]], rtol=0, atol=1e-12)
    # Z' [u; v; 1] = K_cam P'
    np.testing.assert_allclose(2.0 * np.r_[uv[0], 1.0], CAM.K_cam @ P[0], rtol=0, atol=1e-12)
    assert np.array_equal(CAM.intrinsics, CAM.K_cam)




def test_wrong_jacobians_fail_the_check():
    T, points = _random_pose_and_points(np.random.default_rng(3))
    Pc = transform_points(T, points)
    Jpi = kc.geometry.camera.projection_jacobian(CAM, Pc)
    printed_row3 = np.vstack([Jpi[i] @ errata_se3.notes_point_jacobian(Pc[i], as_printed=True) for i in range(len(Pc))])
    assert not check_camera_jacobian(T, points, CAM, "left", jacobian=printed_row3)
    notes_missing = -np.vstack([errata_se3.notes_residual_jacobian(P, CAM, restore_missing=False) for P in Pc])
    assert not check_camera_jacobian(T, points, CAM, "left", jacobian=notes_missing)
    # la jacobienne gauche n'est pas la droite
    assert not check_camera_jacobian(T, points, CAM, "right", jacobian=camera_measurement_jacobian(T, points, CAM, "left"))


def test_notes_matrix_with_restored_entry_is_minus_left_jacobian():
    gen = np.random.default_rng(5)
    for _ in range(20):
        T, points = _random_pose_and_points(gen)
        Pc = transform_points(T, points)
        notes = np.vstack([errata_se3.notes_residual_jacobian(P, CAM) for P in Pc])
        assert np.max(np.abs(notes + camera_measurement_jacobian(T, points, CAM, "left"))) <= 1e-9


def test_right_jacobian_is_left_times_adjoint():
    gen = np.random.default_rng(11)
    for _ in range(50):
        T, points = _random_pose_and_points(gen)
        JR = camera_measurement_jacobian(T, points, CAM, "right")
        JL = camera_measurement_jacobian(T, points, CAM, "left")
        assert np.max(np.abs(JR - JL @ lie.se3_adjoint(T))) <= 1e-10


def test_notes_residual_has_the_wrong_sign_of_the_principal_point(problem):
    # 004-2 : au vrai, le résidu correct est le bruit (~1 px), celui des notes vaut ~2 c_x, 2 c_y
    good = problem.y - camera_measurement(problem.T_true, problem.points, problem.camera)
    bad = errata_se3.notes_residual(problem.T_true, problem.points, problem.camera, problem.y)
    assert np.max(np.abs(good)) < 4.0
    np.testing.assert_allclose((bad - good).reshape(-1, 2), np.tile([640.0, 480.0], (10, 1)), atol=1e-9)


# --------------------------------------------------------------------------- mise à jour itérée


def test_scenario_matches_the_specification(problem):
    assert problem.points.shape == (10, 3)
    np.testing.assert_allclose(np.ptp(problem.points, axis=0), [1.0, 0.8, 0.5])
    assert abs(problem.T_true[2, 3] - 3.5) < 1e-12
    assert problem.camera.fx == 520 and problem.camera.fy == 500
    assert (problem.camera.width, problem.camera.height) == (640, 480)
    d0 = lie.se3_log(np.linalg.inv(problem.T_true) @ problem.T_pred)
    np.testing.assert_allclose([np.linalg.norm(d0[:3]), np.degrees(np.linalg.norm(d0[3:]))], [0.2, 10.0])
    np.testing.assert_allclose(problem.P_pred, np.diag([0.04] * 3 + [np.deg2rad(10) ** 2] * 3))
    assert problem.camera.in_image(problem.y.reshape(-1, 2)).all()
    again = ct.camera_target_problem()
    assert np.array_equal(again.y, problem.y)  # graine fixée


def test_converged_pose_is_the_independent_map(problem, solved):
    T_map = ct.camera_map_estimate(problem)
    assert solved.converged and solved.n_iter <= 10
    assert _distance(solved.T, T_map) <= 1e-6
    assert _distance(ct.camera_map_estimate(problem), T_map) <= 1e-6  # le MAP du scénario aussi
    assert abs(solved.cost[-1] - problem.cost(T_map)) <= 1e-9 * problem.cost(T_map)
    # le coût décroît et la première itération ne suffit pas
    assert np.all(np.diff(solved.cost) <= 1e-9)
    assert _distance(solved.iterates[1], T_map) > 1e-3


def test_one_iteration_is_the_manifold_ekf(problem):
    one = problem.iekf(max_iter=1)
    ekf = kc.se3_ekf_update(problem.T_pred, problem.P_pred, problem.y, problem.points, problem.camera, 1.0)
    # EKF recalculé ici : H en T̂₋, K = P Hᵀ S⁻¹, T = T̂₋ expm(δ^), P = J_r(δ)(I − KH)P J_r(δ)ᵀ
    H = camera_measurement_jacobian(problem.T_pred, problem.points, problem.camera)
    P = problem.P_pred
    S = H @ P @ H.T + np.eye(20)
    K = np.linalg.solve(S, H @ P).T
    d = K @ (problem.y - ct.reference_pixels(problem.T_pred, problem.points, problem.camera))
    J = lie.se3_right_jacobian(d)
    P_post = J @ (np.eye(6) - K @ H) @ P @ J.T
    for res in (one, ekf):
        assert res.n_iter == 1
        assert np.max(np.abs(res.T - problem.T_pred @ scipy.linalg.expm(_hat(d)))) <= 1e-12
        assert np.max(np.abs(res.P - P_post)) <= 1e-12 * np.max(np.abs(P_post)) + 1e-18
        assert np.max(np.abs(res.K - K)) <= 1e-12 * np.max(np.abs(K))


def test_embedded_whitened_step_equals_the_iekf_step_and_scalar_weights_do_not(problem, solved):
    args = (problem.T_pred, problem.P_pred, problem.y, problem.points, problem.camera, problem.sigma_px)
    for i in range(3):
        good = errata_se3.embedded_step(solved.iterates[i], *args)
        notes = errata_se3.embedded_step(solved.iterates[i], *args, weights="notes")
        assert np.max(np.abs(good - solved.steps[i])) <= 1e-10
        assert np.max(np.abs(notes - solved.steps[i])) > 1e-5


def test_notes_loop_drops_the_prior_and_fits_the_measurements_only(problem):
    its = errata_se3.notes_literal_iterates(problem.T_pred, problem.P_pred, problem.y, problem.points,
                                           problem.camera, problem.sigma_px)
    T_meas = ct.camera_measurement_only_fit(problem)
    T_map = ct.camera_map_estimate(problem)
    assert _distance(its[-1], T_meas) <= 1e-6
    assert _distance(its[-1], T_map) > 1e-4
    assert _distance(ct.camera_measurement_only_fit(problem), T_meas) <= 1e-6


def test_identity_jacobian_variant_misses_the_map(problem):
    approx = problem.iekf(use_right_jacobian=False)
    assert approx.converged
    assert _distance(approx.T, ct.camera_map_estimate(problem)) > 1e-6


def test_posterior_covariance_is_symmetric_and_shrinks(solved, problem):
    P = solved.P
    assert np.array_equal(P, P.T)
    assert np.linalg.eigvalsh(P)[0] > 0
    assert np.linalg.eigvalsh(problem.P_pred - P)[0] > 0


def test_monte_carlo_nees_iekf_consistent_ekf_not():
    mc = ct.camera_monte_carlo(n_runs=200, rng=11)
    lo, hi = scipy.stats.chi2.ppf([0.025, 0.975], 6 * 200) / 200  # ≈ [5.53, 6.49]
    assert mc.converged.all()
    assert lo <= mc.iekf_nees.mean() <= hi, mc.iekf_nees.mean()
    assert mc.ekf_nees.mean() > hi  # l'EKF est trop confiant
    assert np.median(mc.iekf_error[:, 0]) < np.median(mc.ekf_error[:, 0])
    assert np.median(mc.iekf_error[:, 1]) < np.median(mc.ekf_error[:, 1])


# --------------------------------------------------------------------------- prédiction et suivi



def test_tracking_run_converges_and_ekf_is_one_iteration():
    truth, y, U, T0, P0 = ct.camera_tracking_data(10)
    model = kc.CameraPoseModel(ct.TARGET_POINTS, ct.CAMERA, 1.0, ct.TRACK_Q)
    res = kc.se3_iterated_filter(model, y, T0, P0, U)
    ekf = kc.se3_iterated_filter(model, y, T0, P0, U, max_iter=1)
    assert res.T.shape == (10, 4, 4) and res.P.shape == (10, 6, 6)
    assert np.all(ekf.n_iter == 1) and np.all(res.n_iter > 1)
    rot, pos = ct.pose_error(res.T[-1], truth[-1])
    assert rot < 1.0 and pos < 2.0
    # frame 0 de l'EKF = se3_ekf_update après la prédiction
    Tp, Pp = kc.se3_predict(T0, P0, U[0], ct.TRACK_Q)
    first = kc.se3_ekf_update(Tp, Pp, y[0], ct.TARGET_POINTS, ct.CAMERA, 1.0)
    assert np.array_equal(first.T, ekf.T[0])


# --------------------------------------------------------------------------- entrées invalides


def _args(problem, **over):
    a = dict(T_pred=problem.T_pred, P_pred=problem.P_pred, y=problem.y, points=problem.points,
             camera=problem.camera, sigma_px=1.0)
    a.update(over)
    return a


@pytest.mark.parametrize(
    "over, message",
    [
        ({"y": np.zeros(19)}, r"« y » doit empiler les pixels des 10 points.*\(20,\)"),
        ({"sigma_px": 0.0}, "« sigma_px ».*réel > 0"),
        ({"sigma_px": "un"}, "« sigma_px »"),
        ({"P_pred": -np.eye(6)}, "« P_pred » doit être définie positive"),
        ({"P_pred": np.eye(5)}, r"« P_pred » doit être de forme \(6, 6\)"),
        ({"T_pred": np.diag([1.0, 1.0, 1.1, 1.0])}, "« T_pred » n'est pas une transformation rigide"),
        ({"points": np.zeros((10, 2))}, r"« points » doit être un tableau de points 3-D de forme \(N, 3\)"),
        ({"camera": "caméra"}, "« camera » doit être une PinholeCamera"),
        ({"T_pred": lie.se3_exp([0, 0, -10.0, 0, 0, 0])}, r"derrière la caméra.*Z' > 0"),
    ],
)
def test_bad_update_inputs_are_french_errors(problem, over, message):
    with pytest.raises(kc.KalmanInputError, match=message):
        kc.se3_iekf_update(**_args(problem, **over))


def test_other_bad_inputs_are_french_errors(problem):
    with pytest.raises(kc.KalmanInputError, match="« max_iter » doit être un entier ≥ 1"):
        kc.se3_iekf_update(**_args(problem), max_iter=0)
    with pytest.raises(kc.KalmanInputError, match="focale « fx » doit être strictement positive"):
        PinholeCamera(fx=-1.0, fy=500.0, cx=320.0, cy=240.0)
    with pytest.raises(kc.KalmanInputError, match="« perturbation » doit valoir"):
        camera_measurement_jacobian(problem.T_true, problem.points, problem.camera, "milieu")
    with pytest.raises(kc.KalmanInputError, match=r"Le point 0 est derrière la caméra"):
        project(CAM, [[0.0, 0.0, -1.0]])
    with pytest.raises(kc.KalmanInputError, match=r"« u » doit être un vecteur de forme \(6,\)"):
        kc.se3_predict(np.eye(4), np.eye(6), np.zeros(3), np.eye(6))
    with pytest.raises(kc.KalmanInputError, match="« Q » doit être semi-définie positive"):
        kc.se3_predict(np.eye(4), np.eye(6), np.zeros(6), -np.eye(6))
    model = kc.CameraPoseModel(problem.points, problem.camera, 1.0)
    with pytest.raises(kc.KalmanInputError, match=r"« y » doit être de forme \(T, 20\)"):
        kc.se3_iterated_filter(model, np.zeros(20), problem.T_pred, problem.P_pred)
