r"""Les carnets de l'étudiant, tirés des pages « Travaux pratiques » du livre.

Une page de TP (``book/tp-*.md``, carnet MyST) contient, pour chaque fonction à écrire, une cellule
« squelette » (``# À vous``, ``raise NotImplementedError``) puis la solution dans un bloc
``{solution-start}`` … ``{solution-end}`` : la construction du livre exécute la page avec la solution
(un TP ne peut pas pourrir), le site la montre repliée. :func:`student_notebook` en tire le carnet de
l'étudiant : les squelettes sans les solutions, les vérifications ``practice.check`` sans sorties, la
figure finale, et le texte en Markdown simple (JupyterLab ne lit pas les directives MyST).

Les carnets sont écrits dans ``book/travaux-pratiques/`` (le site les sert dans son dossier
``travaux-pratiques/``, avec le paquet en roue) par ``python -m kalman_course.practice --notebooks
book/travaux-pratiques`` ; un test vérifie qu'ils suivent les pages. Ils sont nommés d'après le numéro du TP
(:func:`notebook_name` : ``tp1-filtre-lineaire.ipynb`` … ``tp5-helicoptere-samu.ipynb``), pour se ranger dans
l'ordre du cours. Le texte propre au site (l'encadré « Comment travailler », les solutions repliées) n'y est
pas : la première cellule dit comment travailler dans le carnet et quoi faire si ``import kalman_course``
échoue ; le quiz y est, réponses repliées. Écriture déterministe (mêmes octets d'une fois sur l'autre).
"""

from __future__ import annotations

import re
from pathlib import Path

__all__ = ["student_notebook", "write_student_notebooks", "lab_pages", "notebook_name", "NOTEBOOK_DIR",
           "WHEEL_FOLDER"]

#: Dossier des carnets de l'étudiant, relatif à la racine du dépôt.
NOTEBOOK_DIR = Path("book") / "travaux-pratiques"

_ROLE = re.compile(r"\{(?P<role>[\w:-]+)\}`(?P<body>[^`]*)`")
_COLON_OPEN = re.compile(r"^(?P<fence>:{3,})\{(?P<name>[\w-]+)\}[ \t]*(?P<title>.*)$")


#: Dossier du site où sont servis les carnets à compléter, la roue du paquet et ses contraintes de versions.
WHEEL_FOLDER = "travaux-pratiques"


def _number(page: Path) -> int:
    m = re.search(r"(?m)^# TP (\d+) ", Path(page).read_text(encoding="utf-8"))
    if not m:
        raise ValueError(f"{page} : le titre ne commence pas par « TP n — »")
    return int(m.group(1))


def lab_pages(book: Path) -> list[Path]:
    """Les pages de TP du livre (``book/tp-*.md``), dans l'ordre de leur numéro (« # TP 1 — … »)."""
    return sorted(Path(book).glob("tp-*.md"), key=_number)


def notebook_name(page: Path) -> str:
    """Le nom du carnet de l'étudiant d'une page de TP : ``tp-filtre-lineaire.md`` (« TP 1 — … ») →
    ``tp1-filtre-lineaire.ipynb`` ; les carnets se rangent ainsi dans l'ordre du cours."""
    page = Path(page)
    return f"tp{_number(page)}-{page.stem.removeprefix('tp-')}.ipynb"


def _title(book: Path, name: str) -> str:
    path = Path(book) / f"{name}.md"
    if path.is_file():
        m = re.search(r"(?m)^# (.+)$", path.read_text(encoding="utf-8"))
        if m:
            return m.group(1).strip()
    return name


def _roles(text: str, book: Path) -> str:
    def replace(m: re.Match) -> str:
        role, body = m.group("role"), m.group("body")
        label = re.match(r"(.*?)\s*<([^>]*)>$", body)
        if role == "doc":
            return f"« {label.group(1) if label else _title(book, body)} »"
        if role in ("download", "ref", "numref"):
            return label.group(1) if label else body
        if role.startswith("cite"):
            return ""
        if role == "kc-source":
            return f"`{body}`"
        return body

    return _ROLE.sub(replace, text)


