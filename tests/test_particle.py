"""Filtre particulaire : rééchantillonnages contre ``filterpy.monte_carlo`` (mêmes tirages uniformes),
moyenne et log-vraisemblance contre les valeurs exactes d'un modèle linéaire gaussien (filtre de Kalman,
loi jointe des mesures écrite en bloc), vitesse 1/√N, absence de biais de la vraisemblance, reproductibilité,
mesures manquantes, poids en logarithme, modèle bimodal, entrées invalides."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.stats

import kalman_course as kc
from kalman_course.scenarios import convergence, growth, pendulum

SCHEMES = ["multinomial", "stratified", "systematic"]


def _weights(rng, N, zeros=0):
    w = rng.gamma(0.5, size=N)
    w[rng.choice(N, zeros, replace=False)] = 0.0
    return w / w.sum()


def dense_log_likelihood(model, y, x0, P0):
    r"""log p(y₁…y_T) d'un modèle linéaire gaussien par la loi jointe des mesures, écrite en bloc (sans
    filtre) : y ~ N(μ, Σ), μ_k = C Aᵏ x̂₀, Σ_kl = C Cov(x_k, x_l) Cᵀ + δ_kl R."""
    A, C, Q, R = (np.array(a) for a in (model.A, model.C, model.Q, model.R))
    T, m = y.shape
    powers = [np.linalg.matrix_power(A, k) for k in range(T + 1)]
    mean = np.concatenate([C @ powers[k + 1] @ x0 for k in range(T)])
    cov = np.zeros((T * m, T * m))
    for i in range(T):
        for j in range(T):
            s = powers[i + 1] @ P0 @ powers[j + 1].T
            for l in range(1, min(i, j) + 2):
                s = s + powers[i + 1 - l] @ Q @ powers[j + 1 - l].T
            cov[i * m:(i + 1) * m, j * m:(j + 1) * m] = C @ s @ C.T + (R if i == j else 0.0)
    return float(scipy.stats.multivariate_normal.logpdf(y.ravel(), mean, cov))


# --------------------------------------------------------------------------- rééchantillonnages


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("N, zeros", [(7, 0), (100, 10), (1000, 300)])
def test_resampling_equals_filterpy_given_the_same_uniforms(scheme, N, zeros):
    """filterpy tire ses uniformes de ``numpy.random`` : même graine, mêmes tirages, mêmes indices."""
    import filterpy.monte_carlo as mc

    w = _weights(np.random.default_rng(N), N, zeros)
    for seed in range(5):
        np.random.seed(seed)
        ref = getattr(mc, f"{scheme}_resample")(w)
        np.random.seed(seed)
        u = np.random.random() if scheme == "systematic" else np.random.random(N)
        ours = getattr(kc, f"{scheme}_resample")(w, u)
        np.testing.assert_array_equal(ours, ref)
        assert not np.isin(ours, np.flatnonzero(w == 0)).any()  # jamais une particule de poids nul


def test_residual_resampling_against_filterpy_parts_and_filterpy_trap():
    """Le rééchantillonnage résiduel = ⌊Nwⁱ⌋ copies (définition) + le multinomial de filterpy sur les restes
    normalisés, avec les mêmes uniformes. ``filterpy.monte_carlo.residual_resample`` 2.0.0, lui, calcule
    les restes wⁱ − ⌊Nwⁱ⌋ (au lieu de Nwⁱ − ⌊Nwⁱ⌋) : ici leur somme est nulle et il rend des indices faux."""
    import filterpy.monte_carlo as mc

    for N, zeros in ((7, 0), (100, 10), (1000, 300)):
        w = _weights(np.random.default_rng(N + 1), N, zeros)
        counts = np.floor(N * w).astype(int)
        R = N - counts.sum()
        for seed in range(5):
            np.random.seed(seed)
            drawn = mc.multinomial_resample((N * w - counts) / (N * w - counts).sum())[:R]
            np.random.seed(seed)
            ours = kc.residual_resample(w, np.random.random(R))
            np.testing.assert_array_equal(ours[:counts.sum()], np.repeat(np.arange(N), counts))
            np.testing.assert_array_equal(ours[counts.sum():], drawn)
    # le piège de filterpy : w = (0,5 ; 0,3 ; 0,2), N = 3 → restes (−0,5 ; 0,3 ; 0,2), de somme nulle ;
    # filterpy copie alors toujours (1, 2, 0) fois les particules, au lieu de (1,5 ; 0,9 ; 0,6) en moyenne
    w = np.array([0.5, 0.3, 0.2])
    theirs = np.mean([np.bincount(_filterpy_residual(w, s), minlength=3) for s in range(500)], axis=0)
    ours = np.mean([np.bincount(kc.resample(w, "residual", rng=s), minlength=3) for s in range(4000)], axis=0)
    np.testing.assert_allclose(theirs, [1.0, 2.0, 0.0])
    np.testing.assert_allclose(ours, 3 * w, atol=0.05)


def _filterpy_residual(w, seed):
    import filterpy.monte_carlo as mc

    np.random.seed(seed)
    with np.errstate(all="ignore"):
        return mc.residual_resample(w)


@pytest.mark.parametrize("scheme", list(kc.RESAMPLING_SCHEMES))
def test_every_scheme_copies_each_particle_N_w_times_on_average(scheme):
    rng = np.random.default_rng(4)
    w = _weights(rng, 20, 3)
    counts = np.array([np.bincount(kc.resample(w, scheme, rng=rng), minlength=20) for _ in range(5000)])
    assert (counts.sum(axis=1) == 20).all()
    se = counts.std(axis=0) / np.sqrt(len(counts)) + 1e-12
    assert np.all(np.abs(counts.mean(axis=0) - 20 * w) < 5 * se + 1e-9)
    if scheme == "systematic":  # ⌊Nwⁱ⌋ ou ⌈Nwⁱ⌉ copies exactement
        assert np.all((counts >= np.floor(20 * w)) & (counts <= np.ceil(20 * w)))


def test_effective_sample_size():
    assert kc.effective_sample_size(np.full(8, 1 / 8)) == pytest.approx(8.0)
    assert kc.effective_sample_size([1.0, 0.0, 0.0]) == pytest.approx(1.0)
    assert kc.effective_sample_size([0.5, 0.5, 0.0, 0.0]) == pytest.approx(2.0)


# --------------------------------------------------------------------------- contre le filtre de Kalman


def test_mean_and_log_likelihood_match_the_exact_linear_gaussian_answer():
    """20 000 particules : la moyenne reste à quelques erreurs de Monte-Carlo du filtre de Kalman (erreur
    estimée par 4 graines indépendantes), la log-vraisemblance à une fraction de nat de la valeur exacte."""
    bench = convergence.linear_benchmark()
    ref = kc.kalman_filter(bench.model, bench.y, bench.x0, bench.P0)
    exact = dense_log_likelihood(bench.model, np.array(bench.y), bench.x0, bench.P0)
    runs = [kc.particle_filter(bench.nonlinear, bench.y, bench.x0, bench.P0, n_particles=20_000, rng=s)
            for s in range(4)]
    X = np.array([r.x for r in runs])                     # (4, T, n)
    spread = X.std(axis=0, ddof=1)                        # erreur de Monte-Carlo d'un tirage, par pas
    z = (X - ref.x) / (spread + 1e-12)
    assert np.sqrt(np.mean(z**2)) < 2.0                   # ≈ 1 si l'erreur n'est que du Monte-Carlo
    mean_z = (X.mean(axis=0) - ref.x) / (spread / 2 + 1e-12)  # erreur de la moyenne des 4 graines
    assert np.sqrt(np.mean(mean_z**2)) < 2.0
    assert np.abs(X - ref.x).max() < 0.1 * np.sqrt(ref.P.diagonal(axis1=1, axis2=2)).min()
    np.testing.assert_allclose(np.array([r.P for r in runs]).mean(axis=0), ref.P, rtol=0.05, atol=1e-3)
    for r in runs:
        assert abs(r.log_likelihood - exact) < 0.3, (r.log_likelihood, exact)
    assert exact == pytest.approx(kc.filter_log_likelihood(ref), abs=1e-8)


def test_error_decreases_as_one_over_root_n():
    conv = convergence.particle_convergence(sizes=(250, 1000, 4000), n_runs=6)
    assert -0.65 < conv.mean_slope < -0.35, conv.mean_error
    assert -0.65 < conv.cov_slope < -0.35, conv.cov_error
    assert (np.diff(conv.loglik_error) < 0).all()


def test_likelihood_estimate_is_unbiased_and_its_log_is_biased_down():
    """E[p̂(y)] = p(y) (estimateur sans biais) ; E[log p̂] < log p (Jensen). 100 particules, 10 pas."""
    bench = convergence.linear_benchmark(n_steps=10)
    exact = dense_log_likelihood(bench.model, np.array(bench.y), bench.x0, bench.P0)
    logs = np.array([kc.particle_filter(bench.nonlinear, bench.y, bench.x0, bench.P0, n_particles=100,
                                        rng=s).log_likelihood for s in range(600)])
    ratio = np.exp(logs - exact)
    assert abs(ratio.mean() - 1.0) < 4 * ratio.std() / np.sqrt(len(ratio))
    assert logs.mean() < exact


# --------------------------------------------------------------------------- comportement du filtre


def test_vectorized_and_pointwise_models_give_identical_particles():
    data = pendulum.pendulum_data(20)
    fast = kc.particle_filter(pendulum.pendulum_model(), data.y, data.x0, data.P0, n_particles=200, rng=1)
    slow = kc.particle_filter(pendulum.pendulum_model(vectorized=False), data.y, data.x0, data.P0,
                              n_particles=200, rng=1)
    np.testing.assert_allclose(fast.x, slow.x, rtol=0, atol=1e-12)
    np.testing.assert_allclose(fast.log_likelihood, slow.log_likelihood, rtol=1e-12)


def test_missing_rows_keep_the_weights_and_add_no_likelihood():
    data = pendulum.pendulum_data(40)
    y = np.array(data.y)
    y[[5, 6, 20]] = np.nan
    res = kc.particle_filter(pendulum.pendulum_model(), y, data.x0, data.P0, n_particles=1000, rng=2,
                             keep_particles=True)
    for k in (5, 6, 20):
        np.testing.assert_array_equal(res.x[k], res.x_pred[k])
        assert res.log_likelihood_increments[k] == 0.0 and not res.observed[k].any()
        if not res.resampled[k]:
            assert res.ess[k] == res.ess[k - 1]
            np.testing.assert_array_equal(res.weights[k], res.weights[k - 1])
    np.testing.assert_allclose(res.weights.sum(axis=1), 1.0, rtol=1e-12)
    assert res.particles.shape == (40, 1000, 2)
    # le résultat commun à toute la famille (même graine → mêmes tirages : test du moteur dans test_family)
    assert isinstance(res, kc.FilterResult) and res.x.shape == (40, 2) and res.ess.shape == (40,)
    assert isinstance(res.log_likelihood, float)


def test_ess_threshold_controls_resampling():
    data = pendulum.pendulum_data(30)
    model = pendulum.pendulum_model()
    never = kc.particle_filter(model, data.y, data.x0, data.P0, n_particles=300, rng=1, ess_threshold=0.0)
    always = kc.particle_filter(model, data.y, data.x0, data.P0, n_particles=300, rng=1, ess_threshold=1.0)
    assert not never.resampled.any()
    assert always.resampled[1:].all() and not always.resampled[0]
    assert never.ess[-1] < always.ess[-1]  # sans rééchantillonnage, les poids dégénèrent


def test_log_weights_survive_a_tiny_measurement_noise():
    """R = 10⁻¹² : les vraisemblances linéaires sont toutes nulles en double précision ; les log-poids
    donnent quand même une estimation finie, centrée sur la meilleure particule."""
    bench = convergence.linear_benchmark()
    model = kc.NonlinearModel.from_linear(kc.LinearGaussianModel(bench.model.A, bench.model.C, bench.model.Q, [[1e-12]]))
    res = kc.particle_filter(model, bench.y, bench.x0, bench.P0, n_particles=500, rng=0)
    X = bench.x0 + np.random.default_rng(0).standard_normal((500, 2)) @ np.linalg.cholesky(bench.P0).T
    assert np.all(np.exp(-0.5 * (bench.y[0, 0] - X[:, 0]) ** 2 / 1e-12) == 0.0)  # ce qu'auraient été les poids
    assert np.isfinite(res.x).all() and np.isfinite(res.log_likelihood) and (res.ess >= 1.0 - 1e-9).all()


def test_growth_model_particle_filter_beats_every_gaussian_filter():
    """Modèle de Gordon–Salmond–Smith, 20 jeux de données : le filtre particulaire bat nettement l'UKF,
    qui bat nettement l'EKF (médianes des erreurs quadratiques moyennes)."""
    med = growth.growth_comparison(n_runs=20, n_particles=1000).median()
    assert med["filtre particulaire"] < 0.75 * med["UKF"] < 0.75 * 0.75 * med["EKF"], med


