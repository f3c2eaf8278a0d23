"""Plusieurs cibles dans le fouillis (issue 37) : porte, NN, GNN, PDA, JPDA, OSPA et GOSPA contre Stone Soup 1.9.1
(la référence, à 1e-9 près), contre des calculs indépendants écrits ici là où Stone Soup se trompe (OSPA pour
p ≠ 1, décomposition de la GOSPA), et les règles du pisteur sur de petites scènes construites à la main.

Stone Soup range l'état [x, vx, y, vy] ; le paquet [x, y, vx, vy] : ``PERM`` passe de l'un à l'autre. Ses
pistes prédites sont obtenues par un prédicteur à vitesse constante de pas nul (A = I, Q = 0) : l'état
donné est l'état prédit.
"""

from __future__ import annotations

import datetime
import itertools
import math
import subprocess
import sys

import numpy as np
import pytest
import scipy.linalg
import scipy.stats

import kalman_course as kc
from kalman_course import KalmanInputError

stonesoup = pytest.importorskip("stonesoup")

from stonesoup.dataassociator.neighbour import GNNWith2DAssignment, NearestNeighbour  # noqa: E402
from stonesoup.dataassociator.probability import JPDA  # noqa: E402
from stonesoup.hypothesiser.distance import DistanceHypothesiser  # noqa: E402
from stonesoup.hypothesiser.probability import PDAHypothesiser  # noqa: E402
from stonesoup.measures import SquaredMahalanobis  # noqa: E402
from stonesoup.metricgenerator.ospametric import GOSPAMetric, OSPAMetric  # noqa: E402
from stonesoup.models.measurement.linear import LinearGaussian  # noqa: E402
from stonesoup.models.transition.linear import CombinedLinearGaussianTransitionModel, ConstantVelocity  # noqa: E402
from stonesoup.predictor.kalman import KalmanPredictor  # noqa: E402
from stonesoup.types.detection import Detection  # noqa: E402
from stonesoup.types.state import GaussianState, State  # noqa: E402
from stonesoup.types.track import Track  # noqa: E402
from stonesoup.updater.kalman import KalmanUpdater  # noqa: E402
from stonesoup.updater.probability import PDAUpdater  # noqa: E402

RTOL = 1e-9
T0 = datetime.datetime(2024, 5, 17, 12, 0, 0)


# --------------------------------------------------------------------------- scènes et traduction vers Stone Soup


def cv_model(d: int = 2, R=None, dt: float = 1.0, q: float = 1.0) -> kc.LinearGaussianModel:
    """Vitesse presque constante en ``d`` dimensions, positions mesurées."""
    R = 100.0 * np.eye(d) if R is None else np.asarray(R, float)
    return kc.constant_velocity_model(dt, q, np.hstack([np.eye(d), np.zeros((d, d))]), R, dim=d)


def perm(d: int) -> np.ndarray:
    """Indices du paquet rangés dans l'ordre de Stone Soup : [p1, v1, p2, v2, …] ← [p1, p2, …, v1, v2, …]."""
    return np.array([i for k in range(d) for i in (k, d + k)])


def random_spd(rng, n: int, scale: float) -> np.ndarray:
    A = rng.standard_normal((n, n))
    return scale * (A @ A.T / n + 0.5 * np.eye(n))


def scene(seed: int, T: int, d: int = 2, n_clutter: int = 6, spread: float = 60.0, box: float = 400.0):
    """``T`` pistes prédites proches, une détection par piste (tirée de S) et du fouillis uniforme."""
    rng = np.random.default_rng(seed)
    R = random_spd(rng, d, 80.0)
    model = cv_model(d, R)
    n = 2 * d
    x = np.hstack([rng.uniform(-spread, spread, (T, d)), rng.normal(0.0, 20.0, (T, d))])
    P = np.stack([random_spd(rng, n, 150.0) for _ in range(T)])
    S = model.C @ P @ model.C.T + R
    targets = np.array([rng.multivariate_normal(model.C @ x[t], 0.3 * S[t]) for t in range(T)]).reshape(T, d)
    clutter = rng.uniform(-box, box, (n_clutter, d))
    z = np.vstack([targets, clutter])
    z = z[rng.permutation(len(z))]
    return model, x, P, z


class StoneSoup:
    """Les objets Stone Soup d'un modèle du paquet (mesure des positions, prédiction de pas nul)."""

    def __init__(self, model: kc.LinearGaussianModel):
        d = model.n_obs
        self.d = d
        self.perm = perm(d)
        self.measurement = LinearGaussian(ndim_state=2 * d, mapping=tuple(range(0, 2 * d, 2)),
                                          noise_covar=np.asarray(model.R))
        self.predictor = KalmanPredictor(CombinedLinearGaussianTransitionModel([ConstantVelocity(1.0)] * d))
        self.updater = KalmanUpdater(self.measurement)

    def track(self, x, P) -> Track:
        p = self.perm
        return Track([GaussianState(np.asarray(x)[p][:, None], np.asarray(P)[np.ix_(p, p)], timestamp=T0)])

    def detections(self, z) -> list[Detection]:
        return [Detection(np.asarray(zj, float)[:, None], timestamp=T0, measurement_model=self.measurement) for zj in z]

    def pda(self, P_D, lam, P_G) -> PDAHypothesiser:
        return PDAHypothesiser(self.predictor, self.updater, clutter_spatial_density=lam, prob_detect=P_D,
                               prob_gate=P_G)

    def distance(self, gamma) -> DistanceHypothesiser:
        return DistanceHypothesiser(self.predictor, self.updater, SquaredMahalanobis(), missed_distance=gamma)

    def state(self, update) -> tuple[np.ndarray, np.ndarray]:
        """L'état (x, P) d'une correction de Stone Soup, dans l'ordre du paquet."""
        back = np.argsort(self.perm)
        return np.asarray(update.state_vector, float).ravel()[back], np.asarray(update.covar, float)[np.ix_(back, back)]


