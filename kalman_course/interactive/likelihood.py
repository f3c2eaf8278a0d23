r"""Curseurs du chapitre « Apprendre Q et R » : la vraisemblance du Nil au curseur.

Pour :math:`R = \sigma^2_\varepsilon` et :math:`Q = \sigma^2_\eta` choisis, le logarithme de la vraisemblance
(initialisation diffuse exacte, :func:`~kalman_course.log_likelihood`) le long de :math:`Q` à :math:`R` fixé, avec le
maximum de vraisemblance (:func:`~kalman_course.scenarios.nile.nile_fit`), et les innovations
normalisées du filtre, qui doivent ressembler à un bruit :math:`\mathcal N(0, 1)` au bon réglage. Position
par défaut : les variances publiées par Durbin & Koopman, celles du chapitre.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..datasets.nile import nile
from ..diagnostics.consistency import whitened_innovations
from ..likelihood import log_likelihood
from ..scenarios.nile import local_level_model, nile_fit, nile_run
from .figure import SliderSpec, number, register_sliders
from .smoothing import UNIT, nile_axes
from .spec import Follow, Glyph, Panel

__all__ = ["PROFILE_Q", "likelihood_axes", "likelihood_run", "likelihood_spec"]

CHAPTER = "vraisemblance"

#: Valeurs de :math:`Q` du profil de vraisemblance ((10⁸ m³)²).
PROFILE_Q = np.logspace(0.0, 5.5, 45)


@lru_cache(maxsize=None)
def _profile(R: float) -> np.ndarray:
    """:math:`\\log L(R, Q)` pour chaque :math:`Q` de :data:`PROFILE_Q` (initialisation diffuse exacte, Nil complet)."""
    y = nile(False).flow
    return np.array([log_likelihood(local_level_model(R, q), y) for q in PROFILE_Q])


def likelihood_axes():
    """Les axes des curseurs du Nil (:func:`~.smoothing.nile_axes`)."""
    return nile_axes()


def likelihood_run(R: float, Q: float) -> dict[str, np.ndarray]:
    """Profil de :math:`\\log L` le long de :math:`Q`, valeur au point choisi, innovations normalisées."""
    run = nile_run(R, Q, missing=False)
    f = run.filtered
    normalised = np.full(len(f.x), np.nan)  # les pas diffus : pas d'innovation informative
    normalised[f.n_diffuse:] = whitened_innovations(f.after_diffuse())[:, 0]
    return {
        "profile": _profile(float(R)),
        "Q_now": np.array([Q]),
        "ll_now": np.array([log_likelihood(local_level_model(R, Q), nile(False).flow)]),
        "normalised": normalised,
    }


def _readout(series, values) -> str:
    fit = nile_fit(False)
    R_hat, Q_hat = np.exp(fit.theta)
    v = series["normalised"][np.isfinite(series["normalised"])]
    return (f"log L(R, Q) = {number(series['ll_now'][0], significant=5)} ; maximum "
            f"{number(fit.log_likelihood, significant=5)} en R̂ = {number(R_hat, UNIT, significant=5)}, "
            f"Q̂ = {number(Q_hat, UNIT, significant=5)}. Innovations normalisées : écart-type {number(v.std())}, "
            f"{number(100 * np.mean(np.abs(v) > 2), '%')} hors de ±2.")


@register_sliders("vraisemblance-nil", chapter=CHAPTER)
def likelihood_spec() -> SliderSpec:
    """La vraisemblance et les innovations du Nil."""
    fit = nile_fit(False)
    R_hat, Q_hat = np.exp(fit.theta)
    years = nile(False).year.astype(float)
    return SliderSpec(
        name="vraisemblance-nil",
        chapter=CHAPTER,
        title="Le Nil (1871–1970), niveau local : la vraisemblance de (R, Q) et les innovations",
        x_label="année",
        axes=likelihood_axes(),
        run=likelihood_run,
        time=years,
        panels=(
            Panel(
                "Profil de log L le long de Q, pour le R choisi",
                "log L (sans unité)",
                (
                    Glyph("profile", "line", "royalblue", "log L(R, Q) à R fixé", x="profile_q"),
                    Glyph("ll_now", "scatter", "crimson", "(R, Q) choisi", x="Q_now", marker="circle", size=11),
                    Glyph("ll_hat", "scatter", "black", "maximum de vraisemblance", x="Q_hat", marker="star",
                          size=15),
                ),
                x_label="Q = σ²η ((10⁸ m³ par an)²)",
                x_range=(float(PROFILE_Q[0]), float(PROFILE_Q[-1])),
                x_log=True,
                # l'axe montre toujours le point choisi et le maximum (40 nats sous le maximum au moins)
                y_range=Follow(columns=("ll_now", "ll_hat"),
                               include=(float(fit.log_likelihood) - 40.0, float(fit.log_likelihood) + 3.0)),
                height=240,
            ),
            Panel(
                "Innovations normalisées du filtre (initialisation diffuse exacte)",
                "ν / √S (sans unité)",
                (
                    Glyph("", "hline", "gray", "± 2", value=2.0, dash="dashed", width=1.0),
                    Glyph("", "hline", "gray", "", value=-2.0, dash="dashed", width=1.0),
                    Glyph("normalised", "line", "darkorange", "innovation normalisée", width=1.2),
                ),
                y_range=Follow(columns=("normalised",), include=(-3.0, 3.0)),  # ± 2 toujours visibles
                height=200,
            ),
        ),
        fixed={"profile_q": PROFILE_Q, "Q_hat": np.array([Q_hat]), "ll_hat": np.array([fit.log_likelihood])},
        readout=_readout,
    )
