r"""Curseurs du chapitre « Le filtre particulaire » : nombre de particules :math:`N` et variance de mesure
:math:`R` sur le banc d'essai linéaire (:mod:`kalman_course.scenarios.convergence`).

Sur ce modèle linéaire gaussien, le filtre de Kalman donne la réponse exacte : le lecteur voit l'estimation
du filtre particulaire s'en approcher quand :math:`N` croît, et la taille effective de l'échantillon
s'effondrer quand :math:`R` devient petit (mesures précises : peu de particules sont compatibles).
La trajectoire vraie est la même pour tous les :math:`R` (bruits d'état tirés d'abord, même graine) ; le
bruit des mesures est proportionnel à :math:`\sqrt R`.
"""

from __future__ import annotations

import numpy as np

from dataclasses import dataclass

from ..filters.kalman import kalman_filter
from ..numbers import format_integer
from ..filters.particle import particle_filter
from ..scenarios.convergence import LINEAR_STEPS, linear_benchmark
from .grid import ParameterAxis, ParameterGrid, precompute_grid
from .spec import Follow, Glyph, Panel

__all__ = ["PF_SEED", "particle_axes", "particle_run", "particle_grid", "particle_panels", "particle_readout",
           "particle_sliders"]

#: Graine du filtre particulaire (la même pour toutes les positions des curseurs).
PF_SEED = 1


@dataclass(frozen=True, eq=False)
class _CountAxis(ParameterAxis):
    """Curseur d'un nombre entier (de particules) : affiché « 1 000 » plutôt qu'en puissance de dix."""

    def labels(self) -> list[str]:
        return [format_integer(v) for v in self.values]


def particle_axes() -> tuple[ParameterAxis, ParameterAxis]:
    r""":math:`N \in \{10, 30, 100, 300, 1000, 3000, 10\,000\}` (défaut 1000) et
    :math:`R \in \{0{,}01 ; 0{,}03 ; 0{,}1 ; 0{,}3 ; 1 ; 3\}` m² (défaut 1 m²)."""
    return (
        _CountAxis("n_particles", "N", "nombre de particules", "",
                      np.array([10.0, 30.0, 100.0, 300.0, 1000.0, 3000.0, 10000.0]), default=4),
        ParameterAxis("R", "R", "variance de mesure", "m²", np.array([0.01, 0.03, 0.1, 0.3, 1.0, 3.0]), default=4),
    )


def particle_run(n_particles: float, R: float) -> dict[str, np.ndarray]:
    r"""Une position des curseurs ; séries (T,) : écart ``gap`` :math:`=\hat x^{PF}_k - \hat x^{KF}_k` de la
    position (m), bande :math:`\pm 2\sigma` du filtre de Kalman ``lo``, ``hi`` (m), taille effective relative
    ``ess`` :math:`=\mathrm{ESS}/N`."""
    bench = linear_benchmark(R=R)
    kf = kalman_filter(bench.model, bench.y, bench.x0, bench.P0)
    N = int(round(n_particles))
    pf = particle_filter(bench.nonlinear, bench.y, bench.x0, bench.P0, n_particles=N, rng=PF_SEED)
    s = 2.0 * np.sqrt(kf.P[:, 0, 0])
    return {"gap": pf.x[:, 0] - kf.x[:, 0], "lo": -s, "hi": s, "ess": pf.ess / N}


def particle_grid() -> ParameterGrid:
    r"""Toutes les positions :math:`(N, R)` (séries de :func:`particle_run`)."""
    return precompute_grid(particle_run, *particle_axes(), time=np.arange(1, LINEAR_STEPS + 1, dtype=float))


def particle_panels() -> tuple[Panel, ...]:
    """La figure : écart au filtre de Kalman avec sa bande ±2σ, puis la taille effective de l'échantillon."""
    return (
        Panel(
            "Écart de l'estimation du filtre particulaire à la réponse exacte (filtre de Kalman)",
            "x̂ₖ(PF) − x̂ₖ(KF) (m)",
            (
                Glyph("", "hline", "black", "0 : le filtre de Kalman", value=0.0),
                Glyph("lo", "line", "lightsteelblue", "− 2σ du filtre de Kalman"),
                Glyph("hi", "line", "lightsteelblue", "+ 2σ"),
                Glyph("gap", "line", "darkorange", "filtre particulaire − filtre de Kalman"),
            ),
            height=240,
            # l'axe suit la bande ±2σ du R choisi (elle ne dépend pas de N) : à R = 0,01 m², ±0,2 m,
            # et l'écart de N = 1 000 à N = 10 000 se voit ; l'estimation peut sortir de l'axe (N = 10)
            y_range=Follow(columns=("lo", "hi"), margin=0.3),
        ),
        Panel("Taille effective de l'échantillon après chaque mesure", "ESS / N (sans unité)",
              (Glyph("ess", "line", "darkorange", "ESS / N"),), y_log=True, y_range=(1e-3, 1.0), height=190),
    )


def particle_readout(series, values) -> str:
    """Le texte sous les curseurs : écart maximal au filtre de Kalman, demi-largeur de la bande, ESS."""
    from .figure import number

    N = values[0]
    gap = float(np.max(np.abs(series["gap"])))
    band = float(np.max(series["hi"]))
    ess = float(np.median(series["ess"]))
    return (f"Écart maximal au filtre de Kalman : {number(gap, 'm')} (bande ±2σ : ±{number(band, 'm')}). "
            f"Taille effective médiane après une mesure : ESS/N = {number(ess)}, soit "
            f"{format_integer(round(ess * N))} particules utiles sur {format_integer(N)}.")


def particle_sliders():
    """Figure à curseurs statiques :math:`N` et :math:`R` (Bokeh) : celle du registre,
    ``kc.interactive.sliders("filtre-particulaire-curseurs")``."""
    from .figure import sliders

    return sliders("filtre-particulaire-curseurs")