def weights_of(hypotheses, detections) -> np.ndarray:
    """Les probabilités d'une ``MultipleHypothesis`` rangées comme le paquet : [aucune, détection 0, 1, …]."""
    out = np.zeros(len(detections) + 1)
    index = {id(det): j for j, det in enumerate(detections)}
    for h in hypotheses:
        out[0 if not h else 1 + index[id(h.measurement)]] = float(h.probability)
    return out


SETTINGS = [(0.9, 1e-4, 0.99), (1.0, 3e-5, 0.95), (0.6, 1e-3, 0.999), (0.95, 2e-6, 0.9)]


# --------------------------------------------------------------------------- porte et PDA contre Stone Soup


@pytest.mark.parametrize("d", [1, 2, 3])
@pytest.mark.parametrize("seed", range(4))
def test_gate_and_pda_match_stonesoup(seed, d):
    P_D, lam, P_G = SETTINGS[seed]
    lam = lam ** (d / 2)  # une densité par unité de volume de mesure : m, m², m³
    model, x, P, z = scene(seed, 1, d=d, n_clutter=8, box=150.0 if d > 1 else 600.0)
    ss = StoneSoup(model)
    dets = ss.detections(z)
    track = ss.track(x[0], P[0])
    hyps = ss.pda(P_D, lam, P_G).hypothesise(track, set(dets), T0)
    gate = kc.validation_gate(model, x, P, z, gate_probability=P_G)
    # la porte : les détections que Stone Soup garde, leurs NIS, le seuil, le volume
    kept = {id(h.measurement) for h in hyps if h}
    assert list(gate.inside[0]) == [id(det) in kept for det in dets]
    assert 0 < gate.inside.sum() < len(z)  # la scène a des détections dans la porte et hors d'elle
    meas_pred = ss.updater.predict_measurement(ss.predictor.predict(track, timestamp=T0), ss.measurement)
    nis = [SquaredMahalanobis()(meas_pred, det) for det in dets]
    np.testing.assert_allclose(gate.nis[0], nis, rtol=RTOL)
    assert gate.threshold == pytest.approx(PDAHypothesiser._gate_threshold(P_G, d), rel=1e-12)
    assert gate.volume[0] == pytest.approx(PDAHypothesiser._validation_region_volume(P_G, meas_pred), rel=RTOL)
    # les poids et la correction
    upd = kc.pda_update(model, x[0], P[0], z, detection_probability=P_D, clutter_density=lam, gate_probability=P_G)
    np.testing.assert_allclose(upd.weights, weights_of(hyps, dets), rtol=RTOL, atol=1e-300)
    np.testing.assert_array_equal(upd.inside, gate.inside[0])
    x_ss, P_ss = ss.state(PDAUpdater(ss.measurement).update(hyps))
    np.testing.assert_allclose(upd.x, x_ss, rtol=RTOL, atol=RTOL * np.abs(x_ss).max())
    np.testing.assert_allclose(upd.P, P_ss, rtol=RTOL, atol=RTOL * np.abs(P_ss).max())


def test_pda_is_the_moments_of_the_mixture_of_kalman_updates():
    """Indépendamment de Stone Soup : la correction PDA est la moyenne et la covariance du mélange des N + 1
    corrections de Kalman (une par hypothèse, la prédiction pour « aucune »), pondérées par β."""
    model, x, P, z = scene(11, 1, n_clutter=5, box=120.0)
    upd = kc.pda_update(model, x[0], P[0], z, detection_probability=0.8, clutter_density=2e-4, gate_probability=0.99)
    C, R = model.C, model.R
    S = C @ P[0] @ C.T + R
    K = scipy.linalg.solve(S, C @ P[0]).T
    means = [x[0]] + [x[0] + K @ (zj - C @ x[0]) for zj in z]
    covs = [P[0]] + [P[0] - K @ S @ K.T] * len(z)
    beta = upd.weights
    assert beta[1:][~upd.inside].max() == 0.0 and upd.inside.sum() >= 2
    mean = sum(b * mu for b, mu in zip(beta, means))
    cov = sum(b * (Pk + np.outer(mu - mean, mu - mean)) for b, mu, Pk in zip(beta, means, covs))
    np.testing.assert_allclose(upd.x, mean, rtol=1e-12)
    np.testing.assert_allclose(upd.P, cov, rtol=1e-10)
    # les poids : formule écrite ici (densité de scipy), normalisés
    dens = scipy.stats.multivariate_normal(C @ x[0], S).pdf(z)
    w = np.concatenate([[1 - 0.8 * 0.99], np.where(upd.inside, 0.8 * dens / 2e-4, 0.0)])
    np.testing.assert_allclose(beta, w / w.sum(), rtol=1e-12)


def test_pda_on_an_empty_scan_is_the_prediction():
    model, x, P, _ = scene(0, 1)
    upd = kc.pda_update(model, x[0], P[0], np.empty((0, 2)), detection_probability=0.9, clutter_density=1e-4,
                        gate_probability=0.99)
    np.testing.assert_array_equal(upd.weights, [1.0])
    np.testing.assert_allclose(upd.x, x[0])
    np.testing.assert_allclose(upd.P, P[0], rtol=1e-14)
    assert upd.inside.shape == (0,) and upd.inside.dtype == bool


# --------------------------------------------------------------------------- JPDA


def brute_force_jpda(w: np.ndarray) -> np.ndarray:
    """Marginales JPDA par énumération de tout le produit des options (itertools), indépendante des grappes."""
    T, n_opt = w.shape
    beta = np.zeros_like(w)
    for event in itertools.product(range(n_opt), repeat=T):
        dets = [a for a in event if a]
        if len(dets) != len(set(dets)):
            continue
        weight = math.prod(w[t, a] for t, a in enumerate(event))
        for t, a in enumerate(event):
            beta[t, a] += weight
    return beta / beta.sum(axis=1, keepdims=True)


