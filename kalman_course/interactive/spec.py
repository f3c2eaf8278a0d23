"""Description des panneaux d'une figure interactive, commune aux curseurs statiques (Bokeh) et
interactifs (matplotlib + ipywidgets) : un chapitre décrit sa figure une fois, les deux la dessinent."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

from ..core.validation import KalmanInputError

__all__ = ["DASHES", "GLYPH_KINDS", "MARKERS", "Follow", "Glyph", "Panel", "panel_ranges", "panel_y_range"]


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
    trajectoire) ; ``dash``, ``width``, ``alpha``, ``marker``, ``size`` : style du trait ou des marqueurs ;
    ``clip`` : le tracé peut sortir de l'axe (il ne compte pas dans les bornes automatiques, et les tests
    ne vérifient pas qu'il y tient : une ellipse a priori de 30 m autour d'un détail de 3 m).
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
    clip: bool = False

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
class Follow:
    """Bornes d'ordonnée qui **suivent l'exécution affichée** (à donner comme ``Panel.y_range``).

    À chaque position des curseurs, l'axe couvre les valeurs finies des séries ``columns`` de cette
    exécution (par défaut : toutes les séries tracées du panneau), les valeurs ``include`` (par
    exemple 0 pour une densité, qui reste alors le bord de l'axe, sans marge) et une marge relative
    ``margin`` (échelle logarithmique : décades entières, sans autre marge). ``min_span`` : hauteur minimale de l'axe (en décades sur une échelle
    logarithmique ; un panneau presque plat n'est pas agrandi jusqu'au bruit d'arrondi) ; ``above`` :
    marge ajoutée en haut seulement, dans l'unité de l'axe (place d'un repère au-dessus du maximum).

    Les séries hors de ``columns`` peuvent sortir de l'axe : c'est voulu (par exemple une estimation
    qui sort d'une bande, quand la bande fixe l'échelle). Les tests vérifient, à chaque point de la
    grille, que les séries ``columns`` sont dans l'axe.

    Panneau plan (``Panel.equal_aspect``) : l'abscisse suit aussi, et ``aspect`` (largeur sur hauteur
    du cadre, en mètres comme en pixels) reste fixe : le cadre couvre les tracés de l'exécution
    affichée (abscisses et ordonnées), puis s'élargit dans une direction pour garder ce rapport. Un
    croissant de 2 m et un de 40 m remplissent alors tous deux le panneau, sans le déformer.
    """

    columns: tuple[str, ...] | None = None
    include: tuple[float, ...] = ()
    margin: float = 0.05
    min_span: float = 0.0
    above: float = 0.0
    aspect: float | None = None

    def __post_init__(self) -> None:
        if self.aspect is not None and not (math.isfinite(self.aspect) and self.aspect > 0):
            raise KalmanInputError(f"« aspect » doit être un nombre strictement positif ; reçu {self.aspect!r}.")
        if self.columns is not None:
            object.__setattr__(self, "columns", tuple(self.columns))
        object.__setattr__(self, "include", tuple(float(v) for v in self.include))
        if not (self.margin >= 0 and self.min_span >= 0 and self.above >= 0):
            raise KalmanInputError("« margin », « min_span » et « above » doivent être positifs ou nuls.")


@dataclass(frozen=True)
class Panel:
    """Un panneau : titre, ordonnée (avec unité), tracés ; ``y_log`` pour une échelle logarithmique,
    ``y_range`` pour des bornes fixes, ou :class:`Follow` pour des bornes qui suivent l'exécution
    affichée (par défaut : bornes fixes calculées sur toutes les exécutions) ; ``height`` en pixels.

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
    y_range: tuple[float, float] | Follow | None = None
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
        if self.follows and (self.equal_aspect != (self.y_range.aspect is not None)):
            raise KalmanInputError(
                f"Le panneau « {self.title} » : un plan (« equal_aspect ») qui suit les données donne le rapport "
                "« aspect » de son cadre à Follow, et seul un plan le donne.")


    @property
    def follows(self) -> bool:
        """Vrai si l'ordonnée suit l'exécution affichée (``y_range`` est un :class:`Follow`)."""
        return isinstance(self.y_range, Follow)

    @property
    def follows_plane(self) -> bool:
        """Vrai si les deux axes suivent l'exécution affichée (plan à rapport fixe, :class:`Follow` ``aspect``)."""
        return self.follows and self.y_range.aspect is not None

    def aspect(self, y_range: tuple[float, float] | None = None) -> float:
        """Largeur sur hauteur du cadre d'un plan (``equal_aspect``)."""
        if self.follows_plane:
            return float(self.y_range.aspect)
        (x0, x1), (y0, y1) = self.x_range, y_range if y_range is not None else self.y_range
        return abs((x1 - x0) / (y1 - y0))

    def x_columns(self) -> tuple[str, ...]:
        """Les abscisses des tracés qui fixent les bornes (plan qui suit les données)."""
        columns = self.range_columns()
        return tuple(dict.fromkeys(g.x for g in self.glyphs
                                   if g.kind not in ("hline", "vline") and not g.clip and g.column in columns))

    def range_columns(self) -> tuple[str, ...]:
        """Les séries qui fixent l'ordonnée : celles de :class:`Follow` ou, sinon, toutes les séries tracées
        en ordonnée (bords des surfaces compris), sauf celles des tracés ``clip``."""
        if self.follows and self.y_range.columns is not None:
            return self.y_range.columns
        out: list[str] = []
        for glyph in self.glyphs:
            if glyph.kind in ("hline", "vline") or glyph.clip:
                continue
            out += [glyph.column] + ([glyph.upper] if glyph.kind == "band" else [])
        return tuple(dict.fromkeys(out))

    @property
    def own_x(self) -> bool:
        """Vrai si l'abscisse n'est pas le temps commun."""
        return any(g.x != "t" for g in self.glyphs) or self.x_range is not None


def _bounds(values, *, log: bool, margin: float, min_span: float = 0.0, above: float = 0.0,
            fixed: tuple[float, ...] = (), title: str = "") -> tuple[float, float]:
    """Bornes d'un axe couvrant ``values`` : décades entières (log) ou marge relative (linéaire) ; une
    borne égale à une valeur de ``fixed`` n'a pas de marge."""
    import numpy as np

    v = np.asarray(values, dtype=float).ravel()
    v = v[np.isfinite(v)]
    if log:
        v = v[v > 0]
        if v.size == 0:
            raise KalmanInputError(f"Panneau « {title} » : échelle log sans valeur strictement positive.")
        lo, hi = np.floor(np.log10(v.min())), np.ceil(np.log10(v.max()))
        if hi - lo < max(min_span, 1.0):
            hi = lo + max(min_span, 1.0)
        return float(10.0 ** lo), float(10.0 ** hi)
    if v.size == 0:
        raise KalmanInputError(f"Panneau « {title} » : aucune valeur finie à tracer, donnez « y_range ».")
    lo, hi = float(v.min()), float(v.max())
    if hi - lo < min_span:
        middle = 0.5 * (hi + lo)
        lo, hi = middle - 0.5 * min_span, middle + 0.5 * min_span
    pad = margin * (hi - lo) if hi > lo else max(abs(hi), 1.0) * max(margin, 0.05)
    # une borne imposée (le 0 d'une densité) reste le bord de l'axe, sans marge
    return lo - (0.0 if lo in fixed else pad), hi + (0.0 if hi in fixed else pad) + above


def panel_y_range(panel: Panel, data) -> tuple[float, float]:
    """Bornes de l'ordonnée du panneau pour les séries ``data`` (dict nom → valeurs ; une exécution, ou
    toutes les exécutions d'une grille mises bout à bout). Marge ``margin`` ignorée en échelle
    logarithmique (décades entières).

    Bornes fixes : ``panel.y_range`` ; :class:`Follow` : les séries de ``Follow.columns`` de ``data``
    et ses valeurs ``include`` ; sinon toutes les séries tracées, les droites horizontales et le 0 des
    surfaces (``"area"``), marge de 5 % (décades entières en échelle logarithmique).
    """
    import numpy as np

    if panel.y_range is not None and not panel.follows:
        return tuple(panel.y_range)
    values = [np.asarray(data[c], dtype=float).ravel() for c in panel.range_columns()]
    follow = panel.y_range if panel.follows else Follow()
    if panel.follows:
        values.append(np.array(follow.include))
    else:
        values += [np.array([g.value], dtype=float) for g in panel.glyphs if g.kind == "hline"]
        if any(g.kind == "area" for g in panel.glyphs):
            values.append(np.zeros(1))
    return _bounds(np.concatenate(values) if values else np.zeros(0), log=panel.y_log, margin=follow.margin,
                   min_span=follow.min_span, above=follow.above, fixed=follow.include, title=panel.title)


def panel_ranges(panel: Panel, data) -> tuple[tuple[float, float] | None, tuple[float, float]]:
    """``(abscisse, ordonnée)`` du panneau pour les séries ``data`` : l'abscisse n'est donnée (sinon
    ``None``) que pour un plan qui suit les données (:attr:`Panel.follows_plane`) ; son cadre couvre
    les tracés, avec la marge de :class:`Follow`, élargi pour garder le rapport ``aspect``."""
    import numpy as np

    y = panel_y_range(panel, data)
    if not panel.follows_plane:
        return None, y
    follow = panel.y_range
    xs = np.concatenate([np.asarray(data[c], dtype=float).ravel() for c in panel.x_columns()])
    x = _bounds(xs, log=False, margin=follow.margin, title=panel.title)
    width, height = x[1] - x[0], y[1] - y[0]
    if width / height < follow.aspect:  # trop étroit : on élargit l'abscisse autour de son centre
        middle, width = 0.5 * (x[0] + x[1]), height * follow.aspect
        x = (middle - 0.5 * width, middle + 0.5 * width)
    else:  # trop plat : on agrandit l'ordonnée
        middle, height = 0.5 * (y[0] + y[1]), width / follow.aspect
        y = (middle - 0.5 * height, middle + 0.5 * height)
    return (float(x[0]), float(x[1])), (float(y[0]), float(y[1]))


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

    Sert aux curseurs interactifs (:mod:`.live`, figure redessinée à chaque mouvement) et à l'image fixe
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
        x_limits, y_limits = panel_ranges(panel, data) if panel.y_range is not None else (None, None)
        if y_limits is not None:
            ax.set_ylim(*y_limits)
        if x_limits is not None or panel.x_range is not None:
            ax.set_xlim(*(x_limits or panel.x_range))
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
