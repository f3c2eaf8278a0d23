"""Figures du chapitre « Filtrer en parallèle dans le temps »."""

from __future__ import annotations

import numpy as np

from ..numbers import format_number
from ..scenarios import parallel
from ._registry import new_figure, register

CHAPTER = "filtrage-parallele"


@register("parallele-temps", chapter=CHAPTER,
          title="Temps mesurés (filtre et lisseur, séquentiels et parallèles) et profondeur du calcul selon T")
def parallel_timings():
    m = parallel.measured_timings()
    counts = parallel.operation_counts(np.logspace(1, 6, 11).astype(int))
    fig, (ax0, ax1) = new_figure(1, 2, width=11.0, height=4.2)
    ax0.loglog(m.T, m.sequential, "o-", color="tab:red", label="kalman_filter (séquentiel)")
    ax0.loglog(m.T, m.parallel, "s-", color="tab:blue", label="parallel_kalman_filter")
    ax0.loglog(m.T, m.sequential_smoother, "o--", color="tab:red", alpha=0.6,
               label="kalman_filter + rts_smoother")
    ax0.loglog(m.T, m.parallel_smoother, "s--", color="tab:blue", alpha=0.6, label="parallel_rts_smoother")
    for T, s in zip(m.T[-1:], m.speedup[-1:]):
        ax0.annotate(f"× {format_number(s, decimals=1)}", (T, m.parallel[-1]), textcoords="offset points",
                     xytext=(-10, 12), fontsize=9, color="tab:blue", ha="right")
    ax0.set_xlabel("longueur de la série T (pas)")
    ax0.set_ylabel("temps (s)")
    ax0.set_title(f"Temps mesurés (4 états, 2 mesures) — {m.date}", fontsize=10)
    ax0.grid(alpha=0.3, which="both")
    ax0.legend(fontsize=7, loc="upper left")
    ax1.loglog(counts.T, counts.sequential_depth, "o-", color="tab:red", label="séquentiel : T pas dépendants")
    ax1.loglog(counts.T, counts.parallel_depth, "s-", color="tab:blue", label="balayage : passes (≈ 2 log₂ T)")
    ax1.loglog(counts.T, counts.parallel_work, "s:", color="tab:blue", alpha=0.7,
               label="balayage : combinaisons en tout (≈ 2T)")
    ax1.set_xlabel("longueur de la série T (pas)")
    ax1.set_ylabel("nombre d'opérations (sans unité)")
    ax1.set_title("Profondeur et travail (comptés, exacts)", fontsize=10)
    ax1.grid(alpha=0.3, which="both")
    ax1.legend(fontsize=7, loc="upper left")
    return fig
