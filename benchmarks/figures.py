"""Régénération des figures : temps de chaque figure, puis de la commande complète.

Cible : ``python -m kalman_course.figures --out DOSSIER`` (toutes les figures, PNG) en moins de 15 s sur
la machine du cours (2 cœurs), en parallèle (``--jobs 0`` : un processus par cœur). Le script imprime
aussi, figure par figure, le temps CPU du calcul et du tracé puis celui du rendu PNG (mise en page et
dessin par matplotlib), le plancher de la commande sans aucun calcul (import, puis rendu réparti sur les
cœurs), le temps en un seul processus et celui des trois formats (png, svg, pdf), et vérifie que deux
régénérations écrivent les mêmes octets.
Usage : ``python benchmarks/figures.py``.
"""

from __future__ import annotations

import filecmp
import io
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


def import_time(repeats: int = 3) -> float:
    """Temps (s, le meilleur de ``repeats``) d'import de la commande dans un processus neuf : le processus
    parent le paie seul, avant de créer les processus qui dessinent."""
    code = ("import time; t = time.perf_counter(); import kalman_course.figures.__main__; "
            "print(time.perf_counter() - t)")
    return min(float(subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout)
               for _ in range(repeats))


def main() -> None:
    from threadpoolctl import threadpool_limits

    from kalman_course.figures.__main__ import _SAVE_OPTIONS, _warm_up

    _warm_up()
    total = render = 0.0
    print(f"{'figure':32s} {'calcul et tracé':>17s} {'rendu PNG':>11s}")
    with threadpool_limits(limits=1, user_api="blas"):  # comme la commande (BLAS sur un fil)
        for name in kc.figures.names():
            cpu = time.process_time()
            fig = kc.figures.draw(name)
            built = time.process_time() - cpu
            cpu = time.process_time()
            fig.savefig(io.BytesIO(), format="png", dpi=150, **_SAVE_OPTIONS["png"])  # mise en page et rendu
            drawn = time.process_time() - cpu
            total, render = total + built, render + drawn
            print(f"{name:32s} {format_spec(built, '.2f'):>11s} s CPU {format_spec(drawn, '.2f'):>7s} s CPU")
    n = len(kc.figures.names())
    print(f"{'total':32s} {format_spec(total, '.2f'):>11s} s CPU {format_spec(render, '.2f'):>7s} s CPU")
    cores = os.cpu_count() or 1
    imported = import_time()
    floor = imported + render / cores
    print(f"import du paquet et de matplotlib (processus neuf) : {format_spec(imported, '.2f')} s ; plancher de la "
          f"commande sans aucun calcul, import + rendu / {format_spec(cores, 'd')} cœurs : {format_spec(floor, '.1f')} s")
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
