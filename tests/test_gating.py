"""Options du moteur pour le pistage, sur le filtre de Kalman : la porte (``gate=p``, ``.rejected``) et la
mémoire évanescente (``fading=α``, contre ``KalmanFilter.alpha`` de filterpy). Les mêmes options sur chaque
membre du filtre gaussien et sur l'IMM : tests/test_family.py, tests/test_imm.py."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.stats
from filterpy.kalman import KalmanFilter

import kalman_course as kc
from kalman_course.filters.gating import gate_threshold
from kalman_course.scenarios._motion import simulate_turning


def cv_model(dt=1.0, q=0.5, sigma=3.0):
    A, Q = kc.constant_velocity(dt, q, dim=2)
    C = np.eye(4)[:2]
    return kc.LinearGaussianModel(A, C, Q, sigma**2 * np.eye(2))


X0 = np.array([0.0, 0.0, 12.0, -4.0])
P0 = np.diag([9.0, 9.0, 1.0, 1.0])


@pytest.mark.parametrize("p", [0.5, 0.9, 0.99, 0.999])
@pytest.mark.parametrize("m", [1, 2, 4])
def test_gate_threshold_is_the_chi2_quantile(p, m):
    assert gate_threshold(p, m) == pytest.approx(scipy.stats.chi2.ppf(p, m), rel=1e-12)


def test_gated_run_equals_the_run_with_rejected_rows_missing():
    model = cv_model()
    sim = kc.simulate(model, X0, 300, rng=1)
    y = np.array(sim.y)
    y[[40, 120, 121, 250]] += np.array([[80.0, -60.0], [0.0, 150.0], [-90.0, 0.0], [60.0, 60.0]])
    gated = kc.kalman_filter(model, y, X0, P0, gate=0.99)
    assert gated.rejected.shape == (300,) and gated.rejected.dtype == bool
    assert gated.rejected[[40, 120, 121, 250]].all()  # les aberrations grossières, toutes rejetées
    holes = y.copy()
    holes[gated.rejected] = np.nan
    plain = kc.kalman_filter(model, holes, X0, P0)
    assert np.allclose(gated.x, plain.x, rtol=1e-12, atol=1e-12)
    assert np.allclose(gated.P, plain.P, rtol=1e-12, atol=1e-12)
    # un pas rejeté : prédiction seule, gain nul ; son innovation et son NIS restent lisibles
    k = 120
    assert np.array_equal(gated.x[k], gated.x_pred[k]) and not gated.K[k].any()
    assert kc.nis(gated)[k] > gate_threshold(0.99, 2)
    assert not kc.kalman_filter(model, y, X0, P0).rejected.any()  # sans porte : rien n'est rejeté


@pytest.mark.parametrize("p", [0.99, 0.999])
def test_on_clean_data_about_one_minus_p_of_the_steps_are_rejected(p):
    """Sans porte, chaque NIS du filtre bien réglé suit χ²₂ : la part des pas au-delà du seuil suit une loi
    binomiale B(T, 1 − p) (intervalle à 99,9 %). Avec la porte, les pas rejetés rendent le filtre un peu
    trop sûr de lui (il ignore justement les grandes innovations) : la part rejetée est de l'ordre de
    1 − p, un peu au-dessus (mesuré sur 20 séries : 1,4 % pour p = 0,99, 0,12 % pour p = 0,999)."""
    model = cv_model()
    T = 4000
    sim = kc.simulate(model, X0, T, rng=2)
    plain = kc.kalman_filter(model, sim.y, X0, P0)
    lo, hi = scipy.stats.binom.interval(0.999, T, 1 - p)
    assert lo <= (kc.nis(plain) > gate_threshold(p, 2)).sum() <= hi
    gated = kc.kalman_filter(model, sim.y, X0, P0, gate=p)
    assert lo <= gated.rejected.sum() <= 2.5 * hi, (gated.rejected.sum(), lo, hi)


def test_a_gate_too_tight_loses_the_track_on_clean_data():
    """p = 0,9 : 10 % des bonnes mesures écartées, les plus informatives ; l'erreur dépasse ce que dit P,
    les rejets s'enchaînent et la piste finit par se perdre, sur des données pourtant conformes au modèle."""
    model = cv_model()
    sim = kc.simulate(model, X0, 2000, rng=2)
    res = kc.kalman_filter(model, sim.y, X0, P0, gate=0.9)
    run = np.convolve(res.rejected, np.ones(20), "valid")
    assert run.max() == 20 and res.rejected.mean() > 0.3


