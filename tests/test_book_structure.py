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
#: Travaux dirigés et travaux pratiques : des pages d'exercices, pas des chapitres. Elles gardent en tête
#: les encadrés « Objectifs » et « Prérequis » (les chapitres à avoir lus) et finissent par un quiz ; elles
#: n'ont ni section « À retenir » (un encadré la remplace, après le quiz), ni « La suite », ni bibliographie :
#: le cours qu'elles exercent est dans les chapitres cités en prérequis.
PRACTICE = [p for p in CHAPTERS if re.match(r"t[dp]-|sujet-examen$", p)]
LESSONS = [p for p in CHAPTERS if p not in PRACTICE]


def _text(page: str) -> str:
    return (BOOK / f"{page}.md").read_text()


def _prose(text: str) -> str:
    """Le texte sans les cellules de code, les blocs de code et les formules en display. Les directives
    à trois accents graves (```{exercise}, ```{dropdown}…) restent : leur contenu est de la prose. On lit
    ligne à ligne, pour qu'une clôture « ``` » ne soit jamais prise pour l'ouverture d'un bloc de code."""
    kept, stack = [], []
    for line in text.splitlines(keepends=True):
        fence = line.rstrip("\n")
        if stack and stack[-1] == "code":
            if fence == "```":
                stack.pop()
            continue
        if fence == "```" and stack:
            stack.pop()
        elif fence.startswith("```") and not fence.startswith("````"):
            directive = fence[3:].startswith("{") and not fence[3:].startswith("{code-cell}")
            stack.append("directive" if directive else "code")
            if not directive:
                continue
        kept.append(line)
    return re.sub(r"\$\$.*?\$\$", "", "".join(kept), flags=re.S)


def test_prose_drops_code_but_keeps_directives_and_the_prose_after_a_block():
    text = ("Avant.\n\n```{code-cell} ipython3\nx = 1  # code\n```\n\nEntre.\n\n```{exercise}\n:label: e\n"
            "Énoncé.\n```\n\nAprès.\n\n```python\nimport kalman_course\n```\n\nFin.\n\n$$\nx^2\n$$\n")
    prose = _prose(text)
    for kept in ("Avant.", "Entre.", "Énoncé.", "Après.", "Fin."):
        assert kept in prose, kept
    for dropped in ("# code", "import kalman_course", "x^2"):
        assert dropped not in prose, dropped


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


@pytest.mark.parametrize("chapter", LESSONS)
def test_every_chapter_has_the_same_furniture(chapter):
    later = set(TOC[TOC.index(chapter) + 1:])
    problems = furniture_problems(_text(chapter), later)
    assert not problems, f"{chapter} : " + " ; ".join(problems)


def practice_furniture_problems(text: str) -> list[str]:
    """Le mobilier d'une page de TD ou de TP : encadrés « Objectifs » puis « Prérequis » avant la première
    section, et une section « Quiz » qui porte un quiz. Ni « À retenir » en section, ni « La suite », ni
    bibliographie ne sont exigés."""
    problems = []
    head = text.split("\n## ", 1)[0]
    if not re.search(r"^:::\{admonition\} Objectifs\n:class: note\n", head, re.M):
        problems.append("pas d'encadré « Objectifs » en tête")
    prerequisites = re.search(r"^:::\{admonition\} Prérequis\n:class: note\n(.*?)^:::$", head, re.M | re.S)
    if not prerequisites:
        problems.append("pas d'encadré « Prérequis » séparé en tête")
    elif not re.search(r"\{doc\}`", prerequisites.group(1)):
        problems.append("l'encadré « Prérequis » ne renvoie à aucun chapitre")
    if re.search(r"^\*\*Prérequis\*\*", text, re.M):
        problems.append("« Prérequis » dans le texte au lieu d'un encadré")
    quiz = text.split("\n## Quiz\n", 1)[1].split("\n## ", 1)[0] if "\n## Quiz\n" in text else ""
    if not re.search(r"^::::\{quiz\}", quiz, re.M):
        problems.append("pas de section « Quiz » avec son quiz")
    return problems