@pytest.mark.parametrize("seed, T", [(1, 2), (2, 3), (3, 4), (4, 3), (5, 5)])
def test_jpda_matches_stonesoup(seed, T):
    P_D, lam, P_G = SETTINGS[seed % len(SETTINGS)]
    model, x, P, z = scene(seed, T, n_clutter=4, spread=25.0, box=90.0)
    ss = StoneSoup(model)
    dets = ss.detections(z)
    tracks = [ss.track(x[t], P[t]) for t in range(T)]
    result = JPDA(ss.pda(P_D, lam, P_G)).associate(set(tracks), set(dets), T0)
    beta = kc.jpda_probabilities(model, x, P, z, detection_probability=P_D, clutter_density=lam, gate_probability=P_G)
    expected = np.array([weights_of(result[track], dets) for track in tracks])
    gate = kc.validation_gate(model, x, P, z, gate_probability=P_G)
    assert (gate.inside.sum(axis=0) >= 2).any()  # des détections disputées
    np.testing.assert_allclose(beta, expected, rtol=RTOL, atol=1e-300)
    np.testing.assert_allclose(beta.sum(axis=1), 1.0, rtol=1e-12)
    assert np.all(beta[:, 1:][~gate.inside] == 0.0)


def test_jpda_by_clusters_equals_the_whole_product():
    """Deux groupes de pistes éloignés, et une piste seule sans détection : l'énumération par grappes donne les
    marginales de l'énumération de tout le produit des options."""
    model, xa, Pa, za = scene(21, 3, n_clutter=2, spread=20.0, box=60.0)
    _, xb, Pb, zb = scene(22, 2, n_clutter=1, spread=20.0, box=60.0)
    shift = np.array([5000.0, 0.0])
    lone = np.array([[-9000.0, 0.0, 0.0, 0.0]])
    x = np.vstack([xa, lone, xb + np.concatenate([shift, [0.0, 0.0]])])
    P = np.concatenate([Pa, Pb[:1], Pb])
    z = np.vstack([za, zb + shift])
    kw = dict(detection_probability=0.85, clutter_density=5e-5, gate_probability=0.99)
    beta = kc.jpda_probabilities(model, x, P, z, **kw)
    # poids PDA d'une piste = ceux de pda_update, dénormalisés par la porte ; recalculés ici (scipy)
    gate = kc.validation_gate(model, x, P, z, gate_probability=0.99)
    w = np.zeros((len(x), len(z) + 1))
    w[:, 0] = 1 - 0.85 * 0.99
    for t in range(len(x)):
        S = model.C @ P[t] @ model.C.T + model.R
        w[t, 1:] = np.where(gate.inside[t], 0.85 * scipy.stats.multivariate_normal(model.C @ x[t], S).pdf(z) / 5e-5, 0)
    np.testing.assert_allclose(beta, brute_force_jpda(w), rtol=1e-10, atol=1e-300)
    np.testing.assert_array_equal(beta[3], np.eye(len(z) + 1)[0])  # la piste seule : aucune détection


def test_jpda_refuses_a_cluster_too_large_for_exact_enumeration(monkeypatch):
    from kalman_course.multitarget import jpda

    monkeypatch.setattr(jpda, "MAX_EVENTS", 100)
    model, x, P, z = scene(5, 5, n_clutter=0, spread=5.0)
    with pytest.raises(KalmanInputError, match="JPDA exacte.*gate_probability"):
        kc.jpda_probabilities(model, x, P, z, detection_probability=0.9, clutter_density=1e-4, gate_probability=0.99)


def test_jpda_empty_cases():
    model, x, P, z = scene(0, 2)
    kw = dict(detection_probability=0.9, clutter_density=1e-4, gate_probability=0.99)
    np.testing.assert_array_equal(kc.jpda_probabilities(model, x, P, np.empty((0, 2)), **kw), [[1.0], [1.0]])
    assert kc.jpda_probabilities(model, np.empty((0, 4)), np.empty((0, 4, 4)), z, **kw).shape == (0, len(z) + 1)


# --------------------------------------------------------------------------- NN, GNN


@pytest.mark.parametrize("seed", range(6))
def test_gnn_and_nn_match_stonesoup(seed):
    T = 2 + seed % 3
    model, x, P, z = scene(100 + seed, T, n_clutter=3, spread=30.0, box=80.0)
    P_G = 0.99
    gamma = scipy.stats.chi2.ppf(P_G, 2)
    ss = StoneSoup(model)
    dets = ss.detections(z)
    tracks = [ss.track(x[t], P[t]) for t in range(T)]
    index = {id(det): j for j, det in enumerate(dets)}
    for ours, theirs in ((kc.gnn_assign, GNNWith2DAssignment), (kc.nn_assign, NearestNeighbour)):
        result = theirs(ss.distance(gamma)).associate(set(tracks), set(dets), T0)
        expected = [index[id(result[tr].measurement)] if result[tr] else -1 for tr in tracks]
        np.testing.assert_array_equal(ours(model, x, P, z, gate_probability=P_G), expected)


def _total_cost(nis, gamma, assignment):
    return sum(nis[t, j] if j >= 0 else gamma for t, j in enumerate(assignment))