def test_partial_rows_use_the_quantile_of_the_observed_components():
    model = cv_model(sigma=1.0)
    y = np.array([[0.0, np.nan], [np.nan, np.nan], [25.0, -8.0]])
    res = kc.kalman_filter(model, y, [0.0, 0.0, 0.0, 0.0], np.eye(4), gate=0.99)
    nis = kc.nis(res)
    assert res.observed[0].sum() == 1
    assert res.rejected[0] == (nis[0] > gate_threshold(0.99, 1))
    assert not res.rejected[1]  # pas de mesure : pas de rejet
    assert res.rejected[2] == (nis[2] > gate_threshold(0.99, 2))


def test_a_track_lost_behind_its_own_gate():
    """La cible tourne, le filtre réglé pour la ligne droite prend du retard : ses mesures sortent de la
    porte, il ne prédit plus que sa ligne droite et ne revient jamais (le mode d'échec du chapitre)."""
    dt = 1.0
    model = cv_model(dt, q=0.01, sigma=2.0)
    T = 80
    rate = np.where(np.arange(T) < 20, 0.0, 0.12)  # virage serré à partir de 20 s
    truth, y = simulate_turning(rate, [0.0, 0.0, 30.0, 0.0], dt, 2.0, np.random.default_rng(3))
    res = kc.kalman_filter(model, y, [0.0, 0.0, 30.0, 0.0], np.eye(4), gate=0.99)
    assert not res.rejected[:20].any()
    first = int(np.argmax(res.rejected))
    assert res.rejected[first:].all(), "une fois perdue, la piste ne revient pas"
    err = np.linalg.norm(res.x[-1, :2] - truth[-1, :2])
    assert err > 500.0


# --------------------------------------------------------------------------- mémoire évanescente


@pytest.mark.parametrize("alpha", [1.0, 1.02, 1.3])
def test_fading_memory_equals_filterpy_alpha(alpha):
    model = cv_model()
    sim = kc.simulate(model, X0, 60, rng=4)
    res = kc.kalman_filter(model, sim.y, X0, P0, fading=alpha)
    f = KalmanFilter(dim_x=4, dim_z=2)
    f.F, f.H, f.Q, f.R = np.array(model.A), np.array(model.C), np.array(model.Q), np.array(model.R)
    f.x, f.P = X0.reshape(4, 1).copy(), P0.copy()
    f.alpha = alpha
    xs, Ps, Pps = [], [], []
    for z in sim.y:
        f.predict()
        Pps.append(f.P.copy())
        f.update(z.reshape(2, 1))
        xs.append(f.x.ravel().copy())
        Ps.append(f.P.copy())
    assert np.allclose(res.P_pred, Pps, rtol=1e-9, atol=1e-9)
    assert np.allclose(res.x, xs, rtol=1e-9, atol=1e-9)
    assert np.allclose(res.P, Ps, rtol=1e-9, atol=1e-9)


def test_fading_one_is_the_plain_filter_and_the_step_agrees():
    model = cv_model()
    sim = kc.simulate(model, X0, 20, rng=5)
    a = kc.kalman_filter(model, sim.y, X0, P0)
    b = kc.kalman_filter(model, sim.y, X0, P0, fading=1.0)
    assert np.array_equal(a.x, b.x) and np.array_equal(a.P, b.P)
    step = kc.predict(model, X0, P0, fading=1.1)
    assert np.allclose(step.P, 1.21 * model.A @ P0 @ model.A.T + model.Q, rtol=1e-14)


def test_fading_memory_follows_a_manoeuvre_faster():
    """Même retard qu'au test de la porte, sans porte : l'oubli réduit l'erreur pendant le virage."""
    model = cv_model(1.0, q=0.01, sigma=2.0)
    T = 60
    rate = np.where(np.arange(T) < 20, 0.0, 0.08)
    truth, y = simulate_turning(rate, [0.0, 0.0, 30.0, 0.0], 1.0, 2.0, np.random.default_rng(6))
    err = {a: np.sqrt(np.mean(np.sum((kc.kalman_filter(model, y, [0, 0, 30, 0], np.eye(4), fading=a).x[20:, :2]
                                      - truth[20:, :2]) ** 2, axis=1))) for a in (1.0, 1.1)}
    assert err[1.1] < 0.6 * err[1.0], err  # mesuré : 16,6 m contre 34,9 m


@pytest.mark.parametrize("option, value, message", [
    ("gate", 1.0, "probabilité"), ("gate", 0.0, "probabilité"), ("gate", "0.9", "probabilité"),
    ("gate", True, "probabilité"), ("fading", 0.9, "α ≥ 1"), ("fading", np.inf, "α ≥ 1"),
    ("fading", [1.1], "α ≥ 1"),
])
def test_bad_options_are_refused_in_french(option, value, message):
    model = cv_model()
    with pytest.raises(kc.KalmanInputError, match=message):
        kc.kalman_filter(model, np.zeros((3, 2)), X0, P0, **{option: value})
