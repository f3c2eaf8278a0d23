"""Les expériences de la partie « Plusieurs cibles » (``kalman_course.scenarios.traffic`` et ``crossing``) : le radar
de Blagnac (tirages communs, loi du fouillis, bruit), la GOSPA de chaque relevé contre Stone Soup, les
identités, les séries tracées par les curseurs, le relevé détaillé, le croisement sous un petit angle."""

from __future__ import annotations

import datetime

import numpy as np
import pytest
import scipy.stats

import kalman_course as kc
from kalman_course.scenarios import crossing as cr
from kalman_course.scenarios import traffic as tr


def test_radar_scans_follow_the_model():
    scans = tr.radar_scans()
    K, A = scans.truth.shape[:2]
    assert (K, A) == (tr.N_SCANS, 5) and len(scans.scans) == K
    np.testing.assert_allclose(scans.t, 5.0 * np.arange(61))
    e0, e1, n0, n1 = tr.REGION
    noise = []
    for z, origin, truth in zip(scans.scans, scans.origin, scans.truth):
        false = z[origin < 0]
        assert np.all((false[:, 0] >= e0) & (false[:, 0] <= e1) & (false[:, 1] >= n0) & (false[:, 1] <= n1))
        noise.append(z[origin >= 0] - truth[origin[origin >= 0]])
    noise = np.vstack(noise)
    # bruit de 50 m par axe, centré : intervalle de confiance de l'écart-type à 99,9 %
    n = noise.size
    lo, hi = np.sqrt(scipy.stats.chi2.ppf([0.0005, 0.9995], n) / n) * tr.NOISE_STD
    assert lo < np.sqrt(np.mean(noise**2)) < hi and abs(noise.mean()) < 4 * tr.NOISE_STD / np.sqrt(n)
    # détections : proportion P_D (binomiale)
    detected = scans.n_detected.sum()
    assert abs(detected - 0.9 * K * A) < 4 * np.sqrt(K * A * 0.09)


def test_clutter_counts_are_poisson_and_nested_across_densities():
    full = tr.radar_scans(clutter_density=tr.MAX_CLUTTER)
    mean = tr.MAX_CLUTTER * tr.AREA
    counts = full.n_clutter
    assert abs(counts.mean() - mean) < 4 * np.sqrt(mean / counts.size)
    assert 0.5 * mean < counts.var(ddof=1) < 1.8 * mean  # variance = moyenne (Poisson)
    # tirages communs : le fouillis d'une densité est une partie de celui d'une densité plus grande, les
    # détections manquées à P_D = 0,9 le sont aussi à 0,6
    low, mid = tr.radar_scans(clutter_density=5e-9), tr.radar_scans(clutter_density=3e-8)
    for k in range(tr.N_SCANS):
        small = {tuple(p) for p in low.scans[k][low.origin[k] < 0]}
        large = {tuple(p) for p in mid.scans[k][mid.origin[k] < 0]}
        assert small <= large
    seen_09 = tr.radar_scans(0.9).origin
    seen_06 = tr.radar_scans(0.6).origin
    for a, b in zip(seen_06, seen_09):
        assert set(a[a >= 0]) <= set(b[b >= 0])
    with pytest.raises(ValueError):
        tr.radar_scans(clutter_density=2 * tr.MAX_CLUTTER)


def test_scene_gospa_matches_stonesoup_and_decomposes():
    """La GOSPA de chaque relevé (p = 1, c = 1 km) recalculée par Stone Soup sur les mêmes positions."""
    pytest.importorskip("stonesoup")
    from stonesoup.metricgenerator.ospametric import GOSPAMetric
    from stonesoup.types.state import State

    t0 = datetime.datetime(2024, 1, 1)
    run = tr.track_scene("nn")
    metric = GOSPAMetric(c=tr.GOSPA_CUTOFF, p=1)
    truth = tr.truth()
    for k in range(0, tr.N_SCANS, 3):
        est = [State(p[:, None], timestamp=t0) for p in run.tracks.x[k][:, :2]]
        tru = [State(p[:, None], timestamp=t0) for p in truth[k]]
        value = metric.compute_gospa_metric(est, tru)[0].value
        assert run.gospa[k] == pytest.approx(value["distance"], rel=1e-9, abs=1e-9)
        assert (run.localisation[k], run.missed[k], run.false[k]) == pytest.approx(
            (value["localisation"], value["missed"], value["false"]), rel=1e-9, abs=1e-9)
    np.testing.assert_allclose(run.gospa, run.localisation + run.missed + run.false, rtol=1e-12)
    assert run.gospa[0] == pytest.approx(5 * tr.GOSPA_CUTOFF / 2)  # aucune piste au premier relevé


