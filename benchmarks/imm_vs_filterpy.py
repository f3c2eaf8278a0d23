"""Temps par pas de imm_filter comparé à IMMEstimator de filterpy (predict() puis update(z), mêmes données).

Usage : .venv/bin/python benchmarks/imm_vs_filterpy.py [--repeat 3] [--steps 3000]
Cible (issue 21) : au plus 0,8 × le temps de filterpy, à 2 et à 3 régimes (vitesse presque constante
2-D, 4 états, 2 mesures de position). Imprime µs/pas (meilleur de --repeat essais), le rapport, et
l'écart final des estimations combinées et des probabilités des régimes.
"""

from __future__ import annotations

import argparse

import numpy as np
from filterpy.kalman import IMMEstimator, KalmanFilter

import kalman_course as kc
from kalman_course.numbers import format_spec
from _timing import best_time

TARGET = 0.8


def run_filterpy(models, y, x0, P0, transition, mu0):
    filters = []
    for model in models:
        f = KalmanFilter(dim_x=model.n_state, dim_z=model.n_obs)
        f.F, f.H, f.Q, f.R = (np.array(a) for a in (model.A, model.C, model.Q, model.R))
        f.x = np.asarray(x0, float).reshape(-1, 1).copy()
        f.P = np.asarray(P0, float).copy()
        filters.append(f)
    imm = IMMEstimator(filters, np.array(mu0, float), np.array(transition, float))
    for z in [row.reshape(-1, 1) for row in y]:
        imm.predict()
        imm.update(z)
    return imm.x.ravel(), np.array(imm.mu)


def bench(label, models, y, transition, repeat):
    r = len(models)
    x0, P0, mu0 = np.zeros(4), np.eye(4) * 100.0, np.full(r, 1.0 / r)
    T = len(y)
    t_ours, res = best_time(lambda: kc.imm_filter(models, y, x0, P0, transition=transition, mu0=mu0), repeat)
    t_fp, (x_fp, mu_fp) = best_time(lambda: run_filterpy(models, y, x0, P0, transition, mu0), repeat)
    diff = max(np.abs(res.x[-1] - x_fp).max(), np.abs(res.mu[-1] - mu_fp).max())
    ratio = t_ours / t_fp
    status = "OK" if ratio <= TARGET else "AU-DESSUS DE LA CIBLE"
    print(
        f"{label:34s} {format_spec(T, 'd'):>6s} pas  kalman_course {format_spec(t_ours / T * 1e6, '.1f'):>6s} µs/pas  "
        f"filterpy {format_spec(t_fp / T * 1e6, '.1f'):>6s} µs/pas  rapport {format_spec(ratio, '.2f'):>4s} "
        f"(cible ≤ {format_spec(TARGET, 'g')})  {status}  |écart final| {format_spec(diff, '.1e')}"
    )
    return ratio


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="nombre d'essais (on garde le meilleur)")
    parser.add_argument("--steps", type=int, default=3000, help="nombre de pas")
    args = parser.parse_args()
    C, R = np.eye(4)[:2], 25.0 * np.eye(2)
    densities = (0.05, 20.0, 2.0)
    models = [kc.LinearGaussianModel(*kc.constant_velocity(1.0, q, dim=2)[:1], C,
                                     kc.constant_velocity(1.0, q, dim=2).Q, R) for q in densities]
    sim = kc.simulate(models[1], np.array([0.0, 0.0, 60.0, 10.0]), args.steps, rng=1)
    two = np.array([[0.97, 0.03], [0.10, 0.90]])
    three = np.array([[0.95, 0.03, 0.02], [0.10, 0.85, 0.05], [0.05, 0.05, 0.90]])
    bench("IMM à 2 régimes (n=4, m=2)", models[:2], sim.y, two, args.repeat)
    bench("IMM à 3 régimes (n=4, m=2)", models, sim.y, three, args.repeat)


if __name__ == "__main__":
    main()
