r"""Extension Sphinx du livre : les encadrés de sphinx-proof en français, sur le site et dans le PDF.

À déclarer dans ``_config.yml`` après ``sphinx_proof`` (``sphinx: extra_extensions``).

- **Démonstrations** (``{prf:proof}``) : sphinx-proof écrit « Proof. » en tête de la première ligne, en
  anglais, et ne donne pas de titre à l'encadré. Ici, l'encadré reçoit le titre « Démonstration » et perd
  le « Proof. » ; avec ``:class: dropdown``, il est replié (sphinx-togglebutton, dont le bouton est le
  titre de l'encadré). Le symbole ∎ clôt la démonstration (□ dans le PDF, dont les polices n'ont pas ∎) :

  .. code-block:: markdown

      ```{prf:proof}
      :class: dropdown

      Par Fubini, …
      ```

- **Algorithmes** (``{prf:algorithm}``) dans le PDF : sphinx-proof traduit « Algorithm » sur le site
  (« Algorithme 7 ») mais pas dans le LaTeX ; l'écriture LaTeX de ses encadrés numérotés passe ici par
  le même catalogue de traductions.
"""

from __future__ import annotations

__all__ = ["setup", "PROOF_TITLE", "french_proofs"]

#: Le titre d'un encadré ``prf:proof``.
PROOF_TITLE = "Démonstration"
#: Le préfixe que sphinx-proof écrit en tête de la première ligne d'une démonstration.
_PREFIX = "Proof. "


def french_proofs(document) -> int:
    """Donne à chaque encadré de démonstration de ``document`` le titre :data:`PROOF_TITLE` et retire le
    préfixe anglais « Proof. » de sa première ligne ; renvoie le nombre d'encadrés traités."""
    from docutils import nodes
    from sphinx_proof.nodes import proof_node

    changed = 0
    for proof in document.findall(proof_node):
        for box in proof.children:
            if not isinstance(box, nodes.admonition) or "proof" not in box["classes"]:
                continue
            if not any(isinstance(c, nodes.title) for c in box.children):
                box.insert(0, nodes.title(PROOF_TITLE, PROOF_TITLE))
                paragraphs = list(box.findall(nodes.paragraph))
                if paragraphs:  # le symbole de fin, une fois (l'encadré vient de recevoir son titre)
                    paragraphs[-1] += nodes.raw("", " ∎", format="html")
                    paragraphs[-1] += nodes.raw("", r"\hfill\(\square\)", format="latex")
            if box["ids"] == ["proof"]:  # sphinx-proof donne à toutes le même identifiant : un par encadré
                box["ids"] = []
                document.set_id(box, suggested_prefix="demonstration")
            first = next(iter(box.findall(nodes.Text)), None)
            if first is not None and isinstance(first.parent, nodes.title):
                texts = [t for t in box.findall(nodes.Text) if not isinstance(t.parent, nodes.title)]
                first = texts[0] if texts else None
            if first is not None and str(first).startswith(_PREFIX):
                rest = str(first)[len(_PREFIX):]
                if rest:
                    first.parent.replace(first, nodes.Text(rest))
                else:
                    first.parent.remove(first)
            changed += 1
    return changed


def _transform():
    from sphinx.transforms import SphinxTransform

    class FrenchProofs(SphinxTransform):
        """À la lecture, après les directives : titres et premières lignes des démonstrations."""

        default_priority = 500

        def apply(self, **kwargs) -> None:
            french_proofs(self.document)

    return FrenchProofs


def _depart_enumerable_latex(self, node) -> None:
    """Fin d'un encadré numéroté (algorithme…) : celle de sphinx-proof, titre traduit dans le LaTeX aussi."""
    from sphinx.writers.latex import LaTeXTranslator
    from sphinx_proof import nodes as proof_nodes

    if not isinstance(self, LaTeXTranslator):
        proof_nodes.depart_enumerable_node(self, node)
        return
    realtyp = node.attributes.get("realtype", "")
    number = proof_nodes.get_node_number(self, node, node.attributes.get("countertype", ""))
    idx = proof_nodes.list_rindex(self.body, proof_nodes.latex_admonition_start) + 2
    title = proof_nodes._(realtyp.title())
    self.body.insert(idx, f"{title} {number}".strip())
    self.body.append(proof_nodes.latex_admonition_end)


def setup(app):
    app.setup_extension("sphinx_proof")
    from sphinx_proof import nodes as proof_nodes

    for node in proof_nodes.NODE_TYPES.values():  # les encadrés numérotés de sphinx-proof
        app.add_node(node, override=True,
                     html=(proof_nodes.visit_enumerable_node, proof_nodes.depart_enumerable_node),
                     latex=(proof_nodes.visit_enumerable_node, _depart_enumerable_latex))
    app.add_transform(_transform())
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
