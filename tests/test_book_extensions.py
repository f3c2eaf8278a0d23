"""Extensions Sphinx du livre, sans construction : extraits de code sans docstring, citations
auteur–année en français (étiquettes et listes rendues par pybtex, comparées à des chaînes écrites à
la main)."""

from __future__ import annotations

import inspect
import re
from pathlib import Path

import pybtex.plugin
import pytest
from pybtex.database import parse_file

import kalman_course.core.linalg as linalg
from kalman_course.sphinx.citations import FORMATTING_STYLE, author_year_label, register
from kalman_course.sphinx.listings import source_without_docstring

ROOT = Path(__file__).resolve().parent.parent


def test_source_listing_drops_the_docstring_only():
    code, path = source_without_docstring("kalman_course.core.linalg.kalman_gain")
    assert path == Path(inspect.getsourcefile(linalg))
    assert code.startswith("def kalman_gain(")
    assert ":math:" not in code and '"""' not in code and "r\"\"\"" not in code
    assert "psd_solve(S, PHt.T" in code and code.rstrip().endswith("return Kt.T, S, PHt")
    # une fonction sans docstring est rendue entière
    code2, _ = source_without_docstring("kalman_course.filters.kalman._predict")
    assert code2 == inspect.getsource(__import__("kalman_course.filters.kalman", fromlist=["_predict"])._predict)


def test_source_listing_unknown_name():
    with pytest.raises((ImportError, AttributeError)):
        source_without_docstring("kalman_course.core.linalg.n_existe_pas")


@pytest.fixture(scope="module")
def bib():
    register()
    return parse_file(str(ROOT / "book" / "references.bib"))


def test_author_year_labels_are_french(bib):
    labels = {key: author_year_label(e) for key, e in bib.entries.items()}
    assert labels["kalman1960"] == "Kalman, 1960"
    assert labels["welch2006"] == "Welch et Bishop, 2006"
    assert labels["barshalom2001"] == "Bar-Shalom et al., 2001"
    assert labels["chardon"] == "Chardon, s.\u00a0d."
    assert labels["sarkka2013"] == "Särkkä, 2013"
    assert not any(" and " in label for label in labels.values())


def test_french_bibliography_style(bib):
    style = pybtex.plugin.find_plugin("pybtex.style.formatting", FORMATTING_STYLE)()
    rendered = {e.key: (e.label, e.text.render_as("text")) for e in style.format_entries(bib.entries.values())}
    label, text = rendered["welch2006"]
    assert label == "Welch et Bishop, 2006"
    assert text.startswith("Greg Welch et Gary Bishop. An introduction to the Kalman filter. Rapport technique")
    assert all(" and " not in t.split(". ")[0] for _, t in rendered.values())  # auteurs (les titres restent)
    assert "Technical Report" not in " ".join(t for _, t in rendered.values())


# --------------------------------------------------------------------------- où vit le code Sphinx

PACKAGE = ROOT / "kalman_course"
SPHINX_LIBRARIES = {"sphinx", "docutils", "sphinxcontrib", "sphinx_book_theme", "pybtex", "pybtex_docutils"}


def _imported_modules(source: str, package: str) -> set[str]:
    """Modules importés par le code ``source`` d'un module du paquet ``package`` (« kalman_course.x ») ;
    les imports relatifs sont résolus."""
    import ast

    parts = package.split(".") if package else []
    found = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                module = ".".join(parts[: len(parts) - node.level + 1] + ([node.module] if node.module else []))
                found.add(module)
                found |= {f"{module}.{alias.name}" for alias in node.names}
            else:
                found.add(node.module)
    return found


def _package_of(path: Path) -> str:
    return ".".join(path.relative_to(ROOT).parts[:-1])


