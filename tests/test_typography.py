"""Typographie française du livre (kalman_course.typography et son extension Sphinx kalman_course.sphinx.typography) : règles sur des chaînes écrites à la
main, et transformation d'un document docutils qui laisse intacts code, formules et HTML brut."""

from __future__ import annotations

from docutils import nodes
from docutils.core import publish_doctree

from kalman_course.sphinx.typography import italicize_latin, typeset, typeset_mermaid
from kalman_course.typography import french_spacing

NB, NN = "\u00a0", "\u202f"


def test_french_spacing_rules():
    assert french_spacing("Le gain : un compromis ; vraiment ? Oui !") == (
        f"Le gain{NB}: un compromis{NN}; vraiment{NN}? Oui{NN}!"
    )
    assert french_spacing("la « recette de cuisine » du filtre") == f"la «{NB}recette de cuisine{NB}» du filtre"
    assert french_spacing("«mot»") == f"«{NB}mot{NB}»"
    assert french_spacing("95 % des cas") == f"95{NN}% des cas"
    assert french_spacing("l'estimation d'aujourd'hui") == "l’estimation d’aujourd’hui"
    # déjà correct : inchangé (idempotent)
    once = french_spacing("Note : « a » ; b ?")
    assert french_spacing(once) == once


def test_french_spacing_leaves_times_urls_and_math():
    assert french_spacing("à 10:30, voir https://example.org/a:b") == "à 10:30, voir https://example.org/a:b"
    assert french_spacing("avec $x' : y$ : fin") == f"avec $x' : y${NB}: fin"


def test_typeset_skips_code_math_and_raw():
    doc = publish_doctree(
        "Titre : test\n============\n\n"
        "Texte : l'**estimation** ; voir ``code : 'a'`` et :math:`x' : y` !\n\n"
        "::\n\n    print('a : b')\n\n"
        ".. raw:: html\n\n   <b>brut : 'x'</b>\n",
        settings_overrides={"report_level": 5},
    )
    typeset(doc)
    text = doc.astext()
    assert f"Titre{NB}: test" in text
    assert f"Texte{NB}: l’estimation{NN}; voir" in text
    assert "code : 'a'" in text  # littéral intact
    assert "x' : y" in [n.astext() for n in doc.findall(nodes.math)]
    assert "print('a : b')" in text
    assert "<b>brut : 'x'</b>" in text
    assert text.rstrip().endswith("brut : 'x'</b>")


def test_latin_phrases_are_italicised_in_running_text_only():
    doc = publish_doctree(
        "L'estimation a priori, puis a posteriori, et l'a priori ; *a priori* déjà en italique.\n\n"
        "Code : ``a priori`` et :math:`\\text{a priori}` ; le mot « apriorisme » et « la priori ».\n",
        settings_overrides={"report_level": 5},
    )
    assert italicize_latin(doc) == 3
    emphasised = [n.astext() for n in doc.findall(nodes.emphasis)]
    assert emphasised == ["a priori", "a posteriori", "a priori", "a priori"]
    assert "a priori" in [n.astext() for n in doc.findall(nodes.literal)]  # code intact
    assert "\\text{a priori}" in [n.astext() for n in doc.findall(nodes.math)]
    assert doc.astext().startswith("L'estimation a priori, puis a posteriori, et l'a priori ;")
    assert italicize_latin(doc) == 0  # une seconde passe ne change rien


def test_mermaid_labels_get_the_same_typography_but_not_the_syntax():
    doc = publish_doctree("Texte.\n", settings_overrides={"report_level": 5})
    node = nodes.Element()
    node.tagname = "mermaid"
    node["code"] = ('flowchart TB\n    K0["on fait confiance<br/>au <b>MODÈLE</b> : x̂ ≈ x̂⁻ a priori"]\n'
                    '    A["Matrice d\'état A"] -->|"n ← n+1 ; suite"| B\n    style K0 fill:#c8e6c9,stroke:#388e3c\n')
    doc += node
    assert typeset_mermaid(doc) == 1
    assert f"<b>MODÈLE</b>{NB}: x̂" in node["code"] and "Matrice d’état A" in node["code"]
    assert "x̂⁻ <i>a priori</i>" in node["code"]
    assert f"n+1{NN}; suite" in node["code"]
    assert "style K0 fill:#c8e6c9,stroke:#388e3c" in node["code"]  # la syntaxe ne change pas
    assert typeset_mermaid(doc) == 0