def test_identity_changes_count_persistent_changes_only():
    labels = np.array([[-1, 0, 0, 1, 0, 0, 0, -1, 2, 2, 2]]).T  # un échange d'un relevé, puis une renaissance
    assert tr.identity_changes(labels) == 1
    assert tr.identity_changes(np.array([[0, 0, 1, 1, 1, 0, 0, 0]]).T) == 2
    assert tr.identity_changes(np.array([[0, 0, 1, 1, 0, 0]]).T) == 0  # deux relevés : pas assez
    assert tr.identity_changes(np.full((5, 2), -1)) == 0


def test_track_series_draw_every_confirmed_track_once():
    run = tr.track_scene("jpda", 0.6)
    series = tr.track_series(run)
    owner = tr.track_owners(run)
    K = tr.N_SCANS
    for a in range(5):
        for c in "en":
            assert series[f"a{a}_{c}"].shape == (tr.TRACK_SLOTS * (K + 1),)
            assert np.all(np.isnan(series[f"a{a}_{c}"].reshape(tr.TRACK_SLOTS, K + 1)[:, -1]))
    # chaque position de piste confirmée est tracée une fois, dans la ligne de son avion ou en fausse piste
    drawn = sum(np.isfinite(series[f"a{a}_e"]).sum() for a in range(5)) + np.isfinite(series["false_e"]).sum()
    assert drawn == sum(ids.size for ids in run.tracks.ids)
    k = 40
    for i, track in enumerate(run.tracks.ids[k]):
        if int(track) in owner:
            rows = series[f"a{owner[int(track)]}_e"].reshape(tr.TRACK_SLOTS, K + 1)[:, k]
            assert np.any(np.isclose(rows, run.tracks.x[k][i, 0] / 1e3))


def test_snapshot_is_the_tracker_state_and_nn_errs_where_gnn_does_not():
    snap = tr.scan_snapshot()
    run, model = tr.track_scene(), tr.radar_model()
    k = snap.k
    np.testing.assert_allclose(snap.x_pred, run.tracks.x[k - 1] @ model.A.T)
    np.testing.assert_array_equal(snap.ids, run.tracks.ids[k - 1])
    origin_of = lambda a: np.where(a >= 0, snap.origin[np.maximum(a, 0)], -1)  # noqa: E731
    np.testing.assert_array_equal(origin_of(snap.gnn), snap.owner)  # le GNN : chaque piste a son avion
    assert np.sum(origin_of(snap.nn) != snap.owner) == 4  # le NN : deux détections volées, deux pistes sans rien
    np.testing.assert_allclose(snap.jpda.sum(axis=1), 1.0)
    best = snap.jpda[:, 1:].argmax(axis=1)
    np.testing.assert_array_equal(snap.origin[best], snap.owner)


def test_crossing_geometry_and_outcomes():
    truth = cr.crossing_truth(8.0)
    k = int(cr.CROSSING_TIME / tr.DT)
    np.testing.assert_allclose(truth[k], 0.0, atol=1e-9)  # le croisement à t = 75 s, à l'origine
    v = np.diff(truth, axis=0)[0] / tr.DT
    assert np.linalg.norm(v[0]) == pytest.approx(cr.SPEED) and np.linalg.norm(v[1]) == pytest.approx(cr.SPEED)
    angle = np.degrees(np.arccos(v[0] @ v[1] / cr.SPEED**2))
    assert angle == pytest.approx(8.0)
    ref = k - cr.BEFORE
    kept = np.full((cr.N_SCANS, 2), -1)
    kept[3:] = [0, 1]
    swapped = kept.copy()
    swapped[k:] = [1, 0]
    lost = kept.copy()
    lost[-1] = [0, 0]
    assert [cr.crossing_outcome(x) for x in (kept, swapped, lost)] == ["gardées", "échangées", "autre"]
    late = kept.copy()
    late[:ref + 1] = -1  # pas encore confirmées au relevé de référence
    assert cr.crossing_outcome(late) == "autre"


def test_crossing_study_counts_every_run_once():
    study = cr.crossing_study(8.0, 4)
    assert set(study.counts) == {"nn", "gnn", "pda", "jpda"}
    assert all(sum(c) == 4 for c in study.counts.values())
    # les quatre associations voient les mêmes relevés
    np.testing.assert_array_equal(np.vstack(cr.crossing_scans(8.0, 2)), np.vstack(cr.crossing_scans(8.0, 2)))
