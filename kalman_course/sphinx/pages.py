r"""Extension Sphinx du livre : des pages légères, lisibles sur tout écran et utilisables par tous (RGAA).

À déclarer dans ``_config.yml`` (``sphinx: extra_extensions: [kalman_course.sphinx.pages]``). Elle
retire de l'en-tête les scripts BokehJS qu'y ajoute :mod:`kalman_course.interactive.sphinx_ext` (priorité
500) et les fait charger à la demande.

**Poids.** Une page ne charge d'abord que ce qu'elle affiche :

- BokehJS n'est plus dans l'en-tête : le script de la page (``kc/kc-pages.js``) le charge, une fois,
  quand une figure à curseurs approche de l'écran ;
- les exécutions précalculées d'une figure (le JSON de son document Bokeh) sortent du HTML et vont dans
  ``_static/kc-data/<figure>.js``, chargé au même moment ;
- les images des chapitres se chargent quand elles approchent de l'écran (``loading="lazy"``) ;
- l'icônothèque Font Awesome du thème (un script de 1,5 Mo pour une quinzaine d'icônes) est remplacée
  par une feuille de style qui ne contient que les icônes employées par le site (``kc/kc-icons.css``,
  tracés repris du script du thème installé, en masques CSS) ; les polices Font Awesome que la feuille
  du thème charge pour ses encadrés (ampoule, cloche…) sont réduites aux quelques glyphes que ses
  règles emploient (fontTools, ``kc/fa-*.woff`` : quelques ko au lieu de 280).

**Accessibilité (RGAA = WCAG 2.1 AA).** Les formules sortent de l'ordre de tabulation (le menu
contextuel de MathJax les y met : le livre charge MathJax sans lui, et l'extension l'en retire s'il est
chargé ; la MathML d'assistance reste) ; un lien d'évitement mène à la première figure ;
chaque curseur est annoncé par son nom français et sa valeur avec unité ; les diagrammes Mermaid
reçoivent un texte de remplacement (les textes de leurs boîtes) ; les listes de la bibliographie
perdent un rôle ARIA qu'elles ne respectent pas ; le bouton de recherche garde son texte visible dans
son nom ; le thème démarre en mode « auto » (plus d'erreur « Got invalid theme mode » dans la
console) ; le mode sombre et les petits écrans ont leurs règles (``kc/kc-pages.css``).

**Code à recopier.** Les cellules visibles d'un chapitre emploient des noms importés par une cellule
cachée (``kc``, ``np``…) : avant la première cellule visible, un bloc dépliable « Importations du
chapitre » donne ces lignes d'importation, à copier d'abord.

**Recherche.** Le champ de recherche parle français (« Rechercher dans le livre… ») ; l'index de
recherche ne contient pas le TeX des formules (on ne trouve plus une page en cherchant « aligned ») ; les
extraits des résultats montrent les formules en texte lisible (« P⁻ », pas « \(P^-\) ») et ne lisent que
l'article de la page (ni sa table des matières, ni les importations : ``kc/kc-pages.js``).
"""

from __future__ import annotations

import html
import json
import re
from pathlib import Path

from sphinx.util import logging

__all__ = ["setup", "ASSETS", "SEARCH_TEXT", "css_glyphs", "icon_css", "fontawesome_icons", "hidden_imports",
           "subset_fonts", "imports_block", "mermaid_alt", "extract_figure_data", "without_math"]

LOGGER = logging.getLogger(__name__)

#: Les fichiers servis par l'extension (copiés sous ``_static/kc/``).
ASSETS = Path(__file__).resolve().parent / "assets"
#: Dossier des données des figures, sous ``_static/``.
DATA_DIR = "kc-data"
#: Le texte du champ de recherche (le thème écrit « Search this book... », sans traduction).
SEARCH_TEXT = "Rechercher dans le livre…"

