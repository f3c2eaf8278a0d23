#!/usr/bin/env bash
# Construit le site dans _build/html (installe d'abord ce qu'il faut : voir scripts/setup.sh).
# Toutes les pages sont réécrites (--all) ; les carnets inchangés viennent du cache d'exécution.
# La construction échoue sur toute erreur de cellule et tout avertissement Sphinx (-W).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# Le cache d'exécution ne connaît que le code des cellules : si le paquet a changé, on l'efface,
# sinon les pages montreraient des résultats calculés par l'ancienne version.
pkg_sha=$(find kalman_course -name '*.py' -print0 | sort -z | xargs -0 cat | sha256sum | cut -d' ' -f1)
if [ "$(cat _build/.kalman_course.sha 2>/dev/null)" != "$pkg_sha" ]; then
  rm -rf _build/.jupyter_cache
  mkdir -p _build && echo "$pkg_sha" > _build/.kalman_course.sha
fi
.venv/bin/jupyter-book build . --all -W --keep-going "$@"
echo "Site construit : $(pwd)/_build/html/index.html"