def test_gnn_is_the_cheapest_assignment_and_nn_can_be_worse():
    """Deux pistes (0 et 30 m), deux détections (14 et −25 m). Le glouton donne d'abord à la piste 0 la
    détection à 14 m (le couple le plus proche) : la piste 1 n'a plus rien dans sa porte. Le GNN donne 14 m
    à la piste 1 et −25 m à la piste 0, pour un coût total plus petit — le minimum de toutes les
    affectations, énumérées ici."""
    model = cv_model(2, 100.0 * np.eye(2))
    x = np.array([[0.0, 0.0, 0.0, 0.0], [30.0, 0.0, 0.0, 0.0]])
    P = np.stack([np.eye(4) * 50.0] * 2)
    z = np.array([[14.0, 0.0], [-25.0, 0.0]])
    gate = kc.validation_gate(model, x, P, z, gate_probability=0.999)
    gnn = kc.gnn_assign(model, x, P, z, gate_probability=0.999)
    nn = kc.nn_assign(model, x, P, z, gate_probability=0.999)
    options = [a for a in itertools.product(range(-1, 2), repeat=2)
               if all(j < 0 or gate.inside[t, j] for t, j in enumerate(a)) and (a[0] < 0 or a[0] != a[1])]
    best = min(options, key=lambda a: _total_cost(gate.nis, gate.threshold, a))
    np.testing.assert_array_equal(gnn, best)
    np.testing.assert_array_equal(gnn, [1, 0])
    np.testing.assert_array_equal(nn, [0, -1])
    assert not gate.inside[1, 1]  # −25 m est hors de la porte de la piste 1
    assert _total_cost(gate.nis, gate.threshold, nn) > _total_cost(gate.nis, gate.threshold, gnn)


# --------------------------------------------------------------------------- GOSPA, OSPA


def _ss_states(points):
    return [State(np.asarray(p, float)[:, None], timestamp=T0) for p in points]


def point_sets(seed):
    rng = np.random.default_rng(seed)
    n_X, n_Y = rng.integers(0, 6, 2)
    X = rng.uniform(0, 100, (n_X, 2))
    Y = np.vstack([X[: min(n_X, n_Y)] + rng.normal(0, 8, (min(n_X, n_Y), 2)), rng.uniform(0, 100, (max(0, n_Y - n_X), 2))])
    return X, Y[rng.permutation(len(Y))] if len(Y) else Y.reshape(0, 2)


@pytest.mark.parametrize("p", [1, 2, 3])
@pytest.mark.parametrize("seed", range(8))
def test_gospa_matches_stonesoup(seed, p):
    X, Y = point_sets(seed)
    c = 20.0
    ours = kc.gospa(X, Y, c=c, p=p)
    metric, assignment = GOSPAMetric(c=c, p=p).compute_gospa_metric(_ss_states(Y), _ss_states(X))
    v = metric.value
    assert ours.distance == pytest.approx(v["distance"], rel=RTOL, abs=1e-12)
    if p < 3:  # à p = 3, Stone Soup peut mal répartir les composantes (la somme reste juste) : voir plus bas
        assert (ours.localisation, ours.missed, ours.false) == pytest.approx(
            (v["localisation"], v["missed"], v["false"]), rel=RTOL, abs=1e-12)
        if len(X) and len(Y):
            np.testing.assert_array_equal(ours.assignment, assignment)


def brute_force_gospa(X, Y, c, p):
    """GOSPA (α = 2) par énumération de tous les couplages partiels, et sa décomposition."""
    n_X, n_Y = len(X), len(Y)
    best = None
    for k in range(min(n_X, n_Y) + 1):
        for rows in itertools.combinations(range(n_X), k):
            for cols in itertools.permutations(range(n_Y), k):
                d = [np.linalg.norm(X[i] - Y[j]) for i, j in zip(rows, cols)]
                if any(di >= c for di in d):
                    continue
                loc = sum(di ** p for di in d)
                total = loc + c ** p / 2 * (n_X + n_Y - 2 * k)
                if best is None or total < best[0] - 1e-12:
                    best = (total, loc, c ** p / 2 * (n_X - k), c ** p / 2 * (n_Y - k))
    return best


@pytest.mark.parametrize("p", [1, 2, 3, 1.5])
@pytest.mark.parametrize("seed", range(10))
def test_gospa_decomposition_by_enumeration(seed, p):
    X, Y = point_sets(seed)
    c = 20.0
    ours = kc.gospa(X, Y, c=c, p=p)
    total, loc, missed, false = brute_force_gospa(X, Y, c, p)
    assert ours.distance == pytest.approx(total ** (1 / p), rel=1e-12, abs=1e-12)
    assert (ours.localisation, ours.missed, ours.false) == pytest.approx((loc, missed, false), rel=1e-12, abs=1e-12)
    matched = ours.assignment >= 0
    assert matched.sum() == round(len(X) - missed / (c ** p / 2))
    for i in np.flatnonzero(matched):
        assert np.linalg.norm(X[i] - Y[ours.assignment[i]]) < c
    assert len(set(ours.assignment[matched])) == matched.sum()


def test_gospa_components_sum_to_the_distance():
    """Les composantes sont des puissances p-ièmes : leur somme est la distance à la puissance p."""
    for seed in range(10):
        X, Y = point_sets(seed)
        for p in (1, 2, 3):
            g = kc.gospa(X, Y, c=20.0, p=p)
            assert g.distance ** p == pytest.approx(g.localisation + g.missed + g.false, rel=1e-12, abs=1e-12)


def brute_force_ospa(X, Y, c, p):
    if len(X) > len(Y):
        X, Y = Y, X
    n_X, n_Y = len(X), len(Y)
    if n_Y == 0:
        return 0.0
    best = min(sum(min(np.linalg.norm(X[i] - Y[j]), c) ** p for i, j in enumerate(cols))
               for cols in itertools.permutations(range(n_Y), n_X))
    return ((best + c ** p * (n_Y - n_X)) / n_Y) ** (1 / p)


@pytest.mark.parametrize("seed", range(8))
def test_ospa_matches_stonesoup_at_p1_and_enumeration_for_every_p(seed):
    X, Y = point_sets(seed)
    c = 20.0
    if len(X) or len(Y):
        ss = OSPAMetric(c=c, p=1).compute_OSPA_distance(_ss_states(Y), _ss_states(X)).value
        assert kc.ospa(X, Y, c=c, p=1) == pytest.approx(ss, rel=RTOL, abs=1e-12)
    for p in (1, 2, 3, 1.5):
        assert kc.ospa(X, Y, c=c, p=p) == pytest.approx(brute_force_ospa(X, Y, c, p), rel=1e-12, abs=1e-12)


