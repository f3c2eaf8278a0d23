r"""Les nombres en français, produits par une seule fonction (Babel, locale ``fr_FR``).

Tout nombre calculé que lit une personne — texte collé (*glue*) dans les chapitres, tableaux, étiquettes
des curseurs, graduations des figures — passe par :func:`format_number` : virgule décimale, espace fine
insécable (U+202F) entre les milliers, signe moins typographique (U+2212) et puissances de dix écrites
:math:`\times 10^{n}` (« 3,39 × 10⁻⁴ ») au lieu de la notation « e-04 ».

Exemples : ``format_number(0.000339, significant=3)`` → « 3,39 × 10⁻⁴ » ;
``format_number(1234.5, decimals=1)`` → « 1 234,5 » ; ``format_spec(0.25, ".1%")`` → « 25,0 % ».
Les tests (``tests/test_numbers.py``) comparent ces écritures à des chaînes écrites à la main.
"""

from __future__ import annotations

import math
import re
from functools import lru_cache
from typing import Any

from babel.numbers import format_decimal

from .core.validation import KalmanInputError

__all__ = [
    "LOCALE",
    "MINUS",
    "format_number",
    "format_integer",
    "format_percent",
    "format_spec",
    "format_array",
    "format_fractions",
    "matplotlib_formatter",
    "matplotlib_log_formatter",
    "french_figure",
    "bokeh_tick_formatter",
    "glue_number",
]

#: Locale de tous les nombres affichés.
LOCALE = "fr_FR"
#: Signe moins typographique.
MINUS = "\u2212"
#: Espace fine insécable (séparateur des milliers, et avant « × »).
NNBSP = "\u202f"
_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def _check_number(value: Any) -> float:
    if isinstance(value, bool):
        raise KalmanInputError(f"« value » doit être un nombre réel ; reçu un booléen ({value!r}).")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise KalmanInputError(
            f"« value » doit être un nombre réel ; reçu {type(value).__name__} ({value!r})."
        ) from None
    return x


