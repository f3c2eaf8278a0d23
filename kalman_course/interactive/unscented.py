r"""Curseurs du chapitre « Le filtre de Kalman *unscented* (UKF) » : la banane polaire.

Deux figures à curseurs statiques (Bokeh, exécutions précalculées à la construction du livre) :

* :func:`banana_uncertainty_sliders` : incertitude d'azimut :math:`\sigma_\theta` et de distance
  :math:`\sigma_r` — vérité (forme close et nuage de Monte-Carlo), linéarisation (EKF) et transformée sans
  parfum (UKF, :math:`\alpha = 1, \beta = 2, \kappa = 1`) ;
* :func:`banana_parameter_sliders` : paramètres :math:`\alpha` et :math:`\kappa` des points sigma, à
  :math:`\sigma_\theta = 20°` fixé.

La position par défaut des curseurs redonne la figure statique du chapitre (``ukf-banane``). Chaque tracé
est une série de :data:`N_POINTS` points (ellipses à 2σ, nuage ; points sigma et moyennes répétés).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..figures._geometry import ellipse_points
from ..scenarios import banana
from .grid import ParameterAxis, ParameterGrid, format_value, precompute_grid
from .spec import Follow, Glyph, Panel

__all__ = [
    "N_POINTS",
    "banana_series",
    "banana_uncertainty_axes",
    "banana_parameter_axes",
    "banana_uncertainty_grid",
    "banana_parameter_grid",
    "banana_uncertainty_panels",
    "banana_parameter_panels",
    "banana_uncertainty_run",
    "banana_parameter_run",
    "banana_uncertainty_sliders",
    "banana_parameter_sliders",
    "banana_uncertainty_readout",
    "banana_parameter_readout",
]

#: Nombre de points de chaque série (ellipses, nuage).
N_POINTS = 150
#: Dimension de l'état polaire (r, θ).
_N = 2


@dataclass(frozen=True, eq=False)
class _KappaAxis(ParameterAxis):
    r"""Curseur de :math:`\kappa`, qui peut être nul ou négatif : la grille porte :math:`n + \kappa > 0`
    (positif, croissant) et le curseur affiche :math:`\kappa`."""

    n: int = _N

    def labels(self) -> list[str]:
        return [format_value(v - self.n, self.unit) for v in self.values]


def _repeat(points: np.ndarray) -> np.ndarray:
    return np.resize(np.asarray(points, dtype=float), N_POINTS)


def banana_series(range_std: float, bearing_std: float, *, alpha: float = banana.BANANA_ALPHA,
                  beta: float = banana.BANANA_BETA, kappa: float = banana.BANANA_KAPPA,
                  cloud: bool = True) -> dict[str, np.ndarray]:
    r"""Les séries (N_POINTS,) d'une position des curseurs : ellipses à 2σ ``truth_x``, ``truth_y``,
    ``lin_x``…, ``ut_x``…, moyennes ``*_mx``, ``*_my``, images des points sigma ``sig_x``, ``sig_y`` et,
    si ``cloud``, le nuage de Monte-Carlo ``cloud_x``, ``cloud_y`` (m)."""
    comp = banana.banana_comparison(range_std, bearing_std, alpha=alpha, beta=beta, kappa=kappa)
    out: dict[str, np.ndarray] = {}
    for key, mom in (("truth", comp.truth), ("lin", comp.linearized), ("ut", comp.unscented)):
        pts = ellipse_points(mom.mean, mom.cov, 2.0, N_POINTS)
        out[f"{key}_x"], out[f"{key}_y"] = pts[:, 0], pts[:, 1]
        out[f"{key}_mx"], out[f"{key}_my"] = np.full(N_POINTS, mom.mean[0]), np.full(N_POINTS, mom.mean[1])
    out["sig_x"], out["sig_y"] = _repeat(comp.sigma_images[:, 0]), _repeat(comp.sigma_images[:, 1])
    if cloud:
        sample = banana.banana_sample(N_POINTS, range_std, bearing_std)
        out["cloud_x"], out["cloud_y"] = sample[:, 0], sample[:, 1]
    return out


def _panel(title: str, method: str, aspect: float) -> Panel:
    """Un panneau : nuage et vérité (ellipse à 2σ, moyenne), puis la méthode ``"lin"`` (EKF) ou ``"ut"``
    (UKF, avec les images des points sigma). Légendes courtes : elles tiennent sur une ligne."""
    name, color = ("EKF", "firebrick") if method == "lin" else ("UKF", "royalblue")
    glyphs = [
        Glyph("cloud_y", "scatter", "silver", "tirages", x="cloud_x"),
        Glyph("truth_y", "line", "black", "vraie", x="truth_x"),
        Glyph("truth_my", "scatter", "black", "moy. vraie", x="truth_mx"),
        Glyph(f"{method}_y", "line", color, name, x=f"{method}_x"),
        Glyph(f"{method}_my", "scatter", color, f"moy. {name}", x=f"{method}_mx"),
    ]
    if method == "ut":
        glyphs.append(Glyph("sig_y", "scatter", "navy", "points σ", x="sig_x"))
    # le cadre suit la banane affichée (2,5° : quelques centimètres ; 40° : tout l'arc), rapport fixe
    return Panel(title, "y (m)", tuple(glyphs), x_label="x (m)", x_range=(-1.1, 1.1),
                 y_range=Follow(aspect=aspect, margin=0.06), equal_aspect=True)


def banana_uncertainty_axes() -> tuple[ParameterAxis, ParameterAxis]:
    r""":math:`\sigma_\theta \in \{2{,}5 ; 5 ; 10 ; 15 ; 20 ; 30 ; 40\}` (°, défaut 20°) et
    :math:`\sigma_r \in \{0{,}005 ; 0{,}01 ; 0{,}02 ; 0{,}05 ; 0{,}1\}` (m, défaut 0,02 m)."""
    return (
        ParameterAxis("bearing_std", "σθ", "incertitude d'azimut", "°",
                      np.array([2.5, 5.0, 10.0, 15.0, 20.0, 30.0, 40.0]), default=4),
        ParameterAxis("range_std", "σᵣ", "incertitude de distance", "m",
                      np.array([0.005, 0.01, 0.02, 0.05, 0.1]), default=2),
    )


def banana_parameter_axes() -> tuple[ParameterAxis, ParameterAxis]:
    r""":math:`\alpha \in [0{,}1 ; 2]` (défaut 1) et :math:`\kappa \in \{-1{,}5 ; \dots ; 4\}` (défaut
    :math:`3 - n = 1`)."""
    return (
        ParameterAxis("alpha", "α", "écartement des points sigma", "",
                      np.array([0.1, 0.2, 0.3, 0.5, 0.7, 1.0, 1.5, 2.0]), default=5),
        _KappaAxis("kappa", "κ", "paramètre secondaire", "",
                   _N + np.array([-1.5, -1.0, -0.5, 0.0, 1.0, 2.0, 4.0]), default=4),
    )


def banana_uncertainty_grid() -> ParameterGrid:
    r"""Toutes les positions :math:`(\sigma_\theta, \sigma_r)` (séries de :func:`banana_series`)."""

    return precompute_grid(banana_uncertainty_run, *banana_uncertainty_axes(), time=np.arange(N_POINTS, dtype=float))


def banana_parameter_grid() -> ParameterGrid:
    r"""Toutes les positions :math:`(\alpha, \kappa)` à :math:`\sigma_\theta = 20°`, :math:`\sigma_r = 2` cm
    (séries de :func:`banana_series`, sans le nuage, qui ne dépend pas des curseurs)."""

    return precompute_grid(banana_parameter_run, *banana_parameter_axes(), time=np.arange(N_POINTS, dtype=float))


def banana_uncertainty_panels() -> tuple[Panel, ...]:
    """Linéarisation (EKF) puis transformée unscented (UKF), chacune contre la vérité."""
    return (
        _panel("Linéarisation (EKF) contre vérité — ellipses à 2σ", "lin", 1.2),
        _panel("Transformée unscented (UKF) contre vérité — ellipses à 2σ", "ut", 1.2),
    )


def banana_parameter_panels() -> tuple[Panel, ...]:
    """La transformée unscented contre la vérité (σθ = 20°, σᵣ = 2 cm)."""
    return (_panel("Transformée unscented (UKF) contre vérité — ellipses à 2σ", "ut", 1.6),)


def banana_uncertainty_run(bearing_deg: float, range_std: float) -> dict[str, np.ndarray]:
    r"""Une position des curseurs :math:`(\sigma_\theta` en degrés, :math:`\sigma_r)`."""
    return banana_series(range_std, float(np.deg2rad(bearing_deg)))


def banana_parameter_run(alpha: float, n_plus_kappa: float) -> dict[str, np.ndarray]:
    r"""Une position des curseurs :math:`(\alpha, n + \kappa)` à :math:`\sigma_\theta = 20°`, :math:`\sigma_r = 2` cm."""
    return banana_series(banana.BANANA_RANGE_STD, banana.BANANA_BEARING_STD, alpha=alpha,
                         kappa=n_plus_kappa - _N, cloud=False)


def _area(x: np.ndarray, y: np.ndarray) -> float:
    """Aire d'un polygone fermé (formule du lacet) : celle d'une ellipse tracée point par point."""
    return 0.5 * abs(float(np.dot(x, np.roll(y, 1)) - np.dot(y, np.roll(x, 1))))


def _moments_text(series, methods) -> str:
    from .figure import number

    def coordinate(v: float) -> str:  # 6 × 10⁻¹⁷ m est un zéro d'arrondi
        return number(0.0 if abs(v) < 1e-9 else v, significant=2)

    def pair(key: str) -> str:
        return f"({coordinate(series[f'{key}_mx'][0])} ; {coordinate(series[f'{key}_my'][0])}) m"

    truth_area = _area(series["truth_x"], series["truth_y"])
    parts = [f"Moyenne vraie {pair('truth')}"]
    for key, label in methods:
        gap = float(np.hypot(series[f"{key}_mx"][0] - series["truth_mx"][0],
                             series[f"{key}_my"][0] - series["truth_my"][0]))
        ratio = _area(series[f"{key}_x"], series[f"{key}_y"]) / truth_area
        parts.append(f"{label} {pair(key)}, à {number(1000 * gap, 'mm', significant=2)} de la vraie, ellipse "
                     f"d'aire × {number(ratio, significant=2)}")
    return " ; ".join(parts) + "."


def banana_uncertainty_readout(series, values) -> str:
    """Le texte sous les curseurs σθ, σᵣ : les moyennes et les aires des ellipses, comparées aux vraies."""
    return _moments_text(series, (("lin", "EKF"), ("ut", "UKF")))


def banana_parameter_readout(series, values) -> str:
    """Le texte sous les curseurs α, κ : l'écartement des points sigma, la moyenne et l'ellipse de l'UKF."""
    from .figure import number

    alpha, n_plus_kappa = values
    scale = alpha * np.sqrt(n_plus_kappa)
    return (f"Points sigma à √(n + λ) = α √(n + κ) = {number(scale, significant=2)} écart-type de la moyenne. "
            + _moments_text(series, (("ut", "UKF"),)))


def banana_uncertainty_sliders():
    r"""Figure à curseurs statiques :math:`\sigma_\theta`, :math:`\sigma_r` (Bokeh) : celle du registre,
    ``kc.interactive.sliders("ukf-banane-incertitude")``."""
    from .figure import sliders

    return sliders("ukf-banane-incertitude")


def banana_parameter_sliders():
    r"""Figure à curseurs statiques :math:`\alpha`, :math:`\kappa` (Bokeh), :math:`\sigma_\theta = 20°`,
    :math:`\sigma_r = 2` cm : celle du registre, ``kc.interactive.sliders("ukf-banane-parametres")``."""
    from .figure import sliders

    return sliders("ukf-banane-parametres")