def test_stonesoup_ospa_is_wrong_for_p_above_one():
    """Stone Soup minimise Σ min(d, c) puis élève à la puissance p. Ici, le couplage {(0, 0), (1, 1)} a la
    plus petite somme des distances (14,23 < 14,93) mais la plus grande somme des carrés (138 > 114) : à
    p = 2, Stone Soup garde le mauvais et surestime l'OSPA."""
    X = np.array([[4.0, 3.0], [1.0, 8.0]])
    Y = np.array([[6.0, 1.0], [10.0, 1.0]])
    c, p = 100.0, 2
    ss = OSPAMetric(c=c, p=p).compute_OSPA_distance(_ss_states(Y), _ss_states(X)).value
    ours = kc.ospa(X, Y, c=c, p=p)
    assert ours == pytest.approx(math.sqrt(114.0 / 2), rel=1e-12) == brute_force_ospa(X, Y, c, p)
    assert ss == pytest.approx(math.sqrt(138.0 / 2), rel=1e-12)


def test_metrics_of_empty_sets():
    empty = np.empty((0, 2))
    g = kc.gospa(empty, empty, c=10.0, p=2)
    assert g == (0.0, 0.0, 0.0, 0.0, g.assignment) and g.assignment.shape == (0,)
    assert kc.ospa(empty, empty, c=10.0) == 0.0
    three = np.zeros((3, 2))
    g = kc.gospa(three, empty, c=10.0, p=2)
    assert (g.missed, g.false, g.distance) == pytest.approx((150.0, 0.0, math.sqrt(150.0)))
    np.testing.assert_array_equal(g.assignment, [-1, -1, -1])
    g = kc.gospa(empty, three, c=10.0, p=1)
    assert (g.missed, g.false, g.distance) == (0.0, 15.0, 15.0)
    assert kc.ospa(three, empty, c=10.0, p=2) == pytest.approx(10.0)


# --------------------------------------------------------------------------- pisteur : règles sur de petites scènes


def tracker_model(dt=1.0):
    return cv_model(2, 25.0 * np.eye(2), dt=dt, q=0.5)


def straight(start, velocity, k, dt=1.0):
    return np.asarray(start, float) + k * dt * np.asarray(velocity, float)


KW = dict(detection_probability=0.9, clutter_density=1e-6, max_speed=50.0)


@pytest.mark.parametrize("association", kc.multitarget.tracker.ASSOCIATIONS)
def test_two_point_initiation_and_immediate_confirmation(association):
    model = tracker_model(dt=2.0)
    s, z = np.array([0.0, 0.0]), np.array([60.0, 20.0])  # 63 m en 2 s : sous 50 m/s
    res = kc.multi_target_tracker(model, [s[None], z[None]], confirm=(2, 3), association=association, **KW)
    assert len(res.ids) == 2 and res.ids[0].size == 0
    np.testing.assert_array_equal(res.ids[1], [0])
    np.testing.assert_allclose(res.x[1][0], [60.0, 20.0, 30.0, 10.0])
    R = model.R
    expected_P = np.block([[R, R / 2.0], [R / 2.0, 2.0 * R / 4.0]])
    np.testing.assert_allclose(res.P[1][0], expected_P)
    # au-delà de la vitesse maximale : aucune piste
    far = kc.multi_target_tracker(model, [s[None], np.array([[120.0, 0.0]])], confirm=(2, 3), **KW)
    assert far.ids[1].size == 0


def test_m_of_n_confirmation_and_abandon():
    """confirm = (3, 4) : les deux détections de naissance comptent pour les relevés 0 et 1. Cible A :
    détectée en 0, 1, (pas en 2), 3 → 3 touches sur 4, confirmée au relevé 3. Cible B : détectée en 0, 1
    puis plus jamais → abandonnée au relevé 3 sans jamais être confirmée."""
    model = tracker_model()
    a = lambda k: straight([0.0, 0.0], [20.0, 0.0], k)  # noqa: E731
    b = lambda k: straight([0.0, 5000.0], [0.0, -20.0], k)  # noqa: E731
    scans = [np.array([a(0), b(0)]), np.array([a(1), b(1)]), np.empty((0, 2)), np.array([a(3)]), np.array([a(4)])]
    res = kc.multi_target_tracker(model, scans, confirm=(3, 4), association="gnn", **KW)
    assert [r.tolist() for r in res.ids] == [[], [], [], [0], [0]]
    np.testing.assert_allclose(res.x[3][0][:2], a(3), atol=5.0)
    # sans la détection du relevé 3, A n'a plus que 2 touches possibles sur 4 + … : abandonnée
    scans[3] = np.empty((0, 2))
    res = kc.multi_target_tracker(model, scans, confirm=(3, 4), association="gnn", **KW)
    assert all(r.size == 0 for r in res.ids)


