"""Le livre : construction propre (-W, aucune alerte, aucune cellule en erreur) et contenu des pages.

Les tests statiques (sans construction) vérifient que les chapitres ne contiennent pas de code de
tracé et n'appellent que des figures enregistrées. Les autres utilisent la fixture ``built_book`` de
``conftest.py`` (une construction complète par session ; ``KALMAN_BOOK_BUILD_DIR`` choisit le dossier).
"""

from __future__ import annotations

import html as htmllib
import re
from pathlib import Path

import pytest
import yaml

import kalman_course as kc
from kalman_course.figures._registry import CHAPTER_TITLES

from conftest import ROOT as REPO_ROOT, tree_state

ROOT = Path(__file__).resolve().parent.parent
BOOK = ROOT / "book"

# Chapitres de la partie « Le filtre de Kalman linéaire », dans l'ordre du cours, et page des références.
LINEAR_CHAPTERS = [
    "controle-systeme", "estimateur", "predicteur-correcteur", "gain-optimal", "tension-constante",
    "pratique-synthese",
]
# Annexes : pages sans figure ni exercice.
APPENDICES = {"references", "errata", "glossaire"}
# Travaux pratiques : l'étudiant écrit les fonctions ; la solution (repliée) est son code, vérifié par
# practice.check à la construction.
PRACTICAL_WORK = {Path(f).stem for f in (ROOT / "book").glob("tp-*.md")}
# Tous les chapitres du livre (hors introduction et annexes), tels que _toc.yml les liste.
ALL_CHAPTERS = [
    Path(f).name
    for f in [c["file"] for part in yaml.safe_load((ROOT / "_toc.yml").read_text())["parts"] for c in part["chapters"]]
    if Path(f).name not in APPENDICES
]
# Aucun avertissement n'est toléré dans le journal. (L'avis d'ipykernel « Kernel is running over TCP
# without encryption », émis par chaque noyau qui parle en TCP local à la construction, est retiré à la
# source par scripts/ipython_kernel_config.py, que scripts/setup.sh installe dans .venv.)


def _toc_files() -> list[str]:
    toc = yaml.safe_load((ROOT / "_toc.yml").read_text())
    files = [toc["root"]]
    for part in toc.get("parts", []):
        files += [chapter["file"] for chapter in part["chapters"]]
    return files


def _code_cells(text: str) -> list[str]:
    return re.findall(r"```\{code-cell\}[^\n]*\n(.*?)```", text, flags=re.S)


# --------------------------------------------------------------------------- sans construction


def test_toc_has_the_lecture_order_and_references_last():
    files = _toc_files()
    linear = [f for f in files if Path(f).name in LINEAR_CHAPTERS]
    assert linear == [f"book/{name}" for name in LINEAR_CHAPTERS]
    assert files[-1] == "book/references"


@pytest.mark.parametrize("chapter", ALL_CHAPTERS)
def test_chapters_hold_no_plotting_code_and_draw_registered_figures(chapter):
    text = (BOOK / f"{chapter}.md").read_text()
    code = "\n".join(_code_cells(text))
    for forbidden in ("matplotlib", "pyplot", ".plot(", ".scatter(", ".hist(", "savefig", "set_xlabel"):
        assert forbidden not in code, f"{chapter} : code de tracé « {forbidden} » dans une cellule"
    drawn = re.findall(r"kc\.figures\.draw\(\"([^\"]+)\"[,)]", code)  # TP : draw("nom", predict=predict)
    assert drawn, f"{chapter} : aucune figure"
    for name in drawn:
        assert name in kc.figures.REGISTRY, f"{chapter} : figure inconnue {name}"
    own = [n for n, spec in kc.figures.REGISTRY.items() if spec.chapter == chapter]
    assert sorted(set(drawn)) == sorted(own), f"{chapter} : figures du registre non montrées"


