"""Vraisemblance, départ diffus exact, maximum de vraisemblance et EM : contre statsmodels et la loi
jointe des mesures calculée d'un bloc."""

from __future__ import annotations

import numpy as np
import pytest
import statsmodels.api as sm

import kalman_course as kc
from kalman_course.numbers import format_array
from kalman_course.numbers import format_spec as fs
from conftest import random_model
from dense_oracle import batch_log_likelihood

NILE_LLEVEL = [15099.0, 1469.1]  # (σ²_ε, σ²_η) : ALGORITHMS.md § 11.5
NILE_LLTREND = [15000.0, 1300.0, 5.0]  # (σ²_ε, σ²_niveau, σ²_pente)


def _nile_model(trend, params):
    if trend == "llevel":
        return kc.LinearGaussianModel(1.0, 1.0, params[1], params[0])
    A = np.array([[1.0, 1.0], [0.0, 1.0]])
    return kc.LinearGaussianModel(A, [[1.0, 0.0]], np.diag(params[1:]), params[0])


def _local_level(theta):
    """θ = (log σ²_ε, log σ²_η)."""
    return kc.LinearGaussianModel(1.0, 1.0, np.exp(theta[1]), np.exp(theta[0]))


# --------------------------------------------------------------------------- statsmodels


def test_nile_series_is_the_statsmodels_dataset():
    """Le fichier lu directement redonne la série de ``statsmodels.datasets.nile.load()`` (pandas)."""
    from statsmodels.datasets import nile as sm_nile

    data = sm_nile.load().data
    series = kc.datasets.nile()
    np.testing.assert_array_equal(series.year, np.asarray(data["year"], dtype=float).astype(int))
    np.testing.assert_array_equal(series.flow, np.asarray(data["volume"], dtype=float))


def test_nile_series_loads_without_pandas():
    """Cent nombres ne valent pas l'import de pandas et de statsmodels (≈ 0,4 s au premier appel)."""
    import subprocess
    import sys

    code = ("import sys, kalman_course as kc; s = kc.datasets.nile(True); "
            "assert s.flow.shape == (100,) and int(s.missing.sum()) == 40; "
            "print('pandas' in sys.modules, 'statsmodels' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False"]



@pytest.mark.parametrize("trend,params,expected", [
    ("llevel", NILE_LLEVEL, -633.46456365),  # valeurs mesurées avec statsmodels 0.15.0
    ("lltrend", NILE_LLTREND, -632.70137553),
])
def test_exact_diffuse_log_likelihood_equals_statsmodels_on_the_nile(trend, params, expected):
    y = kc.datasets.nile().flow
    ours = kc.log_likelihood(_nile_model(trend, params), y)
    ref = sm.tsa.UnobservedComponents(y, trend, use_exact_diffuse=True).loglike(params)
    print(f"{trend} : kalman_course {fs(ours, '.10f')}  statsmodels {fs(ref, '.10f')}  écart {fs(ours - ref, '.2e')}")
    assert abs(ours - ref) < 1e-6
    assert abs(ours - expected) < 1e-6


@pytest.mark.parametrize("trend,params", [("llevel", NILE_LLEVEL), ("lltrend", NILE_LLTREND)])
def test_exact_diffuse_log_likelihood_with_the_missing_years(trend, params):
    y = kc.datasets.nile(missing=True).flow
    ours = kc.log_likelihood(_nile_model(trend, params), y)
    ref = sm.tsa.UnobservedComponents(y, trend, use_exact_diffuse=True).loglike(params)
    assert abs(ours - ref) < 1e-6


def test_statsmodels_default_start_is_only_approximately_diffuse():
    """Le départ par défaut de statsmodels (variance initiale 10⁶, premier terme écarté) n'est pas le
    départ diffus exact : il manque le −½ log 2π de la première mesure et il reste un écart d'environ
    0,01 (ALGORITHMS § 11.5) ; c'est au départ exact qu'il faut se comparer."""
    y = kc.datasets.nile().flow
    exact = kc.log_likelihood(_nile_model("llevel", NILE_LLEVEL), y)
    approx = sm.tsa.UnobservedComponents(y, "llevel").loglike(NILE_LLEVEL)
    gap = approx - (exact + 0.5 * np.log(2 * np.pi))
    print(f"départ approché − (exact + ½ log 2π) = {fs(gap, '.4f')}")
    assert 1e-3 < abs(gap) < 0.05


