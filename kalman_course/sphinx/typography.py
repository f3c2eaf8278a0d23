r"""Typographie française du livre, appliquée une fois pour toutes à la construction (extension Sphinx).

Les règles (espaces insécables avant « : ; ! ? % » et dans « », apostrophe « ’ ») sont celles de
:mod:`kalman_course.typography` ; cette extension les applique au texte courant de chaque page, jamais
dans le code, les formules ou le HTML brut.

À déclarer dans ``_config.yml`` (``sphinx: extra_extensions``), avec ``smartquotes: false`` : les
« guillemets intelligents » de docutils devinent mal l'apostrophe placée devant un mot en gras ou un
lien (« l” » au lieu de « l’ ») ; ce module la traite à leur place, sans deviner.
"""

from __future__ import annotations

from ..typography import apply_rules, french_spacing

__all__ = ["typeset", "setup"]


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
        new = apply_rules(old)
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
            "kalman_course.sphinx.typography traite lui-même apostrophes et guillemets : mettez "
            "« smartquotes: false » sous « sphinx: config: » dans _config.yml."
        )


def setup(app):
    early, late = _transforms()
    app.add_transform(early)
    app.add_post_transform(late)
    app.connect("config-inited", _check_smartquotes)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
