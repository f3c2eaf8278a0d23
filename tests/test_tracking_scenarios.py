"""Le filtre à Q adaptative (il retrouve l'échelle vraie de Q et un NEES cohérent) et les expériences des
deux chapitres de pistage (hélicoptère SAMU 31, cible qui manœuvre) : les nombres que les
chapitres citent, vérifiés contre des calculs indépendants ou des bornes qui peuvent échouer."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.stats

import kalman_course as kc
from kalman_course.scenarios import helicopter as heli
from kalman_course.scenarios import manoeuvre as man


# --------------------------------------------------------------------------- Q adaptative


def _mismatched_q(factor, seed, T=2000):
    """Vitesse presque constante sur un axe (q = 1 m²/s³, R = 1 m², pas de 1 s) : le filtre a la Q du modèle,
    les données une Q ``factor`` fois plus grande."""
    A, Q = kc.constant_velocity(1.0, 1.0, dim=1)
    model = kc.LinearGaussianModel(A, [[1.0, 0.0]], Q, [[1.0]])
    true = kc.LinearGaussianModel(A, [[1.0, 0.0]], factor * Q, [[1.0]])
    sim = kc.simulate(true, [0.0, 1.0], T, rng=seed)
    return model, true, sim


@pytest.mark.parametrize("factor", [25.0, 100.0])
def test_adaptive_q_finds_the_true_scale_and_stays_consistent(factor):
    """Q vraie 25 (ou 100) fois celle du modèle, 5 séries de 2 000 pas (les 100 premiers écartés) : l'échelle
    trouvée est la vraie à 20 % près (médiane et moyenne des pas), le NEES moyen reste sous 3,5 (2 attendu ;
    le filtre de la vraie Q : 2,0 ; le filtre du modèle : 23), et l'échelle ne bascule presque jamais au
    repos. Mesuré : NEES 2,9 pour 25, 2,3 pour 100 (avant le test sous S nominale et l'hystérésis : 8,9, et
    l'échelle au repos 40 % du temps)."""
    nees, scales, at_rest, oracle, nominal = [], [], [], [], []
    for seed in range(5):
        model, true, sim = _mismatched_q(factor, seed)
        res = kc.adaptive_kalman_filter(model, sim.y, [0.0, 1.0], np.eye(2))
        nees.append(kc.nees(sim.x, res)[100:].mean())
        scales.append(res.q_scale[100:])
        at_rest.append(np.mean(res.q_scale[100:] == 1.0))
        oracle.append(kc.nees(sim.x, kc.kalman_filter(true, sim.y, [0.0, 1.0], np.eye(2)))[100:].mean())
        nominal.append(kc.nees(sim.x, kc.kalman_filter(model, sim.y, [0.0, 1.0], np.eye(2)))[100:].mean())
    scales = np.concatenate(scales)
    assert np.mean(nees) <= 3.5, nees
    assert 0.8 * factor <= np.median(scales) <= 1.2 * factor and 0.8 * factor <= np.mean(scales) <= 1.2 * factor
    assert np.mean(at_rest) < 0.05
    assert abs(np.mean(oracle) - 2.0) < 0.15 and np.mean(nominal) > 10.0  # le scénario est bien mal réglé


def test_adaptive_q_stays_at_rest_on_data_that_fit_the_model():
    """Données conformes au modèle : l'échelle reste à s_min presque tout le temps (le test du χ² à 0,99 sur
    une fenêtre de 10 pas ne s'enclenche qu'à tort), et le filtre est alors celui du modèle (NEES ≈ 2)."""
    nees, at_rest = [], []
    for seed in range(5):
        model, _, sim = _mismatched_q(1.0, seed)
        res = kc.adaptive_kalman_filter(model, sim.y, [0.0, 1.0], np.eye(2))
        nees.append(kc.nees(sim.x, res)[100:].mean())
        at_rest.append(np.mean(res.q_scale[100:] == 1.0))
    assert np.mean(at_rest) > 0.9, at_rest
    assert abs(np.mean(nees) - 2.0) < 0.15, nees


def test_adaptive_q_without_test_and_a_long_memory_is_covariance_matching():
    """Sans test (``detect=None``) et avec une mémoire longue devant la série, l'échelle finale est le rapport
    de covariance matching Σ(νᵀν − tr S₀)/Σ tr(CQCᵀ) de toute la série ; sur une série où la vraie échelle
    est 9, il la retrouve à 15 % près."""
    model, _, sim = _mismatched_q(9.0, 3, T=3000)
    res = kc.adaptive_kalman_filter(model, sim.y, [0.0, 1.0], np.eye(2), window=100_000, detect=None)
    assert 0.85 * 9.0 <= res.q_scale[-1] <= 1.15 * 9.0, res.q_scale[-1]


def test_adaptive_filter_inflates_q_in_turns_only():
    """Sans test, le rapport d'ajustement est si bruité (Q ≪ R) qu'il gonfle Q en ligne droite aussi ; avec
    le test du χ² sur la fenêtre, Q ne grossit que dans les virages."""
    t = man.DT * np.arange(1, man.N_STEPS + 1)
    straight, turn = (t > 15) & (t < 38), (t > 45) & (t < 60)
    for seed in range(5):
        truth, y = man.simulate_target(seed)
        raw = kc.adaptive_kalman_filter(man.cv_model(man.Q_QUIET), y, man.X0, man.P0, window=5, detect=None)
        tested = kc.adaptive_kalman_filter(man.cv_model(man.Q_QUIET), y, man.X0, man.P0, window=5)
        assert raw.q_scale[straight].max() > 100.0
        assert np.all(tested.q_scale[straight] == 1.0)
        assert tested.q_scale[turn].mean() > 100.0


@pytest.mark.parametrize("kwargs, message", [(dict(window=0), "window"), (dict(min_scale=0.0), "min_scale")])
def test_adaptive_options_are_checked(kwargs, message):
    with pytest.raises(kc.KalmanInputError, match=message):
        kc.adaptive_kalman_filter(man.cv_model(1.0), np.zeros((3, 2)), man.X0, man.P0, **kwargs)


# --------------------------------------------------------------------------- hélicoptère


def test_fitted_noise_is_a_likelihood_maximum():
    """Le maximum trouvé par L-BFGS-B : aucune perturbation de ±2 % d'un paramètre ne fait mieux (vérifié
    par des filtrages indépendants de l'optimiseur)."""
    for sensors in heli.SENSORS:
        fit = heli.helicopter_fit(sensors)
        track = heli.helicopter_track(sensors)
        best = fit.log_likelihood
        p = np.array(fit.params)
        for signs in np.vstack([np.eye(p.size), -np.eye(p.size)]):
            moved = p * (1.0 + 0.02 * signs)
            ll = kc.log_likelihood(heli.helicopter_model(track, *moved), track.y, track.x0, track.P0)
            assert ll <= best + 1e-6, (sensors, moved, ll, best)


def test_helicopter_track_merges_the_two_sensors_on_one_time_axis():
    pos, both = heli.helicopter_track("position"), heli.helicopter_track("both")
    f = kc.datasets.samu31()
    assert pos.y.shape == (278, 2) and both.y.shape[1] == 4
    assert both.position_rows.sum() == 278 and both.velocity_rows.sum() == f.velocity_t.size
    assert np.all(np.diff(both.t) > 0) and np.all(both.dt > 0)
    assert np.allclose(both.y[both.position_rows, :2], np.c_[f.east, f.north])
    # l'a priori, 1 s avant la première position, la redonne par sa vitesse
    assert np.allclose(both.x0[:2] + heli.PRIOR_LEAD * both.x0[2:], [f.east[0], f.north[0]])


def test_velocity_reports_improve_the_position_prediction():
    rms_pos = heli.prediction_rms(heli.helicopter_filter("position"), heli.helicopter_track("position"))
    rms_both = heli.prediction_rms(heli.helicopter_filter("both"), heli.helicopter_track("both"))
    assert rms_both < 0.85 * rms_pos, (rms_both, rms_pos)


def test_prediction_rms_is_the_rms_of_the_position_innovations():
    """Sur les positions seules, l'erreur de prédiction est exactement l'innovation du filtre."""
    res = heli.helicopter_filter("position")
    assert heli.prediction_rms(res, heli.helicopter_track("position")) == pytest.approx(
        np.sqrt(np.mean(np.sum(res.innovation**2, axis=1))), rel=1e-12)


def test_gate_study_numbers():
    g = heli.gate_study()
    # sans porte, la part des NIS au-delà du seuil χ²₂(0,99) est compatible avec 1 % (binomiale, 99,9 %)
    lo, hi = scipy.stats.binom.interval(0.999, 278, 0.01)
    assert lo <= g.exceed_99 * 278 <= hi
    assert g.outliers_rejected == len(heli.OUTLIER_ROWS) and g.other_rejected <= 2
    assert g.deviation_gated < 0.25 * g.deviation_plain
    assert g.lost_at_99 is not None and g.lost_at_quiet is not None and g.lost_at_quiet < g.lost_at_99
    assert g.rejected_999 <= 3


def test_gated_run_with_outliers_equals_the_run_without_the_rejected_rows():
    track = heli.helicopter_track("position")
    gated = heli.helicopter_filter("position", gate=0.999, outliers=True)
    y = heli.with_outliers(track)
    y[gated.rejected] = np.nan
    q, sp = heli.fitted_parameters("position")
    plain = kc.kalman_filter(heli.helicopter_model(track, q, sp), y, track.x0, track.P0)
    assert np.allclose(gated.x, plain.x, rtol=1e-12, atol=1e-9)


# --------------------------------------------------------------------------- cible qui manœuvre


def test_simulated_target_flies_the_announced_turns():
    truth, y = man.simulate_target(0)
    speed = np.hypot(truth[:, 2], truth[:, 3])
    assert np.allclose(speed, man.SPEED, rtol=1e-12)
    heading = np.unwrap(np.arctan2(truth[:, 3], truth[:, 2]))
    total = sum(rate * (end - start) for start, end, rate in man.TURNS)
    assert heading[-1] - heading[0] == pytest.approx(total, abs=1e-9)
    assert np.std(y - truth[:, :2]) == pytest.approx(man.POSITION_STD, rel=0.1)


def test_example_trajectory_is_the_first_of_the_study_and_its_filters():
    """La trajectoire des curseurs (calculée seule) est la première de l'étude de Monte-Carlo, et le filtre
    calme de l'étude est celui qu'on relance dessus."""
    st, ex = man.manoeuvre_study(), man.manoeuvre_example()
    np.testing.assert_array_equal(ex.truth, st.truth)
    np.testing.assert_array_equal(ex.y, st.y)
    np.testing.assert_array_equal(ex.t, st.t)
    np.testing.assert_array_equal(ex.turning, st.turning)
    assert ex.turning.any() and not ex.turning.all()
    again = kc.kalman_filter(man.cv_model(man.Q_QUIET), ex.y, man.X0, man.P0)
    np.testing.assert_array_equal(again.x, st.example["calme"].x)


def test_manoeuvre_study_ranks_the_filters():
    st = man.manoeuvre_study()
    i = st.index
    assert st.rmse_turn[i("calme")] > 5 * st.rmse_turn[i("agité")]          # le filtre calme décroche
    assert st.rmse_straight[i("IMM")] < st.rmse_straight[i("agité")]        # l'IMM lisse mieux en ligne droite
    assert st.rmse_turn[i("IMM")] < 1.2 * st.rmse_turn[i("agité")]          # … et suit presque aussi bien en virage
    assert st.rmse_turn[i("oubli")] < 0.5 * st.rmse_turn[i("calme")]
    assert st.rmse_turn[i("adaptatif")] < 0.2 * st.rmse_turn[i("calme")]
    assert st.nees_mean[i("calme")] > 10 * st.band[1]                        # incohérent : il se croit précis
    lo, hi = scipy.stats.chi2.ppf([0.025, 0.975], 4 * man.N_RUNS) / man.N_RUNS
    assert st.band == pytest.approx((lo, hi))


def test_imm_probability_follows_the_helicopter_turns():
    h = man.helicopter_imm()
    assert h.correlation > 0.6
    assert h.prediction_rms < h.prediction_rms_single * 1.05


def test_helicopter_imm_equals_filterpy_with_per_step_matrices_and_sensors():
    """L'IMM de l'hélicoptère (deux régimes variables dans le temps, capteurs de position et de vitesse à des
    instants différents) contre IMMEstimator de filterpy : à chaque pas, chaque filtre reçoit F = A[k], Q =
    Q[k] avant predict(), puis H et R restreints au capteur présent avant update(z). Probabilités des régimes
    et estimation combinée à 10⁻⁹, et la probabilité du régime agité lue aux messages de vitesse."""
    from filterpy.kalman import IMMEstimator, KalmanFilter

    from kalman_course.scenarios.helicopter import fitted_parameters

    h = man.helicopter_imm()
    track = heli.helicopter_track("both")
    _, sp, sv = fitted_parameters("both")
    modes = [heli.helicopter_model(track, q, sp, sv) for q in (0.1, 30.0)]
    filters = []
    for _ in modes:
        f = KalmanFilter(dim_x=4, dim_z=4)
        f.x, f.P = np.asarray(track.x0).reshape(4, 1).copy(), np.array(track.P0)
        filters.append(f)
    imm = IMMEstimator(filters, np.array([0.95, 0.05]), man.imm_transition(0.05))
    mus, xs = [], []
    for k in range(len(track.y)):
        for f, model in zip(imm.filters, modes):
            f.F, f.Q = np.array(model.A[k]), np.array(model.Q[k])
        imm.predict()
        o = ~np.isnan(track.y[k])
        for f, model in zip(imm.filters, modes):
            f.H, f.R, f.dim_z = np.array(model.C)[o], np.array(model.R)[np.ix_(o, o)], int(o.sum())
        imm.update(track.y[k, o].reshape(-1, 1))
        mus.append(imm.mu.copy())
        xs.append(imm.x.ravel().copy())
    np.testing.assert_allclose(h.result.mu, mus, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(h.result.x, xs, rtol=1e-9, atol=1e-6)
    rows = np.searchsorted(np.asarray(track.t), np.round(h.rate_t, 3))
    np.testing.assert_allclose(h.mu_at_rate, np.array(mus)[rows, 1], rtol=1e-9, atol=1e-12)


# --------------------------------------------------------------------------- curseurs, contre filterpy


def test_gate_slider_grid_equals_filterpy_with_a_hand_written_gate():
    """Quelques points de la grille des curseurs de la porte : filterpy pas à pas (predict(F=A[k], Q=Q[k]),
    NIS calculé ici, update sauté au-delà du quantile de scipy.stats)."""
    from filterpy.kalman import KalmanFilter

    import kalman_course.interactive as ki
    from kalman_course.interactive import tracking

    grid = ki.slider_grid("capteurs-porte-curseurs")
    track = heli.helicopter_track("position")
    y = heli.with_outliers(track)
    sp = heli.fitted_parameters("position")[1]
    for index in [(1, 4), (2, 4), (2, 1), (4, 4)]:
        gate, q = grid.values_at(*index)
        A, Q = kc.constant_velocity(track.dt, q, dim=2)
        f = KalmanFilter(dim_x=4, dim_z=2)
        f.H, f.R = np.eye(4)[:2], sp**2 * np.eye(2)
        f.x, f.P = np.asarray(track.x0).reshape(4, 1), np.array(track.P0)
        xs, rejected = [], 0
        for k in range(len(y)):
            f.predict(F=A[k], Q=Q[k])
            nu = y[k].reshape(2, 1) - f.H @ f.x
            S = f.H @ f.P @ f.H.T + f.R
            if gate < 1.0 and (nu.T @ np.linalg.solve(S, nu)).item() > scipy.stats.chi2.ppf(gate, 2):
                rejected += 1
            else:
                f.update(y[k].reshape(2, 1))
            xs.append(f.x.ravel().copy())
        run = grid.run(*index)
        xs = np.array(xs)
        assert int(run["n_rejected"][0]) == rejected, index
        assert np.allclose(run["est_e"] * 1e3, xs[:, 0], rtol=1e-9, atol=1e-6), index
        assert np.allclose(run["est_n"] * 1e3, xs[:, 1], rtol=1e-9, atol=1e-6), index
    assert tracking.GATES[grid.default_index[0]] == 0.999


def test_imm_slider_grid_equals_filterpy_immestimator():
    from filterpy.kalman import IMMEstimator, KalmanFilter

    import kalman_course.interactive as ki

    grid = ki.slider_grid("manoeuvre-imm-curseurs")
    st = man.manoeuvre_study()
    for index in [grid.default_index, (0, 0, 3), (3, 2, 0)]:
        switch, q1, q2 = grid.values_at(*index)
        filters = []
        for q in (q1, q2):
            model = man.cv_model(q)
            f = KalmanFilter(dim_x=4, dim_z=2)
            f.F, f.H, f.Q, f.R = (np.array(a) for a in (model.A, model.C, model.Q, model.R))
            f.x, f.P = man.X0.reshape(4, 1).copy(), man.P0.copy()
            filters.append(f)
        imm = IMMEstimator(filters, np.array([1 - switch, switch]),
                           np.array([[1 - switch, switch], [switch, 1 - switch]]))
        mus = []
        for z in st.y:
            imm.predict()
            imm.update(z.reshape(2, 1))
            mus.append(imm.mu[1])
        assert np.allclose(grid.run(*index)["mu"], mus, rtol=1e-9, atol=1e-12), index


# --------------------------------------------------------------------------- relecture (issue 36)


def test_simulated_turns_have_the_centripetal_acceleration_the_chapter_cites():
    """« 0,12 rad/s … vω = 6 m/s² » (et 4 m/s² au second virage), et non 2,4 m/s² (le changement de cap en
    radians) : accélération mesurée par différences finies des vitesses de la trajectoire simulée."""
    truth, _ = man.simulate_target(0)
    t = man.DT * np.arange(1, man.N_STEPS + 1)
    acc = np.hypot(*np.diff(truth[:, 2:], axis=0).T) / man.DT  # |Δv| / Δt entre t[k] et t[k+1]
    for (start, end, _), cited in zip(man.TURNS, (6.0, 4.0)):
        inside = (t[1:] > start + 1) & (t[1:] <= end)
        # un pas de rotation ωΔt : |Δv| = 2 v sin(ωΔt / 2), soit vω à 0,1 % près
        assert np.allclose(acc[inside], cited, rtol=2e-3)


def test_imm_of_the_study_is_cautious_not_consistent():
    """Pas à pas, la NEES moyenne (50 tirages) de l'IMM est le plus souvent sous l'intervalle à 95 % d'un
    filtre cohérent (prudent), rarement dedans, et au-dessus seulement pendant les virages ; sa moyenne sur le
    vol tombe dans l'intervalle par compensation. Comptes refaits ici sur les NEES de l'étude."""
    st = man.manoeuvre_study()
    lo, hi = scipy.stats.chi2.ppf([0.025, 0.975], 4 * man.N_RUNS) / man.N_RUNS
    settled = st.t > 10.0
    e = st.nees[st.index("IMM"), settled]
    below, inside, above = st.band_shares("IMM")
    assert (below, inside, above) == pytest.approx((np.mean(e < lo), np.mean((e >= lo) & (e <= hi)),
                                                     np.mean(e > hi)))
    assert below > 0.5 and inside < 0.25 and 0 < above < 0.3
    assert st.turning[settled][e > hi].all()  # au-dessus : seulement dans un virage (ou juste après)
    assert lo < st.nees_mean[st.index("IMM")] < hi  # la moyenne sur le vol, elle, tombe dedans
    assert st.band_shares("agité")[0] > 0.5  # l'agité est prudent de même
    for name in ("oubli", "adaptatif"):  # trop sûrs d'eux dans les virages et juste après
        assert st.band_shares(name)[2] > 0.3


def test_gate_exercise_loses_the_track_for_good_below_p_095():
    """L'exercice des fenêtres de validation : à p = 0,9 et 0,95 la piste est perdue pour de bon (le filtre
    finit à plus de 10 km de l'hélicoptère) ; à p = 0,99 la fenêtre rejette plusieurs fois plus de positions
    que de NIS du filtre sans fenêtre au-delà du même seuil (environ 278 (1 − p)), puis retrouve la piste."""
    track = heli.helicopter_track("position")
    plain = heli.helicopter_filter("position")
    for p in (0.9, 0.95):
        res = heli.helicopter_filter("position", gate=p)
        assert heli.lost_track_time(res, track) < 70.0
        assert np.hypot(*(res.x[-1, :2] - track.y[-1, :2])) > 1e4
        assert res.rejected.sum() > 0.8 * len(track.t)
    res = heli.helicopter_filter("position", gate=0.99)
    over = int((kc.nis(plain) > scipy.stats.chi2.ppf(0.99, 2)).sum())
    assert abs(over - 278 * 0.01) <= 3  # sans fenêtre : conforme au modèle
    assert res.rejected.sum() > 3 * over
    assert np.hypot(*(res.x[-1, :2] - track.y[-1, :2])) < 10.0  # piste retrouvée


def test_fading_memory_divides_the_weight_of_a_measurement_by_alpha_squared_per_step():
    """« Le poids d'une mesure vieille de dix pas est divisé par α²⁰ » : sur un modèle constant sans bruit
    d'état (A = C = 1, Q = 0), le filtre à mémoire évanescente rend la moyenne des mesures pondérées par
    α^{−2(k−j)} et de l'a priori (poids α^{−2k} / P₀), forme close écrite ici."""
    alpha, R, P0, x0 = 1.2, 4.0, 9.0, 1.5
    y = np.random.default_rng(5).normal(3.0, 2.0, 25)
    res = kc.kalman_filter(kc.LinearGaussianModel(1.0, 1.0, 0.0, R), y[:, None], [x0], [[P0]], fading=alpha)
    for k in range(1, len(y) + 1):
        w = alpha ** (-2.0 * (k - np.arange(1, k + 1))) / R  # mesure j : poids (1/R) α^{−2(k−j)}
        w0 = alpha ** (-2.0 * k) / P0
        assert res.x[k - 1, 0] == pytest.approx((w0 * x0 + w @ y[:k]) / (w0 + w.sum()), rel=1e-12)
        assert res.P[k - 1, 0, 0] == pytest.approx(1.0 / (w0 + w.sum()), rel=1e-12)
    # dix pas : le poids relatif de la mesure j = k − 10 est divisé par α²⁰ (≈ 38 pour α = 1,2)
    assert (alpha ** -20) == pytest.approx(1 / 38.34, rel=1e-3)
