"""Le cours en un seul PDF (constructeur LaTeX de Jupyter Book, XeLaTeX, césure française).

Construit le PDF dans le dossier de construction des tests (temporaire, même cache d'exécution que la
construction du site : aucun carnet relancé), puis le lit avec pdftotext, pdfinfo et pdfimages
(poppler-utils) : nombre de pages, titre de chaque chapitre, aucune référence « ?? », aucune trace
d'erreur Python, formules composées, figures (dont celles à curseurs, avec leur légende) non vides,
diagrammes Mermaid en images, exercices avec leurs solutions, bibliographie.

TeX Live n'est installé que sur demande (``bash scripts/setup.sh --pdf``, ``bash scripts/build.sh
--pdf``) : sans lui ces tests sont sautés, sauf en CI (``CI=true``), où ``scripts/test.sh`` l'installe
et où son absence est une erreur.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest
import yaml
from PIL import Image

from conftest import ROOT, latex_pdf, tex_missing, tree_state
from kalman_course.numbers import format_spec

sys.path.insert(0, str(ROOT / "scripts"))
from pdf import TARGET  # noqa: E402

pytestmark = pytest.mark.pdf

BOOK = ROOT / "book"


def _toc_docs() -> list[str]:
    toc = yaml.safe_load((ROOT / "_toc.yml").read_text())
    return [toc["root"]] + [c["file"] for part in toc["parts"] for c in part["chapters"]]


#: Appel d'une figure à curseurs dans un chapitre : ``kc.interactive.sliders("nom")`` ou ``…_sliders()``.
_SLIDERS = re.compile(r'kc\.interactive\.(?:sliders\("[^"]+"\)|\w+_sliders\(\))')


def _slider_figures() -> int:
    """Nombre de figures à curseurs appelées par les chapitres du sommaire."""
    return sum(len(_SLIDERS.findall((ROOT / f"{d}.md").read_text())) for d in _toc_docs())


def _title(doc: str) -> str:
    """Le titre du chapitre tel qu'imprimé (sans le balisage d'italique : « *unscented* » → « unscented »)."""
    return re.sub(r"\*([^*]+)\*", r"\1", re.search(r"(?m)^# (.+)$", (ROOT / f"{doc}.md").read_text()).group(1).strip())


def _flat(text: str) -> str:
    """Texte sur une ligne : espaces normalisés (dont les espaces fines de babel-french), apostrophes
    typographiques ramenées à « ' » (celles des sources), coupures de fin de ligne recollées."""
    text = text.replace("\u00ad", "").replace("\u2019", "'")
    text = re.sub(r"(\w)-\n(\w)", r"\1\2", text)
    return " ".join(text.replace("\u202f", " ").replace("\u00a0", " ").split())


@pytest.fixture(scope="module")
def pdf_build(book_build_dir):
    """Le PDF construit en arrière-plan dès la fin de la construction du site (tests/conftest.py :
    construction LaTeX sur le même environnement Sphinx et le même cache d'exécution, puis XeLaTeX)."""
    missing = tex_missing()
    if missing:
        message = (f"TeX Live ou poppler-utils absent ({', '.join(missing)}) : "
                   "« bash scripts/setup.sh --pdf » les installe.")
        if os.environ.get("CI"):
            pytest.fail(message)
        pytest.skip(message)
    log, pdf, compile_s = latex_pdf(book_build_dir)
    latex_dir = book_build_dir / "_build" / "latex"
    print(f"\nPDF construit (XeLaTeX : {format_spec(compile_s, '.0f')} s) : {pdf}")
    text = subprocess.run(["pdftotext", "-enc", "UTF-8", str(pdf), "-"], check=True, capture_output=True,
                          text=True).stdout
    info = subprocess.run(["pdfinfo", str(pdf)], check=True, capture_output=True, text=True).stdout
    return {"pdf": pdf, "log": log, "text": text, "flat": _flat(text), "info": info,
            "tex": (latex_dir / f"{TARGET}.tex").read_text(), "dir": latex_dir}


