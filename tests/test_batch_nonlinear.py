"""Filtres non linéaires en lot (moteur ``run_filter_runs``) : chaque tirage du lot est égal au filtre
lancé seul sur ses mesures (EKF, UKF, EKF itéré, modèle radar qui franchit l'axe θ = ±π), mesures
manquantes comprises ; modèles non vectorisés et jacobiennes qui n'acceptent pas de pile ; erreurs
d'entrée en français. La comparaison au filtre de Kalman de filterpy (modèles linéaires) est dans
``test_family.py`` (membres « … en lot »)."""

from __future__ import annotations

import numpy as np
import pytest

import kalman_course as kc
from kalman_course.filters.engine import run_filter_runs
from kalman_course.filters.extended import extended_kalman_filter_runs
from kalman_course.filters.iterated import iterated_extended_kalman_filter_runs
from kalman_course.filters.square_root_information import srif_family
from kalman_course.filters.unscented import unscented_kalman_filter_runs
from kalman_course.scenarios import radar
from kalman_course.scenarios._motion import simulate_cv

UKF = dict(alpha=1.0, beta=2.0, kappa=0.0)
FIELDS = ("x", "P", "x_pred", "P_pred", "K", "innovation", "S")

# (nom, filtre en lot, filtre seul)
FILTERS = [
    ("EKF", extended_kalman_filter_runs, kc.extended_kalman_filter),
    ("EKF (Joseph)", lambda *a: extended_kalman_filter_runs(*a, joseph=True),
     lambda *a: kc.extended_kalman_filter(*a, joseph=True)),
    ("UKF", lambda *a: unscented_kalman_filter_runs(*a, **UKF), lambda *a: kc.unscented_kalman_filter(*a, **UKF)),
    ("EKF itéré", iterated_extended_kalman_filter_runs, kc.iterated_extended_kalman_filter),
    ("EKF itéré (3, Joseph)", lambda *a: iterated_extended_kalman_filter_runs(*a, max_iter=3, joseph=True),
     lambda *a: kc.iterated_extended_kalman_filter(*a, max_iter=3, joseph=True)),
]
IDS = [f[0] for f in FILTERS]


def _radar_runs(N: int = 12, T: int = 30, seed: int = 5):
    """``N`` cibles à vitesse constante autour de (−25, 12) m qui descendent : elles franchissent l'axe
    θ = ±π (résidus d'azimut à ramener) ; a priori propre à chaque tirage (x0 (N, 4), P0 (N, 4, 4))."""
    rng = np.random.default_rng(seed)
    std = np.array([radar.RADAR_RANGE_STD, radar.RADAR_BEARING_STD])
    Y, X0, P0 = [], [], []
    for _ in range(N):
        start = radar.RADAR_TRACK_TRUE_X0 + rng.standard_normal(4) * [2.0, 2.0, 0.1, 0.1]
        x_true = simulate_cv(start, T, 1.0, 0.05, rng)
        y = radar.range_bearing(x_true) + rng.standard_normal((T, 2)) * std
        y[:, 1] = np.arctan2(np.sin(y[:, 1]), np.cos(y[:, 1]))
        Y.append(y)
        X0.append(start + rng.standard_normal(4) * [1.5, 1.5, 0.3, 0.3])
        s = rng.uniform(0.5, 2.0, 4)
        P0.append(np.diag([4.0, 4.0, 0.25, 0.25]) * np.outer(s, s) ** 0.5)
    return np.array(Y), np.array(X0), np.array(P0)


def _assert_runs_equal(batch, single, model, Y, X0, P0, rtol=1e-10):
    N = Y.shape[0]
    assert batch.x.shape == (N, Y.shape[1], model.n_state) and batch.P.shape == (N, Y.shape[1], 4, 4)
    assert batch.n_iter.shape == (N, Y.shape[1]) and not batch.shared_covariance
    for i in range(N):
        x0 = X0[i] if np.ndim(X0) == 2 else X0
        p0 = P0[i] if np.ndim(P0) == 3 else P0
        ref = single(model, Y[i], x0, p0)
        one = batch.run(i)
        for field in FIELDS:
            a, b = getattr(one, field), getattr(ref, field)
            np.testing.assert_array_equal(np.isnan(a), np.isnan(b), err_msg=field)
            # écart relatif à l'échelle de chaque pas (les covariances mêlent m² et (m/s)²)
            scale = np.max(np.abs(np.nan_to_num(b)), axis=tuple(range(1, b.ndim)), keepdims=True)
            gap = np.abs(np.nan_to_num(a) - np.nan_to_num(b)) / np.maximum(scale, 1e-300)
            assert gap.max() <= rtol, f"tirage {i}, {field} : écart relatif {gap.max():.2e}"
        np.testing.assert_array_equal(one.n_iter, ref.n_iter)
        np.testing.assert_array_equal(one.observed, ref.observed)


