"""Filtres non linéaires en lot (``run_filter_runs``) contre un filtre par tirage.

Le cas mesuré est l'expérience « cible lointaine » du chapitre UKF (100 tirages × 40 pas, radar distance
et azimut, modèle vectorisé) : pour l'EKF, l'UKF et l'EKF itéré, temps CPU du filtre lancé tirage par
tirage (``extended_kalman_filter``…) et du filtre en lot (``extended_kalman_filter_runs``…), meilleur de
3, BLAS sur un fil ; puis ``distant_target_comparison()`` entière (celle du paquet, en lot) contre la
même expérience écrite tirage par tirage (la version d'avant le mode en lot, recopiée ici), avec l'écart
relatif maximal de l'erreur de position et de la NEES (il doit rester sous 10⁻⁹ : mêmes tirages, mêmes
nombres).

Usage : .venv/bin/python benchmarks/batch_nonlinear.py
"""

from __future__ import annotations

import time
from typing import Any, Callable

import numpy as np
from threadpoolctl import threadpool_limits

import kalman_course as kc
from kalman_course.filters.extended import extended_kalman_filter_runs
from kalman_course.filters.iterated import iterated_extended_kalman_filter_runs
from kalman_course.filters.unscented import unscented_kalman_filter_runs
from kalman_course.numbers import format_spec
from kalman_course.scenarios import distant_target as dt

REPEAT = 3
MAX_GAP = 1e-9


def fr_sci(value: float) -> str:
    """Petit écart en notation scientifique française (« 2,3 × 10⁻¹³ ») ; un écart nul s'écrit « 0 »."""
    return format_spec(value, ".1e")


def best_cpu(func: Callable[[], Any]) -> tuple[float, Any]:
    """Meilleur temps CPU (s) de ``REPEAT`` appels, et le dernier résultat."""
    best, out = float("inf"), None
    for _ in range(REPEAT):
        t0 = time.process_time()
        out = func()
        best = min(best, time.process_time() - t0)
    return best, out


def comparison_run_by_run(n_runs: int = dt.TARGET_RUNS, rng: Any = dt.TARGET_SEED,
                          n_steps: int = dt.TARGET_STEPS) -> dt.FilterComparison:
    """L'expérience telle qu'elle était écrite avant le mode en lot : un tirage, puis ses trois filtres."""
    gen = np.random.default_rng(rng)
    model = dt.distant_target_model()
    filters = {
        "EKF": lambda run: kc.extended_kalman_filter(model, run.y, run.x0, run.P0),
        "UKF": lambda run: kc.unscented_kalman_filter(model, run.y, run.x0, run.P0, **dt.TARGET_UKF),
        "EKF itéré": lambda run: kc.iterated_extended_kalman_filter(model, run.y, run.x0, run.P0),
    }
    err = {name: np.zeros(n_steps) for name in filters}
    eps = {name: np.zeros(n_steps) for name in filters}
    for _ in range(n_runs):
        run = dt.distant_target_run(gen, n_steps)
        for name, run_filter in filters.items():
            result = run_filter(run)
            err[name] += np.linalg.norm(result.x[:, :2] - run.x_true[:, :2], axis=1) / n_runs
            eps[name] += kc.nees(run.x_true, result) / n_runs
    return dt.FilterComparison(t=dt.TARGET_DT * np.arange(1, n_steps + 1), position_error=err, nees=eps,
                               n_runs=n_runs)


def main() -> None:
    gen = np.random.default_rng(dt.TARGET_SEED)
    runs = [dt.distant_target_run(gen) for _ in range(dt.TARGET_RUNS)]
    model = dt.distant_target_model()
    Y = np.stack([run.y for run in runs])
    pairs = {
        "EKF": (lambda r: kc.extended_kalman_filter(model, r.y, r.x0, r.P0),
                lambda: extended_kalman_filter_runs(model, Y, dt.TARGET_START, dt.TARGET_P0)),
        "UKF": (lambda r: kc.unscented_kalman_filter(model, r.y, r.x0, r.P0, **dt.TARGET_UKF),
                lambda: unscented_kalman_filter_runs(model, Y, dt.TARGET_START, dt.TARGET_P0, **dt.TARGET_UKF)),
        "EKF itéré": (lambda r: kc.iterated_extended_kalman_filter(model, r.y, r.x0, r.P0),
                      lambda: iterated_extended_kalman_filter_runs(model, Y, dt.TARGET_START, dt.TARGET_P0)),
    }
    failed = False
    with threadpool_limits(1, "blas"):
        print(f"Cible lointaine : {format_spec(Y.shape[0], 'd')} tirages × {format_spec(Y.shape[1], 'd')} pas, "
              f"temps CPU, meilleur de {format_spec(REPEAT, 'd')}, BLAS sur 1 fil")
        for name, (single, batch) in pairs.items():
            t_one, ref = best_cpu(lambda single=single: [single(r) for r in runs])
            t_lot, res = best_cpu(batch)
            gap = max(float(np.max(np.abs(res.x[i] - ref[i].x))) for i in range(len(runs)))
            print(f"  {name:<10} tirage par tirage {format_spec(t_one, '.3f')} s, "
                  f"en lot {format_spec(t_lot, '.3f')} s : {format_spec(t_one / t_lot, '.1f')} × plus rapide "
                  f"(écart maximal des estimations {fr_sci(gap)} m)")
            failed |= gap > 1e-6
        t_old, old = best_cpu(comparison_run_by_run)
        t_new, new = best_cpu(dt.distant_target_comparison)
    gaps = [float(np.max(np.abs(new_d[name] - old_d[name]) / np.abs(old_d[name])))
            for old_d, new_d in ((old.position_error, new.position_error), (old.nees, new.nees)) for name in old_d]
    print(f"distant_target_comparison() : tirage par tirage {format_spec(t_old, '.3f')} s, "
          f"en lot {format_spec(t_new, '.3f')} s : {format_spec(t_old / t_new, '.1f')} × plus rapide")
    print(f"écart relatif maximal (erreur de position et NEES, 3 filtres) : {fr_sci(max(gaps))} "
          f"(tolérance {fr_sci(MAX_GAP)})")
    if failed or max(gaps) > MAX_GAP:
        raise SystemExit("Les filtres en lot ne redonnent pas les nombres du filtre tirage par tirage.")


if __name__ == "__main__":
    main()
