#!/usr/bin/env bash
# Lance tous les tests : paquet (contre filterpy), construction du livre et du PDF, site dans Chromium
# headless. Installe d'abord ce qu'il faut (scripts/setup.sh). Les constructions se font dans un dossier
# temporaire : _build/ (site, cache, empreinte) reste intact. Le test du PDF demande TeX Live : installé ici
# en CI (CI=true), sinon par « bash scripts/setup.sh --pdf » (sans TeX Live, hors CI, ce test est sauté
# avec un message).
#
# Sans argument, deux sessions pytest tournent en même temps :
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
# Les paquets Debian (Chromium sans écran, TeX Live) s'installent en arrière-plan : les carnets n'en ont pas
# besoin ; la construction du site et le PDF attendent leur fin (scripts/wait_system.sh, KALMAN_SYSTEM_SETUP).
KALMAN_SYSTEM_SETUP=$(mktemp -u "${TMPDIR:-/tmp}/kalman-paquets-debian.XXXXXX")
export KALMAN_SYSTEM_SETUP
case "${CI:-}" in
  ""|false|0) bash scripts/setup.sh --system-later "$KALMAN_SYSTEM_SETUP" ;;
  *) bash scripts/setup.sh --pdf --system-later "$KALMAN_SYSTEM_SETUP" ;;
esac
if [ "$#" -gt 0 ]; then
  exec .venv/bin/python -m pytest "$@"
fi

BOOK_MARKS="book or browser or pdf"
# Les grilles des figures à curseurs (27 grilles, ~30 s de calcul) : calculées une fois pour tout le
# lancement — par les carnets, la session du paquet ou les visites du navigateur, le premier qui en a
# besoin — et relues par les autres (kalman_course.interactive.figure.GRID_CACHE).
KALMAN_GRID_CACHE=$(mktemp -d "${TMPDIR:-/tmp}/kalman-grilles.XXXXXX")
export KALMAN_GRID_CACHE
book_log=$(mktemp)
.venv/bin/python -m pytest -m "$BOOK_MARKS" -p no:cacheprovider --durations=12 >"$book_log" 2>&1 &
book_pid=$!
trap 'kill "$book_pid" 2>/dev/null; true' INT TERM
trap 'rm -rf "$KALMAN_GRID_CACHE"' EXIT
package=0
# Les deux sessions à la même priorité : le système partage les cœurs entre leurs processus, et la session du
# livre en a plusieurs (noyaux, visiteurs et Chromium, XeLaTeX). (En priorité basse, celle du paquet ne
# recevait presque rien pendant les tests du navigateur et finissait seule, 150 s après l'autre, sur un cœur.)
.venv/bin/python -m pytest -m "not ($BOOK_MARKS)" --durations=15 || package=$?
book=0
wait "$book_pid" || book=$?
trap - INT TERM
echo
echo "=============================== session du livre (site, navigateur, PDF) ==============================="
cat "$book_log"
rm -f "$book_log"
echo "[tests] session du paquet : code $package ; session du livre : code $book"
[ "$package" = 0 ] && [ "$book" = 0 ]
