#!/usr/bin/env bash
# Tests du paquet (sans le livre, ni le navigateur, ni le PDF) avec un autre Python, dans son propre
# environnement .venv-X.Y/ (versions figées de requirements.txt ; le paquet est lu dans le dépôt par
# PYTHONPATH, sans installation : rien n'est écrit à côté de celle de .venv/, qui peut se faire en même temps) :
#   bash scripts/package_tests.sh /usr/bin/python3.13 [arguments de pytest]
# La CI (.ci/run) le lance avec Python 3.13 quand la machine en a un. Ne touche ni à .venv/ ni à _build/.
set -euo pipefail
unset PYTHONDONTWRITEBYTECODE  # code compilé des modules gardé (voir scripts/setup.sh)
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1  # un fil d'algèbre linéaire (voir scripts/test.sh)
cd "$(dirname "$0")/.."
python=${1:?utilisation : bash scripts/package_tests.sh CHEMIN_DU_PYTHON [arguments de pytest]}
shift
v=$("$python" -c 'import sys; print("%d.%d" % sys.version_info[:2])') \
  || { echo "[tests $python] ERREUR : interpréteur inutilisable" >&2; exit 1; }
venv=.venv-$v
log() { printf '[tests Python %s] %s\n' "$v" "$*" >&2; }
stamp=$venv/.requirements.sha
want=$( (cat requirements.txt pyproject.toml; "$python" -c 'import sys; print(sys.version)') | sha256sum | cut -d' ' -f1)
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ]; then
  rm -rf "$venv"
  log "environnement $venv ($python), requirements.txt…"
  "$python" -m venv "$venv"
  bash scripts/install_requirements.sh "$venv"
  echo "$want" > "$stamp"
fi
log "pytest (tests du paquet : ni livre, ni navigateur, ni PDF)…"
export PYTHONPATH="$PWD${PYTHONPATH:+:$PYTHONPATH}"
exec "$venv/bin/python" -m pytest -m "not book and not browser and not pdf" -p no:cacheprovider "$@"