def test_practice_furniture_check_flags_missing_boxes_and_quiz():
    good = (":::{admonition} Objectifs\n:class: note\n- a\n- b\n:::\n\n:::{admonition} Prérequis\n:class: note\n"
            "Le chapitre {doc}`ukf`.\n:::\n\nTexte.\n\n## 1. Un exercice\n\nTexte.\n\n## Quiz\n\n"
            "::::{quiz}\n:::{question}\nQ ?\n- a\n- b\n:::\n::::\n\n:::{admonition} À retenir\n:class: tip\n- a\n:::\n")
    assert practice_furniture_problems(good) == []
    inside = good.replace(":::\n\n:::{admonition} Prérequis\n:class: note\nLe", "\n**Prérequis** : le")
    assert len(practice_furniture_problems(inside)) == 2
    assert practice_furniture_problems(good.replace("{doc}`ukf`", "précédent")) == [
        "l'encadré « Prérequis » ne renvoie à aucun chapitre"]
    assert practice_furniture_problems(good.replace("## Quiz", "## Questions")) == [
        "pas de section « Quiz » avec son quiz"]
    assert practice_furniture_problems(good.replace(":::{admonition} Objectifs", ":::{admonition} Buts")) == [
        "pas d'encadré « Objectifs » en tête"]


def test_practice_pages_are_the_td_and_tp_pages():
    assert PRACTICE and all(p.startswith(("td-", "tp-", "sujet-examen")) for p in PRACTICE)
    assert len(LESSONS) >= 20 and not any(p.startswith(("td-", "tp-", "sujet-")) for p in LESSONS)


@pytest.mark.parametrize("page", PRACTICE)
def test_every_practice_page_has_its_furniture(page):
    problems = practice_furniture_problems(_text(page))
    assert not problems, f"{page} : " + " ; ".join(problems)


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
    # relecture (issue 36) : un terme par notion, moins de personnification
    r"\b(?:le|un|son|du|au|ce) NEES\b|\bNEES moyen\b": "« la NEES » (une erreur normalisée, comme « la NIS »)",
    r"(?<!racine de l['’])\berreur quadratique moyenne\b":
        "« racine de l'erreur quadratique moyenne (REQM) » (la valeur citée est une REQM)",
    r"\b(?:la|une|sa|sans|cette|leur|propre|à|de) portes?\b(?!\s+(?:sur|le|la|les|l['’]|un|une|des|son|sa|ses|"
    r"leur|aussi|bien|tout|toute|donc|alors|souvent)\b)": "« fenêtre de validation » (en anglais *gate*)",
    r"\bse croi(?:t|ent)\b|\btrembl(?:e|ent|er)\b":
        "ce que font l'estimation ou sa covariance (« suit le bruit des mesures », « sa covariance sous-estime "
        "l'erreur »)",
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


# (une phrase coupée en fin de ligne compte aussi ; un script de mesure nommé dans la prose aussi : issue 36)
_SOFTWARE = re.compile(r"\b[Ll]es\s+tests\s+(?:du\s+paquet\s+)?(?:l[ea]\s+|les\s+|l['’])?(?:vérifient|comparent)"
                       r"|`test_\w+`|`benchmarks/[\w./]+`")


def software_talk_outside_boxes(text: str) -> list[str]:
    """« Les tests vérifient… » ou un nom de test dans la prose, hors des encadrés « Dans le paquet »."""
    outside = re.sub(r":::\{admonition\} Dans le paquet\n.*?\n:::", "", text, flags=re.S)
    return [m.group(0) for m in _SOFTWARE.finditer(_prose(outside))]


def test_software_talk_check():
    assert software_talk_outside_boxes("La covariance est juste (test `test_joseph`). Les tests vérifient tout.") \
        == ["`test_joseph`", "Les tests vérifient"]
    assert software_talk_outside_boxes("C'est le même calcul. Les tests du paquet le vérifient.") == [
        "Les tests du paquet le vérifient"]
    assert software_talk_outside_boxes("C'est un point fixe (les tests du\npaquet le vérifient), mesuré par "
                                       "`benchmarks/imm.py`.") == ["les tests du\npaquet le vérifient",
                                                                   "`benchmarks/imm.py`"]
    boxed = ":::{admonition} Dans le paquet\n:class: seealso\nLe test `test_joseph` la compare.\n:::\n"
    assert software_talk_outside_boxes("La covariance est juste.\n\n" + boxed) == []


