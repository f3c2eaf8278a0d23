"""La relecture du livre (sans construction, sauf les tests marqués ``book``) : même mobilier sur toutes les
pages, encadrés d'algorithme, paragraphe de transition, renvois qui se lisent comme des phrases françaises,
vocabulaire du cours, une seule convention pour la commande, glossaire.

Chaque règle est écrite comme une fonction qui rend la liste des problèmes d'un texte ; un test la vérifie
d'abord sur des textes écrits ici (elle doit pouvoir échouer), puis sur les chapitres du livre.
"""

from __future__ import annotations

import html as htmllib
import re
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parent.parent
BOOK = ROOT / "book"
#: Annexes : ni objectifs, ni bibliographie, ni transition.
APPENDICES = {"errata", "glossaire", "references"}


def _toc() -> list[str]:
    toc = yaml.safe_load((ROOT / "_toc.yml").read_text())
    return [Path(toc["root"]).name] + [Path(c["file"]).name for part in toc["parts"] for c in part["chapters"]]


TOC = _toc()
CHAPTERS = [p for p in TOC if p not in APPENDICES and p != TOC[0]]


def _text(page: str) -> str:
    return (BOOK / f"{page}.md").read_text()


def _prose(text: str) -> str:
    """Le texte sans les cellules de code, les blocs de code et les formules en display."""
    text = re.sub(r"```\{code-cell\}.*?```", "", text, flags=re.S)
    text = re.sub(r"```(?:python|bash|text)?\n.*?```", "", text, flags=re.S)
    return re.sub(r"\$\$.*?\$\$", "", text, flags=re.S)


def _title(page: str) -> str:
    return re.search(r"(?m)^# (.+)$", _text(page)).group(1).strip()


# --------------------------------------------------------------------------- mobilier des pages


def furniture_problems(text: str, later_pages: set[str]) -> list[str]:
    """Le mobilier d'un chapitre : encadrés « Objectifs » puis « Prérequis » avant la première section,
    section « À retenir » qui se termine par « **La suite.** » et un renvoi à une page suivante,
    section « Bibliographie » en dernier, avec la bibliographie du chapitre."""
    problems = []
    head = text.split("\n## ", 1)[0]
    if not re.search(r"^:::\{admonition\} Objectifs\n:class: note\n", head, re.M):
        problems.append("pas d'encadré « Objectifs » en tête")
    if not re.search(r"^:::\{admonition\} Prérequis\n:class: note\n", head, re.M):
        problems.append("pas d'encadré « Prérequis » séparé en tête")
    if re.search(r"^\*\*Prérequis\*\*", text, re.M):
        problems.append("« Prérequis » dans le texte au lieu d'un encadré")
    if re.search(r"^:{3,}\{admonition\} À retenir", text, re.M):
        problems.append("« À retenir » en encadré au lieu d'une section")
    sections = re.findall(r"^## (.+?)\s*$", text, re.M)
    if sections[-2:] != ["À retenir", "Bibliographie"]:
        problems.append(f"les deux dernières sections sont {sections[-2:]}, et non « À retenir », « Bibliographie »")
    if sections.count("À retenir") != 1:
        problems.append(f"{sections.count('À retenir')} sections « À retenir »")
    if "## À retenir" in text:
        keep = text.split("## À retenir", 1)[1].split("\n## ", 1)[0]
        bridge = re.search(r"^\*\*La suite\.\*\* (.+)$", keep, re.M)
        if not bridge:
            problems.append("pas de paragraphe « **La suite.** » à la fin de « À retenir »")
        elif not set(re.findall(r"\{doc\}`(?:[^`<]*<)?([\w-]+)>?`", bridge.group(1))) & later_pages:
            problems.append("« La suite » ne renvoie à aucune page qui suit")
    bib = text.split("## Bibliographie", 1)[1] if "## Bibliographie" in text else ""
    if not re.search(r"```\{bibliography\}\n:filter: docname in docnames\n", bib):
        problems.append("pas de bibliographie du chapitre (filter: docname in docnames)")
    return problems