def _check_digits(name: str, value: Any, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        raise KalmanInputError(f"« {name} » doit être un entier ≥ {minimum} ; reçu {value!r}.")
    return value


@lru_cache(maxsize=8192)
def _fixed(x: float, decimals: int, group: bool = True, trim: bool = False) -> str:
    # « # » : chiffre décimal facultatif (zéros finals retirés) ; « 0 » : chiffre toujours écrit.
    # En cache : les graduations d'une figure sont réécrites à chaque mise en page et à chaque tracé.
    digit = "#" if trim else "0"
    pattern = ("#,##0" if group else "0") + ("." + digit * decimals if decimals > 0 else "")
    text = format_decimal(round(x, decimals) + 0.0, format=pattern, locale=LOCALE)
    return text.replace("-", MINUS)


def _power_of_ten(mantissa: str, exponent: int) -> str:
    return f"{mantissa}{NNBSP}×{NNBSP}10{str(exponent).translate(_SUPERSCRIPT)}"


def format_number(
    value: Any,
    *,
    decimals: int | None = None,
    significant: int | None = None,
    scientific: bool | None = None,
    unit: str | None = None,
    trim: bool = False,
) -> str:
    r"""Un nombre écrit à la française.

    ``decimals`` : nombre fixe de décimales ; ``significant`` : nombre de chiffres significatifs (3 par
    défaut si aucun des deux n'est donné). ``scientific`` : écriture :math:`m \times 10^{n}` ; par défaut
    (``None``), choisie avec ``significant`` quand :math:`|x| < 10^{-3}` ou :math:`|x| \ge 10^{6}`.
    ``unit`` : unité ajoutée après une espace insécable (« 0,08 m ») ; le degré d'angle est collé (« 20° »). ``trim`` : retire les zéros
    inutiles en fin de partie décimale (« 0,5 » plutôt que « 0,500 », comme le format ``g`` de Python).
    NaN s'écrit « NaN », l'infini « ∞ », zéro en écriture scientifique « 0 ».

    Exemples : ``format_number(-0.5, decimals=2)`` → « −0,50 » ;
    ``format_number(2.5e-15, significant=2)`` → « 2,5 × 10⁻¹⁵ ».
    """
    x = _check_number(value)
    if decimals is not None and significant is not None:
        raise KalmanInputError("Donnez « decimals » ou « significant », pas les deux.")
    if decimals is not None:
        _check_digits("decimals", decimals, 0)
    if significant is not None:
        _check_digits("significant", significant, 1)
    if math.isnan(x):
        text = "NaN"
    elif math.isinf(x):
        text = ("" if x > 0 else MINUS) + "∞"
    elif decimals is not None and not scientific:
        text = _fixed(x, decimals, trim=trim)
    else:
        sig = 3 if significant is None else significant
        if decimals is not None:  # écriture scientifique demandée avec un nombre de décimales
            sig = decimals + 1
        exponent = 0 if x == 0 else math.floor(math.log10(abs(x)))
        # arrondi à ``sig`` chiffres significatifs (l'arrondi peut faire passer à la puissance suivante)
        rounded = 0.0 if x == 0 else round(x, sig - 1 - exponent)
        if rounded != 0:
            exponent = math.floor(math.log10(abs(rounded)))
        use_sci = scientific if scientific is not None else (x != 0 and (exponent < -3 or exponent >= 6))
        if use_sci and rounded == 0:  # zéro n'a pas d'ordre de grandeur : « 0 », jamais « 0,0 × 10⁰ »
            text = "0"
        elif use_sci:
            mantissa = rounded / 10.0**exponent
            text = _power_of_ten(_fixed(mantissa, sig - 1, group=False, trim=trim), exponent)
        else:
            text = _fixed(rounded, max(sig - 1 - exponent, 0), trim=trim)
    if unit is None:
        return text
    # le degré d'angle se colle au nombre (« 20° ») ; les autres unités, dont « °C », après une espace insécable
    return f"{text}{unit}" if unit in ("°", "′", "″") else f"{text}\u00a0{unit}"


def format_integer(value: Any) -> str:
    """Un entier avec l'espace fine insécable des milliers : ``format_integer(20000)`` → « 20 000 »."""
    x = _check_number(value)
    if not float(x).is_integer():
        raise KalmanInputError(f"« value » doit être un entier ; reçu {value!r}.")
    return _fixed(x, 0)


def format_percent(value: Any, decimals: int = 0) -> str:
    """Une proportion en pourcentage : ``format_percent(0.256)`` → « 26 % » (espace fine insécable)."""
    x = _check_number(value)
    return f"{_fixed(100.0 * x, _check_digits('decimals', decimals, 0))}{NNBSP}%"


_SPEC = re.compile(r"^(?P<sign>\+)?(?P<comma>,)?(?:\.(?P<precision>\d+))?(?P<kind>[fFeEgG%d])?$")


def format_spec(value: Any, spec: str) -> str:
    r"""Le nombre ``value`` écrit à la française d'après un format à la Python (``".3f"``, ``"{:.2e}"``…).

    Traduction : ``.Nf`` → ``N`` décimales ; ``.Ne`` → ``N + 1`` chiffres significatifs en écriture
    :math:`m \times 10^{n}` ; ``.Ng`` → ``N`` chiffres significatifs, zéros finals retirés (6 sans
    précision) ; ``.N%`` → pourcentage à ``N`` décimales ; ``d`` → entier. Le séparateur « , » des
    milliers est toujours mis (espace fine). Sert aux tableaux (:class:`~kalman_course.tables.Table`)
    et à tout texte qui reçoit un format écrit pour Python.

    Exemples : ``format_spec(0.000339, ".2e")`` → « 3,39 × 10⁻⁴ » ; ``format_spec(0.25, "{:.1%}")`` →
    « 25,0 % » ; ``format_spec(0.5, ".3g")`` → « 0,5 ».
    """
    if not isinstance(spec, str):
        raise KalmanInputError(f"« spec » doit être un format comme \".3f\" ; reçu {spec!r}.")
    inner = spec[2:-1] if spec.startswith("{:") and spec.endswith("}") else spec.lstrip(":")
    match = _SPEC.match(inner)
    if match is None:
        raise KalmanInputError(
            f"Format « {spec} » non reconnu : attendu .Nf, .Ne, .Ng, .N% ou d (par exemple \".3f\")."
        )
    precision = None if match["precision"] is None else int(match["precision"])
    kind = (match["kind"] or "g").lower()
    if kind == "f":
        text = format_number(value, decimals=6 if precision is None else precision)
    elif kind == "e":
        text = format_number(value, significant=7 if precision is None else precision + 1, scientific=True)
    elif kind == "%":
        text = format_percent(value, 6 if precision is None else precision)
    elif kind == "d":
        text = format_integer(value)
    else:
        text = format_number(value, significant=6 if precision is None else max(precision, 1), trim=True)
    if match["sign"] and not text.startswith(MINUS):
        text = "+" + text
    return text


def format_array(values: Any, **options: Any) -> str:
    """Un vecteur ou une matrice écrit à la française, une ligne par ligne de la matrice, colonnes
    alignées à droite (``options`` : ceux de :func:`format_number`) ; pour les sorties ``print``.

    Exemple : ``format_array([[1.5, -0.25], [10, 0]], decimals=2)`` donne les deux lignes
    « [[ 1,50  −0,25] » et « [10,00   0,00]] ».
    """
    import numpy as np

    arr = np.asarray(values, dtype=float)
    if arr.ndim == 0:
        return format_number(float(arr), **options)
    if arr.ndim > 2:
        raise KalmanInputError(f"« values » doit être un vecteur ou une matrice ; reçu {arr.ndim} dimensions.")
    rows = np.atleast_2d(arr)
    cells = [[format_number(v, **options) for v in row] for row in rows]
    width = max(len(c) for row in cells for c in row)
    lines = ["  ".join(c.rjust(width) for c in row) for row in cells]
    if arr.ndim == 1:
        return f"[{lines[0]}]"
    return "[" + "\n ".join(f"[{line}]" for line in lines) + "]"


def format_fractions(values: Any, max_denominator: int = 200) -> str:
    """Des valeurs écrites en fractions, comme les calculs à la main d'un TD : chaque valeur est
    approchée par la fraction la plus proche de dénominateur au plus ``max_denominator``
    (:meth:`fractions.Fraction.limit_denominator`), séparées par des virgules, signe moins
    typographique. ``format_fractions([2/3, 17/8, -0.5])`` → « 2/3, 17/8, −1/2 »."""
    from fractions import Fraction

    import numpy as np

    _check_digits("max_denominator", max_denominator, 1)
    arr = np.atleast_1d(np.asarray(values, dtype=float)).ravel()
    if not np.all(np.isfinite(arr)):
        raise KalmanInputError("« values » doit contenir des nombres finis (ni NaN ni infini).")
    return ", ".join(str(Fraction(float(v)).limit_denominator(max_denominator)).replace("-", MINUS) for v in arr)


def matplotlib_formatter():
    r"""Formateur de graduations matplotlib (linéaires) en français : les graduations choisies par
    ``ScalarFormatter`` (même nombre de décimales pour toutes), écrites par :func:`format_number`, et
    le facteur commun éventuel écrit :math:`\times 10^{n}` ; aucun décalage additif (« +1e3 »).

    Sur un axe gradué 0 ; 0,5 ; 1 : « 0,0 », « 0,5 », « 1,0 ».
    """
    from matplotlib.ticker import ScalarFormatter

    class FrenchScalarFormatter(ScalarFormatter):
        """``ScalarFormatter`` dont les graduations passent par :func:`format_number` (API publique
        seulement : le texte anglais de matplotlib donne la valeur et le nombre de décimales)."""

        def __init__(self) -> None:
            super().__init__(useOffset=False, useMathText=False)

        def __call__(self, x: float, pos: int | None = None) -> str:
            english = super().__call__(x, pos)
            if not english:
                return english
            plain = english.replace(MINUS, "-")
            decimals = len(plain.split(".")[1]) if "." in plain else 0
            return format_number(float(plain), decimals=decimals)

        def get_offset(self) -> str:
            english = super().get_offset().replace(MINUS, "-")
            found = re.fullmatch(r"1e([-+]?\d+)", english.strip())
            if found is None:
                return english
            return f"×{NNBSP}10{str(int(found[1])).translate(_SUPERSCRIPT)}"

        def format_data_short(self, value: float) -> str:
            return format_number(value, significant=4)

    return FrenchScalarFormatter()


_LOG_LABEL = re.compile(r"^(?P<sign>-?)(?:(?P<mantissa>[0-9.]+)\\times\s*)?10\^\{(?P<exponent>-?[0-9]+)\}$")


def _french_log_label(label: str) -> str:
    r"""Une étiquette ``LogFormatterSciNotation`` (mathtext ``$\mathdefault{3\times10^{-2}}$``) écrite
    en texte : « 3 × 10⁻² », « 10⁻² », « −10² », ou le nombre lui-même (« 0,5 ») ; inchangée sinon."""
    inner = re.fullmatch(r"\$\\mathdefault\{(.*)\}\$", label)
    if inner is None:
        return label
    found = _LOG_LABEL.match(inner[1])
    if found is not None:
        sign = MINUS if found["sign"] else ""
        power = f"10{str(int(found['exponent'])).translate(_SUPERSCRIPT)}"
        if found["mantissa"] is None:
            return sign + power
        mantissa = format_number(float(found["mantissa"]), significant=6, trim=True)
        return f"{sign}{mantissa}{NNBSP}×{NNBSP}{power}"
    try:
        value = float(inner[1])
    except ValueError:  # autre base (« 2^{3} ») : laissée telle quelle
        return label
    return format_number(value, significant=6, trim=True)


def matplotlib_log_formatter():
    r"""Formateur de graduations matplotlib pour les axes logarithmiques en base 10, en français : les
    graduations et le choix des étiquettes de ``LogFormatterSciNotation``, écrites en texte Unicode
    (« 10⁻² », « 3 × 10⁻² », signe moins typographique) plutôt qu'en formule mathtext — même lecture,
    et aucune formule à composer pour chaque graduation."""
    from matplotlib.ticker import LogFormatterSciNotation

    class FrenchLogFormatter(LogFormatterSciNotation):
        """``LogFormatterSciNotation`` dont les étiquettes passent par :func:`_french_log_label`."""

        def __call__(self, x: float, pos: int | None = None) -> str:
            return _french_log_label(super().__call__(x, pos))

    return FrenchLogFormatter()


def _figure_texts(artist):
    """Les textes d'une figure : titres, libellés, légendes, annotations, cellules de tableau… Les
    graduations sont laissées (réécrites par leur formateur à chaque tracé) : on ne descend pas dans
    les axes (``Axis``, qui fabriquerait toutes ses graduations), seulement dans leur libellé."""
    from matplotlib.axis import Axis
    from matplotlib.text import Text

    if isinstance(artist, Axis):
        yield artist.label
        return
    if isinstance(artist, Text):
        yield artist
    for child in artist.get_children():
        yield from _figure_texts(child)


def french_figure(figure) -> None:
    """Une figure matplotlib à la française : graduations des axes linéaires par
    :func:`matplotlib_formatter`, des axes logarithmiques (notation scientifique de matplotlib) par
    :func:`matplotlib_log_formatter` (les autres formateurs choisis par la figure sont laissés) et
    typographie des textes — titres, légendes, libellés, annotations — par
    :func:`kalman_course.typography.french_spacing` (espaces insécables, apostrophe « ’ »,
    formules ``$…$`` intactes)."""
    from matplotlib.ticker import LogFormatterSciNotation, ScalarFormatter

    from .typography import french_spacing

    for ax in figure.get_axes():
        for axis in (ax.xaxis, ax.yaxis, getattr(ax, "zaxis", None)):
            if axis is None:
                continue
            major, minor = axis.get_major_formatter(), axis.get_minor_formatter()
            if type(major) is ScalarFormatter:
                axis.set_major_formatter(matplotlib_formatter())
            for formatter, setter in ((major, axis.set_major_formatter), (minor, axis.set_minor_formatter)):
                if type(formatter) is LogFormatterSciNotation:
                    replacement = matplotlib_log_formatter()
                    replacement.__dict__.update(formatter.__dict__)  # même base, mêmes étiquettes choisies
                    setter(replacement)
    for text in _figure_texts(figure):
        old = text.get_text()
        new = french_spacing(old)
        if new != old:
            text.set_text(new)


def bokeh_tick_formatter(group_thousands: bool = True):
    """Un formateur de graduations Bokeh (``CustomJSTickFormatter``) : virgule décimale, signe moins
    typographique, puissances de dix :math:`\\times 10^{n}` (même rendu que :func:`format_number`).
    ``group_thousands=False`` pour un axe d'années : « 1880 », jamais « 1 880 ».

    Une seule écriture par axe : dès qu'une graduation de l'axe s'écrit en puissance de dix
    (:math:`|x| < 10^{-3}` ou :math:`|x| \\ge 10^{6}`), toutes les graduations non nulles de l'axe s'écrivent
    ainsi, « 10ⁿ » quand la mantisse vaut 1 (comme les axes logarithmiques des figures matplotlib,
    :func:`matplotlib_log_formatter`) : jamais « 100 000 » à côté de « 1 × 10⁶ »."""
    from bokeh.models import CustomJSTickFormatter

    code = r"""
    if (!isFinite(tick)) { return String(tick); }
    if (tick === 0) { return "0"; }
    const sup = {"-": "⁻", "0": "⁰", "1": "¹", "2": "²", "3": "³", "4": "⁴", "5": "⁵", "6": "⁶", "7": "⁷", "8": "⁸", "9": "⁹"};
    const french = (s) => {
        const neg = s.startsWith("-");
        const [int, dec] = (neg ? s.slice(1) : s).split(".");
        const grouped = group ? int.replace(/\B(?=(\d{3})+(?!\d))/g, "\u202f") : int;
        return (neg ? "\u2212" : "") + grouped + (dec ? "," + dec : "");
    };
    const scientific = (v) => v !== 0 && isFinite(v) && (Math.abs(v) < 1e-3 || Math.abs(v) >= 1e6);
    const all = (typeof ticks !== "undefined" && ticks) ? Array.from(ticks) : [tick];
    if (scientific(tick) || all.some(scientific)) {
        const [m, e] = tick.toExponential(2).split("e");
        const mantissa = String(parseFloat(m));
        const exp = String(parseInt(e, 10)).split("").map(c => sup[c]).join("");
        if (mantissa === "1" || mantissa === "-1") { return (mantissa === "-1" ? "\u2212" : "") + "10" + exp; }
        return french(mantissa) + "\u202f×\u202f10" + exp;
    }
    return french(String(Number(tick.toPrecision(6))));
    """
    return CustomJSTickFormatter(args={"group": bool(group_thousands)}, code=code)


def glue_number(name: str, value: Any, spec: str | None = None, **options: Any) -> str:
    """Colle (myst-nb ``glue``, sans affichage) le nombre ``value`` écrit à la française sous le nom
    ``name``, pour ``{glue:text}`name``` (sans format) dans la prose ; renvoie le texte collé.

    ``options`` : ceux de :func:`format_number` (``decimals=3``, ``significant=2``…) ; ou bien ``spec`` :
    un format à la Python traduit par :func:`format_spec` (``spec=".1%"`` pour un pourcentage)."""
    from myst_nb import glue

    if spec is not None and options:
        raise KalmanInputError("Donnez « spec » ou les options de format_number, pas les deux.")
    text = format_spec(value, spec) if spec is not None else format_number(value, **options)
    glue(name, text, display=False)
    return text
