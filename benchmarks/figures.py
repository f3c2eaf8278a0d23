"""Temps de construction de chaque figure du registre, et de la commande complète (trois formats).

Cible : la commande ``python -m kalman_course.figures --out DOSSIER --format png,svg,pdf`` écrit toutes
les figures en bien moins d'une minute. Usage : ``python benchmarks/figures.py``.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time

import kalman_course as kc


def main() -> None:
    total = 0.0
    for name in kc.figures.names():
        start = time.perf_counter()
        kc.figures.draw(name)
        elapsed = time.perf_counter() - start
        total += elapsed
        print(f"{name:32s} {elapsed:6.2f} s")
    print(f"{'calcul et tracé (sans écriture)':32s} {total:6.2f} s")
    with tempfile.TemporaryDirectory() as out:
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "kalman_course.figures", "--out", out, "--format", "png,svg,pdf"],
                       check=True, capture_output=True)
        elapsed = time.perf_counter() - start
    n = len(kc.figures.names())
    print(f"commande complète, {n} figures × 3 formats : {elapsed:.1f} s (cible : < 60 s, rapport {elapsed / 60:.2f})")


if __name__ == "__main__":
    main()
