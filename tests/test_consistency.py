"""Cohérence statistique (``kalman_course.consistency``) : NIS, NEES, test du χ², blancheur, centrage.

Oracles indépendants : calcul direct avec ``np.linalg.inv`` ; la distance de Mahalanobis de filterpy
(:math:`\\sqrt{\\text{NIS}}` après ``update``) ; quantiles de ``scipy.stats.chi2`` calculés ici ; la bande
publiée de ALGORITHMS.md §8 ; Ljung–Box écrit autrement (``np.correlate``) ; Hotelling avec l'inverse
explicite ; ``scipy.stats.ttest_1samp``. Tests statistiques à graine fixe : un filtre juste est
accepté, un filtre mal réglé ou un modèle incomplet est rejeté, et le taux de fausses alarmes d'un test
à 95 % est bien d'environ 5 %.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import scipy.stats
from filterpy.kalman import KalmanFilter

import kalman_course as kc
from kalman_course.scenarios import engine
from conftest import random_model

RNG_SEED = 20260


def _consistent_run(model, T, seed):
    """Une trajectoire avec x0 ~ N(0, I) et le filtre initialisé en (0, I) : hypothèses exactes."""
    rng = np.random.default_rng(seed)
    n = model.n_state
    x0 = rng.standard_normal(n)
    sim = kc.simulate(model, x0, T, rng=rng)
    return sim, kc.kalman_filter(model, sim.y, np.zeros(n), np.eye(n))


def _engine_results(T=500):
    """Le banc d'essai du chapitre (scénario du moteur), clés courtes."""
    sim, results = engine.consistency_runs(T)
    return sim, dict(zip(["juste", "psi_petit", "phi_grand", "incomplet"], results.values()))


# --------------------------------------------------------------------------- NIS et NEES : formules


def test_nis_equals_direct_inverse_computation():
    rng = np.random.default_rng(RNG_SEED)
    model = random_model(rng, 3, 2, 0)
    _, res = _consistent_run(model, 40, 1)
    values = kc.nis(res)
    assert values.shape == (40,)
    for k in (0, 1, 17, 39):
        nu, S = res.innovation[k], res.S[k]
        direct = float(nu @ np.linalg.inv(S) @ nu)
        assert values[k] == pytest.approx(direct, rel=1e-10)
    # innovations blanchies : ‖e_k‖² = NIS et e_k = L⁻¹ν avec L L^T = S
    e = kc.whitened_innovations(res)
    np.testing.assert_allclose(np.sum(e**2, axis=1), values, rtol=1e-12)
    L = np.linalg.cholesky(res.S[5])
    np.testing.assert_allclose(L @ e[5], res.innovation[5], rtol=1e-10, atol=1e-12)


def test_nis_equals_filterpy_mahalanobis_squared():
    rng = np.random.default_rng(RNG_SEED + 1)
    model = random_model(rng, 2, 2, 1)
    T = 25
    u = rng.standard_normal((T, 1))
    sim = kc.simulate(model, np.zeros(2), T, u, rng=rng)
    res = kc.kalman_filter(model, sim.y, np.zeros(2), np.eye(2), u)
    f = KalmanFilter(dim_x=2, dim_z=2, dim_u=1)
    f.F, f.H, f.Q, f.R, f.B = (np.array(a) for a in (model.A, model.C, model.Q, model.R, model.B))
    f.x = np.zeros((2, 1))
    f.P = np.eye(2)
    reference = []
    for k in range(T):
        f.predict(u=u[k].reshape(1, 1))
        f.update(sim.y[k].reshape(2, 1))
        reference.append(f.mahalanobis**2)  # filterpy : √(yᵀ S⁻¹ y) après update
    np.testing.assert_allclose(kc.nis(res), reference, rtol=1e-8)


def test_nis_with_missing_components_uses_the_observed_block_and_nan_when_nothing_observed():
    rng = np.random.default_rng(RNG_SEED + 2)
    model = random_model(rng, 3, 3, 0)
    sim = kc.simulate(model, np.zeros(3), 12, rng=rng)
    y = np.array(sim.y)
    y[2, 1] = np.nan          # une composante manquante
    y[5, [0, 2]] = np.nan     # deux composantes manquantes
    y[8] = np.nan             # rien d'observé
    res = kc.kalman_filter(model, y, np.zeros(3), np.eye(3))
    values = kc.nis(res)
    for k, idx in ((2, [0, 2]), (5, [1])):
        nu = res.innovation[k, idx]
        S = res.S[k][np.ix_(idx, idx)]
        assert values[k] == pytest.approx(float(nu @ np.linalg.inv(S) @ nu), rel=1e-10)
    assert np.isnan(values[8])
    assert np.isfinite(np.delete(values, 8)).all()
    test = kc.nis_test(res)
    assert test.n_values == 11
    assert test.dof == 3 * 12 - 1 - 2 - 3  # composantes observées
    e = kc.whitened_innovations(res)
    assert np.isnan(e[2, 1]) and np.isfinite(e[2, [0, 2]]).all()