def test_furniture_check_flags_missing_boxes_sections_and_bridges():
    good = (":::{admonition} Objectifs\n:class: note\n- a\n- b\n:::\n\n:::{admonition} Prérequis\n:class: note\n"
            "Rien.\n:::\n\nTexte.\n\n## Une section\n\nTexte.\n\n## À retenir\n\n- a\n- b\n\n"
            "**La suite.** Le chapitre {doc}`suite` continue.\n\n## Bibliographie\n\n"
            "```{bibliography}\n:filter: docname in docnames\n```\n")
    assert furniture_problems(good, {"suite"}) == []
    assert furniture_problems(good, {"autre"}) == ["« La suite » ne renvoie à aucune page qui suit"]
    inside = good.replace(":::\n\n:::{admonition} Prérequis\n:class: note\nRien.\n:::", "\n**Prérequis** : rien.\n:::")
    assert len(furniture_problems(inside, {"suite"})) == 2
    box = good.replace("## À retenir\n\n- a\n- b\n", ":::{admonition} À retenir\n:class: tip\n- a\n- b\n:::\n")
    assert "« À retenir » en encadré au lieu d'une section" in furniture_problems(box, {"suite"})
    assert furniture_problems(good.replace("**La suite.** ", ""), {"suite"}) == [
        "pas de paragraphe « **La suite.** » à la fin de « À retenir »"]
    no_bib = good.split("## Bibliographie")[0]
    assert len(furniture_problems(no_bib, {"suite"})) == 2


@pytest.mark.parametrize("chapter", CHAPTERS)
def test_every_chapter_has_the_same_furniture(chapter):
    later = set(TOC[TOC.index(chapter) + 1:])
    problems = furniture_problems(_text(chapter), later)
    assert not problems, f"{chapter} : " + " ; ".join(problems)


#: Les chapitres et les algorithmes que leur encadré ``prf:algorithm`` doit porter.
ALGORITHMS = {
    "ekf": "alg-ekf-tag", "ekf-itere": "alg-iekf", "ukf": "alg-ukf", "filtre-particulaire": "alg-pf",
    "enkf": "alg-enkf", "lissage": "alg-rts", "vraisemblance": "alg-em", "srif": "alg-srif",
    "ekf-itere-se3": "alg-iekf-se3",
}


@pytest.mark.parametrize("chapter, label", sorted(ALGORITHMS.items()))
def test_algorithms_have_a_box_with_inputs_and_output(chapter, label):
    box = re.search(r"```\{prf:algorithm\} [^\n]+\n:label: " + re.escape(label) + r"\n(.*?)```", _text(chapter), re.S)
    assert box, f"{chapter} : pas d'encadré prf:algorithm « {label} »"
    body = box.group(1)
    assert "**Entrées**" in body and "**Sortie**" in body, f"{label} : entrées et sortie"
    assert len(re.findall(r"^\s*\d+\. ", body, re.M)) >= 3, f"{label} : au moins trois étapes numérotées"


def test_slider_cells_show_no_code():
    """Les figures à curseurs ne montrent pas leur cellule : la page n'affiche que la figure."""
    for page in TOC:
        for cell in re.findall(r"```\{code-cell\}[^\n]*\n(.*?)```", _text(page), re.S):
            if re.search(r"kc\.interactive\.(?:sliders\(|\w+_sliders\()", cell):
                assert re.search(r":tags: \[[^\]]*remove-(?:input|cell)", cell), f"{page} : cellule à curseurs visible"


# --------------------------------------------------------------------------- renvois et vocabulaire


_ARTICLE_TITLE = re.compile(r"^(?:Le|La|Les|L[’']|Un|Une) ")
_BEFORE_DOC = re.compile(r"(?i)(?<![\w’'])(le|la|les|du|des|au|aux|un|une|de|jusqu[’']au|l[’']|d[’'])\s*\{doc\}`([\w-]+)`")