_FIGURE_DATA = re.compile(r'<script type="application/json" id="(kc-[a-z0-9-]+)-item">(.*?)</script>', re.S)
_CITATION_LIST = re.compile(r'<div role="list" class="citation-list">')
_MERMAID_OBJECT = re.compile(r'<object data="([^"]+\.svg)" type="image/svg\+xml">')


# --------------------------------------------------------------------------- réglages


def _configure(app, config) -> None:
    """MathJax : les formules hors de l'ordre de tabulation ; l'icône du site.

    Le menu contextuel de MathJax met chaque formule dans l'ordre de tabulation : s'il est chargé
    (``tex-chtml.js`` le contient), on l'en retire ; le livre charge MathJax en composants, sans menu
    (``_config.yml``), et n'a rien à régler."""
    options = dict(config.html_theme_options or {})
    options["search_bar_text"] = SEARCH_TEXT
    config.html_theme_options = options
    mathjax = dict(config.mathjax3_config or {})
    load = (mathjax.get("loader") or {}).get("load")
    if load is not None and "ui/menu" not in load:
        _favicon(config)
        return
    options = dict(mathjax.get("options", {}))
    menu = dict(options.get("menuOptions", {}))
    settings = dict(menu.get("settings", {}))
    settings.setdefault("inTabOrder", False)
    menu["settings"] = settings
    options["menuOptions"] = menu
    mathjax["options"] = options
    config.mathjax3_config = mathjax
    _favicon(config)


def _favicon(config) -> None:
    if not config.html_favicon:  # sans icône, le navigateur demande /favicon.ico (404 dans la console)
        config.html_favicon = str(ASSETS / "kc" / "favicon.svg")


def _static_path(app) -> None:
    if app.builder.format == "html":
        app.config.html_static_path.append(str(ASSETS))
        _index_without_math(app.builder)


def without_math(doctree):
    """Une copie de ``doctree`` sans ses formules (``math``, ``math_block``) : ce que lit l'index de recherche."""
    from docutils import nodes

    copy = doctree.deepcopy()
    for node in list(copy.findall(lambda n: isinstance(n, (nodes.math, nodes.math_block)))):
        node.parent.remove(node)
    return copy


def _index_without_math(builder) -> None:
    """L'index de recherche de Sphinx lit le TeX des formules comme des mots (« aligned », « split »,
    « mathbb ») : le constructeur lui donne une copie de chaque page sans ses formules. (Sphinx 7 n'a pas
    de réglage pour cela ; ``index_page`` est la seule entrée de l'index, appelée avant l'écriture.)"""
    index_page = getattr(builder, "index_page", None)
    if index_page is None or getattr(index_page, "_kc_without_math", False):
        return

    def index_page_without_math(pagename, doctree, title):
        return index_page(pagename, without_math(doctree), title)

    index_page_without_math._kc_without_math = True
    builder.index_page = index_page_without_math


# --------------------------------------------------------------------------- page par page


def mermaid_alt(svg_text: str) -> str:
    """Texte de remplacement d'un diagramme Mermaid : les textes de ses boîtes et de ses flèches, dans
    l'ordre du fichier SVG, sans doublon."""
    body = re.sub(r"<(style|script|title|desc)\b.*?</\1>", "", svg_text, flags=re.S)
    texts = re.findall(r">([^<>]+)<", body)
    seen: list[str] = []
    for t in texts:
        t = " ".join(html.unescape(t).split())
        if t and t not in seen:
            seen.append(t)
    return "Diagramme : " + " ; ".join(seen) + "." if seen else "Diagramme."


_CELL = re.compile(r"^```\{code-cell\}[^\n]*\n(.*?)^```", re.S | re.M)
_HIDDEN = re.compile(r"^:tags:\s*\[([^\]]*)\]", re.M)