def test_nees_equals_direct_inverse_computation_posterior_and_prior():
    rng = np.random.default_rng(RNG_SEED + 3)
    model = random_model(rng, 3, 1, 0)
    sim, res = _consistent_run(model, 30, 2)
    post = kc.nees(sim.x, res)
    prior = kc.nees(sim.x, res, prior=True)
    for k in (0, 9, 29):
        e = sim.x[k] - res.x[k]
        assert post[k] == pytest.approx(float(e @ np.linalg.inv(res.P[k]) @ e), rel=1e-10)
        e = sim.x[k] - res.x_pred[k]
        assert prior[k] == pytest.approx(float(e @ np.linalg.inv(res.P_pred[k]) @ e), rel=1e-10)


def test_nees_accepts_a_1d_state_for_a_scalar_model():
    model = kc.scenarios.constant_voltage_model()
    sim = kc.simulate(model, np.array([0.2]), 20, rng=3)
    res = kc.kalman_filter(model, sim.y, 0.0, 1.0)
    direct = (sim.x[:, 0] - res.x[:, 0]) ** 2 / res.P[:, 0, 0]
    np.testing.assert_allclose(kc.nees(sim.x[:, 0], res), direct, rtol=1e-12)


# --------------------------------------------------------------------------- test du χ²


def test_chi2_band_equals_scipy_quantiles_and_the_published_band():
    for dof, n, level in ((2, 1, 0.95), (2, 100, 0.95), (3, 500, 0.99), (1, 7, 0.5)):
        lo, hi = kc.chi2_band(dof, n, level)
        expected = scipy.stats.chi2.ppf([(1 - level) / 2, (1 + level) / 2], dof * n) / n
        assert (lo, hi) == pytest.approx(tuple(expected), rel=1e-12)
    # ALGORITHMS.md §8 : moyenne de 200 NEES à 6 degrés de liberté, bande [5,53 ; 6,49]
    lo, hi = kc.chi2_band(6, 200)
    assert round(lo, 2) == 5.53 and round(hi, 2) == 6.49


def test_chi2_mean_test_statistic_band_and_two_sided_p_value():
    values = np.array([0.5, 1.7, 3.2, 0.1, 2.2, np.nan])
    test = kc.chi2_mean_test(values, 2, level=0.9, quantity="NEES")
    total = 0.5 + 1.7 + 3.2 + 0.1 + 2.2
    assert test.n_values == 5 and test.dof == 10
    assert test.statistic == pytest.approx(total / 5)
    assert test.expected == 2.0
    assert (test.lower, test.upper) == pytest.approx(tuple(scipy.stats.chi2.ppf([0.05, 0.95], 10) / 5))
    cdf = scipy.stats.chi2.cdf(total, 10)
    assert test.p_value == pytest.approx(2 * min(cdf, 1 - cdf))
    assert test.consistent == (test.lower <= test.statistic <= test.upper)
    # degrés de liberté par valeur
    dofs = np.array([1, 2, 3, 1, 2, 2])
    per_value = kc.chi2_mean_test(values, dofs)
    assert per_value.dof == 9
    with pytest.raises(dataclasses.FrozenInstanceError):
        test.consistent = False  # type: ignore[misc]


def test_french_str_of_the_test_results():
    sim, res = _engine_results(200)
    text = str(kc.nis_test(res["juste"]))
    assert "Test du χ² sur la NIS moyenne" in text and "→ cohérent" in text and "bande à 95 %" in text
    assert "rejetée" in str(kc.nis_test(res["psi_petit"]))
    assert "Ljung–Box" in str(kc.whiteness_test(res["incomplet"])) and "non blanches" in str(
        kc.whiteness_test(res["incomplet"]))
    assert "Hotelling" in str(kc.centring_test(res["incomplet"])) and "non centrées" in str(
        kc.centring_test(res["incomplet"]))


