"""Temps du lisseur rts_smoother comparé à KalmanFilter.rts_smoother de filterpy (mêmes sorties du filtre).

Usage : .venv/bin/python benchmarks/smoother_vs_filterpy.py [--repeat 3]
Imprime le temps par pas (meilleur de --repeat essais) de la passe arrière seule, pour les deux
lisseurs, et leur rapport ; vérifie au passage que les estimations lissées sont les mêmes. Le lisseur du
paquet vérifie en plus que le résultat vient bien du filtre de ce modèle (compris dans son temps).
"""

from __future__ import annotations

import argparse

import numpy as np
from filterpy.kalman import KalmanFilter

import kalman_course as kc
from kalman_course.numbers import format_spec
from _timing import best_time


def bench(label, model, y, x0, P0, repeat):
    result = kc.kalman_filter(model, y, x0, P0)
    n, m = model.n_state, model.n_obs
    kf = KalmanFilter(dim_x=n, dim_z=m)
    kf.F, kf.H, kf.Q, kf.R = (np.array(a) for a in (model.A, model.C, model.Q, model.R))
    xs_in, Ps_in = result.x[:, :, None].copy(), np.array(result.P)
    T = len(y)
    t_ours, ours = best_time(lambda: kc.rts_smoother(model, result), repeat)
    t_fp, (xs, Ps, _, _) = best_time(lambda: kf.rts_smoother(xs_in, Ps_in), repeat)
    diff = max(np.abs(ours.x - xs[:, :, 0]).max(), np.abs(ours.P - Ps).max())
    us_ours, us_fp = format_spec(t_ours / T * 1e6, ".2f"), format_spec(t_fp / T * 1e6, ".2f")
    print(f"{label:34s} {format_spec(T, 'd'):>7s} pas  kalman_course {us_ours:>6s} µs/pas  "
          f"filterpy {us_fp:>6s} µs/pas  rapport {format_spec(t_ours / t_fp, '.2f'):>4s}  "
          f"|écart| {format_spec(diff, '.1e')}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="nombre d'essais (on garde le meilleur)")
    args = parser.parse_args()
    model1 = kc.scenarios.constant_voltage_model()
    y1 = kc.scenarios.constant_voltage_measurements(20_000, rng=1)
    bench("tension constante (n=1, m=1)", model1, y1, [0.0], [[1.0]], args.repeat)
    dt = 0.1
    A = np.array([[1, 0, dt, 0], [0, 1, 0, dt], [0, 0, 1, 0], [0, 0, 0, 1.0]])
    G = np.array([[dt**2 / 2, 0], [0, dt**2 / 2], [dt, 0], [0, dt]])
    model4 = kc.LinearGaussianModel(A, np.eye(2, 4), G @ G.T * 0.25 + 1e-6 * np.eye(4), 0.01 * np.eye(2))
    sim = kc.simulate(model4, np.array([0.0, 0.0, 1.0, 0.5]), 20_000, rng=2)
    bench("vitesse constante (n=4, m=2)", model4, sim.y, np.zeros(4), np.eye(4), args.repeat)


if __name__ == "__main__":
    main()
