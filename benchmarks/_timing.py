"""Mesure commune aux bancs : le meilleur de plusieurs essais (le moins perturbé par la machine)."""

from __future__ import annotations

import time
from typing import Any, Callable


def best_time(func: Callable[[], Any], repeat: int, clock: Callable[[], float] = time.perf_counter) -> tuple[float, Any]:
    """Appelle ``func`` ``repeat`` fois ; rend le meilleur temps (s) et le résultat du dernier appel. ``clock`` :
    temps écoulé par défaut, ``time.process_time`` pour le temps CPU du processus."""
    best, out = float("inf"), None
    for _ in range(repeat):
        t0 = clock()
        out = func()
        best = min(best, clock() - t0)
    return best, out
