r"""Extension Sphinx du livre : la directive ``quiz``, questionnaires corrigés dans la page, hors ligne.

À déclarer dans ``_config.yml`` (``sphinx: extra_extensions: [kalman_course.sphinx.quiz]``). Dans un
chapitre (MyST) :

.. code-block:: markdown

    ::::{quiz}
    :::{question}
    :answer: 2
    Quand la variance de mesure $R$ diminue, le gain $K$…

    - diminue ;

      C'est l'effet d'une mesure **moins** précise : $R$ grandit, la mesure pèse moins.
    - augmente ;
    - ne change pas.

      Le gain dépend de $R$ : seule la prédiction ne le voit pas.

    $K = P^-/(P^- + R)$ croît quand $R$ décroît : la mesure, plus précise, pèse davantage.
    :::
    ::::

Dans une question, ce qui précède la **première liste à puces** est l'énoncé, les éléments de la liste
sont les réponses proposées (``:answer:`` : numéro de la bonne, à partir de 1), ce qui suit est
l'explication. Une réponse proposée peut porter, après une ligne vide et en retrait, son **message** :
pour une mauvaise réponse, l'erreur qu'elle trahit (affiché quand on la choisit). ``:name:`` donne un
identifiant stable à la question (pour les tests).

- **HTML** : chaque question est un groupe de boutons radio, un bouton « Vérifier » et une zone de
  réponse ; quelques lignes de JavaScript sans dépendance, ajoutées une fois aux seules pages qui ont
  un quiz, comparent le choix à la bonne réponse, l'annoncent (« Juste ! » ou « Pas tout à fait »),
  montrent le message de la réponse choisie et déplient l'explication. Aucun serveur, aucun noyau,
  aucune requête.
- **Autres sorties** (LaTeX/PDF, texte) : les questions deviennent une liste numérotée, les réponses
  proposées des sous-listes (a), (b), (c)… et les bonnes réponses, avec leur explication et le message de
  chaque mauvaise réponse, sont regroupées sous un intertitre « Réponses du quiz » à la fin du chapitre.

Les règles de rédaction (la bonne réponse n'est pas le plus souvent la plus longue, chaque mauvaise
réponse a son message) sont vérifiées sur tout le livre par ``tests/test_quiz.py`` (:func:`quiz_questions`
lit les questions d'une page MyST).
"""

from __future__ import annotations

import re

from docutils import nodes
from docutils.parsers.rst import directives
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective

from ..quizzes import QuizQuestion, plain_text, quiz_questions, tex_to_text  # noqa: F401 (lus par les tests)

__all__ = ["setup", "QUIZ_MARKER", "QUIZ_SCRIPT", "quiz", "quiz_question", "tex_to_text", "choice_text",
           "QuizQuestion", "quiz_questions", "plain_text"]

LOGGER = logging.getLogger(__name__)

#: Classe HTML d'un quiz (repérée par l'extension pour ajouter le script, et par les tests).
QUIZ_MARKER = "kc-quiz"
_LETTERS = "abcdefghijklmnopqrstuvwxyz"
_NBSP = "\u00a0"


class quiz(nodes.General, nodes.Element):
    """Un questionnaire : ses enfants sont des :class:`quiz_question`."""


class quiz_question(nodes.General, nodes.Element):
    """Une question : ``answer`` (numéro de la bonne réponse, à partir de 1), ``number``, ``qid``."""


class quiz_statement(nodes.General, nodes.Element):
    """L'énoncé d'une question."""


class quiz_choices(nodes.General, nodes.Element):
    """Les réponses proposées (enfants :class:`quiz_choice`)."""


class quiz_choice(nodes.General, nodes.TextElement):
    """Une réponse proposée (contenu en ligne) ; ``index`` à partir de 1."""


class quiz_explanation(nodes.General, nodes.Element):
    """L'explication, dépliée après la première vérification."""


class quiz_why(nodes.General, nodes.Element):
    """Le message d'une réponse proposée (``index`` : son numéro), montré quand on la choisit."""