def test_known_prior_log_likelihood_equals_statsmodels_initialize_known():
    y = kc.datasets.nile().flow
    model = _nile_model("llevel", NILE_LLEVEL)
    x0, P0 = 1000.0, 5000.0
    mod = sm.tsa.UnobservedComponents(y, "llevel")
    # statsmodels : a priori de l'état de la PREMIÈRE mesure = notre prédiction A x0, A P0 Aᵀ + Q
    mod.ssm.initialize_known(np.array([x0]), np.array([[P0 + NILE_LLEVEL[1]]]))
    mod.ssm.loglikelihood_burn = 0
    ref = mod.loglike(NILE_LLEVEL)
    ours = kc.log_likelihood(model, y, x0, P0)
    print(f"a priori connu : kalman_course {fs(ours, '.10f')}  statsmodels {fs(ref, '.10f')}")
    assert abs(ours - ref) < 1e-7


def test_known_prior_multivariate_equals_statsmodels_state_space():
    rng = np.random.default_rng(5)
    model = random_model(rng, 3, 2, 0)
    sim = kc.simulate(model, np.zeros(3), 80, rng=rng)
    y = np.array(sim.y)
    y[[10, 11]] = np.nan
    y[30, 1] = np.nan
    x0, P0 = rng.standard_normal(3), np.eye(3)
    mod = sm.tsa.statespace.MLEModel(y, k_states=3)
    mod.ssm["design"] = np.array(model.C)
    mod.ssm["transition"] = np.array(model.A)
    mod.ssm["selection"] = np.eye(3)
    mod.ssm["state_cov"] = np.array(model.Q)
    mod.ssm["obs_cov"] = np.array(model.R)
    mod.ssm.initialize_known(model.A @ x0, model.A @ P0 @ model.A.T + model.Q)
    ref = mod.ssm.loglike()
    assert abs(kc.log_likelihood(model, y, x0, P0) - ref) < 1e-7


# --------------------------------------------------------------------------- loi jointe d'un bloc


@pytest.mark.parametrize("n,m,p", [(1, 1, 0), (2, 1, 1), (3, 2, 1), (2, 3, 0)])
def test_log_likelihood_equals_the_joint_density_of_the_measurements(n, m, p):
    rng = np.random.default_rng(100 + 10 * n + m + p)
    model = random_model(rng, n, m, p)
    T = 20
    u = rng.standard_normal((T, p)) if p else None
    y = np.array(kc.simulate(model, rng.standard_normal(n), T, u=u, rng=rng).y)
    y[[3, 12]] = np.nan
    if m > 1:
        y[7, 0] = np.nan
    x0, P0 = rng.standard_normal(n), 1.5 * np.eye(n)
    np.testing.assert_allclose(kc.log_likelihood(model, y, x0, P0, u), batch_log_likelihood(model, y, u, x0, P0),
                               rtol=1e-10)
    np.testing.assert_allclose(kc.log_likelihood(model, y, u=u), batch_log_likelihood(model, y, u), rtol=1e-9)


@pytest.mark.parametrize("missing", [False, True])
def test_batched_log_likelihoods_equal_statsmodels_on_a_grid(missing):
    """Le lot (grille de paramètres du chapitre) contre statsmodels point par point."""
    y = kc.datasets.nile(missing=missing).flow
    grid = [(e, q) for e in (3000.0, 15099.0, 80000.0) for q in (20.0, 1469.1, 50000.0)]
    ours = kc.likelihood.log_likelihoods([_nile_model("llevel", g) for g in grid], y)
    mod = sm.tsa.UnobservedComponents(y, "llevel", use_exact_diffuse=True)
    ref = np.array([mod.loglike(list(g)) for g in grid])
    np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-6)


