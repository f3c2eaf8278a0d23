"""Mesure commune aux bancs : le meilleur de plusieurs essais (le moins perturbé par la machine), la
description de la machine, et l'écriture d'une mesure datée que le livre cite (``--write``)."""

from __future__ import annotations

import datetime
import os
import platform
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np


def best_time(func: Callable[[], Any], repeat: int, clock: Callable[[], float] = time.perf_counter) -> tuple[float, Any]:
    """Appelle ``func`` ``repeat`` fois ; rend le meilleur temps (s) et le résultat du dernier appel. ``clock`` :
    temps écoulé par défaut, ``time.process_time`` pour le temps CPU du processus (la machine est partagée :
    il varie moins que le temps écoulé)."""
    best, out = float("inf"), None
    for _ in range(repeat):
        t0 = clock()
        out = func()
        best = min(best, clock() - t0)
    return best, out


def machine() -> str:
    """Le processeur, le nombre de cœurs et le système de cette machine."""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return f"{cpu}, {os.cpu_count()} cœurs, {platform.system()} {platform.machine()}"


def software() -> str:
    """Les versions de Python et de numpy."""
    return f"Python {platform.python_version()}, numpy {np.__version__}"


def write_measurement(output: Path, docstring: str, values: dict[str, Any]) -> None:
    """Écrit le module ``output`` : ``docstring``, puis ``DATE``, ``MACHINE``, ``SOFTWARE`` et chaque
    ``NOM = valeur`` de ``values`` (``repr``) — la mesure datée que lit le livre, qui ne chronomètre rien."""
    lines = [f'"""{docstring}"""', "", f"DATE = {datetime.date.today().isoformat()!r}",
             f"MACHINE = {machine()!r}", f"SOFTWARE = {software()!r}"]
    for name, value in values.items():
        if isinstance(value, dict):
            lines.append(f"{name} = {{\n" + "".join(f"    {k!r}: {v!r},\n" for k, v in value.items()) + "}")
        else:
            lines.append(f"{name} = {value!r}")
    output.write_text("\n".join(lines) + "\n")
    print(f"Mesure écrite dans {output}")