def hidden_imports(source: str) -> list[str]:
    """Les lignes d'importation des cellules cachées (``remove-cell``, ``remove-input``) d'un chapitre
    MyST, dans l'ordre, sans doublon."""
    out: list[str] = []
    for cell in _CELL.findall(source):
        tags = _HIDDEN.search(cell)
        if not tags or not {"remove-cell", "remove-input"} & {t.strip() for t in tags.group(1).split(",")}:
            continue
        for line in cell.splitlines():
            if re.match(r"(import|from)\s+\S+", line) and line not in out:
                out.append(line)
    return out


def imports_block(lines: list[str]) -> str:
    """Le bloc HTML dépliable des importations du chapitre (code copiable, bouton de copie du thème)."""
    code = html.escape("\n".join(lines))
    return ('<details class="kc-imports"><summary>Importations du chapitre : à exécuter avant de recopier '
            'les cellules</summary><div class="highlight-python notranslate"><div class="highlight"><pre>'
            f'{code}</pre></div></div></details>\n')


def extract_figure_data(body: str, write) -> str:
    """Remplace le JSON de chaque figure à curseurs du corps de page par une référence
    ``data-src`` ; ``write(identifiant, json)`` écrit le fichier et renvoie son adresse relative."""

    def move(match: re.Match) -> str:
        fid, data = match.group(1), match.group(2)
        src = write(fid, data)
        return f'<script type="application/json" id="{fid}-item" data-src="{html.escape(src, quote=True)}"></script>'

    return _FIGURE_DATA.sub(move, body)


def _page(app, pagename, templatename, context, doctree) -> None:
    if app.builder.format != "html":
        return
    context["default_mode"] = "auto"  # le thème démarre en mode « auto » (sinon « Got invalid theme mode »)
    pathto = context["pathto"]

    def name(asset) -> str:
        return str(getattr(asset, "filename", asset))

    # BokehJS (ajouté par sphinx_ext aux pages à figures) n'est plus dans l'en-tête : kc-pages.js le
    # charge quand une figure approche de l'écran ; Font Awesome est remplacé par kc-icons.css
    scripts = context.get("script_files", [])
    bokeh_urls = [pathto(name(s), 1) for s in scripts if "bokeh/bokeh-" in name(s)]
    app.add_js_file("kc/kc-pages.js", priority=900, **{"data-bokeh": json.dumps(bokeh_urls)})
    app.add_css_file("kc/kc-pages.css", priority=900)
    app.add_css_file("kc/kc-icons.css", priority=900)
    # en place : la liste du contexte est celle du constructeur (d'autres extensions y ajoutent ensuite)
    scripts[:] = [s for s in scripts if "bokeh/bokeh-" not in name(s) and "fontawesome" not in name(s)]
    body = context.get("body", "")
    if not body:
        return
    body = _CITATION_LIST.sub('<div class="citation-list">', body)
    # images des cellules chargées quand elles approchent de l'écran (premier chargement léger)
    body = re.sub(r"<img (?![^>]*\bloading=)", '<img loading="lazy" decoding="async" ', body)
    # les noms employés par les cellules visibles viennent de cellules cachées : on les montre
    source = Path(app.env.doc2path(pagename))
    first = body.find('<div class="cell_input')
    if first >= 0 and source.suffix == ".md" and source.is_file():
        lines = hidden_imports(source.read_text())
        if lines:
            body = body[:first] + imports_block(lines) + body[first:]
    outdir = Path(app.outdir)

    def mermaid(match: re.Match) -> str:
        src = match.group(1)
        svg = (outdir / Path(pagename).parent / src).resolve()
        alt = mermaid_alt(svg.read_text()) if svg.is_file() else "Diagramme."
        return (f'<object data="{src}" type="image/svg+xml" role="img" '
                f'aria-label="{html.escape(alt, quote=True)}">')

    body = _MERMAID_OBJECT.sub(mermaid, body)

    def write(fid: str, data: str) -> str:
        target = outdir / "_static" / DATA_DIR / f"{fid}.js"
        target.parent.mkdir(parents=True, exist_ok=True)
        content = f"(window.kcFigureData = window.kcFigureData || {{}})[{json.dumps(fid)}] = {data};\n"
        if not target.is_file() or target.read_text() != content:
            target.write_text(content)
        return pathto(f"_static/{DATA_DIR}/{fid}.js", 1)

    context["body"] = extract_figure_data(body, write)


