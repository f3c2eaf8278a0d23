"""Compile le LaTeX de Jupyter Book en un seul PDF (XeLaTeX, latexmk) et refuse un PDF douteux.

Appelé par ``scripts/build.sh --pdf`` après ``jupyter-book build . --builder latex`` ; les tests
(``tests/test_pdf.py``) appellent :func:`compile_pdf`. Échoue (code 1, message en français) sur une
erreur LaTeX, une référence ou une citation non résolue (« ?? » dans le PDF) ou un caractère absent
de la police (glyphe manquant, donc texte amputé).

Usage : ``python scripts/pdf.py DOSSIER_LATEX PDF_DE_SORTIE``.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

#: Nom du document LaTeX (``latex_documents: targetname:`` de _config.yml), sans extension.
TARGET = "filtre-de-kalman"

#: Lignes du journal LaTeX qui rendent le PDF faux ou incomplet.
PROBLEMS = re.compile(
    r"^(!.*"
    r"|.*LaTeX Warning: (Reference|Citation|Hyper reference) .* undefined.*"
    r"|.*There were undefined references.*"
    r"|Missing character: There is no .*)$",
    re.M,
)


class PdfError(RuntimeError):
    """La compilation LaTeX a échoué ou a laissé un problème (message en français)."""


def compile_pdf(latex_dir: Path, output: Path | None = None) -> tuple[Path, float]:
    """Compile ``latex_dir/filtre-de-kalman.tex`` (latexmk, XeLaTeX, autant de passes qu'il faut).

    Renvoie le chemin du PDF (copié vers ``output`` s'il est donné) et la durée de la compilation (s).
    Lève :class:`PdfError` si latexmk échoue ou si le journal signale un problème (:data:`PROBLEMS`).
    """
    latex_dir = Path(latex_dir)
    tex = latex_dir / f"{TARGET}.tex"
    if not tex.is_file():
        raise PdfError(f"{tex} absent : lancez d'abord « jupyter-book build . --builder latex ».")
    for tool in ("latexmk", "xelatex"):
        if shutil.which(tool) is None:
            raise PdfError(f"« {tool} » introuvable : installez TeX Live avec « bash scripts/setup.sh --pdf ».")
    start = time.perf_counter()
    # latexmkrc écrit par Sphinx (dans latex_dir) : XeLaTeX et ses options ; -pdfxe le confirme.
    # xdvipdfmx compresse les images du PDF au niveau 6 de zlib (celui de zlib par défaut) au lieu de 9 :
    # 7 s de calcul au lieu de 18 pour les 94 figures (PNG avec transparence, recompressées), un PDF plus
    # gros de 3 % ; la compression reste sans perte.
    proc = subprocess.run(
        ["latexmk", "-pdfxe", "-dvi-", "-ps-", "-interaction=nonstopmode", "-halt-on-error", "-file-line-error",
         "-e", "$xdvipdfmx = q/xdvipdfmx -z 6 -E -o %D %O %S/", f"{TARGET}.tex"],
        cwd=latex_dir, capture_output=True, text=True, errors="replace", stdin=subprocess.DEVNULL,
    )
    elapsed = time.perf_counter() - start
    log_file = latex_dir / f"{TARGET}.log"
    log = log_file.read_text(errors="replace") if log_file.is_file() else ""
    pdf = latex_dir / f"{TARGET}.pdf"
    if proc.returncode != 0 or not pdf.is_file():
        tail = "\n".join((proc.stdout + proc.stderr).splitlines()[-40:])
        raise PdfError(f"latexmk a échoué (code {proc.returncode}) ; journal complet : {log_file}\n{tail}")
    problems = sorted(set(m.group(0).strip() for m in PROBLEMS.finditer(log)))
    if problems:
        raise PdfError(f"PDF incomplet ({len(problems)} problème(s), journal : {log_file}) :\n" + "\n".join(problems[:40]))
    if output is not None:
        output = Path(output)
        output.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(pdf, output)
        pdf = output
    return pdf, elapsed


def main(argv: list[str]) -> int:
    if len(argv) != 2:
        print("utilisation : python scripts/pdf.py DOSSIER_LATEX PDF_DE_SORTIE", file=sys.stderr)
        return 2
    try:
        pdf, elapsed = compile_pdf(Path(argv[0]), Path(argv[1]))
    except PdfError as exc:
        print(f"[pdf] ERREUR : {exc}", file=sys.stderr)
        return 1
    print(f"[pdf] compilation XeLaTeX : {elapsed:.0f} s → {pdf}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