@pytest.mark.parametrize("chapter", ALL_CHAPTERS)
def test_each_chapter_has_an_exercise_with_a_hidden_computed_solution(chapter):
    text = (BOOK / f"{chapter}.md").read_text()
    labels = re.findall(r"```\{exercise\}\n:label: (\S+)", text)
    assert labels, f"{chapter} : aucun exercice"
    for label in labels:
        block = re.search(r"```\{solution-start\} " + re.escape(label) + r"\n(.*?)```\{solution-end\}", text, re.S)
        assert block, f"{chapter} : pas de solution pour {label}"
        assert ":class: dropdown" in block.group(1)
        if chapter in PRACTICAL_WORK:
            # TP : la solution est le code de l'étudiant (numpy seul) ; c'est la cellule practice.check
            # qui suit le bloc, exécutée à la construction, qui la vérifie contre le paquet.
            after = text[block.end():]
            assert re.match(r"[^\n]*\n```\s*```\{code-cell\}[^\n]*\npractice\.check\(", after), \
                f"{label} : la solution du TP n'est pas suivie de sa vérification practice.check(...)"
        else:
            assert "kc." in "".join(_code_cells(block.group(1) + "```")), f"{label} : la solution n'appelle pas le paquet"


def test_figure_registry_knows_every_chapter_title():
    """``python -m kalman_course.figures --list`` cite le chapitre de chaque figure par son titre : ces
    titres (kalman_course/figures/_registry.py) doivent être ceux des chapitres du livre."""
    for chapter in sorted({spec.chapter for spec in kc.figures.REGISTRY.values()}):
        heading = re.search(r"(?m)^# (.+)$", (BOOK / f"{chapter}.md").read_text()).group(1).strip()
        assert CHAPTER_TITLES.get(chapter) == heading, (
            f"{chapter} : titre « {heading} » absent de CHAPTER_TITLES ou différent"
        )


# --------------------------------------------------------------------------- construction


@pytest.mark.book
def test_build_log_has_no_warning(built_book):
    log = (built_book.parent / "build.log").read_text()
    warnings = [line for line in log.splitlines() if "WARNING" in line]
    assert not warnings, "\n".join(warnings)
    assert "build succeeded" in log


@pytest.mark.book
def test_build_leaves_the_user_build_untouched(built_book, user_build_before):
    """Les tests construisent ailleurs (dossier temporaire) : _build/ du dépôt est intact."""
    assert not built_book.is_relative_to(REPO_ROOT / "_build")
    assert tree_state(REPO_ROOT / "_build") == user_build_before


@pytest.mark.book
def test_every_toc_page_exists(built_book):
    for docname in _toc_files():
        assert (built_book / f"{docname}.html").is_file(), docname


@pytest.mark.book
def test_no_cell_output_is_an_error(built_book):
    for page in built_book.rglob("*.html"):
        html = page.read_text(errors="replace")
        for marker in ('class="output stderr', 'class="output traceback', 'class="output error',
                       "Traceback (most recent call last)"):
            assert marker not in html, f"{page.name} : sortie d'erreur « {marker} »"


# Sorties visibles des cellules de code : texte imprimé (print) et valeur de la dernière expression.
_CELL_OUTPUT = re.compile(r'<div class="output (?:stream|text_plain)\b[^"]*"[^>]*>(.*?)</pre>', re.S)
# Nombres à l'anglaise : 0.95, -3.25 ; écriture e (1e-06, 3.1127e-04, 1e+00) ; flottants de numpy
# « 0. » devant « , » ou « ] ». Pas : 2.0.0 (version), a.png, x1.5, 10.1115/… (chemin), 1:30.
_ENGLISH_NUMBER = re.compile(
    r"(?<![\w.,/:\u2212-])[-\u2212]?\d+\.\d+(?![\w/]|\.\d)"
    r"|(?<![\w.])\d+(?:\.\d+)?e[-+]?\d+(?!\w)"
    r"|(?<![\w.,/:\u2212-])[-\u2212]?\d+\.(?= *[,\]])"
)


def english_numbers_in_outputs(html: str) -> list[str]:
    """Les nombres écrits à l'anglaise dans les sorties visibles des cellules de code d'une page HTML
    (chacun avec un peu de contexte) ; le code des cellules, la prose et les figures ne sont pas lus."""
    found = []
    for block in _CELL_OUTPUT.findall(html):
        text = htmllib.unescape(re.sub(r"<[^>]+>", "", block))
        for m in _ENGLISH_NUMBER.finditer(text):
            found.append(" ".join(text[max(0, m.start() - 25):m.end() + 10].split()))
    return found