def doubled_article_problems(text: str, titles: dict[str, str]) -> list[str]:
    """Un renvoi ``{doc}`` sans texte cite le titre du chapitre ; précédé d'un article ou de « de », il
    donnerait « le Le filtre… » ou « de Exemple… ». Il faut un nom devant : « le chapitre {doc}`…` »."""
    return [f"« {m.group(1)} {{doc}}`{m.group(2)}` » (titre : « {titles[m.group(2)]} »)"
            for m in _BEFORE_DOC.finditer(_prose(text))
            if m.group(2) in titles and (_ARTICLE_TITLE.match(titles[m.group(2)]) or m.group(1).lower() in {"de", "d'", "d’"})]


def test_doubled_article_check():
    titles = {"ukf": "Le filtre de Kalman unscented (UKF)", "suivi-tag": "Exemple — suivi d'un tag radio",
              "glossaire": "Glossaire français–anglais"}
    bad = "puis le {doc}`ukf`, et un exemple complet de {doc}`suivi-tag`."
    assert len(doubled_article_problems(bad, titles)) == 2
    good = ("puis le chapitre {doc}`ukf`, un exemple complet ({doc}`suivi-tag`), le {doc}`glossaire` "
            "et le {doc}`filtre <ukf>`.")
    assert doubled_article_problems(good, titles) == []


@pytest.mark.parametrize("page", [p for p in TOC if p != "references"])
def test_references_to_chapters_read_as_french(page):
    titles = {p: _title(p) for p in TOC}
    problems = doubled_article_problems(_text(page), titles)
    assert not problems, f"{page} : " + " ; ".join(problems)
    # un renvoi à un algorithme numéroté porte son propre texte (« l'algorithme Algorithme 1 »)
    assert not re.search(r"\{prf:ref\}`[\w-]+`", _text(page)), f"{page} : prf:ref sans texte"


#: Les termes que le livre n'emploie plus, et ce qu'il écrit à la place.
WORDING = {
    r"sans parfum": "« *unscented* » (la traduction littérale n'est citée qu'une fois, en note)",
    r"départ diffus": "« initialisation diffuse »",
    r"curseurs? vivants?": "« curseurs interactifs »",
    r"gratuitement": "« sans calcul supplémentaire »",
    r"\be\.t\.": "« écart-type » en toutes lettres",
    r"\$[a-z]\$-ième|\bième\b": "« $i$ᵉ »",
    r"erreurs? standards?": "« erreurs types » ou « écarts-types »",
    r"\bobservateurs?\b(?! est un estimateur)(?!\s*»)": "« fonction d'observation » (un observateur est un estimateur)",
    r"\ble NIS\b": "« la NIS » (l'innovation normalisée)",
    r"regroupant les carrés": "« en complétant le carré »",
}


def wording_problems(text: str) -> list[str]:
    prose = _prose(text)
    prose = re.sub(r"^\[\^unscented\]:.*$", "", prose, flags=re.M)  # la note sur l'origine du nom
    return [f"« {m.group(0)} » : écrire {advice}" for pattern, advice in WORDING.items()
            for m in re.finditer(pattern, prose, re.I)]


def test_wording_check():
    assert len(wording_problems("Le filtre sans parfum, au départ diffus, le NIS et la $i$-ième ligne.")) == 4
    assert wording_problems("Le filtre *unscented*, l'initialisation diffuse, la NIS et la $i$ᵉ ligne.") == []
    assert wording_problems("```{code-cell} ipython3\n# départ diffus\n```\n") == []  # le code n'est pas lu


@pytest.mark.parametrize("page", TOC)
def test_wording_of_the_course(page):
    problems = wording_problems(_text(page))
    assert not problems, f"{page} : " + " ; ".join(problems)


_SOFTWARE = re.compile(r"\b[Ll]es tests (?:du paquet )?(?:vérifient|comparent)")


@pytest.mark.parametrize("chapter", CHAPTERS)
def test_software_talk_stays_in_the_package_boxes(chapter):
    """« Les tests vérifient… » : hors des dérivations, dans un encadré « Dans le paquet » (ou en note)."""
    text = _text(chapter)
    outside = re.sub(r":::\{admonition\} Dans le paquet\n.*?\n:::", "", text, flags=re.S)
    assert not _SOFTWARE.search(_prose(outside)), f"{chapter} : « {_SOFTWARE.search(_prose(outside)).group(0)} »"


