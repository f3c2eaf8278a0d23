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

from ..filters.kalman import kalman_filter
from ..filters.particle import particle_filter
from ..scenarios.convergence import LINEAR_STEPS, linear_benchmark
from .grid import ParameterAxis, precompute_grid
from .spec import Glyph, Panel

__all__ = ["PF_SEED", "particle_axes", "particle_run", "particle_sliders"]

#: Graine du filtre particulaire (la même pour toutes les positions des curseurs).
PF_SEED = 1


def particle_axes() -> tuple[ParameterAxis, ParameterAxis]:
    r""":math:`N \in \{10, 30, 100, 300, 1000, 3000, 10\,000\}` (défaut 1000) et
    :math:`R \in \{0{,}01 ; 0{,}03 ; 0{,}1 ; 0{,}3 ; 1 ; 3\}` m² (défaut 1 m²)."""
    return (
        ParameterAxis("n_particles", "N", "nombre de particules", "",
                      np.array([10.0, 30.0, 100.0, 300.0, 1000.0, 3000.0, 10000.0]), default=4),
        ParameterAxis("R", "R", "variance de mesure", "m²", np.array([0.01, 0.03, 0.1, 0.3, 1.0, 3.0]), default=4),
    )


def particle_run(n_particles: float, R: float) -> dict[str, np.ndarray]:
    r"""Une position des curseurs ; séries (T,) : mesures ``y``, estimations ``kf`` et ``pf`` de la
    position (m), bande :math:`\pm 2\sigma` du filtre de Kalman ``kf_lo``, ``kf_hi``, taille effective
    relative ``ess`` :math:`=\mathrm{ESS}/N`."""
    bench = linear_benchmark(R=R)
    kf = kalman_filter(bench.model, bench.y, bench.x0, bench.P0)
    N = int(round(n_particles))
    pf = particle_filter(bench.nonlinear, bench.y, bench.x0, bench.P0, n_particles=N, rng=PF_SEED)
    s = 2.0 * np.sqrt(kf.P[:, 0, 0])
    return {"y": bench.y[:, 0], "kf": kf.x[:, 0], "pf": pf.x[:, 0], "kf_lo": kf.x[:, 0] - s,
            "kf_hi": kf.x[:, 0] + s, "ess": pf.ess / N}


def particle_sliders():
    """Figure à curseurs statiques :math:`N` et :math:`R` (Bokeh)."""
    from .static import StaticSliders

    grid = precompute_grid(particle_run, *particle_axes(), time=np.arange(1, LINEAR_STEPS + 1, dtype=float))
    panels = (
        Panel(
            "Position : filtre particulaire contre filtre de Kalman (exact ici)",
            "position (m)",
            (
                Glyph("truth", "line", "green", "position vraie"),
                Glyph("y", "scatter", "silver", "mesures yₖ"),
                Glyph("kf_lo", "line", "lightsteelblue", "filtre de Kalman ± 2σ"),
                Glyph("kf_hi", "line", "lightsteelblue", "filtre de Kalman ± 2σ"),
                Glyph("kf", "line", "black", "filtre de Kalman"),
                Glyph("pf", "line", "darkorange", "filtre particulaire"),
            ),
            height=280,
        ),
        Panel("Taille effective de l'échantillon après chaque mesure", "ESS / N (sans unité)",
              (Glyph("ess", "line", "darkorange", "ESS / N"),), y_log=True),
    )
    return StaticSliders(
        grid, panels, x_label="pas k", fixed={"truth": linear_benchmark().x_true[:, 0]},
        name="filtre-particulaire-curseurs",
        title="Filtre particulaire : nombre de particules N et variance de mesure R",
    )
