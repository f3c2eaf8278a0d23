"""La structure pédagogique de chaque page du livre (sans construction) : objectifs et prérequis en tête,
« À retenir » à la fin, un quiz de 3 à 5 questions, une figure à curseurs avec son encadré « À observer »
et ses curseurs interactifs montrés en code ; et les réponses chiffrées des quiz recalculées par le paquet."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import yaml

import kalman_course as kc
import kalman_course.interactive as ki

ROOT = Path(__file__).resolve().parent.parent
BOOK = ROOT / "book"


#: Annexes du livre (ni objectifs, ni figure à curseurs, ni quiz).
APPENDICES = {"references", "errata", "glossaire"}
#: Travaux dirigés (papier et crayon) et travaux pratiques (l'étudiant écrit le code, le correcteur
#: répond) : pas de figure à curseurs — l'interactivité d'un TD est le calcul à la main, celle d'un TP le
#: code de l'étudiant et le verdict de practice.check. Objectifs, « À retenir » et quiz restent exigés.
PRACTICE_PAGES = {p.stem for p in (Path(__file__).resolve().parent.parent / "book").glob("t[dp]-*.md")} | {
    "sujet-examen"}  # le sujet d'examen : une page d'exercices, comme un TD


def _pages() -> list[str]:
    toc = yaml.safe_load((ROOT / "_toc.yml").read_text())
    files = [toc["root"]] + [c["file"] for part in toc["parts"] for c in part["chapters"]]
    return [Path(f).name for f in files if Path(f).name not in APPENDICES]


PAGES = _pages()


def _text(page: str) -> str:
    return (BOOK / f"{page}.md").read_text()


def _h2(text: str) -> list[str]:
    return re.findall(r"^## (.+?)\s*$", text, re.M)


def quiz_questions(text: str) -> list[dict]:
    """Les questions du quiz d'une page : énoncé, réponses proposées, numéro de la bonne, nom, explication
    (la lecture de :func:`kalman_course.sphinx.quiz.quiz_questions`, celle de la directive)."""
    from kalman_course.sphinx.quiz import quiz_questions as read

    return [{"answer": q.answer, "name": q.name, "statement": q.statement, "choices": q.choices,
             "why": q.explanation, "messages": q.messages} for q in read(text)]


def french_number(text: str) -> float:
    """Le nombre écrit à la française au début d'un texte : « 0,990 » → 0.99."""
    m = re.search(r"−?\d+(?:[ \u202f]\d{3})*(?:,\d+)?", text)
    assert m, f"aucun nombre dans « {text} »"
    return float(m.group(0).replace("−", "-").replace(" ", "").replace("\u202f", "").replace(",", "."))


# --------------------------------------------------------------------------- structure


@pytest.mark.parametrize("page", PAGES)
def test_page_opens_with_objectives_and_prerequisites(page):
    text = _text(page)
    head = text[: text.index("\n## ")] if "\n## " in text else text
    assert ":::{admonition} Objectifs" in head, f"{page} : pas d'encadré « Objectifs » avant la première section"
    # les prérequis : un encadré, ou un paragraphe « **Prérequis** » dans celui des objectifs
    assert ":::{admonition} Prérequis" in head or "**Prérequis**" in head, f"{page} : pas de prérequis en tête"
    objectives = re.search(r":::\{admonition\} Objectifs\n:class: \w+\n(.*?)\n:::", head, re.S).group(1)
    assert 2 <= len(re.findall(r"^- ", objectives, re.M)) <= 6, f"{page} : deux à six objectifs"


@pytest.mark.parametrize("page", PAGES)
def test_page_closes_with_what_to_remember(page):
    text = _text(page)
    sections = [h for h in _h2(text) if h != "Bibliographie"]
    box = re.search(r"^:::\{admonition\} À retenir\n:class: \w+\n(.*?)\n:::\s*$", text, re.M | re.S)
    if box and text.rstrip().endswith(":::"):  # un encadré « À retenir » qui ferme la page
        body = box.group(1)
    else:
        assert sections[-1] == "À retenir", f"{page} : la dernière section est « {sections[-1]} »"
        body = text.split("## À retenir", 1)[1].split("\n## ", 1)[0]
    assert 2 <= len(re.findall(r"^- ", body, re.M)) <= 7, f"{page} : « À retenir » court (2 à 7 points)"


@pytest.mark.parametrize("page", PAGES)
def test_page_has_a_quiz_of_three_to_five_well_formed_questions(page):
    questions = quiz_questions(_text(page))
    assert 3 <= len(questions) <= 5, f"{page} : {len(questions)} question(s)"
    for q in questions:
        assert q["statement"] and len(q["choices"]) >= 2
        assert 1 <= q["answer"] <= len(q["choices"])
        assert len(set(q["choices"])) == len(q["choices"]), f"{page} : réponses en double"
        assert q["why"], f"{page} : question sans explication ({q['statement'][:40]})"
    # la bonne réponse n'est pas toujours à la même place
    assert len({q["answer"] for q in questions}) >= 2, f"{page} : la bonne réponse est toujours la n° {questions[0]['answer']}"


_LEGACY = {"voltage": "tension-curseurs", "tag": "tag-curseurs", "nile": "nil-curseurs",
           "particle": "filtre-particulaire-curseurs", "banana_uncertainty": "ukf-banane-incertitude",
           "banana_parameter": "ukf-banane-parametres"}
_SHOWN = re.compile(r'kc\.interactive\.(?:sliders\("([^"]+)"\)|(' + "|".join(_LEGACY) + r')_sliders\(\))')
#: Curseurs interactifs des figures d'avant le registre, sous leur propre nom.
_LIVE = {"tension-curseurs": "live_voltage_explorer()", "tag-curseurs": "live_tag_explorer()",
         "nil-curseurs": "live_nile_explorer()"}


