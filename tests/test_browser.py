"""Le site construit dans Chromium sans écran (Debian, /usr/bin/chromium-headless-shell), sans réseau.

Le site est servi sur 127.0.0.1 (port libre) ; toute requête non locale est interceptée, bloquée et
fait échouer le test. Pour chaque page : aucune erreur de page ni de console, formules composées à la
construction (sortie CHTML de MathJax dans la page, sans script MathJax : kalman_course.sphinx.formulas),
diagrammes mermaid dessinés, aucune violation grave ou critique d'axe-core (règles WCAG 2.0/2.1 A et AA,
le paquet npm de package-lock.json injecté dans la page, après le dessin des curseurs), au plus 2,5 Mo
au premier chargement. Sur les pages à
curseurs statiques : les curseurs sont déplacés par de vrais événements clavier et souris, et les
données tracées, relues dans le document Bokeh, sont comparées aux exécutions calculées ici par le
paquet. Un portable (1366 × 768) voit chaque panneau avec ses curseurs ; un téléphone (390 × 844, mode
sombre) a des curseurs lisibles, des figures dans la colonne et des équations qui défilent ; le
clavier atteint la première figure en quelques touches.

Chaque page est ouverte deux fois en tout, en même temps (deux Chromium, deux fils : fixture ``tours``) :
sur un portable en mode clair et sur un téléphone en mode sombre ; les vérifications de chaque écran se
suivent dans la même visite, et chaque test lit les problèmes de la sienne.

Le français de chaque page est vérifié dans le texte courant (hors code, formules, adresses) : aucun
TeX brut, aucun nombre à l'anglaise (« 0.5 », « 1e-05 »), une espace insécable devant « : ; ? ! » et
dans « », aucune erreur MathJax, aucun caractère de contrôle, aucune cellule de collage (``glue``)
visible, et chaque image a une légende et un texte de remplacement.
"""

from __future__ import annotations

import contextlib
import functools
import http.server
import os
import queue
import re
import threading
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable
from urllib.parse import urlsplit

import numpy as np
import playwright.sync_api as playwright_api
import pytest

import kalman_course.interactive as ki
from conftest import wait_for_system
from kalman_course.typography import french_spacing
from kalman_course.numbers import format_spec
from kalman_course.interactive.static import MARKER, PLOTTED_SOURCE

pytestmark = pytest.mark.browser

ROOT = Path(__file__).resolve().parent.parent
CHROMIUM = "/usr/bin/chromium-headless-shell"
CHROMIUM_ARGS = [
    "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    # Hors ligne comme l'étudiant : aucun nom d'hôte ne se résout, sauf le serveur local des tests. (Chaque
    # requête hors du site est en plus notée par open_page : Visit.blocked.)
    "--host-resolver-rules=MAP * ~NOTFOUND , EXCLUDE 127.0.0.1",
]
# Aucune erreur de page n'est tolérée. (sphinx-thebe, chargée d'office par Jupyter Book 1, insère deux
# fois son script « const THEBE_JS_URL = … » ; l'extension du livre retire la copie, et
# page_errors vérifie qu'il n'en reste qu'une.)

#: Annexes du livre (ni figure à curseurs, ni quiz).
APPENDICES = {"references", "errata", "glossaire"}



class GridPoints:
    """Les points de la grille d'une figure à curseurs que la visite relit : ceux de la grille si elle est
    déjà calculée dans ce lancement des tests (``KALMAN_GRID_CACHE``), sinon calculés ici par le paquet un à
    un (:meth:`~kalman_course.interactive.figure.SliderSpec.run_at` : les mêmes appels de ``run`` que pour
    la grille, tests/test_slider_grids.py le vérifie) plutôt que la grille entière : axes, abscisse commune,
    position par défaut, ``run(*index)``."""

    def __init__(self, name: str):
        self.spec = ki.slider_spec(name)
        self.axes, self.time = self.spec.axes, self.spec.time
        self.shape = tuple(axis.values.size for axis in self.axes)
        self.default_index = tuple(axis.default for axis in self.axes)

    def run(self, *index: int) -> dict[str, np.ndarray]:
        # la grille si un processus de ce lancement l'a déjà calculée (les carnets : KALMAN_GRID_CACHE ;
        # test_a_point_computed_alone_equals_the_grid la compare au calcul seul de chaque point), sinon
        # le point seul, calculé une fois par le paquet puis gardé
        grid = self.spec.cached_grid()
        return grid.run(*index) if grid is not None else self.spec.run_at(*index)


#: Figures à curseurs statiques connues (registre du paquet) → leurs points de grille.
EXPECTED_GRIDS = {name: (lambda name=name: GridPoints(name)) for name in ki.slider_names()}


#: Adresse (sur le serveur des tests, hors du site) où la page charge axe-core : un fichier que le cache
#: HTTP du visiteur garde, compilé une fois, au lieu de 0,5 Mo de source envoyés à chaque visite.
AXE_PATH = "/__tests__/axe.min.js"


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):  # pas de journal d'accès dans la sortie des tests
        pass

    def translate_path(self, path):
        if urlsplit(path).path == AXE_PATH:
            return str(AXE)
        return super().translate_path(path)


@dataclass
class Site:
    root: Path
    base: str

    def url(self, path: Path) -> str:
        return self.base + path.relative_to(self.root).as_posix()

    def file_for(self, url: str) -> Path:
        return self.root / urlsplit(url).path.lstrip("/")


@contextlib.contextmanager
def served(root: Path):
    """Le site du dossier ``root`` servi en local le temps du bloc (axe-core compris, :data:`AXE_PATH`)."""
    handler = functools.partial(_QuietHandler, directory=str(root))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    try:
        yield Site(root, f"http://127.0.0.1:{server.server_address[1]}/")
    finally:
        server.shutdown()
        server.server_close()


@pytest.fixture(scope="module")
def site(request):
    """Le site construit par la session (``built_book``), ou un site déjà construit désigné par
    ``KALMAN_BUILT_SITE`` (dossier html : pour relancer ces tests sans reconstruire)."""
    wanted = os.environ.get("KALMAN_BUILT_SITE")
    root = Path(wanted).resolve() if wanted else request.getfixturevalue("built_book")
    wait_for_system()  # Chromium sans écran
    with served(root) as built:
        yield built


@pytest.fixture(scope="module")
def browser():
    wait_for_system()
    if not Path(CHROMIUM).exists():
        pytest.fail(f"{CHROMIUM} absent : installez le paquet Debian « chromium-headless-shell » (scripts/setup.sh le fait).")
    with playwright_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        yield b
        b.close()


#: Tailles d'écran : un portable courant et un téléphone.
LAPTOP = {"width": 1366, "height": 768}
PHONE = {"width": 390, "height": 844}
#: Le paquet npm axe-core (package-lock.json), injecté dans les pages.
AXE = ROOT / "node_modules" / "axe-core" / "axe.min.js"
#: Règles d'axe-core exigées : WCAG 2.0 et 2.1, niveaux A et AA (le RGAA).
AXE_TAGS = ["wcag2a", "wcag2aa", "wcag21a", "wcag21aa"]
#: Options d'``axe.run`` : ces règles ; les nœuds conformes ne sont pas décrits un à un (``resultTypes``),
#: les violations restent toutes.
AXE_OPTIONS = {"runOnly": {"type": "tag", "values": AXE_TAGS}, "resultTypes": ["violations"]}
#: Poids maximal d'une page au premier chargement (octets des fichiers servis).
FIRST_LOAD_LIMIT = 2.5e6


@dataclass
class Visit:
    page: object
    blocked: list[str] = field(default_factory=list)
    errors: list[str] = field(default_factory=list)
    console: list[str] = field(default_factory=list)
    broken: list[str] = field(default_factory=list)
    loaded: list[str] = field(default_factory=list)
    first_load: list[str] = field(default_factory=list)


def open_page(browser, url: str, allowed_prefix: str, *, viewport=LAPTOP, color_scheme: str = "light",
              figures: bool = True, context=None) -> Visit:
    """Ouvre ``url`` et note (``Visit.blocked``) toute requête qui ne commence pas par ``allowed_prefix`` ;
    Chromium n'en envoie aucune hors de la machine (:data:`CHROMIUM_ARGS`).

    Après le chargement, ``first_load`` note les adresses chargées (le
    premier chargement) ; puis, si ``figures``, toutes les figures à curseurs de la page sont dessinées
    (elles se chargent d'ordinaire quand elles approchent de l'écran).

    Sans ``context``, la page s'ouvre dans un contexte neuf (fermé avec elle : :func:`close_visit`) ;
    avec, dans ce contexte, dont le cache HTTP sert les fichiers partagés comme au lecteur qui passe d'un
    chapitre à l'autre (les réponses du cache comptent dans ``loaded`` comme celles du serveur).
    """
    if context is None:
        context = browser.new_context(viewport=viewport, color_scheme=color_scheme)
    page = context.new_page()
    visit = Visit(page)

    def request(r):
        u = r.url
        if not (u.startswith(allowed_prefix) or u.startswith(("data:", "blob:"))):
            visit.blocked.append(u)

    # (Pas de « context.route » : l'interception des requêtes par Playwright coupe le cache HTTP et fait
    # passer chaque requête par Python.)
    page.on("request", request)
    page.on("pageerror", lambda e: visit.errors.append(str(e)))
    page.on("console", lambda m: visit.console.append(m.text) if m.type == "error" else None)
    page.on("response", lambda r: (visit.broken if r.status >= 400 else visit.loaded).append(r.url))
    page.on("requestfailed", lambda r: None if r.url in visit.blocked else visit.broken.append(r.url))
    page.goto(url, wait_until="load")  # (formules composées à la construction : rien à attendre)
    visit.first_load = list(visit.loaded)
    if figures:
        load_figures(page)
    return visit


