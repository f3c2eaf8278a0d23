"""Description des panneaux d'une figure interactive, commune aux curseurs statiques (Bokeh) et
vivants (matplotlib + ipywidgets) : un chapitre décrit sa figure une fois, les deux la dessinent."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from ..core.validation import KalmanInputError

__all__ = ["DASHES", "GLYPH_KINDS", "MARKERS", "Glyph", "Panel"]


#: Sortes de tracés.
GLYPH_KINDS = ("line", "scatter", "hline", "vline", "area", "band")
#: Styles de trait.
DASHES = ("solid", "dashed", "dotted", "dashdot")
#: Marqueurs des nuages de points.
MARKERS = ("cross", "circle", "square", "diamond", "triangle", "x", "star", "dot")
_KINDS_TEXT = ", ".join(f'"{k}"' for k in GLYPH_KINDS)


@dataclass(frozen=True)
class Glyph:
    """Un tracé d'un panneau.

    ``column`` : nom d'une série calculée (grille ou exécution) ou d'une série fixe, en ordonnée ;
    ``kind`` : ``"line"``, ``"scatter"`` (marqueurs), ``"hline"`` (droite horizontale d'ordonnée
    ``value``, ``column`` ignoré), ``"vline"`` (droite verticale d'abscisse ``value``), ``"area"``
    (surface entre 0 et la série) ou ``"band"`` (surface entre ``column`` et la série ``upper``) ;
    ``color`` : nom de couleur CSS ; ``legend`` : légende en français (vide : pas de légende) ;
    ``x`` : série en abscisse (``"t"``, le temps commun, par défaut ; par exemple la coordonnée x d'une
    trajectoire) ; ``dash``, ``width``, ``alpha``, ``marker``, ``size`` : style du trait ou des marqueurs.
    """

    column: str
    kind: str
    color: str
    legend: str
    value: float | None = None
    x: str = "t"
    upper: str | None = None
    dash: str = "solid"
    width: float = 2.0
    alpha: float = 1.0
    marker: str = "cross"
    size: float = 8.0

    def __post_init__(self) -> None:
        if self.kind not in GLYPH_KINDS:
            raise KalmanInputError(
                f"« kind » doit valoir {_KINDS_TEXT} ; reçu {self.kind!r}."
            )
        if self.kind in ("hline", "vline") and self.value is None:
            raise KalmanInputError(f"Un tracé « {self.kind} » exige « value » (la position de la droite).")
        if self.kind == "band" and not self.upper:
            raise KalmanInputError("Un tracé « band » exige « upper » (la série du bord supérieur).")
        if self.dash not in DASHES:
            raise KalmanInputError(f"« dash » doit valoir {', '.join(DASHES)} ; reçu {self.dash!r}.")
        if self.marker not in MARKERS:
            raise KalmanInputError(f"« marker » doit valoir {', '.join(MARKERS)} ; reçu {self.marker!r}.")

    @property
    def columns(self) -> tuple[str, ...]:
        """Les séries lues par le tracé (abscisse comprise) ; aucune pour une droite."""
        if self.kind in ("hline", "vline"):
            return ()
        return tuple(c for c in (self.x, self.column, self.upper) if c is not None)


@dataclass(frozen=True)
class Panel:
    """Un panneau : titre, ordonnée (avec unité), tracés ; ``y_log`` pour une échelle logarithmique,
    ``y_range`` pour des bornes fixes (sinon calculées sur toutes les exécutions) ; ``height`` en pixels.

    Par défaut l'abscisse est le temps commun de la figure (axe partagé par les panneaux). Un panneau
    dont les tracés ont une autre abscisse (``Glyph.x``, par exemple une trajectoire) donne son
    libellé ``x_label`` (avec unité), ses bornes ``x_range`` et, si ``equal_aspect``, la même échelle
    sur les deux axes (plan d'une pièce) ; ``x_log`` : abscisse logarithmique ; ``width`` : largeur
    fixe en pixels d'un panneau ``equal_aspect`` (sa hauteur s'en déduit), au lieu de toute la largeur.
    """

    title: str
    y_label: str
    glyphs: tuple[Glyph, ...]
    y_log: bool = False
    y_range: tuple[float, float] | None = None
    height: int = 230
    x_label: str | None = None
    x_range: tuple[float, float] | None = None
    equal_aspect: bool = False
    x_log: bool = False
    width: int | None = None

    def __post_init__(self) -> None:
        if not self.glyphs or not all(isinstance(g, Glyph) for g in self.glyphs):
            raise KalmanInputError(f"Le panneau « {self.title} » doit contenir au moins un Glyph.")
        if self.own_x and (self.x_label is None or self.x_range is None):
            raise KalmanInputError(
                f"Le panneau « {self.title} » a sa propre abscisse : donnez « x_label » (avec unité) et "
                "« x_range »."
            )
        if self.equal_aspect and (self.x_range is None or self.y_range is None):
            raise KalmanInputError(f"Le panneau « {self.title} » : « equal_aspect » exige x_range et y_range.")


    @property
    def own_x(self) -> bool:
        """Vrai si l'abscisse n'est pas le temps commun."""
        return any(g.x != "t" for g in self.glyphs) or self.x_range is not None


def check_columns(panels, known: set[str], lengths: Mapping[str, int] | None = None) -> None:
    """Chaque tracé doit lire une série connue (calculée ou fixe) ; avec ``lengths`` (nom → longueur,
    ``"t"`` compris), les séries d'un même tracé doivent avoir la même longueur."""
    for panel in panels:
        for glyph in panel.glyphs:
            if glyph.kind == "band" and glyph.upper not in known:
                raise KalmanInputError(
                    f"Le tracé « {glyph.legend} » prend pour bord supérieur « {glyph.upper} », série absente "
                    f"({', '.join(sorted(known))})."
                )
            if glyph.columns and glyph.x != "t" and glyph.x not in known:
                raise KalmanInputError(
                    f"Le tracé « {glyph.legend} » prend pour abscisse « {glyph.x} », série absente "
                    f"({', '.join(sorted(known))})."
                )
            if glyph.columns and glyph.column not in known:
                raise KalmanInputError(
                    f"Le tracé « {glyph.legend} » lit la série « {glyph.column} », absente des séries "
                    f"calculées et fixes ({', '.join(sorted(known))})."
                )
            if lengths is not None and glyph.columns:
                sizes = {c: lengths[c] for c in glyph.columns}
                if len(set(sizes.values())) > 1:
                    detail = ", ".join(f"« {c} » : {n}" for c, n in sizes.items())
                    raise KalmanInputError(
                        f"Le tracé « {glyph.legend} » mêle des séries de longueurs différentes ({detail})."
                    )


#: Styles de trait et marqueurs matplotlib des tracés décrits par :class:`Glyph`.
MPL_DASH = {"solid": "-", "dashed": "--", "dotted": ":", "dashdot": "-."}
MPL_MARKER = {"cross": "+", "circle": "o", "square": "s", "diamond": "D", "triangle": "^", "x": "x",
              "star": "*", "dot": "."}


def fill_glyph(ax, glyph: Glyph, data, label=None):
    """Une surface (``"area"`` : entre 0 et la série ; ``"band"`` : entre deux séries) ; renvoie la
    collection matplotlib (à retirer et redessiner quand les séries changent)."""
    import numpy as np

    lower = np.zeros_like(data[glyph.column]) if glyph.kind == "area" else data[glyph.column]
    upper = data[glyph.column] if glyph.kind == "area" else data[glyph.upper]
    return ax.fill_between(data[glyph.x], lower, upper, color=glyph.color, alpha=0.25 * glyph.alpha, lw=0,
                           label=label)


def draw_panels(panels, data, x_label: str, *, height_px_per_inch: float = 80.0):
    """Dessine les panneaux avec matplotlib (sans pyplot), un sous-graphique par panneau.

    Sert aux curseurs vivants (:mod:`.live`, figure redessinée à chaque mouvement) et à l'image fixe
    des curseurs statiques (:mod:`.static`, figure du PDF à la position par défaut des curseurs).

    Paramètres
    ----------
    panels : suite de Panel
    data : dict nom → (L,)
        Toutes les séries lues par les tracés, dont ``"t"`` (le temps commun).
    x_label : str
        Libellé de l'abscisse commune, avec unité.

    Renvoie ``(fig, lines, axes)`` : la figure, ``lines`` (dict nom de série → liste de ``Line2D``
    tracées ; chaque ligne porte ``kc_columns = (abscisse, ordonnée)``), les axes (un par panneau). Les
    surfaces (``"area"``, ``"band"``) sont dans ``fig.kc_fills``, liste de ``(axe, tracé, collection)``.
    """
    from ..figures import new_figure
    from ..numbers import french_figure

    panels = tuple(panels)
    height = sum(p.height for p in panels) / height_px_per_inch
    shared = not any(p.own_x for p in panels)
    fig, axes = new_figure(len(panels), 1, width=7.0, height=height, sharex=shared, squeeze=False)
    axes = axes[:, 0]
    lines: dict[str, list] = {}
    fills: list = []
    for ax, panel in zip(axes, panels):
        for glyph in panel.glyphs:
            x = glyph.x
            label = glyph.legend or None
            if glyph.kind in ("hline", "vline"):
                draw = ax.axhline if glyph.kind == "hline" else ax.axvline
                draw(glyph.value, color=glyph.color, lw=1.5, ls=MPL_DASH[glyph.dash], label=label)
                continue
            if glyph.kind in ("area", "band"):
                fills.append((ax, glyph, fill_glyph(ax, glyph, data, label)))
                continue
            if glyph.kind == "scatter":
                style = {"marker": MPL_MARKER[glyph.marker], "ls": "none", "ms": glyph.size * 0.9}
            else:
                style = {"lw": glyph.width * 0.9, "ls": MPL_DASH[glyph.dash]}
            (line,) = ax.plot(data[x], data[glyph.column], color=glyph.color, label=label, alpha=glyph.alpha,
                              **style)
            line.kc_columns = (x, glyph.column)  # séries (abscisse, ordonnée) à relire au redessin
            lines.setdefault(glyph.column, []).append(line)
        if panel.y_log:
            ax.set_yscale("log")
        if panel.x_log:
            ax.set_xscale("log")
        if panel.y_range is not None:
            ax.set_ylim(*panel.y_range)
        if panel.x_range is not None:
            ax.set_xlim(*panel.x_range)
        if panel.equal_aspect:
            ax.set_aspect("equal")
        ax.set_title(panel.title, fontsize=10)
        ax.set_ylabel(panel.y_label)
        ax.set_xlabel(panel.x_label or x_label)
        ax.grid(alpha=0.3, which="both" if panel.y_log else "major")
        if any(g.legend for g in panel.glyphs):
            ax.legend(loc="upper right" if panel.y_log else "lower right", fontsize=8)
    french_figure(fig)  # graduations et nombres des légendes à la française
    fig.kc_fills = fills
    return fig, lines, axes
