"""Coût par pas des sept filtres du chapitre « Quel filtre choisir ? » sur la cible lointaine (un tirage).

Usage : .venv/bin/python benchmarks/filter_choice.py [--repeat 3] [--write]
Imprime, pour chaque filtre, le meilleur temps CPU par pas (µs) de --repeat essais et le rapport à l'EKF.
--write réécrit kalman_course/scenarios/filter_choice_timings.py (la mesure datée que cite le tableau du
chapitre : le livre se construit sans rien chronométrer).
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import time
from pathlib import Path

import numpy as np

import kalman_course as kc
from kalman_course.numbers import format_spec
from kalman_course.scenarios import filter_choice as fc
from kalman_course.scenarios.distant_target import TARGET_START, TARGET_UKF, distant_target_model

OUTPUT = Path(__file__).resolve().parent.parent / "kalman_course" / "scenarios" / "filter_choice_timings.py"
STEPS = 200


def _machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return f"{cpu}, {os.cpu_count()} cœurs, {platform.system()} {platform.machine()}"


def best_cpu_time(func, repeat: int) -> float:
    """Meilleur temps CPU du processus (s) de ``repeat`` appels (la machine est partagée : le temps CPU
    varie moins que le temps écoulé)."""
    best = float("inf")
    for _ in range(repeat):
        t0 = time.process_time()
        func()
        best = min(best, time.process_time() - t0)
    return best


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
    us = {name: best_cpu_time(func, args.repeat) / STEPS * 1e6 for name, func in filters.items()}
    print(f"Machine : {_machine()} ; Python {platform.python_version()}, numpy {np.__version__} ; {STEPS} pas")
    for name, value in us.items():
        print(f"{name:22s} {format_spec(value, '.1f'):>9s} µs/pas   {format_spec(value / us['EKF'], '.2f'):>7s} × EKF")
    if args.write:
        OUTPUT.write_text(
            '"""Temps CPU par pas (µs) mesurés par benchmarks/filter_choice.py --write sur la cible lointaine : le\n'
            'tableau du chapitre « Quel filtre choisir ? » les cite ; le livre ne chronomètre rien."""\n\n'
            f"DATE = {datetime.date.today().isoformat()!r}\n"
            f"MACHINE = {_machine()!r}\n"
            f"SOFTWARE = {f'Python {platform.python_version()}, numpy {np.__version__}'!r}\n"
            f"MICROSECONDS_PER_STEP = {{\n" + "".join(f"    {k!r}: {round(v, 1)!r},\n" for k, v in us.items()) + "}\n"
        )
        print(f"Mesure écrite dans {OUTPUT}")


if __name__ == "__main__":
    main()