def close_visit(visit: Visit, shared_context) -> None:
    """Ferme la page de la visite, et son contexte s'il lui est propre. Dans un contexte partagé, le
    stockage de la page (localStorage, sessionStorage : thème, réponses) est vidé pour la page suivante."""
    if shared_context is None:
        visit.page.context.close()
        return
    try:
        visit.page.evaluate("() => { localStorage.clear(); sessionStorage.clear(); }")
    finally:
        visit.page.close()


def load_figures(page) -> None:
    """Dessine toutes les figures à curseurs de la page et attend leurs curseurs."""
    if not page.locator(f"[{MARKER}]").count():
        return
    page.evaluate("() => window.kcFigures.loadAll().then(() => true)")
    page.wait_for_function(
        """() => [...document.querySelectorAll('.kc-bokeh-root')].every(r => r.dataset.kcReady === '1' &&
               !r.querySelector('.kc-bokeh-missing') && window.kcFigures.documents[r.id])""", timeout=20000)
    page.locator(f"[{MARKER}] .noUi-handle").first.wait_for(timeout=15000)


def figure_ids(page) -> list[str]:
    """Les identifiants des figures à curseurs de la page, dans l'ordre."""
    return page.evaluate("() => [...document.querySelectorAll('.kc-bokeh-root')].map(r => r.id)")


#: Le temps d'axe-core, le rendu CHTML de chaque formule (``mjx-math``, caché aux lecteurs d'écran par
#: ``aria-hidden``, ses glyphes dessinés en CSS, sans nœud de texte) est remplacé par une boîte vide de même
#: taille et de même ligne de base, puis remis. axe-core n'y trouve rien à vérifier, mais y passait le
#: cinquième de son calcul (38 pages, deux écrans : 217 s de calcul, 170 avec les boîtes, et les mêmes
#: violations, mineures comprises, nœud par nœud). Seuls les rendus faits d'éléments ``mjx-*`` sans texte,
#: sans attribut d'accessibilité ou de focus (``aria-*``, ``role``, ``tabindex``, ``href``, ``id``…) et
#: sans style de couleur, de fond, de bordure ou ``!important`` sont remplacés : tout autre rendu reste tel
#: quel devant axe-core. Le MathML d'assistance (ce que lit un lecteur d'écran) et l'élément ``mjx-math``
#: lui-même restent. La mise en page ne bouge pas (test_formula_boxes_keep_the_layout_and_come_back).
BOX_FORMULAS = r"""() => {
  const unsafeAttr = /^(aria-|role$|tabindex$|href$|id$|title$|alt$|lang$|contenteditable$|on)/i;
  const unsafeStyle = /!important|color|background|border|outline/i;
  const safe = m => {
    const walker = document.createTreeWalker(m, NodeFilter.SHOW_ELEMENT | NodeFilter.SHOW_TEXT);
    for (let n = walker.nextNode(); n; n = walker.nextNode()) {
      if (n.nodeType === Node.TEXT_NODE) { if (n.data.trim()) return false; continue; }
      if (!n.localName.startsWith('mjx-')) return false;
      for (const a of n.attributes) {
        if (unsafeAttr.test(a.name) || (a.name === 'style' && unsafeStyle.test(a.value))) return false;
      }
    }
    return true;
  };
  const all = [...document.querySelectorAll('mjx-container > mjx-math')];
  const maths = all.filter(safe);
  // une sonde vide par formule donne la ligne de base ; toutes les lectures, puis toutes les écritures
  const probes = maths.map(m => {
    const p = document.createElement('span');
    p.style.cssText = 'display:inline-block;width:0;height:0;vertical-align:baseline';
    m.before(p);
    return p;
  });
  const boxes = maths.map((m, i) => [m.getBoundingClientRect(), probes[i].getBoundingClientRect().bottom]);
  window.__kcBoxed = maths.map((m, i) => {
    const [r, baseline] = boxes[i];
    probes[i].remove();
    const content = document.createDocumentFragment();
    content.append(...m.childNodes);
    const style = m.getAttribute('style');
    // (par l'attribut : le style écrit par m.style reviendrait en « style="" » après removeAttribute)
    m.setAttribute('style', (style ? style + ';' : '') + `display:inline-block;width:${r.width}px;` +
                            `height:${r.height}px;vertical-align:${baseline - r.bottom}px`);
    return [m, content, style];
  });
  return {boxed: maths.length, kept: all.length - maths.length};
}"""
#: Remet chaque rendu CHTML à sa place (:data:`BOX_FORMULAS`).
UNBOX_FORMULAS = r"""() => {
  for (const [m, content, style] of window.__kcBoxed || []) {
    m.append(content);
    if (style === null) m.removeAttribute('style'); else m.setAttribute('style', style);
  }
  delete window.__kcBoxed;
}"""
#: Nombre d'éléments du document (la page revient-elle entière après :data:`UNBOX_FORMULAS` ?).
ELEMENT_COUNT = "() => document.getElementsByTagName('*').length"


def axe_violations(page) -> list[dict]:
    """Les violations axe-core (WCAG A et AA) de la page : règle, impact, nombre de nœuds, exemples.
    (axe-core est chargé du serveur des tests, :data:`AXE_PATH`, après le premier chargement de la page ;
    options : :data:`AXE_OPTIONS` ; rendus CHTML des formules en boîtes le temps du calcul :
    :data:`BOX_FORMULAS`.)"""
    page.add_script_tag(url=AXE_PATH)
    before = page.evaluate(ELEMENT_COUNT)
    page.evaluate(BOX_FORMULAS)
    try:
        violations = page.evaluate(
            """(options) => axe.run(document, options).then(r => r.violations.map(v =>
                 ({id: v.id, impact: v.impact, nodes: v.nodes.length,
                   examples: v.nodes.slice(0, 3).map(n => n.target.join(' ') + ' : ' + n.html.slice(0, 120))})))""",
            AXE_OPTIONS)
    finally:
        page.evaluate(UNBOX_FORMULAS)
    after = page.evaluate(ELEMENT_COUNT)
    assert after == before, f"formules mal remises après axe-core : {before} éléments avant, {after} après"
    return violations


def serious(violations: list[dict]) -> list[dict]:
    return [v for v in violations if v["impact"] in ("serious", "critical")]


def served_bytes(site, urls) -> int:
    """Octets des fichiers du site servis pour ces adresses (chacune une fois)."""
    total = 0
    for url in dict.fromkeys(urls):
        f = site.file_for(url)
        if f.is_file():
            total += f.stat().st_size
    return total


def html_pages(root: Path) -> list[Path]:
    skip = {"_static", "_sources", "_images", "_downloads"}
    return sorted(p for p in root.rglob("*.html") if not skip & set(p.relative_to(root).parts))


def page_errors(visit: Visit, html: str) -> list[str]:
    """Erreurs de page et de console, plus un doublon de script en ligne (source connue d'erreur de
    redéclaration)."""
    errors = list(visit.errors) + [f"console : {m}" for m in visit.console]
    if html.count("const THEBE_JS_URL") > 1:
        errors.append("script en ligne de sphinx-thebe présent plusieurs fois")
    return errors


# Le texte courant de l'article (hors code, formules, SVG, figures Bokeh, liens qui affichent une adresse) :
# TeX brut, nombres à l'anglaise, espaces ordinaires devant « : ; ? ! » ou dans « ».
_PROSE = r"""() => {
  const root = document.querySelector('main') || document.body;
  const skip = 'pre, code, kbd, samp, script, style, mjx-container, noscript, textarea, svg, object, ' +
               '.highlight, .math, .kc-bokeh-figure, .headerlink';
  const walker = document.createTreeWalker(root, NodeFilter.SHOW_TEXT);
  const out = {tex: [], english: [], space: [], guillemets: []};
  const around = (t, i) => t.slice(Math.max(0, i - 25), i + 25).replace(/\s+/g, ' ');
  const scan = (re, t, list) => { let m; re.lastIndex = 0; while ((m = re.exec(t))) list.push(around(t, m.index)); };
  for (let n = walker.nextNode(); n; n = walker.nextNode()) {
    const el = n.parentElement;
    if (!el || el.closest(skip)) continue;
    const t = n.textContent;
    if (el.closest('a') && /^\s*(https?:|www\.|doi:)/i.test(t)) continue;  // une adresse affichée
    scan(/\$\$|\\\(|\\\)|\\\[|\\\]|\\[a-zA-Z]{2,}|\{glue|\{eq\}|\{doc\}/g, t, out.tex);
    // 0.5, -3.25, 1.2e-05, 3e+02 ; pas 2.0.0 (version), 10.1115/… (DOI), 1:30, a.b
    scan(/(?<![\w.,\/:\u2212-])(?<!§[\s\u00a0\u202f]?)[-\u2212]?\d+\.\d+(?![\w\/]|\.\d)|(?<![\w.])\d+(?:\.\d+)?e[-+]?\d+(?!\w)/g, t, out.english);
    scan(/[ \t\n\r](?=[:;!?](?![\w\/]))/g, t, out.space);
    scan(/«(?![\u00a0\u202f])|(?<![\u00a0\u202f])»/g, t, out.guillemets);
  }
  return out;
}"""