# --------------------------------------------------------------------------- icônes


_PACK = re.compile(r'var p=(\{.*?\});.{0,400}?d\("(fa[bsr])",p\)', re.S)
_ICON = re.compile(r'"?([a-z0-9-]+)"?:\[(\d+),(\d+),\[[^\]]*\],"[0-9a-f]+",("(?:M[^"]+)"|\[[^\]]*\])\]')
_STYLES = {"fas": ("fa-solid", "fas"), "far": ("fa-regular", "far"), "fab": ("fa-brands", "fab")}


def fontawesome_icons(script: str) -> dict[tuple[str, str], tuple[int, int, list[str]]]:
    """Les icônes du script Font Awesome du thème : (style « fas »/« far »/« fab », nom) → (largeur,
    hauteur, tracés SVG)."""
    out = {}
    for pack, style in _PACK.findall(script):
        for name, w, h, paths in _ICON.findall(pack):
            d = json.loads(paths)
            out[(style, name)] = (int(w), int(h), d if isinstance(d, list) else [d])
    return out


def icon_css(used: set[tuple[str, str]], icons) -> str:
    """La feuille de style des icônes ``used`` ((style, nom)), tracés en masque CSS (couleur du texte)."""
    rules = [
        "/* Icônes Font Awesome Free (CC BY 4.0, https://fontawesome.com/license/free) employées par le site,",
        "   extraites du script du thème installé par kalman_course.sphinx.pages. */",
        ".fa-lg{font-size:1.25em;line-height:.05em;vertical-align:-.075em}",
    ]
    for style, name in sorted(used):
        if (style, name) not in icons:
            continue
        w, h, paths = icons[(style, name)]
        svg = (f"<svg xmlns='http://www.w3.org/2000/svg' viewBox='0 0 {w} {h}'>"
               + "".join(f"<path d='{d}'/>" for d in paths) + "</svg>")
        url = "url(\"data:image/svg+xml," + svg.replace("#", "%23").replace('"', "'") + "\")"
        selectors = ",".join(f".{cls}.fa-{name}::before" for cls in _STYLES[style])
        rules.append(f"{selectors}{{content:'';display:inline-block;width:{w / h:.4f}em;height:1em;"
                     f"vertical-align:-.125em;background-color:currentColor;-webkit-mask:{url} center/contain "
                     f"no-repeat;mask:{url} center/contain no-repeat}}")
    return "\n".join(rules) + "\n"


_CLASSES = re.compile(r'class="([^"]*\bfa-[^"]*)"')
#: Le script Font Awesome, écrit par le gabarit du thème dans chaque page (hors de ``script_files``).
_FONTAWESOME_TAG = re.compile(r'\s*<script defer src="[^"]*_static/scripts/fontawesome\.js[^"]*"></script>')


#: Polices Font Awesome du thème : (famille CSS, graisse, fichier).
_FA_FONTS = (("Font Awesome 6 Free", 900, "fa-solid-900"), ("Font Awesome 6 Free", 400, "fa-regular-400"),
             ("Font Awesome 6 Brands", 400, "fa-brands-400"))
_CSS_RULE = re.compile(r"([^{}]+)\{([^{}]*)\}")
_ICON_SELECTOR = re.compile(r"^\s*\.fa-[\w-]+:{1,2}(?:before|after)\s*$")


def _codes(text: str) -> set[int]:
    """Les points de code Font Awesome d'un texte CSS : échappés (« "\\f0eb" ») ou écrits tels quels."""
    escaped = {int(c, 16) for c in re.findall(r'"\\([ef][0-9a-f]{3})"', text, re.I)}
    literal = {ord(c) for c in re.findall(r'"([\ue000-\uf8ff])"', text)}
    return escaped | literal


