r"""Curseurs du chapitre « Le filtre de Kalman d'ensemble (EnKF) » : taille de l'ensemble et perturbation
des observations.

:func:`~kalman_course.scenarios.convergence.ensemble_spread` : sur le banc d'essai linéaire, la variance de
position de l'ensemble analysé, avec ou sans perturbation des observations, contre la variance exacte du
filtre de Kalman. Position par défaut : 200 membres, observations perturbées, la figure du chapitre.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..scenarios.convergence import LINEAR_STEPS, ensemble_spread
from .figure import SliderSpec, number, register_sliders
from .grid import ParameterAxis
from .spec import Follow, Glyph, Panel

__all__ = ["MEMBERS", "ensemble_axes", "ensemble_run", "ensemble_spec"]

CHAPTER = "enkf"

#: Tailles d'ensemble proposées ; 200 est celle de la figure du chapitre.
MEMBERS = (10, 25, 50, 100, 200, 400, 800)


@lru_cache(maxsize=None)
def _spread(n_members: int):
    return ensemble_spread(n_members=n_members)


def ensemble_axes() -> tuple[ParameterAxis, ParameterAxis]:
    """La taille :math:`N` de l'ensemble (200 par défaut) et la perturbation des observations (oui par défaut)."""
    return (
        ParameterAxis("n_members", "N", "taille de l'ensemble", "", np.array(MEMBERS, dtype=float),
                      default=MEMBERS.index(200), tick_labels=tuple(str(n) for n in MEMBERS)),
        ParameterAxis("perturb", "v", "observations perturbées", "", np.array([0.0, 1.0]), default=1,
                      scale="index", tick_labels=("non", "oui")),
    )


def ensemble_run(n_members: float, perturb: float) -> dict[str, np.ndarray]:
    """Variance de position de l'ensemble analysé et du filtre de Kalman à chaque pas (m²)."""
    spread = _spread(int(round(n_members)))
    ens = spread.perturbed if perturb else spread.unperturbed
    return {"ensemble": ens, "kalman": spread.kalman, "ratio": np.array([ens[-10:].mean() / spread.kalman[-10:].mean()]),
            "last_ensemble": np.array([ens[-10:].mean()]), "last_kalman": np.array([spread.kalman[-10:].mean()])}


def _readout(series, values) -> str:
    return (f"Sur les dix derniers pas, variance de position moyenne : {number(series['last_ensemble'][0], 'm²')} "
            f"pour l'ensemble, {number(series['last_kalman'][0], 'm²')} pour le filtre de Kalman "
            f"(rapport {number(series['ratio'][0])}).")


@register_sliders("enkf-ensemble", chapter=CHAPTER)
def ensemble_spec() -> SliderSpec:
    """La variance de l'ensemble contre celle du filtre de Kalman."""
    return SliderSpec(
        name="enkf-ensemble",
        chapter=CHAPTER,
        title="EnKF sur le banc d'essai linéaire : taille de l'ensemble et perturbation des observations",
        x_label="pas de temps k",
        axes=ensemble_axes(),
        run=ensemble_run,
        time=np.arange(1, LINEAR_STEPS + 1, dtype=float),
        panels=(
            Panel(
                "Variance de position après chaque analyse",
                "variance de position (m²)",
                (
                    Glyph("kalman", "line", "black", "filtre de Kalman (exacte)", width=2.5),
                    Glyph("ensemble", "line", "darkorange", "ensemble de l'EnKF"),
                    Glyph("ensemble", "scatter", "darkorange", "", marker="circle", size=4),
                ),
                y_range=Follow(columns=("ensemble", "kalman"), include=(0.0,)),
                height=280,
            ),
        ),
        readout=_readout,
    )