def test_growth_posterior_is_bimodal_at_some_steps():
    data = growth.growth_data()
    res = growth.growth_filters(data, keep_particles=True)["filtre particulaire"]
    both = 0
    for k in range(len(data.y)):
        X, w = res.particles[k, :, 0], res.weights[k]
        if min(w[X > 0].sum(), w[X < 0].sum()) > 0.2:  # au moins 20 % du poids de chaque côté de 0
            both += 1
    assert both >= 3


# --------------------------------------------------------------------------- entrées invalides


@pytest.mark.parametrize("bad, message", [
    (dict(n_particles=0), "« n_particles » doit être un entier ≥ 1 ; reçu 0"),
    (dict(n_particles=2.5), "« n_particles » doit être un entier ≥ 1 ; reçu 2.5"),
    (dict(n_particles=True), "« n_particles » doit être un entier ≥ 1"),
    (dict(resampling="stratifié"), "« resampling » doit valoir 'multinomial', 'stratified', 'systematic', 'residual'"),
    (dict(ess_threshold=1.5), r"« ess_threshold » doit être un nombre entre 0 .* et 1"),
    (dict(ess_threshold=-0.1), "« ess_threshold »"),
    (dict(rng=None), "« rng » doit être une graine entière ou un numpy.random.Generator"),
])
def test_bad_arguments_are_named_in_french(bad, message):
    data = pendulum.pendulum_data(5)
    args = dict(n_particles=10, rng=0)
    args.update(bad)
    with pytest.raises(kc.KalmanInputError, match=message):
        kc.particle_filter(pendulum.pendulum_model(), data.y, data.x0, data.P0, **args)


