"""Le tableau de DAPPER reproduit : chaque ligne de ``kalman_course.scenarios.assimilation.DAPPER_TABLE``
(expériences jumelles de 1000 cycles, réglages de ``mods/Lorenz96/sakov2008.py`` et ``mods/Lorenz63/sakov2012.py``)
sur plusieurs graines, imprimée à côté du rmse.a publié.

Usage : .venv/bin/python benchmarks/assimilation_table.py [--seeds 8] [--write]

Pour chaque ligne : moyenne et écart-type (entre graines) du rmse.a, la valeur de la graine 0, le chiffre
publié, l'écart, la tolérance 0,005 + 3 σ √(1 + 1/k) (le chiffre publié est un tirage arrondi à 0,01 ; k
graines) et le verdict (``kalman_course.scenarios.assimilation.verdict`` : « reproduit », « non
concluant » quand la dispersion entre graines rend la tolérance plus large que 20 % du chiffre publié, « non
reproduit ») ; un verdict différent de celui qu'annoncent les chapitres (``DapperRow.verdict``) est signalé.

--write réécrit kalman_course/scenarios/assimilation_table.py (la mesure datée que citent les chapitres et
que vérifient les tests : le livre se construit sans relancer ces 100 expériences, ≈ 1 à 2 min de calcul).
Compter ≈ 1 s par expérience Lorenz-96 de 1000 cycles, 0,1 s pour 3D-Var et l'interpolation optimale de
Lorenz-63, ≈ 1,5 s pour un ensemble sur Lorenz-63 (25 pas RK4 par cycle).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from kalman_course.numbers import format_spec
from kalman_course.scenarios.assimilation import DAPPER_TABLE, tolerance, twin_experiment, verdict
from _timing import write_measurement

OUTPUT = Path(__file__).resolve().parent.parent / "kalman_course" / "scenarios" / "assimilation_table.py"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=8, help="nombre de graines par ligne (0, 1, …)")
    parser.add_argument("--write", action="store_true", help="réécrire kalman_course/scenarios/assimilation_table.py")
    args = parser.parse_args()
    k = args.seeds
    means, stds, seed0, seconds = [], [], [], []
    print(f"{'méthode (DAPPER)':46s} {'système':9s} {'publié':>7s} {'reproduit (moyenne ± σ)':>24s} "
          f"{'graine 0':>9s} {'écart':>7s} {'tol.':>6s}  verdict")
    for index, row in enumerate(DAPPER_TABLE):
        t0 = time.process_time()
        values = np.array([twin_experiment(row.system, row.method, rng=s, **row.settings).rmse_a for s in range(k)])
        seconds.append((time.process_time() - t0) / k)
        mean, std = float(values.mean()), float(values.std(ddof=1))
        means.append(round(mean, 5))
        stds.append(round(std, 5))
        seed0.append(float(values[0]))
        tol = tolerance(std, k)
        found = verdict(row.published, mean, std, k)
        print(f"{row.dapper:46s} {row.system:9s} {format_spec(row.published, '.2f'):>7s} "
              f"{format_spec(mean, '.3f'):>12s} ± {format_spec(std, '.3f'):<9s} {format_spec(values[0], '.3f'):>9s} "
              f"{format_spec(mean - row.published, '+.3f'):>7s} {format_spec(tol, '.3f'):>6s}  "
              f"{found}{'' if found == row.verdict else f'  (≠ verdict annoncé : {row.verdict} !)'}"
              f"   [{format_spec(seconds[-1], '.2f')} s CPU par expérience]", flush=True)
    if args.write:
        write_measurement(
            OUTPUT,
            "Le tableau de DAPPER reproduit, mesuré par benchmarks/assimilation_table.py --write : pour chaque ligne de\n"
            "kalman_course.scenarios.assimilation.DAPPER_TABLE (même ordre), rmse.a moyen (MEAN) et écart-type entre\n"
            "graines (STD) sur N_SEEDS graines (0, 1, …) de N_CYCLES cycles, valeur de la graine 0 (SEED0), temps CPU\n"
            "par expérience (SECONDS). Les chapitres citent ces nombres ; les tests relancent la graine 0 de quatre\n"
            "lignes et vérifient qu'elle redonne SEED0.",
            {"N_CYCLES": 1000, "N_SEEDS": k, "MEAN": tuple(means), "STD": tuple(stds), "SEED0": tuple(seed0),
             "SECONDS": tuple(round(s, 3) for s in seconds)},
        )


if __name__ == "__main__":
    main()