# --------------------------------------------------------------------------- notations


#: La commande d'indice k : « B u_k » ou « f(…, u_k) ».
_U_K = re.compile(r"B\s*u_\{?k\}?(?![\w+-])|,\s*u_\{?k\}?\s*\)")


def control_index_problems(text: str) -> list[str]:
    r"""La convention de la commande (:math:`x_k = f(x_{k-1}, u_{k-1})`, :math:`x_{k+1} = Ax_k + Bu_k`) : une
    formule qui va de :math:`k-1` à :math:`k` (elle contient un indice :math:`k-1`) ne prend pas :math:`u_k`."""
    return [f"${f.strip()}$ : de k − 1 à k, la commande est u_{{k−1}}"
            for f in re.findall(r"\$([^$]+)\$", _prose(text)) if "k-1" in f.replace(" ", "") and _U_K.search(f)]


def test_control_index_check():
    assert control_index_problems("$x_k = f(x_{k-1}, u_{k-1}) + w$ et $x_{k+1} = Ax_k + Bu_k$") == []
    assert len(control_index_problems("$x^i_k = f(x^i_{k-1}, u_k) + w^i$")) == 1
    assert len(control_index_problems("$r_k = \\hat x_{k\\mid T} - A\\hat x_{k-1\\mid T} - Bu_k$ ; $x_k = Ax_{k-1} + Bu_k$")) == 2


@pytest.mark.parametrize("page", TOC)
def test_one_control_convention(page):
    problems = control_index_problems(_text(page))
    assert not problems, f"{page} : " + " ; ".join(problems)


def test_the_introduction_states_the_control_convention_and_the_notation_switches():
    intro = _text(TOC[0])
    notation = intro.split("(notations)=", 1)[1].split("\n## ", 2)[1]
    assert "**Convention de la commande.**" in notation and "u_{k-1}" in notation and "`u[k]`" in notation
    headers = " ".join(line for line in notation.splitlines() if line.startswith("| grandeur"))
    for column in ("cours", "filtrage non linéaire", "lissage, vraisemblance, SRIF", "paquet", "filterpy"):
        assert column in headers, column
    # chaque chapitre qui change de notation le dit en tête
    for chapter in ("suivi-tag", "lissage", "vraisemblance", "filtre-particulaire"):
        head = _text(chapter).split("\n## ", 1)[0]
        assert re.search(r":::\{admonition\} (?:Changement de notation|Notations de ce chapitre)", head), chapter


def test_roadmap_of_the_introduction_lists_every_page():
    intro = _text(TOC[0])
    roadmap = intro.split("## Comment lire ce livre", 1)[0]
    cited = re.findall(r"\{doc\}`([\w-]+)`", roadmap)
    assert [p for p in TOC[1:] if p in cited] == TOC[1:], sorted(set(TOC[1:]) - set(cited))


def _collation_key(term: str) -> str:
    """Ordre du dictionnaire : sans accents, sans espaces ni ponctuation (« bruit de mesure » avant
    « bruit d'état »)."""
    import unicodedata

    flat = unicodedata.normalize("NFKD", term)
    return "".join(c for c in flat if c.isalnum())


def test_glossary_lists_terms_with_english_symbol_and_chapter():
    rows = [r for r in _text("glossaire").splitlines() if r.startswith("| ") and not r.startswith("| terme")]
    assert len(rows) >= 50
    french = [re.sub(r"[*«»]", "", r.split("|")[1]).strip().lower() for r in rows]
    assert french == sorted(french, key=_collation_key), "ordre alphabétique"
    for row in rows:
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert len(cells) == 4 and all(cells[:2]) and cells[3], row
        for target in re.findall(r"\{doc\}`[^`<]*<([\w-]+)>`", cells[3]):
            assert target in TOC, target
    for term in ("innovation", "gain de kalman", "points sigma", "rééchantillonnage", "vraisemblance",
                 "initialisation diffuse", "lisseur de rauch–tung–striebel (rts)"):
        assert term in french, term


