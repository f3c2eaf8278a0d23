"""Copie dans book/vendor/ les ressources web que le site sert lui-même (aucun CDN à l'ouverture).

book/vendor/ est listé dans html_static_path (copié sous _static/ du site) et exclu des sources ;
ce n'est pas un dossier « _static » à la racine, que Jupyter Book injecterait dans chaque page.

- MathJax 3 (ses polices) : depuis node_modules/mathjax (npm) ;
- BokehJS (noyau + curseurs) : depuis le paquet Python bokeh installé, donc exactement à la version
  qui produit les figures ; fichiers nommés avec la version (bokeh/bokeh-3.9.2.min.js…). L'extension
  kalman_course.sphinx.sliders vérifie à chaque construction qu'ils sont à jour et ne les
  ajoute qu'aux pages qui contiennent une figure à curseurs.
"""

from __future__ import annotations

import shutil
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
VENDOR = ROOT / "book" / "vendor"
MATHJAX = ROOT / "node_modules" / "mathjax" / "es5"

# Ce que le site sert de MathJax 3 : ses polices CHTML (0,3 Mo). Les formules sont composées à la
# construction, dans node, depuis node_modules/mathjax (kalman_course.sphinx.formulas) : aucune page ne
# charge les scripts de MathJax.
MATHJAX_PARTS = ["output/chtml/fonts/woff-v2"]


def copy_tree(src: Path, dst: Path) -> None:
    if src.is_dir():
        shutil.copytree(src, dst, dirs_exist_ok=True)
    else:
        dst.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(src, dst)


def copy_bokehjs() -> None:
    """Copie BokehJS du paquet bokeh installé dans book/vendor/bokeh/ (anciennes versions retirées)."""
    from kalman_course.interactive.static import installed_bokehjs

    files = installed_bokehjs()
    target_dir = VENDOR / "bokeh"
    target_dir.mkdir(parents=True, exist_ok=True)
    wanted = {Path(served).name for served in files}
    for old in target_dir.glob("bokeh*.js"):
        if old.name not in wanted:
            old.unlink()
    for served, source in files.items():
        target = VENDOR / served
        if not target.is_file() or target.read_bytes() != source.read_bytes():
            shutil.copy2(source, target)


def main() -> None:
    if not MATHJAX.is_dir():
        raise SystemExit("node_modules/mathjax absent : lancez d'abord « npm ci » (scripts/setup.sh le fait).")
    for part in MATHJAX_PARTS:
        copy_tree(MATHJAX / part, VENDOR / "mathjax" / part)
    copy_bokehjs()


if __name__ == "__main__":
    main()
