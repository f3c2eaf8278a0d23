r"""Extension Sphinx du livre : les formules composées à la construction, et non dans le navigateur.

À déclarer dans ``_config.yml`` (``sphinx: extra_extensions: [kalman_course.sphinx.formulas]``).

Sphinx écrit chaque formule en TeX (``\(…\)`` dans ``<span class="math">``, ``\[…\]`` dans
``<div class="math">``) pour que MathJax la compose dans la page, à chaque ouverture (1 à 3 s pour un
chapitre, 0,9 Mo de scripts). Ici, MathJax 3 tourne une fois, dans node, à la fin de la construction
(:file:`typeset_formulas.js` : paquet npm ``mathjax``, composants et réglages TeX de ``mathjax3_config``
dans ``_config.yml``), sur les formules des pages écrites : chacune devient la sortie CHTML que MathJax
aurait mise dans la page, MathML d'assistance comprise (lecteurs d'écran). Les pages ne chargent plus
MathJax : une feuille de style commune à tout le site (``_static/kc/kc-formulas.css``, les lettres des
polices TeX de MathJax) et ces polices suffisent, et les formules s'affichent dès le premier rendu,
hors ligne comme en ligne. Le TeX de chaque formule reste dans l'attribut ``data-kc-tex`` de son
conteneur (extraits de la recherche écrits en texte lisible : ``kc/kc-pages.js``).

Une formule que MathJax refuse (commande inconnue…) est un avertissement Sphinx qui nomme la page et la
formule (``-W`` arrête la construction).
"""

from __future__ import annotations

import html
import json
import re
import shutil
import subprocess
from pathlib import Path

from sphinx.util import logging

__all__ = ["setup", "typeset", "typeset_pages", "CSS_FILE"]

LOGGER = logging.getLogger(__name__)

#: Le script node qui compose les formules.
SCRIPT = Path(__file__).resolve().parent / "typeset_formulas.js"
#: La feuille de style des formules, sous ``_static/``.
CSS_FILE = "kc/kc-formulas.css"
#: Les polices CHTML de MathJax servies par le site, relativement à la feuille de style.
FONT_URL = "../mathjax/output/chtml/fonts/woff-v2"

_INLINE = re.compile(r'(<span class="math notranslate nohighlight">)\\\((.*?)\\\)(</span>)', re.S)
_DISPLAY_BOX = re.compile(r'(<div class="math notranslate nohighlight"[^>]*>)(.*?)(</div>)', re.S)
_DISPLAY = re.compile(r"\\\[(.*?)\\\]", re.S)


def _formulas(text: str) -> list[tuple[str, bool]]:
    """Les formules TeX d'une page HTML de Sphinx (entités décodées) : ``(tex, en display)``."""
    found = [(html.unescape(m[2]), False) for m in _INLINE.finditer(text)]
    for box in _DISPLAY_BOX.finditer(text):
        found += [(html.unescape(m[1]), True) for m in _DISPLAY.finditer(box[2])]
    return found


def _container(markup: str, tex: str) -> str:
    """Le conteneur de MathJax, avec le TeX de la formule dans ``data-kc-tex``."""
    return markup.replace("<mjx-container ", f'<mjx-container data-kc-tex="{html.escape(tex)}" ', 1)


def _replace(text: str, composed: dict[tuple[str, bool], str]) -> str:
    """La page où chaque formule TeX est remplacée par sa sortie CHTML."""
    text = _INLINE.sub(lambda m: m[1] + _container(composed[html.unescape(m[2]), False], html.unescape(m[2])) + m[3],
                       text)

    def display(box: re.Match) -> str:
        inner = _DISPLAY.sub(lambda m: _container(composed[html.unescape(m[1]), True], html.unescape(m[1])), box[2])
        return box[1] + inner + box[3]

    return _DISPLAY_BOX.sub(display, text)