@pytest.mark.parametrize("chapter", CHAPTERS)
def test_software_talk_stays_in_the_package_boxes(chapter):
    """« Les tests vérifient… » : hors des dérivations, dans un encadré « Dans le paquet » (ou en note)."""
    found = software_talk_outside_boxes(_text(chapter))
    assert not found, f"{chapter} : {found}"


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
    """Le style des listes de références (kalman_course.sphinx.citations) : « 4ᵉ édition », « Dans … éd. »,
    jamais « 4 edition » ni « In »."""
    from pybtex.database import parse_file

    from kalman_course.sphinx.citations import _formatting_style

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


# --------------------------------------------------------------------------- ordre des chapitres, références


def _sections(text: str) -> list[str]:
    return re.findall(r"^## (.+?)\s*$", text, re.M)


def order_problems(text: str, first: str, then: str) -> list[str]:
    """La section dont le titre contient ``first`` vient avant celle dont le titre contient ``then``."""
    sections = [s.lower() for s in _sections(text)]
    where = {key: next((i for i, s in enumerate(sections) if key.lower() in s), None) for key in (first, then)}
    missing = [f"pas de section « {key} »" for key, i in where.items() if i is None]
    if missing:
        return missing
    return [] if where[first] < where[then] else [f"« {first} » vient après « {then} »"]


def test_order_check():
    text = "# T\n\n## Intro\n\n## L'ensemble symétrique de Julier\n\n## Mettre à l'échelle : α\n"
    assert order_problems(text, "ensemble symétrique", "mettre à l'échelle") == []
    assert len(order_problems(text, "mettre à l'échelle", "ensemble symétrique")) == 1
    assert len(order_problems(text, "grille", "mettre à l'échelle")) == 1


def test_ukf_chapter_starts_from_julier_symmetric_set_then_scales():
    """Issue 18 : l'ensemble symétrique de Julier (κ seul), la transformée, puis α et β et les poids négatifs ;
    aucun α dans le texte avant la mise à l'échelle (sauf l'annonce du plan, en tête)."""
    text = _text("ukf")
    for first, then in (("ensemble symétrique de Julier", "transformée"), ("transformée", "mettre à l'échelle"),
                        ("mettre à l'échelle", "le filtre")):
        assert not order_problems(text, first, then), order_problems(text, first, then)
    before_scaling = _prose(text.split("\n## Mettre à l'échelle", 1)[0].split("\n## ", 1)[1])
    assert "\\alpha" not in before_scaling and "\\beta" not in before_scaling
    # l'ensemble de Julier : poids κ/(n + κ) et 1/(2(n + κ)), vérifiés par une cellule (moment d'ordre 4)
    julier = text.split("## L'ensemble symétrique de Julier", 1)[1].split("\n## ", 1)[0]
    assert "W_0 = \\frac{\\kappa}{n + \\kappa}" in julier and "{glue:text}`m4_julier`" in julier


def test_particle_chapter_opens_with_the_exact_grid_bayes_filter():
    """Le filtre bayésien exact sur une grille (et ses deux modes) avant l'échantillonnage d'importance, calculé
    par le scénario que les tests comparent au filtre de Kalman (tests/test_exact_references.py)."""
    text = _text("filtre-particulaire")
    assert not order_problems(text, "exact, sur une grille", "importance")
    assert _sections(text).index("Le filtre bayésien exact, sur une grille") <= 1
    grid = text.split("## Le filtre bayésien exact, sur une grille", 1)[1].split("\n## ", 1)[0]
    assert "kc.scenarios.grid_bayes.growth_grid_posteriors()" in grid and "**deux modes**" in grid


#: Les références françaises (ou de l'école française) que l'issue 18 demande, et le chapitre qui les cite.
FRENCH_REFERENCES = {
    "filtre-particulaire": ("leglandcours", "chopin2020", "cappe2005"),
    "enkf": ("legland2011", "bocquet2014"),
    "vraisemblance": ("cappe2005",),
    # assimilation de données (issue 33)
    "assimilation-ensemble": ("bocquet2014", "asch2016"),
    "methodes-variationnelles": ("asch2016", "adao"),
}