@pytest.mark.parametrize("n,m", [(1, 1), (2, 1), (3, 2), (2, 3)])
def test_batched_log_likelihoods_equal_the_joint_density(n, m):
    rng = np.random.default_rng(700 + 10 * n + m)
    models = [random_model(rng, n, m, 0) for _ in range(3)]
    y = np.array(kc.simulate(models[0], rng.standard_normal(n), 20, rng=rng).y)
    y[[3, 12]] = np.nan
    ours = kc.likelihood.log_likelihoods(models, y)
    np.testing.assert_allclose(ours, [batch_log_likelihood(mdl, y) for mdl in models], rtol=1e-9)
    if m > 1:  # ligne partielle : le calcul modèle par modèle, même résultat
        y[7, 0] = np.nan
        np.testing.assert_allclose(kc.likelihood.log_likelihoods(models, y),
                                   [batch_log_likelihood(mdl, y) for mdl in models], rtol=1e-9)


def test_batched_log_likelihoods_refuse_bad_input():
    y = kc.datasets.nile().flow
    with pytest.raises(kc.KalmanInputError, match="au moins un modèle"):
        kc.likelihood.log_likelihoods([], y)
    with pytest.raises(kc.KalmanInputError, match="models\\[1\\]"):
        kc.likelihood.log_likelihoods([_nile_model("llevel", NILE_LLEVEL), "pas un modèle"], y)
    with pytest.raises(kc.KalmanInputError, match="mêmes dimensions"):
        kc.likelihood.log_likelihoods([_nile_model("llevel", NILE_LLEVEL), _nile_model("lltrend", NILE_LLTREND)], y)
    with pytest.raises(kc.KalmanInputError, match="commande"):
        kc.likelihood.log_likelihoods([kc.LinearGaussianModel(1.0, 1.0, 1.0, 1.0, B=1.0)], y)
    with pytest.raises(kc.KalmanInputError, match="déterminent pas"):
        kc.likelihood.log_likelihoods([_nile_model("lltrend", NILE_LLTREND)], y[:1])


def test_terms_sum_to_the_log_likelihood_and_missing_steps_add_nothing():
    y = kc.datasets.nile(missing=True).flow
    model = _nile_model("llevel", NILE_LLEVEL)
    res = kc.kalman_filter(model, y, 1000.0, 5000.0)
    terms = kc.log_likelihood_terms(res)
    assert (terms[np.isnan(y)] == 0.0).all()
    k = 5  # le terme d'un pas : −½(log 2π + log S + ν²/S)
    S, nu = res.S[k, 0, 0], res.innovation[k, 0]
    assert terms[k] == pytest.approx(-0.5 * (np.log(2 * np.pi) + np.log(S) + nu**2 / S), rel=1e-12)
    assert kc.log_likelihood(model, y, 1000.0, 5000.0) == pytest.approx(terms.sum(), rel=1e-12)


@pytest.mark.parametrize("trend,params", [("llevel", NILE_LLEVEL), ("lltrend", NILE_LLTREND)])
def test_srif_started_without_information_gives_the_diffuse_likelihood(trend, params):
    """ALGORITHMS § 11.5 : somme des termes après les d premières mesures − (d/2) log 2π."""
    y = kc.datasets.nile().flow
    model = _nile_model(trend, params)
    terms = kc.log_likelihood_terms(kc.square_root_information_filter(model, y))
    d = int(np.isnan(terms).sum())
    assert d == model.n_state
    value = np.nansum(terms) - 0.5 * d * np.log(2 * np.pi)
    assert value == pytest.approx(kc.log_likelihood(model, y), abs=1e-8)


# --------------------------------------------------------------------------- maximum de vraisemblance


@pytest.fixture(scope="module")
def nile_mle():
    y = kc.datasets.nile().flow
    ours = kc.maximum_likelihood(_local_level, y, np.log([10000.0, 1000.0]))
    ref = sm.tsa.UnobservedComponents(y, "llevel", use_exact_diffuse=True).fit(disp=False)
    return ours, ref


