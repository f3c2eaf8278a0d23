r"""Extension Sphinx du livre : les travaux pratiques sur l'ordinateur de l'étudiant, depuis le site lui-même.

À déclarer dans ``_config.yml`` (``sphinx: extra_extensions: [kalman_course.sphinx.workspace]``).

**Ce que le site sert.** À la fin de la construction HTML, le dossier ``travaux-pratiques/`` du site reçoit :

- la **roue** du paquet, ``kalman_course-<version>-py3-none-any.whl``, construite à partir de l'arbre même qui
  construit le livre (``pyproject.toml`` et ``kalman_course/`` copiés dans un dossier temporaire, puis
  ``setuptools.build_meta.build_wheel`` : hors ligne, sans isolation, avec le setuptools figé de
  ``requirements.txt`` ; date des fichiers fixée par ``SOURCE_DATE_EPOCH`` : mêmes octets à chaque
  construction) ;
- ``contraintes.txt`` : les versions figées de ``requirements.txt``, celles avec lesquelles le livre et le
  paquet sont vérifiés (``pip install -c``) ;
- les **carnets à compléter** (``book/travaux-pratiques/*.ipynb``, ``tp1-…`` à ``tp5-…``).

**La directive** ``{comment-travailler}`` (sans argument, dans une page ``book/tp-*.md``) écrit l'encadré
« Comment travailler » : le carnet à télécharger ; les commandes pour un ordinateur avec Python 3.11 à 3.13
(environnement virtuel, ``pip install`` de la roue **depuis ce site**, ``jupyter lab``) ; et, quand
``_config.yml`` nomme un dépôt (``repository: url:``), ``bash scripts/lab.sh`` depuis une copie du dépôt et le
lien Binder (et JupyterHub si ``launch_buttons: jupyterhub_url:`` est donné). Les commandes portent
l'adresse ``ADRESSE-DU-COURS`` : dans la page, un petit script la remplace par l'adresse de la racine du
site, calculée depuis l'adresse de la page elle-même (``document.baseURI``) — le site
publié n'importe où, ou une copie locale ouverte depuis le disque (``file://`` : un chemin de fichier,
que pip accepte). Dans le PDF, les commandes gardent ``ADRESSE-DU-COURS`` et une phrase dit par quoi la
remplacer.
"""

from __future__ import annotations

import os
import posixpath
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from docutils import nodes
from sphinx import addnodes
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective

__all__ = ["setup", "PLACEHOLDER", "CONSTRAINTS", "build_wheel", "commands", "repository_links"]

LOGGER = logging.getLogger(__name__)

#: Ce que le script de la page remplace par l'adresse du site.
PLACEHOLDER = "ADRESSE-DU-COURS"
#: Nom du fichier des versions figées servi à côté de la roue.
CONSTRAINTS = "contraintes.txt"
#: Date des fichiers de la roue (1ᵉʳ janvier 2026) : mêmes octets d'une construction à l'autre.
SOURCE_DATE_EPOCH = "1767225600"
#: Nom de l'environnement virtuel des commandes.
VENV = "tp-kalman"

_SCRIPT = """<script>(function () {
  var box = document.currentScript.parentNode;
  var root = new URL(%s, document.baseURI);
  var base = root.href.replace(/\\/$/, "");
  if (root.protocol === "file:") {
    base = decodeURIComponent(root.pathname).replace(/\\/$/, "");
    if (/^\\/[A-Za-z]:\\//.test(base)) { base = base.slice(1); }
  }
  box.querySelectorAll("pre").forEach(function (pre) {
    var walker = document.createTreeWalker(pre, NodeFilter.SHOW_TEXT);
    for (var node = walker.nextNode(); node; node = walker.nextNode()) {
      if (node.nodeValue.indexOf(%s) >= 0) { node.nodeValue = node.nodeValue.split(%s).join(base); }
    }
  });
  box.querySelectorAll(".kc-adresse").forEach(function (span) {
    span.textContent = "Les adresses ont été remplies d\u2019après celle de cette page\u00a0: " + base + "/.";
  });
})();</script>"""


