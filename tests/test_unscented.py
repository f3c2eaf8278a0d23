"""UKF du paquet : points sigma et transformée contre filterpy (``MerweScaledSigmaPoints``,
``unscented_transform``) et contre des formes closes ; le filtre contre la boucle ``predict()``/``update()``
de ``UnscentedKalmanFilter`` (tests/reference_ukf.py) sur le tag, le pendule et le radar (angles), et contre
le filtre de Kalman ; mesures manquantes ; modèles vectorisés ; formules du chapitre ; erreurs françaises."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import random_model
from reference_ukf import filterpy_unscented_filter

import kalman_course as kc
from kalman_course.scenarios import banana, distant_target, pendulum, radar, tag

TOL = dict(rtol=0, atol=1e-9)
FIELDS = ("x", "P", "x_pred", "P_pred", "K", "innovation", "S")
PARAMS = [(0.1, 2.0, -1.0), (1.0, 2.0, 0.0), (0.5, 0.0, 3.0), (1e-2, 2.0, 0.0)]


def _same(ours, ref, tol=TOL):
    for field in FIELDS:
        np.testing.assert_allclose(getattr(ours, field), getattr(ref, field), err_msg=field, **tol)


# --------------------------------------------------------------------------- points sigma et transformée


@pytest.mark.parametrize("n", [1, 2, 4])
@pytest.mark.parametrize("alpha, beta, kappa", PARAMS)
def test_sigma_points_equal_filterpy_merwe(n, alpha, beta, kappa):
    from filterpy.kalman import MerweScaledSigmaPoints

    rng = np.random.default_rng(n)
    L = rng.standard_normal((n, n))
    P, x = L @ L.T + 0.5 * np.eye(n), rng.standard_normal(n)
    if n + kappa <= 0:  # n + λ = α²(n + κ) ≤ 0 : filterpy diviserait par zéro ; le paquet refuse
        with pytest.raises(kc.KalmanInputError, match="« kappa » doit vérifier n \\+ kappa > 0"):
            kc.sigma_points(x, P, alpha=alpha, beta=beta, kappa=kappa)
        return
    ref = MerweScaledSigmaPoints(n, alpha=alpha, beta=beta, kappa=kappa)
    sp = kc.sigma_points(x, P, alpha=alpha, beta=beta, kappa=kappa)
    np.testing.assert_allclose(sp.Wm, ref.Wm, rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(sp.Wc, ref.Wc, rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(sp.points, ref.sigma_points(x, P), rtol=0, atol=1e-12)
    Wm, Wc, lam = kc.sigma_weights(n, alpha=alpha, beta=beta, kappa=kappa)
    np.testing.assert_array_equal(Wm, sp.Wm)
    assert lam == pytest.approx(alpha**2 * (n + kappa) - n)


def test_sigma_points_have_the_mean_and_covariance_and_weights_can_be_negative():
    """Formules du chapitre : Σ Wᵐ = 1, Σ Wᵐχ = x̄, Σ Wᶜ(χ − x̄)(χ − x̄)ᵀ = P ; W₀ < 0 quand α²(n + κ) < n."""
    rng = np.random.default_rng(3)
    n = 3
    L = rng.standard_normal((n, n))
    P, x = L @ L.T + np.eye(n), rng.standard_normal(n)
    for alpha, kappa in ((0.1, 0.0), (1.0, 0.0), (1.0, 3 - n), (0.5, 2.0)):
        sp = kc.sigma_points(x, P, alpha=alpha, beta=2.0, kappa=kappa)
        lam = alpha**2 * (n + kappa) - n
        assert sp.Wm.sum() == pytest.approx(1.0, abs=1e-12)
        np.testing.assert_allclose(sp.Wm @ sp.points, x, atol=1e-9)
        D = sp.points - x
        np.testing.assert_allclose(D.T @ np.diag(sp.Wc) @ D, P, atol=1e-8)
        assert (sp.Wm[0] < 0) == (alpha**2 * (n + kappa) < n)
        assert sp.Wm[0] == pytest.approx(lam / (n + lam))
        assert sp.Wc[0] == pytest.approx(lam / (n + lam) + 1 - alpha**2 + 2.0)
    # α = 0,1 : W₀ = 1 − n/(α²(n+κ)) = 1 − 3/(0,01·3) = −99
    assert kc.sigma_weights(3, alpha=0.1, beta=2.0, kappa=0.0)[0][0] == pytest.approx(-99.0)


def test_unscented_transform_equals_filterpy_and_is_exact_for_affine_maps():
    from filterpy.kalman import MerweScaledSigmaPoints
    from filterpy.kalman import unscented_transform as fp_ut

    rng = np.random.default_rng(9)
    n, m = 3, 2
    L = rng.standard_normal((n, n))
    P, x = L @ L.T + np.eye(n), rng.standard_normal(n)
    M, b = rng.standard_normal((m, n)), rng.standard_normal(m)

    def g(z):
        return np.array([np.sin(z[0]) * z[1], z[2] ** 2 + z[0]])

    pts = MerweScaledSigmaPoints(n, alpha=0.5, beta=2.0, kappa=0.0)
    sig = pts.sigma_points(x, P)
    mean_fp, cov_fp = fp_ut(np.array([g(s) for s in sig]), pts.Wm, pts.Wc)
    ut = kc.unscented_transform(x, P, g, alpha=0.5, beta=2.0, kappa=0.0)
    np.testing.assert_allclose(ut.mean, mean_fp, atol=1e-12)
    np.testing.assert_allclose(ut.cov, cov_fp, atol=1e-12)
    # affine : moyenne Mx + b, covariance MPMᵀ, covariance croisée PMᵀ, exactes
    aff = kc.unscented_transform(x, P, lambda z: M @ z + b, alpha=0.3, beta=2.0, kappa=1.0)
    np.testing.assert_allclose(aff.mean, M @ x + b, atol=1e-10)
    np.testing.assert_allclose(aff.cov, M @ P @ M.T, atol=1e-8)
    np.testing.assert_allclose(aff.cross, P @ M.T, atol=1e-8)
    # vectorisée : même résultat
    vec = kc.unscented_transform(x, P, lambda Z: Z @ M.T + b, alpha=0.3, beta=2.0, kappa=1.0, vectorized=True)
    np.testing.assert_allclose(vec.mean, aff.mean, atol=1e-12)
    np.testing.assert_allclose(vec.cov, aff.cov, atol=1e-12)


def test_banana_closed_form_against_monte_carlo_and_the_three_answers():
    """Formes closes de la banane contre 10⁶ tirages ; la moyenne de la transformée est bien plus juste
    que la linéarisation (qui place la moyenne sur l'arc, au point g(r̄, θ̄))."""
    truth = banana.banana_truth()
    sample = banana.banana_sample(1_000_000, rng=0)
    se = np.sqrt(np.diag(np.cov(sample.T)) / len(sample))
    assert np.all(np.abs(sample.mean(axis=0) - truth.mean) < 5 * se)
    np.testing.assert_allclose(np.cov(sample.T), truth.cov, rtol=0, atol=2e-4)
    c = banana.banana_comparison()
    e_lin, e_ut = c.mean_errors()
    assert e_lin == pytest.approx(1 - np.exp(-banana.BANANA_BEARING_STD**2 / 2), rel=1e-9)  # 0,059 m
    assert e_ut < e_lin / 100
    # la linéarisation sous-estime fortement la dispersion radiale (axe y ici) : 4e-4 contre 7e-3 m²
    assert c.linearized.cov[1, 1] < c.truth.cov[1, 1] / 10 < c.unscented.cov[1, 1]


def test_mean_error_orders_two_four_six():
    """Erreur de la moyenne : O(σ²) linéarisée, O(σ⁴) unscented (κ = 0), O(σ⁶) avec κ = 3 − n."""
    stds = np.array([0.025, 0.05, 0.1])
    errors = banana.mean_error_orders(stds)
    slopes = [kc.scenarios.convergence.loglog_slope(stds, e) for e in errors]
    np.testing.assert_allclose(slopes, [2.0, 4.0, 6.0], atol=0.05)


# --------------------------------------------------------------------------- le filtre contre filterpy


@pytest.mark.parametrize("alpha, beta, kappa", PARAMS[:3])
def test_tag_ukf_equals_filterpy(alpha, beta, kappa):
    data = tag.tag_data()
    model = tag.tag_model()
    ours = kc.unscented_kalman_filter(model, data.y, data.x0, data.P0, alpha=alpha, beta=beta, kappa=kappa)
    ref = filterpy_unscented_filter(model, data.y, data.x0, data.P0, alpha=alpha, beta=beta, kappa=kappa)
    _same(ours, ref)


@pytest.mark.parametrize("alpha, beta, kappa", PARAMS)
def test_pendulum_ukf_equals_filterpy(alpha, beta, kappa):
    data = pendulum.pendulum_data(300)
    model = pendulum.pendulum_model()
    ours = kc.unscented_kalman_filter(model, data.y, data.x0, data.P0, alpha=alpha, beta=beta, kappa=kappa)
    ref = filterpy_unscented_filter(model, data.y, data.x0, data.P0, alpha=alpha, beta=beta, kappa=kappa)
    _same(ours, ref)


def test_bearing_wrap_ukf_equals_filterpy_with_circular_mean():
    """Radar dont la cible traverse θ = ±π : moyenne circulaire et résidus repliés, comme filterpy les reçoit."""
    x_true, y, x0, P0 = radar.radar_tracking_data()
    model = radar.radar_tracking_model()
    ours = kc.unscented_kalman_filter(model, y, x0, P0, alpha=0.5, beta=2.0, kappa=0.0)
    ref = filterpy_unscented_filter(model, y, x0, P0, alpha=0.5, beta=2.0, kappa=0.0)
    _same(ours, ref)
    assert np.abs(y[:, 1]).max() > 3.0  # l'azimut passe bien par ±π
    assert np.abs(ours.innovation[:, 1]).max() < np.pi / 2  # repliée, jamais un saut de 2π
    assert np.linalg.norm(ours.x[10:, :2] - x_true[10:, :2], axis=1).max() < 1.0


def test_missing_rows_equal_filterpy_and_partial_rows_use_observed_components():
    data = tag.tag_data(120)
    model = tag.tag_model()
    y = np.array(data.y)
    y[[3, 4, 50]] = np.nan
    ours = kc.unscented_kalman_filter(model, y, data.x0, data.P0, alpha=1.0, kappa=0.0)
    _same(ours, filterpy_unscented_filter(model, y, data.x0, data.P0, alpha=1.0, kappa=0.0))
    np.testing.assert_array_equal(ours.x[50], ours.x_pred[50])
    # ligne partielle : filterpy reçoit, à ce pas, h et R restreints aux ancres observées
    from filterpy.kalman import MerweScaledSigmaPoints, UnscentedKalmanFilter

    y = np.array(data.y)
    y[[10, 30], 2] = np.nan
    y[60, [0, 3]] = np.nan
    ours = kc.unscented_kalman_filter(model, y, data.x0, data.P0, alpha=0.5, kappa=0.0)
    f = UnscentedKalmanFilter(4, 4, 1.0, hx=lambda x: model.h(x), fx=lambda x, dt: model.f(x, None),
                              points=MerweScaledSigmaPoints(4, alpha=0.5, beta=2.0, kappa=0.0))
    f.x, f.P, f.Q, f.R = np.array(data.x0), np.array(data.P0), np.array(model.Q), np.array(model.R)
    for k in range(len(y)):
        f.predict()
        obs = ~np.isnan(y[k])
        f.update(y[k, obs], R=np.array(model.R)[np.ix_(obs, obs)], hx=lambda x, obs=obs: model.h(x)[obs])
        np.testing.assert_allclose(ours.x[k], f.x, **TOL)
        np.testing.assert_allclose(ours.P[k], f.P, **TOL)
    assert ours.observed[60].tolist() == [False, True, True, False] and np.all(ours.K[60][:, [0, 3]] == 0)


def test_ukf_with_alpha_one_equals_kalman_filter_on_a_linear_model():
    """α = 1, β = 2, κ = 0 : égalité à 1e-9 ; le réglage α = 0,1 (W₀ ≈ −130) amplifie les arrondis."""
    rng = np.random.default_rng(11)
    lin = random_model(rng, n=4, m=2, p=1)
    u = rng.normal(size=50)
    y = kc.simulate(lin, np.zeros(4), 50, u=u, rng=11).y
    ref = kc.kalman_filter(lin, y, np.ones(4), 2 * np.eye(4), u=u)
    model = kc.NonlinearModel.from_linear(lin)
    ukf = kc.unscented_kalman_filter(model, y, np.ones(4), 2 * np.eye(4), u=u, alpha=1.0, beta=2.0, kappa=0.0)
    for field in FIELDS:
        np.testing.assert_allclose(getattr(ukf, field), getattr(ref, field), err_msg=field, **TOL)
    small = kc.unscented_kalman_filter(model, y, np.ones(4), 2 * np.eye(4), u=u, alpha=0.1, kappa=-1.0)
    np.testing.assert_allclose(small.x, ref.x, rtol=0, atol=1e-6)


def test_vectorized_and_pointwise_models_give_the_same_filter():
    data = pendulum.pendulum_data(200)
    fast = kc.unscented_kalman_filter(pendulum.pendulum_model(), data.y, data.x0, data.P0, alpha=1.0, kappa=0.0)
    slow = kc.unscented_kalman_filter(pendulum.pendulum_model(vectorized=False), data.y, data.x0, data.P0,
                                      alpha=1.0, kappa=0.0)
    _same(fast, slow, dict(rtol=0, atol=1e-12))


# --------------------------------------------------------------------------- formules du chapitre


def test_ukf_step_matches_chapter_formulas():
    """Les formules du chapitre, écrites ici ligne à ligne (racine de Cholesky, points retirés de la loi
    prédite), redonnent l'UKF de filterpy et celui du paquet (tag, 3 pas)."""
    data = tag.tag_data(3)
    model = tag.tag_model()
    n, alpha, beta, kappa = 4, 0.1, 2.0, -1.0
    lam = alpha**2 * (n + kappa) - n
    Wm = np.full(2 * n + 1, 1 / (2 * (n + lam)))
    Wc = Wm.copy()
    Wm[0] = lam / (n + lam)
    Wc[0] = lam / (n + lam) + 1 - alpha**2 + beta
    x, P = np.array(data.x0), np.array(data.P0)
    ours = []
    for y in data.y:
        L = np.linalg.cholesky((n + lam) * P)
        chi = np.vstack([x, x + L.T, x - L.T])  # lignes : χ₀, χ₁..χₙ, χₙ₊₁..χ₂ₙ
        chi_m = np.array([model.transition(c, None) for c in chi])
        x_m = Wm @ chi_m
        P_m = (chi_m - x_m).T @ np.diag(Wc) @ (chi_m - x_m) + model.Q
        L = np.linalg.cholesky((n + lam) * P_m)  # points sigma retirés de (x̂⁻, P⁻)
        chi_t = np.vstack([x_m, x_m + L.T, x_m - L.T])
        Z = np.array([model.observe(c) for c in chi_t])
        y_hat = Wm @ Z
        S = (Z - y_hat).T @ np.diag(Wc) @ (Z - y_hat) + model.R
        Pxy = (chi_t - x_m).T @ np.diag(Wc) @ (Z - y_hat)
        K = Pxy @ np.linalg.inv(S)
        x = x_m + K @ (y - y_hat)
        P = P_m - K @ S @ K.T
        ours.append(x)
    ref = filterpy_unscented_filter(model, data.y, data.x0, data.P0, alpha=alpha, beta=beta, kappa=kappa)
    pkg = kc.unscented_kalman_filter(model, data.y, data.x0, data.P0, alpha=alpha, beta=beta, kappa=kappa)
    np.testing.assert_allclose(np.array(ours), ref.x, **TOL)
    np.testing.assert_allclose(P, ref.P[-1], **TOL)
    np.testing.assert_allclose(pkg.x, ref.x, **TOL)


# --------------------------------------------------------------------------- UKF contre EKF


def test_tag_ekf_and_ukf_tie():
    data = tag.tag_data()
    r_ekf = tag.position_rmse(tag.run_tag_ekf(data=data).x, data.x_true)
    r_ukf = tag.position_rmse(tag.run_tag_ukf(data=data).x, data.x_true)
    assert 0.98 <= r_ekf / r_ukf <= 1.02  # mesuré : 0,9996 (5,98 cm contre 5,99 cm)
    assert 0.05 < r_ukf < 0.07


def test_distant_target_ukf_clearly_beats_ekf():
    """Cible à 1 km, position a priori à 300 m près : l'EKF se trompe et se croit précis (NEES ≫ 4),
    l'UKF reste près de la cible (30 tirages)."""
    comp = distant_target.distant_target_comparison(n_runs=30)
    summary = comp.summary()
    (e_ekf, nees_ekf), (e_ukf, nees_ukf) = summary["EKF"], summary["UKF"]
    assert e_ukf < e_ekf / 2.5
    assert nees_ekf > 10 * nees_ukf
    assert e_ukf < 5.0  # m, pour un radar qui voit la cible à 3,5 m près en travers


# --------------------------------------------------------------------------- modèles vectorisés et erreurs


def test_vectorized_flag_and_shape_errors():
    def f_row(x, u):
        return np.array([x[0] + x[1], x[1]])

    with pytest.raises(kc.KalmanInputError, match="« vectorized » doit être un booléen"):
        kc.NonlinearModel(f_row, lambda x: x[:1], np.eye(2), [[1.0]], vectorized="oui")
    bad = kc.NonlinearModel(f_row, lambda x: x[..., :1], np.eye(2), [[1.0]], vectorized=True)
    X = np.zeros((5, 2))
    with pytest.raises(kc.KalmanInputError, match=r"modèle vectorisé.*forme \(5, 2\).*forme \(2, 2\).*x\[\.\.\., i\]"):
        bad.transition_many(X)
    good = kc.NonlinearModel(f_row, lambda x: x[:1], np.eye(2), [[1.0]])
    np.testing.assert_allclose(good.transition_many(np.arange(10.0).reshape(5, 2)),
                               [[1, 1], [5, 3], [9, 5], [13, 7], [17, 9]])
    nan_h = kc.NonlinearModel(f_row, lambda x: x[..., :1] * np.nan, np.eye(2), [[1.0]], vectorized=True)
    with pytest.raises(kc.KalmanInputError, match="« h » a renvoyé des valeurs non finies"):
        nan_h.observe_many(np.zeros((3, 2)))
    assert "vectorisé" in repr(bad)


def test_ukf_bad_inputs_are_french_errors():
    model = pendulum.pendulum_model()
    data = pendulum.pendulum_data(5)
    with pytest.raises(kc.KalmanInputError, match="« alpha » doit être strictement positif"):
        kc.unscented_kalman_filter(model, data.y, data.x0, data.P0, alpha=0.0, kappa=0.0)
    with pytest.raises(kc.KalmanInputError, match=r"« kappa » doit vérifier n \+ kappa > 0 \(ici n = 2\)"):
        kc.unscented_kalman_filter(model, data.y, data.x0, data.P0, alpha=1.0, kappa=-2.0)
    with pytest.raises(kc.KalmanInputError, match="« beta » doit être un nombre réel fini"):
        kc.unscented_kalman_filter(model, data.y, data.x0, data.P0, alpha=1.0, beta=np.nan, kappa=0.0)
    with pytest.raises(kc.KalmanInputError, match="« alpha » est obligatoire"):  # ni α ni κ par défaut : erreur française
        kc.unscented_kalman_filter(model, data.y, data.x0, data.P0)
    with pytest.raises(kc.KalmanInputError, match="« P0 » doit être définie positive"):
        kc.unscented_kalman_filter(model, data.y, data.x0, np.diag([1.0, 0.0]), alpha=1.0, kappa=0.0)
    noisy = kc.NonlinearModel(model.f, model.h, [[1.0]], model.R, f_noise_jacobian=[[0.0], [1.0]])
    with pytest.raises(kc.KalmanInputError, match="bruits additifs"):
        kc.unscented_kalman_filter(noisy, data.y, data.x0, data.P0, alpha=1.0, kappa=0.0)
    with pytest.raises(kc.KalmanInputError, match=r"« cov » doit être définie positive"):
        kc.sigma_points([0.0, 0.0], np.zeros((2, 2)), alpha=1.0)
    with pytest.raises(kc.KalmanInputError, match="« n » doit être un entier ≥ 1"):
        kc.sigma_weights(0, alpha=1.0, beta=2.0, kappa=0.0)
    with pytest.raises(kc.KalmanInputError, match="« fn » a échoué"):
        kc.unscented_transform([0.0], [[1.0]], lambda x: 1 / 0, alpha=1.0)


def test_covariance_that_stops_being_positive_definite_names_the_step():
    """f écrase tous les points sur une constante et Q = 0 : P⁻ = 0 ; la correction par y[0] ne peut
    pas tirer de points sigma — erreur française qui nomme l'étape et la mesure, pas une LinAlgError."""
    model = kc.NonlinearModel(lambda x, u: np.zeros_like(x), lambda x: x, np.zeros((2, 2)), np.eye(2))
    with pytest.raises(kc.KalmanInputError, match=r"UKF, correction par y\[0\] : la covariance prédite P⁻ n'est plus "
                                                  r"définie positive.*Essayez un α plus grand"):
        kc.unscented_kalman_filter(model, np.zeros((4, 2)), np.zeros(2), np.eye(2), alpha=1.0, kappa=0.0)
    # même chose à la prédiction : une ligne manquante saute la correction ; P = P⁻ = 0 à la prédiction suivante
    y = np.zeros((4, 2))
    y[0] = np.nan
    with pytest.raises(kc.KalmanInputError, match=r"UKF, prédiction vers y\[1\] : la covariance a posteriori P"):
        kc.unscented_kalman_filter(model, y, np.zeros(2), np.eye(2), alpha=1.0, kappa=0.0)


def test_chapter_formula_for_the_unscented_mean_of_the_banana():
    """ȳ_UKF = r̄ [1 − 1/(n+λ) + cos(√(n+λ) σθ)/(n+λ)] à θ̄ = 90° (formule du chapitre), pour plusieurs α, κ."""
    for alpha, kappa, s in ((1.0, 0.0, 0.3), (1.0, 1.0, 0.2), (0.5, 2.0, 0.4), (0.2, 0.0, 0.35)):
        c = alpha**2 * (2 + kappa)  # n + λ
        expected = 1 - 1 / c + np.cos(np.sqrt(c) * s) / c
        ut = banana.banana_unscented(0.02, s, alpha=alpha, kappa=kappa)
        assert ut.mean[1] == pytest.approx(expected, rel=1e-12)


def test_distant_target_iterated_ekf_is_consistent_from_the_start():
    comp = distant_target.distant_target_comparison(n_runs=20)
    lo, hi = kc.chi2_band(4, 20, level=0.999)
    assert lo < comp.nees["EKF itéré"][0] < hi
    assert comp.nees["UKF"][0] > hi and comp.nees["EKF"][0] > comp.nees["UKF"][0]


def test_banana_sliders_default_positions_are_the_chapter_figure():
    from kalman_course.interactive import unscented as iu

    sig, rad = iu.banana_uncertainty_axes()
    assert np.deg2rad(sig.default_value) == banana.BANANA_BEARING_STD and rad.default_value == banana.BANANA_RANGE_STD
    alpha, kappa = iu.banana_parameter_axes()
    assert alpha.default_value == banana.BANANA_ALPHA and kappa.default_value - 2 == banana.BANANA_KAPPA
    assert kappa.labels()[0].replace("\u2212", "-").startswith("-1,5")
    series = iu.banana_series(banana.BANANA_RANGE_STD, banana.BANANA_BEARING_STD)
    comp = banana.banana_comparison()
    assert series["ut_mx"][0] == comp.unscented.mean[0] and series["ut_my"][0] == comp.unscented.mean[1]
    assert len(set(series["sig_x"])) <= 5