def test_page_count(pdf_build):
    pages = int(re.search(r"^Pages:\s+(\d+)", pdf_build["info"], re.M).group(1))
    n_chapters = len(_toc_docs())
    # chaque chapitre tient sur plusieurs pages (texte, formules, figures, exercices) ; borne haute :
    # un PDF démesuré trahirait une figure ou une sortie démesurée
    assert 3 * n_chapters <= pages <= 40 * n_chapters, f"{pages} pages pour {n_chapters} chapitres"


def test_every_chapter_title_is_in_the_text_and_in_the_contents(pdf_build):
    flat = pdf_build["flat"]
    root, *chapters = _toc_docs()
    # la page d'accueil devient l'avant-propos : titre du livre (_config.yml) et ses sections
    assert _flat(yaml.safe_load((ROOT / "_config.yml").read_text())["title"]) in flat
    for heading in re.findall(r"(?m)^## (.+)$", (ROOT / f"{root}.md").read_text()):
        assert _flat(heading) in flat, heading
    for doc in chapters:
        title = _flat(_title(doc))
        # une fois dans la table des matières, une fois en tête du chapitre
        assert flat.count(title) >= 2, f"« {title} » ({doc}) : {flat.count(title)} occurrence(s)"


def test_no_unresolved_reference_no_traceback_no_raw_math(pdf_build):
    text = pdf_build["text"]
    assert "??" not in text
    # aucune sortie d'erreur de cellule (le code source cité peut, lui, nommer KalmanInputError)
    for marker in ("Traceback", "most recent call last", "RuntimeWarning:", "UserWarning:", "DeprecationWarning:"):
        assert marker not in text, marker
    # les formules sont composées (unicode-math) : lettres mathématiques italiques (U+1D434…U+1D467)
    # en nombre, aucun délimiteur TeX resté tel quel
    assert len(re.findall("[\U0001D434-\U0001D467]", text)) > 1000
    assert "$$" not in text and "\\(" not in text


def test_math_of_every_chapter_is_typeset(pdf_build):
    tex = pdf_build["tex"]
    for doc in _toc_docs():
        source = (ROOT / f"{doc}.md").read_text()
        if "$" not in source:
            continue
        name = Path(doc).name
        start = tex.find(f"\\label{{\\detokenize{{{doc}::doc}}}}")
        assert start >= 0, f"{name} absent du LaTeX"
        nxt = tex.find("::doc}}}", start + 10)
        chunk = tex[start: nxt if nxt > 0 else len(tex)]
        assert re.search(r"\\\(|\\begin\{(equation|align|split)", chunk), f"{name} : aucune formule"


def test_every_figure_is_an_image_that_is_not_empty(pdf_build):
    draws = sum(len(re.findall(r"kc\.figures\.draw\(", (ROOT / f"{d}.md").read_text())) for d in _toc_docs())
    sliders = _slider_figures()
    listing = subprocess.run(["pdfimages", "-list", str(pdf_build["pdf"])], check=True, capture_output=True,
                             text=True).stdout.splitlines()[2:]
    numbers = [int(line.split()[1]) for line in listing if line.split()[2] == "image"]  # pas les masques
    assert len(numbers) >= draws + sliders, f"{len(numbers)} images pour {draws} figures et {sliders} à curseurs"
    # images brutes (PPM, sans compression : trois fois moins de calcul que -png), effacées aussitôt lues
    with tempfile.TemporaryDirectory() as folder:
        subprocess.run(["pdfimages", str(pdf_build["pdf"]), f"{folder}/img"], check=True)
        for number in numbers:
            (path,) = Path(folder).glob(f"img-{number:03d}.p[bgp]m")
            pixels = np.asarray(Image.open(path).convert("L"), dtype=float)
            assert min(pixels.shape) >= 100, f"{path.name} : image minuscule {pixels.shape}"
            assert pixels.std() > 5.0, f"{path.name} : image uniforme (figure vide)"


def test_static_slider_figures_are_printed_with_their_caption(pdf_build):
    flat = pdf_build["flat"]
    sliders = _slider_figures()
    assert sliders >= 1
    # « Curseurs à leur position par défaut » ; « Curseur à sa position… » quand la figure n'en a qu'un
    caption = r"Curseurs? à (?:leur|sa) position par défaut"
    assert len(re.findall(caption, flat)) == sliders
    assert len(re.findall(caption, pdf_build["tex"])) == sliders
    assert "Φ = 1 × 10⁻⁵ V², Ψ = 0,01 V²" in flat  # valeurs par défaut du chapitre « tension constante »


