"""Extension Sphinx du livre : boutons de lancement (Binder, JupyterHub, Colab) sans lien mort.

À déclarer dans ``_config.yml`` (``sphinx: extra_extensions: [kalman_course.sphinx.launch_buttons]``).

Les boutons dépendent tous de ``repository: url:`` dans ``_config.yml``, le seul réglage à renseigner.
Tant qu'il est vide (ou vaut l'URL par défaut de Jupyter Book, qui pointerait vers le projet
jupyter-book lui-même), les boutons de lancement sont retirés, mais le téléchargement du carnet exécuté
(``.ipynb``) reste proposé sur chaque chapitre. Colab n'ouvre que des ``.ipynb`` hébergés sur GitHub :
sur une page dont la source est un ``.md`` MyST sans ``.ipynb`` jumeau, le bouton Colab est retiré.

sphinx-thebe (le code exécutable dans la page, chargé d'office par Jupyter Book) ajoute deux fois son
script en ligne : l'extension n'en garde qu'une copie.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from sphinx.util import logging

__all__ = ["setup", "JUPYTER_BOOK_DEFAULT_REPOSITORY"]

LOGGER = logging.getLogger(__name__)

#: URL mise par Jupyter Book 1 quand ``repository: url:`` n'est pas donné.
JUPYTER_BOOK_DEFAULT_REPOSITORY = "https://github.com/executablebooks/jupyter-book"
#: Clés de ``launch_buttons`` qui créent un bouton pointant vers le dépôt.
LAUNCH_PROVIDERS = ("binderhub_url", "jupyterhub_url", "colab_url", "deepnote_url", "jupyterlite_url", "thebe")


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


def setup(app):
    app.add_config_value("kc_ipynb_download", False, "html", types=[bool])
    app.connect("config-inited", _guard_launch_buttons, priority=900)
    # le thème construit ses boutons à la priorité 501 : le carnet doit être copié avant (500),
    # le bouton Colab retiré après (502)
    app.connect("html-page-context", _ipynb_download, priority=500)
    app.connect("html-page-context", _drop_colab_for_markdown, priority=502)
    app.connect("html-page-context", _drop_duplicate_inline_scripts, priority=900)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
