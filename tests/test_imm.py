"""Filtre IMM : contre ``IMMEstimator`` de filterpy (predict() puis update(z) à chaque pas), un régime =
filtre de Kalman, mesures manquantes, régimes variables dans le temps, et entrées invalides."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from filterpy.kalman import IMMEstimator, KalmanFilter

import kalman_course as kc
from kalman_course.scenarios._motion import simulate_turning


def two_modes(dt=1.0, q_quiet=0.05, q_manoeuvre=20.0, sigma=5.0):
    C = np.eye(4)[:2]
    R = sigma**2 * np.eye(2)
    models = []
    for q in (q_quiet, q_manoeuvre):
        A, Q = kc.constant_velocity(dt, q, dim=2)
        models.append(kc.LinearGaussianModel(A, C, Q, R))
    return models


TRANSITION = np.array([[0.97, 0.03], [0.10, 0.90]])


def turning_track(T=120, seed=0, sigma=5.0):
    """Une cible à 60 m/s qui vire à 0,1 rad/s de 40 à 70 s (le simulateur des scénarios)."""
    rate = np.where((np.arange(T) >= 40) & (np.arange(T) < 70), 0.1, 0.0)
    return simulate_turning(rate, [0.0, 0.0, 60.0, 0.0], 1.0, sigma, np.random.default_rng(seed))


def _no_information(imm, m):
    for f in imm.filters:
        f.R_saved = f.R
        f.R = 1e20 * np.eye(m)
    imm.update(np.zeros((m, 1)))
    for f in imm.filters:
        f.R = f.R_saved


def filterpy_imm(models, y, x0, P0, transition, mu0):
    filters = []
    for model in models:
        f = KalmanFilter(dim_x=model.n_state, dim_z=model.n_obs)
        f.F, f.H, f.Q, f.R = (np.array(a) for a in (model.A, model.C, model.Q, model.R))
        f.x = np.asarray(x0, float).reshape(-1, 1).copy()
        f.P = np.asarray(P0, float).copy()
        filters.append(f)
    imm = IMMEstimator(filters, np.array(mu0, float), np.array(transition, float))
    xs, Ps, mus, modes = [], [], [], []
    for z in y:
        imm.predict()
        if np.isnan(z).all():
            # mesure absente : une mesure sans information (R = 10²⁰ I), seule façon de faire passer les
            # probabilités des régimes par la chaîne de Markov dans filterpy (qui, sans update(), garde μ)
            _no_information(imm, len(z))
        else:
            imm.update(z.reshape(-1, 1))
        xs.append(imm.x.ravel().copy())
        Ps.append(imm.P.copy())
        mus.append(np.array(imm.mu).copy())
        modes.append([f.x.ravel().copy() for f in imm.filters])
    return np.array(xs), np.array(Ps), np.array(mus), np.array(modes)


@pytest.mark.parametrize("seed", [0, 1])
def test_imm_equals_filterpy_immestimator(seed):
    models = two_modes()
    _, y = turning_track(seed=seed)
    x0, P0 = np.array([0.0, 0.0, 60.0, 0.0]), np.diag([25.0, 25.0, 10.0, 10.0])
    res = kc.imm_filter(models, y, x0, P0, transition=TRANSITION, mu0=[0.9, 0.1])
    x, P, mu, modes = filterpy_imm(models, y, x0, P0, TRANSITION, [0.9, 0.1])
    assert np.allclose(res.x, x, rtol=1e-9, atol=1e-9)
    assert np.allclose(res.P, P, rtol=1e-9, atol=1e-9)
    assert np.allclose(res.mu, mu, rtol=1e-9, atol=1e-12)
    assert np.allclose(res.x_modes, modes, rtol=1e-9, atol=1e-9)


def test_imm_with_missing_measurements_equals_filterpy():
    """Sans mesure, l'IMM du paquet ne fait que la prédiction et rend les probabilités prédites
    c̄ = μ Π. filterpy, si l'on saute update(), garderait μ et ses poids de mélange d'avant
    (la chaîne de Markov ne tourne pas) : on lui donne une mesure sans information (R = 10²⁰ I), qui ne
    change ni les estimations ni les probabilités au-delà des arrondis."""
    models = two_modes()
    _, y = turning_track(T=60, seed=3)
    y[[10, 11, 30]] = np.nan
    x0, P0 = np.array([0.0, 0.0, 60.0, 0.0]), np.eye(4) * 25.0
    res = kc.imm_filter(models, y, x0, P0, transition=TRANSITION, mu0=[0.5, 0.5])
    x, P, mu, modes = filterpy_imm(models, y, x0, P0, TRANSITION, [0.5, 0.5])
    assert np.allclose(res.x_modes, modes, rtol=1e-9, atol=1e-9)
    assert np.allclose(res.x, x, rtol=1e-9, atol=1e-9)
    assert np.allclose(res.P, P, rtol=1e-9, atol=1e-9)
    assert np.allclose(res.mu, mu, rtol=1e-9, atol=1e-12)
    assert np.allclose(res.mu[10], res.mu_pred[10]) and np.allclose(res.mu_pred[10], mu[9] @ TRANSITION)


def test_one_mode_is_the_kalman_filter():
    model = two_modes()[0]
    _, y = turning_track(T=50, seed=4)
    y[7] = np.nan
    y[12, 1] = np.nan
    x0, P0 = np.array([0.0, 0.0, 60.0, 0.0]), np.eye(4) * 25.0
    res = kc.imm_filter([model], y, x0, P0, transition=[[1.0]])
    kf = kc.kalman_filter(model, y, x0, P0)
    for field in ("x", "P", "x_pred", "P_pred", "K", "innovation", "S"):
        a, b = getattr(res, field), getattr(kf, field)
        assert np.allclose(a, b, rtol=1e-12, atol=1e-12, equal_nan=True), field
    assert np.all(res.mu == 1.0)


def test_two_identical_modes_are_the_kalman_filter_whatever_the_switching():
    model = two_modes()[0]
    _, y = turning_track(T=40, seed=5)
    x0, P0 = np.array([0.0, 0.0, 60.0, 0.0]), np.eye(4) * 25.0
    res = kc.imm_filter([model, model], y, x0, P0, transition=[[0.6, 0.4], [0.3, 0.7]], mu0=[0.2, 0.8])
    kf = kc.kalman_filter(model, y, x0, P0)
    assert np.allclose(res.x, kf.x, rtol=1e-10, atol=1e-10) and np.allclose(res.P, kf.P, rtol=1e-10, atol=1e-10)
    # vraisemblances égales : les probabilités ne font que suivre la chaîne de Markov, μ_k = μ₀ Πᵏ⁺¹
    Pi = np.array([[0.6, 0.4], [0.3, 0.7]])
    chain = np.array([[0.2, 0.8] @ np.linalg.matrix_power(Pi, k + 1) for k in range(40)])
    assert np.allclose(res.mu, chain, rtol=1e-12, atol=1e-14)


def test_the_manoeuvring_mode_wins_during_the_turn():
    models = two_modes()
    truth, y = turning_track(T=120, seed=6)
    res = kc.imm_filter(models, y, [0.0, 0.0, 60.0, 0.0], np.eye(4) * 25.0, transition=TRANSITION, mu0=[0.9, 0.1])
    assert res.mu[45:70, 1].mean() > 0.8     # pendant le virage
    assert res.mu[90:, 0].mean() > 0.8       # en ligne droite
    err = lambda r: np.sqrt(np.mean(np.sum((r.x[40:80, :2] - truth[40:80, :2]) ** 2, axis=1)))
    quiet = kc.kalman_filter(models[0], y, [0.0, 0.0, 60.0, 0.0], np.eye(4) * 25.0)
    assert err(res) < 0.5 * err(quiet)


def test_time_varying_modes_equal_filterpy_with_per_step_matrices():
    """Instants irréguliers : chaque régime est un modèle variable dans le temps ; filterpy reçoit les
    matrices du pas avant chaque predict()."""
    rng = np.random.default_rng(7)
    T = 50
    dts = rng.uniform(0.4, 6.0, T)
    C, R = np.eye(4)[:2], 16.0 * np.eye(2)
    models = []
    for q in (0.02, 8.0):
        A, Q = kc.constant_velocity(dts, q, dim=2)
        models.append(kc.LinearGaussianModel(A, C, Q, R))
    y = np.cumsum(rng.standard_normal((T, 2)) * 30.0, axis=0)
    x0, P0 = np.zeros(4), np.diag([100.0, 100.0, 400.0, 400.0])
    res = kc.imm_filter(models, y, x0, P0, transition=TRANSITION)
    filters = []
    for model in models:
        f = KalmanFilter(dim_x=4, dim_z=2)
        f.H, f.R = C.copy(), R.copy()
        f.x, f.P = x0.reshape(4, 1).copy(), P0.copy()
        filters.append(f)
    imm = IMMEstimator(filters, np.array([0.5, 0.5]), TRANSITION.copy())
    for k in range(T):
        for f, model in zip(imm.filters, models):
            f.F, f.Q = model.A[k], model.Q[k]
        imm.predict()
        imm.update(y[k].reshape(2, 1))
        assert np.allclose(res.x[k], imm.x.ravel(), rtol=1e-9, atol=1e-9)
        assert np.allclose(res.mu[k], imm.mu, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("kwargs, message", [
    (dict(transition=[[0.9, 0.2], [0.1, 0.9]]), "ligne 0 doit valoir 1"),
    (dict(transition=[[1.1, -0.1], [0.1, 0.9]]), "probabilités"),
    (dict(transition=np.eye(3)), r"\(2, 2\)"),
    (dict(transition=np.eye(2), mu0=[0.5, 0.6]), "somme doit valoir 1"),
    (dict(transition=np.eye(2), mu0=[1.0]), r"forme \(2,\)"),
])
def test_bad_imm_input_is_refused_in_french(kwargs, message):
    models = two_modes()
    with pytest.raises(kc.KalmanInputError, match=message):
        kc.imm_filter(models, np.zeros((3, 2)), np.zeros(4), np.eye(4), **kwargs)


def test_modes_of_different_dimensions_are_refused():
    a = two_modes()[0]
    b = kc.LinearGaussianModel(np.eye(2), np.eye(2), np.eye(2), np.eye(2))
    with pytest.raises(kc.KalmanInputError, match="partagent"):
        kc.imm_filter([a, b], np.zeros((3, 2)), np.zeros(4), np.eye(4), transition=np.eye(2))
    with pytest.raises(kc.KalmanInputError, match="liste"):
        kc.imm_filter(a, np.zeros((3, 2)), np.zeros(4), np.eye(4), transition=np.eye(1))


def test_imm_modes_and_most_likely_mode_equal_filterpy():
    """Chaque régime (estimation et covariance) et le régime le plus probable, contre IMMEstimator ; le
    résultat est immuable."""
    models = two_modes()
    _, y = turning_track(T=80, seed=2)
    x0, P0 = np.zeros(4), np.eye(4) * 100.0
    res = kc.imm_filter(models, y, x0, P0, transition=TRANSITION)
    filters = []
    for model in models:
        f = KalmanFilter(dim_x=4, dim_z=2)
        f.F, f.H, f.Q, f.R = (np.array(a) for a in (model.A, model.C, model.Q, model.R))
        f.x, f.P = x0.reshape(4, 1).copy(), P0.copy()
        filters.append(f)
    imm = IMMEstimator(filters, np.array([0.5, 0.5]), TRANSITION.copy())
    for k, z in enumerate(y):
        imm.predict()
        imm.update(z.reshape(2, 1))
        for j, f in enumerate(imm.filters):
            np.testing.assert_allclose(res.P_modes[k, j], f.P, rtol=1e-9, atol=1e-9)
            np.testing.assert_allclose(res.x_modes[k, j], f.x.ravel(), rtol=1e-9, atol=1e-9)
        assert res.mode[k] == int(np.argmax(imm.mu))
    with pytest.raises(ValueError):
        res.mu[0, 0] = 0.3
    copy.deepcopy(res)


# --------------------------------------------------------------------------- vraisemblance du mélange


def filterpy_mixture_log_likelihood(imm, y):
    """Σ_k log Σ_j c̄_j ℓ_j avec les vraisemblances ℓ_j que calcule chaque filtre de filterpy à sa correction
    (``f.likelihood``) et les probabilités prédites c̄ d'IMMEstimator : une référence indépendante."""
    total = 0.0
    for z in y:
        imm.predict()
        cbar = imm.cbar.copy()
        if np.isnan(z).all():
            _no_information(imm, len(z))
            continue
        imm.update(z.reshape(-1, 1))
        total += np.log(sum(c * f.likelihood for c, f in zip(cbar, imm.filters)))
    return total