@pytest.mark.parametrize("page", [p for p in PAGES if p not in PRACTICE_PAGES])
def test_page_shows_its_slider_figures_each_with_an_observation_box_and_live_code(page):
    text = _text(page)
    cells = re.findall(r"```\{code-cell\}[^\n]*\n(.*?)```", text, re.S)
    shown = [m[0] or _LEGACY[m[1]] for cell in cells for m in _SHOWN.findall(cell)]
    assert shown, f"{page} : aucune figure à curseurs"
    assert sorted(shown) == sorted(ki.slider_names(page)), f"{page} : figures du registre non montrées"
    for name in shown:
        legacy = {v: f"{k}_sliders()" for k, v in _LEGACY.items()}
        call = next(c for c in (f'sliders("{name}")', legacy.get(name, "\0")) if c in text)
        after = text[text.index(call):]
        box = re.search(r"(:{3,4})\{admonition\} À observer\n:class: \w+\n(.*?)\n\1\n", after, re.S)
        assert box and after.index(box.group(0)) < 400, f"{page} : pas d'encadré « À observer » après {name}"
        outside = re.sub(r"(```|:::)\{dropdown\}.*?\n\s*\1|:::\{admonition\}[^\n]*\n:class: dropdown.*?\n:::",
                         "", box.group(2), flags=re.S)  # les essais, hors des explications
        items = re.findall(r"^(?:\d\.|-) ", outside, re.M)
        explained = re.findall(r"\{dropdown\}|:class: dropdown", box.group(2))
        assert 2 <= len(items) <= 4 and explained, f"{page} : {name}, deux à quatre essais, expliqués en dépliant"
        # les curseurs interactifs (Jupyter) sont montrés en code à recopier, jamais exécutés dans le livre
        live = _LIVE.get(name, f'live_explorer("{name}")')
        blocks = re.findall(r"```python\n(.*?)```", text, re.S)
        assert any(live in b for b in blocks), f"{page} : curseurs interactifs de {name} non montrés"


def test_intuition_is_the_first_chapter_and_marked_as_an_addition():
    assert PAGES[:3] == ["intro", "intuition", "controle-systeme"]
    head = _text("intuition").split("\n## ", 1)[0]
    assert ":::{admonition} Un ajout au cours" in head


# --------------------------------------------------------------------------- réponses chiffrées


def _named(name: str) -> dict:
    for page in PAGES:
        for q in quiz_questions(_text(page)):
            if q["name"] == name:
                return q
    raise AssertionError(f"question « {name} » introuvable")


def _right(q: dict) -> str:
    return q["choices"][q["answer"] - 1]


def test_quiz_intuition_gain_is_the_package_correction():
    q = _named("intuition-gain")
    step = kc.update(kc.LinearGaussianModel(A=1.0, C=1.0, Q=0.0, R=1.0), [10.0], [[4.0]], [13.0])
    assert french_number(_right(q)) == pytest.approx(step.K[0, 0], rel=1e-12)
    others = [french_number(c) for i, c in enumerate(q["choices"]) if i != q["answer"] - 1]
    assert all(abs(o - step.K[0, 0]) > 0.05 for o in others)


def test_quiz_intuition_posterior_variance_is_smaller_than_both():
    q = _named("intuition-variance")
    rng = np.random.default_rng(1)
    for P, R in rng.uniform(0.01, 100, (50, 2)):
        step = kc.update(kc.LinearGaussianModel(A=1.0, C=1.0, Q=0.0, R=R), [0.0], [[P]], [1.0])
        assert step.P[0, 0] < min(P, R)
    assert "plus petite que les deux" in _right(q)


def test_quiz_estimator_radius_is_the_package_spectral_radius():
    q = _named("estimateur-rayon")
    model = kc.LinearGaussianModel(A=2.0, C=1.0, Q=0.01, R=0.01)
    rho = kc.spectral_radius(kc.error_transition(model, [[0.4]]))
    assert french_number(_right(q)) == pytest.approx(rho, rel=1e-12)
    printed = kc.errata.printed_stability_radius(model, [[0.4]])
    assert french_number(q["choices"][0]) == pytest.approx(printed)  # le piège : la condition imprimée


def test_quiz_optimal_gain_scalar_case():
    q = _named("gain-optimal-scalaire")
    model = kc.LinearGaussianModel(A=1.0, C=1.0, Q=0.0, R=0.5)
    step = kc.update(model, [0.0], [[0.5]], [0.0])
    P_star = kc.covariance_for_gain(model, [[0.5]], step.K)[0, 0]
    numbers = [float(v.replace("{,}", ".")) for v in re.findall(r"= (\d+(?:\{,\}\d+)?)", _right(q))]
    assert numbers == pytest.approx([step.K[0, 0], P_star], rel=1e-12)


def test_quiz_first_voltage_gain_is_the_package_gain():
    q = _named("tension-K1")
    z = kc.scenarios.constant_voltage_measurements(50)
    K1 = kc.kalman_filter(kc.scenarios.constant_voltage_model(Q=1e-5, R=0.01), z, x0=0.0, P0=1.0).K[0, 0, 0]
    assert french_number(_right(q)) == pytest.approx(K1, abs=5e-4)


def test_quiz_nis_degrees_of_freedom_per_step():
    q = _named("tests-nis-ddl")
    model = kc.scenarios.engine.engine_model()
    u = kc.scenarios.engine.engine_commands(50)
    sim = kc.simulate(model, np.zeros(2), 50, u, rng=0)
    res = kc.kalman_filter(model, sim.y, np.zeros(2), np.eye(2), u)
    assert kc.nis_test(res).dof / 50 == french_number(_right(q))