def test_all_weights_zero_names_the_step():
    data = pendulum.pendulum_data(5)
    y = np.array(data.y)
    y[3] = 1e200  # (y − h)² déborde : vraisemblance nulle pour toutes les particules
    with pytest.raises(kc.KalmanInputError, match=r"correction par y\[3\].*toutes les particules ont un poids nul"
                                                  r".*augmentez Q, P0 ou le nombre de particules"):
        kc.particle_filter(pendulum.pendulum_model(), y, data.x0, data.P0, n_particles=50, rng=0)


def test_resampling_functions_check_their_inputs():
    with pytest.raises(kc.KalmanInputError, match="« weights » doit sommer à 1"):
        kc.systematic_resample([0.5, 0.6], 0.3)
    with pytest.raises(kc.KalmanInputError, match="« weights » doit être positif ou nul"):
        kc.multinomial_resample([1.5, -0.5], [0.1, 0.2])
    with pytest.raises(kc.KalmanInputError, match=r"« u » doit être un vecteur \(2,\)"):
        kc.stratified_resample([0.5, 0.5], [0.1])
    with pytest.raises(kc.KalmanInputError, match=r"« u » doit contenir des tirages uniformes dans \[0, 1\)"):
        kc.multinomial_resample([0.5, 0.5], [0.1, 1.0])
    with pytest.raises(kc.KalmanInputError, match="« resampling » doit valoir"):
        kc.resample([0.5, 0.5], "aléatoire", rng=0)