class QuizDirective(SphinxDirective):
    """``quiz`` : un conteneur de questions (titre facultatif en argument)."""

    has_content = True
    optional_arguments = 1
    final_argument_whitespace = True

    def run(self):
        node = quiz()
        node["title"] = self.arguments[0] if self.arguments else ""
        self.set_source_info(node)
        self.state.nested_parse(self.content, self.content_offset, node)
        questions = [c for c in node.children if isinstance(c, quiz_question)]
        if not questions or len(questions) != len(node.children):
            return [self._error("un quiz ne contient que des questions (directive « question »), au moins une.")]
        return [node]

    def _error(self, text: str):
        return self.state.document.reporter.error(f"quiz : {text}", line=self.lineno)


class QuestionDirective(SphinxDirective):
    """``question`` : énoncé, liste des réponses proposées, explication."""

    has_content = True
    option_spec = {"answer": directives.positive_int, "name": directives.unchanged}

    def run(self):
        if "answer" not in self.options:
            return [self._error("l'option « :answer: » (numéro de la bonne réponse, à partir de 1) manque.")]
        body = nodes.container()
        self.state.nested_parse(self.content, self.content_offset, body)
        lists = [i for i, c in enumerate(body.children) if isinstance(c, nodes.bullet_list)]
        if not lists:
            return [self._error("aucune liste à puces : les réponses proposées forment la première liste.")]
        k = lists[0]
        items = body.children[k].children
        answer = self.options["answer"]
        if len(items) < 2 or not 1 <= answer <= len(items):
            return [self._error(f"{len(items)} réponse(s) proposée(s) et « :answer: {answer} » : il faut au moins "
                                "deux réponses et un numéro de bonne réponse parmi elles.")]
        question = quiz_question(answer=answer, name=self.options.get("name", ""))
        self.set_source_info(question)
        statement = quiz_statement()
        statement.extend(body.children[:k])
        choices = quiz_choices()
        whys = []
        for index, item in enumerate(items, start=1):
            choice = quiz_choice(index=index)
            content, why = item.children, []
            # le premier paragraphe : la réponse, en ligne (un <label> n'admet pas de <p>) ; la suite : son message
            if content and isinstance(content[0], nodes.paragraph):
                content, why = content[0].children, content[1:]
            choice.extend([c.deepcopy() for c in content])
            choices += choice
            if why:
                node = quiz_why(index=index)
                node.extend([c.deepcopy() for c in why])
                whys.append(node)
        explanation = quiz_explanation()
        explanation.extend(body.children[k + 1:])
        explanation.extend(whys)
        question += [statement, choices, explanation]
        return [question]

    def _error(self, text: str):
        return self.state.document.reporter.error(f"question de quiz : {text}", line=self.lineno)


# --------------------------------------------------------------------------- texte des réponses (lecteurs d'écran)

def choice_text(node) -> str:
    """Le texte d'une réponse proposée, formules comprises (écrites par :func:`tex_to_text`)."""
    parts = []
    for child in node.findall(lambda n: isinstance(n, (nodes.Text, nodes.math))):
        if isinstance(child, nodes.math):
            parts.append(tex_to_text(child.astext()))
        elif not any(isinstance(a, nodes.math) for a in _ancestors(child, node)):
            parts.append(child.astext())
    return " ".join("".join(parts).split())


def _ancestors(child, stop):
    parent = child.parent
    while parent is not None and parent is not stop:
        yield parent
        parent = parent.parent


# --------------------------------------------------------------------------- numérotation


def _chapter_of(node, docname: str) -> str:
    """Le document (chapitre) d'un nœud. Dans le LaTeX, tout le livre est un seul arbre : Sphinx y range chaque
    chapitre dans un ``start_of_file`` et marque ses sections de son nom (``section["docname"]``) ; sur le
    site, chaque page est son propre arbre (``docname``)."""
    parent = node.parent
    while parent is not None:
        if isinstance(parent, nodes.section) and parent.get("docname"):
            return parent["docname"]
        parent = parent.parent
    return docname


