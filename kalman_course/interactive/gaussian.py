r"""Curseurs du chapitre « Un seul filtre gaussien » : la banane par chaque règle d'intégration.

Deux curseurs : l'incertitude d'azimut :math:`\sigma_\theta` et l'ordre :math:`p` de Gauss–Hermite. Les
ellipses à 2σ de la vérité (forme close), de la linéarisation (EKF), de la règle *unscented* (UKF), de la
règle de cubature (CKF) et de Gauss–Hermite d'ordre :math:`p` (GHKF), calculées par les règles du filtre
gaussien (:func:`~kalman_course.scenarios.gaussian_rules.banana_rules`), et le nuage de tirages de la loi
choisie (il suit :math:`\sigma_\theta`). Position par défaut : :math:`\sigma_\theta = 20°`, :math:`p = 3`, la
figure ``gaussien-banane`` du chapitre.
"""

from __future__ import annotations

import numpy as np

from ..scenarios import banana, gaussian_rules
from .figure import SliderSpec, ellipse_outline, number, register_sliders
from .grid import ParameterAxis
from .spec import Follow, Glyph, Panel

__all__ = ["N_POINTS", "ORDERS", "BEARING_STDS_DEG", "rules_axes", "rules_run", "rules_spec"]

CHAPTER = "filtre-gaussien"
#: Points de chaque contour d'ellipse.
N_POINTS = 73
#: Ordres de Gauss–Hermite proposés.
ORDERS = (2, 3, 4, 5, 8)
#: Écarts-types d'azimut proposés (°).
BEARING_STDS_DEG = (5.0, 10.0, 20.0, 30.0, 45.0, 60.0)
_KEYS = (("vérité", "truth"), ("linéarisation (EKF)", "lin"), ("unscented (UKF)", "ut"), ("cubature (CKF)", "ckf"))
#: Tirages du nuage de chaque position (même graine à toutes les positions : le nuage s'étire avec σθ).
N_CLOUD = 300


def rules_axes() -> tuple[ParameterAxis, ParameterAxis]:
    r""":math:`\sigma_\theta` (°, défaut 20°) et l'ordre :math:`p` de Gauss–Hermite (défaut 3)."""
    return (
        ParameterAxis("bearing_std", "σθ", "incertitude d'azimut", "°", np.array(BEARING_STDS_DEG),
                      default=BEARING_STDS_DEG.index(20.0)),
        ParameterAxis("order", "p", "ordre de Gauss–Hermite", "", np.array(ORDERS, dtype=float),
                      default=ORDERS.index(3), scale="index", tick_labels=tuple(str(p) for p in ORDERS)),
    )


def rules_run(bearing_deg: float, order: float) -> dict[str, np.ndarray]:
    r"""Contours à 2σ (x, y en m) et moyennes (répétées) de chaque règle, et erreurs de la moyenne (m)."""
    p = int(round(order))
    moments = gaussian_rules.banana_rules(banana.BANANA_RANGE_STD, float(np.deg2rad(bearing_deg)), p)
    gh = moments[f"Gauss–Hermite, p = {p} (GHKF)"]
    out: dict[str, np.ndarray] = {}
    truth = moments["vérité"].mean
    for (name, key), mom in zip(_KEYS + (("gh", "gh"),), [moments[k] for k, _ in _KEYS] + [gh]):
        x, y = ellipse_outline(mom.mean, mom.cov, 2.0, N_POINTS)
        out[f"{key}_x"], out[f"{key}_y"] = x, y
        out[f"{key}_mx"], out[f"{key}_my"] = np.full(N_POINTS, mom.mean[0]), np.full(N_POINTS, mom.mean[1])
        out[f"{key}_err"] = np.full(N_POINTS, np.linalg.norm(mom.mean - truth))
    cloud = banana.banana_sample(N_CLOUD, banana.BANANA_RANGE_STD, float(np.deg2rad(bearing_deg)))
    out["cloud_x"], out["cloud_y"] = cloud[:, 0], cloud[:, 1]
    return out


def _readout(series, values) -> str:
    p = int(round(values[1]))
    return (f"Distance de la moyenne à la vraie moyenne : linéarisation {number(1000 * series['lin_err'][0], 'mm')}, "
            f"unscented {number(1000 * series['ut_err'][0], 'mm')}, cubature {number(1000 * series['ckf_err'][0], 'mm')}, "
            f"Gauss–Hermite ({p}² = {p * p} points) {number(1000 * series['gh_err'][0], 'mm')}.")


def _glyphs(key: str, color: str, legend: str) -> tuple[Glyph, ...]:
    return (Glyph(f"{key}_y", "line", color, legend, x=f"{key}_x", dash="dashed" if key == "truth" else "solid"),
            Glyph(f"{key}_my", "scatter", color, "", x=f"{key}_mx", marker="circle", size=7))


@register_sliders("gaussien-banane-regles", chapter=CHAPTER)
def rules_spec() -> SliderSpec:
    """La banane par la linéarisation, la règle unscented, la cubature et Gauss–Hermite d'ordre p, contre la
    vérité et un nuage de tirages de la même loi."""
    # le nuage ne fixe pas le cadre (clip) : à 60°, il fait presque tout le cercle, le cadre suit les ellipses
    cloud = (Glyph("cloud_y", "scatter", "gray", "tirages", x="cloud_x", marker="circle", size=3,
                   alpha=0.5, clip=True),)
    return SliderSpec(
        name="gaussien-banane-regles",
        chapter=CHAPTER,
        title="La banane (r = 1 m, θ = 90°) par quatre règles : incertitude d'azimut et ordre de Gauss–Hermite",
        x_label="x (m)",
        axes=rules_axes(),
        run=rules_run,
        time=np.arange(N_POINTS, dtype=float),
        panels=(
            Panel("Ellipses à 2σ et moyennes", "y (m)",
                  cloud + _glyphs("truth", "black", "vérité") + _glyphs("lin", "firebrick", "linéarisation")
                  + _glyphs("ut", "darkorange", "unscented") + _glyphs("ckf", "seagreen", "cubature")
                  + _glyphs("gh", "purple", "Gauss–Hermite"),
                  x_label="x (m)", x_range=(-1.15, 1.15), y_range=Follow(aspect=2.3 / 1.5, margin=0.06), equal_aspect=True,
                  height=380),  # à 60°, les ellipses débordent du cadre de 20°
        ),
        readout=_readout,
    )
