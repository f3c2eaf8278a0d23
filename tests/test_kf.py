"""Filtre de Kalman linéaire : comparaison avec filterpy, formes équivalentes, invariants, oracles."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
import scipy.optimize
import scipy.stats
from hypothesis import given, settings
from hypothesis import strategies as st

import kalman_course as kc
from conftest import filterpy_kf, random_model

TOL = dict(atol=1e-10, rtol=1e-10)


# --------------------------------------------------------------------------- filterpy


@pytest.mark.parametrize("form", kc.filters.kalman.FORMS)
def test_constant_voltage_equals_filterpy(form):
    model = kc.scenarios.constant_voltage_model()
    z = kc.scenarios.constant_voltage_measurements(500, rng=3)
    ours = kc.kalman_filter(model, z, x0=0.0, P0=1.0, form=form)
    x, P, xp, Pp = filterpy_kf(model, z, [0.0], [[1.0]])
    np.testing.assert_allclose(ours.x, x, **TOL)
    np.testing.assert_allclose(ours.P, P, **TOL)
    np.testing.assert_allclose(ours.x_pred, xp, **TOL)
    np.testing.assert_allclose(ours.P_pred, Pp, **TOL)


@pytest.mark.parametrize("n,m,p", [(1, 1, 1), (2, 1, 1), (3, 2, 1), (4, 2, 2), (6, 3, 2), (5, 5, 0)])
@pytest.mark.parametrize("form", kc.filters.kalman.FORMS)
def test_random_systems_equal_filterpy(n, m, p, form):
    rng = np.random.default_rng(100 * n + 10 * m + p)
    model = random_model(rng, n, m, p)
    T = 300
    u = rng.standard_normal((T, p)) if p else None
    x0 = rng.standard_normal(n)
    sim = kc.simulate(model, x0, T, u=u, rng=rng)
    P0 = 2.0 * np.eye(n)
    ours = kc.kalman_filter(model, sim.y, np.zeros(n), P0, u=u, form=form)
    x, P, xp, Pp = filterpy_kf(model, sim.y, np.zeros(n), P0, u=u)
    np.testing.assert_allclose(ours.x, x, **TOL)
    np.testing.assert_allclose(ours.P, P, **TOL)
    np.testing.assert_allclose(ours.x_pred, xp, **TOL)
    np.testing.assert_allclose(ours.P_pred, Pp, **TOL)


def test_missing_measurements_predict_only_like_filterpy():
    rng = np.random.default_rng(7)
    model = random_model(rng, 3, 2, 0)
    sim = kc.simulate(model, np.zeros(3), 60, rng=rng)
    y = np.array(sim.y)
    y[[5, 6, 30]] = np.nan
    ours = kc.kalman_filter(model, y, np.zeros(3), np.eye(3))
    x, P, _, _ = filterpy_kf(model, y, np.zeros(3), np.eye(3))
    np.testing.assert_allclose(ours.x, x, **TOL)
    np.testing.assert_allclose(ours.P, P, **TOL)
    # un pas sans mesure : estimation = prédiction, gain nul, innovation non définie
    np.testing.assert_array_equal(ours.x[5], ours.x_pred[5])
    np.testing.assert_array_equal(ours.K[5], 0.0)
    assert np.isnan(ours.innovation[5]).all() and not ours.observed[5].any()


def test_none_entries_are_missing_measurements():
    model = kc.scenarios.constant_voltage_model()
    y = [0.1, None, -0.2, None]
    ours = kc.kalman_filter(model, y, 0.0, 1.0)
    ref = kc.kalman_filter(model, [0.1, np.nan, -0.2, np.nan], 0.0, 1.0)
    np.testing.assert_array_equal(ours.x, ref.x)
    assert ours.observed[:, 0].tolist() == [True, False, True, False]


def test_partial_measurement_uses_observed_components_only():
    rng = np.random.default_rng(11)
    model = random_model(rng, 3, 2, 0)
    y = rng.standard_normal((2, 2))
    y[1, 0] = np.nan
    ours = kc.kalman_filter(model, y, np.zeros(3), np.eye(3))
    # référence indépendante : filterpy avec la seule seconde ligne de C au second pas
    first = kc.kalman_filter(model, y[:1], np.zeros(3), np.eye(3))
    reduced = kc.LinearGaussianModel(model.A, model.C[1:], model.Q, model.R[1:, 1:])
    x, P, _, _ = filterpy_kf(reduced, y[1:, 1:], first.x[0], first.P[0])
    np.testing.assert_allclose(ours.x[1], x[0], **TOL)
    np.testing.assert_allclose(ours.P[1], P[0], **TOL)
    assert ours.K[1][:, 0].tolist() == [0.0, 0.0, 0.0]
    assert np.isnan(ours.innovation[1, 0]) and not np.isnan(ours.innovation[1, 1])


# --------------------------------------------------------------------------- oracles (ALGORITHMS.md §7e)


def test_welch_bishop_random_constant_oracles():
    z = kc.scenarios.constant_voltage_measurements(50)
    res = kc.kalman_filter(kc.scenarios.constant_voltage_model(Q=1e-5, R=0.01), z, 0.0, 1.0)
    assert res.P[49, 0, 0] == pytest.approx(3.392e-4, abs=5e-7)
    assert res.K[49, 0, 0] == pytest.approx(0.0339, abs=5e-5)
    k_large = kc.kalman_filter(kc.scenarios.constant_voltage_model(R=1.0), z, 0.0, 1.0).K[49, 0, 0]
    k_small = kc.kalman_filter(kc.scenarios.constant_voltage_model(R=1e-4), z, 0.0, 1.0).K[49, 0, 0]
    assert k_large == pytest.approx(0.0198, abs=5e-5)
    assert k_small == pytest.approx(0.270, abs=5e-4)


def test_scalar_riccati_closed_form():
    """Cas scalaire : P⁻ = P + Q, K = P⁻/(P⁻ + R), P = (1 − K) P⁻, récurrence écrite à la main."""
    Q, R, P = 1e-5, 0.01, 1.0
    z = kc.scenarios.constant_voltage_measurements(50)
    res = kc.kalman_filter(kc.scenarios.constant_voltage_model(Q=Q, R=R), z, 0.0, P)
    x = 0.0
    for k in range(50):
        Pm = P + Q
        K = Pm / (Pm + R)
        x = x + K * (z[k] - x)
        P = (1 - K) * Pm
        assert res.K[k, 0, 0] == pytest.approx(K, rel=1e-13)
        assert res.x[k, 0] == pytest.approx(x, rel=1e-12, abs=1e-15)
        assert res.P[k, 0, 0] == pytest.approx(P, rel=1e-13)


# --------------------------------------------------------------------------- formes équivalentes


def _one_step(seed, n=4, m=2, p=1):
    rng = np.random.default_rng(seed)
    model = random_model(rng, n, m, p)
    x = rng.standard_normal(n)
    L = rng.standard_normal((n, n))
    P = L @ L.T + 0.1 * np.eye(n)
    u = rng.standard_normal(p)
    y = rng.standard_normal(m)
    return model, x, P, u, y


@pytest.mark.parametrize("seed", range(5))
def test_recipe_one_line_form_equals_predict_update(seed):
    model, x, P, u, y = _one_step(seed)
    pred = kc.predict(model, x, P, u)
    upd = kc.update(model, pred.x, pred.P, y)
    x_r, P_r, K_r = kc.recipe_step(model, x, P, y, u)
    np.testing.assert_allclose(K_r, upd.K, atol=1e-12, rtol=1e-12)
    np.testing.assert_allclose(x_r, upd.x, atol=1e-12, rtol=1e-12)
    np.testing.assert_allclose(P_r, upd.P, atol=1e-12, rtol=1e-12)


@pytest.mark.parametrize("seed", range(5))
def test_equivalent_update_forms(seed):
    model, x, P, u, y = _one_step(seed)
    pred = kc.predict(model, x, P, u)
    short = kc.update(model, pred.x, pred.P, y, form="textbook")
    for form in ("joseph", "square_root"):
        other = kc.update(model, pred.x, pred.P, y, form=form)
        for field in ("x", "P", "K", "S"):
            np.testing.assert_allclose(getattr(other, field), getattr(short, field), atol=1e-12, rtol=1e-10,
                                       err_msg=f"{form} : {field}")
    C, R = model.C, model.R
    # gain alternatif des tableaux (000) : K = P_{k|k} Cᵀ R⁻¹
    np.testing.assert_allclose(short.K, short.P @ C.T @ np.linalg.inv(R), atol=1e-10, rtol=1e-9)
    # forme information : P_{k|k}⁻¹ = P_{k|k-1}⁻¹ + Cᵀ R⁻¹ C
    info = np.linalg.inv(pred.P) + C.T @ np.linalg.inv(R) @ C
    np.testing.assert_allclose(np.linalg.inv(short.P), info, atol=1e-9, rtol=1e-9)
    # innovation et sa covariance
    np.testing.assert_allclose(short.innovation, y - C @ pred.x, atol=1e-14)
    np.testing.assert_allclose(short.S, C @ pred.P @ C.T + R, atol=1e-12, rtol=1e-12)


def test_optimal_gain_minimises_trace():
    """Le gain de Kalman minimise tr P(K) = tr[(I−KC)P⁻(I−KC)ᵀ + KRKᵀ] (optimiseur indépendant)."""
    model, x, P, u, y = _one_step(3)
    pred = kc.predict(model, x, P, u)
    upd = kc.update(model, pred.x, pred.P, y)
    n, m = model.n_state, model.n_obs
    I = np.eye(n)

    def trace_P(k_flat):
        K = k_flat.reshape(n, m)
        return np.trace((I - K @ model.C) @ pred.P @ (I - K @ model.C).T + K @ model.R @ K.T)

    best = scipy.optimize.minimize(trace_P, np.zeros(n * m), method="BFGS", options={"gtol": 1e-12})
    np.testing.assert_allclose(best.x.reshape(n, m), upd.K, atol=1e-6)


def test_step_functions_compose_to_runner():
    rng = np.random.default_rng(5)
    model = random_model(rng, 3, 2, 1)
    u = rng.standard_normal((20, 1))
    sim = kc.simulate(model, np.ones(3), 20, u=u, rng=rng)
    res = kc.kalman_filter(model, sim.y, np.zeros(3), np.eye(3), u=u)
    x, P = np.zeros(3), np.eye(3)
    for k in range(20):
        pred = kc.predict(model, x, P, u[k])
        upd = kc.update(model, pred.x, pred.P, sim.y[k])
        x, P = upd.x, upd.P
        np.testing.assert_allclose(res.x[k], x, atol=1e-13)
        np.testing.assert_allclose(res.K[k], upd.K, atol=1e-13)
        np.testing.assert_allclose(res.S[k], upd.S, atol=1e-13)
        np.testing.assert_allclose(res.innovation[k], upd.innovation, atol=1e-13)


def test_square_root_covariances_formed_at_the_end_equal_the_textbook_ones():
    """La forme racine carrée range les racines de P, P⁻ et S et ne forme les covariances qu'à la fin (un
    produit en lot) : mêmes valeurs que la forme du cours, exactement symétriques, aux pas sans mesure
    (deux de suite : racine rectangulaire), partiels, rejetés par la porte ou à mémoire évanescente ; S
    NaN aux mêmes endroits."""
    rng = np.random.default_rng(8)
    model = random_model(rng, 3, 2, 0)
    y = kc.simulate(model, np.ones(3), 60, rng=rng).y.copy()
    y[[3, 4, 30]] = np.nan  # pas sans mesure
    y[[10, 41], 0] = np.nan  # pas partiels
    y[[20, 50], 1] += 50.0  # aberrations, que la porte rejette
    for options in ({}, {"gate": 0.99}, {"gate": 0.99, "fading": 1.05}):
        ours = kc.kalman_filter(model, y, np.zeros(3), np.eye(3), **options)
        ref = kc.kalman_filter(model, y, np.zeros(3), np.eye(3), form="textbook", **options)
        np.testing.assert_array_equal(ours.n_iter, ref.n_iter)
        assert ours.rejected[[20, 50]].all() == bool(options)
        for name in ("P", "P_pred", "S"):
            ours_cov, ref_cov = getattr(ours, name), getattr(ref, name)
            np.testing.assert_array_equal(np.isnan(ours_cov), np.isnan(ref_cov))
            np.testing.assert_allclose(ours_cov, ref_cov, **TOL)
            np.testing.assert_array_equal(ours_cov, np.swapaxes(ours_cov, 1, 2))


# --------------------------------------------------------------------------- invariants


@settings(max_examples=60, deadline=None)
@given(
    n=st.integers(1, 5),
    m=st.integers(1, 4),
    seed=st.integers(0, 2**32 - 1),
    scale=st.floats(1e-3, 1e3),
    form=st.sampled_from(kc.filters.kalman.FORMS),
)
def test_covariances_stay_symmetric_psd_and_shrink(n, m, seed, scale, form):
    rng = np.random.default_rng(seed)
    model = random_model(rng, n, m, 0)
    y = scale * rng.standard_normal((40, m))
    res = kc.kalman_filter(model, y, np.zeros(n), scale * np.eye(n), form=form)
    for P, Pp in zip(res.P, res.P_pred):
        np.testing.assert_array_equal(P, P.T)
        np.testing.assert_array_equal(Pp, Pp.T)
        norm = max(1.0, np.abs(Pp).max())
        assert scipy.linalg.eigvalsh(P)[0] >= -1e-12 * norm
        # P_{k|k} ⪯ P_{k|k-1} : la correction n'augmente jamais l'incertitude
        assert scipy.linalg.eigvalsh(Pp - P)[0] >= -1e-10 * norm


def test_monte_carlo_nees_in_chi2_band():
    """Filtre cohérent : la NEES moyenne sur 200 essais tombe dans la bande χ² à 95 %."""
    rng = np.random.default_rng(2026)
    model = random_model(rng, 2, 1, 0)
    runs, T, n = 200, 30, 2
    P0 = np.eye(n)
    L0 = np.linalg.cholesky(P0)
    nees = []
    for _ in range(runs):
        x0 = L0 @ rng.standard_normal(n)  # x0 ~ N(0, P0), estimation initiale 0
        sim = kc.simulate(model, x0, T, rng=rng)
        res = kc.kalman_filter(model, sim.y, np.zeros(n), P0)
        e = sim.x[-1] - res.x[-1]
        nees.append(e @ np.linalg.solve(res.P[-1], e))
    lo, hi = scipy.stats.chi2.ppf([0.025, 0.975], runs * n) / runs
    assert lo <= np.mean(nees) <= hi


# --------------------------------------------------------------------------- résultat


def test_result_is_immutable_and_time_first():
    model = kc.scenarios.constant_voltage_model()
    res = kc.kalman_filter(model, [0.1, 0.2, 0.3], 0.0, 1.0)
    assert res.x.shape == (3, 1) and res.P.shape == (3, 1, 1) and res.K.shape == (3, 1, 1)
    assert res.innovation.shape == (3, 1) and res.S.shape == (3, 1, 1) and res.n_steps == 3
    with pytest.raises(ValueError):
        res.x[0, 0] = 1.0
    with pytest.raises(AttributeError):
        res.x = np.zeros((3, 1))
    with pytest.raises(ValueError):
        model.A[0, 0] = 2.0
    np.testing.assert_allclose(res.std()[:, 0], np.sqrt(res.P[:, 0, 0]))