def test_output_check_flags_english_numbers_in_outputs_only():
    """Sur des pages écrites ici : les sorties à l'anglaise sont signalées, les sorties en français,
    le code des cellules, les versions et les noms de fichiers ne le sont pas."""
    def output(kind: str, text: str) -> str:
        return (f'<div class="cell_output docutils container"><div class="output {kind} highlight-myst-ansi '
                f'notranslate"><div class="highlight"><pre><span></span>{text}</pre></div></div></div>')

    code = '<div class="cell_input docutils container"><pre>x = 0.5 ; eps = 1e-6 ; print(x)</pre></div>'
    good = (code + output("stream", "A =\n [[0,95  0,03]\n [0,02  0,96]]\nP∞ = 3,1127 × 10⁻⁴ V²")
            + output("text_plain", "écart : 1,0 × 10⁻¹⁷ ; filterpy 2.0.0, figure a.png, x1.5, 10:30")
            + "<p>Prose : 0.5 (vérifiée ailleurs)</p>")
    assert english_numbers_in_outputs(good) == []
    bad = (code + output("stream", "A =\n [[0.95 0.03]\n [0.02 0.96]]\n|1 − KC| = 0.60")
           + output("stream", "P = &nbsp;&nbsp;1e+00 V² ; écart 1.0408340855860843e-17 ; P∞ = 3.1127e-04 V²")
           + output("text_plain", "(2, array([0.       , 0.2970297, 0.2970297]), array([-3.]))"))
    found = english_numbers_in_outputs(bad)
    assert len(found) == 5 + 3 + 4, found
    assert any("0.60" in f for f in found) and any("1e+00" in f for f in found)


@pytest.mark.book
def test_cell_outputs_write_french_numbers(built_book):
    """Ce que les cellules impriment est écrit à la française (kc.numbers.format_number,
    kc.numbers.format_array) : aucun « 0.95 », « 1e-06 » ni tableau numpy brut."""
    problems = []
    for page in sorted((built_book / "book").glob("*.html")):
        found = english_numbers_in_outputs(page.read_text())
        if found:
            problems.append(f"{page.name} : {len(found)} nombre(s) à l'anglaise dans la sortie des cellules, "
                            f"par exemple {found[:3]} (écrire avec kc.numbers.format_number ou format_array)")
    assert not problems, "\n".join(problems)


@pytest.mark.book
@pytest.mark.parametrize("chapter", ALL_CHAPTERS)
def test_chapter_pages_show_math_figures_and_glued_numbers(built_book, chapter):
    html = (built_book / "book" / f"{chapter}.html").read_text()
    text = (BOOK / f"{chapter}.md").read_text()
    assert 'class="math' in html
    n_draws = len(re.findall(r"kc\.figures\.draw\(", "\n".join(_code_cells(text))))
    images = re.findall(r'<img [^>]*?alt="[^"]*" src="(\.\./_images/[0-9a-f]+\.png)"', html)
    assert len(images) >= n_draws
    for src in images:
        assert (built_book / "book" / src).resolve().is_file()
    n_glue = len(re.findall(r"\{glue:text\}", text))
    assert html.count('class="pasted-text"') >= n_glue  # chaque nombre cité vient d'une cellule
    assert "???" not in re.sub(r"<[^>]+>", "", html)
    assert html.count('class="solution dropdown') >= 1


@pytest.mark.book
def test_mermaid_diagrams_are_build_time_svg(built_book):
    html = (built_book / "book" / "predicteur-correcteur.html").read_text()
    svgs = re.findall(r'<object data="(\.\./_images/mermaid-[0-9a-f]+\.svg)" type="image/svg\+xml"[^>]*>', html)
    assert len(svgs) == 3
    texts = [(built_book / "book" / s).resolve().read_text() for s in svgs]
    assert any("Kₙ₊₁" in t for t in texts)  # la boucle, indices lisibles
    assert any("K → C⁻¹" in t for t in texts)  # schéma du gain corrigé (erratum 001-4)
    assert not any("K → I" in t for t in texts)
    assert "mermaid.esm" not in html and "cdn.jsdelivr" not in html  # pas de JavaScript mermaid distant


