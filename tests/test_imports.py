"""Imports légers : ``import kalman_course`` ne charge que les filtres (ni matplotlib, ni bokeh, ni
ipywidgets, ni filterpy, ni Babel) ; les sous-modules lourds se chargent à la première utilisation."""

from __future__ import annotations

import subprocess
import sys
import textwrap

HEAVY = ("matplotlib", "bokeh", "ipywidgets", "filterpy", "babel", "statsmodels", "myst_nb")


def _run(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=300)


def test_filters_run_with_heavy_libraries_blocked():
    # un module à None dans sys.modules fait échouer tout import : si le paquet en avait besoin, on le verrait
    proc = _run(f"""
        import sys
        for name in {HEAVY!r}:
            sys.modules[name] = None
        import numpy as np
        import kalman_course as kc
        model = kc.LinearGaussianModel([[1.0, 1.0], [0.0, 1.0]], [[1.0, 0.0]], 0.01 * np.eye(2), [[0.5]])
        sim = kc.simulate(model, [0.0, 1.0], 50, rng=0)
        kf = kc.kalman_filter(model, sim.y, [0.0, 0.0], np.eye(2))
        ekf = kc.extended_kalman_filter(kc.NonlinearModel.from_linear(model), sim.y, [0.0, 0.0], np.eye(2))
        iekf = kc.iterated_extended_kalman_filter(kc.NonlinearModel.from_linear(model), sim.y, [0.0, 0.0], np.eye(2))
        srif = kc.square_root_information_filter(model, sim.y, [0.0, 0.0], np.eye(2))
        runs = kc.kalman_filter_runs(model, np.stack([sim.y, sim.y]), [0.0, 0.0], np.eye(2))
        assert np.allclose(kf.x, ekf.x) and np.allclose(kf.x, srif.x) and np.allclose(kf.x, runs.x[1])
        print("ok")
    """)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert proc.stdout.strip() == "ok"


def test_import_loads_no_heavy_library_and_submodules_load_on_use():
    proc = _run(f"""
        import sys
        import kalman_course as kc
        print(sorted(m for m in {HEAVY!r} if m in sys.modules))
        assert "kalman_course.figures" not in sys.modules and "kalman_course.scenarios" not in sys.modules
        kc.scenarios.constant_voltage_model()          # chargé à la demande
        assert "matplotlib" not in sys.modules         # les scénarios ne tracent rien
        kc.figures.names()
        print("matplotlib" in sys.modules, "bokeh" in sys.modules)
    """)
    assert proc.returncode == 0, proc.stderr[-3000:]
    loaded, after = proc.stdout.strip().splitlines()
    assert loaded == "[]"
    assert after == "True False"  # les figures chargent matplotlib, pas bokeh
