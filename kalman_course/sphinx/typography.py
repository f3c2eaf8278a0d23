r"""Typographie française du livre, appliquée une fois pour toutes à la construction (extension Sphinx).

Règles, sur le texte courant seulement (jamais dans le code, les formules, le HTML brut) :

- celles de :mod:`kalman_course.typography` : espace insécable (U+00A0) avant « : » et à l'intérieur
  des guillemets « », espace fine insécable (U+202F) avant « ; », « ! », « ? » et « % », une seule
  apostrophe, la typographique « ’ » (U+2019) ;
- un renvoi à un chapitre (``{doc}`` sans texte) cite son titre entre guillemets : « … » ;
- les locutions latines *a priori* et *a posteriori* en italique (:func:`italicize_latin`) ;
- les mêmes règles dans les étiquettes des diagrammes Mermaid (:func:`typeset_mermaid`).

À déclarer dans ``_config.yml`` (``sphinx: extra_extensions``), avec ``smartquotes: false`` : les
« guillemets intelligents » de docutils devinent mal l'apostrophe placée devant un mot en gras ou un
lien (« l” » au lieu de « l’ ») ; ce module la traite à leur place, sans deviner.
"""

from __future__ import annotations

import re

from ..typography import LATIN, NBSP, apply_rules, french_spacing

__all__ = ["typeset", "italicize_latin", "quote_document_titles", "typeset_mermaid", "setup"]


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


def _inside(node, classes) -> bool:
    """``node`` ou l'un de ses ancêtres est-il de l'une des ``classes`` (code, formule, HTML brut…) ?"""
    while node is not None:
        if isinstance(node, classes):
            return True
        node = node.parent
    return False


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
        if _inside(parent, skipped):
            continue
        old = str(node)
        new = apply_rules(old)
        if new != old:
            parent.replace(node, nodes.Text(new))
            changed += 1
    from sphinx import addnodes

    for toctree in document.findall(addnodes.toctree):  # titres des parties (barre latérale)
        if toctree.get("caption"):
            toctree["caption"] = french_spacing(toctree["caption"])
    return changed


#: Texte d'une étiquette de diagramme Mermaid : entre guillemets droits (``A["…"]``, ``-->|"…"|``).
_MERMAID_LABEL = re.compile(r'"([^"\n]*)"')


def typeset_mermaid(document) -> int:
    """Applique les règles aux étiquettes des diagrammes Mermaid (le code du diagramme est un attribut
    du nœud, que :func:`typeset` ne voit pas) ; seul le texte entre guillemets change, jamais la syntaxe
    (« style A fill:#fff ») ; *a priori* et *a posteriori* y passent en italique (``<i>``). Renvoie le
    nombre de diagrammes modifiés."""
    changed = 0
    for node in document.findall(lambda n: getattr(n, "tagname", "") == "mermaid" and "code" in n.attributes):
        old = node["code"]
        new = _MERMAID_LABEL.sub(lambda m: '"' + _LATIN_HTML.sub(r"<i>\1</i>", apply_rules(m.group(1))) + '"', old)
        if new != old:
            node["code"] = new
            changed += 1
    return changed


#: La même, dans une étiquette HTML (Mermaid) : pas déjà entre ``<i>`` et ``</i>``.
_LATIN_HTML = re.compile(r"(?<![\w-])(?<!<i>)(a (?:priori|posteriori))(?![\w-])")


def italicize_latin(document) -> int:
    """Met en italique les locutions latines (*a priori*, *a posteriori*) du texte courant de
    ``document`` : pas dans le code, les formules, le HTML brut, ni dans un texte déjà en italique.
    Renvoie le nombre de locutions mises en italique."""
    from docutils import nodes

    skipped = _skipped_classes() + (nodes.emphasis,)
    changed = 0
    for node in list(document.findall(nodes.Text)):
        parent = node.parent
        if parent is None or not LATIN.search(str(node)):
            continue
        if _inside(parent, skipped):
            continue
        pieces = []
        for i, part in enumerate(LATIN.split(str(node))):
            if i % 2:
                pieces.append(nodes.emphasis(part, part))
                changed += 1
            elif part:
                pieces.append(nodes.Text(part))
        index = parent.index(node)
        parent.remove(node)
        for offset, piece in enumerate(pieces):
            parent.insert(index + offset, piece)
    return changed


def quote_document_titles(document, env) -> int:
    """Les renvois ``{doc}`` sans texte explicite citent le titre du chapitre entre guillemets français :
    « le chapitre « Lissage… » », jamais « le Le filtre… » (un titre cité se met entre guillemets, et
    l'article de la phrase ne bute plus sur celui du titre). Renvoie le nombre de renvois modifiés."""
    from docutils import nodes
    from sphinx import addnodes
    from sphinx.util import docname_join
    from sphinx.util.nodes import clean_astext

    changed = 0
    for ref in list(document.findall(addnodes.pending_xref)):
        if ref.get("refdomain") != "std" or ref.get("reftype") != "doc" or ref.get("refexplicit"):
            continue
        docname = docname_join(ref.get("refdoc", env.docname), ref["reftarget"])
        if docname not in env.titles:
            continue  # renvoi cassé : Sphinx le signale lui-même
        quoted = "«" + NBSP + clean_astext(env.titles[docname]) + NBSP + "»"
        inner = nodes.inline(quoted, quoted, classes=["xref", "std", "std-doc"])
        ref.children = []
        ref += inner
        ref["refexplicit"] = True
        changed += 1
    return changed


def _transforms():
    from sphinx.transforms import SphinxTransform
    from sphinx.transforms.post_transforms import SphinxPostTransform

    class QuotedDocumentTitles(SphinxPostTransform):
        """Avant la résolution des renvois (priorité 10) : titres de chapitres cités entre « »."""

        default_priority = 5

        def run(self, **kwargs) -> None:
            quote_document_titles(self.document, self.env)

    class FrenchTypography(SphinxTransform):
        """À la lecture : les titres (table des matières, liens « suivant ») en profitent aussi."""

        default_priority = 760  # après les transformations de docutils et de Sphinx sur le texte

        def apply(self, **kwargs) -> None:
            italicize_latin(self.document)
            typeset(self.document)
            typeset_mermaid(self.document)

    class FrenchTypographyLate(SphinxPostTransform):
        """À l'écriture : texte résolu après la lecture (références, nombres collés d'autres pages)."""

        default_priority = 900

        def run(self, **kwargs) -> None:
            italicize_latin(self.document)  # textes résolus : titres cités par {ref}, nombres collés…
            typeset(self.document)

    return FrenchTypography, FrenchTypographyLate, QuotedDocumentTitles


def _check_smartquotes(app, config) -> None:
    if config.smartquotes:
        from sphinx.errors import ConfigError

        raise ConfigError(
            "kalman_course.sphinx.typography traite lui-même apostrophes et guillemets : mettez "
            "« smartquotes: false » sous « sphinx: config: » dans _config.yml."
        )


def setup(app):
    early, late, quoted = _transforms()
    app.add_transform(early)
    app.add_post_transform(late)
    app.add_post_transform(quoted)
    app.connect("config-inited", _check_smartquotes)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
