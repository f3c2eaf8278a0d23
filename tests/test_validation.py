"""Entrées invalides : chaque erreur est une KalmanInputError en français qui nomme l'argument."""

from __future__ import annotations

import re

import numpy as np
import pytest

import kalman_course as kc
from kalman_course import KalmanInputError

A2 = np.array([[1.0, 0.1], [0.0, 1.0]])
C2 = np.array([[1.0, 0.0]])
Q2 = 0.01 * np.eye(2)
R1 = np.array([[0.5]])


def model2(**over):
    args = dict(A=A2, C=C2, Q=Q2, R=R1)
    args.update(over)
    return kc.LinearGaussianModel(**args)


# --------------------------------------------------------------------------- modèle


@pytest.mark.parametrize(
    "over, pattern",
    [
        (dict(A=np.ones((2, 3))), r"« A » doit être une matrice carrée"),
        (dict(A=[1.0, 2.0]), r"« A » doit être une matrice carrée"),
        (dict(C=np.ones((1, 3))), r"« C » doit être de forme \(m, 2\) ; reçu la forme \(1, 3\)"),
        (dict(C=[1.0, 0.0]), r"« C » doit être une matrice 2-D .* C = \[\[…\]\]"),
        (dict(Q=np.eye(3)), r"« Q » doit être de forme \(2, 2\)"),
        (dict(R=np.eye(2)), r"« R » doit être de forme \(1, 1\)"),
        (dict(B=np.ones((3, 1))), r"« B » doit être de forme \(2, p\)"),
        (dict(B=[1.0, 0.0]), r"« B » doit être une matrice 2-D .*une colonne"),
        (dict(A=[[1.0, np.nan], [0.0, 1.0]]), r"« A » contient des valeurs non finies"),
        (dict(Q=[[np.inf, 0], [0, 1.0]]), r"« Q » contient des valeurs non finies"),
        (dict(Q=[[1.0, 0.5], [0.0, 1.0]]), r"« Q » doit être symétrique"),
        (dict(Q=[[1.0, 0.0], [0.0, -0.1]]), "« Q » doit être semi-définie positive .* −0,1"),
        (dict(R=[[0.0]]), r"« R » doit être définie positive"),
        (dict(R=[[-1.0]]), r"« R » doit être définie positive"),
        (dict(A=[["a", "b"], ["c", "d"]]), r"« A » doit être un tableau de nombres réels"),
        (dict(A=[[1 + 1j, 0], [0, 1]]), r"« A » doit être réel"),
        (dict(C=None), r"« C » est absent"),
    ],
)
def test_model_rejects_bad_input(over, pattern):
    with pytest.raises(KalmanInputError, match=pattern):
        model2(**over)


def test_two_measurements_need_psd_r_not_only_diagonal():
    with pytest.raises(KalmanInputError, match=r"« R » doit être définie positive"):
        kc.LinearGaussianModel(A2, np.eye(2), Q2, [[1.0, 1.0], [1.0, 1.0]])


def test_singular_q_is_allowed():
    model = kc.LinearGaussianModel(A2, C2, np.zeros((2, 2)), R1)
    assert model.n_state == 2 and model.n_obs == 1 and model.n_control == 0


def test_scalars_accepted_for_one_dimensional_model():
    model = kc.LinearGaussianModel(1, 1, 1e-5, 0.01, B=0.5)
    assert model.A.shape == model.C.shape == model.Q.shape == model.R.shape == model.B.shape == (1, 1)


# --------------------------------------------------------------------------- filtre


