"""Une seule suite pour toute la famille : chaque filtre qui se réduit au filtre de Kalman sur un modèle
linéaire est comparé à la référence indépendante (la boucle ``predict()``/``update()`` de filterpy) sur les
mêmes données — mêmes ``x`` et ``P`` à 1e-9, même traitement des mesures manquantes, mêmes erreurs
d'entrée (elles viennent du moteur commun).

Les filtres de Monte-Carlo (filtre particulaire, EnKF) rejoignent la famille **statistiquement** (liste
``STOCHASTIC``) : même moteur, mêmes erreurs d'entrée, mêmes pas sans mesure, et une moyenne qui tend vers
celle du filtre de Kalman quand le nombre de particules ou de membres croît.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
import pytest

import kalman_course as kc
from conftest import filterpy_kf, random_model
from kalman_course.filters.extended import extended_kalman_filter_runs
from kalman_course.filters.iterated import iterated_extended_kalman_filter_runs
from kalman_course.filters.unscented import unscented_kalman_filter_runs

TOL = dict(atol=1e-9, rtol=1e-9)


@dataclass(frozen=True)
class Member:
    """Un filtre de la famille : ``run(linear_model, y, x0, P0, u)`` → FilterResult."""

    name: str
    run: Callable
    partial_rows: bool = True   # accepte une ligne partiellement manquante
    control: bool = True        # accepte une commande
    vague: bool = False         # sûr pour un a priori vague (P0 = 10¹⁰ I à 10¹⁴ I)


def _nonlinear(model):
    return kc.NonlinearModel.from_linear(model)


def _stacked(model, T):
    """Le même modèle écrit comme un modèle variable dans le temps (T copies de chaque matrice)."""
    rep = lambda a: None if a is None else np.repeat(np.asarray(a)[None], T, axis=0)  # noqa: E731
    return kc.LinearGaussianModel(rep(model.A), rep(model.C), rep(model.Q), rep(model.R), B=rep(model.B))


def _ukf(model, y, x0, P0, u=None):
    return kc.unscented_kalman_filter(_nonlinear(model), y, x0, P0, u, alpha=1.0, beta=2.0, kappa=0.0)


FILTERS = [
    Member("KF", lambda m, y, x0, P0, u=None: kc.kalman_filter(m, y, x0, P0, u), vague=True),
    Member("KF (Joseph)", lambda m, y, x0, P0, u=None: kc.kalman_filter(m, y, x0, P0, u, form="joseph")),
    Member("KF (cours)", lambda m, y, x0, P0, u=None: kc.kalman_filter(m, y, x0, P0, u, form="textbook")),
    Member("KF en lot", lambda m, y, x0, P0, u=None: kc.kalman_filter_runs(m, np.asarray(y)[None], x0, P0, u).run(0),
           vague=True),
    Member("EKF", lambda m, y, x0, P0, u=None: kc.extended_kalman_filter(_nonlinear(m), y, x0, P0, u)),
    Member("EKF itéré (1)", lambda m, y, x0, P0, u=None: kc.iterated_extended_kalman_filter(
        _nonlinear(m), y, x0, P0, u, max_iter=1)),
    Member("EKF itéré (20)", lambda m, y, x0, P0, u=None: kc.iterated_extended_kalman_filter(_nonlinear(m), y, x0, P0, u)),
    Member("SRIF (inverse)", lambda m, y, x0, P0, u=None: kc.square_root_information_filter(m, y, x0, P0, u),
           vague=True),
    Member("SRIF (joint)", lambda m, y, x0, P0, u=None: kc.square_root_information_filter(
        m, y, x0, P0, u, method="joint")),
    Member("SRIF étendu", lambda m, y, x0, P0, u=None: kc.extended_square_root_information_filter(
        _nonlinear(m), y, x0, P0, u), vague=True),
    Member("UKF (α=1, β=2, κ=0)", _ukf),
    # mode en lot du moteur (run_filter_runs), sur un lot d'un tirage
    Member("EKF en lot", lambda m, y, x0, P0, u=None: extended_kalman_filter_runs(
        _nonlinear(m), np.asarray(y)[None], x0, P0, u).run(0)),
    Member("EKF itéré en lot", lambda m, y, x0, P0, u=None: iterated_extended_kalman_filter_runs(
        _nonlinear(m), np.asarray(y)[None], x0, P0, u).run(0)),
    Member("UKF en lot", lambda m, y, x0, P0, u=None: unscented_kalman_filter_runs(
        _nonlinear(m), np.asarray(y)[None], x0, P0, u, alpha=1.0, beta=2.0, kappa=0.0).run(0)),
    # le filtre gaussien et ses règles d'intégration (issue 22)
    Member("filtre gaussien (linéarisation)", lambda m, y, x0, P0, u=None: kc.gaussian_filter(
        _nonlinear(m), y, x0, P0, u, rule=kc.Linearization())),
    Member("CKF", lambda m, y, x0, P0, u=None: kc.cubature_kalman_filter(_nonlinear(m), y, x0, P0, u)),
    Member("CKF en lot", lambda m, y, x0, P0, u=None: kc.cubature_kalman_filter_runs(
        _nonlinear(m), np.asarray(y)[None], x0, P0, u).run(0)),
    Member("GHKF (p=3)", lambda m, y, x0, P0, u=None: kc.gauss_hermite_kalman_filter(_nonlinear(m), y, x0, P0, u)),
    Member("GHKF en lot (p=2)", lambda m, y, x0, P0, u=None: kc.gauss_hermite_kalman_filter_runs(
        _nonlinear(m), np.asarray(y)[None], x0, P0, u, order=2).run(0)),
    Member("IPLF (cubature)", lambda m, y, x0, P0, u=None: kc.iterated_posterior_linearization_filter(
        _nonlinear(m), y, x0, P0, u)),
]
# pistage (issue 21) : options et filtres qui redeviennent le filtre de Kalman
FILTERS += [
    Member("KF variable dans le temps (pile constante)", lambda m, y, x0, P0, u=None: kc.kalman_filter(
        _stacked(m, max(len(y), 1)), y, x0, P0, u)),
    Member("KF à porte (p = 1 − 10⁻¹²)", lambda m, y, x0, P0, u=None: kc.kalman_filter(
        m, y, x0, P0, u, gate=1 - 1e-12)),
    Member("IMM (un régime)", lambda m, y, x0, P0, u=None: kc.imm_filter([m], y, x0, P0, transition=[[1.0]], u=u)),
    Member("Q adaptative (test jamais échoué)", lambda m, y, x0, P0, u=None: kc.adaptive_kalman_filter(
        m, y, x0, P0, u, detect=1 - 1e-12)),
]
IDS = [f.name for f in FILTERS]


def _case(seed: int, n: int, m: int, p: int, T: int = 80):
    rng = np.random.default_rng(seed)
    model = random_model(rng, n, m, p)
    # dynamique stable (rayon spectral 0,95) : l'état reste d'ordre 1 et les arrondis de la moyenne des
    # points sigma de l'UKF (qui croissent avec |x|² / P) restent négligeables
    A = 0.95 * model.A / max(1.0, float(np.max(np.abs(np.linalg.eigvals(model.A)))))
    model = kc.LinearGaussianModel(A, model.C, model.Q, model.R, B=model.B)
    u = rng.standard_normal((T, p)) if p else None
    sim = kc.simulate(model, rng.standard_normal(n), T, u=u, rng=rng)
    return model, np.array(sim.y), rng.standard_normal(n), 2.0 * np.eye(n), u


@pytest.mark.parametrize("member", FILTERS, ids=IDS)
@pytest.mark.parametrize("n,m,p", [(1, 1, 0), (3, 2, 1), (4, 2, 2)])
def test_equals_filterpy_kalman_filter(member, n, m, p):
    model, y, x0, P0, u = _case(10 * n + m + p, n, m, p)
    res = member.run(model, y, x0, P0, u)
    x, P, xp, Pp = filterpy_kf(model, y, x0, P0, u=u)
    np.testing.assert_allclose(res.x, x, **TOL)
    np.testing.assert_allclose(res.P, P, **TOL)
    np.testing.assert_allclose(res.x_pred, xp, **TOL)
    np.testing.assert_allclose(res.P_pred, Pp, **TOL)
    assert isinstance(res, kc.FilterResult) and res.x.shape == (len(y), n) and res.P.shape == (len(y), n, n)


@pytest.mark.parametrize("member", FILTERS, ids=IDS)
def test_missing_rows_are_prediction_only(member):
    model, y, x0, P0, u = _case(3, 3, 2, 1)
    y[[0, 7, 8, 40]] = np.nan
    res = member.run(model, y, x0, P0, u)
    x, P, xp, Pp = filterpy_kf(model, y, x0, P0, u=u)
    np.testing.assert_allclose(res.x, x, **TOL)
    np.testing.assert_allclose(res.P, P, **TOL)
    for k in (0, 7, 8, 40):  # pas sans mesure : l'estimation est la prédiction, gain nul
        np.testing.assert_array_equal(res.x[k], res.x_pred[k])
        assert not res.observed[k].any() and np.all(res.K[k] == 0) and np.isnan(res.innovation[k]).all()


@pytest.mark.parametrize("member", [f for f in FILTERS if f.partial_rows], ids=[f.name for f in FILTERS if f.partial_rows])
def test_partial_rows_use_only_the_observed_components(member):
    """Référence indépendante : filterpy avec, au pas partiel, la seule ligne observée de C et de R."""
    model, y, x0, P0, u = _case(5, 3, 2, 1, T=30)
    y[[4, 12], 1] = np.nan
    res = member.run(model, y, x0, P0, u)
    from filterpy.kalman import KalmanFilter

    f = KalmanFilter(dim_x=3, dim_z=2, dim_u=1)
    f.F, f.B, f.Q = np.array(model.A), np.array(model.B), np.array(model.Q)
    f.x, f.P = x0.reshape(3, 1), P0.copy()
    for k in range(len(y)):
        f.predict(u=u[k].reshape(1, 1))
        obs = ~np.isnan(y[k])
        f.update(y[k, obs].reshape(-1, 1), R=np.array(model.R)[np.ix_(obs, obs)], H=np.array(model.C)[obs])
        np.testing.assert_allclose(res.x[k], f.x.ravel(), **TOL)
        np.testing.assert_allclose(res.P[k], f.P, **TOL)
    assert res.observed[4].tolist() == [True, False] and np.isnan(res.innovation[4, 1])
    assert np.all(res.K[4][:, 1] == 0) and np.isnan(res.S[4][1]).all()


def test_nis_is_consistent_on_every_member():
    """Innovation et S de chaque filtre forment une NIS du même filtre linéaire (à 1e-9)."""
    model, y, x0, P0, u = _case(11, 3, 2, 1)
    ref = kc.nis(kc.kalman_filter(model, y, x0, P0, u))
    for member in FILTERS:
        np.testing.assert_allclose(kc.nis(member.run(model, y, x0, P0, u)), ref, rtol=1e-8, err_msg=member.name)


# --------------------------------------------------------------------------- a priori vague


def _vague_case(name):
    if name == "vitesse constante au mm":  # le scénario du chapitre SRIF : positions à 1 mm près, état à 100 m
        return kc.scenarios.diffuse.diffuse_model(), kc.scenarios.diffuse.diffuse_data()[1]
    rng = np.random.default_rng(5)  # 3 états, 2 mesures mélangées, dynamique stable
    A = np.array([[0.9, 0.2, 0.0], [0.0, 0.8, 0.3], [0.1, 0.0, 0.7]])
    model = kc.LinearGaussianModel(A, rng.standard_normal((2, 3)), 0.1 * np.eye(3), np.diag([0.5, 0.2]))
    return model, kc.simulate(model, np.ones(3), 50, rng=4).y


VAGUE = [f for f in FILTERS if f.vague]


@pytest.mark.parametrize("member", VAGUE, ids=[f.name for f in VAGUE])
@pytest.mark.parametrize("exponent", [10, 12, 14])
@pytest.mark.parametrize("case", ["vitesse constante au mm", "3 états, 2 mesures"])
def test_vague_prior_reaches_the_exact_diffuse_start(member, exponent, case):
    """Un a priori vague x̂₀ = 0, P₀ = 10ᵏ I (ce qu'utilisent les étudiants et l'« approximate diffuse » de
    statsmodels) : dès le 2ᵉ pas (le 1ᵉʳ ne détermine pas l'état), la moyenne est à moins de 10⁻⁸ du départ
    diffus exact (filtre augmenté, vérifié contre statsmodels et l'arithmétique décimale à 120 chiffres),
    et au moins aussi près que la forme de Joseph de filterpy. Mesuré : ≤ 1,1 × 10⁻⁹ pour le KF (racine
    carrée), quand filterpy s'écarte de 10⁻⁷ à 0,5 et que la forme du cours échoue à 10¹² (S non définie
    positive)."""
    model, y = _vague_case(case)
    n = model.n_state
    exact = kc.diffuse_kalman_filter(model, y).x
    assert np.isnan(exact[0]).all() and np.isfinite(exact[1:]).all()
    P0 = 10.0**exponent * np.eye(n)
    res = member.run(model, y, np.zeros(n), P0)
    gap = np.max(np.abs(res.x[1:] - exact[1:]))
    joseph = np.max(np.abs(filterpy_kf(model, y, np.zeros(n), P0)[0][1:] - exact[1:]))
    assert gap < 1e-8, gap
    assert gap <= joseph, (gap, joseph)
    assert np.isfinite(res.P).all() and (np.linalg.eigvalsh(res.P[1:])[:, 0] > 0).all()


def test_vague_prior_breaks_the_textbook_form_as_the_srif_chapter_shows():
    """La forme du cours (P = P⁻ − KCP⁻), gardée pour le chapitre SRIF : avec P₀ = 10¹⁰ I elle s'écarte de plus
    de 10⁻⁵ du départ diffus exact, et à 10¹² S n'est plus définie positive (erreur française)."""
    model, y = _vague_case("vitesse constante au mm")
    exact = kc.diffuse_kalman_filter(model, y).x
    res = kc.kalman_filter(model, y, np.zeros(4), 1e10 * np.eye(4), form="textbook")
    assert np.max(np.abs(res.x[1:] - exact[1:])) > 1e-5
    with pytest.raises(kc.KalmanInputError, match=r"« S = C P⁻ Cᵀ \+ R » n'est pas définie positive"):
        kc.kalman_filter(model, y, np.zeros(4), 1e12 * np.eye(4), form="textbook")


# --------------------------------------------------------------------------- mêmes erreurs d'entrée

BAD_INPUTS = [
    (dict(y=np.zeros((5, 3))), r"« y » doit être de forme \(T, 2\)"),
    (dict(y=np.zeros((0, 2))), r"« y » ne contient aucune mesure"),
    (dict(y=np.full((5, 2), np.inf)), r"« y » contient des valeurs infinies"),
    (dict(x0=np.zeros(4)), r"« x0 » doit être un vecteur de forme \(3,\) ; reçu la forme \(4,\)"),
    (dict(x0=np.zeros((3, 1))), r"vecteur colonne"),
    (dict(P0=-np.eye(3)), r"« P0 » doit être (semi-)?définie positive"),  # définie pour le SRIF étendu
    (dict(P0=np.ones((3, 2))), r"« P0 » doit être une matrice carrée"),
    (dict(u=np.zeros((4, 1))), r"« u » doit avoir une commande par pas de temps : 5 ligne\(s\) attendue\(s\), 4"),
]


@pytest.mark.parametrize("member", [f for f in FILTERS if not f.name.startswith("SRIF (") and "en lot" not in f.name],
                         ids=[f.name for f in FILTERS if not f.name.startswith("SRIF (") and "en lot" not in f.name])
@pytest.mark.parametrize("bad, message", BAD_INPUTS)
def test_same_bad_input_errors(member, bad, message):
    model, y, x0, P0, u = _case(1, 3, 2, 1, T=5)
    args = dict(y=y, x0=x0, P0=P0, u=u)
    args.update(bad)
    with pytest.raises(kc.KalmanInputError, match=message):
        member.run(model, args["y"], args["x0"], args["P0"], args["u"])


@pytest.mark.parametrize("bad, message", BAD_INPUTS[:3] + BAD_INPUTS[7:])
@pytest.mark.parametrize("method", ["inverse", "joint"])
def test_srif_shares_the_engine_errors(bad, message, method):
    model, y, x0, P0, u = _case(1, 3, 2, 1, T=5)
    args = dict(y=y, u=u)
    args.update(bad)
    with pytest.raises(kc.KalmanInputError, match=message):
        kc.square_root_information_filter(model, args["y"], x0, P0, args["u"], method=method)


@pytest.mark.parametrize(
    "call",
    [
        lambda m, y: kc.kalman_filter(kc.NonlinearModel.from_linear(m), y, np.zeros(3), np.eye(3)),
        lambda m, y: kc.extended_kalman_filter(m, y, np.zeros(3), np.eye(3)),
        lambda m, y: kc.iterated_extended_kalman_filter(m, y, np.zeros(3), np.eye(3)),
        lambda m, y: kc.square_root_information_filter(kc.NonlinearModel.from_linear(m), y),
        lambda m, y: kc.extended_square_root_information_filter(m, y, np.zeros(3), np.eye(3)),
        lambda m, y: kc.kalman_filter_runs(kc.NonlinearModel.from_linear(m), y[None], np.zeros(3), np.eye(3)),
    ],
)
def test_wrong_model_type_is_named_with_a_hint(call):
    model, y, *_ = _case(1, 3, 2, 0, T=5)
    with pytest.raises(kc.KalmanInputError, match=r"« model » doit être un \w+ ; reçu \w+ \(pour un modèle"):
        call(model, y)


def test_control_without_B_is_refused_by_every_member():
    model, y, x0, P0, _ = _case(1, 3, 2, 0, T=5)
    for member in FILTERS:
        with pytest.raises(kc.KalmanInputError, match="« u » est fourni mais le modèle n'a pas de matrice de commande B"):
            member.run(model, y, x0, P0, np.zeros((5, 1)))


# --------------------------------------------------------------------------- tirages en lot


@pytest.mark.parametrize("missing", [False, True])
def test_runs_equal_kalman_filter_run_by_run(missing):
    rng = np.random.default_rng(8)
    model = _case(8, 4, 2, 1)[0]
    N, T = 12, 40
    U = rng.standard_normal((T, 1))
    Y = np.stack([kc.simulate(model, rng.standard_normal(4), T, U, rng=rng).y for _ in range(N)])
    X0 = rng.standard_normal((N, 4))
    if missing:
        Y[rng.random((N, T)) < 0.15] = np.nan          # lignes entières
        Y[:, :, 1][rng.random((N, T)) < 0.2] = np.nan  # composantes isolées
    runs = kc.kalman_filter_runs(model, Y, X0, np.eye(4), U)
    assert runs.x.shape == (N, T, 4)
    assert runs.shared_covariance is (not missing)
    assert runs.P.shape == ((T, 4, 4) if not missing else (N, T, 4, 4))
    for r in range(N):
        ref = kc.kalman_filter(model, Y[r], X0[r], np.eye(4), U)
        one = runs.run(r)
        for field in ("x", "P", "x_pred", "P_pred", "K", "innovation", "S"):
            np.testing.assert_allclose(getattr(one, field), getattr(ref, field), rtol=1e-12, atol=1e-12,
                                       err_msg=field)
        np.testing.assert_array_equal(one.observed, ref.observed)
        np.testing.assert_array_equal(one.n_iter, ref.n_iter)


def test_runs_bad_input():
    rng = np.random.default_rng(2)
    model = random_model(rng, 2, 1, 0)
    with pytest.raises(kc.KalmanInputError, match=r"« Y » doit être de forme \(N, T, 1\) : .* reçu la forme \(5,\)\.$"):
        kc.kalman_filter_runs(model, np.zeros(5), np.zeros(2), np.eye(2))
    # 2-D : 30 tirages d'une mesure, ou un tirage de 30 mesures ? Refusé, avec les deux écritures possibles
    with pytest.raises(kc.KalmanInputError, match=r"reçu la forme \(30, 1\) : pour un seul tirage, .* Y\[None\] ; "
                                                  r"pour N tirages d'une mesure scalaire, donnez Y\[\.\.\., None\]"):
        kc.kalman_filter_runs(model, np.zeros((30, 1)), np.zeros(2), np.eye(2))
    Y = np.zeros((3, 5, 1))
    with pytest.raises(kc.KalmanInputError, match=r"« x0 » doit être de forme \(2,\) \(commun\) ou \(3, 2\)"):
        kc.kalman_filter_runs(model, Y, np.zeros((4, 2)), np.eye(2))
    with pytest.raises(kc.KalmanInputError, match=r"« P0 » doit être de forme \(2, 2\) \(commune\) ou \(3, 2, 2\)"):
        kc.kalman_filter_runs(model, Y, np.zeros(2), np.ones((4, 2, 2)))
    with pytest.raises(kc.KalmanInputError, match=r"« P0\[1\] » doit être semi-définie positive"):
        kc.kalman_filter_runs(model, Y, np.zeros(2), np.stack([np.eye(2), -np.eye(2), np.eye(2)]))
    with pytest.raises(kc.KalmanInputError, match=r"« u » est fourni mais le modèle n'a pas de matrice de commande B"):
        kc.kalman_filter_runs(model, Y, np.zeros(2), np.eye(2), u=np.zeros(5))
    with pytest.raises(kc.KalmanInputError, match=r"« u » doit être de forme \(5, 1\) \(commune\) ou \(3, 5, 1\)"):
        kc.kalman_filter_runs(kc.LinearGaussianModel(model.A, model.C, model.Q, model.R, B=np.ones((2, 1))), Y,
                              np.zeros(2), np.eye(2), u=np.zeros((2, 5, 1)))
    runs = kc.kalman_filter_runs(model, Y, np.zeros(2), np.eye(2))
    with pytest.raises(kc.KalmanInputError, match="« i » doit être un indice de tirage"):
        runs.run(3)


def test_runs_with_a_prior_and_controls_per_run_equal_the_filter_run_by_run():
    """P0 (N, n, n) et u (N, T, p) propres à chaque tirage : le KF en lot (et l'EKF en lot, qui prédit alors
    tirage par tirage) redonne le filtre de chaque tirage."""
    rng = np.random.default_rng(21)
    model = _case(21, 3, 2, 1)[0]
    N, T = 5, 25
    U = rng.standard_normal((N, T, 1))
    Y = np.stack([kc.simulate(model, rng.standard_normal(3), T, U[i], rng=rng).y for i in range(N)])
    X0 = rng.standard_normal((N, 3))
    P0 = np.stack([(1.0 + i) * np.eye(3) for i in range(N)])
    for runs in (kc.kalman_filter_runs(model, Y, X0, P0, U),
                 extended_kalman_filter_runs(_nonlinear(model), Y, X0, P0, U)):
        assert not runs.shared_covariance and runs.P.shape == (N, T, 3, 3)
        for i in range(N):
            x, P, _, _ = filterpy_kf(model, Y[i], X0[i], P0[i], u=U[i])
            np.testing.assert_allclose(runs.x[i], x, **TOL)
            np.testing.assert_allclose(runs.P[i], P, **TOL)


# --------------------------------------------------------------------------- filtres de Monte-Carlo


STOCHASTIC = [
    Member("filtre particulaire", lambda m, y, x0, P0, u=None, size=4000, rng=0: kc.particle_filter(
        _nonlinear(m), y, x0, P0, u, n_particles=size, rng=rng)),
    Member("EnKF", lambda m, y, x0, P0, u=None, size=4000, rng=0: kc.ensemble_kalman_filter(
        _nonlinear(m), y, x0, P0, u, n_members=size, rng=rng)),
    # assimilation de données (issue 33) : l'ETKF et le LETKF de rayon infini tendent aussi vers le KF (le
    # DEnKF non : sa covariance analysée garde le terme ¼ KHPHᵀKᵀ — tests/test_assimilation.py)
    Member("ETKF", lambda m, y, x0, P0, u=None, size=4000, rng=0: kc.ensemble_kalman_filter(
        _nonlinear(m), y, x0, P0, u, n_members=size, rng=rng, method="etkf")),
    Member("LETKF (rayon infini)", lambda m, y, x0, P0, u=None, size=4000, rng=0: kc.ensemble_kalman_filter(
        _nonlinear(m), y, x0, P0, u, n_members=size, rng=rng, method="etkf", localization=np.inf,
        distances=np.zeros((m.n_obs, m.n_state)))),
]
STOCHASTIC_IDS = [f.name for f in STOCHASTIC]


@pytest.mark.parametrize("member", STOCHASTIC, ids=STOCHASTIC_IDS)
def test_monte_carlo_members_tend_to_the_kalman_filter(member):
    """Même modèle linéaire que la suite, lignes manquantes et partielles comprises : écart à la moyenne et
    à la covariance du KF petit devant l'écart-type du KF, et divisé par environ 2 quand N est multiplié
    par 4 (erreur de Monte-Carlo en 1/√N ; moyenne sur 3 graines)."""
    model, y, x0, P0, u = _case(3, 3, 2, 1, T=40)
    y[[5, 6]] = np.nan
    y[[12, 20], 1] = np.nan
    ref = kc.kalman_filter(model, y, x0, P0, u)
    std = np.sqrt(ref.P.diagonal(axis1=1, axis2=2))
    errors = []
    for size in (500, 8000):
        e = [np.sqrt(np.mean(((member.run(model, y, x0, P0, u, size=size, rng=s).x - ref.x) / std) ** 2))
             for s in range(3)]
        errors.append(np.mean(e))
    assert errors[1] < 0.1
    assert 2.5 < errors[0] / errors[1] < 6.5, errors  # √16 = 4


@pytest.mark.parametrize("member", STOCHASTIC, ids=STOCHASTIC_IDS)
def test_monte_carlo_missing_rows_are_prediction_only(member):
    model, y, x0, P0, u = _case(3, 3, 2, 1, T=20)
    y[[0, 7, 8]] = np.nan
    res = member.run(model, y, x0, P0, u, size=200)
    for k in (0, 7, 8):
        np.testing.assert_array_equal(res.x[k], res.x_pred[k])
        assert not res.observed[k].any() and np.all(res.K[k] == 0) and np.isnan(res.innovation[k]).all()
    assert res.n_iter.tolist() == [0 if k in (0, 7, 8) else 1 for k in range(20)]


@pytest.mark.parametrize("member", STOCHASTIC, ids=STOCHASTIC_IDS)
@pytest.mark.parametrize("bad, message", BAD_INPUTS)
def test_monte_carlo_members_share_the_engine_errors(member, bad, message):
    model, y, x0, P0, u = _case(1, 3, 2, 1, T=5)
    args = dict(y=y, x0=x0, P0=P0, u=u)
    args.update(bad)
    with pytest.raises(kc.KalmanInputError, match=message):
        member.run(model, args["y"], args["x0"], args["P0"], args["u"], size=10)


@pytest.mark.parametrize("member", STOCHASTIC, ids=STOCHASTIC_IDS)
def test_monte_carlo_members_refuse_a_control_without_B(member):
    model, y, x0, P0, _ = _case(1, 3, 2, 0, T=5)
    with pytest.raises(kc.KalmanInputError, match="« u » est fourni mais le modèle n'a pas de matrice de commande B"):
        member.run(model, y, x0, P0, np.zeros((5, 1)), size=10)


def test_engine_random_generator_and_step_outputs_hooks():
    """Le moteur passe un seul générateur à toutes les étapes d'une famille ``stochastic`` (même graine →
    mêmes tirages) et empile, temps en premier, les sorties de ``step_outputs``."""
    from kalman_course.filters.engine import Correction, FilterFamily, run_filter

    seen = []

    def prior(model, x0, P0, rng):
        return (np.asarray(x0, float), np.asarray(P0, float), rng.random())

    def predict(model, state, u, rng):
        seen.append(rng)
        return (state[0], state[1], rng.random())

    def update(model, state, y, idx, rng):
        return (state[0] + y[:1], state[1], rng.random()), Correction(np.zeros((1, 1)), y - state[0], np.eye(1))

    family = FilterFamily(
        name="filtre de test", model_type=kc.LinearGaussianModel, prior=prior, predict=predict, update=update,
        moments=lambda s: (s[0], s[1]), stochastic=True,
        step_outputs=lambda s: {"draw": s[2], "pair": np.array([s[2], 2 * s[2]])},
    )
    model = kc.LinearGaussianModel(1.0, [[1.0]], 1.0, 1.0)
    y = np.array([1.0, np.nan, 2.0])
    with pytest.raises(TypeError):  # FilterResult n'a pas de champ « draw » : la famille doit le déclarer
        run_filter(family, model, y, [0.0], [[1.0]], rng=5)

    from dataclasses import dataclass

    @dataclass(frozen=True, eq=False, repr=False)
    class Extra(kc.FilterResult):
        draw: np.ndarray | None = None
        pair: np.ndarray | None = None

    import dataclasses
    family = dataclasses.replace(family, result_type=Extra)
    seen.clear()
    a = run_filter(family, model, y, [0.0], [[1.0]], rng=5)
    assert len({id(g) for g in seen}) == 1 and len(seen) == 3  # un seul générateur, passé à chaque pas
    b = run_filter(family, model, y, [0.0], [[1.0]], rng=np.random.default_rng(5))
    g = np.random.default_rng(5)
    draws = g.random(6)  # prior, predict, update, predict, predict, update
    np.testing.assert_array_equal(a.draw, [draws[2], draws[3], draws[5]])
    np.testing.assert_array_equal(a.draw, b.draw)
    assert a.pair.shape == (3, 2)
    with pytest.raises(kc.KalmanInputError, match="« rng » doit être une graine entière"):
        run_filter(family, model, y, [0.0], [[1.0]])
    with pytest.raises(kc.KalmanInputError, match="« rng » est fourni, mais le filtre de Kalman ne tire rien"):
        run_filter(kc.filters.kalman.kalman_family(), model, y, [0.0], [[1.0]], rng=1)


# --------------------------------------------------------------------------- filtres sur SE(2) (issue 35)
# L'EKF invariant et l'EKF standard du robot plan ne se réduisent pas au filtre de Kalman (l'état est une pose) :
# ils rejoignent la famille par le moteur — mêmes pas sans mesure, mêmes erreurs sur y et u, lot = tirage par
# tirage. Leurs équations sont vérifiées dans tests/test_invariant.py.

SE2_MEMBERS = [kc.se2_invariant_ekf, kc.se2_standard_ekf]


def _se2_case(T=40):
    rng = np.random.default_rng(35)
    model = kc.OdometryGnssModel(0.05, [0.02, 0.01, 0.03], 0.8)
    u = np.array([1.0, 0.0, 0.3]) + 0.02 * rng.standard_normal((T, 3))
    y = rng.standard_normal((T, 2))
    T0 = kc.se2_exp([0.0, 0.0, 0.4])
    return model, y, T0, np.diag([0.1, 0.1, 0.2]), u


@pytest.mark.parametrize("member", SE2_MEMBERS, ids=lambda f: f.__name__)
def test_se2_filters_missing_rows_are_prediction_only(member):
    model, y, T0, P0, u = _se2_case()
    y[[0, 7, 8, 30]] = np.nan
    res = member(model, y, T0, P0, u)
    for k in (0, 7, 8, 30):
        np.testing.assert_array_equal(res.x[k], res.x_pred[k])
        assert not res.observed[k].any() and np.all(res.K[k] == 0) and np.isnan(res.innovation[k]).all()
    assert res.n_iter.tolist() == [0 if k in (0, 7, 8, 30) else 1 for k in range(len(y))]
    runs = (kc.se2_invariant_ekf_runs if member is kc.se2_invariant_ekf else kc.se2_standard_ekf_runs)(
        model, y[None], T0, P0, u)
    np.testing.assert_allclose(runs.run(0).x, res.x, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("member", SE2_MEMBERS, ids=lambda f: f.__name__)
def test_se2_filters_gated_step_is_the_same_step_with_the_row_missing(member):
    """La porte, option du moteur, sur les filtres de SE(2) : des positions aberrantes rejetées ; le filtrage à
    porte égale le même filtrage où ces lignes manquent, log-vraisemblance comprise."""
    model, _, T0, P0, u = _se2_case(T=60)
    clean = member(model, np.full((60, 2), np.nan), T0, P0, u)
    y = clean.position + np.random.default_rng(5).normal(0.0, 0.8, (60, 2))
    y[[10, 30, 31]] += 40.0
    gated = member(model, y, T0, P0, u, gate=0.999)
    assert gated.rejected[[10, 30, 31]].all()
    holes = y.copy()
    holes[gated.rejected] = np.nan
    plain = member(model, holes, T0, P0, u)
    for field in ("x", "P", "x_pred", "P_pred"):
        np.testing.assert_allclose(getattr(gated, field), getattr(plain, field), rtol=1e-8, atol=1e-10, err_msg=field)
    assert kc.filter_log_likelihood(gated) == pytest.approx(kc.filter_log_likelihood(plain), rel=1e-10)


@pytest.mark.parametrize("member", SE2_MEMBERS, ids=lambda f: f.__name__)
@pytest.mark.parametrize("bad, message", BAD_INPUTS[:3] + BAD_INPUTS[7:])
def test_se2_filters_share_the_engine_errors(member, bad, message):
    model, y, T0, P0, u = _se2_case(T=5)
    args = dict(y=y, u=u)
    args.update(bad)
    if "u" in bad:
        args["u"] = np.zeros((4, 3))
    with pytest.raises(kc.KalmanInputError, match=message):
        member(model, args["y"], T0, P0, args["u"])


# --------------------------------------------------------------------------- issue 32 : l'axe « modèle variable
# dans le temps » pour chaque membre linéaire, et la porte pour chaque membre (gate=p : un pas rejeté est le
# même pas avec la mesure manquante)

from dense_oracle import batch_log_likelihood, batch_posterior  # noqa: E402


def varying_case(seed: int = 0, T: int = 30, n: int = 3, m: int = 2, p: int = 1, partial: bool = True):
    """Un modèle vraiment variable dans le temps (A_k, B_k, C_k, Q_k, R_k tirées à chaque pas autour d'un
    modèle stable), ses mesures avec des lignes manquantes (et partielles si ``partial``), un a priori loin
    de zéro et des commandes."""
    rng = np.random.default_rng(seed)
    base = random_model(rng, n, m, p)
    A0 = 0.9 * np.asarray(base.A) / max(1.0, float(np.max(np.abs(np.linalg.eigvals(base.A)))))
    A = A0 + 0.1 * rng.standard_normal((T, n, n))
    C = np.asarray(base.C) + 0.3 * rng.standard_normal((T, m, n))
    s = rng.uniform(0.5, 2.0, T)
    Q = s[:, None, None] * np.asarray(base.Q)
    R = rng.uniform(0.5, 3.0, T)[:, None, None] * np.asarray(base.R)
    B = np.asarray(base.B) * rng.uniform(0.5, 1.5, (T, 1, 1)) if p else None
    model = kc.LinearGaussianModel(A, C, Q, R, B=B)
    u = rng.standard_normal((T, p)) if p else None
    x0 = 10.0 + rng.standard_normal(n)
    y = np.array(kc.simulate(model, x0, T, u=u, rng=rng).y)
    y[[3, 11, 12]] = np.nan
    if partial:
        y[[6, 20], 1] = np.nan
        y[25, 0] = np.nan
    return model, y, x0, np.diag(rng.uniform(0.5, 2.0, n)), u


def filterpy_per_step(model, y, x0, P0, u=None):
    """La référence indépendante : filterpy, au pas k predict(F=A_k, Q=Q_k, B=B_k, u=u_k) puis
    update(y_k, R=R_k, H=C_k) sur les seules composantes observées ; x, P, x⁻, P⁻."""
    from filterpy.kalman import KalmanFilter

    T = len(y)
    A, Q, C, R = (np.asarray(model.sequence(k, T)) for k in ("A", "Q", "C", "R"))
    B = np.asarray(model.sequence("B", T)) if model.B is not None else None
    f = KalmanFilter(dim_x=model.n_state, dim_z=model.n_obs, dim_u=max(model.n_control, 1))
    f.x, f.P = np.asarray(x0, float).reshape(-1, 1), np.asarray(P0, float).copy()
    out = [[], [], [], []]
    for k in range(T):
        if B is None:
            f.predict(F=A[k], Q=Q[k])
        else:
            f.predict(u=u[k].reshape(-1, 1), B=B[k], F=A[k], Q=Q[k])
        out[2].append(f.x.ravel().copy())
        out[3].append(f.P.copy())
        o = ~np.isnan(y[k])
        if o.any():
            f.update(y[k, o].reshape(-1, 1), R=R[k][np.ix_(o, o)], H=C[k][o])
        out[0].append(f.x.ravel().copy())
        out[1].append(f.P.copy())
    return tuple(np.array(a) for a in out)


VARYING_FILTERS = {
    "KF (racine carrée)": lambda m, y, x0, P0, u: kc.kalman_filter(m, y, x0, P0, u),
    "KF (Joseph)": lambda m, y, x0, P0, u: kc.kalman_filter(m, y, x0, P0, u, form="joseph"),
    "KF (cours)": lambda m, y, x0, P0, u: kc.kalman_filter(m, y, x0, P0, u, form="textbook"),
    "KF en lot": lambda m, y, x0, P0, u: kc.kalman_filter_runs(m, y[None], x0, P0, u).run(0),
    "SRIF (inverse)": lambda m, y, x0, P0, u: kc.square_root_information_filter(m, y, x0, P0, u),
    "SRIF (joint)": lambda m, y, x0, P0, u: kc.square_root_information_filter(m, y, x0, P0, u, method="joint"),
    "filtre parallèle": lambda m, y, x0, P0, u: kc.parallel_kalman_filter(m, y, x0, P0, u),
    "IMM (un régime)": lambda m, y, x0, P0, u: kc.imm_filter([m], y, x0, P0, u, transition=[[1.0]]),
    "Q adaptative (au repos)": lambda m, y, x0, P0, u: kc.adaptive_kalman_filter(m, y, x0, P0, u, detect=1 - 1e-12),
}


@pytest.mark.parametrize("name", list(VARYING_FILTERS))
def test_every_linear_filter_on_a_time_varying_model_with_missing_rows(name):
    """Modèle variable dans le temps (A, B, C, Q, R changent à chaque pas), lignes manquantes et partielles :
    chaque filtre linéaire égale filterpy pas à pas à 10⁻⁸ relatif (x, P, x⁻, P⁻)."""
    model, y, x0, P0, u = varying_case()
    res = VARYING_FILTERS[name](model, y, x0, P0, u)
    for got, ref in zip((res.x, res.P, res.x_pred, res.P_pred), filterpy_per_step(model, y, x0, P0, u)):
        np.testing.assert_allclose(got, ref, rtol=1e-8, atol=1e-8 * np.abs(ref).max())


@pytest.mark.parametrize("smoother", ["rts_smoother", "parallel_rts_smoother"])
def test_smoothers_on_a_time_varying_model_equal_the_dense_posterior(smoother):
    """Lisseurs (forme commune : lisseur(model, result, x0, P0, u)) contre l'oracle dense (loi de toute la
    trajectoire d'un bloc, sans récurrence) : x, P, covariances de décalage, état initial, à 10⁻⁸."""
    model, y, x0, P0, u = varying_case(1)
    if smoother == "rts_smoother":
        sm = kc.rts_smoother(model, kc.kalman_filter(model, y, x0, P0, u), x0, P0, u)
    else:
        sm = kc.parallel_rts_smoother(model, kc.parallel_kalman_filter(model, y, x0, P0, u), x0, P0, u)
    dense = batch_posterior(model, y, u=u, x0=x0, P0=P0)
    for got, key in ((sm.x, "x"), (sm.P, "P"), (sm.P_lag[1:], "P_lag"), (sm.x_initial, "x_initial"),
                     (sm.P_initial, "P_initial"), (sm.P_lag[0], "lag0")):
        ref = dense[key][1:] if key == "P_lag" else dense[key]
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-8 * np.abs(ref).max(), err_msg=key)


def test_diffuse_filter_and_smoother_on_a_time_varying_model_equal_the_dense_posterior():
    """Départ diffus exact sur un modèle variable : chaque estimation filtrée déterminée est la moyenne a
    posteriori de l'état du pas sachant les mesures jusqu'à lui (oracle dense sur la série tronquée, sans a
    priori), et le lissage exact est l'oracle dense sur toute la série."""
    model, y, _, _, _ = varying_case(2, T=20, p=0, partial=False)
    res = kc.diffuse_kalman_filter(model, y)
    determined = np.flatnonzero(np.isfinite(res.x).all(axis=1))
    assert determined.size > 15
    for k in determined:
        head = kc.LinearGaussianModel(*(np.asarray(getattr(model, a))[:k + 1] for a in ("A", "C", "Q", "R")))
        dense = batch_posterior(head, y[:k + 1])
        np.testing.assert_allclose(res.x[k], dense["x"][-1], rtol=0, atol=1e-8 * np.abs(dense["x"]).max())
        np.testing.assert_allclose(res.P[k], dense["P"][-1], rtol=0, atol=1e-8 * np.abs(dense["P"][-1]).max())
    sm = kc.rts_smoother(model, res)
    dense = batch_posterior(model, y)
    np.testing.assert_allclose(sm.x, dense["x"], rtol=0, atol=1e-8 * np.abs(dense["x"]).max())
    np.testing.assert_allclose(sm.P, dense["P"], rtol=0, atol=1e-8 * np.abs(dense["P"]).max())
    np.testing.assert_allclose(sm.P_lag[1:], dense["P_lag"][1:], rtol=0, atol=1e-8 * np.abs(dense["P"]).max())


@pytest.mark.parametrize("prior", [True, False])
def test_likelihood_on_a_time_varying_model_equals_the_dense_gaussian(prior):
    """log L d'un modèle variable, lignes manquantes et partielles, a priori connu ou départ diffus exact,
    contre la loi jointe des mesures calculée d'un bloc (aucune récurrence) ; aussi par le filtre
    parallèle et par le lot de modèles (log_likelihoods)."""
    model, y, x0, P0, u = varying_case(3, p=0 if not prior else 1)
    if prior:
        ours = kc.log_likelihood(model, y, x0, P0, u)
        ref = batch_log_likelihood(model, y, u, x0, P0)
        assert kc.filter_log_likelihood(kc.parallel_kalman_filter(model, y, x0, P0, u)) == pytest.approx(ref, rel=1e-9)
    else:
        ours = kc.log_likelihood(model, y)
        ref = batch_log_likelihood(model, y)
        np.testing.assert_allclose(kc.likelihood.log_likelihoods([model, model], y), [ref, ref], rtol=1e-9)
    assert ours == pytest.approx(ref, rel=1e-9)


def test_em_step_on_a_time_varying_model_is_the_closed_form_on_the_dense_moments():
    """EM sur un modèle à A_k, B_k, C_k variables (Q et R constantes, estimées) : l'étape M du paquet égale
    les formules closes de Shumway et Stoffer appliquées aux moments a posteriori de l'oracle dense (état
    initial compris), à 10⁻⁸."""
    model, y, x0, P0, u = varying_case(4, partial=False)
    model = kc.LinearGaussianModel(model.A, model.C, np.asarray(model.Q)[0], np.asarray(model.R)[0], B=model.B)
    _, new = kc.likelihood.em_step(model, y, x0, P0, u)
    dense = batch_posterior(model, y, u=u, x0=x0, P0=P0)
    T = len(y)
    A, B, C = (np.asarray(model.sequence(k, T)) for k in ("A", "B", "C"))
    xs = np.vstack([dense["x_initial"], dense["x"]])
    Ps = np.concatenate([dense["P_initial"][None], dense["P"]])
    lags = np.concatenate([dense["lag0"][None], dense["P_lag"][1:]])  # Cov(x_k, x_{k-1}), k = 1…T
    terms = []
    for k in range(1, T + 1):
        r = xs[k] - A[k - 1] @ xs[k - 1] - B[k - 1] @ u[k - 1]
        terms.append(np.outer(r, r) + Ps[k] - lags[k - 1] @ A[k - 1].T - A[k - 1] @ lags[k - 1].T
                     + A[k - 1] @ Ps[k - 1] @ A[k - 1].T)
    Q_ref = np.mean(terms, axis=0)
    R_terms = []
    for k in range(T):
        if np.isnan(y[k]).all():
            R_terms.append(np.asarray(model.R))
        else:
            e = y[k] - C[k] @ dense["x"][k]
            R_terms.append(np.outer(e, e) + C[k] @ dense["P"][k] @ C[k].T)
    np.testing.assert_allclose(new.Q, Q_ref, rtol=1e-8, atol=1e-10)
    np.testing.assert_allclose(new.R, np.mean(R_terms, axis=0), rtol=1e-8, atol=1e-10)
    em = kc.expectation_maximization(model, y, x0, P0, u, max_iter=30)
    assert np.all(np.diff(em.history) >= -1e-9)  # la vraisemblance ne décroît jamais


def _nonlinear_members():
    """Les membres gaussiens à porte, sur le modèle linéaire vu comme non linéaire."""
    def nl(m):
        return kc.NonlinearModel.from_linear(m)
    return {
        "KF (racine carrée)": lambda m, y, x0, P0, u, **o: kc.kalman_filter(m, y, x0, P0, u, **o),
        "KF (Joseph)": lambda m, y, x0, P0, u, **o: kc.kalman_filter(m, y, x0, P0, u, form="joseph", **o),
        "KF (cours)": lambda m, y, x0, P0, u, **o: kc.kalman_filter(m, y, x0, P0, u, form="textbook", **o),
        "EKF": lambda m, y, x0, P0, u, **o: kc.extended_kalman_filter(nl(m), y, x0, P0, u, **o),
        "UKF": lambda m, y, x0, P0, u, **o: kc.unscented_kalman_filter(nl(m), y, x0, P0, u, alpha=0.5, beta=2.0,
                                                                      kappa=0.0, **o),
        "CKF": lambda m, y, x0, P0, u, **o: kc.cubature_kalman_filter(nl(m), y, x0, P0, u, **o),
        "GHKF": lambda m, y, x0, P0, u, **o: kc.gauss_hermite_kalman_filter(nl(m), y, x0, P0, u, **o),
        "filtre gaussien (linéarisation)": lambda m, y, x0, P0, u, **o: kc.gaussian_filter(
            nl(m), y, x0, P0, u, rule=kc.Linearization(), **o),
        "IMM (un régime)": lambda m, y, x0, P0, u, **o: kc.imm_filter([m], y, x0, P0, u, transition=[[1.0]], **o),
        "IMM (deux régimes)": lambda m, y, x0, P0, u, **o: kc.imm_filter(
            [m, kc.LinearGaussianModel(m.A, m.C, 4.0 * np.asarray(m.Q), m.R, B=m.B)], y, x0, P0, u,
            transition=[[0.9, 0.1], [0.2, 0.8]], **o),
        "IMM à régimes EKF": lambda m, y, x0, P0, u, **o: kc.imm_filter(
            [nl(m), nl(kc.LinearGaussianModel(m.A, m.C, 4.0 * np.asarray(m.Q), m.R, B=m.B))], y, x0, P0, u,
            transition=[[0.9, 0.1], [0.2, 0.8]], **o),
        "IMM à régimes CKF": lambda m, y, x0, P0, u, **o: kc.imm_filter(
            [m, kc.LinearGaussianModel(m.A, m.C, 4.0 * np.asarray(m.Q), m.R, B=m.B)], y, x0, P0, u,
            transition=[[0.9, 0.1], [0.2, 0.8]], rule=kc.CubatureRule(), **o),
        "Q adaptative": lambda m, y, x0, P0, u, **o: kc.adaptive_kalman_filter(m, y, x0, P0, u, **o),
    }


GATED = _nonlinear_members()


@pytest.mark.parametrize("name", list(GATED))
def test_a_gated_step_is_the_same_step_with_the_row_missing(name):
    """Porte (option du moteur) : des mesures aberrantes (et une composante aberrante d'une ligne partielle)
    sont rejetées ; le filtrage à porte égale, à 10⁻⁸, le même filtrage où ces lignes manquent. La
    log-vraisemblance du filtrage à porte ne compte pas les pas rejetés (elle égale celle du filtrage à
    trous)."""
    model, y, x0, P0, u = _case(6, 3, 2, 1, T=60)
    y[[10, 30, 31]] += 40.0
    y[45, 1] = np.nan
    y[45, 0] += 40.0
    gated = GATED[name](model, y, x0, P0, u, gate=0.999)
    assert gated.rejected[[10, 30, 31, 45]].all()
    holes = y.copy()
    holes[gated.rejected] = np.nan
    plain = GATED[name](model, holes, x0, P0, u)
    for field in ("x", "P", "x_pred", "P_pred"):
        np.testing.assert_allclose(getattr(gated, field), getattr(plain, field), rtol=1e-8, atol=1e-10, err_msg=field)
    assert kc.filter_log_likelihood(gated) == pytest.approx(kc.filter_log_likelihood(plain), rel=1e-10)
    # un pas rejeté : gain nul, innovation et S gardées (son NIS se lit)
    assert not gated.K[10].any() and np.isfinite(gated.innovation[10]).all()
    assert not plain.rejected.any()


@pytest.mark.parametrize("name", [k for k in GATED if k != "Q adaptative"])
def test_fading_memory_is_the_same_option_on_every_member(name):
    """Mémoire évanescente (option du moteur) : chaque membre, sur le modèle linéaire, égale la boucle de
    filterpy avec ``KalmanFilter.alpha`` (P⁻ = α² A P Aᵀ + Q) — l'IMM à deux régimes identiques aussi."""
    from filterpy.kalman import KalmanFilter

    model, y, x0, P0, u = _case(7, 3, 2, 1, T=40)
    if name.startswith("IMM") and name != "IMM (un régime)":  # deux régimes identiques : le filtre d'un régime
        modes = [kc.NonlinearModel.from_linear(model)] * 2 if "EKF" in name else [model, model]
        res = kc.imm_filter(modes, y, x0, P0, u, transition=[[0.9, 0.1], [0.2, 0.8]], fading=1.05,
                            rule=kc.CubatureRule() if "CKF" in name else None)
    else:
        res = GATED[name](model, y, x0, P0, u, fading=1.05)
    f = KalmanFilter(dim_x=3, dim_z=2, dim_u=1)
    f.F, f.H, f.Q, f.R, f.B = (np.array(a) for a in (model.A, model.C, model.Q, model.R, model.B))
    f.x, f.P, f.alpha = x0.reshape(3, 1).copy(), P0.copy(), 1.05
    for k in range(len(y)):
        f.predict(u=u[k].reshape(1, 1))
        f.update(y[k].reshape(2, 1))
        np.testing.assert_allclose(res.x[k], f.x.ravel(), rtol=1e-8, atol=1e-8)
        np.testing.assert_allclose(res.P[k], f.P, rtol=1e-8, atol=1e-8)


def test_options_a_member_does_not_have_are_refused_in_french():
    from kalman_course.filters.engine import run_filter
    from kalman_course.filters.particle import particle_family

    model, y, x0, P0, _ = _case(1, 3, 2, 0, T=5)
    nl = kc.NonlinearModel.from_linear(model)
    with pytest.raises(kc.KalmanInputError, match="« gate » : le filtre particulaire n'a pas de porte"):
        run_filter(particle_family(50), nl, y, x0, P0, rng=0, gate=0.99)
    with pytest.raises(kc.KalmanInputError, match="« fading » : le filtre particulaire n'a pas de mémoire"):
        run_filter(particle_family(50), nl, y, x0, P0, rng=0, fading=1.1)
    with pytest.raises(kc.KalmanInputError, match="« gate » doit être une probabilité"):
        kc.cubature_kalman_filter(nl, y, x0, P0, gate=1.5)
    with pytest.raises(kc.KalmanInputError, match="« fading » doit être un facteur α ≥ 1"):
        kc.imm_filter([model], y, x0, P0, transition=[[1.0]], fading=0.5)