@pytest.mark.book
def test_references_page_has_the_thirty_lecture_references(built_book):
    html = (built_book / "book" / "references.html").read_text()
    for needle in ("10.1115/1.3662552", "10.1109/78.978374", "10.1109/MSP.2012.2203621",
                   "kalman_intro.pdf", "poly_Kalman_Herscovici.pdf", "gilleschardon.fr/fc/kalman/kalman.pdf",
                   "Kalman-and-Bayesian-Filters-in-Python", "wiki.ros.org/robot_localization",
                   "cup_book_online_20131111.pdf", "978-0262018029", "978-0471708582"):
        assert needle in html, needle
    bib = (BOOK / "references.bib").read_text()
    entries = re.split(r"(?m)^@", bib)[1:]
    lecture = [e for e in entries if re.search(r"keywords\s*=\s*\{cours-", e)]
    assert len(lecture) == 30
    assert html.count('role="doc-biblioentry"') >= 30
    page_text = " ".join(htmllib.unescape(re.sub(r"<[^>]+>", " ", html)).split()).lower()
    for entry in lecture:
        title = re.search(r"\btitle\s*=\s*\{(.*)\},?\n", entry).group(1)
        clean = title.replace("{", "").replace("}", "").replace("\\_", "_")
        start = " ".join(clean.split()[:3]).lower()
        assert start in page_text, start
    # les chapitres citent la page des références
    intro = (built_book / "book" / "intro.html").read_text()
    assert "references.html#" in intro


# --------------------------------------------------------------------------- annexe des errata


def _errata_labels() -> set[str]:
    return set(re.findall(r"^\((errata-[\w-]+)\)=$", (BOOK / "errata.md").read_text(), re.M))


def test_errata_appendix_names_existing_tests():
    text = (BOOK / "errata.md").read_text()
    cited = set(re.findall(r"`(test_\w+)`", text))
    defined = set()
    for path in (ROOT / "tests").glob("test_*.py"):
        defined |= set(re.findall(r"^def (test_\w+)\(", path.read_text(), re.M))
    assert cited, "l'annexe ne cite aucun test"
    assert not cited - defined, f"tests cités mais absents : {sorted(cited - defined)}"


def test_errata_appendix_has_the_corrections_the_chapters_did_not_cover():
    labels = _errata_labels()
    for number in ("000-1", "000-3", "000-11", "002-1", "002-2", "002-6", "004-5", "004-6"):
        assert f"errata-{number}" in labels, number
    # et toutes les corrections des notes de l'EKF itéré sur SE(3), celles que le chapitre fait sans encadré comprises
    for number in range(1, 15):
        assert f"errata-004-{number}" in labels, f"004-{number}"
    # chaque entrée : écrit, correct, pourquoi, vérifié par
    entries = re.split(r"^\(errata-[\w-]+\)=$", (BOOK / "errata.md").read_text(), flags=re.M)[1:]
    assert len(entries) == len(labels)
    for entry in entries:
        for field in ("Écrit\n:", "Correct\n:", "Pourquoi\n:", "Vérifié par\n:"):
            assert field in entry, entry[:80]


#: Longueur maximale d'une note d'erratum, une fois les rôles remplacés par leur texte (une ligne ou deux).
ERRATUM_NOTE_MAX = 200


