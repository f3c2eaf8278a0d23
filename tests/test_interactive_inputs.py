"""Entrées invalides des figures à curseurs et des expériences qu'elles appellent : une erreur française
(KalmanInputError) qui nomme l'argument et ce qui était attendu."""

from __future__ import annotations

import numpy as np
import pytest

import kalman_course as kc
import kalman_course.interactive as ki
from kalman_course.interactive.figure import SliderSpec
from kalman_course.scenarios import (
    camera_noise,
    consistency_scaling,
    engine_cycle,
    gain_trace,
    half_steps,
    intuition,
    noise_levels,
    polar,
    radar_prior,
    sensor_tuning,
    stability,
)

AXIS = dict(name="a", symbol="a", description="un axe", unit="m")


@pytest.mark.parametrize(
    "call, match",
    [
        # axes, grilles, tracés
        (lambda: ki.ParameterAxis(**AXIS, values=[0.0, 1.0], default=0, scale="carré"), "scale"),
        (lambda: ki.ParameterAxis(**AXIS, values=[1.0, 0.0], default=0, scale="linear"), "strictement croissantes"),
        (lambda: ki.ParameterAxis(**AXIS, values=[0.0, 1.0], default=0, scale="index", tick_labels=("x",)),
         "tick_labels"),
        (lambda: ki.ParameterAxis(**AXIS, values=[0.0, 1.0], default=0, scale="index", tick_labels=("x", "")),
         "tick_labels"),
        (lambda: ki.precompute_grid(lambda: {"s": [1.0]}, time=[0.0]), "un, deux ou trois axes"),
        (lambda: ki.precompute_grid(lambda a: {"s": [1.0]}, ki.ParameterAxis(**AXIS, values=[1.0, 2.0], default=0)),
         "time"),
        (lambda: ki.precompute_grid(lambda a: {"s": [[1.0]]}, ki.ParameterAxis(**AXIS, values=[1.0, 2.0], default=0),
                                    time=[0.0]), "vecteur non vide"),
        (lambda: ki.Glyph("x", "vline", "red", "v"), "value"),
        (lambda: ki.Glyph("x", "band", "red", "bande"), "upper"),
        (lambda: ki.Glyph("x", "line", "red", "x", dash="pointillé"), "dash"),
        (lambda: ki.Glyph("x", "scatter", "red", "x", marker="cœur"), "marker"),
        # registre et curseurs interactifs
        (lambda: ki.sliders("pas-une-figure"), "Figure à curseurs inconnue"),
        (lambda: SliderSpec("n", "c", "t", "x (m)", axes=(), run=lambda: {}, time=[0.0], panels=()), "un à trois"),
        (lambda: ki.LinearParameter("K", "gain", "", 3.0, 0.0, 2.0, 0.1), "hors de la plage"),
        (lambda: ki.LinearParameter("K", "gain", "", 1.0, 2.0, 0.0, 0.1), "low"),
        (lambda: ki.LinearParameter("K", "gain", "", 1.0, 0.0, 2.0, 0.0), "step"),
        (lambda: ki.ChoiceParameter("i", "itération", (0.0, 1.0), ("0",), 0.0), "un libellé par valeur"),
        (lambda: ki.ChoiceParameter("i", "itération", (0.0, 1.0), ("0", "1"), 5.0), "positions"),
        # expériences
        (lambda: intuition.gaussian_density([0.0], 0.0, -1.0), "var"),
        (lambda: intuition.gaussian_product(0.0, 1.0, [1.0, 2.0], 1.0), "mean2"),
        (lambda: intuition.correction_1d(0.0, 0.0, 1.0, 1.0), "prior_var"),
        (lambda: intuition.cart_model(Q=float("nan")), "Q"),
        (lambda: half_steps.half_steps("pas un résultat", [0.0], [[1.0]]), "result"),
        (lambda: noise_levels.engine_at_noise(-1.0, 1.0), "phi_scale"),
        (lambda: noise_levels.engine_at_noise(1.0, 0.0), "R"),
        (lambda: stability.fixed_gain_experiment(float("inf")), "K"),
        (lambda: stability.counter_example_model([1.0, 2.0]), "A"),
        (lambda: engine_cycle.engine_cycle(0.0), "psi_scale"),
        (lambda: gain_trace.gain_trace(0, 0.1), "n"),
        (lambda: gain_trace.gain_trace(10, "beaucoup"), "K"),
        (lambda: sensor_tuning.sensor_tuning(true_std=0.0), "true_std"),
        (lambda: consistency_scaling.scaled_consistency(psi_factor=-1.0), "psi_factor"),
        (lambda: polar.polar_transform(range_std=0.0), "range_std"),
        (lambda: radar_prior.radar_problem_with_prior(-3.0), "prior_std"),
        (lambda: camera_noise.camera_problem_with_noise(float("nan")), "sigma_px"),
    ],
)
def test_bad_arguments_raise_french_errors(call, match):
    with pytest.raises(kc.KalmanInputError, match=match):
        call()