# --------------------------------------------------------------------------- le livre construit


_DOUBLED = re.compile(r"\b(?:[Ll]e|[Ll]a|[Ll]es|[Dd]u|[Dd]es|[Aa]u|[Uu]n|[Uu]ne)\s+(?:Le|La|Les|Un|Une)\s"
                      r"|\b[Dd]e\s+(?:Le(?! Gland)|La|Les|Exemple|Exercice|Algorithme)\b"
                      r"|l[’']algorithme\s+Algorithme|Solution de Exercice")


@pytest.mark.book
def test_built_pages_have_no_doubled_article_and_italic_latin(built_book):
    problems = []
    for page in sorted((built_book / "book").glob("*.html")):
        html = page.read_text()
        body = html.split('<article class="bd-article"', 1)[-1].split("</article>", 1)[0]
        text = htmllib.unescape(re.sub(r"<[^>]+>", " ", re.sub(r"<(script|style)\b.*?</\1>", "", body, flags=re.S)))
        text = " ".join(text.split())
        for m in _DOUBLED.finditer(text):
            problems.append(f"{page.name} : « {text[max(0, m.start() - 30):m.end() + 30]} »")
        # a priori / a posteriori : toujours en italique dans le texte courant
        plain = re.sub(r"<em>a (?:priori|posteriori)</em>", "", body)
        plain = re.sub(r"<(script|style|code|pre|object)\b.*?</\1>|<span class=\"math[^>]*>.*?</span>", "", plain,
                       flags=re.S)
        for m in re.finditer(r"(?<![\w-])a (?:priori|posteriori)(?![\w-])", htmllib.unescape(re.sub(r"<[^>]+>", "", plain))):
            problems.append(f"{page.name} : « a priori » sans italique")
            break
    assert not problems, "\n".join(problems)


@pytest.mark.book
def test_solutions_are_titled_solution_and_chapter_references_are_quoted(built_book):
    html = (built_book / "book" / "intuition.html").read_text()
    assert "Solution de Exercice" not in html
    assert re.search(r'class="admonition-title">Solution', html) or re.search(r">Solution<", html)
    intro = (built_book / "book" / "intro.html").read_text()
    # les titres de chapitres cités sont entre guillemets français
    assert re.search(r"«\s*Le filtre de Kalman en images\s*»", htmllib.unescape(re.sub(r"<[^>]+>", "", intro)))


def test_bibliography_style_writes_editions_and_collections_in_french():
    """Le style des listes de références (kalman_course.book_citations) : « 4ᵉ édition », « Dans … éd. »,
    jamais « 4 edition » ni « In »."""
    from pybtex.database import parse_file

    from kalman_course.book_citations import _formatting_style

    style = _formatting_style()(label_style="alpha")
    entries = parse_file(str(BOOK / "references.bib")).entries
    text = {key: list(style.format_entries([entries[key]]))[0].text.render_as("text")
            for key in ("shumway2017", "legland2011", "doucet2011")}
    assert "4ᵉ édition" in text["shumway2017"] and "edition" not in text["shumway2017"]
    for key in ("legland2011", "doucet2011"):
        assert ". Dans Dan Crisan et Boris Rozovskii, éd., The Oxford Handbook" in text[key], text[key]
        assert " In " not in text[key]
    assert "une autre loi sinon" in text["legland2011"]  # la note est imprimée


@pytest.mark.parametrize("page", TOC)
def test_no_line_of_prose_starts_with_a_high_punctuation_mark(page):
    """Une ligne qui commence par « ; », « : », « ? » ou « ! » (hors marque de définition « : » en début de
    ligne) laisse une espace ordinaire devant le signe : la typographie travaille nœud par nœud, et le retour à
    la ligne de MyST en sépare deux."""
    bad = [line for line in _prose(_text(page)).splitlines() if re.match(r"^\s+[;:!?](\s|$)|^[;!?](\s|$)", line)]
    assert not bad, f"{page} : {bad[:3]}"