def test_imm_log_likelihood_is_the_mixture_likelihood():
    """filter_log_likelihood(imm) = Σ_k log Σ_j c̄_j N(ν_j; 0, S_j), contre filterpy (une ligne manquante
    comprise) — et non la vraisemblance de la gaussienne de mêmes moments (innovation et S du résultat),
    qui est plus petite ici (mesuré : −139,03 contre −139,60 sur les 20 premiers pas)."""
    models = two_modes()
    _, y = turning_track(T=60, seed=8)
    y[25] = np.nan
    x0, P0 = np.array([0.0, 0.0, 60.0, 0.0]), np.diag([25.0, 25.0, 10.0, 10.0])
    res = kc.imm_filter(models, y, x0, P0, transition=TRANSITION, mu0=[0.9, 0.1])
    filters = []
    for model in models:
        f = KalmanFilter(dim_x=4, dim_z=2)
        f.F, f.H, f.Q, f.R = (np.array(a) for a in (model.A, model.C, model.Q, model.R))
        f.x, f.P = x0.reshape(4, 1).copy(), P0.copy()
        filters.append(f)
    ref = filterpy_mixture_log_likelihood(IMMEstimator(filters, np.array([0.9, 0.1]), TRANSITION.copy()), y)
    assert kc.filter_log_likelihood(res) == pytest.approx(ref, rel=1e-10)
    assert res.log_likelihood_increments[25] == 0.0
    moments = kc.FilterResult(x=res.x, P=res.P, x_pred=res.x_pred, P_pred=res.P_pred, K=res.K,
                              innovation=res.innovation, S=res.S, observed=res.observed, n_iter=res.n_iter)
    assert abs(kc.filter_log_likelihood(moments) - ref) > 0.1  # l'ancien nombre, qui voulait dire autre chose
    np.testing.assert_array_equal(kc.log_likelihood_terms(res), res.log_likelihood_increments)