# Cellules de code visibles qui collent des nombres (elles doivent être cachées).
_GLUE_CELLS = r"""() => [...document.querySelectorAll('main .cell_input')]
    .filter(c => /\bglue(_number)?\(/.test(c.textContent)).map(c => c.textContent.trim().slice(0, 60))"""

# Images sans légende numérotée ou sans texte de remplacement (un nom de fichier ne compte pas).
_IMAGES = r"""() => [...document.querySelectorAll('main img')].filter(img => {
  const alt = (img.getAttribute('alt') || '').trim();
  const altOk = alt.length > 0 && !/\.(png|jpe?g|svg|gif|webp)$/i.test(alt);
  const figure = img.closest('figure');
  const caption = figure && figure.querySelector('figcaption');
  return !(altOk && caption && caption.textContent.trim().length > 0);
}).map(img => img.getAttribute('src'))"""

#: Caractères de contrôle (hors tabulation et fins de ligne) : un « \a » de « \approx » devenu BEL…
_CONTROL = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f]")

_MATH = """() => [...document.querySelectorAll('.math')].map(el => !!el.querySelector('mjx-container'))"""

_MERMAID = """() => [...document.querySelectorAll(
    'object[data*="mermaid"], img[src*="mermaid"], pre.mermaid, div.mermaid')].map(el => {
  const box = el.getBoundingClientRect();
  let svg = null;
  if (el.tagName === 'OBJECT') svg = el.contentDocument && el.contentDocument.querySelector('svg');
  else if (el.tagName === 'IMG') return {kind: 'img', w: box.width, h: box.height, ok: el.naturalWidth > 0};
  else svg = el.querySelector('svg');
  const sb = svg ? svg.getBoundingClientRect() : {width: 0, height: 0};
  const labels = svg ? svg.querySelectorAll('text, foreignObject').length : 0;
  return {kind: el.tagName.toLowerCase(), w: box.width, h: box.height, ok: !!svg && sb.width > 0 &&
          sb.height > 0 && labels > 0};
})"""


def _mermaid_sources(html_file: Path, root: Path) -> int:
    source = ROOT / html_file.relative_to(root).with_suffix(".md")
    if not source.is_file():
        return 0
    return len(re.findall(r"^(?:```|:::)\{mermaid\}", source.read_text(), re.M))


def _check_page(site: Site, html_file: Path, visit: Visit, problems: list[str], report: list[str]) -> None:
    """Hors ligne, formules composées, figures et diagrammes dessinés, français du texte courant, poids du
    premier chargement, axe-core (portable, mode clair)."""
    html = html_file.read_text()
    name = html_file.relative_to(site.root).as_posix()
    page = visit.page
    if visit.blocked:
        problems.append(f"{name} : requêtes non locales {visit.blocked}")
    if visit.broken:
        problems.append(f"{name} : ressources locales manquantes {visit.broken}")
    for err in page_errors(visit, html):
        problems.append(f"{name} : erreur de page {err}")
    typeset = page.evaluate(_MATH)
    if not all(typeset):
        problems.append(f"{name} : {typeset.count(False)} formule(s) sur {len(typeset)} non composées")
    if '<span class="math' in html or '<div class="math' in html:
        if page.locator("mjx-container").count() == 0:
            problems.append(f"{name} : aucune sortie MathJax")
    mathjax_js = [u for u in visit.loaded if "/_static/mathjax/" in u and urlsplit(u).path.endswith(".js")]
    if mathjax_js or page.evaluate("() => !!window.MathJax"):
        problems.append(f"{name} : MathJax chargé par la page ({mathjax_js[:2]}) : les formules sont composées "
                        f"à la construction")
    prose = page.evaluate(_PROSE)
    for kind, label in (("tex", "TeX brut visible"), ("english", "nombre à l'anglaise dans le texte"),
                        ("space", "espace ordinaire devant « : ; ? ! »"),
                        ("guillemets", "guillemets sans espace insécable")):
        if prose[kind]:
            problems.append(f"{name} : {len(prose[kind])} × {label}, par exemple {prose[kind][:3]}")
    if page.locator("mjx-merror, [data-mjx-error]").count():
        problems.append(f"{name} : erreur MathJax ({page.locator('mjx-merror').first.text_content()!r})")
    control = _CONTROL.findall(html)
    if control:
        problems.append(f"{name} : caractère(s) de contrôle dans la page {sorted(set(control))}")
    glue_cells = page.evaluate(_GLUE_CELLS)
    if glue_cells:
        problems.append(f"{name} : cellule(s) de collage visible(s) {glue_cells[:2]}")
    images = page.evaluate(_IMAGES)
    if images:
        problems.append(f"{name} : {len(images)} image(s) sans légende ou sans texte de remplacement")
    if page.locator(".mermaid, object[data*='mermaid'], img[src*='mermaid']").count():
        try:  # attendre le chargement des SVG ; un échec est signalé plus bas, diagramme par diagramme
            page.wait_for_function(
                "() => [...document.querySelectorAll('object[data*=\"mermaid\"]')].every(o => "
                "o.contentDocument && o.contentDocument.querySelector('svg'))", timeout=10000)
        except playwright_api.TimeoutError:
            pass
    diagrams = page.evaluate(_MERMAID)
    bad = [d for d in diagrams if not (d["ok"] and d["w"] > 0 and d["h"] > 0)]
    if bad:
        problems.append(f"{name} : diagramme(s) mermaid non dessiné(s) {bad}")
    expected = _mermaid_sources(html_file, site.root)
    if len(diagrams) != expected:
        problems.append(f"{name} : {len(diagrams)} diagramme(s) affiché(s), {expected} dans la source")
    # aucun curseur ipywidgets (il serait mort sans noyau), aucun lien vers le projet jupyter-book
    if page.locator(".jupyter-widgets, script[type='application/vnd.jupyter.widget-state+json']").count():
        problems.append(f"{name} : widget ipywidgets dans la page publiée")
    if page.locator("a[href*='executablebooks']").count():
        problems.append(f"{name} : lien vers le projet jupyter-book")
    # léger : le premier chargement (avant qu'une figure n'approche) tient dans 2,5 Mo
    first, full = served_bytes(site, visit.first_load), served_bytes(site, visit.loaded)
    if first > FIRST_LOAD_LIMIT:
        problems.append(f"{name} : {format_spec(first / 1e6, '.2f')} Mo au premier chargement (> 2,5 Mo)")
    # RGAA : aucune violation grave ou critique d'axe-core, figures et formules dessinées
    violations = axe_violations(page)
    for v in serious(violations):
        problems.append(f"{name} : axe-core « {v['id']} » ({v['impact']}, {v['nodes']} nœud(s)) {v['examples']}")
    report.append(f"  {name:38s} {format_spec(first / 1e6, '.2f'):>5s} Mo au premier chargement, "
                  f"{format_spec(full / 1e6, '.2f'):>5s} Mo figures comprises, "
                  f"{format_spec(len(dict.fromkeys(visit.first_load)), 'd'):>3s} requêtes ; axe-core : "
                  f"{format_spec(sum(v['nodes'] for v in serious(violations)), 'd')} nœud(s) grave(s), "
                  f"{format_spec(sum(v['nodes'] for v in violations), 'd')} en tout")


# --------------------------------------------------------------------------- curseurs statiques

# Toutes les sources tracées de la figure k (une par longueur de série : PLOTTED_SOURCE, PLOTTED_SOURCE-<L>),
# la position de chaque curseur, ce que chaque curseur affiche et annonce (valeur écrite, aria-label,
# aria-valuetext : dans les racines fantômes des widgets Bokeh) et le texte de lecture, en un seul aller-retour
# (``data`` faux : tout sauf les séries, pour attendre que les curseurs soient à jour).
_READ = """(args) => {
  const id = args.id, doc = window.kcFigures.documents[id];
  const out = {};
  for (const m of args.data ? doc.all_models : []) {
    if (m.name && m.name.startsWith('%s') && m.data) {
      for (const name of Object.keys(m.data)) out[name] = Array.from(m.data[name]);
    }
  }
  const index = [];
  for (let s = 0; doc.get_model_by_name('kc-slider-' + s); s++) index.push(doc.get_model_by_name('kc-slider-' + s).value);
  const deep = (node, sel) => {  // premier élément qui répond à sel sous node, racines fantômes comprises
    if (!node) return null;
    const hit = node.querySelector(sel);
    if (hit) return hit;
    for (const el of node.querySelectorAll('*')) {
      if (el.shadowRoot) { const h = deep(el.shadowRoot, sel); if (h) return h; }
    }
    return null;
  };
  const sliders = index.map((_, s) => {
    const box = document.getElementById(id + '-slider-' + s);
    const value = deep(box, '.bk-slider-value'), handle = deep(box, '.noUi-handle');
    return {shown: value && value.textContent, label: handle && handle.getAttribute('aria-label'),
            valuetext: handle && handle.getAttribute('aria-valuetext')};
  });
  const readout = document.getElementById(id + '-readout');
  return {index: index, data: out, sliders: sliders, readout: readout ? readout.textContent : null};
}""" % PLOTTED_SOURCE


