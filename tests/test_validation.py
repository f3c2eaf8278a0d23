"""Entrées invalides : chaque erreur est une KalmanInputError en français qui nomme l'argument."""

from __future__ import annotations

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
        (dict(Q=[[1.0, 0.0], [0.0, -0.1]]), r"« Q » doit être semi-définie positive .* -0\.1"),
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


def test_errors_are_value_errors_for_generic_handlers():
    assert issubclass(KalmanInputError, ValueError)