# --------------------------------------------------------------------------- régimes non linéaires


def cv_ct_modes(dt=1.0, sigma=5.0):
    """Vitesse constante (linéaire, ω ignorée) et virage coordonné (non linéaire) sur l'état
    [x, y, vx, vy, ω] : l'IMM de pistage classique."""
    A, Q = kc.constant_velocity(dt, 0.1, dim=2)
    A5, Q5 = np.eye(5), np.zeros((5, 5))
    A5[:4, :4], Q5[:4, :4], Q5[4, 4] = A, Q, 1e-6
    cv = kc.LinearGaussianModel(A5, np.eye(5)[:2], Q5, sigma**2 * np.eye(2))
    ct = kc.coordinated_turn(dt, 0.1, 1e-3, sigma**2 * np.eye(2))
    return cv, ct


def filterpy_ekf_modes(models, x0, P0):
    """Les régimes pour IMMEstimator : ExtendedKalmanFilter de filterpy, predict() écrit ici
    (x = f(x), P = FPFᵀ + Q), update(z) celui de filterpy avec la jacobienne de h."""
    from filterpy.kalman import ExtendedKalmanFilter

    class Mode(ExtendedKalmanFilter):
        def __init__(self, model):
            super().__init__(dim_x=model.n_state, dim_z=model.n_obs)
            self.model = model
            self.Q, self.R = np.array(model.Q), np.array(model.R)
            self.x, self.P = np.asarray(x0, float).reshape(-1, 1).copy(), np.asarray(P0, float).copy()

        def predict(self, u=None):
            x = self.x.ravel()
            F = self.model.transition_jacobian(x)
            self.x = self.model.transition(x).reshape(-1, 1)
            self.P = F @ self.P @ F.T + self.Q

        def update(self, z):
            super().update(z, lambda x: self.model.observation_jacobian(x.ravel()),
                           lambda x: self.model.observe(x.ravel()).reshape(-1, 1))

    return [Mode(kc.NonlinearModel.from_linear(m) if isinstance(m, kc.LinearGaussianModel) else m) for m in models]