@pytest.mark.parametrize(
    "kwargs, pattern",
    [
        (dict(x0=[0.0, 0.0, 0.0]), r"« x0 » doit être un vecteur de forme \(2,\) ; reçu la forme \(3,\)"),
        (dict(x0=[[0.0], [0.0]]), r"« x0 » .*vecteur colonne"),
        (dict(x0=[np.nan, 0.0]), r"« x0 » contient des valeurs non finies"),
        (dict(P0=np.eye(3)), r"« P0 » doit être de forme \(2, 2\)"),
        (dict(P0=1.0), r"« P0 » doit être une matrice carrée \(2, 2\)"),
        (dict(P0=[[1.0, 0.3], [0.0, 1.0]]), r"« P0 » doit être symétrique"),
        (dict(P0=[[1.0, 2.0], [2.0, 1.0]]), r"« P0 » doit être semi-définie positive"),
        (dict(y=np.ones((10, 2))), r"« y » doit être de forme \(T, 1\) ou \(T,\)"),
        (dict(y=np.ones((2, 5, 1))), r"« y » doit être de forme \(T, 1\)"),
        (dict(y=[1.0, np.inf]), r"« y » contient des valeurs infinies"),
        (dict(y=[]), r"« y » ne contient aucune mesure|« y » doit être de forme"),
        (dict(u=np.ones(10)), r"« u » est fourni mais le modèle n'a pas de matrice de commande B"),
    ],
)
def test_filter_rejects_bad_input(kwargs, pattern):
    args = dict(y=np.zeros(10), x0=np.zeros(2), P0=np.eye(2))
    args.update(kwargs)
    with pytest.raises(KalmanInputError, match=pattern):
        kc.kalman_filter(model2(), **args)


@pytest.mark.parametrize(
    "u, pattern",
    [
        (np.ones(9), r"« u » doit avoir une commande par pas de temps : 10 ligne\(s\) attendue\(s\), 9"),
        (np.ones((10, 2)), r"« u » doit être de forme \(T, 1\) ou \(T,\)"),
        (np.full(10, np.nan), r"« u » contient des valeurs non finies"),
    ],
)
def test_filter_rejects_bad_command(u, pattern):
    model = model2(B=[[0.0], [1.0]])
    with pytest.raises(KalmanInputError, match=pattern):
        kc.kalman_filter(model, np.zeros(10), np.zeros(2), np.eye(2), u=u)


def test_model_type_is_checked():
    with pytest.raises(KalmanInputError, match=r"« model » doit être un LinearGaussianModel"):
        kc.kalman_filter({"A": 1}, [0.0], 0.0, 1.0)


def test_numerically_singular_innovation_covariance():
    """S = C P⁻ Cᵀ + R singulière en arithmétique flottante : erreur claire, pas de NaN."""
    model = kc.LinearGaussianModel(np.eye(2), np.eye(2), np.zeros((2, 2)), 1e-10 * np.eye(2))
    P0 = 1e20 * np.ones((2, 2))
    with pytest.raises(KalmanInputError, match=r"« S = C P⁻ Cᵀ \+ R » n'est pas définie positive"):
        kc.kalman_filter(model, np.zeros((3, 2)), np.zeros(2), P0)


# --------------------------------------------------------------------------- étapes


def test_step_functions_validate():
    model = model2(B=[[0.0], [1.0]])
    with pytest.raises(KalmanInputError, match=r"« P » doit être symétrique"):
        kc.predict(model, np.zeros(2), [[1.0, 1.0], [0.0, 1.0]])
    with pytest.raises(KalmanInputError, match=r"« u » doit être un vecteur de forme \(1,\)"):
        kc.predict(model, np.zeros(2), np.eye(2), u=[1.0, 2.0])
    with pytest.raises(KalmanInputError, match=r"« u » est fourni mais le modèle n'a pas de matrice de commande B"):
        kc.predict(model2(), np.zeros(2), np.eye(2), u=[1.0])
    with pytest.raises(KalmanInputError, match=r"« y » doit être un vecteur de forme \(1,\)"):
        kc.update(model, np.zeros(2), np.eye(2), [1.0, 2.0])
    with pytest.raises(KalmanInputError, match=r"« P_pred » doit être semi-définie positive"):
        kc.update(model, np.zeros(2), -np.eye(2), [1.0])
    with pytest.raises(KalmanInputError, match=r"« x_pred » doit être un vecteur"):
        kc.update(model, np.zeros(3), np.eye(2), [1.0])


# --------------------------------------------------------------------------- simulation


