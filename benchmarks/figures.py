"""Régénération des figures : temps de chaque figure, puis de la commande complète.

Cible : ``python -m kalman_course.figures --out DOSSIER`` (toutes les figures, PNG) en moins de 15 s sur
la machine du cours (2 cœurs), en parallèle (``--jobs 0`` : un processus par cœur). Le script imprime
aussi le temps en un seul processus et celui des trois formats (png, svg, pdf), et vérifie que deux
régénérations écrivent les mêmes octets.
Usage : ``python benchmarks/figures.py``.
"""

from __future__ import annotations

import filecmp
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import kalman_course as kc
from kalman_course.numbers import format_spec

TARGET_S = 15.0


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def timed_command(out: Path, *args: str) -> float:
    """Durée (s) de la commande ; imprime aussi son temps CPU (processus fils compris) et la charge de
    la machine : sur une machine partagée et chargée, le temps écoulé n'est pas la mesure du code."""
    cpu = _children_cpu()
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "kalman_course.figures", "--out", str(out), *args],
                   check=True, capture_output=True)
    elapsed = time.perf_counter() - start
    print(f"  {' '.join(args)} : {format_spec(elapsed, '.1f')} s écoulées, "
          f"{format_spec(_children_cpu() - cpu, '.1f')} s CPU, charge moyenne {format_spec(os.getloadavg()[0], '.1f')} "
          f"sur {format_spec(os.cpu_count() or 1, 'd')} cœurs")
    return elapsed


def main() -> None:
    from threadpoolctl import threadpool_limits

    total = 0.0
    with threadpool_limits(limits=1, user_api="blas"):  # comme la commande (BLAS sur un fil)
        for name in kc.figures.names():
            start, cpu = time.perf_counter(), time.process_time()
            kc.figures.draw(name)
            elapsed = time.perf_counter() - start
            total += elapsed
            print(f"{name:32s} {format_spec(elapsed, '.2f'):>6s} s "
                  f"({format_spec(time.process_time() - cpu, '.2f'):>5s} s CPU)")
    n = len(kc.figures.names())
    print(f"{'calcul et tracé (sans écriture)':32s} {format_spec(total, '.2f'):>6s} s")
    cores = os.cpu_count() or 1
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        serial = timed_command(tmp / "serie", "--jobs", "1")
        parallel = timed_command(tmp / "parallele", "--jobs", "0")
        formats = timed_command(tmp / "formats", "--jobs", "0", "--format", "png,svg,pdf")
        same = all(filecmp.cmp(tmp / "serie" / f"{name}.png", tmp / "parallele" / f"{name}.png", shallow=False)
                   for name in kc.figures.names())
    n_text = format_spec(n, "d")
    print(f"commande complète, {n_text} figures PNG, 1 processus : {format_spec(serial, '.1f'):>5s} s")
    print(f"commande complète, {n_text} figures PNG, --jobs 0 ({format_spec(cores, 'd')} cœurs) : "
          f"{format_spec(parallel, '.1f'):>5s} s (cible : < {format_spec(TARGET_S, '.0f')} s, "
          f"rapport {format_spec(parallel / TARGET_S, '.2f')} ; "
          f"accélération ×{format_spec(serial / parallel, '.2f')})")
    print(f"commande complète, {n_text} figures × 3 formats, --jobs 0 : {format_spec(formats, '.1f'):>5s} s")
    print(f"PNG identiques octet pour octet (1 processus contre --jobs 0) : {'oui' if same else 'NON'}")


if __name__ == "__main__":
    main()
