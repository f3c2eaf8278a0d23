r"""Curseurs du chapitre « Vérifier les hypothèses : tests statistiques » : NEES et NIS d'un filtre mal réglé.

:func:`~kalman_course.scenarios.consistency_scaling.scaled_consistency` : 100 tirages de 100 s du
moteur, filtrés avec :math:`a\,\Phi` et :math:`b\,\Psi`. La NEES et la NIS moyennes des tirages sont
comparées à leurs bandes à 95 % (:func:`~kalman_course.chi2_band`). Position par défaut :
:math:`a = b = 1`, le modèle juste du chapitre ; :math:`b = 1/10` et :math:`a = 10` sont ses deux
filtres mal réglés.
"""

from __future__ import annotations

import numpy as np

from ..diagnostics.consistency import chi2_band
from ..scenarios.engine import CONSISTENCY_MC_RUNS, CONSISTENCY_MC_STEPS, ENGINE_DT
from ..scenarios.consistency_scaling import scaled_consistency
from .figure import SliderSpec, number, register_sliders
from .grid import ParameterAxis
from .spec import Glyph, Panel

__all__ = ["FACTORS", "consistency_axes", "consistency_run", "consistency_spec"]

CHAPTER = "tests-statistiques"

#: Facteurs proposés pour Φ et Ψ.
FACTORS = (0.1, 1.0, 10.0)
#: Dimensions de l'état et de la mesure du moteur (degrés de liberté des deux statistiques).
N_STATE = N_OBS = 2


def consistency_axes() -> tuple[ParameterAxis, ParameterAxis]:
    """Facteurs :math:`a` de :math:`\\Phi` et :math:`b` de :math:`\\Psi` (1 par défaut)."""
    labels = tuple(f"× {number(f)}" for f in FACTORS)
    return (
        ParameterAxis("phi_factor", "a", "Φ du filtre = a Φ vrai", "", np.array(FACTORS), default=1,
                      tick_labels=labels),
        ParameterAxis("psi_factor", "b", "Ψ du filtre = b Ψ vrai", "", np.array(FACTORS), default=1,
                      tick_labels=labels),
    )


def consistency_run(phi_factor: float, psi_factor: float) -> dict[str, np.ndarray]:
    """NEES et NIS moyennes des tirages à chaque instant."""
    runs = scaled_consistency(phi_factor, psi_factor)
    return {"nees": runs.nees.mean(axis=0), "nis": runs.nis.mean(axis=0)}


def _readout(series, values) -> str:
    lo, hi = chi2_band(N_STATE, CONSISTENCY_MC_RUNS)
    nees, nis = series["nees"], series["nis"]
    out_nees = 100 * np.mean((nees < lo) | (nees > hi))
    out_nis = 100 * np.mean((nis < lo) | (nis > hi))
    return (f"Au dernier instant, NEES moyenne {number(nees[-1])} et NIS moyenne {number(nis[-1])} "
            f"(bande à 95 % : [{number(lo)} ; {number(hi)}]). Hors de la bande : {number(out_nees, '%')} des "
            f"instants pour la NEES, {number(out_nis, '%')} pour la NIS (5 % attendus).")


@register_sliders("tests-nees-nis", chapter=CHAPTER)
def consistency_spec() -> SliderSpec:
    """NEES et NIS moyennes contre leurs bandes du khi-deux."""
    lo, hi = chi2_band(N_STATE, CONSISTENCY_MC_RUNS)
    band = (
        Glyph("", "hline", "gray", "bande à 95 %", value=lo, dash="dashed", width=1.0),
        Glyph("", "hline", "gray", "", value=hi, dash="dashed", width=1.0),
        Glyph("", "hline", "black", "espérance 2", value=2.0, dash="dotted", width=1.0),
    )
    return SliderSpec(
        name="tests-nees-nis",
        chapter=CHAPTER,
        title=(f"Moteur, {CONSISTENCY_MC_RUNS} tirages de {CONSISTENCY_MC_STEPS} s : multipliez Φ et Ψ "
               "du filtre"),
        x_label="temps (s)",
        axes=consistency_axes(),
        run=consistency_run,
        time=ENGINE_DT * np.arange(1, CONSISTENCY_MC_STEPS + 1),
        panels=(
            Panel("NEES moyenne : l'erreur vraie contre la covariance Pₙ annoncée", "NEES moyenne (sans unité)",
                  band + (Glyph("nees", "line", "royalblue", "NEES moyenne des tirages"),), y_log=True,
                  y_range=(0.1, 100.0), height=250),
            Panel("NIS moyenne : l'innovation contre sa covariance Sₙ", "NIS moyenne (sans unité)",
                  band + (Glyph("nis", "line", "darkorange", "NIS moyenne des tirages"),), y_log=True,
                  y_range=(0.1, 100.0), height=250),
        ),
        readout=_readout,
    )
