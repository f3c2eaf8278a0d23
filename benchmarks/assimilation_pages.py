"""Temps CPU des carnets de la partie « Assimilation de données » (chapitres, TD, TP), sans noyau Jupyter.

Usage : .venv/bin/python benchmarks/assimilation_pages.py

Chaque page est exécutée dans un processus neuf, comme son carnet : ses cellules de code, dans l'ordre, la
dernière expression de chaque cellule rendue comme Jupyter la rend (PNG d'une figure, HTML d'un tableau ou
d'une figure à curseurs). Deux passages : grilles des figures à curseurs à calculer (un dossier
``KALMAN_GRID_CACHE`` neuf, comme le premier processus d'un lancement des tests), puis grilles déjà
calculées (le même dossier : ce que paient les carnets quand la session du paquet, ou un autre carnet, les
a calculées). Imprime le temps CPU de chaque page (import du paquet compris) et celui des grilles.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PAGES = ("assimilation-ensemble", "methodes-variationnelles", "td-assimilation", "tp-assimilation")

RUNNER = r"""
import ast, re, sys, time
t0 = time.process_time()
text = open(sys.argv[1]).read()
namespace = {}
for cell in re.findall(r"```\{code-cell\}[^\n]*\n(.*?)```", text, re.S):
    body = re.sub(r"\A---\n.*?\n---\n", "", cell, flags=re.S)
    body = re.sub(r"\A(:[\w-]+:.*\n)+", "", body)
    tree = ast.parse(body)
    last = tree.body.pop() if tree.body and isinstance(tree.body[-1], ast.Expr) else None
    exec(compile(tree, "<cellule>", "exec"), namespace)
    if last is not None:
        value = eval(compile(ast.Expression(last.value), "<cellule>", "eval"), namespace)
        for method in ("_repr_png_", "_repr_html_"):
            if hasattr(value, method):
                getattr(value, method)()
                break
print(time.process_time() - t0)
"""


def run_page(page: str, cache: str) -> float:
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", KALMAN_GRID_CACHE=cache, MPLBACKEND="Agg")
    out = subprocess.run([sys.executable, "-c", RUNNER, str(ROOT / "book" / f"{page}.md")], env=env,
                         capture_output=True, text=True, check=True, cwd=ROOT / "book")
    return float(out.stdout.strip().splitlines()[-1])


def main() -> None:
    from kalman_course.numbers import format_spec

    with tempfile.TemporaryDirectory() as cache:
        cold = {page: run_page(page, cache) for page in PAGES}
        warm = {page: run_page(page, cache) for page in PAGES}
    print(f"{'page':28s} {'grilles à calculer (s)':>23s} {'grilles déjà calculées (s)':>27s}")
    for page in PAGES:
        print(f"{page:28s} {format_spec(cold[page], '.2f'):>23s} {format_spec(warm[page], '.2f'):>27s}")
    print(f"{'total':28s} {format_spec(sum(cold.values()), '.2f'):>23s} {format_spec(sum(warm.values()), '.2f'):>27s}")
    print(f"grilles des figures à curseurs : {format_spec(sum(cold.values()) - sum(warm.values()), '.2f')} s de calcul")


if __name__ == "__main__":
    main()
