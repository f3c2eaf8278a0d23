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
