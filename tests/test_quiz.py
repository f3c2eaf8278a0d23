"""La directive ``quiz`` (kalman_course.sphinx.quiz) : HTML corrigé dans la page, LaTeX avec les
réponses en fin de chapitre, erreurs de rédaction qui arrêtent la construction. Un petit projet Sphinx
(MyST) est construit dans un dossier temporaire ; le livre lui-même est vérifié par tests/test_browser.py."""

from __future__ import annotations

import io
import re
from pathlib import Path

import pytest
from sphinx.cmd.build import build_main

from kalman_course.sphinx.quiz import QUIZ_MARKER

CONF = """
extensions = ["myst_parser", "kalman_course.sphinx.quiz"]
myst_enable_extensions = ["colon_fence", "dollarmath"]
language = "fr"
root_doc = "index"
"""

GOOD = """# Chapitre

Du texte.

## Quiz

::::{quiz}
:::{question}
:answer: 2
:name: gain-r
Quand la variance de mesure $R$ diminue, le gain $K$…

- diminue ;
- augmente ;
- ne change pas.

Le gain croît quand $R$ décroît.
:::
:::{question}
:answer: 3
Deuxième question ?

- un
- deux
- trois
- $K = P^-/(P^- + R)$
:::
::::

## À retenir

Fin.
"""

PLAIN = "# Sans quiz\n\nRien à vérifier ici.\n"


def _project(tmp_path: Path, index: str, extra: dict[str, str] | None = None) -> Path:
    src = tmp_path / "src"
    src.mkdir()
    (src / "conf.py").write_text(CONF)
    (src / "index.md").write_text(index)
    for name, text in (extra or {}).items():
        (src / name).write_text(text)
    return src


def _build(src: Path, builder: str) -> tuple[int, Path, str]:
    out = src.parent / f"_build_{builder}"
    warnings = io.StringIO()
    import contextlib

    with contextlib.redirect_stderr(warnings):
        code = build_main(["-b", builder, "-q", "-W", "-E", str(src), str(out)])
    return code, out, warnings.getvalue()


def test_html_quiz_has_radios_answers_and_one_script(tmp_path):
    toc = "\n```{toctree}\n:hidden:\nplain\n```\n"
    src = _project(tmp_path, GOOD + toc, {"plain.md": PLAIN})
    code, out, log = _build(src, "html")
    assert code == 0, log
    html = (out / "index.html").read_text()
    assert html.count(f'class="{QUIZ_MARKER}"') == 1
    questions = re.findall(r'<fieldset class="kc-quiz-question" id="([^"]+)" data-answer="(\d)"', html)
    assert questions == [("kc-quiz-index-1", "2"), ("kc-quiz-index-2", "3")]
    assert 'data-name="gain-r"' in html
    # trois puis quatre boutons radio, groupés par question, valeurs 1…n
    for qid, n in (("kc-quiz-index-1", 3), ("kc-quiz-index-2", 4)):
        values = re.findall(rf'<input type="radio" name="{qid}" value="(\d)" aria-label="Réponse ([a-z]) : [^"]+">',
                            html)
        assert values == [(str(k), "abcd"[k - 1]) for k in range(1, n + 1)]
    # une réponse faite d'une formule a un nom accessible lisible (pas de TeX brut)
    assert 'aria-label="Réponse d : K = P⁻/(P⁻ + R)"' in html
    assert html.count("Vérifier</button>") == 2
    # l'explication existe pour la première question seulement (la seconde n'en a pas)
    assert html.count('class="kc-quiz-explanation" hidden') == 1
    assert "Le gain croît quand" in html
    # le script de correction, une fois, en ligne (aucune requête), seulement sur la page qui en a besoin
    assert html.count("window.kcQuizReady = true") == 1
    assert "window.kcQuizReady" not in (out / "plain.html").read_text()


def test_latex_lists_questions_and_gathers_answers_at_the_end(tmp_path):
    src = _project(tmp_path, GOOD)
    code, out, log = _build(src, "latex")
    assert code == 0, log
    tex = next(out.glob("*.tex")).read_text()
    assert "Réponses du quiz" in tex
    body, answers = tex.split("Réponses du quiz", 1)
    # questions et réponses proposées dans le corps, sans la bonne réponse marquée
    assert "Deuxième question" in body and "ne change pas" in body
    assert "Le gain croît quand" not in body
    # à la fin : chaque bonne réponse, sa lettre, puis l'explication
    assert re.search(r"Question 1\s*:\s*\(b\)\s*}\s*augmente", answers)
    assert re.search(r"Question 2\s*:\s*\(c\)\s*}\s*trois", answers)
    assert "Le gain croît quand" in answers
    # la section des réponses vient après « À retenir » : à la fin du chapitre
    assert tex.index("retenir") < tex.index("Réponses du quiz")


@pytest.mark.parametrize(
    "question, message",
    [
        ("Énoncé.\n\n- a\n- b\n", "answer"),  # pas de :answer:
        (":answer: 3\nÉnoncé.\n\n- a\n- b\n", "au moins"),  # bonne réponse hors de la liste
        (":answer: 1\nÉnoncé sans liste.\n", "liste à puces"),
        (":answer: 1\nÉnoncé.\n\n- une seule\n", "au moins"),
    ],
)
def test_badly_written_questions_stop_the_build(tmp_path, question, message):
    src = _project(tmp_path, f"# T\n\n::::{{quiz}}\n:::{{question}}\n{question}:::\n::::\n")
    code, _, log = _build(src, "html")
    assert code != 0
    assert message in log


def test_a_quiz_holds_only_questions(tmp_path):
    src = _project(tmp_path, "# T\n\n::::{quiz}\nUn paragraphe perdu.\n::::\n")
    code, _, log = _build(src, "html")
    assert code != 0 and "ne contient que des questions" in log
