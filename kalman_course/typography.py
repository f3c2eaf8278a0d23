r"""Typographie française des chaînes écrites pour un lecteur (titres et légendes de figures, curseurs,
texte du livre).

Règles, sur le texte courant seulement :

- espace insécable (U+00A0) avant « : » et à l'intérieur des guillemets « » ;
- espace fine insécable (U+202F) avant « ; », « ! », « ? » et « % » ;
- une seule apostrophe, la typographique « ’ » (U+2019).

Les espaces ordinaires déjà présentes devant ces signes sont remplacées ; aucune espace n'est ajoutée
devant un deux-points collé (« 10:30 », « http: »). Les guillemets reçoivent toujours leurs espaces.

:func:`french_spacing` laisse les segments de formule ``$…$`` tels quels ; :func:`apply_rules` applique
les règles à tout le texte (l'extension Sphinx du livre, :mod:`kalman_course.sphinx.typography`, l'appelle
sur les nœuds de texte courant, hors code et formules). Module sans dépendance : les figures, les
curseurs et les nombres (:mod:`kalman_course.numbers`) l'importent sans charger Sphinx.
"""

from __future__ import annotations

import re

__all__ = ["NBSP", "NNBSP", "LATIN", "apply_rules", "french_spacing", "italic_latin_html"]

#: Espace insécable (avant « : », dans « »).
NBSP = "\u00a0"
#: Espace fine insécable (avant « ; ! ? % »).
NNBSP = "\u202f"

_SPACES = "[ \t\r\n\u00a0\u202f]"
_RULES = (
    (re.compile(_SPACES + r"+:"), NBSP + ":"),
    (re.compile(_SPACES + r"+([;!?%])"), NNBSP + r"\1"),
    (re.compile("«" + _SPACES + "*"), "«" + NBSP),
    (re.compile(_SPACES + "*»"), NBSP + "»"),
    (re.compile("'"), "\u2019"),
)
_MATH = re.compile(r"(\$[^$]+\$)")


def apply_rules(text: str) -> str:
    """``text`` avec les espaces insécables et l'apostrophe de la typographie française, partout (aucune
    formule n'est reconnue : voir :func:`french_spacing`)."""
    for pattern, replacement in _RULES:
        text = pattern.sub(replacement, text)
    return text


def french_spacing(text: str) -> str:
    """``text`` avec les espaces insécables et l'apostrophe de la typographie française (voir le
    module) ; les formules ``$…$`` ne sont pas modifiées."""
    parts = _MATH.split(text)
    return "".join(part if i % 2 else apply_rules(part) for i, part in enumerate(parts))


#: Locutions latines composées en italique : *a priori*, *a posteriori*.
LATIN = re.compile(r"(?<![\w-])(a (?:priori|posteriori))(?![\w-])")


def italic_latin_html(escaped: str) -> str:
    """Un texte HTML déjà échappé (titre de figure à curseurs, lecture chiffrée…) avec *a priori* et
    *a posteriori* en italique (``<em>``), comme le texte courant du livre."""
    return LATIN.sub(r"<em>\1</em>", escaped)