def _check_plotted(page, fid: str, grid, name: str | None = None) -> tuple[int, ...]:
    """Relit la figure ``fid`` (:data:`_READ`) : les séries tracées sont celles de la grille au point des
    curseurs, que les curseurs affichent et annoncent aux lecteurs d'écran ; renvoie ce point."""
    # La valeur écrite et annoncée par le livre remplace celle de Bokeh juste après l'événement : relire
    # les curseurs (sans les données) jusqu'à ce qu'ils l'affichent, 3 s au plus, puis les données une fois.
    for _ in range(60):
        state = page.evaluate(_READ, {"id": fid, "data": False})
        index = tuple(int(v) if float(v).is_integer() else -1 for v in state["index"])
        if len(index) == len(grid.axes) and min(index) >= 0:
            labels = [french_spacing(axis.labels()[i]) for axis, i in zip(grid.axes, index)]
            if all(sl["shown"] == lab and sl["valuetext"] == lab for sl, lab in zip(state["sliders"], labels)):
                break
        page.wait_for_timeout(50)
    state["data"] = page.evaluate(_READ, {"id": fid, "data": True})["data"]
    assert len(state["index"]) == len(grid.axes)
    assert all(float(v).is_integer() for v in state["index"])
    index = tuple(int(v) for v in state["index"])
    expected = grid.run(*index)
    for series, values in expected.items():
        np.testing.assert_allclose(np.array(state["data"][series], dtype=float), values, rtol=1e-12, atol=0,
                                   equal_nan=True, err_msg=f"série {series}, point {index}")
    if "t" in state["data"]:  # temps commun, s'il est tracé (des figures n'ont que des abscisses propres)
        np.testing.assert_array_equal(state["data"]["t"], grid.time)
    # les curseurs affichent les vraies valeurs du point de grille…
    labels = [french_spacing(axis.labels()[i]) for axis, i in zip(grid.axes, index)]
    assert [slider["shown"] for slider in state["sliders"]] == labels
    # … et les annoncent aux lecteurs d'écran : nom français, valeur avec unité (pas l'indice)
    for slider, axis, label in zip(state["sliders"], grid.axes, labels):
        assert slider["label"] == french_spacing(f"{axis.symbol} — {axis.description}")
        assert slider["valuetext"] == label
    # le texte de lecture donne les nombres de cette exécution, calculés par le paquet
    if name is not None and ki.slider_spec(name).readout is not None:
        assert state["readout"] == french_spacing(ki.slider_spec(name).text_at(*index))
    return index


def _drag(page, handle, base, fraction: float) -> None:
    hb, bb = handle.bounding_box(), base.bounding_box()
    y = hb["y"] + hb["height"] / 2
    page.mouse.move(hb["x"] + hb["width"] / 2, y)
    page.mouse.down()
    page.mouse.move(bb["x"] + fraction * bb["width"], y, steps=8)
    page.mouse.up()


def _weight(visit: Visit, site: Site, html_file: Path) -> dict[str, int]:
    """Octets de la page, par catégorie (tailles des fichiers servis). Les images sont comptées
    d'après le HTML (chargement différé possible), les scripts et feuilles d'après les réponses."""
    html = html_file.read_text()
    images = {(html_file.parent / src).resolve() for src in re.findall(r'<img[^>]+src="([^"]+)"', html)}
    sizes = {"page HTML (données incluses)": html_file.stat().st_size,
             "images du chapitre": sum(f.stat().st_size for f in images if f.is_file()),
             "BokehJS (partagé)": 0, "formules (feuille et polices, partagées)": 0, "thème et autres scripts (partagés)": 0}
    for url in dict.fromkeys(visit.loaded):
        f = site.file_for(url).resolve()
        if not f.is_file() or f == html_file.resolve() or f in images:
            continue
        rel = f.relative_to(site.root.resolve()).as_posix()
        if rel.startswith("_static/bokeh/"):
            sizes["BokehJS (partagé)"] += f.stat().st_size
        elif rel.startswith("_static/mathjax/") or rel == "_static/kc/kc-formulas.css":
            sizes["formules (feuille et polices, partagées)"] += f.stat().st_size
        elif not rel.startswith("_images/"):
            sizes["thème et autres scripts (partagés)"] += f.stat().st_size
    return sizes


def _check_static_sliders(site: Site, html_file: Path, visit: Visit, problems: list[str], report: list[str]) -> None:
    """Chaque curseur de chaque figure, par le clavier (Fin, Début, flèches), la souris (glisser, cliquer
    sur la glissière) : les données tracées sont celles de la grille du paquet ; puis le poids de la page."""
    page = visit.page
    figures = page.locator(f"[{MARKER}]")
    ids = figure_ids(page)
    for j in range(figures.count()):
        fig_name = figures.nth(j).get_attribute(MARKER)
        root = figures.nth(j)
        k = ids[j]  # la figure est relue par son identifiant
        assert fig_name in EXPECTED_GRIDS, f"figure « {fig_name} » inconnue du test : ajoutez sa grille"
        grid = EXPECTED_GRIDS[fig_name]()
        check = functools.partial(_check_plotted, name=fig_name)
        # position par défaut = la figure statique du chapitre
        assert check(page, k, grid) == grid.default_index
        for s in range(len(grid.axes)):
            handle = root.locator(".noUi-handle").nth(s)
            base = root.locator(".noUi-base").nth(s)
            n = grid.shape[s]
            handle.focus()
            page.keyboard.press("End")
            pos = check(page, k, grid)
            assert pos[s] == n - 1
            page.keyboard.press("Home")
            pos_home = check(page, k, grid)
            assert pos_home[s] == 0
            # une touche a changé les données tracées (elles sont celles de la grille aux deux positions)
            if not _differs(grid.run(*pos), grid.run(*pos_home)):
                problems.append(f"{html_file.relative_to(site.root).as_posix()} : le curseur {s} de « {fig_name} » "
                                f"ne change pas les données tracées")
            for _ in range(3):
                page.keyboard.press("ArrowRight")
            pos = check(page, k, grid)
            assert pos[s] == min(3, n - 1)
            _drag(page, handle, base, 0.8)
            pos = check(page, k, grid)
            assert abs(pos[s] - 0.8 * (n - 1)) <= 1
            page.mouse.click(*_point(base, 0.1))  # clic sur la glissière
            pos = check(page, k, grid)
            assert abs(pos[s] - 0.1 * (n - 1)) <= 1
    assert not visit.blocked and not visit.broken
    assert not page_errors(visit, html_file.read_text()), visit.errors
    sizes = _weight(visit, site, html_file)
    own = sizes["page HTML (données incluses)"] + sizes["images du chapitre"]
    shared = sum(sizes.values()) - own
    report.append(f"Poids de {html_file.relative_to(site.root)} :")
    for label, size in sizes.items():
        report.append(f"  {label:38s} {format_spec(size / 1e6, '.3f'):>7s} Mo")
    report.append(f"  {'propre au chapitre (HTML + données + images)':38s} {format_spec(own / 1e6, '.3f'):>7s} Mo")
    report.append(f"  {'partagé par le site':38s} {format_spec(shared / 1e6, '.3f'):>7s} Mo")


def _point(locator, fraction: float) -> tuple[float, float]:
    b = locator.bounding_box()
    return b["x"] + fraction * b["width"], b["y"] + b["height"] / 2


def test_interactive_chapter_works_from_file_url(site, browser):
    """Le site téléchargé s'ouvre aussi sans serveur (file://) : BokehJS, MathJax et données suivent."""
    html_file = site.root / "book" / "tension-constante.html"
    visit = open_page(browser, html_file.as_uri(), "file://")
    page = visit.page
    assert not visit.blocked, visit.blocked
    assert page.locator("mjx-container").count() > 0
    grid = ki.voltage_grid()
    root = page.locator(f"[{MARKER}='tension-curseurs']")
    fid = figure_ids(page)[0]
    assert _check_plotted(page, fid, grid) == grid.default_index
    root.locator(".noUi-handle").nth(1).focus()
    page.keyboard.press("PageUp")
    i, j = _check_plotted(page, fid, grid)
    assert (i, j) != grid.default_index
    assert not page_errors(visit, html_file.read_text()), visit.errors
    page.context.close()


def test_requests_outside_the_site_are_noted_and_never_leave_the_machine(site, browser):
    """La garde hors ligne des visites : une requête vers un autre hôte est notée (``Visit.blocked``) et
    échoue sans quitter la machine (:data:`CHROMIUM_ARGS`), même quand la page la fait après coup."""
    visit = open_page(browser, site.base + "search.html", site.base, figures=False)
    outcome = visit.page.evaluate("""() => fetch('https://cdn.jsdelivr.net/npm/mathjax@3/es5/tex-chtml.js')
        .then(r => 'chargé ' + r.status, e => 'refusé')""")
    assert outcome == "refusé"
    assert visit.blocked == ["https://cdn.jsdelivr.net/npm/mathjax@3/es5/tex-chtml.js"]
    assert not visit.broken  # une requête refusée n'est pas comptée deux fois
    close_visit(visit, None)


