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

  Le message de la réponse a.
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


# --------------------------------------------------------------------------- messages des réponses (issue 36)


def test_a_chosen_answer_shows_its_own_message(tmp_path):
    """Une réponse proposée suivie (ligne vide, retrait) d'un message : le message est dans la page, caché,
    rattaché à sa réponse (``data-choice``), hors de l'explication dépliable ; le script ne montre que celui de
    la réponse choisie. Dans le PDF, il suit l'explication, dans le corrigé."""
    src = _project(tmp_path, GOOD)
    code, out, log = _build(src, "html")
    assert code == 0, log
    html = (out / "index.html").read_text()
    assert re.search(r'<div class="kc-quiz-why" data-choice="1" hidden>\s*<p>Le message de la réponse a\.</p>', html)
    assert html.count('class="kc-quiz-why"') == 1
    # la réponse elle-même reste « un » (le message n'entre pas dans son nom accessible)
    assert 'aria-label="Réponse a : un"' in html
    assert 'w.getAttribute("data-choice") !== chosen.value' in html
    (tmp_path / "latex").mkdir()
    code, out, log = _build(_project(tmp_path / "latex", GOOD), "latex")
    assert code == 0, log
    tex = next(out.glob("*.tex")).read_text()
    body, answers = tex.split("Réponses du quiz", 1)
    assert "Le message de la réponse a" not in body and "Le message de la réponse a" in answers


# --------------------------------------------------------------------------- rédaction des quiz du livre

BOOK = Path(__file__).resolve().parent.parent / "book"
#: Part maximale des questions d'une page dont la bonne réponse est la plus longue.
LONGEST_SHARE = 0.4


def quiz_problems(text: str) -> list[str]:
    """Les fautes de rédaction des quiz d'une page : la bonne réponse est la plus longue (à égalité comprise)
    dans plus de 40 % des questions — un élève qui choisit la plus longue gagnerait — ; une mauvaise réponse
    sans message qui explique son erreur."""
    from kalman_course.sphinx.quiz import quiz_questions

    questions = quiz_questions(text)
    problems = []
    longest = [q for q in questions if q.right_is_longest()]
    if questions and len(longest) > LONGEST_SHARE * len(questions):
        problems.append(f"bonne réponse la plus longue dans {len(longest)} question(s) sur {len(questions)} "
                        f"(lignes {', '.join(str(q.line) for q in longest)})")
    for q in questions:
        for k, (choice, message) in enumerate(zip(q.choices, q.messages), start=1):
            if k != q.answer and not message:
                problems.append(f"ligne {q.line} : la réponse « {choice[:40]} » n'a pas de message")
    return problems


def test_quiz_rules_can_fail():
    from kalman_course.sphinx.quiz import quiz_questions

    longest = (":::{question}\n:answer: 1\nQ ?\n\n- la bonne, longue réponse $x_k$\n\n  Message.\n- b\n\n"
               "  Faux : b.\n- c\n\n  Faux : c.\n\nExplication.\n:::\n")
    q = quiz_questions(longest)[0]
    assert (q.answer, q.choices[0], q.messages, q.explanation) == (
        1, "la bonne, longue réponse $x_k$", ["Message.", "Faux : b.", "Faux : c."], "Explication.")
    assert q.right_is_longest() and q.lengths()[0] == len("la bonne, longue réponse xₖ")
    assert quiz_problems(longest * 3) == ["bonne réponse la plus longue dans 3 question(s) sur 3 (lignes 1, 17, 33)"]
    short = longest.replace(":answer: 1", ":answer: 2")
    assert quiz_problems(short * 2 + longest) == []  # 1 sur 3 : permis
    silent = short.replace("\n\n  Faux : c.", "")
    assert quiz_problems(silent) == ["ligne 1 : la réponse « c » n'a pas de message"]


@pytest.mark.parametrize("page", sorted(p.stem for p in BOOK.glob("*.md") if "{quiz}" in p.read_text()))
def test_quizzes_of_the_book_are_not_won_by_length_and_explain_each_mistake(page):
    """Sur chaque page (nouvelles pages comprises) : la bonne réponse n'est la plus longue que dans 40 % des
    questions au plus, et chaque mauvaise réponse a son message."""
    problems = quiz_problems((BOOK / f"{page}.md").read_text())
    assert not problems, f"{page} : " + " ; ".join(problems)


def test_the_introduction_quiz_asks_about_the_filter_not_the_book():
    """Le quiz de l'introduction porte sur le filtrage de Kalman (prédiction, correction, gain), pas sur la
    fabrication du livre."""
    from kalman_course.sphinx.quiz import quiz_questions

    questions = quiz_questions((BOOK / "intro.md").read_text())
    assert len(questions) >= 3
    for q in questions:
        text = (q.statement + " " + " ".join(q.choices)).lower()
        assert not re.search(r"paquet|construction|jupyter|curseur|livre|python|page", text), q.statement
    words = " ".join(q.statement + " " + q.explanation for q in questions).lower()
    for notion in ("gain", "prédiction", "mesure"):
        assert notion in words, notion


def test_choices_of_equal_length_give_nothing_away():
    from kalman_course.sphinx.quiz import QuizQuestion

    assert not QuizQuestion(3, "Q ?", ["$A$", "$B$", "$C$"]).right_is_longest()
    assert QuizQuestion(2, "Q ?", ["ab", "abc", "abc"]).right_is_longest()  # à égalité avec une autre : 1 chance sur 2
    assert not QuizQuestion(1, "Q ?", ["ab", "abc", "abc"]).right_is_longest()


def test_latex_gathers_the_answers_at_the_end_of_each_chapter(tmp_path):
    """Le LaTeX d'un livre est un seul arbre (un ``start_of_file`` par chapitre) : les réponses restaient
    toutes à la fin du premier chapitre, numérotées de 1 à 105. Chaque chapitre a les siennes, numérotées à
    partir de 1, après son propre texte."""
    def chapter(n):
        return GOOD.replace("# Chapitre", f"# Chapitre {n}").replace("Deuxième question", f"Deuxième question du {n}")

    index = "# Livre\n\n```{toctree}\nun\ndeux\n```\n"
    src = _project(tmp_path, index, {"un.md": chapter("un"), "deux.md": chapter("deux")})
    code, out, log = _build(src, "latex")
    assert code == 0, log
    tex = next(out.glob("*.tex")).read_text()
    assert tex.count("Réponses du quiz") == 2
    first, second = tex.split("Réponses du quiz")[1:]
    assert "Chapitre deux" in first and "Chapitre deux" not in second  # les réponses de un, avant deux
    for part in (first, second):
        assert re.search(r"Question 1\s*:", part) and re.search(r"Question 2\s*:", part)
        assert not re.search(r"Question 3\s*:", part)
