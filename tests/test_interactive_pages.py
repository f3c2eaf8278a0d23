"""L'extension des pages (:mod:`kalman_course.sphinx.pages`) sans construire le livre : icônes
extraites du script du thème, textes de remplacement des diagrammes, données des figures sorties du
HTML, importations des chapitres (elles s'exécutent), formules en texte lisible (Python et JavaScript
donnent le même texte)."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from pathlib import Path

import pytest

import kalman_course.interactive as ki
from kalman_course.sphinx import pages
from kalman_course.sphinx.quiz import tex_to_text

ROOT = Path(__file__).resolve().parent.parent
BOOK = ROOT / "book"
SCRIPT = pages.ASSETS / "kc" / "kc-pages.js"


def _theme_fontawesome() -> Path:
    import pydata_sphinx_theme

    return Path(pydata_sphinx_theme.__file__).parent / "theme" / "pydata_sphinx_theme" / "static" / "scripts" / \
        "fontawesome.js"


def test_icons_are_taken_from_the_theme_script_with_their_true_paths():
    source = _theme_fontawesome().read_text()
    icons = pages.fontawesome_icons(source)
    assert len(icons) > 1000
    # la loupe de la recherche : 512 × 512, le tracé du script du thème (vérifié ici dans le texte même)
    w, h, paths = icons[("fas", "magnifying-glass")]
    assert (w, h) == (512, 512) and paths[0].startswith("M416 208c0 45.9")
    assert f'"magnifying-glass":[512,512,' in source and paths[0] in source
    css = pages.icon_css({("fas", "magnifying-glass"), ("fas", "sun"), ("fas", "absente")}, icons)
    assert ".fa-solid.fa-magnifying-glass::before" in css and ".fas.fa-sun::before" in css
    assert "absente" not in css
    assert "#" not in re.sub(r"%23", "", css.split("*/", 1)[1])  # « # » encodé dans les URL data:
    assert len(css) < 20_000  # quelques icônes, pas 1,5 Mo


def test_mermaid_alternative_lists_the_boxes_in_order():
    svg = ('<svg><g><foreignObject><div><span class="nodeLabel">Prédiction<br>x̂⁻</span></div></foreignObject>'
           '<text>Correction</text><span>Prédiction</span><p>K &amp; S</p></g></svg>')
    assert pages.mermaid_alt(svg) == "Diagramme : Prédiction ; x̂⁻ ; Correction ; K & S."
    assert pages.mermaid_alt("<svg></svg>") == "Diagramme."


def test_figure_data_leaves_the_page_for_a_script_file():
    html = ki.sliders("intro-chariot").html()
    written = {}

    def write(fid, data):
        written[fid] = data
        return f"../_static/kc-data/{fid}.js"

    body = pages.extract_figure_data(f"<p>avant</p>{html}<p>après</p>", write)
    (fid, data), = written.items()
    assert f'id="{fid}-item" data-src="../_static/kc-data/{fid}.js"></script>' in body
    assert len(body) < len(html) / 5 and "<p>avant</p>" in body and "<p>après</p>" in body
    item = json.loads(data)  # le JSON du document Bokeh, intact
    assert set(item) == {"docs_json", "render_items"}
    assert f'id="{fid}-sliders"' in body  # la description des curseurs reste dans la page


@pytest.mark.parametrize("page", sorted(p.stem for p in BOOK.glob("*.md")))
def test_chapter_imports_shown_to_students_run(page):
    """Les importations montrées avant la première cellule visible s'exécutent telles quelles, et
    définissent les noms employés par les cellules visibles du chapitre."""
    source = (BOOK / f"{page}.md").read_text()
    lines = pages.hidden_imports(source)
    visible = [c for c in re.findall(r"^```\{code-cell\}[^\n]*\n(.*?)^```", source, re.S | re.M)
               if not re.search(r"^:tags:.*\b(remove-cell|remove-input)\b", c, re.M)]
    if not visible:
        return
    namespace: dict = {}
    exec("\n".join(lines), namespace)  # noqa: S102 — le code même que la page montre
    code = "\n".join(visible)
    for name in ("kc", "np", "engine"):
        if re.search(rf"\b{name}\.", code) and not re.search(rf"^\s*import .* as {name}\b|^\s*from .* import .*\b{name}\b",
                                                              code, re.M):
            assert name in namespace, f"{page} : « {name} » employé sans importation montrée"
    assert "kalman_course" in "\n".join(lines) or "kc." not in code
    block = pages.imports_block(lines)
    assert block.startswith('<details class="kc-imports">') and "highlight" in block


@pytest.mark.parametrize("tex, text", [
    (r"K = P^-_{n+1}C^TS_{n+1}^{-1}", "K = P⁻ₙ₊₁CᵀSₙ₊₁⁻¹"),
    (r"\hat x_n = \hat x_n^- + K(y_n - C\hat x_n^-)", "x̂ₙ = x̂ₙ⁻ + K(yₙ - Cx̂ₙ⁻)"),
    (r"K^\star = 0{,}5", "K* = 0,5"),
    (r"\frac{P^-}{P^- + R}", "(P⁻)/(P⁻ + R)"),
    (r"\sqrt{R} = 1\,\mathrm{m}", "√(R) = 1 m"),
    (r"\sigma_\theta^2", "σ_θ²"),
])
def test_formulas_become_readable_text_in_python_and_in_the_page_script(tex, text):
    assert tex_to_text(tex) == text
    if shutil.which("node") is None:
        pytest.skip("Node.js absent : le script de la page n'est pas vérifié")
    js = ("global.window={addEventListener(){}};global.document={currentScript:null,readyState:'loading',"
          "querySelectorAll:()=>[],querySelector:()=>null,addEventListener(){},"
          "createElement(){return{set innerHTML(v){this.value=v}}}};"
          f"require({json.dumps(str(SCRIPT))});"
          "process.stdout.write(JSON.stringify([window.kcTexToText(process.argv[1]),"
          "window.kcReadableMath('voir \\\\('+process.argv[1]+'\\\\) ici')]));")
    out = subprocess.run(["node", "-e", js, tex], capture_output=True, text=True, check=True).stdout
    assert json.loads(out) == [text, f"voir {text} ici"]


def test_theme_css_glyphs_are_found_in_variables_and_content_rules_but_not_icon_rules():
    css = ('.fa-bars:before,.fa-navicon:before{content:"\\f0c9"}:root{--pst-icon-lightbulb:"\uf0eb";'
           '--pst-icon-admonition-tip:var(--pst-icon-lightbulb)}.admonition-title:after{content:var(--x)}'
           'a.github:before{content:"\\f09b";color:red}.other{content:"x"}')
    assert pages.css_glyphs(css) == {0xF0EB, 0xF09B}


def test_fontawesome_fonts_are_cut_to_the_glyphs_the_theme_uses(tmp_path):
    from fontTools.ttLib import TTFont

    webfonts = _theme_fontawesome().parent.parent / "vendor" / "fontawesome" / "webfonts"
    static = tmp_path / "_static"
    (static / "vendor" / "fontawesome" / "webfonts").mkdir(parents=True)
    (static / "kc").mkdir()
    for ttf in webfonts.glob("*.ttf"):
        shutil.copy(ttf, static / "vendor" / "fontawesome" / "webfonts" / ttf.name)
    css = pages.subset_fonts(static, {0xF0EB, 0xF05A, 0xF09B})
    assert css.count("@font-face") == 3 and 'font-family:"Font Awesome 6 Brands"' in css
    solid = TTFont(static / "kc" / "fa-solid-900.woff")
    full = TTFont(webfonts / "fa-solid-900.ttf")
    assert {0xF0EB, 0xF05A} <= set(solid.getBestCmap()) and 0xF0C9 not in solid.getBestCmap()
    assert full["glyf"][full.getBestCmap()[0xF0EB]].numberOfContours == \
        solid["glyf"][solid.getBestCmap()[0xF0EB]].numberOfContours  # le même glyphe, pas un autre
    assert 0xF09B in TTFont(static / "kc" / "fa-brands-400.woff").getBestCmap()
    assert (static / "kc" / "fa-solid-900.woff").stat().st_size < 5000 < (webfonts / "fa-solid-900.woff2").stat().st_size
