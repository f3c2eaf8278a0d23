"""Mesure commune aux bancs : le meilleur de plusieurs essais (le moins perturbé par la machine)."""

from __future__ import annotations

import time
from typing import Any, Callable


def best_time(func: Callable[[], Any], repeat: int) -> tuple[float, Any]:
    """Appelle ``func`` ``repeat`` fois ; rend le meilleur temps écoulé (s) et le résultat du dernier appel."""
    best, out = float("inf"), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = func()
        best = min(best, time.perf_counter() - t0)
    return best, out