def test_prose_checks_flag_prose_only(browser):
    """Les vérifications du français (sur une page écrite ici) signalent le texte courant fautif et
    laissent le code, les formules, les adresses, les heures et les numéros de version."""
    NB, NN = "\u00a0", "\u202f"
    good = (f"<p>Le gain{NB}: 0,5{NN}; la «{NB}recette{NB}»{NN}? À 10:30, voir "
            f"<a href='https://example.org/a:b'>https://example.org/a:b</a>, doi:10.1115/1.3662552, "
            f"filterpy 2.0.0, Durbin et Koopman (§{NB}5.2).</p><pre>x = 0.5 ; print('a : b')</pre><code>1e-05 :</code>"
            f"<span class='math'>\\frac{{a}}{{b}} : 0.5</span>")
    bad = ("<p>Le gain : 0.5 ; la « recette » ? Écart 1.2e-05 et \\frac{a}{b}.</p>"
           "<div class='cell_input'><pre>kc.numbers.glue_number('x', 1.0)</pre></div>"
           "<img src='a.png' alt='a.png'>")
    context = browser.new_context()
    page = context.new_page()
    page.set_content(f"<main>{good}</main>")
    assert page.evaluate(_PROSE) == {"tex": [], "english": [], "space": [], "guillemets": []}
    assert page.evaluate(_GLUE_CELLS) == [] and page.evaluate(_IMAGES) == []
    page.set_content(f"<main>{bad}</main>")
    found = page.evaluate(_PROSE)
    assert len(found["english"]) == 2 and len(found["space"]) == 3 and len(found["guillemets"]) == 2
    assert len(found["tex"]) == 1
    assert len(page.evaluate(_GLUE_CELLS)) == 1 and page.evaluate(_IMAGES) == ["a.png"]
    assert _CONTROL.findall("x \\approx y") == [] and _CONTROL.findall("x \approx y") == ["\a"]
    context.close()


# --------------------------------------------------------------------------- chaque chapitre se manipule


def _toc_pages(root: Path) -> list[Path]:
    import yaml

    toc = yaml.safe_load((ROOT / "_toc.yml").read_text())
    files = [toc["root"]] + [c["file"] for part in toc["parts"] for c in part["chapters"]]
    return [root / f"{f}.html" for f in files if Path(f).name not in APPENDICES]


def _differs(before: dict, after: dict) -> bool:
    return any(not np.array_equal(np.array(before[n], dtype=float), np.array(after.get(n, []), dtype=float),
                                  equal_nan=True) for n in before)


def _check_chapter_sliders(site: Site, html_file: Path, visit: Visit, problems: list[str], report: list[str]) -> None:
    """Le chapitre a au moins une figure à curseurs. (Chaque curseur de chaque figure est ensuite déplacé
    par de vraies touches du clavier, et les données tracées doivent changer : :func:`_check_static_sliders`,
    sur la même visite.)"""
    if visit.page.locator(f"[{MARKER}]").count() == 0:
        problems.append(f"{html_file.relative_to(site.root).as_posix()} : aucune figure à curseurs")


#: Contraste WCAG entre la couleur du texte d'un élément et son fond (calculés par le navigateur).
_CONTRAST = r"""(el) => {
  const rgb = (c) => (c.match(/[\d.]+/g) || []).slice(0, 4).map(Number);
  const lum = ([r, g, b]) => {
    const f = (v) => { v /= 255; return v <= 0.03928 ? v / 12.92 : Math.pow((v + 0.055) / 1.055, 2.4); };
    return 0.2126 * f(r) + 0.7152 * f(g) + 0.0722 * f(b);
  };
  const style = getComputedStyle(el);
  let bg = rgb(style.backgroundColor);
  for (let p = el.parentElement; p && (bg.length === 4 && bg[3] === 0); p = p.parentElement) bg = rgb(getComputedStyle(p).backgroundColor);
  const a = lum(rgb(style.color)), b = lum(bg);
  return (Math.max(a, b) + 0.05) / (Math.min(a, b) + 0.05);
}"""


def _check_quiz(site: Site, html_file: Path, visit: Visit, problems: list[str], report: list[str]) -> None:
    """Chaque question du quiz de la page : une mauvaise réponse est marquée fausse, la bonne juste,
    l'explication se déplie ; aucune requête pendant le quiz."""
    name = html_file.relative_to(site.root).as_posix()
    page = visit.page
    questions = page.locator(".kc-quiz .kc-quiz-question")
    n = questions.count()
    if not 3 <= n <= 5:
        problems.append(f"{name} : {n} question(s) de quiz")
    calls: list[str] = []  # requêtes de données (XHR, fetch, WebSocket) pendant le quiz : aucune permise
    def listen(r):
        if r.resource_type in ("xhr", "fetch", "websocket", "eventsource"):
            calls.append(r.url)

    page.on("request", listen)
    for q in range(n):
        question = questions.nth(q)
        answer = int(question.get_attribute("data-answer"))
        radios = question.locator("input[type=radio]")

        def submit(choice: int) -> tuple[list[str], str]:  # coche la réponse n° choice et vérifie
            radios.nth(choice - 1).check()
            question.locator(".kc-quiz-check").click()
            return question.get_attribute("class").split(), question.locator(".kc-quiz-feedback").text_content()

        wrong = 1 if answer != 1 else 2
        classes, feedback = submit(wrong)
        if "kc-quiz-wrong" not in classes or not feedback.startswith("Pas tout"):
            problems.append(f"{name} : question {q + 1}, une mauvaise réponse n'est pas marquée fausse")
        # le message de la mauvaise réponse choisie, et lui seul, est montré (issue 36)
        shown = question.locator(".kc-quiz-why").evaluate_all(
            "ws => ws.filter(w => !w.hidden && w.offsetParent !== null).map(w => w.dataset.choice)")
        if shown != [str(wrong)]:
            problems.append(f"{name} : question {q + 1}, messages montrés {shown} pour la réponse {wrong}")
        if q == 0:  # « Vérifier » reste lisible au survol (fond et texte de la même couleur auparavant)
            button = question.locator(".kc-quiz-check")
            button.hover()
            ratio = page.evaluate(_CONTRAST, button.element_handle())
            if ratio < 4.5:
                problems.append(f"{name} : « Vérifier » au survol, contraste {ratio:.2f} < 4,5")
            page.mouse.move(0, 0)
        classes, feedback = submit(answer)
        if "kc-quiz-right" not in classes or not feedback.startswith("Juste"):
            problems.append(f"{name} : question {q + 1}, la bonne réponse n'est pas marquée juste")
        explanation = question.locator(".kc-quiz-explanation")
        if explanation.count() and not explanation.is_visible():
            problems.append(f"{name} : question {q + 1}, l'explication reste cachée")
    if calls or visit.blocked:
        problems.append(f"{name} : le quiz a fait des requêtes {calls + visit.blocked}")
    page.remove_listener("request", listen)
    if page_errors(visit, html_file.read_text()):
        problems.append(f"{name} : erreurs de page {visit.errors}")


# --------------------------------------------------------------------------- un écran, tout écran

_PANELS_IN_VIEW = r"""(id) => {
  // chaque panneau, amené en bas de l'écran : les curseurs (collés sous l'en-tête) et tout le panneau
  // sont visibles ensemble
  // (bas des en-têtes du thème encore à l'écran : l'en-tête du site défile, celui de l'article colle)
  const controls = document.getElementById(id + '-controls');
  const headerBottom = () => Math.max(0, ...[...document.querySelectorAll('.bd-header, .bd-header-article')]
    .filter(h => getComputedStyle(h).display !== 'none').map(h => h.getBoundingClientRect().bottom));
  const out = [];
  for (const panel of document.getElementById(id).querySelectorAll('.kc-bokeh-panel')) {
    panel.scrollIntoView({block: 'end'});
    const top = headerBottom();
    const p = panel.getBoundingClientRect(), c = controls.getBoundingClientRect();
    out.push({panel: panel.id, height: Math.round(p.height), controls: Math.round(c.height),
              ok: c.top >= top - 1 && c.bottom <= p.top + 1 && p.bottom <= window.innerHeight + 1 && p.height > 50});
  }
  const fig = document.getElementById(id).getBoundingClientRect();
  return {panels: out, figure: Math.round(fig.height)};
}"""


def _check_panels(site: Site, html_file: Path, visit: Visit, problems: list[str], report: list[str]) -> None:
    """Sur un portable (1366 × 768), chaque panneau de chaque figure de la page se voit en entier avec ses
    curseurs (collés sous l'en-tête quand on fait défiler la figure) ; aucun panneau ne dépasse 700 px."""
    name = html_file.relative_to(site.root).as_posix()
    page = visit.page
    for fid in figure_ids(page):
        found = page.evaluate(_PANELS_IN_VIEW, fid)
        heights = [p["height"] for p in found["panels"]]
        report.append(f"  {fid[3:-11]:30s} figure {format_spec(found['figure'], 'd'):>5s} px, curseurs "
                      f"{format_spec(found['panels'][0]['controls'], 'd'):>4s} px, panneaux "
                      f"{', '.join(format_spec(h, 'd') for h in heights)} px")
        for p in found["panels"]:
            if not p["ok"] or p["height"] > 700:
                problems.append(f"{name} : {p['panel']} ({p['height']} px) pas visible avec ses curseurs "
                                f"({p['controls']} px)")


# --------------------------------------------------------------------------- une visite par page, sur un portable


