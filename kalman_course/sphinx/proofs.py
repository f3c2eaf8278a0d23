r"""Extension Sphinx du livre : les démonstrations, repliées et titrées en français.

À déclarer dans ``_config.yml`` (``sphinx: extra_extensions: [kalman_course.sphinx.proofs]``), après
``sphinx_proof``.

La directive ``{prf:proof}`` de sphinx-proof écrit un encadré sans titre et met « Proof. » en tête de son
premier paragraphe, sans le traduire. Le livre écrit ses démonstrations ainsi :

.. code-block:: md

    ```{prf:proof}
    :class: dropdown

    …
    ```

et l'extension, à la lecture de chaque page, retire « Proof. » et donne à l'encadré le titre
« Démonstration » : sur le site, l'encadré est replié derrière ce titre (sphinx-togglebutton, classe
``dropdown``) ; dans le PDF, il est imprimé en entier sous ce titre. Le symbole ∎ (□ dans le PDF, dont les
polices n'ont pas ∎) clôt la démonstration.
"""

from __future__ import annotations

from docutils import nodes

__all__ = ["setup", "TITLE"]

#: Titre des démonstrations.
TITLE = "Démonstration"
_PREFIX = "Proof. "


def _retitle(app, doctree) -> None:
    from sphinx_proof.nodes import proof_node

    for proof in doctree.findall(proof_node):
        for box in proof.findall(nodes.admonition):
            if box.children and isinstance(box.children[0], nodes.title):
                continue
            first = next(iter(box.findall(nodes.Text)), None)
            if first is not None and first.astext().startswith(_PREFIX):
                first.parent.replace(first, nodes.Text(first.astext()[len(_PREFIX):]))
            box.insert(0, nodes.title(TITLE, TITLE))
            last = [p for p in box.findall(nodes.paragraph)]
            if last:  # le symbole de fin : ∎ sur le site ; carré d'amssymb dans le PDF (∎ manque aux polices)
                last[-1] += nodes.raw("", " ∎", format="html")
                last[-1] += nodes.raw("", r"\hfill\(\square\)", format="latex")
            break


def setup(app):
    app.setup_extension("sphinx_proof")
    app.connect("doctree-read", _retitle)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
