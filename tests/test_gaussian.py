"""Un seul filtre gaussien, des règles d'intégration : la règle de linéarisation contre l'EKF de filterpy, la
règle unscented contre l'UKF de filterpy (filtres et pas isolés) ; le CKF contre l'UKF (α = 1, β = 0, κ = 0) et contre ``CubatureKalmanFilter`` de
filterpy ; le GHKF contre les moments gaussiens exacts de :math:`x^3` (forme close) et contre scipy ;
les sommes centrées de l'UKF loin de zéro ; erreurs françaises. (L'égalité avec le filtre de Kalman sur un
modèle linéaire est dans tests/test_family.py.)"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.stats
from reference_ckf import filterpy_cubature_filter
from reference_ukf import filterpy_unscented_filter

import kalman_course as kc
from kalman_course.filters.gauss_hermite import gauss_hermite_points
from kalman_course.scenarios import pendulum, tag

FIELDS = ("x", "P", "x_pred", "P_pred", "K", "innovation", "S")


def _same(ours, ref, **tol):
    for field in FIELDS:
        np.testing.assert_allclose(getattr(ours, field), getattr(ref, field), err_msg=field, **tol)


def _tag_model_and_data(n_steps=120):
    data = tag.tag_data(n_steps)
    return tag.tag_model(tag.TAG_ACCEL_STD, tag.TAG_RANGE_STD, data.dt, data.anchors), data


# --------------------------------------------------------------------------- l'EKF et l'UKF sont des membres


def filterpy_ekf(model, y, x0, P0):
    """La référence indépendante de la règle de linéarisation : ``ExtendedKalmanFilter`` de filterpy, prédiction
    x = f(x), P = FPFᵀ + Q écrite ici (filterpy n'a pas de f non linéaire), correction de filterpy (forme de
    Joseph) avec la jacobienne et h du modèle ; ligne NaN : prédiction seule."""
    from filterpy.kalman import ExtendedKalmanFilter

    n, m = model.n_state, model.n_obs
    ekf = ExtendedKalmanFilter(dim_x=n, dim_z=m)
    ekf.x, ekf.P = np.array(x0, dtype=float).reshape(n, 1), np.array(P0, dtype=float)
    ekf.Q, ekf.R = np.array(model.Q), np.array(model.R)
    xs, Ps = [], []
    for yk in np.asarray(y, dtype=float).reshape(len(y), m):
        F = model.transition_jacobian(ekf.x.ravel())
        ekf.x = model.transition(ekf.x.ravel()).reshape(n, 1)
        ekf.P = F @ ekf.P @ F.T + ekf.Q
        if not np.isnan(yk).all():
            ekf.update(yk.reshape(m, 1), lambda x: model.observation_jacobian(x.ravel()),
                       lambda x: model.observe(x.ravel()).reshape(m, 1))
        xs.append(ekf.x.ravel().copy())
        Ps.append(ekf.P.copy())
    return np.array(xs), np.array(Ps)


@pytest.mark.parametrize("joseph", [False, True])
def test_the_linearization_rule_is_filterpy_extended_kalman_filter(joseph):
    """``gaussian_filter(rule=Linearization())``, un tirage et en lot (lignes manquantes comprises), contre
    l'EKF de filterpy (sa correction est la forme de Joseph ; la forme courte lui est égale à l'arrondi
    près)."""
    model, data = pendulum.pendulum_model(), pendulum.pendulum_data(150)
    y = np.array(data.y)
    y[[5, 6, 40]] = np.nan
    ours = kc.gaussian_filter(model, y, data.x0, data.P0, rule=kc.Linearization(), joseph=joseph)
    x_ref, P_ref = filterpy_ekf(model, y, data.x0, data.P0)
    np.testing.assert_allclose(ours.x, x_ref, rtol=0, atol=1e-10)
    np.testing.assert_allclose(ours.P, P_ref, rtol=0, atol=1e-12)
    Y = np.stack([y, np.array(data.y)])
    runs = kc.gaussian_filter_runs(model, Y, data.x0, data.P0, rule=kc.Linearization(), joseph=joseph)
    for i in range(2):
        x_ref, P_ref = filterpy_ekf(model, Y[i], data.x0, data.P0)
        np.testing.assert_allclose(runs.run(i).x, x_ref, rtol=0, atol=1e-10)
        np.testing.assert_allclose(runs.run(i).P, P_ref, rtol=0, atol=1e-12)


def test_the_unscented_rule_is_filterpy_unscented_kalman_filter():
    """``gaussian_filter(rule=UnscentedRule(α, β, κ))`` contre ``UnscentedKalmanFilter`` de filterpy (points
    de van der Merwe), sur le tag (quatre distances)."""
    model, data = _tag_model_and_data()
    ours = kc.gaussian_filter(model, data.y, data.x0, data.P0, rule=kc.UnscentedRule(0.1, 2.0, -1.0))
    ref = filterpy_unscented_filter(model, data.y, data.x0, data.P0, alpha=0.1, beta=2.0, kappa=-1.0)
    for field in ("x", "P", "x_pred", "P_pred", "innovation", "S"):
        np.testing.assert_allclose(getattr(ours, field), getattr(ref, field), rtol=1e-8,
                                   atol=1e-8 * np.abs(getattr(ref, field)).max(), err_msg=field)


def test_single_steps_against_filterpy():
    r"""``gaussian_predict`` / ``gaussian_update`` d'un pas, contre filterpy : l'EKF (prédiction et correction de
    filterpy, jacobiennes du modèle) ; la cubature contre ``UnscentedKalmanFilter`` à α = 1, β = 0, κ = 0 (mêmes
    points ± √n L, poids 1/2n, point central de poids nul), sa correction partant des points de
    :math:`(\hat x^-, P^-)`."""
    from filterpy.kalman import MerweScaledSigmaPoints, UnscentedKalmanFilter

    model, data = pendulum.pendulum_model(), pendulum.pendulum_data(3)
    y0 = np.asarray(data.y)[0]
    x_ref, P_ref = filterpy_ekf(model, data.y[:1], data.x0, data.P0)
    pred = kc.gaussian_predict(model, data.x0, data.P0, rule=kc.Linearization())
    F = model.transition_jacobian(np.asarray(data.x0, dtype=float))
    np.testing.assert_allclose(pred.P, F @ data.P0 @ F.T + model.Q, rtol=1e-14, atol=1e-16)
    upd = kc.gaussian_update(model, pred.x, pred.P, y0, rule=kc.Linearization())
    np.testing.assert_allclose(upd.x, x_ref[0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(upd.P, P_ref[0], rtol=0, atol=1e-14)
    points = MerweScaledSigmaPoints(2, alpha=1.0, beta=0.0, kappa=0.0)
    ukf = UnscentedKalmanFilter(dim_x=2, dim_z=1, dt=1.0, points=points,
                                fx=lambda x, dt: model.transition(np.asarray(x, dtype=float)),
                                hx=lambda x: model.observe(np.asarray(x, dtype=float)))
    ukf.x, ukf.P, ukf.Q, ukf.R = np.array(data.x0, dtype=float), np.array(data.P0, dtype=float), model.Q, model.R
    ukf.predict()
    pred = kc.gaussian_predict(model, data.x0, data.P0, rule=kc.CubatureRule())
    np.testing.assert_allclose(pred.x, ukf.x, rtol=1e-13)
    np.testing.assert_allclose(pred.P, ukf.P, rtol=1e-12)
    ukf.sigmas_f = points.sigma_points(ukf.x, ukf.P)  # la correction tire ses points de (x̂⁻, P⁻)
    ukf.update(y0)
    upd = kc.gaussian_update(model, pred.x, pred.P, y0, rule=kc.CubatureRule())
    np.testing.assert_allclose(upd.x, ukf.x, rtol=1e-12)
    np.testing.assert_allclose(upd.P, ukf.P, rtol=1e-10, atol=1e-14)


def test_linearization_and_cubature_moments_by_hand():
    r"""Les moments d'une règle contre un calcul à la main : linéarisation d'une fonction affine (exacte) ;
    cubature de :math:`g(x) = x_1^2 + x_1x_2` (polynôme de degré 2 : moyenne exacte, forme close)."""
    rng = np.random.default_rng(4)
    L = rng.standard_normal((2, 2))
    P, x = L @ L.T + 0.3 * np.eye(2), rng.standard_normal(2)
    M, b = rng.standard_normal((3, 2)), rng.standard_normal(3)
    model = kc.NonlinearModel(lambda z, u: z, lambda z: M @ z + b, np.eye(2), np.eye(3), h_jacobian=M)
    mom = kc.Linearization().observation(model, x, P, None, "essai")
    np.testing.assert_allclose(mom.mean, M @ x + b, rtol=1e-14)
    np.testing.assert_allclose(mom.cov, M @ P @ M.T, rtol=1e-13)
    np.testing.assert_allclose(mom.cross, P @ M.T, rtol=1e-13)
    quad = kc.NonlinearModel(lambda z, u: z, lambda z: np.array([z[0] ** 2 + z[0] * z[1]]), np.eye(2), [[1.0]])
    mom = kc.CubatureRule().observation(quad, x, P, None, "essai")
    exact = x[0] ** 2 + P[0, 0] + x[0] * x[1] + P[0, 1]  # E[x₁²] + E[x₁x₂]
    assert mom.mean[0] == pytest.approx(exact, rel=1e-13)


# --------------------------------------------------------------------------- sommes centrées (issue 17)


def test_unscented_sums_keep_their_digits_far_from_zero_with_a_small_alpha():
    """État décalé de 10⁶ et α = 10⁻³ : W₀ᵐ = 1 − 1/α² ≈ −10⁶. Sur une marche aléatoire mesurée en une
    coordonnée (f et h exactes en flottants), l'UKF doit redonner le filtre de Kalman décalé. Avec la somme
    directe Σ Wᵐχ (termes de 10¹²) et des points χ = x̂ ± s arrondis séparément, l'écart était de 3 × 10⁻⁴ ;
    avec la somme centrée sur χ₀ et des points exactement symétriques, il ne reste que l'arrondi des points
    eux-mêmes (ulp(10⁶) / ‖s‖ ≈ 10⁻⁷ en relatif sur P)."""
    Q = np.array([[0.02, 0.005], [0.005, 0.01]])
    R = np.array([[0.25]])
    C = np.array([[1.0, 0.0]])
    lin = kc.LinearGaussianModel(np.eye(2), C, Q, R)
    y = np.array(kc.simulate(lin, np.zeros(2), 50, rng=0).y)
    kf = kc.kalman_filter(lin, y, np.zeros(2), np.eye(2))
    model = kc.NonlinearModel(lambda x, u: x, lambda x: x[..., :1], Q, R, vectorized=True)
    offset = np.array([1e6, -2.5e5])
    ukf = kc.unscented_kalman_filter(model, y + offset[0], offset, np.eye(2), alpha=1e-3, beta=2.0, kappa=0.0)
    assert np.abs(ukf.x - offset - kf.x).max() < 1e-6
    assert np.abs(ukf.P - kf.P).max() < 1e-6 * np.abs(kf.P).max()
    # les points eux-mêmes : exactement symétriques, de moyenne pondérée x̂
    sp = kc.sigma_points(offset, np.eye(2), alpha=1e-3)
    n = 2
    np.testing.assert_array_equal(sp.points[1:n + 1] - offset, offset - sp.points[n + 1:])
    ut = kc.unscented_transform(offset, np.eye(2), lambda x: x, alpha=1e-3)
    assert np.abs(ut.mean - offset).max() < 1e-9


# --------------------------------------------------------------------------- CKF


@pytest.fixture(params=["pendule", "tag"])
def cubature_case(request):
    """Le pendule ou le tag, avec deux mesures manquantes : (modèle, y, données)."""
    model, data = (pendulum.pendulum_model(), pendulum.pendulum_data(200)) if request.param == "pendule" \
        else _tag_model_and_data()
    y = np.array(data.y)
    y[[3, 17]] = np.nan
    return model, y, data


def test_cubature_with_redraw_equals_the_ukf_alpha_one_beta_zero_kappa_zero(cubature_case):
    model, y, data = cubature_case
    ckf = kc.cubature_kalman_filter(model, y, data.x0, data.P0)
    ukf = kc.unscented_kalman_filter(model, y, data.x0, data.P0, alpha=1.0, beta=0.0, kappa=0.0)
    _same(ckf, ukf, rtol=0, atol=1e-10)
    runs = kc.cubature_kalman_filter_runs(model, np.stack([y, y]), data.x0, data.P0)
    _same(runs.run(1), ckf, rtol=0, atol=1e-10)


def test_cubature_without_redraw_equals_filterpy_cubature_kalman_filter(cubature_case):
    model, y, data = cubature_case
    ours = kc.cubature_kalman_filter(model, y, data.x0, data.P0, redraw=False)
    ref = filterpy_cubature_filter(model, y, data.x0, data.P0)
    _same(ours, ref, rtol=1e-9, atol=1e-9)
    runs = kc.cubature_kalman_filter_runs(model, np.stack([y, y]), data.x0, data.P0, redraw=False)
    _same(runs.run(0), ours, rtol=0, atol=1e-10)
    # les points propagés ignorent Q : sur le même problème, redessiner change le résultat
    assert np.abs(kc.cubature_kalman_filter(model, y, data.x0, data.P0).x - ours.x).max() > 1e-4


def test_cubature_without_redraw_is_not_the_kalman_filter_on_a_linear_model():
    rng = np.random.default_rng(2)
    A = np.array([[1.0, 0.1], [0.0, 1.0]])
    lin = kc.LinearGaussianModel(A, [[1.0, 0.0]], 0.1 * np.eye(2), [[0.5]])
    y = np.array(kc.simulate(lin, np.zeros(2), 30, rng=rng).y)
    kf = kc.kalman_filter(lin, y, np.zeros(2), np.eye(2))
    model = kc.NonlinearModel.from_linear(lin)
    np.testing.assert_allclose(kc.cubature_kalman_filter(model, y, np.zeros(2), np.eye(2)).x, kf.x, atol=1e-12)
    stale = kc.cubature_kalman_filter(model, y, np.zeros(2), np.eye(2), redraw=False)
    np.testing.assert_allclose(stale.x_pred[0], kf.x_pred[0], atol=1e-12)  # la prédiction est exacte
    assert np.abs(stale.x - kf.x).max() > 1e-3  # la correction sur les points propagés ne l'est plus


# --------------------------------------------------------------------------- Gauss–Hermite


@pytest.mark.parametrize("order", [2, 3, 5])
def test_gauss_hermite_points_integrate_gaussian_moments_up_to_degree_2p_minus_1(order):
    xi, w = gauss_hermite_points(1, order)
    assert w.sum() == pytest.approx(1.0, rel=1e-14)
    for degree in range(2 * order):
        assert w @ xi[:, 0] ** degree == pytest.approx(scipy.stats.norm.moment(degree), abs=1e-10)
    # degré 2p : plus exact (le test peut échouer)
    assert abs(w @ xi[:, 0] ** (2 * order) - scipy.stats.norm.moment(2 * order)) > 1e-3
    xi2, w2 = gauss_hermite_points(2, order)
    assert xi2.shape == (order**2, 2) and w2.sum() == pytest.approx(1.0, rel=1e-14)
    np.testing.assert_allclose(w2 @ (xi2[:, 0] ** 2 * xi2[:, 1] ** 2), 1.0, rtol=1e-12)  # E[x₁²x₂²] = 1


def _cube_model(R=0.04):
    return kc.NonlinearModel(lambda x, u: 0.9 * x, lambda x: x**3, [[0.05]], [[R]], vectorized=True)


def _cube_moments(m, s2):
    """Moments exacts de x³ pour x ~ N(m, s²) : E[x³], Var(x³), Cov(x, x³)."""
    mean = m**3 + 3 * m * s2
    var = 9 * m**4 * s2 + 36 * m**2 * s2**2 + 15 * s2**3
    cross = 3 * m**2 * s2 + 3 * s2**2
    return mean, var, cross


def test_gauss_hermite_order_four_has_the_exact_innovation_covariance_of_x_cubed():
    """h(x) = x³ : S = Var(x³) + R (forme close des moments gaussiens) à chaque pas, dès l'ordre 4
    (Var demande le degré 6 ≤ 2p − 1) ; l'ordre 3 (exact jusqu'au degré 5) ne l'est plus, l'EKF encore moins."""
    model, R = _cube_model(), 0.04
    y = np.array([0.9, 1.1, 0.7, np.nan, 0.5, 0.8])
    res = kc.gauss_hermite_kalman_filter(model, y, [1.0], [[0.3]], order=4)
    for k in (0, 1, 2, 4, 5):
        mean, var, cross = _cube_moments(res.x_pred[k, 0], res.P_pred[k, 0, 0])
        assert res.S[k, 0, 0] == pytest.approx(var + R, rel=1e-12)
        assert res.innovation[k, 0] == pytest.approx(y[k] - mean, rel=1e-12, abs=1e-13)
        assert res.K[k, 0, 0] == pytest.approx(cross / (var + R), rel=1e-12)
    low = kc.gauss_hermite_kalman_filter(model, y[:1], [1.0], [[0.3]], order=3)
    mean, var, _ = _cube_moments(low.x_pred[0, 0], low.P_pred[0, 0, 0])
    assert low.innovation[0, 0] == pytest.approx(y[0] - mean, rel=1e-12)  # la moyenne (degré 3) reste exacte
    assert abs(low.S[0, 0, 0] - var - R) > 0.01 * var
    ekf = kc.extended_kalman_filter(model, y[:1], [1.0], [[0.3]])
    assert abs(ekf.S[0, 0, 0] - var - R) > 0.1 * var


def test_gauss_hermite_tensor_points_in_two_dimensions_match_scipy_quadrature():
    r"""E[g(x)] d'une fonction non polynomiale en dimension 2 : Gauss–Hermite d'ordre 12 contre
    ``scipy.integrate.dblquad`` de la densité gaussienne."""
    from scipy.integrate import dblquad

    x = np.array([0.3, -0.2])
    P = np.array([[0.5, 0.2], [0.2, 0.3]])
    h = lambda z: np.array([np.sin(z[..., 0]) * np.exp(0.3 * z[..., 1])]).T.reshape(np.shape(z)[:-1] + (1,))
    model = kc.NonlinearModel(lambda z, u: z, h, np.eye(2), [[1.0]], vectorized=True)
    mom = kc.GaussHermiteRule(12).observation(model, x, P, None, "essai")
    dens = scipy.stats.multivariate_normal(x, P)
    ref, _ = dblquad(lambda b, a: np.sin(a) * np.exp(0.3 * b) * dens.pdf([a, b]), -6, 6, -6, 6, epsabs=1e-12)
    assert mom.mean[0] == pytest.approx(ref, abs=1e-9)


def test_gauss_hermite_equals_the_unscented_rule_where_both_are_exact():
    """Sur un modèle linéaire, ordre 2 et ordre 5 donnent le même filtre (et le filtre de Kalman)."""
    rng = np.random.default_rng(8)
    A = np.array([[1.0, 0.1, 0.0], [0.0, 1.0, 0.1], [0.0, 0.0, 0.95]])
    lin = kc.LinearGaussianModel(A, [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]], 0.05 * np.eye(3), 0.2 * np.eye(2))
    y = np.array(kc.simulate(lin, np.zeros(3), 40, rng=rng).y)
    kf = kc.kalman_filter(lin, y, np.ones(3), np.eye(3))
    model = kc.NonlinearModel.from_linear(lin)
    for order in (2, 5):
        gh = kc.gauss_hermite_kalman_filter(model, y, np.ones(3), np.eye(3), order=order)
        np.testing.assert_allclose(gh.x, kf.x, atol=1e-10)
        np.testing.assert_allclose(gh.P, kf.P, atol=1e-10)
    runs = kc.gauss_hermite_kalman_filter_runs(model, np.stack([y, y]), np.ones(3), np.eye(3), order=2)
    np.testing.assert_allclose(runs.run(1).x, kf.x, atol=1e-10)


# --------------------------------------------------------------------------- erreurs


def test_bad_inputs_are_french_errors():
    model, data = pendulum.pendulum_model(), pendulum.pendulum_data(5)
    with pytest.raises(kc.KalmanInputError, match="« order » doit être un entier ≥ 2"):
        kc.gauss_hermite_kalman_filter(model, data.y, data.x0, data.P0, order=1)
    with pytest.raises(kc.KalmanInputError, match="« order » doit être un entier ≥ 2"):
        kc.gauss_hermite_kalman_filter(model, data.y, data.x0, data.P0, order=2.5)
    big = kc.NonlinearModel(lambda x, u: x, lambda x: x[..., :1], np.eye(12), [[1.0]], vectorized=True)
    with pytest.raises(kc.KalmanInputError, match=r"3\^12 = 531441 points.*cubature \(2n = 24 points\)"):
        kc.gauss_hermite_kalman_filter(big, np.zeros(3), np.zeros(12), np.eye(12))
    with pytest.raises(kc.KalmanInputError, match="« redraw » doit être un booléen"):
        kc.cubature_kalman_filter(model, data.y, data.x0, data.P0, redraw="non")
    with pytest.raises(kc.KalmanInputError, match="« P0 » doit être définie positive"):
        kc.cubature_kalman_filter(model, data.y, data.x0, np.diag([1.0, 0.0]))
    noisy = kc.NonlinearModel(model.f, model.h, [[1.0]], model.R, f_noise_jacobian=[[0.0], [1.0]])
    with pytest.raises(kc.KalmanInputError, match="Le CKF du paquet suppose des bruits additifs"):
        kc.cubature_kalman_filter(noisy, data.y, data.x0, data.P0)
    with pytest.raises(kc.KalmanInputError, match="« rule » doit être une règle d'intégration gaussienne"):
        kc.gaussian_filter(model, data.y, data.x0, data.P0, rule="ukf")
    with pytest.raises(kc.KalmanInputError, match="pour un modèle linéaire, utilisez kalman_filter"):
        kc.cubature_kalman_filter(kc.LinearGaussianModel(np.eye(2), [[1.0, 0.0]], np.eye(2), [[1.0]]),
                                  data.y, data.x0, data.P0)


def test_covariance_that_stops_being_positive_definite_names_the_filter_and_the_step():
    model = kc.NonlinearModel(lambda x, u: np.zeros_like(x), lambda x: x, np.zeros((2, 2)), np.eye(2))
    with pytest.raises(kc.KalmanInputError, match=r"CKF, correction par y\[0\] : la covariance prédite P⁻ n'est "
                                                  r"plus définie positive.*points de cubature"):
        kc.cubature_kalman_filter(model, np.zeros((4, 2)), np.zeros(2), np.eye(2))
    with pytest.raises(kc.KalmanInputError, match=r"GHKF, correction par y\[0\].*points de Gauss–Hermite"):
        kc.gauss_hermite_kalman_filter(model, np.zeros((4, 2)), np.zeros(2), np.eye(2))


# --------------------------------------------------------------------------- IPLF


def test_iplf_with_the_linearization_rule_is_the_iterated_ekf():
    """Régression statistique d'une linéarisation : H = Cᵀ P_i⁻¹ = ∂h/∂x, Ω = 0 — les itérations sont celles
    de Gauss–Newton (kc.iterated_extended_kalman_filter, écrit à part), jusqu'au nombre d'itérations."""
    from kalman_course.scenarios import distant_target

    model, data = pendulum.pendulum_model(), pendulum.pendulum_data(150)
    run = distant_target.distant_target_run(7)
    for m, y, x0, P0 in ((model, data.y, data.x0, data.P0),
                         (distant_target.distant_target_model(), run.y, run.x0, run.P0)):
        ours = kc.iterated_posterior_linearization_filter(m, y, x0, P0, rule=kc.Linearization())
        ref = kc.iterated_extended_kalman_filter(m, y, x0, P0)
        scale = np.abs(ref.P).max()
        np.testing.assert_allclose(ours.x, ref.x, rtol=1e-10, atol=1e-9)
        np.testing.assert_allclose(ours.P, ref.P, rtol=0, atol=1e-10 * scale)
        np.testing.assert_array_equal(ours.n_iter, ref.n_iter)


def test_iplf_one_iteration_is_the_sigma_point_filter():
    model, data = pendulum.pendulum_model(), pendulum.pendulum_data(100)
    for rule, ref in ((kc.CubatureRule(), kc.cubature_kalman_filter(model, data.y, data.x0, data.P0)),
                      (kc.UnscentedRule(0.5, 2.0, 1.0), kc.unscented_kalman_filter(
                          model, data.y, data.x0, data.P0, alpha=0.5, beta=2.0, kappa=1.0))):
        ours = kc.iterated_posterior_linearization_filter(model, data.y, data.x0, data.P0, rule=rule, max_iter=1)
        _same(ours, ref, rtol=0, atol=1e-10)


def test_iplf_is_consistent_from_the_start_on_the_distant_target():
    """Cible lointaine (a priori à 300 m, mesures à 1 m et 0,2°) : le CKF calcule son gain sous la loi
    prédite et se croit bien plus précis qu'il n'est au début ; l'IPLF (même règle), qui relinéarise sous la
    loi a posteriori, a une NEES moyenne proche de 4 dès les premiers pas."""
    from kalman_course.scenarios import distant_target

    model = distant_target.distant_target_model()
    gen = np.random.default_rng(11)
    first = {"CKF": [], "IPLF": []}
    for _ in range(12):
        run = distant_target.distant_target_run(gen)
        first["CKF"].append(kc.nees(run.x_true, kc.cubature_kalman_filter(model, run.y, run.x0, run.P0))[:5])
        first["IPLF"].append(kc.nees(run.x_true, kc.iterated_posterior_linearization_filter(
            model, run.y, run.x0, run.P0))[:5])
    assert np.mean(first["IPLF"]) < 8.0
    assert np.mean(first["CKF"]) > 50.0


def test_iplf_bad_inputs():
    model, data = pendulum.pendulum_model(), pendulum.pendulum_data(5)
    with pytest.raises(kc.KalmanInputError, match="« rule » doit être une règle d'intégration gaussienne"):
        kc.iterated_posterior_linearization_filter(model, data.y, data.x0, data.P0, rule=None)
    with pytest.raises(kc.KalmanInputError, match="« max_iter » doit être un entier ≥ 1"):
        kc.iterated_posterior_linearization_filter(model, data.y, data.x0, data.P0, max_iter=0)
    with pytest.raises(kc.KalmanInputError, match="« P0 » doit être définie positive"):
        kc.iterated_posterior_linearization_filter(model, data.y, data.x0, np.diag([1.0, 0.0]))
