#!/usr/bin/env bash
# Construit le site dans _build/html (installe d'abord ce qu'il faut : voir scripts/setup.sh).
# Avec --pdf : construit aussi le cours en un seul PDF, _build/pdf/filtre-de-kalman.pdf (LaTeX de
# Jupyter Book, XeLaTeX, césure française) ; setup.sh installe alors TeX Live (paquets Debian).
# Toutes les pages sont réécrites (--all) ; les carnets inchangés viennent du cache d'exécution, les
# autres sont d'abord exécutés en parallèle (scripts/execute_notebooks.py).
# La construction échoue sur toute erreur de cellule et tout avertissement Sphinx (-W).
# Les autres arguments sont transmis à « jupyter-book build ».
set -euo pipefail
unset PYTHONDONTWRITEBYTECODE  # code compilé des modules gardé (voir scripts/setup.sh)
cd "$(dirname "$0")/.."

pdf=0
args=()
for arg in "$@"; do
  if [ "$arg" = "--pdf" ]; then pdf=1; else args+=("$arg"); fi
done
if [ "$pdf" = 1 ]; then bash scripts/setup.sh --pdf; else bash scripts/setup.sh; fi

# Le cache d'exécution ne connaît que le code des cellules : si le paquet a changé, on l'efface,
# sinon les pages montreraient des résultats calculés par l'ancienne version.
pkg_sha=$(.venv/bin/python scripts/package_hash.py)
if [ "$(cat _build/.kalman_course.sha 2>/dev/null)" != "$pkg_sha" ]; then
  rm -rf _build/.jupyter_cache
  mkdir -p _build && echo "$pkg_sha" > _build/.kalman_course.sha
fi
# Les carnets absents du cache, exécutés en parallèle (un noyau par cœur) et rangés dans le cache :
# la construction les y trouve et n'en exécute aucun (voir scripts/execute_notebooks.py).
.venv/bin/python scripts/execute_notebooks.py _build/.jupyter_cache
.venv/bin/jupyter-book build . --all -W --keep-going ${args[@]+"${args[@]}"}
echo "Site construit : $(pwd)/_build/html/index.html"

if [ "$pdf" = 1 ]; then
  start=$(date +%s)
  # Même cache d'exécution et même environnement Sphinx que le site, qu'on vient de reconstruire en
  # entier : aucun carnet n'est relancé, aucune page relue.
  .venv/bin/jupyter-book build . --builder latex -W --keep-going ${args[@]+"${args[@]}"}
  .venv/bin/python scripts/pdf.py _build/latex _build/pdf/filtre-de-kalman.pdf
  echo "PDF construit en $(( $(date +%s) - start )) s : $(pwd)/_build/pdf/filtre-de-kalman.pdf"
fi
