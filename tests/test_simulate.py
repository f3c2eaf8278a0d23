"""Simulation : reproductible, alignée sur le filtre, statistiques conformes au modèle."""

from __future__ import annotations

import numpy as np
import scipy.stats

import kalman_course as kc
from conftest import random_model


def test_same_seed_same_draws_and_generator_accepted():
    model = random_model(np.random.default_rng(0), 3, 2, 1)
    u = np.ones((20, 1))
    a = kc.simulate(model, np.zeros(3), 20, u=u, rng=42)
    b = kc.simulate(model, np.zeros(3), 20, u=u, rng=np.random.default_rng(42))
    np.testing.assert_array_equal(a.x, b.x)
    np.testing.assert_array_equal(a.y, b.y)
    c = kc.simulate(model, np.zeros(3), 20, u=u, rng=43)
    assert not np.array_equal(a.y, c.y)
    assert a.x.shape == (20, 3) and a.y.shape == (20, 2)


def test_noise_free_dynamics_follow_the_recursion():
    A = np.array([[1.0, 0.1], [0.0, 1.0]])
    B = np.array([[0.005], [0.1]])
    model = kc.LinearGaussianModel(A, [[1.0, 0.0]], np.zeros((2, 2)), [[1e-12]], B=B)
    u = np.linspace(0, 1, 15)
    sim = kc.simulate(model, [1.0, -1.0], 15, u=u, rng=0)
    x = np.array([1.0, -1.0])
    for k in range(15):
        x = A @ x + B[:, 0] * u[k]
        np.testing.assert_allclose(sim.x[k], x, atol=1e-12)


def test_measurement_noise_has_covariance_r():
    R = np.array([[0.5, 0.2], [0.2, 0.3]])
    model = kc.LinearGaussianModel(np.eye(2), np.eye(2), np.zeros((2, 2)), R)
    T = 20000
    sim = kc.simulate(model, np.zeros(2), T, rng=1)
    v = sim.y - sim.x
    cov = np.cov(v.T)
    # erreur type de chaque élément de covariance empirique ~ sqrt((R_ij² + R_ii R_jj)/T)
    se = np.sqrt((R**2 + np.outer(np.diag(R), np.diag(R))) / T)
    assert np.all(np.abs(cov - R) < 5 * se)
    # moyenne nulle (test de Student sur chaque composante)
    assert np.all(scipy.stats.ttest_1samp(v, 0.0).pvalue > 1e-3)