@pytest.mark.parametrize("name, batch, single", FILTERS, ids=IDS)
@pytest.mark.parametrize("per_run_prior", [False, True])
def test_every_run_equals_the_single_run_filter(name, batch, single, per_run_prior):
    model = radar.radar_tracking_model()
    Y, X0, P0 = _radar_runs()
    if not per_run_prior:
        X0, P0 = X0[0], P0[0]
    res = batch(model, Y, X0, P0)
    _assert_runs_equal(res, single, model, Y, X0, P0)
    if name.startswith("EKF itéré") and "3" not in name:
        assert res.n_iter.min() >= 2 and len(np.unique(res.n_iter)) > 1  # arrêts différents selon les tirages


@pytest.mark.parametrize("name, batch, single", FILTERS, ids=IDS)
def test_missing_measurements_run_by_run(name, batch, single):
    """Lignes entières manquantes pour certains tirages, composantes isolées, un pas sans aucune mesure."""
    model = radar.radar_tracking_model()
    Y, X0, P0 = _radar_runs(N=10, T=25, seed=9)
    rng = np.random.default_rng(1)
    Y[rng.random(Y.shape[:2]) < 0.15] = np.nan
    Y[:, :, 0][rng.random(Y.shape[:2]) < 0.15] = np.nan   # distance seule manquante
    Y[:, :, 1][rng.random(Y.shape[:2]) < 0.15] = np.nan   # azimut seul manquant
    Y[:, 6] = np.nan                                      # aucun tirage n'observe au pas 6
    res = batch(model, Y, X0, P0)
    _assert_runs_equal(res, single, model, Y, X0, P0)
    assert np.all(res.n_iter[:, 6] == 0) and np.all(res.K[:, 6] == 0)
    np.testing.assert_array_equal(res.x[:, 6], res.x_pred[:, 6])


def _row_by_row_radar(jacobian=None, vectorized=False):
    """Le modèle radar écrit pour un seul état (``f``, ``h`` et la jacobienne de ``h``)."""
    F = np.array(radar.radar_tracking_model().f_jacobian)
    ref = radar.radar_tracking_model()

    def h(x):
        return np.array([np.hypot(x[0], x[1]), np.arctan2(x[1], x[0])])

    return kc.NonlinearModel(
        f=lambda x, u: F @ x if not vectorized else x @ F.T,
        h=h if not vectorized else radar.range_bearing,
        Q=ref.Q, R=ref.R, f_jacobian=F,
        h_jacobian=jacobian or (lambda x: radar.range_bearing_jacobian(np.asarray(x)[:4], 4)),
        angle_indices=(1,), vectorized=vectorized,
    )


@pytest.mark.parametrize("name, batch, single", FILTERS, ids=IDS)
def test_non_vectorized_model_works_run_by_run(name, batch, single):
    """Modèle non vectorisé : ``f``, ``h`` et les jacobiennes sont appelées tirage par tirage (ou point par
    point pour l'UKF) ; mêmes nombres."""
    model = _row_by_row_radar()
    Y, X0, P0 = _radar_runs(N=5, T=15)
    _assert_runs_equal(batch(model, Y, X0, P0), single, model, Y, X0, P0)


def _single_state_jacobian(x):
    """Jacobienne écrite pour un seul état, qui plante sur une pile."""
    x = np.asarray(x)
    if x.ndim != 1:
        raise ValueError("un seul état")
    return radar.range_bearing_jacobian(x, 4)


def test_vectorized_model_whose_jacobian_refuses_a_stack():
    model = _row_by_row_radar(jacobian=_single_state_jacobian, vectorized=True)
    Y, X0, P0 = _radar_runs(N=4, T=10)
    _assert_runs_equal(extended_kalman_filter_runs(model, Y, X0, P0), kc.extended_kalman_filter, model, Y, X0, P0)


