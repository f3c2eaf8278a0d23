r"""Curseurs du chapitre « Filtrer en parallèle dans le temps » : quand le balayage paie-t-il ?

Deux curseurs : le nombre :math:`N_p` de processeurs qui combinent des éléments en même temps (:math:`P`
reste la covariance), et le coût :math:`c` d'une combinaison (en pas du filtre séquentiel). Le temps du
balayage est compté exactement, passe par passe : une passe de :math:`w` combinaisons prend
:math:`c\lceil w / N_p\rceil`
(:func:`~kalman_course.filters.parallel.associative_scan`) ; le filtre séquentiel prend :math:`T`. Un
modèle de calcul, pas une mesure : les temps mesurés sont dans la figure ``parallele-temps``. Position par
défaut : :math:`N_p = 1`, :math:`c = 2`.
"""

from __future__ import annotations

import math

import numpy as np

from .figure import SliderSpec, number, register_sliders
from .grid import ParameterAxis
from .spec import Glyph, Panel

__all__ = ["LENGTHS", "PROCESSORS", "COSTS", "pass_sizes", "scan_time", "parallel_axes", "parallel_run",
           "parallel_spec"]

CHAPTER = "filtrage-parallele"
#: Longueurs de série (abscisse).
LENGTHS = np.unique(np.round(np.logspace(1, 6, 41)).astype(int))
#: Nombres de processeurs proposés.
PROCESSORS = (1, 2, 8, 64, 1024, 100_000)
#: Coûts d'une combinaison (en pas du filtre séquentiel).
COSTS = (1.0, 2.0, 4.0, 8.0)


def pass_sizes(T: int) -> list[int]:
    """Nombre de combinaisons de chaque passe du balayage de Blelloch sur ``T`` éléments (dans l'ordre)."""
    if T < 2:
        return []
    inner = pass_sizes(T // 2)
    even = (T - 1) // 2
    return [T // 2] + inner + ([even] if even > 0 else [])


def scan_time(T: int, processors: int, cost: float) -> float:
    r"""Temps du balayage avec ``processors`` processeurs : :math:`c\sum_{\text{passes}}\lceil w/N_p\rceil`."""
    return cost * sum(math.ceil(w / processors) for w in pass_sizes(int(T)))


def parallel_axes() -> tuple[ParameterAxis, ParameterAxis]:
    r""":math:`N_p` (processeurs, défaut 1) et :math:`c` (coût d'une combinaison, défaut 2)."""
    return (
        ParameterAxis("processors", "Nₚ", "processeurs", "", np.array(PROCESSORS, dtype=float), default=0,
                      scale="index", tick_labels=tuple(number(p, significant=6) for p in PROCESSORS)),
        ParameterAxis("cost", "c", "coût d'une combinaison (pas séquentiels)", "", np.array(COSTS), default=1,
                      scale="index", tick_labels=tuple(number(c) for c in COSTS)),
    )


def parallel_run(processors: float, cost: float) -> dict[str, np.ndarray]:
    """Temps (en pas séquentiels) du filtre séquentiel et du balayage pour chaque longueur, et leur rapport."""
    P = int(round(processors))
    par = np.array([scan_time(int(T), P, cost) for T in LENGTHS])
    seq = LENGTHS.astype(float)
    return {"sequential": seq, "parallel": par, "speedup": seq / par}


def _readout(series, values) -> str:
    P, c = int(round(values[0])), values[1]
    s = series["speedup"]
    processors = "un seul processeur" if P == 1 else f"Nₚ = {number(P, significant=6)} processeurs"
    return (f"{processors}, une combinaison coûte {number(c)} pas : accélération (temps séquentiel / "
            f"temps du balayage) {number(s[np.searchsorted(LENGTHS, 1000)])} à T = 1 000 et {number(s[-1])} à "
            "T = 10⁶ (au-dessous de 1, le balayage est plus lent).")


@register_sliders("parallele-processeurs", chapter=CHAPTER)
def parallel_spec() -> SliderSpec:
    """Temps compté du filtre séquentiel et du balayage, selon Nₚ et c."""
    return SliderSpec(
        name="parallele-processeurs",
        chapter=CHAPTER,
        title="Quand le balayage paie-t-il ? Temps compté selon le nombre de processeurs Nₚ et le coût c d'une combinaison",
        x_label="longueur de la série T (pas)",
        axes=parallel_axes(),
        run=parallel_run,
        time=LENGTHS.astype(float),
        panels=(
            Panel("Temps (en pas du filtre séquentiel)", "temps (pas)",
                  (Glyph("sequential", "line", "firebrick", "filtre séquentiel : T"),
                   Glyph("parallel", "line", "royalblue", "balayage : c Σ ⌈w/Nₚ⌉")),
                  y_log=True, x_log=True, x_label="longueur de la série T (pas)", x_range=(10.0, 1e6),
                  y_range=(1.0, 1e8), height=260),
            Panel("Accélération (séquentiel / balayage)", "rapport (sans unité)",
                  (Glyph("speedup", "line", "royalblue", "accélération"),
                   Glyph("speedup", "hline", "black", "1 : aucun gain", value=1.0, dash="dashed")),
                  y_log=True, x_log=True, x_label="longueur de la série T (pas)", x_range=(10.0, 1e6),
                  y_range=(0.01, 1e5), height=220),
        ),
        readout=_readout,
    )
