"""Jacobiennes : différences centrées, check_jacobian, angles ; jacobiennes analytiques des exemples."""

from __future__ import annotations

import numpy as np
import pytest

import kalman_course as kc
from kalman_course.scenarios import radar, tag


def test_numerical_jacobian_closed_form():
    """Différences centrées contre la jacobienne écrite à la main d'une fonction test."""

    def g(x):
        return np.array([np.sin(x[0]) * x[1], np.exp(0.3 * x[1]), x[0] ** 3 - 2 * x[2]])

    rng = np.random.default_rng(0)
    for _ in range(20):
        x = rng.normal(size=3) * 3
        expected = np.array(
            [
                [np.cos(x[0]) * x[1], np.sin(x[0]), 0.0],
                [0.0, 0.3 * np.exp(0.3 * x[1]), 0.0],
                [3 * x[0] ** 2, 0.0, -2.0],
            ]
        )
        J = kc.numerical_jacobian(g, x)
        np.testing.assert_allclose(J, expected, rtol=1e-7, atol=1e-8)


def test_numerical_jacobian_with_extra_argument():
    A = np.array([[1.0, 2.0], [3.0, -4.0]])
    J = kc.numerical_jacobian(lambda x, u: A @ x + u, np.array([0.5, 30.0]), (np.ones(2),))
    np.testing.assert_allclose(J, A, rtol=1e-8)


def test_wrap_angle_interval():
    a = np.array([0.0, np.pi, -np.pi, 3 * np.pi, -3 * np.pi, 2 * np.pi, 1.5 * np.pi, -1.5 * np.pi, 7.0])
    w = kc.wrap_angle(a)
    np.testing.assert_allclose(w, [0.0, np.pi, np.pi, np.pi, np.pi, 0.0, -0.5 * np.pi, 0.5 * np.pi, 7.0 - 2 * np.pi],
                               rtol=0, atol=1e-12)
    assert np.all(w > -np.pi) and np.all(w <= np.pi)


def test_numerical_jacobian_of_angle_across_pi():
    """Azimut au voisinage de ±π : sans repli la différence centrée vaut ≈ −2π/(2h) ; avec, ∂θ/∂y = x/r²."""
    x = np.array([-5.0, 0.0])
    wrong = kc.numerical_jacobian(radar.range_bearing, x)
    right = kc.numerical_jacobian(radar.range_bearing, x, angle_indices=(1,))
    assert abs(wrong[1, 1]) > 1e3
    np.testing.assert_allclose(right, radar.range_bearing_jacobian(x), rtol=1e-7, atol=1e-9)


def test_check_jacobian_detects_a_wrong_jacobian():
    x = np.array([3.0, 4.0])
    good = kc.check_jacobian(radar.range_bearing, radar.range_bearing_jacobian, x, name="H radar")
    assert good.ok and good.max_rel_error < 1e-8
    assert "correcte" in repr(good)

    def wrong(x):  # erreur de signe classique sur la dérivée de l'azimut
        J = radar.range_bearing_jacobian(x)
        J[1] *= -1
        return J

    bad = kc.check_jacobian(radar.range_bearing, wrong, x, name="H radar")
    assert not bad.ok and not bad
    assert bad.max_rel_error > 0.01
    assert "FAUSSE" in repr(bad)


def test_check_jacobian_wrong_shape_is_an_error():
    with pytest.raises(kc.KalmanInputError, match=r"jacobienne « H » doit être de forme \(2, 2\)"):
        kc.check_jacobian(radar.range_bearing, lambda x: np.zeros((2, 3)), np.array([3.0, 4.0]), name="H")


def test_numerical_jacobian_rejects_nan_function():
    with pytest.raises(kc.KalmanInputError, match=r"« h » a renvoyé des valeurs non finies"):
        kc.numerical_jacobian(lambda x: np.array([x[0], np.nan]), np.array([-1.0]), name="h")
    with pytest.raises(kc.KalmanInputError, match=r"« h » a échoué"):
        kc.numerical_jacobian(lambda x: 1 / 0, np.array([1.0]), name="h")
    with pytest.raises(kc.KalmanInputError, match="step"):
        kc.numerical_jacobian(np.sin, np.array([1.0]), step=0.0)


# --------------------------------------------------------------------------- jacobiennes des exemples


def test_tag_transition_jacobian_is_the_constant_velocity_matrix():
    data = tag.tag_data()
    np.testing.assert_allclose(tag.tag_model().transition_jacobian(data.x0), kc.constant_velocity(tag.TAG_DT, accel_std=0.0).A)


def test_tag_jacobian_rows_are_unit_vectors_to_the_anchors():
    x = np.array([2.0, 6.0, 0.3, -0.1])
    H = tag.tag_ranges_jacobian(x)
    np.testing.assert_allclose(np.linalg.norm(H[:, :2], axis=1), 1.0)
    np.testing.assert_array_equal(H[:, 2:], 0.0)
    for row, a in zip(H, tag.TAG_ANCHORS):
        np.testing.assert_allclose(row[:2], (x[:2] - a) / np.linalg.norm(x[:2] - a))



def test_model_numerical_fallback_matches_analytic():
    """Sans jacobiennes, le modèle dérive par différences centrées (angles repliés)."""
    analytic = radar.radar_tracking_model()
    numeric = kc.NonlinearModel(analytic.f, analytic.h, analytic.Q, analytic.R, angle_indices=(1,))
    x = np.array([-7.0, 1e-9, 0.1, 0.2])  # azimut ≈ π
    np.testing.assert_allclose(numeric.observation_jacobian(x), analytic.observation_jacobian(x), rtol=0, atol=1e-8)
    np.testing.assert_allclose(numeric.transition_jacobian(x, None), analytic.transition_jacobian(x, None),
                               rtol=0, atol=1e-9)