# --------------------------------------------------------------------------- cohérence : filtre juste, filtres faux


def test_nis_mean_of_a_long_correct_run_is_in_its_chi2_band():
    rng = np.random.default_rng(RNG_SEED + 4)
    base = random_model(rng, 3, 2, 0)
    A = 0.95 * base.A / max(abs(np.linalg.eigvals(base.A)))  # stable : 3000 pas sans divergence
    model = kc.LinearGaussianModel(A, base.C, base.Q, base.R)
    _, res = _consistent_run(model, 3000, 4)
    test = kc.nis_test(res)
    assert test.dof == 6000 and test.consistent, str(test)
    assert abs(test.statistic - 2.0) < 0.1


def test_engine_correct_filter_passes_and_mistuned_or_incomplete_filters_are_rejected():
    _, res = _engine_results()
    good = res["juste"]
    assert kc.nis_test(good).consistent
    assert kc.whiteness_test(good).white
    assert kc.centring_test(good).centred
    # Ψ dix fois trop petit : NIS trop grande ; Φ dix fois trop grand : NIS trop petite
    small_psi, big_phi = kc.nis_test(res["psi_petit"]), kc.nis_test(res["phi_grand"])
    assert not small_psi.consistent and small_psi.statistic > small_psi.upper
    assert not big_phi.consistent and big_phi.statistic < big_phi.lower
    # même rapport Φ/Ψ, donc même gain en régime permanent (P0 identique : le transitoire diffère) :
    # mêmes innovations, S dans un rapport 10
    np.testing.assert_allclose(res["psi_petit"].K[100:], res["phi_grand"].K[100:], rtol=1e-9)
    np.testing.assert_allclose(res["psi_petit"].innovation[100:], res["phi_grand"].innovation[100:], rtol=1e-6)
    np.testing.assert_allclose(kc.nis(res["psi_petit"])[100:], 10 * kc.nis(res["phi_grand"])[100:], rtol=1e-6)
    assert not np.allclose(res["psi_petit"].K[1], res["phi_grand"].K[1], rtol=1e-3)
    # gain trop fort : innovations corrélées négativement, non blanches, mais centrées
    white = kc.whiteness_test(res["psi_petit"])
    assert not white.white and white.autocorrelation[0, 0] < -white.band
    assert kc.centring_test(res["psi_petit"]).centred
    # modèle incomplet : rejeté par les trois tests
    bad = res["incomplet"]
    assert not kc.nis_test(bad).consistent
    assert not kc.whiteness_test(bad).white
    assert not kc.centring_test(bad).centred


def test_monte_carlo_nees_of_a_correct_filter_is_in_band_and_mistuned_filters_are_rejected():
    model = engine.engine_model()
    u = engine.engine_commands(50)
    kwargs = dict(x0_hat=np.zeros(2), P0=np.eye(2), rng=11, u=u)
    runs = kc.monte_carlo_consistency(model, 50, 200, **kwargs)
    assert runs.nees.shape == (200, 50) and runs.nis.shape == (200, 50) and runs.n_runs == 200
    final = runs.nees_test()
    assert final.dof == 400 and final.consistent, str(final)
    assert runs.nees_test(0).consistent  # initialisation cohérente : dès le premier pas
    # la NEES de la bibliothèque est celle d'un calcul direct sur un tirage refait à la main
    gen = np.random.default_rng(11)
    x0 = gen.standard_normal(2)  # x0 = x̂0 + L0 ξ avec L0 = I
    sim = kc.simulate(model, x0, 50, u, rng=gen)
    res = kc.kalman_filter(model, sim.y, np.zeros(2), np.eye(2), u)
    e = sim.x[-1] - res.x[-1]
    assert runs.nees[0, -1] == pytest.approx(float(e @ np.linalg.inv(res.P[-1]) @ e), rel=1e-10)
    optimistic = kc.monte_carlo_consistency(model, 50, 200, filter_model=engine.engine_model(
        Psi=engine.ENGINE_PSI / 10), **kwargs).nees_test()
    runs_big_phi = kc.monte_carlo_consistency(model, 50, 200, filter_model=engine.engine_model(
        Phi=10 * engine.ENGINE_PHI), **kwargs)
    pessimistic = runs_big_phi.nees_test()
    assert not optimistic.consistent and optimistic.statistic > optimistic.upper
    # Φ dix fois trop grand : P trop grande, NEES sous son espérance (1,84 ici : peu marqué à un instant,
    # dans la bande), mais la NIS des mêmes tirages au même instant est nettement rejetée
    assert pessimistic.statistic < 0.95 * pessimistic.expected
    nis_final = kc.chi2_mean_test(runs_big_phi.nis[:, -1], 2)
    assert not nis_final.consistent and nis_final.statistic < nis_final.lower


