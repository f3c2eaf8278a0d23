r"""Les nombres en français, produits par une seule fonction (Babel, locale ``fr_FR``).

Tout nombre calculé que lit une personne — texte collé (*glue*) dans les chapitres, tableaux, étiquettes
des curseurs, graduations des figures — passe par :func:`format_number` : virgule décimale, espace fine
insécable (U+202F) entre les milliers, signe moins typographique (U+2212) et puissances de dix écrites
:math:`\times 10^{n}` (« 3,39 × 10⁻⁴ ») au lieu de la notation « e-04 ».

>>> format_number(0.000339, significant=3)
'3,39 × 10⁻⁴'
>>> format_number(1234.5, decimals=1)
'1\u202f234,5'
"""

from __future__ import annotations

import math
from typing import Any

from babel.numbers import format_decimal

from .core.validation import KalmanInputError

__all__ = [
    "LOCALE",
    "MINUS",
    "format_number",
    "format_integer",
    "format_percent",
    "matplotlib_formatter",
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


def _fixed(x: float, decimals: int, group: bool = True) -> str:
    pattern = ("#,##0" if group else "0") + ("." + "0" * decimals if decimals > 0 else "")
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
) -> str:
    r"""Un nombre écrit à la française.

    ``decimals`` : nombre fixe de décimales ; ``significant`` : nombre de chiffres significatifs (3 par
    défaut si aucun des deux n'est donné). ``scientific`` : écriture :math:`m \times 10^{n}` ; par défaut
    (``None``), choisie avec ``significant`` quand :math:`|x| < 10^{-3}` ou :math:`|x| \ge 10^{6}`.
    ``unit`` : unité ajoutée après une espace insécable (« 0,08 m »). NaN s'écrit « NaN », l'infini « ∞ ».

    >>> format_number(-0.5, decimals=2)
    '−0,50'
    >>> format_number(2.5e-15, significant=2)
    '2,5 × 10⁻¹⁵'
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
        text = _fixed(x, decimals)
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
        if use_sci:
            mantissa = rounded / 10.0**exponent
            text = _power_of_ten(_fixed(mantissa, sig - 1, group=False), exponent)
        else:
            text = _fixed(rounded, max(sig - 1 - exponent, 0))
    return text if unit is None else f"{text}\u00a0{unit}"


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


def matplotlib_formatter(**options: Any):
    """Un ``matplotlib.ticker.FuncFormatter`` qui écrit les graduations avec :func:`format_number`
    (``options`` : ceux de :func:`format_number` ; par défaut, autant de décimales que nécessaire)."""
    from matplotlib.ticker import FuncFormatter

    def fmt(value: float, _pos: int | None = None) -> str:
        if options:
            return format_number(value, **options)
        if value == 0:
            return "0"
        text = f"{value:.6g}"
        if "e" in text:
            return format_number(value, significant=2)
        decimals = len(text.split(".")[1]) if "." in text else 0
        return format_number(value, decimals=decimals)

    return FuncFormatter(fmt)


def bokeh_tick_formatter():
    """Un formateur de graduations Bokeh (``CustomJSTickFormatter``) : virgule décimale, signe moins
    typographique, puissances de dix :math:`\\times 10^{n}` (même rendu que :func:`format_number`)."""
    from bokeh.models import CustomJSTickFormatter

    code = r"""
    if (!isFinite(tick)) { return String(tick); }
    if (tick === 0) { return "0"; }
    const sup = {"-": "⁻", "0": "⁰", "1": "¹", "2": "²", "3": "³", "4": "⁴", "5": "⁵", "6": "⁶", "7": "⁷", "8": "⁸", "9": "⁹"};
    let text = Number(tick.toPrecision(6)).toString();
    if (text.includes("e")) {
        const [m, e] = Number(tick).toExponential(1).split("e");
        const exp = String(parseInt(e, 10)).split("").map(c => sup[c]).join("");
        text = m + "\u202f×\u202f10" + exp;
    }
    return text.replace(".", ",").replace(/^-/, "\u2212");
    """
    return CustomJSTickFormatter(code=code)


def glue_number(name: str, value: Any, **options: Any) -> str:
    """Colle (myst-nb ``glue``, sans affichage) le nombre ``value`` écrit par :func:`format_number` sous le
    nom ``name``, pour ``{glue:text}`name``` dans la prose ; renvoie le texte collé."""
    from myst_nb import glue

    text = format_number(value, **options)
    glue(name, text, display=False)
    return text