def _chapter_top(doctree, chapter: str, docname: str):
    """La section de tête du chapitre ``chapter`` dans ``doctree`` (l'arbre lui-même à défaut)."""
    for section in doctree.findall(nodes.section):
        if section.get("docname", docname) == chapter:
            return section
    return doctree


def _number_questions(app, doctree, docname: str) -> list[quiz_question]:
    """Numérote les questions de chaque chapitre à partir de 1 (dans le LaTeX aussi, où le livre entier est un
    seul arbre)."""
    questions = list(doctree.findall(quiz_question))
    counts: dict[str, int] = {}
    for q in questions:
        chapter = _chapter_of(q, docname)
        counts[chapter] = k = counts.get(chapter, 0) + 1
        slug = re.sub(r"[^a-z0-9]+", "-", chapter.lower()).strip("-")
        q["number"] = k
        q["qid"] = f"kc-quiz-{slug}-{k}"
        q["chapter"] = chapter
    return questions


# --------------------------------------------------------------------------- HTML

#: Le script ajouté une fois aux pages qui ont un quiz : styles et vérification des réponses.
QUIZ_SCRIPT = r"""
(function () {
  if (window.kcQuizReady) return;
  window.kcQuizReady = true;
  var css = ".kc-quiz{border:1px solid #d0d7de;border-radius:6px;padding:.6em 1em;margin:1em 0}" +
    ".kc-quiz-question{border:0;border-top:1px solid #eaeef2;padding:.6em 0;margin:0}" +
    ".kc-quiz-question:first-of-type{border-top:0}" +
    ".kc-quiz-question legend{font-weight:600;font-size:.95em;padding:0}" +
    ".kc-quiz-choice{display:block;margin:.2em 0;cursor:pointer}" +
    ".kc-quiz-choice input{margin-right:.5em}" +
    ".kc-quiz-check{margin:.4em 0;padding:.2em .9em;border:1px solid var(--pst-color-border,#888);" +
    "border-radius:4px;background:var(--pst-color-surface,#f6f8fa);color:var(--pst-color-text-base,#222);cursor:pointer}" +
    // survol : fond et texte contrastés dans les deux modes (le fond « on-surface » du thème était la couleur du texte)
    ".kc-quiz-check:hover{background:#0a55c0;border-color:#0a55c0;color:#fff}" +
    "html[data-theme=dark] .kc-quiz-check:hover{background:#79b8ff;border-color:#79b8ff;color:#0d1117}" +
    ".kc-quiz-why{margin:.2em 0 .4em;padding:.1em .6em;border-left:3px solid var(--pst-color-border,#888)}" +
    ".kc-quiz-why>p{margin:.2em 0}" +
    ".kc-quiz-wrong .kc-quiz-why{border-left-color:#cf222e}.kc-quiz-right .kc-quiz-why{border-left-color:#1a7f37}" +
    ".kc-quiz-feedback{font-weight:600;margin:.2em 0}" +
    ".kc-quiz-right .kc-quiz-feedback{color:#1a7f37}" +
    ".kc-quiz-wrong .kc-quiz-feedback{color:#cf222e}" +
    ".kc-quiz-explanation{margin:.3em 0 .2em 0}" +
    ".kc-quiz-explanation summary{cursor:pointer;color:var(--pst-color-link,#0969da)}" +
    "html[data-theme=dark] .kc-quiz-right .kc-quiz-feedback{color:#3fb950}" +
    "html[data-theme=dark] .kc-quiz-wrong .kc-quiz-feedback{color:#ff7b72}" +
    ".kc-quiz{border-color:var(--pst-color-border,#d0d7de)}.kc-quiz-question{border-top-color:var(--pst-color-border-muted,#eaeef2)}";
  var style = document.createElement("style");
  style.textContent = css;
  document.head.appendChild(style);
  document.addEventListener("click", function (event) {
    var button = event.target.closest ? event.target.closest(".kc-quiz-check") : null;
    if (!button) return;
    var question = button.closest(".kc-quiz-question");
    var chosen = question.querySelector("input[type=radio]:checked");
    var feedback = question.querySelector(".kc-quiz-feedback");
    var explanation = question.querySelector(".kc-quiz-explanation");
    question.classList.remove("kc-quiz-right", "kc-quiz-wrong");
    if (!chosen) {
      feedback.textContent = "Choisissez d\u2019abord une r\u00e9ponse.";
      return;
    }
    var right = chosen.value === question.getAttribute("data-answer");
    question.classList.add(right ? "kc-quiz-right" : "kc-quiz-wrong");
    // le message de la réponse choisie (l'erreur qu'elle trahit), et lui seul
    var why = null;
    question.querySelectorAll(".kc-quiz-why").forEach(function (w) {
      w.hidden = w.getAttribute("data-choice") !== chosen.value;
      if (!w.hidden) why = w;
    });
    feedback.textContent = right ? "Juste\u00a0!" : (why ?
      "Pas tout \u00e0 fait\u00a0: voici l\u2019erreur de cette r\u00e9ponse. R\u00e9essayez." :
      "Pas tout \u00e0 fait. R\u00e9essayez, ou d\u00e9pliez l\u2019explication.");
    if (explanation) {
      explanation.hidden = false;
      explanation.open = right;
    }
  });
})();
"""