def test_false_alarm_rate_of_95_percent_tests_is_about_5_percent():
    """Sur 400 séries indépendantes vraiment N(0, 1) et blanches, chaque test rejette ≈ 5 % du temps
    (binomiale B(400 ; 0,05) : 20 ± 4,4 ; bornes à ± 3 écarts-types)."""
    rng = np.random.default_rng(RNG_SEED + 5)
    rejections = {"chi2": 0, "blancheur": 0, "centrage": 0}
    for _ in range(400):
        e = rng.standard_normal((300, 2))
        rejections["chi2"] += not kc.chi2_mean_test(np.sum(e**2, axis=1), 2).consistent
        rejections["blancheur"] += not kc.whiteness_test(e, 10).white
        rejections["centrage"] += not kc.centring_test(e).centred
    for name, count in rejections.items():
        assert 7 <= count <= 33, (name, count)


# --------------------------------------------------------------------------- blancheur et centrage : formules


def _ljung_box_textbook(x: np.ndarray, L: int) -> float:
    """Ljung–Box écrit autrement : autocovariances par np.correlate (mode « full »)."""
    T = x.size
    d = x - x.mean()
    full = np.correlate(d, d, mode="full")  # indices T-1+ℓ : Σ d_t d_{t+ℓ}
    rho = full[T:T + L] / full[T - 1]
    return float(T * (T + 2) * sum(rho[l - 1] ** 2 / (T - l) for l in range(1, L + 1)))


def test_autocorrelation_and_ljung_box_equal_an_independent_computation():
    rng = np.random.default_rng(RNG_SEED + 6)
    x = np.cumsum(rng.standard_normal(150)) * 0.1 + rng.standard_normal(150)  # série corrélée
    L = 12
    d = x - x.mean()
    rho = np.correlate(d, d, mode="full")[x.size:x.size + L] / np.dot(d, d)
    np.testing.assert_allclose(kc.autocorrelation(x, L), rho, rtol=1e-12)
    y = rng.standard_normal((150, 2))
    test = kc.whiteness_test(np.column_stack([x, y[:, 0]]), L)
    expected = [_ljung_box_textbook(x, L), _ljung_box_textbook(y[:, 0], L)]
    np.testing.assert_allclose(test.ljung_box, expected, rtol=1e-12)
    assert test.statistic == pytest.approx(sum(expected))
    assert test.dof == 2 * L
    assert test.p_value == pytest.approx(scipy.stats.chi2.sf(sum(expected), 2 * L))
    np.testing.assert_allclose(test.component_p_values, scipy.stats.chi2.sf(expected, L))
    assert test.band == pytest.approx(1.959963984540054 / np.sqrt(150))
    assert test.lags.tolist() == list(range(1, L + 1))
    assert kc.autocorrelation(np.column_stack([x, x]), L).shape == (2, L)
    with pytest.raises(ValueError):
        test.autocorrelation[0, 0] = 1.0  # tableaux en lecture seule


def test_whiteness_accepts_white_noise_and_rejects_a_correlated_series():
    rng = np.random.default_rng(RNG_SEED + 7)
    white = rng.standard_normal(1000)
    assert kc.whiteness_test(white).white
    ar = np.empty(1000)
    ar[0] = 0.0
    for t in range(1, 1000):  # AR(1) de coefficient 0,3
        ar[t] = 0.3 * ar[t - 1] + rng.standard_normal()
    test = kc.whiteness_test(ar)
    assert not test.white and test.p_value < 1e-6
    assert test.lags.size == 20  # défaut : min(20, T/5)


