#!/usr/bin/env bash
# Lance tous les tests : paquet (contre filterpy), construction du livre et du PDF, site dans Chromium
# headless. Installe d'abord ce qu'il faut (scripts/setup.sh). Les constructions se font dans un dossier
# temporaire : _build/ (site, cache, empreinte) reste intact. Le test du PDF demande TeX Live : installé ici
# en CI (CI=true), sinon par « bash scripts/setup.sh --pdf » (sans TeX Live, hors CI, ce test est sauté
# avec un message).
#
# Sans argument, deux sessions pytest tournent en même temps (celle du paquet en priorité basse) :
#   - le livre (marqueurs book, browser, pdf) : carnets exécutés en parallèle puis site construit, tests du
#     site et du navigateur pendant que le PDF se construit, tests du PDF (voir tests/conftest.py) ;
#   - le paquet : tous les autres tests.
# Le journal de la session du livre s'affiche à la fin. Avec des arguments, une seule session pytest les
# reçoit (ex. « bash scripts/test.sh tests/test_kf.py -k joseph »).
set -euo pipefail
unset PYTHONDONTWRITEBYTECODE  # code compilé des modules gardé (voir scripts/setup.sh)
# Une algèbre linéaire (BLAS) sur un fil par processus : les tests font de petits calculs, plusieurs
# processus à la fois (deux sessions, noyaux, constructions) ; les fils d'OpenBLAS, qui attendent du travail
# en tournant, y prenaient 18 % de calcul de plus pour la même durée.
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1
cd "$(dirname "$0")/.."
case "${CI:-}" in
  ""|false|0) bash scripts/setup.sh ;;
  *) bash scripts/setup.sh --pdf ;;
esac
if [ "$#" -gt 0 ]; then
  exec .venv/bin/python -m pytest "$@"
fi

BOOK_MARKS="book or browser or pdf"
book_log=$(mktemp)
.venv/bin/python -m pytest -m "$BOOK_MARKS" -p no:cacheprovider >"$book_log" 2>&1 &
book_pid=$!
trap 'kill "$book_pid" 2>/dev/null; true' INT TERM
package=0
# La session du livre est le chemin critique (carnets, site, navigateur, PDF, l'un après l'autre) ; celle du
# paquet, en priorité basse, prend le temps de calcul qu'elle laisse.
nice -n 10 .venv/bin/python -m pytest -m "not ($BOOK_MARKS)" || package=$?
book=0
wait "$book_pid" || book=$?
trap - INT TERM
echo
echo "=============================== session du livre (site, navigateur, PDF) ==============================="
cat "$book_log"
rm -f "$book_log"
echo "[tests] session du paquet : code $package ; session du livre : code $book"
[ "$package" = 0 ] && [ "$book" = 0 ]