def test_a_stack_result_that_disagrees_with_the_single_call_is_not_used():
    """h_jacobian écrite pour un état (indices x[0], x[1]) renvoie sur une pile de 2 états 2-D un
    tableau (2, 2, 2) — la bonne forme, de mauvaises valeurs : le lot doit s'en apercevoir (première ligne
    comparée à l'appel seul) et revenir à un appel par tirage."""
    def h(x):
        return np.stack([x[..., 0] * x[..., 1], x[..., 0] + x[..., 1] ** 2], axis=-1)

    def H(x):
        return np.array([[x[1], x[0]], [np.ones_like(x[0]), 2 * x[1]]])

    model = kc.NonlinearModel(lambda x, u: x, h, 0.01 * np.eye(2), 0.1 * np.eye(2), f_jacobian=np.eye(2),
                              h_jacobian=H, vectorized=True)
    assert np.shape(H(np.array([[1.0, 2.0], [3.0, 4.0]]))) == (2, 2, 2)  # le piège : la forme d'une pile
    rng = np.random.default_rng(0)
    Y = rng.standard_normal((2, 8, 2)) + [2.0, 5.0]
    X0, P0 = np.array([[1.0, 2.0], [1.5, 1.0]]), np.eye(2)
    res = extended_kalman_filter_runs(model, Y, X0, P0)
    for i in range(2):
        ref = kc.extended_kalman_filter(model, Y[i], X0[i], P0)
        np.testing.assert_allclose(res.run(i).x, ref.x, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(res.run(i).P, ref.P, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("name, batch, single",
                         FILTERS + [("KF", kc.kalman_filter_runs, kc.kalman_filter)], ids=IDS + ["KF"])
def test_scalar_prior_accepted_like_the_single_run_filter(name, batch, single):
    """Un état scalaire (n = 1) : x0 et P0 scalaires, acceptés par le filtre seul, le sont aussi en lot."""
    linear = kc.LinearGaussianModel(A=0.9, C=1.0, Q=0.1, R=0.5)
    model = linear if name == "KF" else kc.NonlinearModel.from_linear(linear)
    Y = np.random.default_rng(2).standard_normal((4, 15, 1))
    runs = batch(model, Y, 0.3, 2.0)
    for i in range(4):
        np.testing.assert_allclose(runs.run(i).x, single(model, Y[i], 0.3, 2.0).x, rtol=1e-12, atol=1e-14)


def test_common_control_is_used_by_every_run():
    lin = kc.LinearGaussianModel(np.eye(2), [[1.0, 0.0]], 0.1 * np.eye(2), [[0.5]], B=[[1.0], [0.5]])
    model = kc.NonlinearModel.from_linear(lin)
    rng = np.random.default_rng(3)
    Y, U = rng.standard_normal((4, 12, 1)), rng.standard_normal((12, 1))
    res = extended_kalman_filter_runs(model, Y, np.zeros(2), np.eye(2), U)
    ref = kc.kalman_filter_runs(lin, Y, np.zeros(2), np.eye(2), U)  # le KF en lot (covariances communes)
    np.testing.assert_allclose(res.x, ref.x, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(res.P, np.broadcast_to(ref.P, res.P.shape), rtol=1e-12, atol=1e-12)


# --------------------------------------------------------------------------- erreurs d'entrée


@pytest.mark.parametrize("name, batch, single", FILTERS, ids=IDS)
@pytest.mark.parametrize("change, message", [
    (dict(Y=np.zeros((3, 5, 3))), r"« Y » doit être de forme \(N, T, 2\) : N ≥ 1 tirages de T ≥ 1 mesures de 2 composante\(s\) ; reçu la forme \(3, 5, 3\)"),
    (dict(Y=np.zeros((5, 2))), r"« Y » doit être de forme \(N, T, 2\).*reçu la forme \(5, 2\)"),
    (dict(Y=np.zeros((0, 5, 2))), r"« Y » doit être de forme \(N, T, 2\)"),
    (dict(Y=np.full((3, 5, 2), np.inf)), r"« Y » contient des valeurs infinies"),
    (dict(x0=np.zeros((4, 4))), r"« x0 » doit être de forme \(4,\) \(commun\) ou \(3, 4\) \(un par tirage\) ; reçu la forme \(4, 4\)"),
    (dict(x0=np.zeros(3)), r"« x0 » doit être de forme \(4,\) \(commun\) ou \(3, 4\)"),
    (dict(P0=np.tile(np.eye(4), (2, 1, 1))), r"« P0 » doit être de forme \(4, 4\) \(commune\) ou \(3, 4, 4\) \(une par tirage\) ; reçu la forme \(2, 4, 4\)"),
    (dict(P0=np.stack([np.eye(4), -np.eye(4), np.eye(4)])), r"« P0\[1\] » doit être (semi-)?définie positive"),
    (dict(P0=np.ones((4, 3))), r"« P0 » doit être une matrice carrée"),
    (dict(u=np.zeros((5, 1))), r"« u » est fourni mais le modèle n'a pas de matrice de commande B"),
])
def test_bad_batch_input_is_a_french_error(name, batch, single, change, message):
    model = radar.radar_tracking_model()
    args = dict(Y=np.tile([[[30.0, 0.5]]], (3, 5, 1)), x0=np.ones(4), P0=np.eye(4), u=None)
    args.update(change)
    with pytest.raises(kc.KalmanInputError, match=message):
        batch(model, args["Y"], args["x0"], args["P0"], args["u"])


def test_bad_controls_linear_models_and_families_without_batch_mode_are_refused():
    lin = kc.LinearGaussianModel(np.eye(2), [[1.0, 0.0]], 0.1 * np.eye(2), [[0.5]], B=[[1.0], [0.5]])
    model = kc.NonlinearModel.from_linear(lin)
    with pytest.raises(kc.KalmanInputError, match=r"« u » doit être de forme \(4, 1\) \(commune\) ou \(3, 4, 1\) \(une suite"):
        extended_kalman_filter_runs(model, np.zeros((3, 4, 1)), np.zeros(2), np.eye(2), np.zeros((2, 4, 1)))
    with pytest.raises(kc.KalmanInputError, match=r"« u » doit avoir une commande par pas de temps : 4 ligne"):
        iterated_extended_kalman_filter_runs(model, np.zeros((3, 4, 1)), np.zeros(2), np.eye(2), np.zeros((3, 1)))
    with pytest.raises(kc.KalmanInputError, match=r"« model » doit être un NonlinearModel ; reçu LinearGaussianModel"):
        unscented_kalman_filter_runs(lin, np.zeros((3, 4, 1)), np.zeros(2), np.eye(2), **UKF)
    with pytest.raises(kc.KalmanInputError, match="Le filtre d'information en racine carrée n'a pas de mode en lot"):
        run_filter_runs(srif_family(), lin, np.zeros((3, 4, 1)), None, None)


def test_ukf_batch_errors_name_the_run_and_the_step():
    model = kc.NonlinearModel(lambda x, u: np.zeros_like(x), lambda x: x, np.zeros((2, 2)), np.eye(2),
                              vectorized=True)
    with pytest.raises(kc.KalmanInputError, match=r"UKF, tirage 0, correction par y\[0\] : la covariance prédite P⁻"):
        unscented_kalman_filter_runs(model, np.zeros((3, 4, 2)), np.zeros(2), np.eye(2), **UKF)
    with pytest.raises(kc.KalmanInputError, match="« P0\\[2\\] » doit être définie positive"):
        P0 = np.stack([np.eye(2), np.eye(2), np.diag([1.0, 0.0])])
        unscented_kalman_filter_runs(model, np.zeros((3, 4, 2)), np.zeros(2), P0, **UKF)
    with pytest.raises(kc.KalmanInputError, match="« alpha » doit être strictement positif"):
        unscented_kalman_filter_runs(model, np.zeros((3, 4, 2)), np.zeros(2), np.eye(2), alpha=0.0, kappa=0.0)


def test_ekf_batch_error_names_the_run_when_S_is_not_positive_definite():
    """Pour le tirage 1 seul (x₀ > 50), H = 0 et V = 0 : S = HP⁻Hᵀ + VRVᵀ = 0 n'est pas définie positive ;
    l'erreur nomme S, le tirage et la mesure (pas une LinAlgError)."""
    def H(x):
        return [[0.0, 0.0]] if x[0] > 50 else [[1.0, 0.0]]

    def V(x):
        return [[0.0]] if x[0] > 50 else [[1.0]]

    model = kc.NonlinearModel(lambda x, u: x, lambda x: x[..., :1], np.zeros((2, 2)), [[1.0]],
                              f_jacobian=np.eye(2), h_jacobian=H, h_noise_jacobian=V, n_obs=1, vectorized=True)
    X0 = np.array([[0.0, 0.0], [100.0, 0.0]])
    with pytest.raises(kc.KalmanInputError, match=r"n'est pas définie positive.*\(S, tirage 1, correction par y\[0\]\)"):
        extended_kalman_filter_runs(model, np.zeros((2, 3, 1)), X0, np.eye(2))
    ref = extended_kalman_filter_runs(model, np.zeros((1, 3, 1)), X0[:1], np.eye(2))  # le tirage 0 seul passe
    assert ref.x.shape == (1, 3, 2)