def test_centring_test_matches_student_and_a_direct_hotelling_computation():
    rng = np.random.default_rng(RNG_SEED + 8)
    x = rng.standard_normal(80) + 0.2
    test = kc.centring_test(x)
    ref = scipy.stats.ttest_1samp(x, 0.0)
    assert test.t_statistic[0] == pytest.approx(ref.statistic)
    assert test.p_value == pytest.approx(ref.pvalue, rel=1e-9)  # m = 1 : Hotelling = Student²
    assert test.hotelling == pytest.approx(ref.statistic**2)
    e = rng.standard_normal((60, 3)) @ np.array([[1.0, 0.3, 0.0], [0.0, 1.0, 0.5], [0.0, 0.0, 1.0]])
    e += np.array([0.1, -0.2, 0.3])
    test = kc.centring_test(e, level=0.9)
    N, m = e.shape
    mean = e.mean(axis=0)
    W = (e - mean).T @ (e - mean) / (N - 1)
    t2 = N * mean @ np.linalg.inv(W) @ mean
    assert test.hotelling == pytest.approx(t2, rel=1e-10)
    F = t2 * (N - m) / (m * (N - 1))
    assert test.f_statistic == pytest.approx(F, rel=1e-10)
    assert test.p_value == pytest.approx(scipy.stats.f.sf(F, m, N - m), rel=1e-9)
    assert test.dof == (3, 57)
    np.testing.assert_allclose(test.mean, mean)
    assert not kc.centring_test(rng.standard_normal((400, 2)) + 0.3).centred
    assert kc.centring_test(rng.standard_normal((400, 2))).centred


def test_consistency_table_lists_each_filter():
    _, res = _engine_results(200)
    table = kc.consistency_table({"juste": res["juste"], "incomplet": res["incomplet"]})
    assert table.n_rows == 2
    md = table.to_markdown()
    assert "NIS moyenne" in md and "| juste |" in md and "| incomplet |" in md
    assert table.headers[2] == "NIS cohérente" and table.columns[2] == ["oui", "non"]
    assert table.columns[4] == ["oui", "non"] and table.columns[6] == ["oui", "non"]


# --------------------------------------------------------------------------- entrées invalides


def _small_result():
    model = kc.scenarios.constant_voltage_model()
    sim = kc.simulate(model, np.array([0.1]), 30, rng=5)
    return sim, kc.kalman_filter(model, sim.y, 0.0, 1.0)


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda s, r: kc.nis(r.innovation), r"« result » doit être un FilterResult"),
        (lambda s, r: kc.whitened_innovations("résultat"), r"« result » doit être un FilterResult"),
        (lambda s, r: kc.nees(s.x[:-1], r), r"« x_true » doit être de forme \(30, 1\)"),
        (lambda s, r: kc.nees(np.full((30, 1), np.nan), r), r"« x_true » contient des valeurs non finies"),
        (lambda s, r: kc.nees(s.x, None), r"« result » doit être un FilterResult"),
        (lambda s, r: kc.nees(s.x, kc.kalman_filter_runs(kc.scenarios.constant_voltage_model(), s.y[None], [0.0], [[1.0]])),
         r"« result » doit être le résultat d'un seul tirage ; reçu un FilterRuns de 1 tirages"),
        (lambda s, r: kc.chi2_band(0), r"« dof » doit être un entier ≥ 1"),
        (lambda s, r: kc.chi2_band(2, 0), r"« n_values » doit être un entier ≥ 1"),
        (lambda s, r: kc.chi2_band(2, 10, 1.0), r"« level » doit être strictement entre 0 et 1"),
        (lambda s, r: kc.chi2_band(2, 10, 0.0), r"« level » doit être strictement entre 0 et 1"),
        (lambda s, r: kc.chi2_band(2, 10, True), r"« level » doit être un niveau de confiance réel"),
        (lambda s, r: kc.chi2_band(2, 10, "95 %"), r"« level » doit être un niveau de confiance réel"),
        (lambda s, r: kc.chi2_mean_test([1.0, -0.5], 1), r"« values » contient des valeurs négatives"),
        (lambda s, r: kc.chi2_mean_test([np.nan, np.nan], 1), r"« values » ne contient aucune valeur"),
        (lambda s, r: kc.chi2_mean_test([], 1), r"« values » ne contient aucune valeur"),
        (lambda s, r: kc.chi2_mean_test([1.0, np.inf], 1), r"« values » contient des valeurs infinies"),
        (lambda s, r: kc.chi2_mean_test([1.0, 2.0], [1, 2, 3]), r"« dof » doit être un entier ou un tableau"),
        (lambda s, r: kc.chi2_mean_test([1.0, 2.0], [1, 1.5]), r"« dof » doit ne contenir que des entiers"),
        (lambda s, r: kc.chi2_mean_test([1.0, 2.0], 2, level=95), r"« level » doit être strictement entre"),
        (lambda s, r: kc.whiteness_test(r, 16), r"« max_lag » = 16 est trop grand .* T = 30 .* T/2 = 15"),
        (lambda s, r: kc.whiteness_test(r, 0), r"« max_lag » doit être un entier ≥ 1"),
        (lambda s, r: kc.whiteness_test(r, 2.5), r"« max_lag » doit être un entier ≥ 1"),
        (lambda s, r: kc.whiteness_test(np.zeros((4, 3, 2))), r"« innovations » doit être une série"),
        (lambda s, r: kc.whiteness_test([0.1, np.nan, 0.3, 0.2]), r"« innovations » contient des valeurs non"),
        (lambda s, r: kc.whiteness_test(r, level=-0.1), r"« level » doit être strictement entre 0 et 1"),
        (lambda s, r: kc.autocorrelation(np.ones(20), 3), r"« series » est constante"),
        (lambda s, r: kc.autocorrelation(np.arange(10.0), 6), r"« max_lag » = 6 est trop grand"),
        (lambda s, r: kc.centring_test(np.ones((2, 2))), r"il en faut au moins 3"),
        (lambda s, r: kc.centring_test(np.ones((5, 2))), r"covariance empirique singulière"),
        (lambda s, r: kc.centring_test(r, level=2), r"« level » doit être strictement entre 0 et 1"),
        (lambda s, r: kc.consistency_table({}), r"« results » doit être un dictionnaire non vide"),
        (lambda s, r: kc.consistency_table({"a": s}), r"« results\['a'\] » doit être un FilterResult"),
    ],
)
def test_bad_input_raises_a_french_error_naming_the_argument(call, message):
    sim, res = _small_result()
    with pytest.raises(kc.KalmanInputError, match=message):
        call(sim, res)


