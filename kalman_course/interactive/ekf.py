r"""Curseurs du chapitre « Le filtre de Kalman étendu » : une loi gaussienne polaire transformée en
coordonnées cartésiennes.

:func:`~kalman_course.scenarios.polar.polar_transform` : nuage de Monte-Carlo, moyenne et covariance
exactes (forme close) et approximation de l'EKF (tangente). Les curseurs changent l'incertitude d'azimut
:math:`\sigma_\theta` et de distance :math:`\sigma_r` ; la position par défaut (20°, 0,5 m) est la figure
de linéarisation du chapitre. En haut, le croissant et l'ellipse de l'EKF ; en bas, la fonction
:math:`x = r\cos\theta` et sa tangente en :math:`\hat\theta = 0`.
"""

from __future__ import annotations

import numpy as np

from ..scenarios.polar import POLAR_BEARING_STD_DEG, POLAR_MEAN, POLAR_RANGE_STD, polar_transform
from .figure import SliderSpec, ellipse_outline, number, register_sliders
from .grid import ParameterAxis
from .spec import Follow, Glyph, Panel

__all__ = ["BEARING_STDS", "RANGE_STDS", "SHOWN", "polar_axes", "ekf_run", "ekf_spec"]

#: Écarts-types d'azimut proposés (degrés) ; 20° est celui du chapitre.
BEARING_STDS = (2.5, 5.0, 10.0, 20.0, 30.0, 45.0, 60.0)
#: Écarts-types de distance proposés (m) ; 0,5 m est celui du chapitre.
RANGE_STDS = (0.125, 0.25, 0.5, 1.0, 2.0)
#: Nombre de tirages affichés (les moments sont calculés sur tous).
SHOWN = 400
#: Azimuts (degrés) du panneau de la tangente.
ANGLES = np.linspace(-180.0, 180.0, 241)  # ±2σθ atteint ±120° à σθ = 60°
# le plan suit les tracés de l'exécution affichée (un croissant de 2 m à 2,5°, de 40 m à 60°), cadre carré
_PLANE = dict(x_label="x (m)", x_range=(-6.0, 13.0), y_range=Follow(aspect=1.0, margin=0.06), equal_aspect=True)


def polar_axes() -> tuple[ParameterAxis, ParameterAxis]:
    r""":math:`\sigma_\theta` (degrés) et :math:`\sigma_r` (m, de 0,125 à 2 m), centrés sur le chapitre."""
    return (
        ParameterAxis("bearing_std_deg", "σθ", "incertitude d'azimut", "°", np.array(BEARING_STDS),
                      default=BEARING_STDS.index(POLAR_BEARING_STD_DEG), scale="linear",
                      tick_labels=tuple(f"{number(b)}°" for b in BEARING_STDS)),
        ParameterAxis("range_std", "σr", "incertitude de distance", "m", np.array(RANGE_STDS),
                      default=RANGE_STDS.index(POLAR_RANGE_STD)),
    )


def _common(tr) -> dict[str, np.ndarray]:
    ex, ey = ellipse_outline(tr.exact_mean, tr.exact_cov)
    kx, ky = ellipse_outline(tr.ekf_mean, tr.ekf_cov)
    return {
        "cloud_x": tr.mapped[:SHOWN, 0], "cloud_y": tr.mapped[:SHOWN, 1],
        "exact_x": ex, "exact_y": ey, "ekf_x": kx, "ekf_y": ky,
        "exact_mean_x": tr.exact_mean[:1], "exact_mean_y": tr.exact_mean[1:],
        "ekf_mean_x": tr.ekf_mean[:1], "ekf_mean_y": tr.ekf_mean[1:],
        "ekf_bias": np.array([tr.ekf_bias]),
        # écarts-types (x, y) : ils dépendent de σr comme de σθ (la moyenne, elle, ne dépend que de σθ)
        "exact_sd": np.sqrt(np.diag(tr.exact_cov)), "ekf_sd": np.sqrt(np.diag(tr.ekf_cov)),
    }