def css_glyphs(css: str) -> set[int]:
    """Les points de code Font Awesome (U+E000–U+F8FF) que les règles d'une feuille de style écrivent en
    ``content`` (hors des règles d'icônes ``.fa-nom::before``, remplacées par ``kc-icons.css``) ou dans
    une variable CSS (``--pst-icon-lightbulb: "\\f0eb"``, lue par ``content: var(…)``)."""
    out: set[int] = set()
    for selectors, body in _CSS_RULE.findall(css):
        for declaration in body.split(";"):
            name = declaration.split(":", 1)[0].strip()
            if name.startswith("--") or (name == "content" and not all(
                    _ICON_SELECTOR.match(sel) for sel in selectors.split(","))):
                out |= _codes(declaration)
    return out


def subset_fonts(static: Path, glyphs: set[int]) -> str:
    """Écrit dans ``static/kc/`` les polices Font Awesome du thème réduites à ``glyphs`` (WOFF) et renvoie
    les règles ``@font-face`` qui les substituent aux polices complètes (déclarées plus tard, elles
    l'emportent)."""
    from fontTools import subset
    from fontTools.ttLib import TTFont

    rules = []
    for family, weight, stem in _FA_FONTS:
        source = next(iter(sorted(static.glob(f"vendor/fontawesome/**/webfonts/{stem}.ttf"))), None)
        if source is None:
            continue
        font = TTFont(source)
        options = subset.Options()
        options.flavor = "woff"
        options.notdef_outline = True
        subsetter = subset.Subsetter(options)
        subsetter.populate(unicodes=sorted(glyphs & set(font.getBestCmap() or {})) or [0x20])
        subsetter.subset(font)
        font.flavor = "woff"
        font.save(static / "kc" / f"{stem}.woff")
        rules.append(f'@font-face{{font-display:block;font-family:"{family}";font-style:normal;font-weight:{weight};'
                     f'src:url({stem}.woff) format("woff")}}')
    return "\n".join(rules) + "\n"


def _write_icons(app, exception) -> None:
    if exception is not None or app.builder.format != "html":
        return
    outdir = Path(app.outdir)
    script = outdir / "_static" / "scripts" / "fontawesome.js"
    target = outdir / "_static" / "kc" / "kc-icons.css"
    if not script.is_file():
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text("/* thème sans Font Awesome */\n")
        return
    icons = fontawesome_icons(script.read_text())
    used: set[tuple[str, str]] = set()
    for page in outdir.rglob("*.html"):
        text = page.read_text(errors="replace")
        lighter = _FONTAWESOME_TAG.sub("", text)  # 1,5 Mo de moins par page : kc-icons.css le remplace
        if lighter != text:
            page.write_text(lighter)
        for classes in _CLASSES.findall(text):
            names = classes.split()
            style = next((s for s, aliases in _STYLES.items() if set(aliases) & set(names)), "fas")
            used |= {(style, n[3:]) for n in names if n.startswith("fa-") and n not in
                     ("fa-lg", "fa-solid", "fa-regular", "fa-brands", "fa-fw", "fa-sm", "fa-xs")}
    missing = sorted(n for s, n in used if (s, n) not in icons)
    if missing:
        LOGGER.info(f"[kalman_course] icônes absentes du script du thème : {', '.join(missing)}")
    target.parent.mkdir(parents=True, exist_ok=True)
    glyphs: set[int] = set()
    for sheet in (outdir / "_static").rglob("*.css"):
        if "kc" not in sheet.parent.name:
            glyphs |= css_glyphs(sheet.read_text(errors="replace"))
    target.write_text(icon_css(used, icons) + subset_fonts(outdir / "_static", glyphs))


def setup(app):
    app.connect("config-inited", _configure)
    app.connect("builder-inited", _static_path)
    # avant le dédoublonnage des scripts de sphinx_ext (900), qui remplace la liste du contexte
    app.connect("html-page-context", _page, priority=850)
    app.connect("build-finished", _write_icons)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