def test_whiteness_refuses_missing_measurements_in_a_result():
    model = kc.scenarios.constant_voltage_model()
    y = kc.scenarios.constant_voltage_measurements(40)
    y[7] = np.nan
    res = kc.kalman_filter(model, y, 0.0, 1.0)
    with pytest.raises(kc.KalmanInputError, match=r"« innovations » a une mesure manquante au pas k = 7"):
        kc.whiteness_test(res, 5)
    assert kc.centring_test(res).n_values == 39  # le centrage écarte le pas incomplet


def test_non_positive_definite_s_is_named_with_its_step():
    _, res = _small_result()
    S = np.array(res.S)
    S[4] = -1.0
    broken = dataclasses.replace(res, S=S)
    with pytest.raises(kc.KalmanInputError, match=r"« result\.S » n'est pas définie positive .* k = 4"):
        kc.nis(broken)
    nu = np.array(res.innovation)
    nu[3] = np.nan
    with pytest.raises(kc.KalmanInputError, match=r"« result\.innovation » n'est pas finie au pas k = 3"):
        kc.nis(dataclasses.replace(res, innovation=nu))


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(n_runs=1), r"« n_runs » doit être un entier ≥ 2"),
        (dict(n_steps=0), r"« n_steps » doit être un entier ≥ 1"),
        (dict(P0=-np.eye(2)), r"« P0 » doit être définie positive"),
        (dict(x0_hat=np.zeros(3)), r"« x0_hat » doit être un vecteur de forme \(2,\)"),
        (dict(rng=None), r"« rng » doit être une graine entière"),
        (dict(filter_model=kc.scenarios.constant_voltage_model()), r"« filter_model » doit avoir les dimensions"),
        (dict(filter_model="modèle"), r"« filter_model » doit être un LinearGaussianModel"),
        (dict(true_model=np.eye(2)), r"« true_model » doit être un LinearGaussianModel"),
        (dict(u=np.ones((4, 1))), r"« u » doit avoir une commande par pas de temps"),
    ],
)
def test_monte_carlo_consistency_bad_input(kwargs, message):
    args = dict(true_model=engine.engine_model(), n_steps=5, n_runs=3, x0_hat=np.zeros(2), P0=np.eye(2), rng=0,
                u=engine.engine_commands(5))
    args.update(kwargs)
    with pytest.raises(kc.KalmanInputError, match=message):
        kc.monte_carlo_consistency(**args)


def test_nees_test_step_must_be_a_valid_index():
    runs = kc.monte_carlo_consistency(engine.engine_model(), 5, 3, x0_hat=np.zeros(2), P0=np.eye(2), rng=0,
                                      u=engine.engine_commands(5))
    with pytest.raises(kc.KalmanInputError, match=r"« step » doit être un indice de pas entier entre -5 et 4"):
        runs.nees_test(5)
