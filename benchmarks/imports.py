"""Temps d'import de ``kalman_course`` en plus de numpy et scipy (cible : moins de 0,3 s).

Chaque mesure est faite dans un processus neuf (médiane de plusieurs essais) : on importe d'abord numpy et
les modules de scipy dont le paquet se sert, puis ``kalman_course``.

    .venv/bin/python benchmarks/imports.py
"""

from __future__ import annotations

import statistics
import subprocess
import sys

from kalman_course.numbers import format_spec  # dans ce processus seulement : la mesure est faite ailleurs

CODE = """
import time
t0 = time.perf_counter()
import numpy, scipy.linalg, scipy.stats
t1 = time.perf_counter()
import kalman_course
t2 = time.perf_counter()
print(t1 - t0, t2 - t1)
"""


def main(repeats: int = 7) -> None:
    base, extra = [], []
    for _ in range(repeats):
        out = subprocess.run([sys.executable, "-c", CODE], capture_output=True, text=True, check=True).stdout.split()
        base.append(float(out[0]))
        extra.append(float(out[1]))
    b, e = statistics.median(base), statistics.median(extra)
    print(f"numpy + scipy (linalg, stats) : {format_spec(b, '.3f')} s (médiane de {format_spec(repeats, 'd')})")
    print(f"import kalman_course en plus  : {format_spec(e, '.3f')} s (cible < {format_spec(0.3, '.1f')} s) — "
          f"{'atteinte' if e < 0.3 else 'MANQUÉE'}")


if __name__ == "__main__":
    main()