@dataclass
class Tour:
    """Ce qu'a trouvé une visite (d'une page, ou de toutes les pages sur un écran) : par vérification, les
    pages vues, les problèmes et le compte rendu."""

    visited: dict[str, list[str]] = field(default_factory=lambda: defaultdict(list))
    problems: dict[str, list[str]] = field(default_factory=lambda: defaultdict(list))
    reports: dict[str, list[str]] = field(default_factory=lambda: defaultdict(list))

    def assert_clean(self, key: str) -> None:
        assert self.visited[key], f"aucune page pour la vérification « {key} »"
        assert not self.problems[key], "\n".join(self.problems[key])


def _laptop_checks(html_file: Path, html: str, toc: set[Path]) -> list[tuple[str, Callable]]:
    """Les vérifications d'une page sur un portable, dans l'ordre où elles passent : la page telle qu'elle
    s'ouvre (axe-core compris), les panneaux (défilement seul), puis les curseurs (ils reviennent à leur
    position par défaut)."""
    checks: list[tuple[str, Callable]] = [("pages", _check_page)]
    if html_file in toc:
        checks.append(("panneaux", _check_panels))
        # TD, TP et sujet d'examen : pages d'exercices, sans figure à curseurs (PRACTICE_PAGES,
        # test_chapter_pedagogy.py)
        if not (html_file.stem.startswith(("tp-", "td-")) or html_file.stem == "sujet-examen"):
            checks.append(("chapitres", _check_chapter_sliders))
    if MARKER in html:
        checks.append(("curseurs", _check_static_sliders))
    return checks


def _phone_checks(html_file: Path, html: str, toc: set[Path]) -> list[tuple[str, Callable]]:
    """Les vérifications d'une page sur un téléphone en mode sombre : l'écran et axe-core, puis le quiz
    (clics)."""
    checks: list[tuple[str, Callable]] = [("téléphone", _check_phone)]
    if html_file in toc:
        checks.append(("quiz", _check_quiz))
    return checks


def _visit_page(browser, site: Site, html_file: Path, checks_of: Callable, viewport: dict,
                color_scheme: str, toc: set[Path], context=None) -> Tour:
    """Une page ouverte **une fois** (figures dessinées) ; les vérifications ``checks_of(page)`` s'y
    suivent et notent leurs problèmes à part. Une vérification qui lève une exception (assertion, délai
    de Playwright) compte comme un problème de la page, et les suivantes passent quand même."""
    tour = Tour()
    html = html_file.read_text()
    name = html_file.relative_to(site.root).as_posix()
    redirect = re.search(r'http-equiv="refresh" content="0; url=([^"]+)"', html, re.I)
    if redirect:  # page de redirection (index.html → première page) : la cible doit exister
        if checks_of is _laptop_checks:
            tour.visited["pages"].append(name)
            if not (html_file.parent / redirect[1]).is_file():
                tour.problems["pages"].append(f"{name} : redirection vers {redirect[1]} introuvable")
        return tour
    checks = checks_of(html_file, html, toc)
    try:
        visit = open_page(browser, site.url(html_file), site.base, viewport=viewport, color_scheme=color_scheme,
                          context=context)
    except playwright_api.Error as exc:
        for key, _ in checks:
            tour.visited[key].append(name)
            tour.problems[key].append(f"{name} : la page ne s'ouvre pas ({type(exc).__name__} : {exc})")
        return tour
    for key, check in checks:
        tour.visited[key].append(name)
        try:
            check(site, html_file, visit, tour.problems[key], tour.reports[key])
        except (AssertionError, playwright_api.Error) as exc:
            tour.problems[key].append(f"{name} : {type(exc).__name__} : {exc}")
    close_visit(visit, context)
    return tour


#: Visiteurs par écran : chaque visiteur est un fil avec son Playwright et son Chromium, qui prend la page
#: suivante de la file de son écran. (Une visite attend surtout Chromium et le pilote de Playwright :
#: un visiteur occupe environ un tiers de cœur.)
VISITORS_PER_SCREEN = 2


@pytest.fixture(scope="module")
def tours(site) -> tuple[Tour, Tour]:
    """Deux visites de chaque page : sur un portable en mode clair (:func:`_laptop_checks`) et sur un
    téléphone en mode sombre (:func:`_phone_checks`), par :data:`VISITORS_PER_SCREEN` visiteurs par écran,
    tous en même temps. Chaque test ci-dessous lit les problèmes de sa vérification ; les pages y sont
    dans l'ordre du site. (Une visite par test coûtait six chargements de chaque page, l'un après l'autre.)"""
    pages = html_pages(site.root)
    toc = set(_toc_pages(site.root))
    screens = {"portable": (_laptop_checks, LAPTOP, "light"), "téléphone": (_phone_checks, PHONE, "dark")}
    queues = {label: queue.SimpleQueue() for label in screens}
    for q in queues.values():
        for html_file in sorted(pages, key=lambda f: -f.stat().st_size):  # les plus longues d'abord
            q.put(html_file)
    found: dict[tuple[str, Path], Tour] = {}
    errors: list[BaseException] = []

    def visitor(label):
        checks_of, viewport, color_scheme = screens[label]
        try:
            with playwright_api.sync_playwright() as p:
                browser = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
                # un contexte par visiteur : ses pages partagent le cache HTTP (BokehJS, thème, polices
                # chargés et compilés une fois) ; ouvrir une page et dessiner ses figures coûte un tiers de
                # calcul en moins qu'avec un contexte neuf par page
                context = browser.new_context(viewport=viewport, color_scheme=color_scheme)
                while True:
                    try:
                        html_file = queues[label].get_nowait()
                    except queue.Empty:
                        break
                    found[label, html_file] = _visit_page(browser, site, html_file, checks_of, viewport,
                                                          color_scheme, toc, context)
                context.close()
                browser.close()
        except BaseException as exc:  # relevée dans le fil principal
            errors.append(exc)

    threads = [threading.Thread(target=visitor, args=(label,), name=f"{label}-{k}")
               for k in range(VISITORS_PER_SCREEN) for label in screens]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    if errors:
        raise errors[0]
    merged = {label: Tour() for label in screens}
    for label, tour in merged.items():
        for html_file in pages:
            part = found[label, html_file]
            for field_name in ("visited", "problems", "reports"):
                for key, items in getattr(part, field_name).items():
                    getattr(tour, field_name)[key].extend(items)
    return merged["portable"], merged["téléphone"]


def test_every_page_is_offline_typeset_and_drawn(tours, capsys):
    """Chaque page : hors ligne, sans erreur, formules composées, diagrammes dessinés, français du texte
    courant, premier chargement léger, aucune violation grave d'axe-core (:func:`_check_page`)."""
    assert "book/tension-constante.html" in tours[0].visited["pages"]
    with capsys.disabled():
        print("\nPages (portable 1366 × 768, mode clair) :\n" + "\n".join(tours[0].reports["pages"]))
    tours[0].assert_clean("pages")


def test_static_sliders_show_the_package_runs(tours, capsys):
    """Chaque curseur de chaque figure, au clavier et à la souris, affiche l'exécution du paquet
    (:func:`_check_static_sliders`)."""
    assert "book/tension-constante.html" in tours[0].visited["curseurs"], \
        "le chapitre « tension constante » n'a plus ses curseurs"
    with capsys.disabled():
        print("\n" + "\n".join(tours[0].reports["curseurs"]))
    tours[0].assert_clean("curseurs")


def test_every_chapter_has_a_slider_that_changes_the_plotted_data(tours):
    """Chaque chapitre (introduction comprise) a au moins une figure à curseurs qui marche dans la page
    publiée, sans noyau (:func:`_check_chapter_sliders`)."""
    tours[0].assert_clean("chapitres")


def test_every_quiz_marks_a_right_and_a_wrong_answer(tours):
    """Chaque question de chaque quiz, dans la page publiée, corrige juste et faux, sans requête
    (:func:`_check_quiz`)."""
    tours[1].assert_clean("quiz")


def test_each_panel_and_its_sliders_fit_a_laptop_screen(tours, capsys):
    """Sur un portable, chaque panneau se voit en entier avec ses curseurs (:func:`_check_panels`)."""
    with capsys.disabled():
        print("\nFigures sur un portable 1366 × 768 :\n" + "\n".join(tours[0].reports["panneaux"]))
    tours[0].assert_clean("panneaux")


_PHONE = r"""() => {
  const out = {overflow: document.documentElement.scrollWidth - window.innerWidth, wide: [], overlap: [],
               cut: [], values: []};
  const column = document.querySelector('main .bd-article, main article, main');
  const width = column ? column.getBoundingClientRect().width : window.innerWidth;
  // (le canevas de Bokeh aussi : un plan de largeur fixe dépassait de sa boîte, coupé par la colonne)
  for (const el of document.querySelectorAll('main .kc-bokeh-panel, main .kc-bokeh-canvas > *, main .kc-bokeh-slider, main img, main object')) {
    const b = el.getBoundingClientRect();
    if (b.width > 0 && (b.right > window.innerWidth + 1 || b.left < -1)) out.wide.push(el.id || el.tagName);
  }
  for (const root of document.querySelectorAll('.kc-bokeh-root')) {
    const boxes = [...root.querySelectorAll('.kc-bokeh-slider')].map(s => s.getBoundingClientRect());
    for (let i = 0; i < boxes.length; i++) for (let j = i + 1; j < boxes.length; j++) {
      const a = boxes[i], b = boxes[j];
      if (a.left < b.right - 1 && b.left < a.right - 1 && a.top < b.bottom - 1 && b.top < a.bottom - 1)
        out.overlap.push(root.id);
    }
  }
  // une équation plus large que la colonne doit pouvoir défiler dans son cadre (pas de coupe)
  for (const m of document.querySelectorAll("mjx-container[display='true']")) {
    let box = m, scrolls = false;
    for (let el = m; el && el !== document.body; el = el.parentElement) {
      const style = getComputedStyle(el);
      if (el.scrollWidth > el.clientWidth + 1 && (style.overflowX === 'auto' || style.overflowX === 'scroll')) {
        scrolls = true; box = el; break;
      }
    }
    const wide = m.scrollWidth > m.getBoundingClientRect().width + 1 ||
                 m.getBoundingClientRect().right > window.innerWidth + 1;
    // … et son début doit être atteignable : pas à gauche de son cadre (une équation centrée qui déborde
    // y perd son début)
    const math = m.querySelector('mjx-math');
    const start = scrolls ? box.getBoundingClientRect().left : 0;
    const lost = math && math.getBoundingClientRect().left < start - 1;
    if ((wide && !scrolls) || lost) out.cut.push((m.dataset.kcTex || m.textContent).slice(0, 40));
  }
  return out;
}"""


