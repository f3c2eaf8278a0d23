"""Description des panneaux d'une figure interactive, commune aux curseurs statiques (Bokeh) et
vivants (matplotlib + ipywidgets) : un chapitre décrit sa figure une fois, les deux la dessinent."""

from __future__ import annotations

from dataclasses import dataclass

from ..core.validation import KalmanInputError

__all__ = ["Glyph", "Panel"]


@dataclass(frozen=True)
class Glyph:
    """Un tracé d'un panneau.

    ``column`` : nom d'une série calculée (grille ou exécution) ou d'une série fixe, en ordonnée ;
    ``kind`` : ``"line"``, ``"scatter"`` (croix) ou ``"hline"`` (droite horizontale d'ordonnée
    ``value``, ``column`` ignoré) ; ``color`` : nom de couleur CSS ; ``legend`` : légende en français ;
    ``x`` : série en abscisse (``"t"``, le temps commun, par défaut ; par exemple la coordonnée x d'une
    trajectoire).
    """

    column: str
    kind: str
    color: str
    legend: str
    value: float | None = None
    x: str = "t"

    def __post_init__(self) -> None:
        if self.kind not in ("line", "scatter", "hline"):
            raise KalmanInputError(
                f"« kind » doit valoir \"line\", \"scatter\" ou \"hline\" ; reçu {self.kind!r}."
            )
        if self.kind == "hline" and self.value is None:
            raise KalmanInputError("Un tracé « hline » exige « value » (l'ordonnée de la droite).")


@dataclass(frozen=True)
class Panel:
    """Un panneau : titre, ordonnée (avec unité), tracés ; ``y_log`` pour une échelle logarithmique,
    ``y_range`` pour des bornes fixes (sinon calculées sur toutes les exécutions) ; ``height`` en pixels.

    Par défaut l'abscisse est le temps commun de la figure (axe partagé par les panneaux). Un panneau
    dont les tracés ont une autre abscisse (``Glyph.x``, par exemple une trajectoire) donne son
    libellé ``x_label`` (avec unité), ses bornes ``x_range`` et, si ``equal_aspect``, la même échelle
    sur les deux axes (plan d'une pièce).
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


def check_columns(panels, known: set[str]) -> None:
    """Chaque tracé doit lire une série connue (calculée ou fixe)."""
    for panel in panels:
        for glyph in panel.glyphs:
            if glyph.kind != "hline" and glyph.x != "t" and glyph.x not in known:
                raise KalmanInputError(
                    f"Le tracé « {glyph.legend} » prend pour abscisse « {glyph.x} », série absente "
                    f"({', '.join(sorted(known))})."
                )
            if glyph.kind != "hline" and glyph.column not in known:
                raise KalmanInputError(
                    f"Le tracé « {glyph.legend} » lit la série « {glyph.column} », absente des séries "
                    f"calculées et fixes ({', '.join(sorted(known))})."
                )


def draw_panels(panels, data, x_label: str, *, height_px_per_inch: float = 80.0):
    """Dessine les panneaux avec matplotlib (sans pyplot), un sous-graphique par panneau.

    Sert aux curseurs vivants (:mod:`.live`, figure redessinée à chaque mouvement) et à l'image fixe
    des curseurs statiques (:mod:`.static`, figure du PDF à la position par défaut des curseurs).

    Paramètres
    ----------
    panels : suite de Panel
    data : dict nom → (T,)
        Toutes les séries lues par les tracés, dont ``"t"`` (le temps commun).
    x_label : str
        Libellé de l'abscisse commune, avec unité.

    Renvoie ``(fig, lines, axes)`` : la figure, ``lines`` (dict nom de série → liste de ``Line2D``
    tracées ; chaque ligne porte ``kc_columns = (abscisse, ordonnée)``), les axes (un par panneau).
    """
    from ..figures import new_figure
    from ..numbers import french_figure

    panels = tuple(panels)
    height = sum(p.height for p in panels) / height_px_per_inch
    shared = not any(p.own_x for p in panels)
    fig, axes = new_figure(len(panels), 1, width=7.0, height=height, sharex=shared, squeeze=False)
    axes = axes[:, 0]
    lines: dict[str, list] = {}
    for ax, panel in zip(axes, panels):
        for glyph in panel.glyphs:
            x = glyph.x
            if glyph.kind == "hline":
                ax.axhline(glyph.value, color=glyph.color, lw=1.5, label=glyph.legend)
                continue
            style = {"marker": "+", "ls": "none", "ms": 7} if glyph.kind == "scatter" else {"lw": 1.8}
            (line,) = ax.plot(data[x], data[glyph.column], color=glyph.color, label=glyph.legend, **style)
            line.kc_columns = (x, glyph.column)  # séries (abscisse, ordonnée) à relire au redessin
            lines.setdefault(glyph.column, []).append(line)
        if panel.y_log:
            ax.set_yscale("log")
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
        ax.legend(loc="upper right" if panel.y_log else "lower right", fontsize=8)
    french_figure(fig)  # graduations et nombres des légendes à la française
    return fig, lines, axes