def test_sphinx_code_lives_in_kalman_course_sphinx_only():
    """Tout le code Sphinx/docutils est dans kalman_course/sphinx/ ; aucun module du paquet ni script ne
    l'importe (seul _config.yml le charge) ; les extensions déclarées sont exactement ses modules."""
    import yaml

    outside = [p for p in PACKAGE.rglob("*.py") if "sphinx" not in p.relative_to(PACKAGE).parts]
    outside += list((ROOT / "scripts").glob("*.py"))
    assert len(outside) > 50
    for path in outside:
        imported = _imported_modules(path.read_text(), _package_of(path))
        sphinx_libs = {m for m in imported if m.split(".")[0] in SPHINX_LIBRARIES}
        assert not sphinx_libs, f"{path.relative_to(ROOT)} importe {sorted(sphinx_libs)}"
        ours = {m for m in imported if m == "kalman_course.sphinx" or m.startswith("kalman_course.sphinx.")}
        assert not ours, f"{path.relative_to(ROOT)} importe {sorted(ours)}"
    modules = sorted(f"kalman_course.sphinx.{p.stem}" for p in (PACKAGE / "sphinx").glob("*.py") if p.stem != "__init__")
    declared = yaml.safe_load((ROOT / "_config.yml").read_text())["sphinx"]["extra_extensions"]
    assert sorted(e for e in declared if e.startswith("kalman_course")) == modules


def test_import_check_resolves_relative_imports():
    """Le relevé des imports voit ``from ..sphinx import x`` écrit dans kalman_course/interactive/."""
    found = _imported_modules("from ..sphinx import quiz\nfrom docutils import nodes\n", "kalman_course.interactive")
    assert {"kalman_course.sphinx", "kalman_course.sphinx.quiz", "docutils"} <= found
    assert _package_of(PACKAGE / "interactive" / "static.py") == "kalman_course.interactive"


# --------------------------------------------------------------------------- formules composées à la construction

_SPHINX_PAGE = """<html><head></head><body><div class="document"><p>Soit
<span class="math notranslate nohighlight">\\(x^2\\)</span> et <span class="math notranslate nohighlight">\\(a &lt; b\\)</span>.</p>
<div class="math notranslate nohighlight" id="equation-eq-k">
<span class="eqno">(1)<a class="headerlink" href="#equation-eq-k" title="Lien vers cette équation">#</a></span>\\[K = \\frac{P}{P + R}\\]</div>
<pre>\\(pas une formule\\)</pre></div></body></html>"""


@pytest.fixture(scope="module")
def mathjax_settings():
    import yaml

    config = yaml.safe_load((ROOT / "_config.yml").read_text())["sphinx"]["config"]["mathjax3_config"]
    return {"mathjax": ROOT / "node_modules" / "mathjax" / "es5", "load": config["loader"]["load"], "tex": config["tex"]}


def test_formulas_are_typeset_at_build_time_with_their_mathml(tmp_path, mathjax_settings):
    """Chaque ``\\(…\\)`` et ``\\[…\\]`` de Sphinx devient la sortie CHTML de MathJax, avec la MathML
    d'assistance (écrite ici à la main) et le TeX dans ``data-kc-tex`` ; le numéro d'équation et le code
    restent ; une page déjà composée ne change plus (constructions incrémentales)."""
    from kalman_course.sphinx.formulas import FONT_URL, typeset_pages

    page = tmp_path / "chapitre.html"
    page.write_text(_SPHINX_PAGE)
    css, problems = typeset_pages([page], **mathjax_settings)
    assert problems == []
    out = page.read_text()
    assert out.count("<mjx-container") == 3
    assert '<math xmlns="http://www.w3.org/1998/Math/MathML"><msup><mi>x</mi><mn>2</mn></msup></math>' in out
    assert "<mi>a</mi><mo>&lt;</mo><mi>b</mi>" in out
    assert ("<mi>K</mi><mo>=</mo><mfrac><mi>P</mi><mrow><mi>P</mi><mo>+</mo><mi>R</mi></mrow></mfrac>" in out)
    assert 'data-kc-tex="a &lt; b"' in out and 'data-kc-tex="K = \\frac{P}{P + R}"' in out
    assert 'jax="CHTML" display="true"' in out and '<span class="eqno">(1)' in out
    assert "<pre>\\(pas une formule\\)</pre>" in out
    assert "\\(x^2" not in out and "\\[K" not in out
    # la feuille commune : polices servies par le site, relatives à _static/kc/
    fonts = ROOT / "book" / "vendor" / "kc"
    urls = set(__import__("re").findall(r'url\("?([^")]+\.woff)', css))
    assert urls and all(u.startswith(FONT_URL) for u in urls)
    assert all((fonts / u).resolve().is_file() for u in urls), sorted(urls)[:3]
    again, _ = typeset_pages([page], **mathjax_settings)
    assert page.read_text() == out and again == css