def erratum_note_problems(text: str, labels: set[str]) -> list[str]:
    """Ce qui ne va pas dans les corrections du support d'une page MyST : une correction est une note de bas
    de page d'une ligne, « [^id]: Erratum {ref}`001-7 <errata-001-7>` : … », appelée dans le texte et qui
    renvoie à des entrées existantes de l'annexe ; aucun encadré « Erratum » ne coupe le texte."""
    problems = []
    if re.search(r"^:{3,}\{admonition\} Errat", text, re.M):
        problems.append("encadré « Erratum » dans le texte (une note de bas de page d'une ligne suffit)")
    for fid, note, after in re.findall(r"^\[\^([\w-]+)\]: (Errat(?:um|a)\b.*)\n(.*)", text + "\n", re.M):
        links = re.findall(r"\{ref\}`[^`<]+<(errata-[\w-]+)>`", note)
        if not links:
            problems.append(f"note {fid} sans lien vers l'annexe")
        if set(links) - labels:
            problems.append(f"note {fid} : entrée(s) inconnue(s) {sorted(set(links) - labels)}")
        if after.strip():
            problems.append(f"note {fid} sur plusieurs lignes")
        plain = re.sub(r"\{ref\}`([^`<]*?) ?<[^>]*>`", r"\1", note)
        plain = re.sub(r"\{(?:glue:text|eq)\}`[^`]*`", "0,000", plain)
        if len(plain) > ERRATUM_NOTE_MAX:
            problems.append(f"note {fid} trop longue ({len(plain)} caractères)")
        if text.count(f"[^{fid}]") < 2:
            problems.append(f"note {fid} jamais appelée dans le texte")
    # une correction hors note (un renvoi « Détails : » à l'annexe, reste d'un ancien encadré)
    if re.search(r"^Détails : \{ref\}`errata", text, re.M):
        problems.append("renvoi « Détails : » à l'annexe hors d'une note")
    return problems


def test_erratum_note_check_flags_boxes_long_notes_and_dead_links():
    labels = {"errata-001-7", "errata-001-8"}
    good = ("La recette, étape 3.[^e1]\n\n[^e1]: Erratum {ref}`001-7 <errata-001-7>` : le support écrit "
            "$\\Psi$ au lieu de $\\Phi$.\n\nSuite du texte.\n")
    assert erratum_note_problems(good, labels) == []
    box = ":::{admonition} Erratum 001-7\n:class: warning\nLong encadré.\nDétails : {ref}`errata-001-7`.\n:::\n"
    assert len(erratum_note_problems(box, labels)) == 2
    unknown = good.replace("errata-001-7", "errata-009-1")
    assert "inconnue" in " ".join(erratum_note_problems(unknown, labels))
    no_link = good.replace("{ref}`001-7 <errata-001-7>`", "001-7")
    assert "sans lien" in " ".join(erratum_note_problems(no_link, labels))
    two_lines = good.replace("$\\Phi$.\n", "$\\Phi$,\ncomme l'explique l'annexe.\n")
    assert "plusieurs lignes" in " ".join(erratum_note_problems(two_lines, labels))
    long = good.replace("le support écrit", "le support écrit " + "vraiment " * 30)
    assert "trop longue" in " ".join(erratum_note_problems(long, labels))
    uncalled = good.replace("étape 3.[^e1]", "étape 3.")
    assert "jamais appelée" in " ".join(erratum_note_problems(uncalled, labels))


@pytest.mark.parametrize("chapter", ALL_CHAPTERS)
def test_errata_are_one_line_footnotes_that_link_to_the_appendix(chapter):
    text = (BOOK / f"{chapter}.md").read_text()
    problems = erratum_note_problems(text, _errata_labels())
    assert not problems, f"{chapter} : " + " ; ".join(problems)
    # aucun renvoi à des documents ou numéros de ligne que l'étudiant n'a pas
    prose = re.sub(r"```\{code-cell\}.*?```", "", text, flags=re.S)
    assert not re.search(r"\bl\.\s*\d|ALGORITHMS|\.txt\b", prose), chapter


# --------------------------------------------------------------------------- cellules et figures


def _cells_with_metadata(text: str) -> list[tuple[dict, str]]:
    """Les cellules de code : (métadonnées, source)."""
    cells = []
    for body in re.findall(r"```\{code-cell\}[^\n]*\n(.*?)```", text, flags=re.S):
        meta: dict = {}
        if body.startswith("---\n"):
            head, body = body[4:].split("\n---\n", 1)
            meta = yaml.safe_load(head) or {}
        else:
            options = re.match(r"((?::[\w-]+:.*\n)*)", body)[1]
            for key, value in re.findall(r"^:([\w-]+):\s*(.*)$", options, re.M):
                meta[key] = yaml.safe_load(value)
            body = body[len(options):]
        cells.append((meta, body))
    return cells