def _quote(title: str, body: list[str]) -> list[str]:
    lines = [f"> **{title}**" if title else ">"]
    if body:
        lines.append(">")
        lines += [f"> {line}".rstrip() for line in body]
    return lines


#: Directives propres au site, absentes du carnet (le carnet a sa propre première cellule).
_SITE_ONLY = {"comment-travailler"}


def _quiz_markdown(body: list[str]) -> list[str]:
    """Le quiz d'une page en Markdown : chaque question, ses réponses numérotées, puis, dans un bloc
    ``<details>`` replié (JupyterLab l'affiche comme sur le site), la bonne réponse et son explication, et ce
    qu'a de faux chaque autre réponse (même lecture que la directive du livre : :func:`~kalman_course.quizzes.quiz_questions`)."""
    from ..quizzes import quiz_questions

    out = ["**Quiz** (la réponse de chaque question est repliée sous elle : cherchez d'abord !)"]
    for number, q in enumerate(quiz_questions("\n".join(body)), 1):
        letter = [chr(ord("a") + i) for i in range(len(q.choices))]
        out += ["", f"{number}. {q.statement}", ""]
        out += [f"   - **{letter[i]}.** {choice}" for i, choice in enumerate(q.choices)]
        out += ["", "   <details><summary>Réponse</summary>", "",
                f"   **{letter[q.answer - 1]}.** {q.choices[q.answer - 1]} — {q.explanation}"]
        out += [f"   - {letter[i]}. {message}" for i, message in enumerate(q.messages)
                if message and i != q.answer - 1]
        out += ["", "   </details>"]
    return out


def _plain_markdown(text: str, book: Path) -> str:
    """Directives MyST → Markdown simple : encadrés et exercices en citations, quiz retirés."""
    out: list[str] = []
    lines = text.split("\n")
    i = 0
    while i < len(lines):
        line = lines[i]
        opened = _COLON_OPEN.match(line)
        fenced = re.match(r"^(?P<fence>`{3,})\{(?P<name>[\w-]+)\}[ \t]*(?P<title>.*)$", line)
        if opened or fenced:
            m = opened or fenced
            fence, name, title = m.group("fence"), m.group("name"), m.group("title").strip()
            j = i + 1
            depth = 1
            body = []
            while j < len(lines):
                if re.match(rf"^{re.escape(fence)}\s*$", lines[j]):
                    depth -= 1
                    if depth == 0:
                        break
                elif re.match(rf"^{re.escape(fence)}\{{", lines[j]):
                    depth += 1
                body.append(lines[j])
                j += 1
            raw = body
            body = [b for b in body if not re.match(r"^:[\w-]+:", b)]
            while body and not body[0].strip():
                body.pop(0)
            if name == "quiz":
                out += _quiz_markdown(raw)
            elif name in _SITE_ONLY:
                pass
            else:
                heading = {"exercise": "Exercice", "note": "Remarque", "tip": "Conseil",
                           "warning": "Attention"}.get(name, title)
                if name == "admonition":
                    heading = title
                inner = _plain_markdown("\n".join(body), book).split("\n")
                out += _quote(heading, inner)
            i = j + 1
            continue
        out.append(line)
        i += 1
    return _roles("\n".join(out), book)