def test_a_formula_mathjax_refuses_names_its_page(tmp_path, mathjax_settings):
    from kalman_course.sphinx.formulas import typeset_pages

    page = tmp_path / "td.html"
    page.write_text('<span class="math notranslate nohighlight">\\(\\hatx + 1\\)</span>'
                    '<span class="math notranslate nohighlight">\\(\\frac{1}{\\)</span>')
    _, problems = typeset_pages([page], **mathjax_settings)
    assert problems == ["td.html : « \\hatx + 1 » : commande inconnue \\hatx",
                        "td.html : « \\frac{1}{ » : Missing close brace"]


# --------------------------------------------------------------------------- sphinx-proof en français (issue 36)

_PROOF_PAGE = """# Chapitre

```{prf:algorithm} Un pas du filtre
:label: alg-pas

1. Prédire.
2. Corriger.
```

```{prf:proof}
:class: dropdown

Par **Fubini**, les deux intégrales sont égales.
```
"""


def _sphinx_project(tmp_path: Path, builder: str) -> tuple[int, Path, str]:
    import contextlib
    import io

    from sphinx.cmd.build import build_main

    src = tmp_path / f"src-{builder}"
    src.mkdir()
    (src / "conf.py").write_text('extensions = ["myst_parser", "sphinx_proof", "kalman_course.sphinx.proofs"]\n'
                                 'myst_enable_extensions = ["colon_fence", "dollarmath"]\nlanguage = "fr"\n'
                                 'root_doc = "index"\nnumfig = True\n')
    (src / "index.md").write_text(_PROOF_PAGE)
    out, log = tmp_path / f"out-{builder}", io.StringIO()
    with contextlib.redirect_stderr(log):
        code = build_main(["-b", builder, "-q", "-W", "-E", str(src), str(out)])
    return code, out, log.getvalue()


def test_proofs_get_a_french_title_and_fold(tmp_path):
    """« Proof. » (sphinx-proof) devient un encadré titré « Démonstration », replié avec ``:class: dropdown``
    (le titre sert de bouton à sphinx-togglebutton)."""
    code, out, log = _sphinx_project(tmp_path, "html")
    assert code == 0, log
    html = (out / "index.html").read_text()
    assert "Proof." not in html
    box = re.search(r'<div class="([^"]*)" id="([^"]+)">\s*<p class="admonition-title">Démonstration</p>', html)
    assert box and {"proof", "dropdown", "admonition"} <= set(box.group(1).split()), html
    assert box.group(2) != "proof"  # un identifiant par encadré (sphinx-proof donnait « proof » à toutes)
    assert "Par <strong>Fubini</strong>, les deux" in html


def test_algorithm_boxes_are_titled_in_french_in_the_pdf(tmp_path):
    """Dans le LaTeX (le PDF), les encadrés d'algorithme sont titrés « Algorithme », comme sur le site."""
    code, out, log = _sphinx_project(tmp_path, "latex")
    assert code == 0, log
    tex = next(out.glob("*.tex")).read_text()
    assert "Algorithm " not in tex.replace("\\begin{algorithm", "") and "Algorithme" in tex
    assert "Proof." not in tex and "Démonstration" in tex
