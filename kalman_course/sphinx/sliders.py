"""Extension Sphinx du livre : figures à curseurs statiques (BokehJS servi par le site, image du PDF).

À déclarer dans ``_config.yml`` (``sphinx: extra_extensions: [kalman_course.sphinx.sliders]``).

1. **BokehJS, une fois par page, seulement où il sert.** Les figures à curseurs statiques
   (:mod:`kalman_course.interactive.static`) ne contiennent pas BokehJS. Sur chaque page dont le corps
   contient une telle figure (attribut :data:`~kalman_course.interactive.static.MARKER`), l'extension
   ajoute à l'en-tête les scripts ``_static/bokeh/bokeh-<version>.min.js`` et
   ``bokeh-widgets-<version>.min.js`` (une fois, même avec plusieurs figures ; chemin relatif calculé
   par Sphinx, valable en ``http://`` et en ``file://``). Au démarrage, elle vérifie que ces fichiers,
   copiés par ``scripts/vendor_assets.py`` dans un dossier de ``html_static_path``, sont identiques à
   ceux du paquet Python ``bokeh`` installé.

2. **Figures à curseurs dans le PDF.** Une figure à curseurs statiques fournit, à côté de son HTML,
   une image PNG (position par défaut des curseurs) et une légende (attribut
   :data:`~kalman_course.interactive.static.CAPTION_ATTRIBUTE`). Pour le constructeur LaTeX, avant que
   myst-nb ne choisisse l'image dans la sortie de la cellule, l'extension place cette sortie dans une
   figure légendée. Une figure à curseurs sans image de repli est un avertissement (donc une erreur
   avec ``-W``).
"""

from __future__ import annotations

import html
import re
from pathlib import Path

from docutils import nodes
from sphinx.errors import ExtensionError
from sphinx.transforms.post_transforms import SphinxPostTransform
from sphinx.util import logging

from ..interactive.static import BOKEH_VERSION, CAPTION_ATTRIBUTE, MARKER, bokehjs_files, installed_bokehjs

__all__ = ["setup"]

LOGGER = logging.getLogger(__name__)


def _check_bokehjs(app) -> None:
    if app.builder.format != "html":
        return
    static_dirs = [Path(app.confdir, p) for p in app.config.html_static_path]
    for served, source in installed_bokehjs().items():
        candidates = [d / served for d in static_dirs if (d / served).is_file()]
        if not candidates:
            raise ExtensionError(
                f"BokehJS {BOKEH_VERSION} introuvable : « {served} » n'est dans aucun dossier de "
                f"html_static_path ({', '.join(map(str, app.config.html_static_path))}). "
                "Lancez « python scripts/vendor_assets.py »."
            )
        if candidates[0].read_bytes() != source.read_bytes():
            raise ExtensionError(
                f"« {candidates[0]} » diffère du BokehJS du paquet bokeh {BOKEH_VERSION} installé : "
                "relancez « python scripts/vendor_assets.py »."
            )


def _add_bokehjs(app, pagename, templatename, context, doctree) -> None:
    if MARKER in context.get("body", ""):
        for served in bokehjs_files():
            app.add_js_file(served)


class StaticSlidersForLatex(SphinxPostTransform):
    """LaTeX : la sortie d'une figure à curseurs statiques devient une figure légendée dont l'image est
    le PNG de repli. S'exécute avant le choix du type MIME par myst-nb (priorité 4)."""

    default_priority = 3
    builders = ("latex",)

    def run(self, **kwargs) -> None:
        for bundle in list(self.document.findall(nodes.container)):
            if bundle.get("nb_element") != "mime_bundle":
                continue
            by_type = {child.get("mime_type"): child for child in bundle.children}
            html_part = by_type.get("text/html")
            if html_part is None or MARKER not in html_part.astext():
                continue
            if "image/png" not in by_type:
                LOGGER.warning(
                    "[kalman_course] figure à curseurs statiques sans image PNG de repli : elle manquerait "
                    "au PDF (relancer l'exécution du carnet).",
                    location=bundle,
                )
                continue
            found = re.search(CAPTION_ATTRIBUTE + r'="([^"]*)"', html_part.astext())
            caption = html.unescape(found.group(1)) if found else ""
            figure = nodes.figure(classes=["kc-static-sliders"])
            figure.source, figure.line = bundle.source, bundle.line
            bundle.replace_self(figure)
            figure += bundle
            if caption:
                figure += nodes.caption(caption, caption)


def setup(app):
    app.connect("builder-inited", _check_bokehjs)
    app.connect("html-page-context", _add_bokehjs)
    app.add_post_transform(StaticSlidersForLatex)
    return {"version": BOKEH_VERSION, "parallel_read_safe": True, "parallel_write_safe": True}
