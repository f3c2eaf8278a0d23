"""Copie dans book/vendor/ les ressources web que le site sert lui-même (aucun CDN à l'ouverture).

book/vendor/ est listé dans html_static_path (copié sous _static/ du site) et exclu des sources ;
ce n'est pas un dossier « _static » à la racine, que Jupyter Book injecterait dans chaque page.
"""

from __future__ import annotations

import shutil
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
VENDOR = ROOT / "book" / "vendor"
MATHJAX = ROOT / "node_modules" / "mathjax" / "es5"

# Sous-ensemble de MathJax 3 utile au site (24 Mo → ~3 Mo) : composant TeX + CommonHTML, polices,
# extensions TeX chargées à la demande (autoload), menu contextuel et accessibilité.
MATHJAX_PARTS = ["tex-chtml.js", "output/chtml/fonts/woff-v2", "input/tex/extensions", "ui", "a11y", "adaptors"]


def copy_tree(src: Path, dst: Path) -> None:
    if src.is_dir():
        shutil.copytree(src, dst, dirs_exist_ok=True)
    else:
        dst.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(src, dst)


def main() -> None:
    if not MATHJAX.is_dir():
        raise SystemExit("node_modules/mathjax absent : lancez d'abord « npm ci » (scripts/setup.sh le fait).")
    for part in MATHJAX_PARTS:
        copy_tree(MATHJAX / part, VENDOR / "mathjax" / part)


if __name__ == "__main__":
    main()