def visit_quiz_html(self, node):
    self.body.append(f'<div class="{QUIZ_MARKER}" data-kc-quiz="{len(node.children)}">')
    if node["title"]:
        self.body.append(f'<p class="kc-quiz-title"><strong>{self.encode(node["title"])}</strong></p>')


def depart_quiz_html(self, node):
    self.body.append("</div>\n")


def visit_question_html(self, node):
    name = f' data-name="{self.attval(node["name"])}"' if node.get("name") else ""
    self.body.append(f'<fieldset class="kc-quiz-question" id="{node["qid"]}" data-answer="{node["answer"]}"{name}>'
                     f'<legend>Question {node["number"]}</legend>')


def depart_question_html(self, node):
    self.body.append("</fieldset>\n")


def visit_statement_html(self, node):
    self.body.append('<div class="kc-quiz-statement">')


def depart_div_html(self, node):
    self.body.append("</div>")


def visit_choices_html(self, node):
    self.body.append('<div class="kc-quiz-choices">')


def depart_choices_html(self, node):
    self.body.append('</div><button type="button" class="kc-quiz-check">Vérifier</button>'
                     '<p class="kc-quiz-feedback" role="status" aria-live="polite"></p>')


def visit_choice_html(self, node):
    qid = node.parent.parent["qid"]
    # nom accessible explicite : une réponse faite d'une formule n'a pas de texte pour les outils
    label = f"Réponse {_LETTERS[node['index'] - 1]} : {choice_text(node)}"
    self.body.append(f'<label class="kc-quiz-choice"><input type="radio" name="{qid}" value="{node["index"]}" '
                     f'aria-label="{self.attval(label)}"><span>')


def depart_choice_html(self, node):
    self.body.append("</span></label>")


def visit_explanation_html(self, node):
    # messages des réponses (hors de l'explication dépliable : on les voit dès qu'on choisit), puis l'explication
    whys = [c for c in node.children if isinstance(c, quiz_why)]
    for why in whys:
        node.remove(why)
    if whys:
        self.body.append('<div class="kc-quiz-whys" aria-live="polite">')
        for why in whys:
            why.walkabout(self)
        self.body.append("</div>")
    if not node.children:
        raise nodes.SkipNode
    self.body.append('<details class="kc-quiz-explanation" hidden><summary>Explication</summary>')


def depart_explanation_html(self, node):
    self.body.append("</details>")


def visit_why_html(self, node):
    self.body.append(f'<div class="kc-quiz-why" data-choice="{node["index"]}" hidden>')


def depart_why_html(self, node):
    self.body.append("</div>")


# --------------------------------------------------------------------------- autres sorties (LaTeX…)


