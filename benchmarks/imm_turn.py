"""Coût par pas de l'IMM vitesse constante / virage coordonné (régimes EKF, état [p, v, ω]) comparé à l'IMM
calme/agité (deux filtres de Kalman, état [p, v]), sur les mêmes mesures.

Usage : .venv/bin/python benchmarks/imm_turn.py [--repeat 3]
Deux cas : la cible simulée du chapitre « Cibles qui manœuvrent » (pas fixe de 1 s, positions) et
l'hélicoptère SAMU 31 (pas irréguliers lus dans la commande u = [Δt], positions et vitesses, mesures
partielles). Imprime µs/pas (temps CPU, meilleur de --repeat essais) et le rapport CV/CT ÷ CV/CV. Pas de
cible : le surcoût est celui de l'EKF (transition et jacobienne évaluées à chaque pas, en Python) ; il
dit ce que coûte une page qui relance l'IMM CV/CT.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import kalman_course as kc
from kalman_course.numbers import format_spec
from kalman_course.scenarios import helicopter as heli
from kalman_course.scenarios import manoeuvre as man
from _timing import best_time


def report(label: str, T: int, t_cvcv: float, t_cvct: float) -> None:
    print(f"{label:34s} {format_spec(T, 'd'):>5s} pas  IMM CV/CV {format_spec(t_cvcv / T * 1e6, '.0f'):>5s} µs/pas  "
          f"IMM CV/CT {format_spec(t_cvct / T * 1e6, '.0f'):>5s} µs/pas  rapport {format_spec(t_cvct / t_cvcv, '.2f')}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="nombre d'essais (on garde le meilleur)")
    args = parser.parse_args()
    clock = time.process_time

    _, y = man.simulate_target(np.random.default_rng(man.SEED))
    quiet, agitated = man.cv_model(man.Q_QUIET), man.cv_model(man.Q_MANOEUVRE)
    Pi = man.imm_transition(man.SWITCH)
    t_cvcv, _ = best_time(lambda: kc.imm_filter([quiet, agitated], y, man.X0, man.P0, transition=Pi), args.repeat,
                          clock)
    t_cvct, _ = best_time(lambda: man.run_cv_ct(y), args.repeat, clock)
    report("cible simulée (pas fixe)", len(y), t_cvcv, t_cvct)

    track = heli.helicopter_track("both")
    _, sp, sv = heli.fitted_parameters("both")
    R = np.diag([sp**2] * 2 + [sv**2] * 2)
    linear = [heli.helicopter_model(track, q, sp, sv) for q in (0.1, 30.0)]
    modes = man.cv_ct_modes(None, 0.1, man.HELI_TURN_ACCEL_PSD, man.TURN_RATE_PSD, R, C=np.eye(5)[:4])
    x0, P0 = man.turn_state_prior(track.x0, track.P0)
    u = np.asarray(track.dt)[:, None]
    t_cvcv, _ = best_time(lambda: kc.imm_filter(linear, track.y, track.x0, track.P0, transition=Pi), args.repeat,
                          clock)
    t_cvct, _ = best_time(lambda: kc.imm_filter(modes, track.y, x0, P0, u, transition=Pi), args.repeat, clock)
    report("hélicoptère (pas variable)", len(track.y), t_cvcv, t_cvct)


if __name__ == "__main__":
    main()