def commands(notebook: str, wheel: str) -> str:
    """Les commandes d'un ordinateur Linux ou macOS, adresse du site laissée à ``ADRESSE-DU-COURS``."""
    folder = f"{PLACEHOLDER}/travaux-pratiques"
    return (f"python3 -m venv {VENV}\n"
            f"source {VENV}/bin/activate\n"
            f'python -m pip install -c "{folder}/{CONSTRAINTS}" "{folder}/{wheel}"\n'
            f'python -m pip install -c "{folder}/{CONSTRAINTS}" jupyterlab jupyterlab-language-pack-fr-fr\n'
            f"jupyter lab {notebook}")


def repository_links(config) -> dict[str, str]:
    """Le dépôt (``url``), son lien Binder (``binder``) et JupyterHub (``jupyterhub``) d'après
    ``_config.yml`` ; vide si aucun dépôt n'est nommé."""
    from .launch_buttons import JUPYTER_BOOK_DEFAULT_REPOSITORY

    options = config.html_theme_options or {}
    url = str(options.get("repository_url", "") or "").strip().rstrip("/")
    if not url or url == JUPYTER_BOOK_DEFAULT_REPOSITORY:
        return {}
    branch = str(options.get("repository_branch", "") or "main")
    links = {"url": url}
    launch = dict(options.get("launch_buttons") or {})
    if url.startswith("https://github.com/"):
        binder = str(launch.get("binderhub_url") or "https://mybinder.org").rstrip("/")
        links["binder"] = f"{binder}/v2/gh/{url.removeprefix('https://github.com/')}/{branch}"
    hub = str(launch.get("jupyterhub_url") or "").rstrip("/")
    if hub:
        links["jupyterhub"] = hub
    return links


def _paragraph(*parts) -> nodes.paragraph:
    para = nodes.paragraph()
    for part in parts:
        para += nodes.Text(part) if isinstance(part, str) else part
    return para


def _code(text: str) -> nodes.literal:
    return nodes.literal(text, text)


def _link(text: str, url: str) -> nodes.reference:
    return nodes.reference(text, text, refuri=url)


class WorkspaceDirective(SphinxDirective):
    """``{comment-travailler}`` : l'encadré « Comment travailler » d'une page de TP."""

    has_content = False
    required_arguments = 0

    def run(self):
        from ..practice import wheel_name
        from ..practice.notebooks import WHEEL_FOLDER, notebook_name

        page = Path(self.env.doc2path(self.env.docname))
        notebook = notebook_name(page)
        wheel = wheel_name()
        box = nodes.admonition(classes=["tip", "kc-comment-travailler"])
        box += nodes.title("Comment travailler", "Comment travailler")
        local = f"{WHEEL_FOLDER}/{notebook}"
        download = addnodes.download_reference("", "", reftarget=local, refdoc=self.env.docname, refexplicit=True,
                                               refdomain="", reftype="download")
        download += _code(notebook)
        box += _paragraph(
            nodes.strong("", "Le carnet à compléter : "), download,
            " (les mêmes énoncés, sans les solutions). Complétez chaque ", _code("# À vous"), ", exécutez la "
            "cellule, puis la vérification ", _code("practice.check(...)"), " qui la suit : le correcteur essaie "
            "votre fonction sur des cas cachés et répond en français. Sur cette page, les solutions sont "
            "repliées : essayez d'abord !")
        box += _paragraph(
            nodes.strong("", "Sur votre ordinateur"), " (Python ", _code("3.11"), ", ", _code("3.12"), " ou ",
            _code("3.13"), "), dans le dossier où vous avez enregistré le carnet : un environnement virtuel, le "
            "paquet du cours (depuis ce site), puis JupyterLab en français, aux versions avec lesquelles le cours "
            "est vérifié.")
        block = nodes.literal_block(commands(notebook, wheel), commands(notebook, wheel), language="text")
        box += block
        note = nodes.inline("", "", classes=["kc-adresse"])
        note += nodes.Text(f"{PLACEHOLDER} est l'adresse du site du cours, sans le nom de la page (par exemple "
                           f"https://…/filtre-de-kalman) : sur le site, la page la remplit elle-même.")
        box += _paragraph(note, " Sous Windows : ", _code(f"py -m venv {VENV}"), " puis ",
                          _code(f"{VENV}\\Scripts\\activate"), ". Une fois installé, chaque séance reprend par ",
                          _code(f"source {VENV}/bin/activate"), " puis ", _code("jupyter lab"), ".")
        links = repository_links(self.config)
        if links:
            para = _paragraph(nodes.strong("", "Depuis une copie du dépôt"), " (", _code(f"git clone {links['url']}"),
                              ") : ", _code("bash scripts/lab.sh"), " installe ce qu'il faut et ouvre JupyterLab "
                              "sur vos carnets, hors ligne.")
            online = [(name, links[key]) for key, name in (("binder", "Binder"), ("jupyterhub", "JupyterHub"))
                      if key in links]
            if online:
                para += nodes.Text(" Sans rien installer : ")
                for i, (name, url) in enumerate(online):
                    if i:
                        para += nodes.Text(" ou ")
                    para += _link(name, url)
                para += nodes.Text(" (les carnets sont dans le dossier book/travaux-pratiques).")
            box += para
        root = posixpath.relpath(".", posixpath.dirname(self.env.docname) or ".") + "/"  # la racine du site
        script = _SCRIPT % (_js(root), _js(PLACEHOLDER), _js(PLACEHOLDER))
        box += nodes.raw("", script, format="html")
        return [box]


