"""Filtrage de nombreux tirages : ``kalman_filter_runs`` (lot) contre une boucle de filterpy sur les tirages.

1000 tirages × 100 pas d'un modèle à 4 états et 2 mesures (vitesse constante dans le plan, position
mesurée). Cible (issue « Un seul moteur ») : au moins 100 fois plus rapide que la boucle
``predict()``/``update()`` de filterpy, pour les mêmes nombres (vérifiés ici à 10⁻¹⁰ près).

Usage : .venv/bin/python benchmarks/kf_runs_vs_filterpy.py [--runs 1000] [--steps 100]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from filterpy.kalman import KalmanFilter

import kalman_course as kc
from kalman_course.numbers import format_spec

TARGET = 100.0


def cv_model(dt: float = 0.1) -> kc.LinearGaussianModel:
    F = np.eye(4)
    F[0, 2] = F[1, 3] = dt
    G = np.vstack([0.5 * dt**2 * np.eye(2), dt * np.eye(2)])
    return kc.LinearGaussianModel(F, np.hstack([np.eye(2), np.zeros((2, 2))]), 0.25 * G @ G.T, 0.01 * np.eye(2))


def filterpy_runs(model, Y, x0, P0):
    N, T, m = Y.shape
    out = np.empty((N, T, model.n_state))
    for r in range(N):
        f = KalmanFilter(dim_x=model.n_state, dim_z=m)
        f.F, f.H, f.Q, f.R = (np.array(a) for a in (model.A, model.C, model.Q, model.R))
        f.x = np.array(x0, dtype=float).reshape(-1, 1)
        f.P = np.array(P0, dtype=float)
        for k in range(T):
            f.predict()
            f.update(Y[r, k].reshape(m, 1))
            out[r, k] = f.x.ravel()
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description="kalman_filter_runs contre filterpy sur de nombreux tirages.")
    parser.add_argument("--runs", type=int, default=1000, help="nombre de tirages (défaut : 1000)")
    parser.add_argument("--steps", type=int, default=100, help="nombre de pas par tirage (défaut : 100)")
    args = parser.parse_args()
    model = cv_model()
    rng = np.random.default_rng(0)
    x0, P0 = np.zeros(4), np.eye(4)
    Y = np.stack([kc.simulate(model, rng.standard_normal(4), args.steps, rng=rng).y for _ in range(args.runs)])

    t0 = time.perf_counter()
    ref = filterpy_runs(model, Y, x0, P0)
    t_fp = time.perf_counter() - t0
    best = np.inf
    for _ in range(5):
        t0 = time.perf_counter()
        runs = kc.kalman_filter_runs(model, Y, x0, P0)
        best = min(best, time.perf_counter() - t0)
    err = float(np.max(np.abs(runs.x - ref)))
    ratio = t_fp / best
    print(f"{format_spec(args.runs, 'd')} tirages × {format_spec(args.steps, 'd')} pas, 4 états, 2 mesures")
    print(f"filterpy (boucle sur les tirages) : {format_spec(t_fp, '.3f')} s")
    print(f"kalman_filter_runs (lot)          : {format_spec(1e3 * best, '.2f')} ms (meilleur de 5)")
    print(f"rapport : {format_spec(ratio, '.0f')} × plus rapide (cible ≥ {format_spec(TARGET, '.0f')} ×) — "
          f"{'atteinte' if ratio >= TARGET else 'MANQUÉE'}")
    print(f"écart maximal des estimations : {format_spec(err, '.1e')}")
    if err > 1e-10:
        raise SystemExit("Les estimations diffèrent de filterpy.")


if __name__ == "__main__":
    main()