def test_kalman_updates_of_a_gnn_track_are_the_kalman_filter_from_its_birth():
    """Sans fouillis, une piste GNN est un filtre de Kalman parti de l'état de naissance (deux points)."""
    model = tracker_model()
    rng = np.random.default_rng(4)
    truth = np.array([straight([100.0, -50.0], [15.0, 8.0], k) for k in range(8)])
    y = truth + rng.normal(0.0, 5.0, truth.shape)
    res = kc.multi_target_tracker(model, [row[None] for row in y], confirm=(3, 5), association="gnn", **KW)
    x_birth = np.concatenate([y[1], y[1] - y[0]])
    P_birth = np.block([[model.R, model.R], [model.R, 2.0 * model.R]])
    kf = kc.kalman_filter(model, y[2:], x_birth, P_birth, form="joseph")
    for k in range(3, 8):  # confirmée au relevé 2 (3 touches sur 3)
        np.testing.assert_array_equal(res.ids[k], [0])
        np.testing.assert_allclose(res.x[k][0], kf.x[k - 2], rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(res.P[k][0], kf.P[k - 2], rtol=1e-9, atol=1e-9)
    assert res.ids[2].tolist() == [0] and res.ids[1].tolist() == []


def test_deletion_after_consecutive_misses_and_ids_never_reused():
    """Une piste confirmée sans touche pendant ``delete_after`` relevés est supprimée à ce relevé ; une cible
    qui réapparaît plus tard reçoit un nouveau numéro. Les numéros suivent l'ordre de confirmation."""
    model = tracker_model()
    a = lambda k: straight([0.0, 0.0], [20.0, 0.0], k)  # noqa: E731
    b = lambda k: straight([0.0, 3000.0], [0.0, 20.0], k)  # noqa: E731
    scans = [np.array([a(0)]), np.array([a(1)]), np.array([a(2), b(2)]), np.array([b(3)]), np.array([b(4)]),
             np.array([b(5)]), np.array([a(6), b(6)]), np.array([a(7), b(7)])]
    res = kc.multi_target_tracker(model, scans, confirm=(2, 2), delete_after=3, association="jpda", **KW)
    # A confirmée au relevé 1 (n° 0), B au relevé 3 (n° 1) ; A manque 3, 4, 5 : supprimée au relevé 5 ;
    # A revient en 6 (germe) et 7 : nouvelle piste n° 2
    assert [r.tolist() for r in res.ids] == [[], [0], [0], [0, 1], [0, 1], [1], [1], [1, 2]]
    np.testing.assert_allclose(res.x[7][1][:2], a(7))


def test_tentative_tracks_only_see_detections_left_by_confirmed_tracks():
    """Une détection prise par une piste confirmée ne peut ni corriger une piste provisoire ni servir de germe."""
    model = tracker_model()
    a = lambda k: straight([0.0, 0.0], [20.0, 0.0], k)  # noqa: E731
    scans = [np.array([a(k)]) for k in range(6)]
    res = kc.multi_target_tracker(model, scans, confirm=(2, 3), association="gnn", **KW)
    # une seule piste : après sa confirmation, ses détections sont prises, aucun germe ne naît
    assert [r.tolist() for r in res.ids] == [[], [0], [0], [0], [0], [0]]


def test_seed_used_once_as_a_birth_is_not_a_seed_again():
    """Une détection qui a fait naître une piste au relevé k n'est pas un germe au relevé k + 1 : avec
    confirm = (3, 3) et une cible détectée aux relevés 0 et 1 seulement, puis une détection à 50 m au relevé
    2, la piste née en 1 est abandonnée en 2 (elle manque), et aucune piste ne naît du couple (z₁, z₂)."""
    model = tracker_model()
    scans = [np.array([[0.0, 0.0]]), np.array([[20.0, 0.0]]), np.array([[20.0, 45.0]]), np.array([[20.0, 90.0]])]
    res = kc.multi_target_tracker(model, scans, confirm=(3, 3), association="gnn", **KW)
    # la détection du relevé 2 est hors de la porte de la piste née en 1 (prévue à 40 m à l'est) ; elle
    # devient un germe, et (z₂, z₃) fait naître une piste qui n'a que 2 touches au relevé 3.
    assert all(r.size == 0 for r in res.ids)
    res = kc.multi_target_tracker(model, scans, confirm=(2, 3), association="gnn", **KW)
    ids = [r.tolist() for r in res.ids]
    assert ids[1] == [0] and 1 in ids[3]  # (z₂, z₃) : une nouvelle piste ; pas de piste (z₁, z₂)
    assert all(np.linalg.norm(x[:2] - [20.0, 45.0]) > 1.0 for x in res.x[2])


def test_jpda_tracks_update_as_stonesoup_jpda_and_pda_updater():
    """Deux pistes confirmées à la naissance (M = 2), puis un relevé de détections disputées : la correction
    JPDA du pisteur est celle de Stone Soup (JPDA + PDAUpdater) sur les mêmes prédictions."""
    model = tracker_model()
    s = np.array([[0.0, 0.0], [0.0, 40.0]])
    z1 = np.array([[20.0, 5.0], [20.0, 33.0]])
    z2 = np.array([[41.0, 16.0], [39.0, 27.0], [60.0, 60.0]])
    kw = dict(detection_probability=0.9, clutter_density=1e-4, max_speed=25.0, gate_probability=0.99)
    res = kc.multi_target_tracker(model, [s, z1, z2], confirm=(2, 3), association="jpda", **kw)
    assert res.ids[1].tolist() == [0, 1] and res.ids[2].tolist() == [0, 1]
    x_birth = np.hstack([z1, z1 - s])
    P_birth = np.block([[model.R, model.R], [model.R, 2.0 * model.R]])
    x_pred = x_birth @ model.A.T
    P_pred = model.A @ P_birth @ model.A.T + model.Q
    ss = StoneSoup(model)
    dets = ss.detections(z2)
    tracks = [ss.track(x_pred[t], P_pred) for t in range(2)]
    result = JPDA(ss.pda(0.9, 1e-4, 0.99)).associate(set(tracks), set(dets), T0)
    for t, track in enumerate(tracks):
        x_ss, P_ss = ss.state(PDAUpdater(ss.measurement).update(result[track]))
        np.testing.assert_allclose(res.x[2][t], x_ss, rtol=RTOL, atol=1e-9)
        np.testing.assert_allclose(res.P[2][t], P_ss, rtol=RTOL, atol=1e-9)
    beta = kc.jpda_probabilities(model, x_pred, np.stack([P_pred] * 2), z2, detection_probability=0.9,
                                 clutter_density=1e-4, gate_probability=0.99)
    assert (beta[:, 1:3] > 0.05).all()  # les deux détections sont vraiment disputées


@pytest.mark.parametrize("association", ["pda", "jpda", "gnn", "nn"])
def test_pda_tracks_hit_when_a_detection_outweighs_the_miss(association):
    """Une piste confirmée qui ne reçoit que des détections lointaines (hors porte) pendant deux relevés est
    supprimée avec delete_after = 2 ; avec une détection proche à chaque relevé, elle reste."""
    model = tracker_model()
    a = lambda k: straight([0.0, 0.0], [20.0, 0.0], k)  # noqa: E731
    far = np.array([[5000.0, 5000.0]])
    scans = [np.array([a(0)]), np.array([a(1)]), far, far + 400.0, np.array([a(4)])]
    res = kc.multi_target_tracker(model, scans, confirm=(2, 2), delete_after=2, association=association, **KW)
    assert [r.tolist() for r in res.ids[:4]] == [[], [0], [0], []]


# --------------------------------------------------------------------------- entrées invalides


def _good():
    model, x, P, z = scene(0, 2)
    return model, x, P, z


BAD_SETTINGS = [
    (dict(detection_probability=1.2), "« detection_probability » doit être une probabilité dans ]0, 1] ; reçu 1.2."),
    (dict(detection_probability=0.0), "detection_probability"),
    (dict(detection_probability=True), "detection_probability"),
    (dict(detection_probability=float("nan")), "detection_probability"),
    (dict(clutter_density=0.0), "« clutter_density » doit être une densité"),
    (dict(clutter_density=-1e-4), "clutter_density"),
    (dict(clutter_density="1e-4"), "clutter_density"),
    (dict(gate_probability=1.0), "« gate_probability » doit être une probabilité strictement entre 0 et 1"),
    (dict(gate_probability=0.0), "gate_probability"),
]


@pytest.mark.parametrize("bad, message", BAD_SETTINGS)
def test_settings_are_checked_in_french(bad, message):
    model, x, P, z = _good()
    kw = dict(detection_probability=0.9, clutter_density=1e-4, gate_probability=0.99)
    kw.update(bad)
    calls = [lambda: kc.pda_update(model, x[0], P[0], z, **kw), lambda: kc.jpda_probabilities(model, x, P, z, **kw),
             lambda: kc.multi_target_tracker(model, [z], max_speed=10.0, **kw)]
    if set(bad) == {"gate_probability"}:
        calls += [lambda: kc.validation_gate(model, x, P, z, gate_probability=bad["gate_probability"]),
                  lambda: kc.gnn_assign(model, x, P, z, gate_probability=bad["gate_probability"]),
                  lambda: kc.nn_assign(model, x, P, z, gate_probability=bad["gate_probability"])]
    for call in calls:
        with pytest.raises(KalmanInputError, match=message.replace("(", r"\(").replace(")", r"\)")
                           .replace("[", r"\[").replace("]", r"\]").replace(".", r"\.")):
            call()


def _gate(**over):
    model, x, P, z = _good()
    args = dict(model=model, x_pred=x, P_pred=P, detections=z)
    args.update(over)
    return kc.validation_gate(args["model"], args["x_pred"], args["P_pred"], args["detections"], gate_probability=0.99)


@pytest.mark.parametrize("over, message", [
    (dict(x_pred=np.zeros(4)), r"« x_pred » doit être de forme \(T, 4\).*x_pred\[None\]"),
    (dict(x_pred=np.zeros((2, 3))), r"« x_pred » doit être de forme \(T, 4\)"),
    (dict(P_pred=np.zeros((3, 4, 4))), r"« P_pred » doit être de forme \(2, 4, 4\)"),
    (dict(P_pred=np.stack([np.eye(4), np.diag([1.0, 1.0, 1.0, -1.0])])), r"« P_pred\[1\] » doit être semi-définie"),
    (dict(P_pred=np.stack([np.eye(4), np.eye(4) + np.triu(np.ones((4, 4)), 1)])), r"« P_pred\[1\] » doit être symétrique"),
    (dict(detections=np.zeros((3, 3))), r"« detections » doit être de forme \(N, 2\)"),
    (dict(detections=np.zeros(2)), r"« detections ».*forme \(1, 2\)"),
    (dict(detections=[[1.0, np.nan]]), r"« detections » contient des valeurs non finies"),
    (dict(model="modèle"), r"« model » doit être un LinearGaussianModel"),
    (dict(model=kc.constant_velocity_model(np.ones(3), 1.0, np.hstack([np.eye(2), np.zeros((2, 2))]), np.eye(2))),
     r"« model » doit être un modèle constant"),
])
def test_shapes_and_models_are_checked_in_french(over, message):
    with pytest.raises(KalmanInputError, match=message):
        _gate(**over)


def test_single_track_arguments_of_pda_update_are_checked():
    model, x, P, z = _good()
    kw = dict(detection_probability=0.9, clutter_density=1e-4, gate_probability=0.99)
    with pytest.raises(KalmanInputError, match=r"« x_pred » doit être un vecteur de forme \(4,\)"):
        kc.pda_update(model, x, P[0], z, **kw)
    with pytest.raises(KalmanInputError, match=r"« P_pred » doit être une matrice de forme \(4, 4\)"):
        kc.pda_update(model, x[0], P, z, **kw)


@pytest.mark.parametrize("kwargs, message", [
    (dict(c=0.0), "« c » doit être une distance de coupure strictement positive"),
    (dict(c=10.0, p=0.5), r"« p » doit être un ordre 1 ≤ p < ∞"),
    (dict(c=10.0, p=float("inf")), r"« p » doit être un ordre 1 ≤ p < ∞"),
    (dict(c=10.0, alpha=1), "« alpha » doit valoir 2"),
])
def test_metric_settings_are_checked_in_french(kwargs, message):
    with pytest.raises(KalmanInputError, match=message):
        kc.gospa(np.zeros((1, 2)), np.zeros((1, 2)), **kwargs)
    if "alpha" not in kwargs:
        with pytest.raises(KalmanInputError, match=message):
            kc.ospa(np.zeros((1, 2)), np.zeros((1, 2)), **kwargs)


def test_metric_points_are_checked_in_french():
    with pytest.raises(KalmanInputError, match="« X » doit être un tableau"):
        kc.gospa(np.zeros(3), np.zeros((1, 3)), c=1.0)
    with pytest.raises(KalmanInputError, match="même nombre de coordonnées"):
        kc.ospa(np.zeros((1, 2)), np.zeros((1, 3)), c=1.0)


@pytest.mark.parametrize("over, message", [
    (dict(model=kc.LinearGaussianModel(np.eye(4), np.hstack([np.eye(2), np.zeros((2, 2))]), np.eye(4), np.eye(2))),
     "« model » doit être le modèle à vitesse presque constante"),
    (dict(model=kc.LinearGaussianModel(np.eye(2), np.eye(2), np.eye(2), np.eye(2))), "« model » doit être le modèle"),
    (dict(association="mht"), "« association » doit valoir 'nn', 'gnn', 'pda', 'jpda'"),
    (dict(confirm=(1, 3)), r"« confirm » doit être un couple d'entiers \(M, N\) avec 2 ≤ M ≤ N"),
    (dict(confirm=(4, 3)), "« confirm »"),
    (dict(confirm=(2.0, 3)), "« confirm »"),
    (dict(confirm=3), "« confirm »"),
    (dict(delete_after=0), "« delete_after » doit être un entier ≥ 1"),
    (dict(max_speed=0.0), "« max_speed » doit être une vitesse strictement positive"),
    (dict(scans=[]), "« scans » ne contient aucun relevé"),
    (dict(scans=[np.zeros((1, 2)), np.zeros((2, 3))]), r"« scans\[1\] » doit être de forme \(N, 2\)"),
    (dict(scans="relevés"), "« scans » doit être une suite de relevés"),
])
def test_tracker_arguments_are_checked_in_french(over, message):
    args = dict(model=tracker_model(), scans=[np.zeros((1, 2))], max_speed=50.0, association="jpda", confirm=(4, 5),
                delete_after=3)
    args.update(over)
    with pytest.raises(KalmanInputError, match=message):
        kc.multi_target_tracker(args.pop("model"), args.pop("scans"), detection_probability=0.9,
                                clutter_density=1e-6, **args)


# --------------------------------------------------------------------------- résultats et imports


def test_results_are_immutable_named_tuples():
    model, x, P, z = _good()
    kw = dict(detection_probability=0.9, clutter_density=1e-4, gate_probability=0.99)
    results = [kc.validation_gate(model, x, P, z, gate_probability=0.99), kc.pda_update(model, x[0], P[0], z, **kw),
               kc.gospa(x[:, :2], z, c=50.0)]
    for res in results:
        assert isinstance(res, tuple) and hasattr(res, "_fields")
        for value in res:
            if isinstance(value, np.ndarray):
                assert not value.flags.writeable
    for arr in (kc.jpda_probabilities(model, x, P, z, **kw), kc.gnn_assign(model, x, P, z, gate_probability=0.99),
                kc.nn_assign(model, x, P, z, gate_probability=0.99)):
        assert not arr.flags.writeable
    track = kc.multi_target_tracker(tracker_model(), [np.zeros((1, 2)), np.ones((1, 2))], confirm=(2, 2), **KW)
    assert track._fields == ("ids", "x", "P") and isinstance(track.ids, tuple)
    assert track.ids[1].dtype.kind == "i" and not track.x[1].flags.writeable
    assert kc.gnn_assign(model, x, P, z, gate_probability=0.99).dtype.kind == "i"


def test_the_course_never_imports_stonesoup():
    code = ("import sys; sys.modules['stonesoup'] = None\n"
            "import numpy as np, kalman_course as kc\n"
            "m = kc.constant_velocity_model(1.0, 1.0, np.hstack([np.eye(2), np.zeros((2, 2))]), np.eye(2))\n"
            "r = kc.multi_target_tracker(m, [np.zeros((1, 2)), np.ones((1, 2))], detection_probability=0.9, "
            "clutter_density=1e-4, max_speed=5.0, confirm=(2, 2))\n"
            "print(r.ids[1].tolist())")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.strip() == "[0]"


def test_event_count_is_the_number_of_partial_matchings():
    """k pistes qui voient les mêmes k détections : Σ C(k, i)² i! événements (couplages partiels) ; des grappes
    indépendantes multiplient leurs nombres."""
    from kalman_course.multitarget.jpda import count_events

    for k in range(1, 7):
        assert count_events(np.ones((k, k), dtype=bool)) == sum(math.comb(k, i) ** 2 * math.factorial(i)
                                                                 for i in range(k + 1))
    two_clusters = np.zeros((4, 4), dtype=bool)
    two_clusters[:2, :2] = True
    two_clusters[2:, 2:] = True
    assert count_events(two_clusters) == 7 * 7
    assert count_events(np.zeros((3, 2), dtype=bool)) == 1
    lone = np.array([[True, False, True]])
    assert count_events(lone) == 3


def test_clusters_are_the_connected_components_of_the_gate():
    """Les grappes de la JPDA sont les composantes connexes du graphe pistes–détections (scipy.sparse.csgraph,
    référence indépendante), sur des portes tirées au hasard."""
    import scipy.sparse
    import scipy.sparse.csgraph

    from kalman_course.multitarget.jpda import clusters

    rng = np.random.default_rng(8)
    for _ in range(50):
        T, N = rng.integers(1, 9), rng.integers(0, 9)
        inside = rng.uniform(size=(T, N)) < 0.2
        graph = scipy.sparse.bmat([[None, scipy.sparse.csr_matrix(inside.astype(float))],
                                   [scipy.sparse.csr_matrix(inside.T.astype(float)), None]]) if N else None
        expected = set()
        if N:
            _, label = scipy.sparse.csgraph.connected_components(graph, directed=False)
            for lab in set(label[:T][inside.any(axis=1)]):
                members = np.flatnonzero(label == lab)
                expected.add((tuple(members[members < T]), tuple(members[members >= T] - T)))
        found = {(tuple(t), tuple(d)) for t, d in clusters(inside)}
        assert found == expected