def test_maximum_likelihood_reaches_statsmodels_maximum_on_the_nile(nile_mle):
    ours, ref = nile_mle
    var = np.exp(ours.theta)
    rel = var / ref.params - 1
    print(f"\nMV du Nil : kalman_course log L = {fs(ours.log_likelihood, '.6f')}, statsmodels {fs(ref.llf, '.6f')} "
          f"(écart {fs(ours.log_likelihood - ref.llf, '+.2e')})")
    print(f"  σ²_ε = {fs(var[0], '.1f')} (statsmodels {fs(ref.params[0], '.1f')}, {fs(rel[0], '+.2%')}), "
          f"σ²_η = {fs(var[1], '.1f')} (statsmodels {fs(ref.params[1], '.1f')}, {fs(rel[1], '+.2%')})")
    assert ours.converged
    assert abs(ours.log_likelihood - ref.llf) < 1e-3
    assert ours.log_likelihood >= ref.llf - 1e-6  # pas moins bon que statsmodels
    assert np.all(np.abs(rel) < 0.03)
    assert isinstance(ours.model, kc.LinearGaussianModel)
    assert ours.model.R[0, 0] == pytest.approx(var[0])


def test_maximum_is_a_stationary_point_with_negative_definite_hessian(nile_mle):
    ours, _ = nile_mle
    y = kc.datasets.nile().flow
    h = 1e-4
    for i in range(2):
        e = np.zeros(2)
        e[i] = h
        grad = (kc.log_likelihood(_local_level(ours.theta + e), y) - kc.log_likelihood(_local_level(ours.theta - e), y)) / (2 * h)
        assert abs(grad) < 1e-3
    assert np.linalg.eigvalsh(ours.hessian).max() < 0
    # hessienne contre des différences centrées indépendantes
    H = np.empty((2, 2))
    h = 1e-3
    for i in range(2):
        for j in range(2):
            ei, ej = np.eye(2)[i] * h, np.eye(2)[j] * h
            f = [kc.log_likelihood(_local_level(ours.theta + a + b), y) for a, b in
                 ((ei, ej), (ei, -ej), (-ei, ej), (-ei, -ej))]
            H[i, j] = (f[0] - f[1] - f[2] + f[3]) / (4 * h * h)
    np.testing.assert_allclose(ours.hessian, H, rtol=1e-4)
    np.testing.assert_allclose(ours.standard_errors, np.sqrt(np.diag(np.linalg.inv(-H))), rtol=1e-4)


def test_standard_errors_agree_with_statsmodels_by_the_delta_method(nile_mle):
    ours, ref = nile_mle
    """statsmodels donne par défaut les écarts-types du produit des gradients (« opg ») ; on compare à sa
    hessienne numérique (``cov_params_approx``), en des optimums un peu différents (surface plate)."""
    se_var = np.exp(ours.theta) * ours.standard_errors  # σ² = e^θ : se(σ²) = σ² se(θ) au maximum
    se_ref = np.sqrt(np.diag(ref.cov_params_approx))
    print(f"\nécarts-types de (σ²_ε, σ²_η) : kalman_course {format_array(se_var, decimals=1)}, "
          f"statsmodels (hessienne) {format_array(se_ref, decimals=1)}")
    np.testing.assert_allclose(se_var, se_ref, rtol=0.05)


# --------------------------------------------------------------------------- EM


@pytest.mark.parametrize("missing", [False, True])
def test_em_never_decreases_and_reaches_the_maximum_likelihood(missing):
    y = kc.datasets.nile(missing=missing).flow
    em = kc.expectation_maximization(_nile_model("llevel", [10000.0, 1000.0]), y, max_iter=3000, tol=1e-12)
    mle = kc.maximum_likelihood(_local_level, y, np.log([10000.0, 1000.0]))
    steps = np.diff(em.history)
    print(f"\nEM (manquantes : {'oui' if missing else 'non'}) : {fs(em.n_iter, 'd')} itérations, "
          f"log L {fs(em.log_likelihood, '.8f')}, MV {fs(mle.log_likelihood, '.8f')} ; plus petit pas {fs(steps.min(), '.2e')}")
    assert (steps >= -1e-9).all()  # jamais de baisse (aux arrondis près)
    assert em.converged
    assert em.log_likelihood == pytest.approx(mle.log_likelihood, abs=1e-5)
    np.testing.assert_allclose([em.model.R[0, 0], em.model.Q[0, 0]], np.exp(mle.theta), rtol=2e-3)
    # l'historique est celui des modèles itérés
    k = 3
    iterate = kc.LinearGaussianModel(1.0, 1.0, em.Q[k], em.R[k])
    assert em.history[k] == pytest.approx(kc.log_likelihood(iterate, y), rel=1e-12)