def ekf_run(bearing_std_deg: float, range_std: float) -> dict[str, np.ndarray]:
    """Le plan (nuage, ellipses à 2σ) et la coupe :math:`x = \\hat r\\cos\\theta` avec l'intervalle ±2σθ."""
    tr = polar_transform(range_std, bearing_std_deg)
    out = _common(tr)
    a = 2.0 * bearing_std_deg
    out["band_x"] = np.array([-a, -a, np.nan, a, a])
    out["band_y"] = np.array([-11.0, 11.0, np.nan, -11.0, 11.0])
    out["mean_line"] = np.repeat(tr.exact_mean[0], ANGLES.size)
    return out


def _ekf_readout(series, values) -> str:
    (sx, sy), (kx, ky) = series["exact_sd"], series["ekf_sd"]
    return (f"Biais de la moyenne de l'EKF : {number(series['ekf_bias'][0], 'm')} ; moyenne exacte de x : "
            f"{number(series['exact_mean_x'][0], 'm')}, alors que l'EKF propage f(x̂) = "
            f"{number(series['ekf_mean_x'][0], 'm')}. Écarts-types de x et de y : exacts {number(sx, 'm')} et "
            f"{number(sy, 'm')}, EKF {number(kx, 'm')} et {number(ky, 'm')}.")


def _plane_glyphs() -> tuple[Glyph, ...]:
    return (
        Glyph("cloud_y", "scatter", "gray", f"{SHOWN} tirages transformés f(x)", x="cloud_x", marker="circle",
              size=3, alpha=0.5),
        Glyph("exact_y", "line", "black", "moyenne et covariance exactes (2σ)", x="exact_x", dash="dashed"),
        Glyph("ekf_y", "line", "firebrick", "EKF : f(x̂), J P Jᵀ (2σ)", x="ekf_x"),
        Glyph("exact_mean_y", "scatter", "black", "", x="exact_mean_x", marker="circle", size=8),
        Glyph("ekf_mean_y", "scatter", "firebrick", "", x="ekf_mean_x", marker="circle", size=8),
    )


@register_sliders("ekf-linearisation-curseurs", chapter="ekf")
def ekf_spec() -> SliderSpec:
    """Ce que la linéarisation oublie, au curseur."""
    r_hat = float(POLAR_MEAN[0])
    return SliderSpec(
        name="ekf-linearisation-curseurs",
        chapter="ekf",
        title="Loi gaussienne en polaires (r̂ = 10 m, θ̂ = 0) transformée par f(r, θ) = (r cos θ, r sin θ)",
        x_label="azimut θ (°)",
        axes=polar_axes(),
        run=ekf_run,
        time=ANGLES,
        panels=(
            Panel("Dans le plan : le croissant des tirages et l'ellipse de l'EKF", "y (m)", _plane_glyphs(),
                  **_PLANE),
            Panel(
                "Coupe : x = r̂ cos θ et sa tangente en θ̂ = 0 (celle qu'utilise l'EKF)",
                "x (m)",
                (
                    Glyph("f_x", "line", "black", "x = r̂ cos θ"),
                    Glyph("", "hline", "firebrick", "tangente en θ̂ = 0 : x = r̂", value=r_hat),
                    Glyph("mean_line", "line", "black", "moyenne exacte de x", dash="dashed", width=1.5),
                    Glyph("band_y", "line", "royalblue", "± 2 σθ", x="band_x", dash="dotted"),
                ),
                x_label="azimut θ (°)",
                x_range=(-180.0, 180.0),
                y_range=(-11.0, 11.0),
                height=260,  # légende sur quatre lignes sur un téléphone
            ),
        ),
        fixed={"f_x": r_hat * np.cos(np.deg2rad(ANGLES))},
        readout=_ekf_readout,
    )