@pytest.mark.parametrize("chapter, keys", sorted(FRENCH_REFERENCES.items()))
def test_french_references_are_cited_where_they_are_the_reference(chapter, keys):
    bib = (BOOK / "references.bib").read_text()
    cited = set(re.findall(r"\{cite:[pt]\}`([^`]+)`", _text(chapter)))
    cited = {key.split("-", 1)[-1] for group in cited for key in group.split(",")}
    for key in keys:
        assert re.search(rf"^@\w+\{{{key},", bib, re.M), f"{key} absent de references.bib"
        assert key in cited, f"{chapter} ne cite pas {key}"


def test_chapters_cite_the_second_edition_of_sarkka():
    """Särkkä et Svensson (2023, 2ᵉ éd.) remplace l'édition de 2013 dans les chapitres (la page des références
    garde la liste du support, qui cite l'édition de 2013)."""
    for page in TOC:
        if page != "references":
            assert "sarkka2013" not in _text(page), page
    assert any("sarkka2023" in _text(page) for page in CHAPTERS)


# --------------------------------------------------------------------------- annexe des errata


def verified_by_problems(entry: str) -> list[str]:
    """Le champ « Vérifié par » d'une entrée de l'annexe : d'abord ce que la vérification calcule, en mots
    (une phrase, pas un nom de test), puis, pour l'enseignant, le test qui la refait ; ou « rien à calculer »
    (faute de français, notation) et pourquoi."""
    if "Vérifié par\n:" not in entry:
        return ["pas de champ « Vérifié par »"]
    field = entry.split("Vérifié par\n:", 1)[1]
    words, _, teacher = field.partition("*Pour l'enseignant* :")
    plain = re.sub(r"\$[^$]*\$|\{\w+\}`[^`]*`", "x", words)
    problems = []
    if "`test_" in words:
        problems.append("nom de test dans la phrase destinée à l'étudiant")
    if len(re.findall(r"[a-zà-ÿ]{3,}", plain)) < 6:
        problems.append("« Vérifié par » sans phrase en mots")
    if words.strip().startswith("rien à calculer"):
        return problems
    if not re.search(r"`test_\w+`", teacher):
        problems.append("pas de test nommé « Pour l'enseignant »")
    return problems


def test_verified_by_check():
    good = ("Vérifié par\n: le filtre part de zéro et retrouve la tension vraie (chapitre {doc}`tension`).\n\n"
            "  *Pour l'enseignant* : `test_voltage` (`tests/test_lecture_formulas.py`).\n")
    assert verified_by_problems(good) == []
    assert verified_by_problems("Vérifié par\n: rien à calculer : c'est une faute de français.\n") == []
    assert len(verified_by_problems("Vérifié par\n: `test_voltage` (`tests/test_errata.py`).\n")) == 3
    assert len(verified_by_problems(good.split("  *Pour")[0])) == 1
    assert verified_by_problems("Écrit\n: x\n") == ["pas de champ « Vérifié par »"]


def test_errata_entries_say_what_checks_them_in_words_then_name_the_test():
    entries = re.split(r"^\(errata-[\w-]+\)=$", _text("errata"), flags=re.M)[1:]
    assert len(entries) >= 70
    problems = [f"{entry.split(chr(10), 2)[1][:40]} : {p}" for entry in entries for p in verified_by_problems(entry)]
    assert not problems, "\n".join(problems)


# --------------------------------------------------------------------------- relecture (issue 36)

_CELL = re.compile(r"^```\{code-cell\}[^\n]*\n(.*?)^```", re.S | re.M)


def _cells(text: str) -> list[tuple[bool, str]]:
    """Les cellules de code d'une page MyST : ``(cachée, code)`` (``remove-cell`` ou ``remove-input``)."""
    out = []
    for cell in _CELL.findall(text):
        tags = re.search(r"^:tags:\s*\[([^\]]*)\]", cell, re.M)
        hidden = bool(tags and {"remove-cell", "remove-input"} & {t.strip() for t in tags.group(1).split(",")})
        body = re.sub(r"\A---\n.*?\n---\n", "", cell, flags=re.S)
        out.append((hidden, "\n".join(line for line in body.splitlines() if not line.startswith(":tags:"))))
    return out