def test_em_with_known_prior_and_partial_rows_reaches_the_maximum_likelihood():
    """Un état (marche aléatoire), deux capteurs aux bruits corrélés, des composantes manquantes."""
    rng = np.random.default_rng(21)
    truth = kc.LinearGaussianModel(1.0, [[1.0], [1.0]], 0.5, [[1.0, 0.3], [0.3, 2.0]])
    y = np.array(kc.simulate(truth, [0.0], 150, rng=rng).y)
    y[rng.random(150) < 0.2, 0] = np.nan
    y[rng.random(150) < 0.2, 1] = np.nan
    x0, P0 = 0.0, 1.0

    def build(theta):
        L = np.array([[np.exp(theta[1]), 0.0], [theta[2], np.exp(theta[3])]])
        return kc.LinearGaussianModel(1.0, [[1.0], [1.0]], np.exp(theta[0]), L @ L.T)

    start = kc.LinearGaussianModel(1.0, [[1.0], [1.0]], 1.0, np.eye(2))
    em = kc.expectation_maximization(start, y, x0, P0, max_iter=5000, tol=1e-13)
    assert (np.diff(em.history) >= -1e-9).all()
    mle = kc.maximum_likelihood(build, y, np.zeros(4), x0, P0)
    print(f"\nEM (a priori connu, lignes partielles) : {fs(em.n_iter, 'd')} itérations, "
          f"log L {fs(em.log_likelihood, '.8f')}, MV {fs(mle.log_likelihood, '.8f')}")
    assert em.log_likelihood == pytest.approx(mle.log_likelihood, abs=1e-5)
    np.testing.assert_allclose(em.model.Q, mle.model.Q, rtol=5e-3)
    np.testing.assert_allclose(em.model.R, mle.model.R, rtol=5e-3, atol=5e-3)


def test_em_m_step_maximises_the_expected_complete_log_likelihood():
    """L'étape M contre un optimiseur : on maximise numériquement l'espérance de la log-vraisemblance
    complète (écrite indépendamment, en traces) sur les moments du lisseur."""
    import scipy.optimize

    rng = np.random.default_rng(2)
    model = random_model(rng, 2, 2, 0)
    y = np.array(kc.simulate(model, np.zeros(2), 40, rng=rng).y)
    x0, P0 = np.zeros(2), np.eye(2)
    _, new = kc.likelihood.em_step(model, y, x0, P0, None)
    sm_ = kc.rts_smoother(model, kc.kalman_filter(model, y, x0, P0), x0, P0)
    A, C = np.array(model.A), np.array(model.C)
    xs = np.vstack([sm_.x_initial, sm_.x])
    Ps = np.concatenate([sm_.P_initial[None], sm_.P])

    def expected(theta):
        Lq = np.array([[np.exp(theta[0]), 0], [theta[1], np.exp(theta[2])]])
        Lr = np.array([[np.exp(theta[3]), 0], [theta[4], np.exp(theta[5])]])
        Q, R = Lq @ Lq.T, Lr @ Lr.T
        Qi, Ri = np.linalg.inv(Q), np.linalg.inv(R)
        total = 0.0
        for k in range(1, xs.shape[0]):
            r = xs[k] - A @ xs[k - 1]
            M = np.outer(r, r) + Ps[k] - sm_.P_lag[k - 1] @ A.T - A @ sm_.P_lag[k - 1].T + A @ Ps[k - 1] @ A.T
            total += -0.5 * (np.linalg.slogdet(Q)[1] + np.trace(Qi @ M))
            e = y[k - 1] - C @ xs[k]
            total += -0.5 * (np.linalg.slogdet(R)[1] + np.trace(Ri @ (np.outer(e, e) + C @ Ps[k] @ C.T)))
        return -total

    opt = scipy.optimize.minimize(expected, np.zeros(6), method="BFGS", options={"gtol": 1e-9})
    Lq = np.array([[np.exp(opt.x[0]), 0], [opt.x[1], np.exp(opt.x[2])]])
    Lr = np.array([[np.exp(opt.x[3]), 0], [opt.x[4], np.exp(opt.x[5])]])
    np.testing.assert_allclose(new.Q, Lq @ Lq.T, rtol=1e-4, atol=1e-6)
    np.testing.assert_allclose(new.R, Lr @ Lr.T, rtol=1e-4, atol=1e-6)


