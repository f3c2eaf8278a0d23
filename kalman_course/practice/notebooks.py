r"""Les carnets de l'étudiant, tirés des pages « Travaux pratiques » du livre.

Une page de TP (``book/tp-*.md``, carnet MyST) contient, pour chaque fonction à écrire, une cellule
« squelette » (``# À vous``, ``raise NotImplementedError``) puis la solution dans un bloc
``{solution-start}`` … ``{solution-end}`` : la construction du livre exécute la page avec la solution
(un TP ne peut pas pourrir), le site la montre repliée. :func:`student_notebook` en tire le carnet de
l'étudiant : les squelettes sans les solutions, les vérifications ``practice.check`` sans sorties, la
figure finale, et le texte en Markdown simple (JupyterLab ne lit pas les directives MyST).

Les carnets sont écrits dans ``book/travaux-pratiques/`` (téléchargeables depuis chaque page) par
``python -m kalman_course.practice --notebooks book/travaux-pratiques`` ; un test vérifie qu'ils suivent
les pages. Écriture déterministe (mêmes octets d'une fois sur l'autre).
"""

from __future__ import annotations

import re
from pathlib import Path

__all__ = ["student_notebook", "write_student_notebooks", "lab_pages", "NOTEBOOK_DIR"]

#: Dossier des carnets de l'étudiant, relatif à la racine du dépôt.
NOTEBOOK_DIR = Path("book") / "travaux-pratiques"

_ROLE = re.compile(r"\{(?P<role>[\w:-]+)\}`(?P<body>[^`]*)`")
_COLON_OPEN = re.compile(r"^(?P<fence>:{3,})\{(?P<name>[\w-]+)\}[ \t]*(?P<title>.*)$")


def lab_pages(book: Path) -> list[Path]:
    """Les pages de TP du livre (``book/tp-*.md``), dans l'ordre des noms."""
    return sorted(Path(book).glob("tp-*.md"))


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
            body = [b for b in body if not re.match(r"^:[\w-]+:", b)]
            while body and not body[0].strip():
                body.pop(0)
            if name == "quiz":
                out.append("*(Le quiz de cette séance est sur la page du cours.)*")
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


def student_notebook(page: Path, book: Path | None = None):
    """Le carnet de l'étudiant (``nbformat.NotebookNode``) tiré de la page de TP ``page``."""
    import nbformat
    from myst_nb.core.read import read_myst_markdown_notebook

    page = Path(page)
    book = page.parent if book is None else Path(book)
    source = read_myst_markdown_notebook(page.read_text(encoding="utf-8"), path=str(page))
    cells = []
    in_solution = False
    header = nbformat.v4.new_markdown_cell(
        f"*Carnet de travail tiré de la page « {_title(book, page.stem)} » du cours (`book/{page.name}`) : "
        "les solutions n'y sont pas. Complétez chaque `# À vous`, exécutez la cellule, puis celle de "
        "`practice.check` juste après.*"
    )
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
    for page in lab_pages(book):
        path = out / f"{page.stem}.ipynb"
        text = nbformat.writes(student_notebook(page, book)) + "\n"
        path.write_text(text, encoding="utf-8")
        written.append(path)
    return written