def hidden_definitions_used_in_visible_cells(text: str) -> list[str]:
    """Les noms qu'une cellule **cachée** définit (fonction, classe, variable ; pas une importation, que la
    page montre dans « Importations du chapitre ») et qu'une cellule **visible** emploie sans les définir :
    l'étudiant qui recopie les cellules visibles obtiendrait une ``NameError``."""
    import ast

    def names(tree, kinds):
        out = set()
        for node in ast.walk(tree):
            if "def" in kinds and isinstance(node, (ast.FunctionDef, ast.ClassDef)):
                out.add(node.name)
            elif "def" in kinds and isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
                out.add(node.id)
            elif "import" in kinds and isinstance(node, (ast.Import, ast.ImportFrom)):
                out |= {(a.asname or a.name).split(".")[0] for a in node.names}
        return out

    hidden_defs, visible_defs, problems = set(), set(), []
    for hidden, code in _cells(text):
        try:
            tree = ast.parse(code)
        except SyntaxError:  # une cellule magique d'IPython : rien à lire
            continue
        if hidden:
            hidden_defs |= names(tree, {"def"}) - names(tree, {"import"})
            continue
        own = names(tree, {"def", "import"})
        loads = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)}
        problems += sorted((loads & hidden_defs) - visible_defs - own - set(problems))
        visible_defs |= own
    return problems


def test_hidden_definition_check():
    hidden = "```{code-cell} ipython3\n:tags: [remove-cell]\nimport numpy as np\n\ndef exact(v):\n    return v\n```\n"
    bad = hidden + "\n```{code-cell} ipython3\nprint(exact(np.ones(2)))\n```\n"
    assert hidden_definitions_used_in_visible_cells(bad) == ["exact"]
    good = hidden + "\n```{code-cell} ipython3\ndef exact(v):\n    return 2 * v\nprint(exact(np.ones(2)))\n```\n"
    assert hidden_definitions_used_in_visible_cells(good) == []


@pytest.mark.parametrize("page", TOC)
def test_visible_cells_run_when_copied(page):
    """td-lissage-em appelait ``exact()``, définie dans une cellule cachée : les cellules visibles n'emploient
    que des noms qu'elles définissent ou que la page importe (bloc « Importations du chapitre »)."""
    problems = hidden_definitions_used_in_visible_cells(_text(page))
    assert not problems, f"{page} : noms définis dans une cellule cachée : {problems}"


@pytest.mark.parametrize("chapter", LESSONS)
def test_the_bridge_names_the_next_page(chapter):
    """« La suite » renvoie à la page qui suit dans la table des matières (enkf sautait « Un seul filtre
    gaussien » et « Quel filtre choisir ? », écrits après lui) : un chapitre inséré met à jour le précédent."""
    keep = _text(chapter).split("## À retenir", 1)[1].split("\n## ", 1)[0]
    bridge = re.search(r"^\*\*La suite\.\*\* (.+)$", keep, re.M)
    cited = re.findall(r"\{doc\}`(?:[^`<]*<)?([\w-]+)>?`", bridge.group(1)) if bridge else []
    following = TOC[TOC.index(chapter) + 1]
    assert following in cited, f"{chapter} : « La suite » ne cite pas {following} (cite {cited})"


def test_the_gaussian_chapter_names_the_chapters_it_builds_on():
    """« Les deux chapitres précédents » (l'EKF et l'UKF) était faux depuis que le filtre particulaire et l'EnKF
    les séparent de « Un seul filtre gaussien » : le chapitre les nomme."""
    text = _text("filtre-gaussien")
    assert "chapitres précédents" not in text
    assert re.search(r"Les chapitres \{doc\}`ekf`\s+et \{doc\}`ukf`", text)