def test_mermaid_diagrams_are_images(pdf_build):
    n_diagrams = sum((ROOT / f"{d}.md").read_text().count("```{mermaid}") for d in _toc_docs())
    included = re.findall(r"\\sphinxincludegraphics(?:\[[^\]]*\])?\{(mermaid-[0-9a-f]+)\.pdf\}", pdf_build["tex"])
    assert len(included) == n_diagrams
    for name in included:
        assert (pdf_build["dir"] / f"{name}.pdf").stat().st_size > 1000
    assert "Kₙ₊₁" in pdf_build["text"]  # texte du diagramme de la boucle (predicteur-correcteur)


def test_exercises_come_with_their_solutions(pdf_build):
    n_exercises = sum((ROOT / f"{d}.md").read_text().count("```{exercise}") for d in _toc_docs())
    n_solutions = sum((ROOT / f"{d}.md").read_text().count("```{solution-start}") for d in _toc_docs())
    flat = pdf_build["flat"]
    assert n_solutions == n_exercises
    assert len(re.findall(r"Exercice \d+", flat)) >= n_exercises
    # sphinx-exercise (exercise_style: solution_follow_exercise) : la solution suit son exercice, titrée
    # « Solution » ; jamais « Solution de Exercice 3 »
    assert "Solution de Exercice" not in flat
    assert len(re.findall(r"\\begin\{sphinxadmonition\}\{note\}\{Solution\}", pdf_build["tex"])) == n_solutions


def test_bibliography_is_printed(pdf_build):
    flat = pdf_build["flat"]
    for needle in ("10.1115/1.3662552", "10.1109/78.978374", "Welch"):
        assert needle in flat, needle


def test_pdf_build_leaves_the_user_build_untouched(pdf_build, user_build_before):
    assert tree_state(ROOT / "_build") == user_build_before


def test_contents_numbers_do_not_run_into_titles_and_parts_are_the_book_parts(pdf_build):
    """Table des matières : « 13.10 Quiz », jamais « 13.10Quiz » ; les seules parties (\\part) sont celles
    de _toc.yml (les réponses du quiz de l'introduction n'en deviennent pas une)."""
    text = pdf_build["text"]
    contents = text[: text.find(_title(_toc_docs()[1]), text.find(_title(_toc_docs()[1])) + 1)]
    assert not re.search(r"\b\d+\.\d+[A-Za-zÀ-ÿ]", contents), re.findall(r"\b\d+\.\d+[A-Za-zÀ-ÿ]\S*", contents)[:5]
    parts = re.findall(r"\\part\{([^}]*)\}", pdf_build["tex"])
    captions = [p["caption"] for p in yaml.safe_load((ROOT / "_toc.yml").read_text())["parts"]]
    assert len(parts) == len(captions), parts
    assert "Réponses du quiz" not in parts


# --------------------------------------------------------------------------- relecture (issue 36)


def test_algorithm_boxes_proofs_and_quiz_answers_are_in_french(pdf_build):
    """Les encadrés d'algorithme sont titrés « Algorithme » (le site dit « Algorithme 7 » ; le LaTeX de
    sphinx-proof disait « Algorithm ») ; la démonstration du filtrage parallèle est titrée
    « Démonstration » ; le corrigé des quiz donne l'erreur de chaque mauvaise réponse."""
    flat = pdf_build["flat"]
    boxes = len(re.findall(r"```\{prf:algorithm\}", "".join((ROOT / f"{d}.md").read_text() for d in _toc_docs())))
    assert boxes >= 9
    assert flat.count("Algorithme") >= boxes
    assert not re.search(r"\bAlgorithm\b", flat)
    assert "Démonstration" in flat and "Proof." not in flat
    # un message de mauvaise réponse, dans le corrigé en fin de chapitre (quiz du filtre gaussien)
    answers = flat.split("Réponses du quiz")
    assert len(answers) > 20
    assert any("L'EKF n'a pas de points sigma, et le GHKF en a" in part for part in answers[1:])