@pytest.mark.parametrize(
    "kwargs, pattern",
    [
        (dict(rng=None), r"« rng » doit être une graine entière ou un numpy.random.Generator"),
        (dict(rng=1.5), r"« rng » doit être une graine entière"),
        (dict(n_steps=0), r"« n_steps » doit être un entier ≥ 1"),
        (dict(n_steps=2.5), r"« n_steps » doit être un entier ≥ 1"),
        (dict(x0=[1.0]), r"« x0 » doit être un vecteur de forme \(2,\)"),
        (dict(u=np.ones(5)), r"« u » est fourni mais le modèle n'a pas de matrice de commande B"),
    ],
)
def test_simulate_rejects_bad_input(kwargs, pattern):
    args = dict(x0=np.zeros(2), n_steps=5, rng=0)
    args.update(kwargs)
    with pytest.raises(KalmanInputError, match=pattern):
        kc.simulate(model2(), **args)


def test_errors_are_caught_by_generic_value_error_handlers():
    """Un code qui attrape ``ValueError`` (l'erreur d'argument de Python) attrape aussi les erreurs du paquet,
    avec leur message français."""
    try:
        kc.kalman_filter(model2(), np.zeros((3, 5)), np.zeros(2), np.eye(2))
    except ValueError as exc:
        assert "« y » doit être de forme (T, 1)" in str(exc)
    else:  # pragma: no cover
        pytest.fail("une mesure de mauvaise forme doit lever une erreur")


# --------------------------------------------------------------------------- erreurs qui s'échappaient