@pytest.mark.parametrize("chapter", ALL_CHAPTERS)
def test_every_figure_has_a_caption_a_name_and_an_alt_text(chapter):
    for meta, body in _cells_with_metadata((BOOK / f"{chapter}.md").read_text()):
        drawn = re.findall(r'kc\.figures\.draw\("([^"]+)"[,)]', body)
        if not drawn:
            continue
        figure = meta.get("mystnb", {}).get("figure", {})
        alt = meta.get("mystnb", {}).get("image", {}).get("alt", "")
        assert len(figure.get("caption", "")) > 20, f"{chapter} : {drawn[0]} sans légende"
        assert figure.get("name") == f"fig-{drawn[0]}", f"{chapter} : {drawn[0]} sans nom de figure"
        assert len(alt) > 40, f"{chapter} : {drawn[0]} sans texte de remplacement"


@pytest.mark.parametrize("chapter", ALL_CHAPTERS)
def test_bookkeeping_cells_are_hidden(chapter):
    """Une cellule qui colle des nombres, ou qui ne fait qu'importer, est cachée aux étudiants."""
    for meta, body in _cells_with_metadata((BOOK / f"{chapter}.md").read_text()):
        tags = set(meta.get("tags", []))
        code = [line for line in body.splitlines() if line.strip() and not line.lstrip().startswith("#")]
        glues = re.search(r"\bglue(_number)?\(", body)
        imports_only = code and all(re.match(r"(import|from)\s", line) for line in code)
        if glues or imports_only:
            assert tags & {"remove-cell", "remove-input"}, f"{chapter} : cellule visible :\n{body[:200]}"


def test_errata_headings_have_no_math():
    """Un titre d'entrée sert de texte aux liens {ref} des chapitres, rendu sans MathJax : pas de $…$."""
    headings = re.findall(r"^### (.*)$", (BOOK / "errata.md").read_text(), re.M)
    assert headings and not [h for h in headings if "$" in h or "\\" in h]


# --------------------------------------------------------------------------- relecture (issue 36), pages construites


def _article_text(built_book: Path, page: str) -> str:
    """Le texte de l'article d'une page construite, formules écrites en TeX entre « $ »."""
    html = (built_book / "book" / f"{page}.html").read_text()
    body = html.split('<article class="bd-article"', 1)[-1].split("</article>", 1)[0]
    body = re.sub(r"<(script|style)\b.*?</\1>", "", body, flags=re.S)
    body = re.sub(r'<mjx-container[^>]*data-kc-tex="([^"]*)"[^>]*>.*?</mjx-container>',
                  lambda m: " $" + htmllib.unescape(m.group(1)) + "$ ", body, flags=re.S)
    return " ".join(htmllib.unescape(re.sub(r"<[^>]+>", " ", body)).split())


def _outputs(built_book: Path, page: str) -> str:
    html = (built_book / "book" / f"{page}.html").read_text()
    return "\n".join(htmllib.unescape(re.sub(r"<[^>]+>", "", b)) for b in _CELL_OUTPUT.findall(html))


@pytest.mark.book
def test_manoeuvring_targets_page_cites_the_centripetal_acceleration_and_a_cautious_imm(built_book):
    """« 0,12 rad/s, soit 2,4 m/s² » (le changement de cap en radians) : la page cite vω = 6 et 4 m/s² (les
    accélérations sont vérifiées sur la trajectoire simulée par tests/test_tracking_scenarios.py) ; l'IMM y
    est « prudent », jugé pas à pas, et non « cohérent » par sa moyenne sur le vol."""
    from kalman_course.scenarios import manoeuvre as man

    text = _article_text(built_book, "cibles-manoeuvrantes")
    assert "2,4 m/s²" not in text
    assert re.search(r"accélération centripète vaut alors \$v\\omega =\$ 6 m/s²", text)
    assert re.search(r"0,08 rad/s \( ?4 m/s²\)", text)
    assert "$\\alpha^{-20}$" not in text and "divisé par $\\alpha^{20}$" in text
    below, inside, above = man.manoeuvre_study().band_shares("IMM")
    share = re.search(r"est \*?\*?prudent\W+sa NEES moyenne est dans l’intervalle à (\d+) % des pas seulement, en "
                      r"dessous à (\d+) %", text.replace("**", ""))
    assert share and (int(share[1]), int(share[2])) == (round(100 * inside), round(100 * below)), share
    assert "seul l’IMM est à la fois précis partout et cohérent" not in text
    assert "NEES moyen " not in text  # la NEES, au féminin


