"""Temps par pas de kalman_filter comparé à la boucle predict()/update() de filterpy (même données).

Usage : .venv/bin/python benchmarks/kf_vs_filterpy.py [--repeat 3]
Cible (issue « Foundation ») : au plus 0,8 × le temps de filterpy sur les deux modèles.
Imprime µs/pas (meilleur de --repeat essais) et le rapport, pour la forme par défaut (racine carrée de P)
et pour la forme du cours (``form="textbook"``) ; vérifie au passage que les filtres donnent les mêmes
estimations. Le temps est le temps CPU du processus (``time.process_time``) : sur une machine partagée,
il dépend beaucoup moins des autres processus que le temps écoulé.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from filterpy.kalman import KalmanFilter

import kalman_course as kc
from kalman_course.numbers import format_spec
from _timing import best_time

TARGET = 0.8


def run_filterpy(model, y, x0, P0):
    n, m = model.n_state, model.n_obs
    f = KalmanFilter(dim_x=n, dim_z=m)
    f.F, f.H, f.Q, f.R = (np.array(a) for a in (model.A, model.C, model.Q, model.R))
    f.x = np.asarray(x0, float).reshape(n, 1)
    f.P = np.asarray(P0, float).reshape(n, n)
    zs = [row.reshape(m, 1) for row in y.reshape(len(y), m)]
    for z in zs:
        f.predict()
        f.update(z)
    return f.x.ravel(), f.P


def bench(label, model, y, x0, P0, repeat):
    T = len(y)
    t_fp, (x_fp, P_fp) = best_time(lambda: run_filterpy(model, y, x0, P0), repeat, time.process_time)
    for form in ("square_root", "textbook"):
        t_ours, res = best_time(lambda: kc.kalman_filter(model, y, x0, P0, form=form), repeat, time.process_time)
        diff = max(np.abs(res.x[-1] - x_fp).max(), np.abs(res.P[-1] - P_fp).max())
        ratio = t_ours / t_fp
        status = "OK" if ratio <= TARGET else "AU-DESSUS DE LA CIBLE"
        us_ours, us_fp = format_spec(t_ours / T * 1e6, ".2f"), format_spec(t_fp / T * 1e6, ".2f")
        print(
            f"{label:30s} {form:11s} {format_spec(T, 'd'):>7s} pas  kalman_course {us_ours:>6s} µs/pas  "
            f"filterpy {us_fp:>6s} µs/pas  rapport {format_spec(ratio, '.2f'):>4s} "
            f"(cible ≤ {format_spec(TARGET, 'g')})  {status}  |écart final| {format_spec(diff, '.1e')}"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="nombre d'essais (on garde le meilleur)")
    args = parser.parse_args()
    # 1-D : tension constante, 100 000 pas
    model1 = kc.scenarios.constant_voltage_model()
    y1 = kc.scenarios.constant_voltage_measurements(100_000, rng=1)
    bench("tension constante (n=1, m=1)", model1, y1, [0.0], [[1.0]], args.repeat)
    # 4 états (vitesse constante 2-D), 2 mesures de position, 20 000 pas
    dt = 0.1
    A = np.array([[1, 0, dt, 0], [0, 1, 0, dt], [0, 0, 1, 0], [0, 0, 0, 1.0]])
    G = np.array([[dt**2 / 2, 0], [0, dt**2 / 2], [dt, 0], [0, dt]])
    model4 = kc.LinearGaussianModel(A, np.eye(2, 4), G @ G.T * 0.25, 0.01 * np.eye(2))
    sim = kc.simulate(model4, np.array([0.0, 0.0, 1.0, 0.5]), 20_000, rng=2)
    bench("vitesse constante (n=4, m=2)", model4, sim.y, np.zeros(4), np.eye(4), args.repeat)


if __name__ == "__main__":
    main()