def test_simulate_accepts_a_nonlinear_model():
    """Le modèle linéaire vu comme NonlinearModel donne la même trajectoire, avec la même graine."""
    lin = model2(B=[[1.0], [0.5]])
    u = np.linspace(0.0, 1.0, 20)
    a = kc.simulate(lin, [1.0, -1.0], 20, u, rng=4)
    b = kc.simulate(kc.NonlinearModel.from_linear(lin), [1.0, -1.0], 20, u, rng=4)
    np.testing.assert_allclose(b.x, a.x, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(b.y, a.y, rtol=1e-12, atol=1e-12)


def test_simulate_nonlinear_uses_the_noise_jacobians():
    W = np.array([[1.0], [2.0]])
    m = kc.NonlinearModel(lambda x, u: x, lambda x: x[:1], [[0.25]], [[1e-6]], f_noise_jacobian=W)
    sim = kc.simulate(m, [0.0, 0.0], 200, rng=1)
    steps = np.diff(np.vstack([[0.0, 0.0], sim.x]), axis=0)
    np.testing.assert_allclose(steps[:, 1], 2.0 * steps[:, 0], rtol=1e-12)  # bruit le long de W
    assert 0.4 < steps[:, 0].std() < 0.6  # écart-type 0,5


def test_monte_carlo_refuses_a_nonlinear_model_in_french():
    m = kc.NonlinearModel.from_linear(model2())
    with pytest.raises(KalmanInputError, match="« model » doit être un LinearGaussianModel ; reçu NonlinearModel"):
        kc.monte_carlo(m, None, 5, 5, x0_mean=np.zeros(2), x0_cov=np.eye(2), x0_hat=np.zeros(2), rng=0, P0=np.eye(2))


def test_jacobian_tools_turn_user_errors_into_french_errors():
    with pytest.raises(KalmanInputError, match=r"jacobienne « H » » a échoué.*ZeroDivisionError"):
        kc.check_jacobian(np.sin, lambda x: 1 / 0, np.array([1.0]), name="H")
    with pytest.raises(KalmanInputError, match="« x » doit être un tableau de nombres réels"):
        kc.numerical_jacobian(np.sin, "abc")


def test_position_rmse_wants_state_sequences():
    from kalman_course.scenarios import tag

    with pytest.raises(KalmanInputError, match=r"« x_est » doit être une suite d'états \(T, n\).*la forme \(5,\)"):
        tag.position_rmse(np.zeros(5), np.zeros(5))
    with pytest.raises(KalmanInputError, match="même forme"):
        tag.position_rmse(np.zeros((5, 4)), np.zeros((6, 4)))


def test_ukf_with_singular_P0_is_a_french_error():
    m = kc.NonlinearModel.from_linear(kc.LinearGaussianModel(np.eye(2), np.eye(2), np.eye(2), np.eye(2)))
    with pytest.raises(KalmanInputError, match="« P0 » doit être définie positive"):
        kc.unscented_kalman_filter(m, np.zeros((3, 2)), np.zeros(2), np.zeros((2, 2)), alpha=1.0, kappa=0.0)


def test_shapes_read_well_in_messages():
    with pytest.raises(KalmanInputError, match=r"« x0 » doit être un vecteur de forme \(2,\) ; reçu un scalaire\."):
        kc.kalman_filter(model2(), np.zeros(5), 1.0, np.eye(2))
    with pytest.raises(KalmanInputError, match=r"reçu la forme \(3,\)\."):
        kc.kalman_filter(model2(), np.zeros(5), np.zeros(3), np.eye(2))


def test_extended_srif_with_singular_jacobian_does_not_advise_a_missing_method():
    m = kc.NonlinearModel(lambda x, u: np.array([x[0], 0.0]), lambda x: x[:1], np.eye(2), [[1.0]])
    with pytest.raises(KalmanInputError, match="jacobienne « F ».*singulière") as err:
        kc.extended_square_root_information_filter(m, np.zeros(3), np.zeros(2), np.eye(2))
    assert "joint" not in str(err.value)


def test_se3_filter_with_zero_prior_and_noise_runs_instead_of_blaming_P_pred():
    from kalman_course.scenarios import camera_target as ct

    truth, y, U, T0, P0 = ct.camera_tracking_data(3)
    res = kc.se3_iterated_filter(kc.CameraPoseModel(ct.TARGET_POINTS, ct.CAMERA, 1.0), y, T0, np.zeros((6, 6)), U)
    np.testing.assert_allclose(res.P, 0.0, atol=1e-12)  # aucune incertitude : les mesures ne corrigent rien
    np.testing.assert_allclose(res.T[-1], T0 @ kc.se3_exp(U[0]) @ kc.se3_exp(U[1]) @ kc.se3_exp(U[2]), atol=1e-12)


def _camera_behind():
    from kalman_course.geometry.camera import PinholeCamera, project

    return project(PinholeCamera(fx=500.0, fy=500.0, cx=320.0, cy=240.0), [[0.0, 0.0, -9.75]])


@pytest.mark.parametrize(
    "call, number",
    [
        (lambda: kc.kalman_filter(model2(), np.zeros(3), np.zeros(2), [[1.0, 0.0], [0.0, -0.00125]]), "−0,00125"),
        (lambda: model2(Q=[[0.01, 0.0], [0.25, 0.01]]), "0,25"),
        (lambda: kc.unscented_kalman_filter(kc.NonlinearModel.from_linear(model2()), np.zeros(3), np.zeros(2),
                                            [[1.0, 0.0], [0.0, -0.5]], alpha=1.0, kappa=0.0), "−0,5"),
        (lambda: kc.geometry.lie.as_rotation("R", np.diag([1.0, 1.0, 1.5])), "det R = 1,5"),
        (lambda: kc.geometry.lie.as_pose("T", np.vstack([np.eye(4)[:3], [0.125, 0.0, 0.0, 1.0]])), "[0,1250  0,0000"),
        (lambda: kc.square_root_information_filter(model2(), np.zeros(3), None, None, R0=[[1.0, 0.0], [0.5, 1.0]],
                                                      z0=np.zeros(2)),
         "0,5"),
        (_camera_behind, "Z' = −9,75 m"),
        (lambda: kc.measurement_initialisation(
            kc.LinearGaussianModel(np.eye(2), [[1.0, 1.0], [1.0, 1.0]], np.eye(2), np.eye(2)), [1.0, 1.0]), "∞"),
    ],
)
def test_numbers_in_error_messages_are_written_the_french_way(call, number):
    """Un nombre cité par un message d'erreur suit l'écriture française (virgule décimale, signe moins,
    « ∞ ») : kalman_course.numbers.format_spec, pas le format de Python."""
    with pytest.raises(KalmanInputError) as err:
        call()
    message = str(err.value)
    assert number in message, message
    assert not re.search(r"\d\.\d|e[+-]\d\d|(?<![\w−])-\d|\binf\b", message), message


def test_error_message_numbers_match_the_babel_writing_without_importing_it():
    """Les messages d'erreur écrivent leurs nombres sans Babel (le cœur n'en dépend pas) : même écriture
    que kalman_course.numbers (Babel), référence indépendante, sur des valeurs de tous ordres de grandeur."""
    from kalman_course import numbers
    from kalman_course.core.validation import array_text, number_text

    rng = np.random.default_rng(3)
    values = [0.0, -0.0, 1.0, -1.5, 0.25, 1e-3, 9.995e-4, 0.00125, -0.00125, 999999.4, 1e6, 15099.0, -123456.789,
              2.5e-15, 1.0e300, np.inf, -np.inf, np.nan, 0.5, 1.25, 0.125]
    values += list(rng.standard_normal(40) * 10.0 ** rng.integers(-8, 9, 40))
    for v in values:
        for spec in (".2g", ".3g", ".4g", ".6g"):
            assert number_text(v, spec) == numbers.format_spec(v, spec), (v, spec)
    rows = rng.standard_normal((3, 4)) * 10.0 ** rng.integers(-5, 6, (3, 4))
    for options in (dict(decimals=4), dict(significant=6, trim=True), dict(significant=4)):
        for arr in (rows, rows[0], [0.125, 0.0, 0.0, 1.0]):
            assert array_text(arr, **options) == numbers.format_array(arr, **options), (arr, options)


def test_the_core_does_not_import_babel():
    import subprocess
    import sys

    code = ("import sys, kalman_course as kc, numpy as np\n"
            "try:\n    kc.kalman_filter(kc.LinearGaussianModel(1.0, 1.0, 1.0, 1.0), [0.0], 0.0, -1.0)\n"
            "except kc.KalmanInputError as e:\n    assert '−1' in str(e), str(e)\n"
            "assert 'babel' not in sys.modules and 'kalman_course.numbers' not in sys.modules")
    subprocess.run([sys.executable, "-c", code], check=True)


# --------------------------------------------------------------------------- erreurs d'usage : l'appel juste


def _misuse_setup():
    from kalman_course.scenarios import nile as sn

    model = sn.local_level_model(15099.0, 1469.1)
    y = kc.datasets.nile().flow
    return model, y, kc.kalman_filter(model, y, [1000.0], [[1e7]])


MISUSES = [
    ("log_likelihood(result, y)", lambda m, y, r: kc.log_likelihood(r, y),
     r"« model » est un résultat de filtre \(FilterResult\) : log_likelihood prend le modèle d'abord, "
     r"log_likelihood\(model, y, x0, P0\) ; .* appelez filter_log_likelihood\(result\)"),
    ("filter_log_likelihood(model)", lambda m, y, r: kc.filter_log_likelihood(m),
     r"« result » est un modèle .* appelez log_likelihood\(model, y, x0, P0\)"),
    ("rts_smoother(result, model)", lambda m, y, r: kc.rts_smoother(r, m),
     r"« model » est un résultat de filtre \(FilterResult\) : les arguments sont inversés ; appelez "
     r"rts_smoother\(model, result\)"),
    ("extended_rts_smoother(result, model)", lambda m, y, r: kc.extended_rts_smoother(r, kc.NonlinearModel.from_linear(m)),
     r"les arguments sont inversés ; appelez extended_rts_smoother\(model, result\)"),
    ("unscented_rts_smoother(result, model)", lambda m, y, r: kc.unscented_rts_smoother(
        r, kc.NonlinearModel.from_linear(m), alpha=1.0, kappa=0.0),
     r"les arguments sont inversés ; appelez unscented_rts_smoother\(model, result\)"),
    ("nis(diffuse_result)", lambda m, y, r: kc.nis(kc.diffuse_kalman_filter(m, y)),
     r"« result » vient de diffuse_kalman_filter : au début \(1 pas ici\), l'état n'est pas encore déterminé .* "
     r"nis\(result\.after_diffuse\(\)\)"),
    ("nis_test(diffuse_result)", lambda m, y, r: kc.nis_test(kc.diffuse_kalman_filter(m, y)),
     r"vient de diffuse_kalman_filter .* result\.after_diffuse\(\)"),
    ("whiteness_test(diffuse_result)", lambda m, y, r: kc.whiteness_test(kc.diffuse_kalman_filter(m, y)),
     r"vient de diffuse_kalman_filter .*result\.after_diffuse\(\)"),
    ("kalman_filter_runs(model, y 2-D)", lambda m, y, r: kc.kalman_filter_runs(m, y[:, None], [0.0], [[1.0]]),
     r"« Y » doit être de forme \(N, T, 1\) .* reçu la forme \(100, 1\) : pour un seul tirage, filtrez-le sans "
     r"« _runs » ou donnez Y\[None\]"),
    ("kalman_filter(form=…)", lambda m, y, r: kc.kalman_filter(m, y, [0.0], [[1.0]], form="joseph form"),
     r"« form » doit être l'une des formes 'square_root', 'textbook', 'joseph' ; reçu 'joseph form'"),
    ("unscented_kalman_filter sans alpha", lambda m, y, r: kc.unscented_kalman_filter(
        kc.NonlinearModel.from_linear(m), y, [1000.0], [[1e7]], kappa=0.0), r"« alpha » est obligatoire .* alpha=1\.0, kappa=0\.0"),
    ("unscented_kalman_filter sans kappa", lambda m, y, r: kc.unscented_kalman_filter(
        kc.NonlinearModel.from_linear(m), y, [1000.0], [[1e7]], alpha=1.0), r"« kappa » est obligatoire"),
    ("unscented_rts_smoother sans kappa (comme le filtre)", lambda m, y, r: kc.unscented_rts_smoother(
        kc.NonlinearModel.from_linear(m), kc.unscented_kalman_filter(kc.NonlinearModel.from_linear(m), y, [1000.0],
                                                                      [[1e7]], alpha=1.0, kappa=0.0), alpha=1.0),
     r"« kappa » est obligatoire"),
    ("se3_iterated_filter(y, T0, P0, u)", lambda m, y, r: kc.se3_iterated_filter(np.zeros((3, 8)), np.eye(4), np.eye(6), None),
     r"« model » doit être un CameraPoseModel ; reçu ndarray : le modèle vient d'abord"),
    # issue 32 : le contrat commun (model, y, x0, P0, u positionnels ; options par leur nom ; lisseurs sur un résultat)
    ("imm_filter(models, y, x0, P0, Pi)", lambda m, y, r: kc.imm_filter([m, m], y, [1000.0], [[1e7]],
                                                                        [[0.9, 0.1], [0.2, 0.8]]),
     r"« transition » manque : .* imm_filter\(models, y, x0, P0, transition=Pi, mu0=…\)\. La matrice donnée en "
     r"cinquième position, qui est la place des commandes « u », ressemble à une matrice de transition"),
    ("parallel_rts_smoother(model, y, x0, P0)", lambda m, y, r: kc.parallel_rts_smoother(m, y, [1000.0], [[1e7]]),
     r"« result » est un tableau \(ndarray\) : tous les lisseurs du paquet lissent la sortie d'un filtre, "
     r"parallel_rts_smoother\(model, result, x0, P0, u\) ; filtrez d'abord les mesures : "
     r"parallel_rts_smoother\(model, parallel_kalman_filter\(model, y, x0, P0\), x0, P0\)"),
    ("rts_smoother(model, y)", lambda m, y, r: kc.rts_smoother(m, list(y)),
     r"« result » est un tableau \(list\) : .* rts_smoother\(model, kalman_filter\(model, y, x0, P0\), x0, P0\)"),
    ("unscented_rts_smoother(model, y)", lambda m, y, r: kc.unscented_rts_smoother(
        kc.NonlinearModel.from_linear(m), y, alpha=1.0, kappa=0.0),
     r"unscented_rts_smoother\(model, unscented_kalman_filter\(model, y, x0, P0\), x0, P0\)"),
    ("adaptive_kalman_filter(detect=1.0)", lambda m, y, r: kc.adaptive_kalman_filter(m, y, [1000.0], [[1e7]],
                                                                                    detect=1.0),
     r"« detect » doit être une probabilité strictement entre 0 et 1 .* reçu 1\.0"),
    ("kalman_filter(model, vol, …)", lambda m, y, r: kc.kalman_filter(m, kc.datasets.samu31(), [1000.0], [[1e7]]),
     r"« y » est un vol \(Flight\), pas un tableau de mesures \(T, 1\) : donnez ses positions, par exemple "
     r"np\.column_stack\(\[vol\.east, vol\.north\]\)"),
    ("particle_filter(..., gate=…) par le moteur", lambda m, y, r: __import__(
        "kalman_course.filters.engine", fromlist=["run_filter"]).run_filter(
        __import__("kalman_course.filters.particle", fromlist=["particle_family"]).particle_family(20),
        kc.NonlinearModel.from_linear(m), y, [1000.0], [[1e7]], rng=0, gate=0.99),
     r"« gate » : le filtre particulaire n'a pas de porte"),
    ("parallel_kalman_filter, modèle trop court", lambda m, y, r: kc.parallel_kalman_filter(
        kc.LinearGaussianModel(np.ones((5, 1, 1)), [[1.0]], 1469.1, 15099.0), y, [1000.0], [[1e7]]),
     r"Le modèle varie dans le temps sur 5 pas .* reçu 100 mesures"),
    ("imm_filter(rule=\"ukf\")", lambda m, y, r: kc.imm_filter([m], y, [1000.0], [[1e7]], transition=[[1.0]],
                                                               rule="ukf"),
     r"« rule » doit être une règle du filtre gaussien .* reçu str"),
]


@pytest.mark.parametrize("name, call, message", MISUSES, ids=[m[0] for m in MISUSES])
def test_misuse_gets_a_french_error_with_the_right_call(name, call, message):
    model, y, result = _misuse_setup()
    with pytest.raises(KalmanInputError, match=message):
        call(model, y, result)


def test_likelihood_of_monte_carlo_filters_is_their_own_estimate_or_refused():
    """Filtre particulaire : sa propre estimation log p̂(y) (somme des incréments), pas la formule gaussienne
    appliquée à ses innovations ; EnKF : refusé en français (il n'estime pas la vraisemblance)."""
    from kalman_course.scenarios import convergence

    bench = convergence.linear_benchmark(n_steps=20)
    pf = kc.particle_filter(bench.nonlinear, bench.y, bench.x0, bench.P0, n_particles=300, rng=0)
    assert kc.filter_log_likelihood(pf) == pytest.approx(float(np.sum(pf.log_likelihood_increments)), abs=1e-12)
    np.testing.assert_array_equal(kc.log_likelihood_terms(pf), pf.log_likelihood_increments)
    gaussian = float(np.sum(kc.likelihood.log_likelihood_terms(kc.FilterResult(
        x=pf.x, P=pf.P, x_pred=pf.x_pred, P_pred=pf.P_pred, K=pf.K, innovation=pf.innovation, S=pf.S,
        observed=pf.observed, n_iter=pf.n_iter))))
    assert kc.filter_log_likelihood(pf) != pytest.approx(gaussian, abs=1e-6)  # pas le substitut gaussien
    enkf = kc.ensemble_kalman_filter(bench.nonlinear, bench.y, bench.x0, bench.P0, n_members=200, rng=0)
    for call in (kc.filter_log_likelihood, kc.log_likelihood_terms):
        with pytest.raises(KalmanInputError, match=r"« result » vient de l'EnKF .* n'estime pas la vraisemblance"):
            call(enkf)
