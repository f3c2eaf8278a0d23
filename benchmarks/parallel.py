"""Filtre et lisseur parallèles (balayage associatif) contre kalman_filter et rts_smoother, T = 10³ … 10⁵
(et 10⁶ avec --million).

Usage : .venv/bin/python benchmarks/parallel.py [--repeat 3] [--write] [--million]
Cible : à T = 100 000 et à T = 1 000 000 (4 états, 2 mesures), parallel_kalman_filter au moins 3 × plus
rapide que kalman_filter sur la machine à deux cœurs du projet, mesures complètes ou partielles (une
composante cachée un pas sur trois, une ligne entière un pas sur dix). Imprime, pour chaque T, le meilleur
temps de --repeat essais (temps CPU du processus : la machine est partagée, le temps CPU varie moins que le
temps écoulé ; les calculs sont sur un seul fil), le rapport et l'écart relatif maximal entre les deux
résultats (cible : 10⁻⁸).

--write réécrit kalman_course/scenarios/parallel_timings.py (la mesure datée que lit la figure du
chapitre « Filtrer en parallèle dans le temps » : le livre se construit sans rien chronométrer).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import kalman_course as kc
from kalman_course.numbers import format_spec
from kalman_course.scenarios.parallel import PARALLEL_P0, PARALLEL_X0, parallel_data, parallel_model
from _timing import best_time, machine, software, write_measurement

TARGET = 3.0
LENGTHS = (1_000, 3_000, 10_000, 30_000, 100_000)
OUTPUT = Path(__file__).resolve().parent.parent / "kalman_course" / "scenarios" / "parallel_timings.py"


def _gap(a, b, fields) -> float:
    return max(float(np.nanmax(np.abs(np.asarray(getattr(a, f)) - getattr(b, f)))
                     / np.nanmax(np.abs(getattr(b, f)))) for f in fields)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="nombre d'essais (on garde le meilleur)")
    parser.add_argument("--write", action="store_true", help="réécrire kalman_course/scenarios/parallel_timings.py")
    parser.add_argument("--million", action="store_true", help="mesurer aussi T = 1 000 000 (≈ 2 min de calcul)")
    args = parser.parse_args()
    model, x0, P0 = parallel_model(), PARALLEL_X0, PARALLEL_P0
    rows = []
    print(f"Machine : {machine()} ; {software()}")
    for T in LENGTHS + ((1_000_000,) if args.million else ()):
        for partial in (False, True):
            y = parallel_data(T)
            if partial:  # une composante cachée un pas sur trois, une ligne entière un pas sur dix
                y[::3, 1] = np.nan
                y[5::10] = np.nan
            repeat = args.repeat if T < 100_000 else max(1, args.repeat - 1 - (T >= 1_000_000))
            t_seq, seq = best_time(lambda: kc.kalman_filter(model, y, x0, P0), repeat, time.process_time)
            t_par, par = best_time(lambda: kc.parallel_kalman_filter(model, y, x0, P0), repeat, time.process_time)
            t_seq_s, seq_s = best_time(lambda: kc.rts_smoother(model, seq, x0, P0), repeat, time.process_time)
            t_par_s, par_s = best_time(lambda: kc.parallel_rts_smoother(model, par, x0, P0), repeat, time.process_time)
            gap = _gap(par, seq, ("x", "P", "x_pred", "P_pred", "K", "innovation", "S"))
            gap_s = _gap(par_s, seq_s, ("x", "P", "G"))
            ratio = t_seq / t_par
            ratio_s = (t_seq + t_seq_s) / (t_par + t_par_s)  # filtre puis lisseur
            status = "" if T < 100_000 else ("  OK" if ratio >= TARGET else "  SOUS LA CIBLE")
            print(f"T = {format_spec(T, 'd'):>9s} {'partielles' if partial else 'complètes ':10s}  filtre : séquentiel "
                  f"{format_spec(t_seq, '.3f'):>7s} s, parallèle {format_spec(t_par, '.3f'):>7s} s, rapport "
                  f"{format_spec(ratio, '.2f'):>5s}{status} (cible ≥ {format_spec(TARGET, 'g')} dès T = 100 000) ; "
                  f"filtre et lisseur : rapport {format_spec(ratio_s, '.2f'):>5s} ; écarts relatifs "
                  f"{format_spec(gap, '.1e')}, {format_spec(gap_s, '.1e')}")
            if not partial and T in LENGTHS:
                rows.append((T, t_seq, t_par, t_seq + t_seq_s, t_par + t_par_s))
    if args.write:
        T, seq, par, seq_s, par_s = (list(c) for c in zip(*rows))
        write_measurement(OUTPUT, "Temps CPU mesurés par benchmarks/parallel.py --write (secondes, meilleur de plusieurs "
                          "essais) : la\nfigure du chapitre « Filtrer en parallèle dans le temps » les lit ; le livre ne "
                          "chronomètre rien.",
                          {"T": tuple(T), "SEQUENTIAL": tuple(round(t, 5) for t in seq),
                           "PARALLEL": tuple(round(t, 5) for t in par),
                           "SEQUENTIAL_SMOOTHER": tuple(round(t, 5) for t in seq_s),
                           "PARALLEL_SMOOTHER": tuple(round(t, 5) for t in par_s)})


if __name__ == "__main__":
    main()
