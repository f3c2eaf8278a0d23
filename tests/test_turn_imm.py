"""L'IMM vitesse constante / virage coordonné (issue 37) : les modèles à pas variable (Δt lu dans la commande)
contre les modèles à pas fixe et la vitesse presque constante de ``constant_velocity`` (discrétisation
numérique, indépendante des formes closes testées), l'IMM à un régime contre l'EKF, l'IMM sur l'hélicoptère
contre IMMEstimator de filterpy (bruit d'état recalculé ici à chaque pas), et les nombres que le chapitre
« Cibles qui manœuvrent » cite, sur les fonctions de scénario qu'il appelle."""

from __future__ import annotations

import numpy as np
import pytest

import kalman_course as kc
from kalman_course.core import motion
from kalman_course.scenarios import helicopter as heli
from kalman_course.scenarios import manoeuvre as man

X = np.array([120.0, -40.0, 30.0, 12.0, 0.0])
STEPS = (0.4, 1.0, 7.5)


def _cv_block(h, q):
    """(A, Q) de la vitesse presque constante sur deux axes, par ``kc.constant_velocity`` (discrétisation
    numérique de l'EDS, pas les formes closes de motion.turn_noise_gain)."""
    return kc.constant_velocity(h, q, dim=2)


# --------------------------------------------------------------------------- modèles à pas variable


