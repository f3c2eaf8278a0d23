"""Filtre et lisseur par balayage associatif (Särkkä et García-Fernández, 2021) : le balayage contre des
préfixes calculés un à un ; l'opérateur associatif ; le filtre et le lisseur parallèles contre le filtre et
le lisseur séquentiels (10⁻⁸ relatif, a priori loin de zéro compris : le cas de dynamax #423) et contre
l'oracle dense (loi de toute la trajectoire d'un bloc, tests/dense_oracle.py) ; erreurs françaises."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import random_model
from dense_oracle import batch_log_likelihood, batch_posterior

import kalman_course as kc
from kalman_course.filters.parallel import (
    associative_scan,
    combine_filtering,
    combine_smoothing,
    filtering_elements,
    scan_passes,
)

RTOL = 1e-8
FIELDS = ("x", "P", "x_pred", "P_pred", "K", "innovation", "S")


def _case(seed, n, m, p, T=120, offset=100.0):
    rng = np.random.default_rng(seed)
    model = random_model(rng, n, m, p)
    A = 0.97 * model.A / max(1.0, float(np.max(np.abs(np.linalg.eigvals(model.A)))))
    model = kc.LinearGaussianModel(A, model.C, model.Q, model.R, B=model.B)
    u = rng.standard_normal((T, p)) if p else None
    x0 = offset + rng.standard_normal(n)
    y = np.array(kc.simulate(model, x0, T, u=u, rng=rng).y)
    return model, y, x0, 2.0 * np.eye(n), u


def _close(ours, ref, field):
    a, b = np.asarray(getattr(ours, field)), np.asarray(getattr(ref, field))
    assert (np.isnan(a) == np.isnan(b)).all(), field
    scale = np.nanmax(np.abs(b)) if np.isfinite(b).any() else 1.0
    np.testing.assert_allclose(np.nan_to_num(a), np.nan_to_num(b), rtol=0, atol=RTOL * scale, err_msg=field)


# --------------------------------------------------------------------------- le balayage


@pytest.mark.parametrize("T", [1, 2, 3, 4, 5, 7, 8, 9, 16, 31, 33, 100])
def test_scan_gives_every_prefix_of_a_non_commutative_associative_operator(T):
    """Produits préfixes de matrices 2 × 2 (associatif, non commutatif) contre la boucle, et nombre de passes
    ≤ 2⌈log₂ T⌉."""
    rng = np.random.default_rng(T)
    M = rng.standard_normal((T, 2, 2))
    calls = []

    def product(a, b):
        calls.append(len(a[0]))
        return (a[0] @ b[0],)

    (prefix,) = associative_scan(product, (M,))
    ref = [M[0]]
    for k in range(1, T):
        ref.append(ref[-1] @ M[k])
    np.testing.assert_allclose(prefix, np.array(ref), rtol=1e-10, atol=1e-10)
    assert len(calls) == scan_passes(T) <= 2 * int(np.ceil(np.log2(max(T, 1))))
    assert sum(calls) <= 2 * T  # environ 2T combinaisons en tout (travail linéaire)


def test_filtering_operator_is_associative_and_its_prefix_is_the_kalman_filter():
    model, y, x0, P0, u = _case(1, 3, 2, 1, T=6)
    BU = u @ model.B.T
    el = filtering_elements(model, y, x0, P0, BU)  # en colonnes : axe des éléments en dernier
    a, b, c = ([e[..., k:k + 1] for e in el] for k in (1, 2, 3))
    left = combine_filtering(combine_filtering(a, b), c)
    right = combine_filtering(a, combine_filtering(b, c))
    for L, R in zip(left, right):
        np.testing.assert_allclose(L, R, rtol=1e-11, atol=1e-12)
    # a₁ ⊗ a₂ ⊗ a₃ : F = 0 et (b, Σ) = (x̂₃, P₃) du filtre séquentiel
    kf = kc.kalman_filter(model, y, x0, P0, u)
    first = [e[..., 0:1] for e in el]
    prefix = combine_filtering(combine_filtering(first, a), b)
    assert not np.asarray(prefix[0]).any()
    np.testing.assert_allclose(prefix[1][..., 0], kf.x[2], rtol=1e-12)
    np.testing.assert_allclose(prefix[2][..., 0], kf.P[2], rtol=1e-12, atol=1e-14)


def test_smoothing_operator_is_associative():
    rng = np.random.default_rng(5)
    el = [(rng.standard_normal((3, 3, 1)), rng.standard_normal((3, 1)), np.eye(3)[:, :, None] * (1 + k)) for k in range(3)]
    left = combine_smoothing(combine_smoothing(el[0], el[1]), el[2])
    right = combine_smoothing(el[0], combine_smoothing(el[1], el[2]))
    for L, R in zip(left, right):
        np.testing.assert_allclose(L, R, rtol=1e-12, atol=1e-12)


# --------------------------------------------------------------------------- filtre et lisseur


@pytest.mark.parametrize("n,m,p", [(1, 1, 0), (3, 2, 1), (4, 2, 0), (4, 3, 2)])
def test_parallel_filter_equals_the_kalman_filter_far_from_zero(n, m, p):
    model, y, x0, P0, u = _case(10 * n + m + p, n, m, p)
    ours = kc.parallel_kalman_filter(model, y, x0, P0, u)
    ref = kc.kalman_filter(model, y, x0, P0, u)
    for field in FIELDS:
        _close(ours, ref, field)
    np.testing.assert_array_equal(ours.observed, ref.observed)
    np.testing.assert_array_equal(ours.n_iter, ref.n_iter)
    assert kc.filter_log_likelihood(ours) == pytest.approx(kc.filter_log_likelihood(ref), rel=1e-10)


def test_missing_and_partial_rows_and_the_dynamax_423_prior():
    """x0 = 100 (dynamax #423 : la log-vraisemblance parallèle y différait de la séquentielle), lignes
    manquantes et partielles ; log-vraisemblance contre l'oracle dense (aucune récurrence)."""
    model, y, x0, P0, u = _case(7, 3, 2, 1, T=60)
    x0 = np.full(3, 100.0)
    y[[0, 9, 10, 33]] = np.nan
    y[[4, 20, 21], 1] = np.nan
    y[40, 0] = np.nan
    ours = kc.parallel_kalman_filter(model, y, x0, P0, u)
    ref = kc.kalman_filter(model, y, x0, P0, u)
    for field in FIELDS:
        _close(ours, ref, field)
    ll = kc.filter_log_likelihood(ours)
    assert ll == pytest.approx(kc.filter_log_likelihood(ref), rel=1e-10)
    assert ll == pytest.approx(batch_log_likelihood(model, y, u=u, x0=x0, P0=P0), rel=1e-9)


def test_parallel_smoother_equals_rts_and_the_dense_posterior():
    model, y, x0, P0, u = _case(3, 3, 2, 1, T=80)
    y[[5, 6, 50]] = np.nan
    y[12, 0] = np.nan
    ours = kc.parallel_rts_smoother(model, kc.parallel_kalman_filter(model, y, x0, P0, u), x0, P0, u)
    ref = kc.rts_smoother(model, kc.kalman_filter(model, y, x0, P0, u), x0, P0, u)
    for field in ("x", "P", "G", "P_lag", "x_initial", "P_initial", "G_initial"):
        _close(ours, ref, field)
    dense = batch_posterior(model, y, u=u, x0=x0, P0=P0)
    for ours_value, key in ((ours.x, "x"), (ours.P, "P"), (ours.P_lag[1:], "P_lag"), (ours.x_initial, "x_initial"),
                            (ours.P_initial, "P_initial"), (ours.P_lag[0], "lag0")):
        ref_value = dense[key][1:] if key == "P_lag" else dense[key]
        np.testing.assert_allclose(ours_value, ref_value, rtol=0, atol=1e-8 * np.abs(ref_value).max(), err_msg=key)
    assert "parallèle" in ours.method


def test_short_series_and_a_single_step():
    model, y, x0, P0, u = _case(2, 2, 1, 0, T=1)
    _close(kc.parallel_kalman_filter(model, y, x0, P0), kc.kalman_filter(model, y, x0, P0), "P")
    sm = kc.parallel_rts_smoother(model, kc.parallel_kalman_filter(model, y, x0, P0), x0, P0)
    _close(sm, kc.rts_smoother(model, kc.kalman_filter(model, y, x0, P0), x0, P0), "x_initial")


def test_bad_inputs_are_the_kalman_filter_errors():
    model, y, x0, P0, u = _case(2, 3, 2, 1, T=5)
    with pytest.raises(kc.KalmanInputError, match=r"« y » doit être de forme \(T, 2\)"):
        kc.parallel_kalman_filter(model, np.zeros((5, 3)), x0, P0, u)
    with pytest.raises(kc.KalmanInputError, match="« P0 » doit être"):
        kc.parallel_kalman_filter(model, y, x0, -P0, u)
    with pytest.raises(kc.KalmanInputError, match="« P0 » n'est pas l'a priori du filtre"):
        kc.parallel_rts_smoother(model, kc.parallel_kalman_filter(model, y, x0, P0, u), x0, 2.0 * P0, u)
    with pytest.raises(kc.KalmanInputError, match="« u » doit avoir une commande par pas de temps"):
        kc.parallel_kalman_filter(model, y, x0, P0, u[:3])
    nonlinear = kc.NonlinearModel.from_linear(model)
    with pytest.raises(kc.KalmanInputError, match="extended_kalman_filter"):
        kc.parallel_kalman_filter(nonlinear, y, x0, P0, u)