def _as_plain_nodes(app, doctree, questions: list[quiz_question], docname: str = "") -> None:
    """Remplace chaque quiz par des listes ordinaires et regroupe les réponses à la fin de **son** chapitre
    (le LaTeX du livre est un seul arbre : un intertitre « Réponses du quiz » par chapitre)."""
    answers: dict[str, list] = {}
    for node in list(doctree.findall(quiz)):
        chapter = next((q["chapter"] for q in node.children if isinstance(q, quiz_question)), docname)
        rubric = nodes.rubric(text=node["title"] or "Quiz")
        listing = nodes.enumerated_list(enumtype="arabic", prefix="", suffix=".")
        for q in [c for c in node.children if isinstance(c, quiz_question)]:
            statement, choices, explanation = q.children
            item = nodes.list_item()
            item.extend(statement.children)
            options = nodes.enumerated_list(enumtype="loweralpha", prefix="(", suffix=")")
            for choice in choices.children:
                options += nodes.list_item("", nodes.paragraph("", "", *choice.children))
            item += options
            listing += item
            right = choices.children[q["answer"] - 1]
            letter = _LETTERS[q["answer"] - 1]
            head = nodes.paragraph()
            head += nodes.strong(text=f"Question {q['number']}{_NBSP}: ({letter}) ")
            head.extend(c.deepcopy() for c in right.children)
            whys = [c for c in explanation.children if isinstance(c, quiz_why)]
            block = [head, *[c for c in explanation.children if not isinstance(c, quiz_why)]]
            if whys:  # l'erreur de chaque autre réponse, pour le corrigé de l'enseignant
                listing_whys = nodes.bullet_list()
                for why in whys:
                    item = nodes.list_item()
                    content = [c.deepcopy() for c in why.children]
                    if content and isinstance(content[0], nodes.paragraph):
                        content[0].insert(0, nodes.emphasis(text=f"({_LETTERS[why['index'] - 1]}){_NBSP}: "))
                    item.extend(content)
                    listing_whys += item
                block.append(listing_whys)
            answers.setdefault(chapter, []).append(block)
        node.replace_self([rubric, listing])
    for chapter, blocks in answers.items():
        # un intertitre (rubrique), pas une section : ni numéro ni entrée dans la table des matières, et la
        # page d'accueil, dont LaTeX aplatit les sections, n'en fait pas une « partie » avant le cours
        slug = re.sub(r"[^a-z0-9]+", "-", chapter.lower()).strip("-")
        heading = nodes.rubric(text="Réponses du quiz", ids=[f"kc-quiz-reponses-{slug}"])
        target = _chapter_top(doctree, chapter, docname)
        target.append(heading)
        for block in blocks:
            target.extend(block)


def _resolve(app, doctree, docname: str) -> None:
    questions = _number_questions(app, doctree, docname)
    if not questions:
        return
    if app.builder.format != "html":
        _as_plain_nodes(app, doctree, questions, docname)


def _add_script(app, pagename, templatename, context, doctree) -> None:
    if doctree is not None and next(iter(doctree.findall(quiz_question)), None) is not None:
        app.add_js_file(None, body=QUIZ_SCRIPT)


def setup(app):
    html = (visit_quiz_html, depart_quiz_html)
    app.add_node(quiz, html=html)
    app.add_node(quiz_question, html=(visit_question_html, depart_question_html))
    app.add_node(quiz_statement, html=(visit_statement_html, depart_div_html))
    app.add_node(quiz_choices, html=(visit_choices_html, depart_choices_html))
    app.add_node(quiz_choice, html=(visit_choice_html, depart_choice_html))
    app.add_node(quiz_explanation, html=(visit_explanation_html, depart_explanation_html))
    app.add_node(quiz_why, html=(visit_why_html, depart_why_html))
    app.add_directive("quiz", QuizDirective)
    app.add_directive("question", QuestionDirective)
    app.connect("doctree-resolved", _resolve)
    app.connect("html-page-context", _add_script)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
