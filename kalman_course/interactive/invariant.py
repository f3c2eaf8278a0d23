r"""Curseurs du chapitre « Filtrage invariant sur les groupes de Lie » : le robot plan, odométrie et GNSS.

Trois curseurs : l'écart-type :math:`\sigma_0` de l'erreur initiale de cap (0° à 90°), la période du GNSS
(0,4 s à 2 s) et le bruit de l'odométrie (0,3 à 3 fois celui du banc d'essai). Deux panneaux : la NEES de
position moyenne et l'erreur quadratique moyenne de position de l'EKF invariant et de l'EKF standard au
cours du temps (:func:`~kalman_course.scenarios.robot_localization.slider_study` : odométrie à 5 Hz,
8 tirages par position, erreurs initiales de cap aux quantiles de la loi normale). Position par défaut :
45°, 1 s, bruit du banc d'essai.
"""

from __future__ import annotations

import numpy as np

from ..scenarios import robot_localization as rl
from .figure import SliderSpec, number, register_sliders
from .grid import ParameterAxis
from .spec import Follow, Glyph, Panel

__all__ = ["NEES_CAP", "invariant_axes", "invariant_run", "invariant_spec"]

CHAPTER = "filtrage-invariant"
#: NEES tracée au plus (l'échelle reste lisible au tout début, quand la covariance de position est presque nulle).
NEES_CAP = 1e6


def invariant_axes() -> tuple[ParameterAxis, ParameterAxis, ParameterAxis]:
    """σ₀ (°), période du GNSS (s) et bruit de l'odométrie (multiple de celui du banc d'essai)."""
    scales = np.array(rl.SLIDER_ODOMETRY_SCALES)
    labels = tuple(f"× {number(s)} ({number(s * np.degrees(rl.ODOMETRY_STD[2]), '°/s')})" for s in scales)
    return (
        ParameterAxis("heading_std", "σ₀", "erreur initiale de cap (écart-type)", "°",
                      np.array(rl.SLIDER_HEADINGS_DEG), default=rl.SLIDER_HEADINGS_DEG.index(45.0), scale="linear"),
        ParameterAxis("gnss_period", "T_GNSS", "période du GNSS", "s", np.array(rl.SLIDER_GNSS_PERIODS),
                      default=rl.SLIDER_GNSS_PERIODS.index(1.0), scale="index",
                      tick_labels=tuple(number(p, "s") for p in rl.SLIDER_GNSS_PERIODS)),
        ParameterAxis("odometry_scale", "σ_odo", "bruit de l'odométrie (× celui du banc d'essai, σ_ω)", "",
                      scales, default=list(scales).index(1.0), scale="index", tick_labels=labels),
    )


def invariant_run(heading_std: float, gnss_period: float, odometry_scale: float) -> dict[str, np.ndarray]:
    """NEES de position et erreur de position moyennes des deux filtres (courbes et moyennes)."""
    study = rl.slider_study(float(odometry_scale))
    runs = study.runs[(float(heading_std), float(gnss_period))]
    out = {}
    for k in ("inv", "std"):
        out[f"{k}_nees"] = np.clip(runs[f"{k}_nees"], 1e-2, NEES_CAP)
        out[f"{k}_rmse"] = runs[f"{k}_rmse"]
        out[f"{k}_nees_mean"] = runs[f"{k}_nees_mean"]
        out[f"{k}_rmse_mean"] = runs[f"{k}_rmse_mean"]
    return out


def _readout(series, values) -> str:
    h, period, scale = values
    return (f"σ₀ = {number(h)}°, période du GNSS {number(period, 's')}, odométrie × {number(scale)} : "
            f"NEES de position moyenne après 20 s — EKF invariant {number(series['inv_nees_mean'][0])}, "
            f"EKF standard {number(series['std_nees_mean'][0])} ; erreur de position (RMSE) — "
            f"{number(series['inv_rmse_mean'][0], 'm')} et {number(series['std_rmse_mean'][0], 'm')}.")


@register_sliders("invariant-curseurs", chapter=CHAPTER)
def invariant_spec() -> SliderSpec:
    """Les deux filtres sur le robot, selon l'erreur initiale de cap, la période du GNSS et le bruit d'odométrie."""
    t = rl.slider_study(1.0).t
    return SliderSpec(
        name="invariant-curseurs",
        chapter=CHAPTER,
        title=(f"Robot plan, odométrie à 5 Hz et GNSS à 1 m : EKF invariant et EKF standard "
               f"({rl.SLIDER_RUNS} tirages par position)"),
        x_label="temps (s)",
        axes=invariant_axes(),
        run=invariant_run,
        time=t,
        fixed={"one": np.ones_like(t)},
        panels=(
            Panel("NEES de position moyenne (1 : filtre cohérent ; plafonnée à 10⁶)", "NEES (sans unité)",
                  (Glyph("one", "line", "black", "1 : filtre cohérent", width=1.0),
                   Glyph("one", "vline", "gray", "20 s", value=20.0, dash="dotted", width=1.0),
                   Glyph("inv_nees", "line", "royalblue", "EKF invariant"),
                   Glyph("std_nees", "line", "crimson", "EKF standard", dash="dashed")),
                  y_log=True, y_range=(1e-2, 2 * NEES_CAP), height=250),
            Panel("Erreur quadratique moyenne de position", "erreur (m)",
                  (Glyph("inv_rmse", "line", "royalblue", "EKF invariant"),
                   Glyph("std_rmse", "line", "crimson", "EKF standard", dash="dashed")),
                  y_range=Follow(include=(0.0,)), height=230),
        ),
        readout=_readout,
    )