def test_cv_and_coordinated_turn_imm_with_ekf_modes_equals_filterpy():
    """L'IMM vitesse constante / virage coordonné à régimes EKF (issue 37) contre IMMEstimator de filterpy
    sur des ExtendedKalmanFilter : estimation combinée, covariance, probabilités et vraisemblance du mélange
    à 10⁻⁹ ; le régime « virage » l'emporte pendant le virage."""
    cv, ct = cv_ct_modes()
    truth, y = turning_track(T=100, seed=11)
    x0, P0 = np.array([0.0, 0.0, 60.0, 0.0, 0.0]), np.diag([25.0, 25.0, 10.0, 10.0, 0.01])
    Pi = np.array([[0.95, 0.05], [0.05, 0.95]])
    res = kc.imm_filter([cv, ct], y, x0, P0, transition=Pi)
    imm = IMMEstimator(filterpy_ekf_modes([cv, ct], x0, P0), np.array([0.5, 0.5]), Pi.copy())
    for k, z in enumerate(y):
        imm.predict()
        imm.update(z.reshape(2, 1))
        np.testing.assert_allclose(res.x[k], imm.x.ravel(), rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(res.P[k], imm.P, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(res.mu[k], imm.mu, rtol=1e-9, atol=1e-12)
    ref = filterpy_mixture_log_likelihood(
        IMMEstimator(filterpy_ekf_modes([cv, ct], x0, P0), np.array([0.5, 0.5]), Pi.copy()), y)
    assert kc.filter_log_likelihood(res) == pytest.approx(ref, rel=1e-10)
    assert res.mu[50:70, 1].mean() > 0.8 and res.mu[85:, 0].mean() > 0.6
    cv_only = kc.kalman_filter(cv, y, x0, P0)
    err = lambda r: np.sqrt(np.mean(np.sum((r.x[45:75, :2] - truth[45:75, :2]) ** 2, axis=1)))  # noqa: E731
    assert err(res) < 0.7 * err(cv_only)


@pytest.mark.parametrize("rule", [kc.Linearization(), kc.CubatureRule(), kc.UnscentedRule(1.0, 2.0, 0.0),
                                  kc.GaussHermiteRule(order=2)], ids=["EKF", "CKF", "UKF", "GHKF"])
def test_any_gaussian_member_runs_the_modes_of_a_linear_imm(rule):
    """Sur des régimes linéaires, chaque membre du filtre gaussien redonne l'IMM de filtres de Kalman
    (filterpy) : ``rule=`` choisit le membre qui filtre les régimes."""
    models = two_modes()
    _, y = turning_track(T=50, seed=4)
    y[[5, 6]] = np.nan
    x0, P0 = np.array([0.0, 0.0, 60.0, 0.0]), np.diag([25.0, 25.0, 10.0, 10.0])
    res = kc.imm_filter(models, y, x0, P0, transition=TRANSITION, rule=rule)
    x, P, mu, _ = filterpy_imm(models, y, x0, P0, TRANSITION, [0.5, 0.5])
    np.testing.assert_allclose(res.x, x, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(res.P, P, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(res.mu, mu, rtol=1e-9, atol=1e-12)


# --------------------------------------------------------------------------- porte par régime


def test_a_measurement_inside_one_mode_gate_is_kept_and_outside_all_is_rejected():
    """Porte de l'IMM : une par régime. Une mesure hors de la porte du régime calme mais dans celle du régime
    agité est gardée (le pas égale celui de l'IMM sans porte) ; hors des deux, elle est rejetée (le pas égale
    celui où la mesure manque) et ne compte pas dans la vraisemblance."""
    models = two_modes(q_quiet=0.01, q_manoeuvre=200.0, sigma=2.0)
    _, y = turning_track(T=30, seed=1, sigma=2.0)
    x0, P0 = np.array([0.0, 0.0, 60.0, 0.0]), np.diag([4.0, 4.0, 1.0, 1.0])
    plain = kc.imm_filter(models, y, x0, P0, transition=TRANSITION)
    k = 20
    assert not plain.rejected.any()
    y_mid, y_far = y.copy(), y.copy()
    y_mid[k] += 25.0    # loin pour le régime calme, plausible pour le régime agité
    y_far[k] += 400.0   # loin pour les deux
    mid = kc.imm_filter(models, y_mid, x0, P0, transition=TRANSITION, gate=0.999)
    ref_mid = kc.imm_filter(models, y_mid, x0, P0, transition=TRANSITION)
    assert not mid.rejected[k]
    np.testing.assert_allclose(mid.x[k], ref_mid.x[k], rtol=1e-12)
    from kalman_course.filters.gating import gate_threshold
    from kalman_course.filters.imm import ModeSet, imm_family
    # le régime calme seul aurait rejeté la mesure : sa NIS dépasse le seuil
    quiet = kc.kalman_filter(models[0], y_mid, x0, P0, gate=0.999)
    assert quiet.rejected[k] and kc.nis(quiet)[k] > gate_threshold(0.999, 2)
    far = kc.imm_filter(models, y_far, x0, P0, transition=TRANSITION, gate=0.999)
    holes = y_far.copy()
    holes[k] = np.nan
    ref_far = kc.imm_filter(models, holes, x0, P0, transition=TRANSITION)
    assert far.rejected[k] and not far.rejected[:k].any()
    np.testing.assert_allclose(far.x, ref_far.x, rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(far.mu, ref_far.mu, rtol=1e-10, atol=1e-12)
    assert kc.filter_log_likelihood(far) == pytest.approx(kc.filter_log_likelihood(ref_far), rel=1e-12)
    assert ModeSet(models, TRANSITION).linear and imm_family().gating
