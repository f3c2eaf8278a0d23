r"""Extraits du code du paquet dans le livre, sans leur docstring (extension Sphinx).

La directive ``{kc-source}`` montre une fonction du paquet telle qu'elle est au moment de la
construction, comme ``literalinclude`` avec ``:pyobject:``, mais **sans sa docstring** : celle-ci
porte la documentation en reStructuredText (``:math:``, ``.. math::``, ``:func:``…), illisible dans un
bloc de code, et la page dit déjà en prose ce que fait la fonction. Le nom de la fonction et son
fichier sont donnés en légende.

.. code-block:: markdown

    ```{kc-source} kalman_course.core.linalg.kalman_gain
    ```
"""

from __future__ import annotations

import ast
import importlib
import inspect
import textwrap
from pathlib import Path

__all__ = ["source_without_docstring", "setup"]


def _resolve(dotted: str):
    parts = dotted.split(".")
    for cut in range(len(parts) - 1, 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for attr in parts[cut:]:
            obj = getattr(obj, attr)
        return obj
    raise ImportError(dotted)


def source_without_docstring(dotted: str) -> tuple[str, Path]:
    """Le code source de l'objet ``dotted`` (« module.fonction »), docstring retirée, et son fichier."""
    obj = _resolve(dotted)
    source = textwrap.dedent(inspect.getsource(obj))
    tree = ast.parse(source)
    definition = tree.body[0]
    body = getattr(definition, "body", [])
    lines = source.splitlines(keepends=True)
    if body and isinstance(body[0], ast.Expr) and isinstance(getattr(body[0], "value", None), ast.Constant) \
            and isinstance(body[0].value.value, str):
        doc = body[0]
        lines[doc.lineno - 1:doc.end_lineno] = []
    return "".join(lines).rstrip() + "\n", Path(inspect.getsourcefile(obj))


def _directive():
    from docutils import nodes
    from sphinx.directives.code import container_wrapper
    from sphinx.util.docutils import SphinxDirective

    class PackageSource(SphinxDirective):
        """``{kc-source} module.fonction`` : la fonction, sans docstring, avec son fichier en légende."""

        required_arguments = 1
        has_content = False

        def run(self):
            dotted = self.arguments[0]
            try:
                code, path = source_without_docstring(dotted)
            except (ImportError, AttributeError, TypeError, OSError) as exc:
                raise self.error(f"kc-source : « {dotted} » introuvable dans le paquet ({exc}).") from None
            self.env.note_dependency(str(path))
            block = nodes.literal_block(code, code, language="python")
            root = Path(importlib.import_module("kalman_course").__file__).parent.parent
            try:
                shown = path.relative_to(root).as_posix()
            except ValueError:
                shown = path.name
            caption = f"{dotted.rsplit('.', 1)[-1]} — {shown}"
            self.set_source_info(block)
            return [container_wrapper(self, block, caption)]

    return PackageSource


def setup(app):
    app.add_directive("kc-source", _directive())
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