@pytest.mark.parametrize("h", STEPS)
@pytest.mark.parametrize("w", [0.21, -0.05, 0.0])
def test_variable_step_turn_model_is_the_fixed_step_model_at_each_step(h, w):
    """Δt dans la commande u = [Δt] : transition, jacobienne et covariance du bruit W Q Wᵀ égales à celles du
    modèle à pas fixe Δt ; le bloc [p, v] du bruit est la Q de ``constant_velocity`` (discrétisation
    numérique), celui de ω vaut q_ω Δt."""
    q, q_w = 0.7, 2e-3
    R = 9.0 * np.eye(2)
    var, fixed = kc.coordinated_turn(None, q, q_w, R), kc.coordinated_turn(h, q, q_w, R)
    x = X.copy()
    x[4] = w
    np.testing.assert_allclose(var.transition(x, [h]), fixed.transition(x), rtol=1e-15, atol=0)
    np.testing.assert_allclose(var.transition_jacobian(x, [h]), fixed.transition_jacobian(x), rtol=1e-15, atol=0)
    Q = var.process_noise(x, [h])
    np.testing.assert_allclose(Q, fixed.Q, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(Q[:4, :4], _cv_block(h, q).Q, rtol=1e-12, atol=1e-15)
    assert Q[4, 4] == pytest.approx(q_w * h, rel=1e-14)
    assert np.all(Q[4, :4] == 0.0)


@pytest.mark.parametrize("h", STEPS)
def test_straight_flight_is_constant_velocity_with_the_turn_rate_reset(h):
    """Le régime ligne droite : [p, v] suivent A de ``constant_velocity`` (à pas fixe et lu dans u), ω est
    remise à 0, et le bruit est celui de ``constant_velocity`` (rien sur ω)."""
    q = 0.3
    A, Q = _cv_block(h, q)
    x = X.copy()
    x[4] = 0.17
    for model, u in ((kc.straight_flight(h, q, np.eye(2)), None), (kc.straight_flight(None, q, np.eye(2)), [h])):
        out = model.transition(x, u)
        np.testing.assert_allclose(out[:4], A @ x[:4], rtol=1e-14)
        assert out[4] == 0.0
        F = model.transition_jacobian(x, u)
        np.testing.assert_allclose(F[:4, :4], A, rtol=1e-14)
        assert np.all(F[4] == 0.0) and np.all(F[:4, 4] == 0.0)
        Qm = model.process_noise(x, u)
        np.testing.assert_allclose(Qm[:4, :4], Q, rtol=1e-12, atol=1e-15)
        assert np.all(Qm[4] == 0.0)


@pytest.mark.parametrize("h", STEPS)
def test_turn_transition_reduces_to_constant_velocity_as_the_turn_rate_vanishes(h):
    """ω → 0 : la transition du virage tend vers A x de ``constant_velocity`` (écart en O(ω), exactement nul à
    ω = 0), sa jacobienne en [p, v] vers A."""
    A = _cv_block(h, 1.0).A
    errors, rates = [], np.array([1e-2, 1e-3, 1e-4, 1e-6])
    for w in rates:
        x = X.copy()
        x[4] = w
        errors.append(np.linalg.norm(motion.turn_transition(x, h)[:2] - (A @ x[:4])[:2]))
        np.testing.assert_allclose(motion.turn_jacobian(x, h)[:4, :4], A, atol=5 * w * h * (1 + h))
    slope = np.array(errors) / rates                             # décroît comme ω : pente |v|Δt²/2
    np.testing.assert_allclose(slope, slope[1], rtol=0.05)
    assert slope[1] == pytest.approx(np.hypot(X[2], X[3]) * h**2 / 2, rel=0.05)
    np.testing.assert_array_equal(motion.turn_transition(X, h)[:4], A @ X[:4])


def test_variable_step_models_need_the_step_in_the_command():
    model = kc.coordinated_turn(None, 1.0, 1e-3, np.eye(2))
    y = np.ones((3, 2))
    with pytest.raises(kc.KalmanInputError, match="« u ».*aucune commande"):
        kc.extended_kalman_filter(model, y, np.zeros(5), np.eye(5))
    with pytest.raises(kc.KalmanInputError, match="« u ».*Δt = -1"):
        kc.extended_kalman_filter(model, y, np.zeros(5), np.eye(5), [[1.0], [-1.0], [1.0]])
    with pytest.raises(kc.KalmanInputError, match="« C »"):
        kc.coordinated_turn(None, 1.0, 1e-3, np.eye(2), C=np.eye(4))


# --------------------------------------------------------------------------- filtres, sur l'hélicoptère


def _helicopter():
    track = heli.helicopter_track("both")
    q, sp, sv = heli.fitted_parameters("both")
    return track, q, np.diag([sp**2] * 2 + [sv**2] * 2), np.asarray(track.dt)[:, None]


@pytest.mark.parametrize("which", [0, 1], ids=["ligne droite", "virage"])
def test_one_mode_imm_is_the_ekf_of_that_mode(which):
    """Un seul régime (ligne droite ou virage, pas variable, mesures partielles de l'hélicoptère) : l'IMM est
    ``kc.extended_kalman_filter`` du même modèle, à 10⁻¹⁰."""
    track, _, R, u = _helicopter()
    mode = man.cv_ct_modes(None, 0.1, 1.0, 1e-3, R, C=np.eye(5)[:4])[which]
    x0, P0 = man.turn_state_prior(track.x0, track.P0)
    imm = kc.imm_filter([mode], track.y, x0, P0, u, transition=[[1.0]])
    ekf = kc.extended_kalman_filter(mode, track.y, x0, P0, u)
    np.testing.assert_allclose(imm.x, ekf.x, rtol=1e-10, atol=1e-8)
    np.testing.assert_allclose(imm.P, ekf.P, rtol=1e-10, atol=1e-10)
    assert kc.filter_log_likelihood(imm) == pytest.approx(kc.filter_log_likelihood(ekf), rel=1e-10)


def test_turn_mode_without_turn_noise_from_a_zero_turn_rate_is_the_constant_velocity_filter():
    """q_ω = 0 et ω₀ = 0 connue : le virage ne tourne jamais, l'EKF du virage coordonné est le filtre de
    Kalman de la vitesse presque constante de l'hélicoptère (``helicopter_model``, matrices par pas), à
    10⁻⁹ ; ω reste 0."""
    track, q, R, u = _helicopter()
    ct = kc.coordinated_turn(None, q, 0.0, R, C=np.eye(5)[:4])
    x0, P0 = man.turn_state_prior(track.x0, track.P0, 0.0)
    ekf = kc.extended_kalman_filter(ct, track.y, x0, P0, u)
    sp, sv = np.sqrt(R[0, 0]), np.sqrt(R[2, 2])
    kf = kc.kalman_filter(heli.helicopter_model(track, q, sp, sv), track.y, track.x0, track.P0)
    np.testing.assert_allclose(ekf.x[:, :4], kf.x, rtol=1e-9, atol=1e-8)
    np.testing.assert_allclose(ekf.P[:, :4, :4], kf.P, rtol=1e-9, atol=1e-10)
    assert np.all(ekf.x[:, 4] == 0.0)
    assert kc.filter_log_likelihood(ekf) == pytest.approx(kc.filter_log_likelihood(kf), rel=1e-10)


def test_helicopter_cv_ct_imm_equals_filterpy_with_the_noise_recomputed_at_each_step():
    """L'IMM de l'hélicoptère (``helicopter_turn_imm``) contre IMMEstimator de filterpy sur deux
    ExtendedKalmanFilter : à chaque pas, x = f(x, Δt), P = F P Fᵀ + Q_k avec Q_k recalculée ici
    (``constant_velocity(Δt_k)`` pour [p, v], q_ω Δt_k pour ω, rien sur ω en ligne droite), puis la correction
    de filterpy sur les composantes présentes. Probabilités des régimes et estimation combinée à 10⁻⁹."""
    from filterpy.kalman import ExtendedKalmanFilter, IMMEstimator

    h = man.helicopter_turn_imm()
    track, _, R, u = _helicopter()
    q_straight, q_turn, q_w = 0.1, man.HELI_TURN_ACCEL_PSD, man.TURN_RATE_PSD
    modes = man.cv_ct_modes(None, q_straight, q_turn, q_w, R, C=np.eye(5)[:4])
    x0, P0 = man.turn_state_prior(track.x0, track.P0)

    class Mode(ExtendedKalmanFilter):
        def __init__(self, model, accel_psd, turn_psd):
            super().__init__(dim_x=5, dim_z=4)
            self.model, self.accel_psd, self.turn_psd = model, accel_psd, turn_psd
            self.x, self.P = x0.reshape(5, 1).copy(), P0.copy()

        def predict(self, u=None):
            dt = self.step
            Q = np.zeros((5, 5))
            Q[:4, :4] = kc.constant_velocity(dt, self.accel_psd, dim=2).Q
            Q[4, 4] = self.turn_psd * dt
            x = self.x.ravel()
            F = self.model.transition_jacobian(x, [dt])
            self.x = self.model.transition(x, [dt]).reshape(5, 1)
            self.P = F @ self.P @ F.T + Q

        def update(self, z):
            super().update(z, lambda x: self.H, lambda x: self.H @ x)

    filters = [Mode(modes[0], q_straight, 0.0), Mode(modes[1], q_turn, q_w)]
    imm = IMMEstimator(filters, np.array([0.95, 0.05]), man.imm_transition(0.05))
    mus, xs = [], []
    for k in range(len(track.y)):
        for f in filters:
            f.step = float(u[k, 0])
        imm.predict()
        o = ~np.isnan(track.y[k])
        for f in filters:
            f.H, f.R, f.dim_z = np.eye(5)[:4][o], R[np.ix_(o, o)], int(o.sum())
        imm.update(track.y[k, o].reshape(-1, 1))
        mus.append(imm.mu.copy())
        xs.append(imm.x.ravel().copy())
    np.testing.assert_allclose(h.result.mu, mus, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(h.result.x, xs, rtol=1e-9, atol=1e-6)


# --------------------------------------------------------------------------- ce que le chapitre affirme


def test_on_the_helicopter_the_turn_imm_predicts_better_and_estimates_the_turn_rate():
    """Le chapitre : l'IMM CV/CT prédit les positions mieux que l'IMM calme/agité (de plus de 15 %) et que le
    filtre unique appris, sa vraisemblance est bien plus haute ; sa ω̂ suit la vitesse de rotation mesurée
    (corrélation > 0,9, avec son signe), mais la probabilité du régime virage suit |vitesse de virage| moins
    bien que celle du régime agité (un virage à ω ≈ 0 explique aussi la ligne droite)."""
    h = man.helicopter_turn_imm()
    assert h.prediction_rms < 0.85 * h.prediction_rms_cvcv
    assert h.prediction_rms < h.prediction_rms_single
    assert h.log_likelihood > h.log_likelihood_cvcv + 100.0
    assert h.rate_correlation > 0.9
    assert h.correlation < h.correlation_cvcv
    assert 0.3 < h.correlation < 0.9
    # … car, quand l'hélicoptère vole presque droit, le régime virage reste probable (un virage à ω ≈ 0 est une
    # ligne droite), bien plus que le régime agité
    straight = np.abs(h.rate) < man.STRAIGHT_RATE
    assert 0.2 < straight.mean() < 0.8
    assert h.straight_turn_prob == pytest.approx(h.turn_prob[straight].mean())
    assert h.straight_turn_prob > 3 * h.straight_agitated_prob
    # le même IMM à la main : la ω̂ combinée est μ_CT ω̂_CT (la ligne droite a ω = 0)
    res = h.result
    np.testing.assert_allclose(res.x[:, 4], res.mu[:, 1] * res.x_modes[:, 1, 4], rtol=1e-12, atol=1e-15)


def test_the_helicopter_gain_is_not_a_matter_of_tuning():
    """L'IMM CV/CT aux réglages du chapitre prédit mieux que l'IMM calme/agité à ses meilleurs réglages
    d'une grille plus large (calme 0,1 ou 1 m²/s³, agité 30 ou 100 m²/s³), et, réglé autrement (régime
    virage 0,3 ou 3 m²/s³, q_ω 3·10⁻⁴ ou 3·10⁻³), il reste meilleur que l'IMM calme/agité du chapitre."""
    h = man.helicopter_turn_imm()
    for q_quiet in (0.1, 1.0):
        for q_man in (30.0, 100.0):
            assert h.prediction_rms < man.helicopter_imm(q_quiet, q_man).prediction_rms
    for q_turn, q_w in ((0.3, 3e-4), (3.0, 3e-3)):
        assert man.helicopter_turn_imm(q_turn=q_turn, turn_psd=q_w).prediction_rms < h.prediction_rms_cvcv


def test_on_the_simulated_target_the_turn_imm_is_better_in_turns_and_as_consistent():
    """Sur les trajectoires simulées (les premières de l'étude, mêmes tirages) : l'IMM CV/CT a une REQM plus
    petite que l'IMM calme/agité en virage (de plus de 10 %) et en ligne droite ; les deux sont prudents
    en ligne droite (NEES < 4) et un peu trop sûrs d'eux en virage (NEES > 4), de même ordre ; ω̂ à moins de
    0,05 rad/s près (les virages : 0,12 et 0,08 rad/s)."""
    st, first = man.turn_mode_study(), man.manoeuvre_study()
    np.testing.assert_array_equal(st.truth[:, :4], first.truth)
    np.testing.assert_array_equal(st.y, first.y)
    np.testing.assert_allclose(st.truth[:, 4], man.turn_rate_profile(st.t - man.DT))
    cv, ct = st.index("IMM CV/CV"), st.index("IMM CV/CT")
    assert st.rmse_turn[ct] < 0.9 * st.rmse_turn[cv]
    assert st.rmse_straight[ct] < st.rmse_straight[cv]
    assert np.all(st.nees_straight < 4.0) and np.all(st.nees_turn > 4.0)
    assert st.nees_turn[ct] < 1.2 * st.nees_turn[cv]
    assert st.turn_rate_rmse < 0.05


def test_the_estimated_turn_rate_catches_up_with_each_turn_within_seconds():
    """Le chapitre : la marche aléatoire de ω met quelques secondes à rejoindre chaque virage. Sur la première
    trajectoire, au début de chaque virage (et à sa fin), ω̂ est encore loin de la vraie (écart > moitié du
    saut) ; moins de 8 s plus tard, l'écart est sous la moitié du saut."""
    st = man.turn_mode_study()
    w_hat, w = st.example.x[:, 4], st.truth[:, 4]
    for start, end, rate in man.TURNS:
        for t0 in (start, end):
            k = int(np.searchsorted(st.t, t0 + 1.0))
            gap = np.abs(w_hat[k:k + 8] - w[k:k + 8]) < 0.5 * abs(rate)
            assert not gap[0] and gap.any(), (t0, w_hat[k:k + 8], w[k:k + 8])