def _header(title: str) -> str:
    """La première cellule du carnet : d'où il vient, comment y travailler, et quoi faire si
    ``import kalman_course`` échoue."""
    from . import wheel_name

    return (
        f"*Carnet à compléter, tiré de la page « {title} » du cours « Filtre de Kalman » : les solutions n'y "
        "sont pas.*\n\n"
        "**Comment travailler.** Exécutez les cellules dans l'ordre (Maj + Entrée). Pour chaque fonction, "
        "remplacez `raise NotImplementedError` par votre code (`# À vous`), exécutez la cellule, puis la cellule "
        "`practice.check(...)` qui la suit : le correcteur essaie votre fonction sur des cas cachés et répond en "
        "français, dans un encadré vert ou rouge. La figure de la fin fait tourner vos fonctions.\n\n"
        "**Si la cellule `import kalman_course` échoue** (`ModuleNotFoundError: No module named "
        "'kalman_course'`), le noyau de ce carnet ne voit pas le paquet du cours :\n\n"
        "1. fermez JupyterLab, activez l'environnement virtuel où vous avez installé le paquet "
        "(`source tp-kalman/bin/activate` ; sous Windows `tp-kalman\\Scripts\\activate`), puis relancez "
        "`jupyter lab` depuis ce terminal ;\n"
        "2. ou installez le paquet dans le noyau de ce carnet : une cellule `%pip install "
        f"ADRESSE-DU-COURS/{WHEEL_FOLDER}/{wheel_name()}`, où `ADRESSE-DU-COURS` est l'adresse du site du "
        "cours (l'encadré « Comment travailler » de la page du TP donne la commande complète), puis "
        "*Noyau › Redémarrer le noyau* ;\n"
        "3. depuis une copie du dépôt du cours : `bash scripts/lab.sh` installe ce qu'il faut et ouvre ces "
        "carnets."
    )


def student_notebook(page: Path, book: Path | None = None):
    """Le carnet de l'étudiant (``nbformat.NotebookNode``) tiré de la page de TP ``page``."""
    import nbformat
    from myst_nb.core.read import read_myst_markdown_notebook

    page = Path(page)
    book = page.parent if book is None else Path(book)
    source = read_myst_markdown_notebook(page.read_text(encoding="utf-8"), path=str(page))
    cells = []
    in_solution = False
    header = nbformat.v4.new_markdown_cell(_header(_title(book, page.stem)))
    cells.append(header)
    for cell in source.cells:
        if cell.cell_type == "markdown":
            text = cell.source
            kept = []
            while text:
                if in_solution:
                    end = re.search(r"```\{solution-end\}[^\n]*\n```[ \t]*\n?", text)
                    if not end:
                        text = ""
                        break
                    text = text[end.end():]
                    in_solution = False
                else:
                    start = re.search(r"```\{solution-start\}", text)
                    if not start:
                        kept.append(text)
                        break
                    kept.append(text[:start.start()])
                    text = text[start.start():]
                    in_solution = True
            markdown = _plain_markdown("".join(kept), book).strip()
            markdown = re.sub(r"\n{3,}", "\n\n", markdown)
            if markdown:
                cells.append(nbformat.v4.new_markdown_cell(markdown))
        elif cell.cell_type == "code" and not in_solution:
            cells.append(nbformat.v4.new_code_cell(cell.source.strip("\n")))
    for k, cell in enumerate(cells):
        cell["id"] = f"{page.stem}-{k:02d}"
    nb = nbformat.v4.new_notebook(cells=cells)
    nb.metadata["kernelspec"] = {"display_name": "Python 3", "language": "python", "name": "python3"}
    nb.metadata["language_info"] = {"name": "python"}
    return nb


def write_student_notebooks(book: Path, out: Path) -> list[Path]:
    """Écrit le carnet de l'étudiant de chaque page de TP de ``book`` dans ``out`` ; renvoie les chemins."""
    import nbformat

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for stale in out.glob("tp-*.ipynb"):  # les anciens noms, qui ne se rangeaient pas dans l'ordre des TP
        stale.unlink()
    for page in lab_pages(book):
        path = out / notebook_name(page)
        text = nbformat.writes(student_notebook(page, book)) + "\n"
        path.write_text(text, encoding="utf-8")
        written.append(path)
    return written
