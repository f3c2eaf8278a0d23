r"""Typographie française du livre, appliquée une fois pour toutes à la construction (extension Sphinx).

Règles, sur le texte courant seulement (jamais dans le code, les formules, le HTML brut) :

- espace insécable (U+00A0) avant « : » et à l'intérieur des guillemets « » ;
- espace fine insécable (U+202F) avant « ; », « ! », « ? » et « % » ;
- une seule apostrophe, la typographique « ’ » (U+2019).

Les espaces ordinaires déjà présentes devant ces signes sont remplacées ; aucune espace n'est ajoutée
devant un deux-points collé (« 10:30 », « http: »). Les guillemets reçoivent toujours leurs espaces.

À déclarer dans ``_config.yml`` (``sphinx: extra_extensions``), avec ``smartquotes: false`` : les
« guillemets intelligents » de docutils devinent mal l'apostrophe placée devant un mot en gras ou un
lien (« l” » au lieu de « l’ ») ; ce module la traite à leur place, sans deviner.

:func:`french_spacing` s'applique aussi à une chaîne Python (titres de figures Bokeh, légendes) ; les
segments de formule ``$…$`` y sont laissés tels quels.
"""

from __future__ import annotations

import re

__all__ = ["NBSP", "NNBSP", "french_spacing", "setup"]

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


def _apply(text: str) -> str:
    for pattern, replacement in _RULES:
        text = pattern.sub(replacement, text)
    return text


def french_spacing(text: str) -> str:
    """``text`` avec les espaces insécables et l'apostrophe de la typographie française (voir le
    module) ; les formules ``$…$`` ne sont pas modifiées."""
    parts = _MATH.split(text)
    return "".join(part if i % 2 else _apply(part) for i, part in enumerate(parts))


# --------------------------------------------------------------------------- extension Sphinx


def _skipped_classes():
    from docutils import nodes
    from sphinx import addnodes

    return (
        nodes.FixedTextElement,  # literal_block, math_block, doctest_block…
        nodes.literal,
        nodes.math,
        nodes.raw,
        nodes.comment,
        nodes.substitution_definition,
        addnodes.desc_signature,
    )


def typeset(document) -> int:
    """Applique les règles à tous les nœuds de texte courant de ``document`` ; renvoie le nombre de
    nœuds modifiés. Un nœud dont un ancêtre est du code, une formule ou du HTML brut est laissé."""
    from docutils import nodes

    skipped = _skipped_classes()
    changed = 0
    for node in list(document.findall(nodes.Text)):
        parent = node.parent
        if parent is None:
            continue
        ancestor, skip = parent, False
        while ancestor is not None:
            if isinstance(ancestor, skipped):
                skip = True
                break
            ancestor = ancestor.parent
        if skip:
            continue
        old = str(node)
        new = _apply(old)
        if new != old:
            parent.replace(node, nodes.Text(new))
            changed += 1
    from sphinx import addnodes

    for toctree in document.findall(addnodes.toctree):  # titres des parties (barre latérale)
        if toctree.get("caption"):
            toctree["caption"] = french_spacing(toctree["caption"])
    return changed


def _transforms():
    from sphinx.transforms import SphinxTransform
    from sphinx.transforms.post_transforms import SphinxPostTransform

    class FrenchTypography(SphinxTransform):
        """À la lecture : les titres (table des matières, liens « suivant ») en profitent aussi."""

        default_priority = 760  # après les transformations de docutils et de Sphinx sur le texte

        def apply(self, **kwargs) -> None:
            typeset(self.document)

    class FrenchTypographyLate(SphinxPostTransform):
        """À l'écriture : texte résolu après la lecture (références, nombres collés d'autres pages)."""

        default_priority = 900

        def run(self, **kwargs) -> None:
            typeset(self.document)

    return FrenchTypography, FrenchTypographyLate


def _check_smartquotes(app, config) -> None:
    if config.smartquotes:
        from sphinx.errors import ConfigError

        raise ConfigError(
            "kalman_course.book_typography traite lui-même apostrophes et guillemets : mettez "
            "« smartquotes: false » sous « sphinx: config: » dans _config.yml."
        )


def setup(app):
    early, late = _transforms()
    app.add_transform(early)
    app.add_post_transform(late)
    app.connect("config-inited", _check_smartquotes)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