# --------------------------------------------------------------------------- entrées invalides


def test_build_must_return_a_model():
    y = kc.datasets.nile().flow
    with pytest.raises(kc.KalmanInputError, match="« build » doit renvoyer un LinearGaussianModel"):
        kc.maximum_likelihood(lambda t: np.exp(t), y, [1.0, 2.0])
    with pytest.raises(kc.KalmanInputError, match="« build » doit être une fonction"):
        kc.maximum_likelihood("modèle", y, [1.0, 2.0])


def test_theta0_of_the_wrong_length():
    y = kc.datasets.nile().flow
    with pytest.raises(kc.KalmanInputError, match="bonne longueur"):
        kc.maximum_likelihood(_local_level, y, [9.0])  # trop court : build échoue (IndexError)
    with pytest.raises(kc.KalmanInputError, match="composante 2 de « theta0 » n'agit pas"):
        kc.maximum_likelihood(_local_level, y, [9.0, 7.0, 1.0])  # trop long : une composante inutile
    with pytest.raises(kc.KalmanInputError, match="« theta0 » doit être un vecteur"):
        kc.maximum_likelihood(_local_level, y, [[9.0, 7.0]])


def test_likelihood_must_be_finite_at_theta0():
    y = kc.datasets.nile().flow
    with pytest.raises(kc.KalmanInputError, match="« build » a refusé theta0"):
        kc.maximum_likelihood(lambda t: kc.LinearGaussianModel(1.0, 1.0, t[1], t[0]), y, [-1.0, 1.0])
    with pytest.raises(kc.KalmanInputError, match="n'est pas finie en « theta0 »"):
        kc.maximum_likelihood(_local_level, y * 1e200, [0.0, 0.0])


def test_log_likelihood_input_errors():
    y = kc.datasets.nile().flow
    model = _nile_model("llevel", NILE_LLEVEL)
    with pytest.raises(kc.KalmanInputError, match="vont ensemble"):
        kc.log_likelihood(model, y, x0=1000.0)
    with pytest.raises(kc.KalmanInputError, match="« model » doit être un LinearGaussianModel"):
        kc.log_likelihood(kc.NonlinearModel.from_linear(model), y)
    unobservable = kc.LinearGaussianModel(np.eye(2), [[1.0, 0.0]], np.eye(2), 1.0)
    with pytest.raises(kc.KalmanInputError, match="ne déterminent pas l'état"):
        kc.log_likelihood(unobservable, y)
    srif = kc.square_root_information_filter(model, y)
    with pytest.raises(kc.KalmanInputError, match="prédiction non déterminée"):
        kc.filter_log_likelihood(srif)


def test_em_input_errors():
    y = kc.datasets.nile().flow
    model = _nile_model("llevel", NILE_LLEVEL)
    with pytest.raises(kc.KalmanInputError, match="max_iter"):
        kc.expectation_maximization(model, y, max_iter=0)
    with pytest.raises(kc.KalmanInputError, match="tol"):
        kc.expectation_maximization(model, y, tol=-1.0)
    with pytest.raises(kc.KalmanInputError, match="aucune mesure"):
        kc.expectation_maximization(model, np.full(10, np.nan))
    with pytest.raises(kc.KalmanInputError, match="« model » doit être un LinearGaussianModel"):
        kc.expectation_maximization(kc.NonlinearModel.from_linear(model), y)


# --------------------------------------------------------------------------- données


def test_nile_dataset():
    nile = kc.datasets.nile()
    assert nile.year[0] == 1871 and nile.year[-1] == 1970 and len(nile) == 100
    assert nile.flow[0] == 1120.0 and not nile.missing.any()
    dk = kc.datasets.nile(missing=True)
    assert dk.missing.sum() == 40
    assert dk.year[dk.missing].tolist() == list(range(1891, 1911)) + list(range(1931, 1951))
    np.testing.assert_array_equal(dk.flow[~dk.missing], nile.flow[~dk.missing])
    with pytest.raises(ValueError):
        nile.flow[0] = 0.0
    with pytest.raises(kc.KalmanInputError, match="missing"):
        kc.datasets.nile(missing="oui")


