r"""Curseurs du chapitre « Quel filtre choisir ? » : l'incertitude initiale de la cible lointaine.

Un curseur, :math:`\sigma_0` (10 m à 1 km) : erreur de position et NEES moyennes des sept filtres au fil du
temps (:func:`~kalman_course.scenarios.filter_choice.choice_runs`, les mêmes tirages que le tableau et la
figure du chapitre). Position par défaut : 300 m, la figure ``choix-cible-lointaine``.
"""

from __future__ import annotations

import numpy as np

from ..scenarios import filter_choice as fc
from ..scenarios.distant_target import TARGET_DT, TARGET_STEPS
from ..diagnostics.consistency import chi2_band
from .figure import SliderSpec, number, register_sliders
from .grid import ParameterAxis
from .spec import Glyph, Panel

__all__ = ["COLORS", "choice_axes", "choice_run", "choice_spec"]

CHAPTER = "quel-filtre"
#: Couleur et trait de chaque filtre (ceux de la figure du chapitre).
COLORS = {
    "EKF": ("firebrick", "solid"),
    "EKF itéré": ("purple", "dashed"),
    "UKF": ("royalblue", "solid"),
    "CKF": ("seagreen", "dashdot"),
    "GHKF": ("olive", "dotted"),
    "filtre particulaire": ("gray", "solid"),
    "EnKF": ("darkorange", "dashed"),
}
_NEES_CAP = 1e8


def _key(name: str) -> str:
    return {"EKF": "ekf", "EKF itéré": "iekf", "UKF": "ukf", "CKF": "ckf", "GHKF": "ghkf",
            "filtre particulaire": "pf", "EnKF": "enkf"}[name]


def choice_axes() -> tuple[ParameterAxis]:
    r""":math:`\sigma_0 \in \{10, 100, 300, 1000\}` m (défaut 300 m)."""
    stds = np.array(fc.CHOICE_PRIOR_STDS)
    labels = tuple(number(s / 1e3, "km") if s >= 1e3 else number(s, "m") for s in stds)  # « 1 km », pas « 1 × 10³ m »
    return (ParameterAxis("prior_std", "σ₀", "incertitude initiale de position", "m", stds,
                          default=fc.CHOICE_PRIOR_STDS.index(fc.CHOICE_PRIOR_STD), tick_labels=labels),)


def choice_run(prior_std: float) -> dict[str, np.ndarray]:
    """Erreur de position (m) et NEES moyennes de chaque filtre à chaque pas, et son erreur quadratique moyenne."""
    runs = fc.choice_runs(float(prior_std))
    out = {}
    for name in fc.CHOICE_FILTERS:
        k = _key(name)
        out[f"{k}_err"] = np.maximum(runs.position_error[name], 1e-3)
        out[f"{k}_nees"] = np.clip(runs.nees[name], 1e-2, _NEES_CAP)
        out[f"{k}_rmse"] = np.full(TARGET_STEPS, runs.rmse(name))
    return out


def _readout(series, values) -> str:
    parts = [f"{name} {number(series[f'{_key(name)}_rmse'][0], 'm', 3)}" for name in fc.CHOICE_FILTERS]  # comme le tableau
    return "REQM de position après les dix premiers pas : " + ", ".join(parts) + "."


@register_sliders("choix-incertitude", chapter=CHAPTER)
def choice_spec() -> SliderSpec:
    """Les sept filtres sur la cible lointaine, selon l'incertitude initiale."""
    lo, hi = chi2_band(4, fc.CHOICE_RUNS)
    err = tuple(Glyph(f"{_key(n)}_err", "line", c, n, dash=d) for n, (c, d) in COLORS.items())
    nees = tuple(Glyph(f"{_key(n)}_nees", "line", c, n, dash=d) for n, (c, d) in COLORS.items())
    # la bande que le texte demande de regarder : aussi visible que les autres surfaces du livre
    band = (Glyph("band_lo", "band", "green", "bande verte (95 %)", upper="band_hi"),)
    T = TARGET_STEPS
    return SliderSpec(
        name="choix-incertitude",
        chapter=CHAPTER,
        title="Cible lointaine : sept filtres selon l'incertitude initiale de position σ₀ (30 tirages)",
        x_label="temps (s)",
        axes=choice_axes(),
        run=choice_run,
        time=TARGET_DT * np.arange(1, T + 1),
        fixed={"band_lo": np.full(T, lo), "band_hi": np.full(T, hi)},
        panels=(
            Panel("Erreur de position moyenne", "erreur (m)", err, y_log=True, y_range=(0.5, 3e3), height=260),
            Panel("NEES moyenne (4 attendu ; plafonnée à 10⁸)", "NEES (sans unité)", band + nees, y_log=True,
                  y_range=(1.0, 2 * _NEES_CAP), height=260),
        ),
        readout=_readout,
    )