#: Contraste des cellules de tableau (texte contre le premier fond opaque au-dessus d'elles), en mode sombre :
#: axe-core range ces nœuds en « à revoir » quand le fond vient d'un ancêtre (sortie HTML de myst-nb) et ne les
#: signale pas ; un tableau kc.Table avait son texte blanc sur le fond clair de la sortie.
_TABLE_CONTRAST = r"""() => {
  const rgb = (c) => (c.match(/[\d.]+/g) || []).map(Number);
  const lum = ([r, g, b]) => { const f = (v) => { v /= 255; return v <= 0.03928 ? v / 12.92 : ((v + 0.055) / 1.055) ** 2.4; };
    return 0.2126 * f(r) + 0.7152 * f(g) + 0.0722 * f(b); };
  const bad = [];
  for (const cell of document.querySelectorAll('main td, main th')) {
    if (!cell.textContent.trim()) continue;
    let e = cell, bg = null;
    while (e && !bg) { const c = rgb(getComputedStyle(e).backgroundColor); if (c.length === 3 || (c.length === 4 && c[3] > 0.5)) bg = c; e = e.parentElement; }
    bg = bg || [255, 255, 255];
    const [a, b] = [lum(rgb(getComputedStyle(cell).color).slice(0, 3)), lum(bg.slice(0, 3))];
    const ratio = (Math.max(a, b) + 0.05) / (Math.min(a, b) + 0.05);
    if (ratio < 4.5) bad.push(cell.textContent.trim().slice(0, 20) + ' (' + ratio.toFixed(1) + ')');
  }
  return bad;
}"""

def _check_phone(site: Site, html_file: Path, visit: Visit, problems: list[str], report: list[str]) -> None:
    """Sur un téléphone (390 × 844), en mode sombre : la page ne déborde pas de l'écran, les figures tiennent
    dans la colonne, les curseurs ne se chevauchent pas et montrent leur valeur, chaque équation trop large
    défile dans son cadre ; axe-core (contrastes du mode sombre compris) ne trouve aucune violation grave
    ou critique, et la console reste vide."""
    name = html_file.relative_to(site.root).as_posix()
    page = visit.page
    assert page.evaluate("() => document.documentElement.dataset.theme") == "dark"
    found = page.evaluate(_PHONE)
    if found["overflow"] > 1:
        problems.append(f"{name} : la page déborde de {found['overflow']} px à droite")
    for key, label in (("wide", "hors de l'écran"), ("overlap", "curseurs qui se chevauchent"),
                       ("cut", "équations coupées")):
        if found[key]:
            problems.append(f"{name} : {label} {found[key][:4]}")
    for k, fid in enumerate(figure_ids(page)):
        fig = page.locator(f"[{MARKER}]").nth(k)
        axes = ki.slider_spec(fig.get_attribute(MARKER)).axes  # (les axes seuls : pas besoin de la grille)
        for s, axis in enumerate(axes):  # chaque curseur montre sa valeur, entière et lisible
            value = fig.locator(".bk-slider-value").nth(s)
            box, slider = value.bounding_box(), page.locator(f"#{fid}-slider-{s}").bounding_box()
            if value.text_content() != french_spacing(axis.labels()[axis.default]) or box is None or \
                    box["x"] + box["width"] > slider["x"] + slider["width"] + 1:
                problems.append(f"{name} : valeur du curseur {s} de {fid} illisible")
    violations = serious(axe_violations(page))
    for v in violations:
        problems.append(f"{name} : axe-core (mode sombre) « {v['id']} » ({v['nodes']}) {v['examples']}")
    faint = page.evaluate(_TABLE_CONTRAST)
    if faint:
        problems.append(f"{name} : cellules de tableau illisibles en mode sombre (contraste < 4,5) {faint[:4]}")
    for err in page_errors(visit, html_file.read_text()):
        problems.append(f"{name} : {err}")
    report.append(f"  {name:38s} axe-core (sombre, téléphone) : "
                  f"{format_spec(sum(v['nodes'] for v in violations), 'd')} nœud(s) grave(s)")


def test_phone_in_dark_mode_fits_the_column_and_passes_axe(tours, capsys):
    """Chaque page sur un téléphone, en mode sombre (:func:`_check_phone`)."""
    phone = tours[1]
    with capsys.disabled():
        print("\nPages sur un téléphone 390 × 844, mode sombre :\n" + "\n".join(phone.reports["téléphone"]))
    phone.assert_clean("téléphone")


# --------------------------------------------------------------------------- clavier et lecteur d'écran

_FOCUSED = r"""() => {
  let el = document.activeElement;
  while (el && el.shadowRoot && el.shadowRoot.activeElement) el = el.shadowRoot.activeElement;
  return el ? {tag: el.tagName.toLowerCase(), cls: String(el.className || ''), label: el.getAttribute('aria-label'),
               text: (el.textContent || '').trim().slice(0, 40)} : null;
}"""


def _tabs_to_slider(page, limit: int = 200) -> tuple[int, list[dict]]:
    """Tabulations depuis le haut de la page jusqu'au premier curseur, et les arrêts traversés."""
    stops = []
    for n in range(1, limit + 1):
        page.keyboard.press("Tab")
        focused = page.evaluate(_FOCUSED)
        if focused and "noUi-handle" in focused["cls"]:
            return n, stops
        stops.append(focused or {"tag": "?", "cls": "", "text": ""})
    return limit + 1, stops


def test_keyboard_reaches_the_first_slider_in_a_few_keys(site, browser, capsys):
    """Au clavier, depuis le haut de l'introduction : les formules ne sont plus des arrêts de tabulation,
    le lien « Aller à la figure à curseurs » (deuxième arrêt) mène au premier curseur en quatre touches,
    et le curseur s'annonce par son nom français et sa valeur avec unité."""
    url = site.url(site.root / "book" / "intro.html")
    visit = open_page(browser, url, site.base)
    page = visit.page
    assert page.evaluate("() => document.querySelectorAll('mjx-container[tabindex=\"0\"]').length") == 0
    assert page.locator("mjx-assistive-mml").count() > 0  # la MathML d'assistance reste
    page.evaluate("() => { document.activeElement && document.activeElement.blur(); window.scrollTo(0, 0); }")
    plain, stops = _tabs_to_slider(page)
    page.context.close()
    # Sans le lien d'évitement, chaque arrêt est un lien ou une commande : aucune formule, aucun conteneur.
    # (Leur nombre suit le texte : le plan de l'introduction renvoie à chaque page du livre.)
    others = [s for s in stops if s["tag"] not in ("a", "button", "input", "select", "summary", "label")]
    assert not others, others[:5]
    links = sum(s["tag"] == "a" for s in stops)

    visit = open_page(browser, url, site.base, figures=False)
    page = visit.page
    page.keyboard.press("Tab")
    page.keyboard.press("Tab")
    focused = page.evaluate(_FOCUSED)
    assert focused["text"] == "Aller à la figure à curseurs", focused
    page.keyboard.press("Enter")
    page.wait_for_function("() => document.querySelector('.kc-bokeh-root').dataset.kcReady === '1'", timeout=20000)
    page.keyboard.press("Tab")
    focused = page.evaluate(_FOCUSED)
    assert "noUi-handle" in focused["cls"], focused
    spec = ki.slider_spec(page.locator(f"[{MARKER}]").first.get_attribute(MARKER))
    axis = spec.axes[0]
    assert focused["label"] == french_spacing(f"{axis.symbol} — {axis.description}")
    handle = page.locator(".noUi-handle").first
    assert handle.get_attribute("aria-valuetext") == french_spacing(axis.labels()[axis.default])
    page.keyboard.press("ArrowRight")
    page.wait_for_timeout(50)
    assert handle.get_attribute("aria-valuetext") == french_spacing(axis.labels()[axis.default + 1])
    page.context.close()
    with capsys.disabled():
        print(f"\nClavier (introduction) : premier curseur atteint en {plain} tabulations depuis le haut de la "
              f"page (dont {links} liens), ou en 4 touches par le lien d'évitement (Tab, Tab, Entrée, Tab)")
    assert plain <= 200, "premier curseur jamais atteint au clavier"