def _js(text: str) -> str:
    import json

    return json.dumps(text)


def build_wheel(root: Path, out: Path) -> Path:
    """La roue du paquet de l'arbre ``root`` (``pyproject.toml``, ``README.md``, ``kalman_course/``), écrite
    dans ``out`` : copie dans un dossier temporaire (l'arbre n'est pas touché), puis
    ``setuptools.build_meta.build_wheel`` dans un processus à part, hors ligne."""
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="kc-roue-") as tmp:
        src = Path(tmp) / "src"
        src.mkdir()
        for name in ("pyproject.toml", "README.md"):
            shutil.copy2(root / name, src / name)
        shutil.copytree(root / "kalman_course", src / "kalman_course",
                        ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        env = {**os.environ, "SOURCE_DATE_EPOCH": SOURCE_DATE_EPOCH, "PIP_NO_INDEX": "1"}
        code = "import sys; from setuptools import build_meta; print(build_meta.build_wheel(sys.argv[1]))"
        done = subprocess.run([sys.executable, "-c", code, str(Path(tmp) / "dist")], cwd=src, env=env,
                              capture_output=True, text=True)
        if done.returncode != 0:
            raise RuntimeError(f"construction de la roue du paquet : échec\n{done.stderr[-3000:]}")
        name = done.stdout.strip().splitlines()[-1]
        target = out / name
        shutil.copy2(Path(tmp) / "dist" / name, target)
    return target


def _write_folder(app, exception) -> None:
    if exception is not None or app.builder.format != "html":
        return
    from ..practice import wheel_name
    from ..practice.notebooks import WHEEL_FOLDER

    root = Path(app.srcdir)
    if not (root / "pyproject.toml").is_file():
        return
    out = Path(app.outdir) / WHEEL_FOLDER
    if out.exists():
        shutil.rmtree(out)
    wheel = build_wheel(root, out)
    if wheel.name != wheel_name():
        raise RuntimeError(f"roue {wheel.name} : les pages annoncent {wheel_name()} (réinstallez le paquet : "
                           f"bash scripts/setup.sh)")
    requirements = (root / "requirements.txt").read_text(encoding="utf-8")
    (out / CONSTRAINTS).write_text(
        "# Versions avec lesquelles le cours « Filtre de Kalman » est vérifié (requirements.txt du dépôt) :\n"
        "# pip install -c contraintes.txt …\n" + requirements, encoding="utf-8")
    for notebook in sorted((root / "book" / "travaux-pratiques").glob("*.ipynb")):
        shutil.copy2(notebook, out / notebook.name)
    LOGGER.info(f"[kalman_course] {WHEEL_FOLDER}/ : {wheel.name}, {CONSTRAINTS} et les carnets à compléter")


def setup(app):
    app.add_directive("comment-travailler", WorkspaceDirective)
    app.connect("build-finished", _write_folder)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
