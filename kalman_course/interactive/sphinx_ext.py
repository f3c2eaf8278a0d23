"""Extension Sphinx du livre : BokehJS servi par le site, boutons de lancement sans lien mort.

À déclarer dans ``_config.yml`` (``sphinx: extra_extensions: [kalman_course.interactive.sphinx_ext]``).

1. **BokehJS, une fois par page, seulement où il sert.** Les figures à curseurs statiques
   (:mod:`.static`) ne contiennent pas BokehJS. Sur chaque page dont le corps contient une telle figure
   (attribut :data:`~.static.MARKER`), l'extension ajoute à l'en-tête les scripts
   ``_static/bokeh/bokeh-<version>.min.js`` et ``bokeh-widgets-<version>.min.js`` (une fois, même avec
   plusieurs figures ; chemin relatif calculé par Sphinx, valable en ``http://`` et en ``file://``).
   Au démarrage, elle vérifie que ces fichiers, copiés par ``scripts/vendor_assets.py`` dans un
   dossier de ``html_static_path``, sont identiques à ceux du paquet Python ``bokeh`` installé.

2. **Boutons de lancement (Binder, JupyterHub, Colab) sans lien mort.** Ils dépendent tous de
   ``repository: url:`` dans ``_config.yml``, le seul réglage à renseigner. Tant qu'il est vide (ou
   vaut l'URL par défaut de Jupyter Book, qui pointerait vers le projet jupyter-book lui-même), les
   boutons de lancement sont retirés, mais le téléchargement du carnet exécuté (``.ipynb``) reste
   proposé sur chaque chapitre. Colab n'ouvre que des ``.ipynb`` hébergés sur GitHub : sur une page
   dont la source est un ``.md`` MyST sans ``.ipynb`` jumeau, le bouton Colab est retiré.

3. **Figures à curseurs dans le PDF.** Une figure à curseurs statiques fournit, à côté de son HTML,
   une image PNG (position par défaut des curseurs) et une légende (attribut
   :data:`~.static.CAPTION_ATTRIBUTE`). Pour le constructeur LaTeX, avant que myst-nb ne choisisse
   l'image dans la sortie de la cellule, l'extension place cette sortie dans une figure légendée.
   Une figure à curseurs sans image de repli est un avertissement (donc une erreur avec ``-W``).
"""

from __future__ import annotations

import html
import re
import shutil
from pathlib import Path

from docutils import nodes
from sphinx.errors import ExtensionError
from sphinx.transforms.post_transforms import SphinxPostTransform
from sphinx.util import logging

from .static import BOKEH_VERSION, CAPTION_ATTRIBUTE, MARKER, bokehjs_files

__all__ = ["setup", "installed_bokehjs", "JUPYTER_BOOK_DEFAULT_REPOSITORY"]

LOGGER = logging.getLogger(__name__)

#: URL mise par Jupyter Book 1 quand ``repository: url:`` n'est pas donné.
JUPYTER_BOOK_DEFAULT_REPOSITORY = "https://github.com/executablebooks/jupyter-book"
#: Clés de ``launch_buttons`` qui créent un bouton pointant vers le dépôt.
LAUNCH_PROVIDERS = ("binderhub_url", "jupyterhub_url", "colab_url", "deepnote_url", "jupyterlite_url", "thebe")


def installed_bokehjs() -> dict[str, Path]:
    """Fichiers BokehJS du paquet Python ``bokeh`` installé : nom servi → chemin source."""
    from bokeh.util.paths import bokehjs_path

    js = Path(bokehjs_path()) / "js"
    sources = [js / "bokeh.min.js", js / "bokeh-widgets.min.js"]
    return dict(zip(bokehjs_files(), sources))


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


def _guard_launch_buttons(app, config) -> None:
    options = config.html_theme_options
    launch = dict(options.get("launch_buttons") or {})
    url = str(options.get("repository_url", "") or "").strip().rstrip("/")
    if url and url != JUPYTER_BOOK_DEFAULT_REPOSITORY:
        return
    if any(launch.get(key) for key in LAUNCH_PROVIDERS):
        LOGGER.info(
            "[kalman_course] « repository: url: » n'est pas renseigné dans _config.yml : boutons de "
            "lancement (Binder, JupyterHub, Colab) désactivés, téléchargement .ipynb conservé."
        )
    options["launch_buttons"] = {k: v for k, v in launch.items() if k not in LAUNCH_PROVIDERS}
    config.kc_ipynb_download = True


def _ipynb_download(app, pagename, templatename, context, doctree) -> None:
    """Sans bouton de lancement, le thème ne copie pas le carnet exécuté : on le fait ici (même
    emplacement que le thème : ``_sources/<page>.ipynb``) pour garder le bouton « .ipynb »."""
    if not app.config.kc_ipynb_download:
        return
    if "kernelspec" not in app.env.metadata.get(pagename, {}):
        return
    source = Path(app.outdir).parent / "jupyter_execute" / f"{pagename}.ipynb"
    if not source.is_file():
        return
    target = Path(app.outdir) / "_sources" / f"{pagename}.ipynb"
    target.parent.mkdir(parents=True, exist_ok=True)
    shutil.copy2(source, target)
    context["ipynb_source"] = f"{pagename}.ipynb"


def _drop_colab_for_markdown(app, pagename, templatename, context, doctree) -> None:
    source = Path(app.env.doc2path(pagename))
    if source.suffix == ".ipynb" or source.with_suffix(".ipynb").exists():
        return
    for group in context.get("header_buttons", []):
        if group.get("label") == "launch-buttons":
            group["buttons"] = [b for b in group["buttons"] if b.get("text") != "Colab"]
    context["header_buttons"] = [
        g for g in context.get("header_buttons", []) if g.get("label") != "launch-buttons" or g["buttons"]
    ]


def _drop_duplicate_inline_scripts(app, pagename, templatename, context, doctree) -> None:
    """sphinx-thebe (chargée d'office par Jupyter Book) ajoute deux fois son script en ligne
    « const THEBE_JS_URL = … » : la seconde déclaration d'une même constante est une erreur de page.
    On garde une seule copie de chaque script en ligne identique."""
    seen: set[str] = set()
    kept = []
    for script in context.get("script_files", []):
        body = getattr(script, "attributes", {}).get("body") if not isinstance(script, str) else None
        if body:
            if body in seen:
                continue
            seen.add(body)
        kept.append(script)
    context["script_files"] = kept


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
    app.add_config_value("kc_ipynb_download", False, "html", types=[bool])
    app.connect("config-inited", _guard_launch_buttons, priority=900)
    app.connect("builder-inited", _check_bokehjs)
    app.connect("html-page-context", _add_bokehjs)
    # le thème construit ses boutons à la priorité 501 : le carnet doit être copié avant (500),
    # le bouton Colab retiré après (502)
    app.connect("html-page-context", _ipynb_download, priority=500)
    app.connect("html-page-context", _drop_colab_for_markdown, priority=502)
    app.connect("html-page-context", _drop_duplicate_inline_scripts, priority=900)
    app.add_post_transform(StaticSlidersForLatex)
    return {"version": BOKEH_VERSION, "parallel_read_safe": True, "parallel_write_safe": True}