# --------------------------------------------------------------------------- formules du chapitre


def test_bayes_filter_recursion_on_a_grid_is_the_kalman_filter():
    """La récurrence du chapitre (prédiction de Chapman–Kolmogorov, correction de Bayes, vraisemblance
    produit des p(y_k | y_1:k−1)), calculée sur une grille fine pour un modèle linéaire à un état, redonne
    la moyenne, la variance et la log-vraisemblance du filtre de Kalman."""
    a, q, r, x0, p0 = 0.9, 0.5, 0.3, 0.5, 2.0
    model = kc.LinearGaussianModel(a, [[1.0]], q, r)
    y = kc.simulate(model, [1.0], 30, rng=4).y
    ref = kc.kalman_filter(model, y, x0, p0)
    grid = np.linspace(-15, 15, 3001)
    dx = grid[1] - grid[0]
    post = scipy.stats.norm.pdf(grid, x0, np.sqrt(p0))
    transition = scipy.stats.norm.pdf(grid[:, None], a * grid[None, :], np.sqrt(q))  # p(x_k | x_k−1)
    log_lik = 0.0
    for k in range(len(y)):
        prior = transition @ post * dx                                    # ∫ p(x_k | x_k−1) p(x_k−1 | y) dx
        like = scipy.stats.norm.pdf(y[k, 0], grid, np.sqrt(r))
        evidence = np.sum(like * prior) * dx                              # p(y_k | y_1:k−1)
        post = like * prior / evidence
        log_lik += np.log(evidence)
        mean = np.sum(grid * post) * dx
        var = np.sum((grid - mean) ** 2 * post) * dx
        assert mean == pytest.approx(ref.x[k, 0], abs=1e-6)
        assert var == pytest.approx(ref.P[k, 0, 0], rel=1e-5)
    exact = dense_log_likelihood(model, np.array(y), np.array([x0]), np.array([[p0]]))
    assert log_lik == pytest.approx(exact, abs=1e-6)