@pytest.mark.book
def test_filter_choice_text_cites_the_table_numbers(built_book):
    """Le texte citait « 150 m » (deux chiffres) là où le tableau dit 145 : texte, tableau et lecture des
    curseurs écrivent les mêmes nombres (trois chiffres significatifs)."""
    text = _article_text(built_book, "quel-filtre")
    cited = re.search(r"l’EKF finit avec une REQM de ([\d ,]+) m et une NEES moyenne de ([\d  ,]+) au lieu", text)
    row = re.search(r"\bEKF ([\d ,]+) ([\d  ,]+) \d+ %", text)
    assert cited and row and cited.groups() == row.groups(), (cited and cited.groups(), row and row.groups())
    pf = re.search(r"filtre particulaire ([\d  ,]+) ∞", text)
    assert pf and f"échoue ( {pf[1]} m)" in text


@pytest.mark.book
def test_gate_exercise_prints_plain_probabilities_and_french_plurals(built_book):
    """« p = 0,90000 » et « 1 rejetées » : l'exercice des fenêtres écrit « p = 0,9 » et accorde le pluriel."""
    out = _outputs(built_book, "capteurs-temps-irregulier")
    assert "p = 0,9 : 240 positions rejetées" in out
    assert "0,90000" not in out and "1 rejetées" not in out and "1 position rejetée" in out
    text = _article_text(built_book, "capteurs-temps-irregulier")
    assert "perdue puis retrouvée" not in text and "perdue pour de bon" in text
    assert "si chaque NIS était indépendant" not in text


@pytest.mark.book
def test_outputs_have_no_space_inside_parentheses(built_book):
    """« (exact : 0,800 ) » : aucune sortie de cellule n'a d'espace juste après « ( » ou avant « ) »."""
    problems = []
    for page in sorted((built_book / "book").glob("*.html")):
        for m in re.finditer(r"\( \S|\S \)", _outputs(built_book, page.stem)):
            problems.append(f"{page.name} : « {m.group(0)} »")
    assert not problems, problems[:10]


@pytest.mark.book
def test_slider_fallback_paragraph_has_french_spacing(built_book):
    """Le paragraphe de repli des figures à curseurs (HTML brut, hors de la passe de typographie) a son espace
    insécable avant « : » sur toutes les pages."""
    pages = 0
    for page in sorted((built_book / "book").glob("*.html")):
        for missing in re.findall(r'<p class="kc-bokeh-missing">(.*?)</p>', page.read_text(), re.S):
            pages += 1
            assert "précalculés\u00a0: elle" in missing and " :" not in missing, (page.name, missing[:80])
    assert pages >= 20


@pytest.mark.book
def test_parallel_page_proves_associativity_and_names_dynamax_correctly(built_book):
    """La démonstration de l'associativité est repliée (« Démonstration ») et cite la vérification par
    quadrature ; dynamax : une fonction à part, le ticket 423 corrigé par la demande de fusion 455."""
    html = (built_book / "book" / "filtrage-parallele.html").read_text()
    proof = re.search(r'<div class="([^"]*\bproof\b[^"]*)"[^>]*>\s*<p class="admonition-title">Démonstration</p>'
                      r'(.*?)</div>', html, re.S)
    assert proof and "dropdown" in proof.group(1).split()
    assert "Fubini" in proof.group(2) and "Tonelli" in proof.group(2)
    text = _article_text(built_book, "filtrage-parallele")
    assert "parallel_lgssm_filter" in text and "ticket n° 423" in text and "455" in text
    assert "filtre par défaut" not in text and "question n° 423" not in text
    spread = re.search(r"le rapport des deux varie de ([^ ]+ × 10⁻[⁰¹²³⁴⁵⁶⁷⁸⁹]+|0) en relatif", text)
    assert spread, "vérification par quadrature non citée"