def test_import_kalman_course_does_not_import_statsmodels():
    import subprocess
    import sys

    code = "import sys, kalman_course; print('statsmodels' in sys.modules, 'pandas' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "False"]


@pytest.mark.parametrize("missing", [False, True])
def test_em_fast_e_step_equals_the_public_filter_and_smoother(missing):
    """L'étape E d'EM (filtre augmenté, information et lissage exact sans vérifications) redonne ce que
    donnent diffuse_kalman_filter, filter_log_likelihood et rts_smoother, et l'étape M qui en découle."""
    from kalman_course.filters.smoothers import diffuse_rts_pass
    from kalman_course.likelihood import em_step

    y = kc.datasets.nile(missing=missing).flow
    model = kc.LinearGaussianModel(1.0, 1.0, 2000.0, 9000.0)
    res = kc.diffuse_kalman_filter(model, y)
    sm = kc.rts_smoother(model, res)
    xs, Ps, lag = diffuse_rts_pass(model.A, res.augmented, res.information[-1], res.information_vector[-1])
    np.testing.assert_allclose(xs, sm.x, rtol=1e-12)
    np.testing.assert_allclose(Ps, sm.P, rtol=1e-12)
    np.testing.assert_allclose(lag[1:], sm.P_lag[1:], rtol=1e-12)
    ll, new = em_step(model, y[:, None], None, None, None)
    assert ll == pytest.approx(kc.filter_log_likelihood(res), abs=1e-9)
    # étape M à la main, depuis le lisseur public (mesures complètes seulement)
    if not missing:
        r = sm.x[1:, 0] - sm.x[:-1, 0]
        Q_ref = np.mean(r**2 + sm.P[1:, 0, 0] - 2 * sm.P_lag[1:, 0, 0] + sm.P[:-1, 0, 0])
        R_ref = np.mean((y - sm.x[:, 0]) ** 2 + sm.P[:, 0, 0])
        assert new.Q[0, 0] == pytest.approx(Q_ref, rel=1e-10)
        assert new.R[0, 0] == pytest.approx(R_ref, rel=1e-10)


# --------------------------------------------------------------------------- a priori vague


def test_vague_prior_likelihood_em_and_monte_carlo_run_and_tend_to_the_diffuse_limit():
    """P₀ = 10¹⁰ I à 10¹⁴ I sur la vitesse constante au millimètre (Q de rang 2) : log L + (n/2) log κ tend vers
    la vraisemblance diffuse exacte (Durbin & Koopman : L_d = lim κ^{n/2} L_κ, det A = 1) ; EM tourne,
    ne décroît jamais, et son Q ne dépend plus de κ (à 10⁻⁶ près, relatif) ; le Monte-Carlo en lot tourne."""
    import math

    model, y = kc.scenarios.diffuse.diffuse_model(), kc.scenarios.diffuse.diffuse_data()[1]
    diffuse = kc.log_likelihood(model, y)
    Qs = []
    for exponent in (10, 12, 14):
        kappa = 10.0**exponent
        ll = kc.log_likelihood(model, y, np.zeros(4), kappa * np.eye(4))
        assert abs(ll + 2.0 * math.log(kappa) - diffuse) < 1e-4
        em = kc.expectation_maximization(model, y, np.zeros(4), kappa * np.eye(4), max_iter=15)
        assert np.all(np.diff(em.history) >= -1e-9 * np.abs(em.history[1:]))
        Qs.append(em.model.Q)
        mc = kc.monte_carlo(model, None, 20, 50, x0_mean=np.zeros(4), x0_cov=np.eye(4), x0_hat=np.zeros(4),
                            P0=kappa * np.eye(4), rng=1)
        assert np.isfinite(mc.x_hat).all()
    for Q in Qs[1:]:
        np.testing.assert_allclose(Q, Qs[0], rtol=0, atol=1e-6 * np.abs(Qs[0]).max())
