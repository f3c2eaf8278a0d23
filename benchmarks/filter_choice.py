"""Coût par pas des sept filtres du chapitre « Quel filtre choisir ? » sur la cible lointaine (un tirage).

Usage : .venv/bin/python benchmarks/filter_choice.py [--repeat 3] [--write]
Imprime, pour chaque filtre, le meilleur temps CPU par pas (µs) de --repeat essais et le rapport à l'EKF.
--write réécrit kalman_course/scenarios/filter_choice_timings.py (la mesure datée que cite le tableau du
chapitre : le livre se construit sans rien chronométrer).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import kalman_course as kc
from kalman_course.numbers import format_spec
from kalman_course.scenarios import filter_choice as fc
from kalman_course.scenarios.distant_target import TARGET_START, TARGET_UKF, distant_target_model
from _timing import best_time, machine, software, write_measurement

OUTPUT = Path(__file__).resolve().parent.parent / "kalman_course" / "scenarios" / "filter_choice_timings.py"
STEPS = 200


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="nombre d'essais (on garde le meilleur)")
    parser.add_argument("--write", action="store_true", help="réécrire kalman_course/scenarios/filter_choice_timings.py")
    args = parser.parse_args()
    model = distant_target_model()
    rng = np.random.default_rng(0)
    P0 = np.diag([100.0**2, 100.0**2, 9.0, 9.0])
    x = kc.simulate(model, TARGET_START, STEPS, rng=rng)
    y, x0 = np.array(x.y), np.asarray(TARGET_START)
    filters = {
        "EKF": lambda: kc.extended_kalman_filter(model, y, x0, P0),
        "EKF itéré": lambda: kc.iterated_extended_kalman_filter(model, y, x0, P0),
        "UKF": lambda: kc.unscented_kalman_filter(model, y, x0, P0, **TARGET_UKF),
        "CKF": lambda: kc.cubature_kalman_filter(model, y, x0, P0),
        "GHKF": lambda: kc.gauss_hermite_kalman_filter(model, y, x0, P0, order=fc.CHOICE_GH_ORDER),
        "filtre particulaire": lambda: kc.particle_filter(model, y, x0, P0, n_particles=fc.CHOICE_PARTICLES, rng=1),
        "EnKF": lambda: kc.ensemble_kalman_filter(model, y, x0, P0, n_members=fc.CHOICE_MEMBERS, rng=1),
    }
    us = {name: best_time(func, args.repeat, time.process_time)[0] / STEPS * 1e6 for name, func in filters.items()}
    print(f"Machine : {machine()} ; {software()} ; {STEPS} pas")
    for name, value in us.items():
        print(f"{name:22s} {format_spec(value, '.1f'):>9s} µs/pas   {format_spec(value / us['EKF'], '.2f'):>7s} × EKF")
    if args.write:
        write_measurement(OUTPUT, "Temps CPU par pas (µs) mesurés par benchmarks/filter_choice.py --write sur la cible "
                          "lointaine : le\ntableau du chapitre « Quel filtre choisir ? » les cite ; le livre ne chronomètre rien.",
                          {"MICROSECONDS_PER_STEP": {k: round(v, 1) for k, v in us.items()}})


if __name__ == "__main__":
    main()