def typeset(formulas: list[tuple[str, bool]], *, mathjax: Path, load: list[str], tex: dict,
            font_url: str = FONT_URL) -> tuple[list[str], list[tuple[int, str]], str]:
    """Compose ``formulas`` (``(tex, display)``) par MathJax dans node : renvoie les conteneurs CHTML
    (``<mjx-container …>``, MathML d'assistance comprise), les erreurs ``(rang, message)`` et la feuille
    de style CHTML (polices sous ``font_url``, relatif à la feuille)."""
    node = shutil.which("node")
    if node is None:
        raise RuntimeError("node introuvable : installez Node.js (scripts/setup.sh le demande), il compose les formules.")
    if not (mathjax / "node-main.js").is_file():
        raise RuntimeError(f"MathJax absent ({mathjax}) : lancez « npm ci » à la racine du dépôt (scripts/setup.sh le fait).")
    request = {"mathjax": str(Path(mathjax).resolve()), "load": list(load), "tex": tex, "fontURL": font_url,
               "formulas": [[t, bool(d)] for t, d in formulas]}
    done = subprocess.run([node, str(SCRIPT)], input=json.dumps(request), capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"La composition des formules par MathJax a échoué :\n{done.stderr[-3000:]}")
    out = json.loads(done.stdout)
    return out["html"], [tuple(e) for e in out["errors"]], out["css"]


def typeset_pages(pages: list[Path], *, mathjax: Path, load: list[str], tex: dict) -> tuple[str, list[str]]:
    """Compose en place les formules de ces pages HTML (une seule exécution de node pour toutes) ;
    renvoie la feuille de style et les erreurs (« page : formule : message »)."""
    texts = {page: page.read_text(encoding="utf-8") for page in pages}
    found = {page: _formulas(text) for page, text in texts.items()}
    unique = list(dict.fromkeys(f for formulas in found.values() for f in formulas))
    markup, errors, css = typeset(unique, mathjax=mathjax, load=load, tex=tex)
    composed = dict(zip(unique, markup))
    problems = []
    for k, message in errors:
        where = [p.name for p, formulas in found.items() if unique[k] in formulas]
        problems.append(f"{', '.join(where)} : « {unique[k][0].strip()} » : {message}")
    for page, text in texts.items():
        if found[page]:
            page.write_text(_replace(text, composed), encoding="utf-8")
    return css, problems


# --------------------------------------------------------------------------- Sphinx


def _page(app, pagename, templatename, context, doctree) -> None:
    """Ni MathJax ni son réglage dans la page ; la feuille des formules si la page en a."""
    scripts = context.get("script_files", [])
    mathjax = {app.config.mathjax_path, f"_static/{app.config.mathjax_path}"}

    def is_mathjax(script) -> bool:
        body = getattr(script, "attributes", {}).get("body", "")
        return str(getattr(script, "filename", script)) in mathjax or body.startswith("window.MathJax")

    scripts[:] = [s for s in scripts if not is_mathjax(s)]  # en place : la liste du constructeur
    if app.env.get_domain("math").has_equations(pagename):
        app.add_css_file(CSS_FILE, priority=900)


def _typeset_site(app, exception) -> None:
    if exception is not None or app.builder.format != "html":
        return
    out = Path(app.outdir)
    pages = [p for p in sorted(out.rglob("*.html")) if "_static" not in p.relative_to(out).parts]
    config = app.config.mathjax3_config or {}
    load = [c for c in (config.get("loader") or {}).get("load", []) if c != "ui/menu"]
    tex = dict(config.get("tex") or {})
    mathjax = Path(app.srcdir) / app.config.kc_formulas_mathjax
    css, problems = typeset_pages(pages, mathjax=mathjax, load=load, tex=tex)
    target = out / "_static" / CSS_FILE
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text(css, encoding="utf-8")
    for problem in problems:
        LOGGER.warning(f"formule refusée par MathJax : {problem}", type="kc", subtype="formulas")


def setup(app):
    app.add_config_value("kc_formulas_mathjax", "node_modules/mathjax/es5", "env")
    # après l'ajout des scripts de MathJax (sphinx.ext.mathjax, priorité 500)
    app.connect("html-page-context", _page, priority=860)
    app.connect("build-finished", _typeset_site)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