def test_importance_example_of_the_chapter():
    """Poids ∝ vraisemblance sur des tirages de l'a priori : l'estimation tend vers la moyenne a posteriori
    exacte y/(1 + r²) (qui est aussi la correction du filtre de Kalman), ESS entre 1 et N."""
    from kalman_course.scenarios import importance

    ex = importance.importance_example()
    post = kc.update(kc.LinearGaussianModel(1.0, [[1.0]], 0.0, ex.r_std**2), 0.0, 1.0, ex.y)
    assert ex.posterior_mean == pytest.approx(post.x[0]) and ex.posterior_var == pytest.approx(post.P[0, 0])
    assert 1.0 <= ex.ess <= len(ex.particles)
    assert ex.ess == pytest.approx(kc.effective_sample_size(ex.weights))
    big = importance.importance_example(n=400_000, rng=1)
    se = np.sqrt(ex.posterior_var / big.ess)
    assert abs(big.estimate - big.posterior_mean) < 5 * se


def test_degeneracy_without_resampling():
    from kalman_course.scenarios import importance

    d = importance.degeneracy()
    assert d.without[19] * d.n_particles < 2.0 and d.with_.min() > 0.05 and d.resampled.sum() > 10


def test_particle_sliders_default_position_is_the_chapter_run():
    from kalman_course.interactive import particle as ip

    axes = ip.particle_axes()
    run = ip.particle_run(axes[0].default_value, axes[1].default_value)
    bench = convergence.linear_benchmark()
    pf = kc.particle_filter(bench.nonlinear, bench.y, bench.x0, bench.P0, n_particles=1000, rng=ip.PF_SEED)
    kf = kc.kalman_filter(bench.model, bench.y, bench.x0, bench.P0)
    np.testing.assert_array_equal(run["gap"], pf.x[:, 0] - kf.x[:, 0])
    assert axes[0].labels()[-1] == "10\u202f000"
    np.testing.assert_array_equal(run["ess"], pf.ess / 1000)


def test_resampling_never_returns_an_index_past_the_last_particle_under_rounding():
    """Issue 34 : avec u à un ulp de 1, la dernière position (u + N − 1)/N s'arrondit à 1 exactement ; et la somme
    cumulée de 27 poids égaux s'arrête à 1 − 8 × 10⁻¹⁶. Aucun indice N, et jamais une particule de poids nul."""
    u = np.nextafter(1.0, 0.0)
    assert (u + 9) / 10 == 1.0
    assert kc.systematic_resample(np.full(10, 0.1), u)[-1] == 9
    w = np.r_[np.full(9, 1 / 9), 0.0]
    assert kc.systematic_resample(w, u)[-1] == 8
    assert kc.systematic_resample(np.full(27, 1 / 27), 0.99999999999999)[-1] == 26


def test_equivalent_correction_is_angle_aware_for_a_bearing_near_pi():
    """Un azimut mesuré près de ±π (``angle_indices``) : le nuage prédit de ses images est à cheval sur ±π.
    La correction « linéaire équivalente » du filtre particulaire prend la moyenne circulaire et des écarts
    ramenés dans (−π, π] : son √S et son innovation sont ceux du CKF (même modèle, 20 000 particules, à 5 %
    près), et la NIS reste de l'ordre de 1 (avant : √S ≈ 3 rad, la moyenne arithmétique d'angles proches de
    +π et de −π tombant près de 0)."""
    def h(x):
        x = np.asarray(x)
        return np.stack([np.hypot(x[..., 0], x[..., 1]), np.arctan2(x[..., 1], x[..., 0])], axis=-1)

    model = kc.NonlinearModel(lambda x, u: x, h, 0.01 * np.eye(2), np.diag([1.0, 1e-4]), angle_indices=(1,),
                              vectorized=True)
    x0, P0 = np.array([-100.0, 0.0]), np.eye(2)
    y = np.array([[100.0, np.pi - 0.001], [100.2, -np.pi + 0.002], [99.9, np.pi - 0.003]])
    pf = kc.particle_filter(model, y, x0, P0, n_particles=20_000, rng=1)
    ckf = kc.cubature_kalman_filter(model, y, x0, P0)
    np.testing.assert_allclose(np.sqrt(pf.S[:, 1, 1]), np.sqrt(ckf.S[:, 1, 1]), rtol=0.05)
    np.testing.assert_allclose(pf.innovation[:, 1], ckf.innovation[:, 1], atol=3e-4)
    assert np.all(kc.nis(pf) < 1.0) and np.all(np.abs(pf.innovation[:, 1]) < 0.01)
    np.testing.assert_allclose(pf.x, ckf.x, atol=0.05)