_LAYOUT = """() => [...document.querySelectorAll(
    'main p, main li, main h2, main h3, main td, main a, main img, mjx-container, mjx-math')].map(e => {
    const r = e.getBoundingClientRect();
    return [r.left, r.top, r.width, r.height].map(v => Math.round(v * 4) / 4); })"""


def test_formula_boxes_keep_the_layout_and_come_back(site, browser):
    """Les boîtes qui remplacent les rendus CHTML le temps d'axe-core (:data:`BOX_FORMULAS`) : toutes les
    formules d'une page de formules deviennent des boîtes, la mise en page ne bouge pas (au quart de pixel
    près), la page revient à l'identique ; un rendu qui porte du texte ou un attribut de focus reste."""
    visit = open_page(browser, site.base + "book/estimateur.html", site.base, figures=False)
    page = visit.page
    # deux rendus que axe-core doit voir : du texte, un élément que le clavier atteint
    page.evaluate("""() => {
      const maths = document.querySelectorAll('mjx-container > mjx-math');
      maths[0].querySelector('mjx-c').append('x');
      maths[1].querySelector('mjx-c').setAttribute('tabindex', '0');
    }""")
    html = page.evaluate("() => document.querySelector('main').innerHTML")
    layout, n = page.evaluate(_LAYOUT), page.locator("mjx-container > mjx-math").count()
    count = page.evaluate(ELEMENT_COUNT)
    inside = page.evaluate("""() => [...document.querySelectorAll('mjx-container > mjx-math')].slice(2)
        .reduce((total, m) => total + m.getElementsByTagName('*').length, 0)""")
    assert n > 100
    report = page.evaluate(BOX_FORMULAS)
    assert report == {"boxed": n - 2, "kept": 2}
    assert page.evaluate(_LAYOUT) == layout
    assert page.evaluate(ELEMENT_COUNT) == count - inside  # le rendu de chaque boîte, hors du document
    assert page.locator("mjx-math mjx-c").count() > 0  # les deux rendus gardés
    page.evaluate(UNBOX_FORMULAS)
    assert page.evaluate("() => document.querySelector('main').innerHTML") == html
    assert page.evaluate(_LAYOUT) == layout
    close_visit(visit, None)


def test_dragging_a_slider_leaves_the_page_style(site, browser):
    """Glisser un curseur ne recalcule pas le style de toute la page : noUiSlider (dans BokehJS) écrit
    « cursor » et « user-select » dans le style de body pendant le glissé, mais body garde son style calculé
    (règle de kc/kc-pages.css ; sans elle, deux recalculs du style du document à chaque glissé, ≈ 150 ms
    chacun sur un chapitre à curseurs). Le glissé déplace bien le curseur, et le texte de la page n'est pas
    sélectionné quand la souris y passe."""
    visit = open_page(browser, site.base + "book/tension-constante.html", site.base)
    page = visit.page
    handle = page.locator(f"[{MARKER}] .noUi-handle").first
    base = page.locator(f"[{MARKER}] .noUi-base").first
    handle.focus()  # comme les vérifications des curseurs : le clavier d'abord, puis la souris
    page.keyboard.press("End")
    computed = "() => { const s = getComputedStyle(document.body); return [s.cursor, s.userSelect]; }"
    before, end = page.evaluate(computed), handle.get_attribute("aria-valuenow")
    hb, bb = handle.bounding_box(), base.bounding_box()
    y = hb["y"] + hb["height"] / 2
    page.mouse.move(hb["x"] + hb["width"] / 2, y)
    page.mouse.down()
    page.mouse.move(bb["x"] + 0.3 * bb["width"], y, steps=4)
    written = page.evaluate("() => document.body.getAttribute('style') || ''")
    during = page.evaluate(computed)
    page.mouse.move(bb["x"] + 0.3 * bb["width"], max(y - 200, 5), steps=4)  # au-dessus du curseur : le texte
    selected = page.evaluate("() => window.getSelection().toString()")
    page.mouse.up()
    assert "cursor" in written, f"noUiSlider n'a rien écrit dans le style de body ({written!r}) : test à revoir"
    assert during == before == ["auto", "auto"], f"style de body pendant le glissé : {during} (avant : {before})"
    assert selected == "", f"texte sélectionné pendant le glissé : {selected[:80]!r}"
    assert handle.get_attribute("aria-valuenow") != end, "le glissé n'a pas déplacé le curseur"
    assert not visit.errors, visit.errors
    close_visit(visit, None)


def test_diagrams_and_quiz_answers_have_text_alternatives(site, browser):
    """Les diagrammes ont un texte de remplacement (les textes de leurs boîtes) ; chaque réponse de quiz
    a un nom accessible lisible, formules écrites en texte."""
    html_file = site.root / "book" / "predicteur-correcteur.html"
    visit = open_page(browser, site.url(html_file), site.base, figures=False)
    page = visit.page
    labels = page.evaluate("() => [...document.querySelectorAll('object[type=\"image/svg+xml\"]')].map(o => "
                           "[o.getAttribute('role'), o.getAttribute('aria-label')])")
    assert len(labels) == 3
    for role, label in labels:
        assert role == "img" and label.startswith("Diagramme : ") and len(label) > 40, label
    names = page.evaluate("() => [...document.querySelectorAll('.kc-quiz input[type=radio]')].map(r => "
                          "r.getAttribute('aria-label'))")
    assert names and all(re.fullmatch(r"Réponse [a-e] : .+", n) for n in names), names
    assert not any("\\" in n or "{" in n for n in names), names  # pas de TeX brut
    # « Vérifier » au survol, en mode clair (issue 36 : fond et texte rgb(34, 40, 50))
    button = page.locator(".kc-quiz-check").first
    button.scroll_into_view_if_needed()
    button.hover()
    assert page.evaluate(_CONTRAST, button.element_handle()) >= 4.5
    page.context.close()


# --------------------------------------------------------------------------- recherche


def test_search_shows_readable_snippets(site, browser):
    """La recherche du site trouve « innovation » dans le chapitre qui la définit, et ses extraits
    montrent les formules en texte lisible, sans TeX brut."""
    visit = open_page(browser, site.base + "search.html?q=innovation", site.base, figures=False)
    page = visit.page
    page.wait_for_function("() => document.querySelectorAll('#search-results li').length > 0", timeout=30000)
    page.wait_for_timeout(1500)  # les extraits arrivent page par page
    results = page.evaluate("""() => [...document.querySelectorAll('#search-results li')].map(li => ({
        href: li.querySelector('a').getAttribute('href'), text: li.textContent}))""")
    hrefs = [r["href"] for r in results]
    assert any("predicteur-correcteur" in h for h in hrefs[:3]), hrefs[:5]
    for r in results:
        assert not re.search(r"\\\(|\\\)|\\\[|\\[a-zA-Z]{2,}", r["text"]), r["text"][:200]
    assert not page_errors(visit, "")
    page.context.close()


def _search(site, browser, query: str) -> tuple[Visit, list[dict]]:
    visit = open_page(browser, site.base + f"search.html?q={query}", site.base, figures=False)
    page = visit.page
    page.wait_for_function("() => document.querySelector('#search-results .search-summary, #search-results p')",
                           timeout=30000)
    page.wait_for_timeout(1500)  # les extraits arrivent page par page
    results = page.evaluate("""() => [...document.querySelectorAll('#search-results li')].map(li => ({
        href: li.querySelector('a').getAttribute('href'), text: li.textContent}))""")
    return visit, results


def test_search_speaks_french_and_reads_the_article_only(site, browser):
    """La recherche (issue 36) : le champ dit « Rechercher dans le livre… » et sa loupe ne couvre pas le texte
    tapé ; l'index ne contient pas le TeX des formules (« aligned » ne trouve rien) ; « gating » trouve le
    glossaire ; les extraits ne montrent ni le TeX d'un environnement (« && ») ni la table des matières de la
    page, ni ses importations."""
    visit, results = _search(site, browser, "gauss")
    page = visit.page
    field = page.locator("form.bd-search input[type=search]").first
    assert field.get_attribute("placeholder") == "Rechercher dans le livre…"
    gap = page.evaluate("""() => {
        const form = document.querySelector('.bd-search-container form.bd-search') ||
                     document.querySelector('form.bd-search');
        const icon = form.querySelector('.fa-magnifying-glass').getBoundingClientRect();
        const input = form.querySelector('input');
        const start = input.getBoundingClientRect().left + parseFloat(getComputedStyle(input).paddingLeft);
        return start - icon.right;
    }""")
    assert gap >= 0, f"la loupe recouvre le texte du champ de {-gap:.1f} px"
    gaussian = [r for r in results if "filtre-gaussien" in r["href"]]
    assert gaussian, [r["href"] for r in results]
    for r in results:
        assert "&&" not in r["text"] and "aligned" not in r["text"], r["text"][:200]
        assert "Importations du chapitre" not in r["text"], r["text"][:200]
    # la table des matières de la page : ses titres de sections, à la suite
    assert "Quatre règles pour trois intégrales La banane" not in " ".join(gaussian[0]["text"].split())
    close_visit(visit, None)
    visit, results = _search(site, browser, "aligned")
    assert results == [], [r["href"] for r in results]
    close_visit(visit, None)
    visit, results = _search(site, browser, "gating")
    assert any("glossaire" in r["href"] for r in results), [r["href"] for r in results]
    assert any("capteurs-temps-irregulier" in r["href"] for r in results), [r["href"] for r in results]
    close_visit(visit, None)