def test_glossary_has_the_notions_of_the_newest_chapters():
    """Les notions des chapitres de pistage, du filtre gaussien, du choix d'un filtre et du filtrage parallèle,
    avec leur nom anglais (chercher « gating » sur le site trouve le glossaire)."""
    rows = {re.sub(r"[*«»]", "", r.split("|")[1]).strip().lower(): r.split("|")[2].lower()
            for r in _text("glossaire").splitlines() if r.startswith("| ") and not r.startswith("| terme")}
    for term, english in (("imm", "interacting multiple model"), ("régime, mode", "mode"),
                          ("fenêtre de validation", "gating"), ("mémoire évanescente", "fading memory"),
                          ("ajustement de covariance", "covariance matching"), ("cohérence", "consistency"),
                          ("filtre gaussien", "gaussian filter"), ("cubature", "cubature"),
                          ("gauss–hermite", "gauss–hermite"), ("iplf", "posterior linearisation"),
                          ("produit préfixe", "prefix"), ("piste", "track")):
        hits = [k for k in rows if k.startswith(term)]
        assert hits and english in rows[hits[0]], term


def test_bibliography_notes_use_the_words_of_the_course():
    """Les notes de ``references.bib`` (imprimées dans les bibliographies) suivent le vocabulaire du cours :
    la note de Durbin et Koopman disait encore « départ diffus exact »."""
    notes = re.findall(r"^\s*note\s*=\s*\{(.*)\},?\s*$", (BOOK / "references.bib").read_text(), re.M)
    assert len(notes) >= 10
    problems = [p for note in notes for p in wording_problems(note)]
    assert not problems, problems


def test_readme_speaks_to_lecturers_on_one_screen_and_contributing_holds_the_machinery():
    """Le README tient sur un écran (ce qu'est le cours, les deux commandes, publier, les TP) ; la CI lance
    la commande de test qu'il donne ; le détail des tests (sessions, caches, CI) est dans CONTRIBUTING.md."""
    readme = (ROOT / "README.md").read_text()
    assert len(readme.splitlines()) <= 50
    sections = re.findall(r"^## (.+)$", readme, re.M)
    assert sections[:3] == ["Les deux commandes", "Publier", "Travaux pratiques"], sections
    commands = re.findall(r"^bash (scripts/\S+)", readme, re.M)
    assert commands == ["scripts/build.sh", "scripts/test.sh"]
    assert "bash scripts/test.sh || status=$?" in (ROOT / ".ci" / "run").read_text()
    assert "bash scripts/lab.sh" in readme and "CONTRIBUTING.md" in readme
    for detail in ("KALMAN_GRID_CACHE", "cache d'exécution", "fmtutil.cnf"):  # la machinerie des tests
        assert detail not in readme, detail
    contributing = (ROOT / "CONTRIBUTING.md").read_text()
    for heading in ("## Écrire un chapitre : ce que vérifient les tests", "## Organisation",
                    "## Publier le livre : boutons de lancement"):
        assert heading in contributing, heading
    assert "KALMAN_GRID_CACHE" in contributing and "`.ci/run`" in contributing


# --------------------------------------------------------------------------- pas d'inverse dans un chapitre (issue 32)

_INVERSE = re.compile(r"\b(?:np|numpy|scipy)\.linalg\.inv\(|\bla\.inv\(")


def inverse_problems(text: str) -> list[str]:
    """Les cellules de code qui forment une inverse (``np.linalg.inv``) : le cours résout (``solve``,
    Cholesky), il n'inverse jamais."""
    return [cell.strip().splitlines()[0] for cell in re.findall(r"```\{code-cell\}[^\n]*\n(.*?)```", text, re.S)
            if _INVERSE.search(cell)]


def test_inverse_check():
    bad = "```{code-cell} ipython3\nK = P @ C.T @ np.linalg.inv(S)\n```\n"
    good = "```{code-cell} ipython3\nK = np.linalg.solve(S, C @ P).T\n```\n"
    assert inverse_problems(bad) and not inverse_problems(good)


@pytest.mark.parametrize("page", TOC)
def test_no_chapter_forms_an_inverse(page):
    assert not inverse_problems(_text(page)), f"{page} : {inverse_problems(_text(page))}"
