"""Les références « exactes » que montrent les chapitres, vérifiées par des calculs indépendants :

- le filtre bayésien sur une grille (chapitre « Le filtre particulaire ») : égal au filtre de Kalman sur un
  modèle linéaire, et, sur le modèle de croissance, aux moments d'un filtre particulaire à très grand nombre
  de particules (deux approximations qui ne partagent aucun code) ;
- la moyenne et la covariance exactes d'une loi polaire transformée en cartésiennes (chapitre « EKF »),
  contre une quadrature numérique de scipy.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.integrate
import scipy.stats

import kalman_course as kc
from kalman_course.scenarios import grid_bayes, growth, polar


def test_grid_bayes_filter_is_the_kalman_filter_on_a_linear_model():
    model = kc.LinearGaussianModel(0.9, [[1.0]], 0.5, 0.3, B=[[1.0]])
    u = np.sin(np.arange(30))[:, None]
    y = np.array(kc.simulate(model, [1.0], 30, u, rng=4).y)
    y[7] = np.nan  # une mesure manquante : la correction est sautée
    ref = kc.kalman_filter(model, y, 0.5, 2.0, u)
    post = grid_bayes.grid_bayes_filter(kc.NonlinearModel.from_linear(model), y, 0.5, 2.0, u,
                                        grid=np.linspace(-20.0, 20.0, 4001))
    np.testing.assert_allclose(post.mean, ref.x[:, 0], atol=1e-9)
    np.testing.assert_allclose(post.var, ref.P[:, 0, 0], rtol=1e-7)
    assert post.log_likelihood == pytest.approx(kc.log_likelihood(model, y, 0.5, 2.0, u), abs=1e-8)
    dx = post.grid[1] - post.grid[0]
    np.testing.assert_allclose(post.density.sum(axis=1) * dx, 1.0, atol=1e-12)


def test_growth_grid_posterior_matches_a_large_particle_filter_and_is_bimodal():
    data = growth.growth_data()
    post = grid_bayes.growth_grid_posteriors()
    pf = kc.particle_filter(growth.growth_model(), data.y, [growth.GROWTH_X0], [[growth.GROWTH_P0]], data.u,
                            n_particles=20_000, rng=1)
    # deux approximations indépendantes de la même loi : l'écart des moyennes est de l'ordre de l'erreur de
    # Monte-Carlo, σ/√ESS (médiane d'une demi-normale : 0,67) ; un biais du filtre sur grille le ferait exploser
    z = np.abs(pf.x[:, 0] - post.mean) / np.sqrt(post.var / pf.ess)
    assert np.median(z) < 1.5 and z.max() < 6.0, (np.median(z), z.max())
    assert pf.log_likelihood == pytest.approx(post.log_likelihood, abs=0.4)  # log p̂ : biaisé vers le bas
    # une grille deux fois plus fine ne change rien
    fine = grid_bayes.grid_bayes_filter(growth.growth_model(), data.y, growth.GROWTH_X0, growth.GROWTH_P0,
                                        data.u, grid=np.linspace(-32.0, 32.0, 1601))
    np.testing.assert_allclose(fine.mean, post.mean, atol=1e-8)
    # le pas montré par le chapitre : deux modes, en ±x, chacun d'au moins 30 % de la masse
    k = grid_bayes.bimodal_step(post)
    truth = data.x_true[k, 0]
    near, mirror = post.mass_near(k, truth, 3.0), post.mass_near(k, -truth, 3.0)
    assert min(near, mirror) > 0.3 and near + mirror > 0.95
    # un filtre gaussien place sa moyenne entre les deux, ou sur un seul
    assert abs(post.mean[k]) < 0.5 * abs(truth)


def test_grid_bayes_filter_refuses_a_vector_state_or_an_irregular_grid():
    with pytest.raises(kc.KalmanInputError, match="scalaires"):
        grid_bayes.grid_bayes_filter(kc.scenarios.tag_model(), np.zeros((3, 4)), 0.0, 1.0)
    with pytest.raises(kc.KalmanInputError, match="« grid »"):
        grid_bayes.grid_bayes_filter(growth.growth_model(), np.zeros((3, 1)), 0.0, 1.0,
                                     grid=np.array([0.0, 1.0, 3.0]))


@pytest.mark.parametrize("range_std, bearing_deg", [(0.5, 20.0), (0.125, 60.0), (2.0, 2.5)])
def test_polar_exact_moments_are_the_quadrature_of_the_transformed_law(range_std, bearing_deg):
    """E[f(x)] et Cov(f(x)) pour f(r, θ) = (r cos θ, r sin θ), r et θ gaussiens indépendants, par une
    quadrature de scipy (l'espérance se factorise : E[r^a] E[g(θ)])."""
    tr = polar.polar_transform(range_std, bearing_deg)
    r0, t0 = polar.POLAR_MEAN
    st = np.deg2rad(bearing_deg)

    def e_theta(g):
        return scipy.integrate.quad(lambda t: g(t) * scipy.stats.norm.pdf(t, t0, st), t0 - 12 * st, t0 + 12 * st,
                                    epsabs=1e-13, limit=200)[0]

    er, er2 = r0, r0**2 + range_std**2
    mean = er * np.array([e_theta(np.cos), e_theta(np.sin)])
    second = er2 * np.array([[e_theta(lambda t: np.cos(t) ** 2), e_theta(lambda t: np.sin(t) * np.cos(t))],
                             [e_theta(lambda t: np.sin(t) * np.cos(t)), e_theta(lambda t: np.sin(t) ** 2)]])
    np.testing.assert_allclose(tr.exact_mean, mean, atol=1e-10)
    np.testing.assert_allclose(tr.exact_cov, second - np.outer(mean, mean), atol=1e-9)
    # la moyenne exacte ne dépend pas de σr ; le nuage de 3000 tirages s'en écarte de l'erreur de Monte-Carlo
    assert tr.exact_mean[0] == pytest.approx(r0 * np.exp(-st**2 / 2), rel=1e-12)
    sem = np.sqrt(np.diag(tr.exact_cov) / tr.samples.shape[0])
    assert np.all(np.abs(tr.sample_mean - tr.exact_mean) < 5 * sem)