def test_static_figure_rejects_a_fixed_series_named_like_a_computed_one_and_a_bad_readout():
    axis = ki.ParameterAxis(**AXIS, values=[1.0, 2.0], default=0)
    t = np.arange(3.0)
    grid = ki.precompute_grid(lambda a: {"s": a * t}, axis, time=t)
    panel = ki.Panel("p", "s (m)", (ki.Glyph("s", "line", "red", "s"),))
    with pytest.raises(kc.KalmanInputError, match="nom d'une série calculée"):
        ki.StaticSliders(grid, (panel,), "t (s)", fixed={"s": t})
    with pytest.raises(kc.KalmanInputError, match="readout"):
        ki.StaticSliders(grid, (panel,), "t (s)", readout="pas une fonction")
    with pytest.raises(kc.KalmanInputError, match="hors de la grille"):
        grid.run(2)


def test_a_grid_with_one_and_three_axes_and_series_of_several_lengths():
    a = ki.ParameterAxis(**AXIS, values=[0.0, 1.0, 2.0], default=1, scale="linear")
    b = ki.ParameterAxis("b", "b", "second", "s", [1.0, 10.0], default=0)
    c = ki.ParameterAxis("c", "c", "troisième", "", [0.0, 1.0], default=1, scale="index", tick_labels=("non", "oui"))
    t = np.arange(4.0)
    grid = ki.precompute_grid(lambda x, y, z: {"long": x + y * t + z, "point": [x * y * z]}, a, b, c, time=t)
    assert grid.shape == (3, 2, 2) and grid.size == 12 and grid.default_index == (1, 0, 1)
    assert grid.length("long") == 4 and grid.length("point") == 1
    np.testing.assert_array_equal(grid.run(2, 1, 1)["long"], 2.0 + 10.0 * t + 1.0)
    # ordre aplati (C) : l'exécution (i, j, k) commence à ((i·N1 + j)·N2 + k)·L
    start = ((2 * 2 + 1) * 2 + 1) * 4
    np.testing.assert_array_equal(grid.flat("long")[start:start + 4], grid.run(2, 1, 1)["long"])
    assert grid.flat("point")[(2 * 2 + 1) * 2 + 1] == 20.0
    assert c.labels() == ["non", "oui"] and grid.values_at(0, 1, 0) == (0.0, 10.0, 0.0)
    one = ki.precompute_grid(lambda x: {"s": x * t}, a, time=t)
    assert one.shape == (3,) and one.default_index == (1,)
    panel = ki.Panel("p", "s (m)", (ki.Glyph("s", "line", "red", "s"),))
    html = ki.StaticSliders(one, (panel,), "t (s)", name="un-axe", readout=lambda idx: f"position {idx[0]}").html()
    assert "kc-slider-0" in html and "kc-slider-1" not in html and "position 1" in html
