#!/usr/bin/env bash
# Ouvre JupyterLab sur les carnets des travaux pratiques, hors ligne, depuis .venv/.
#
# 1. installe ce qui manque (scripts/setup.sh --python-only : .venv/ et requirements.txt, dont JupyterLab) ;
# 2. copie les carnets à compléter (book/travaux-pratiques/*.ipynb, sans les solutions) dans votre dossier
#    de travail travaux-pratiques/, sans jamais écraser un carnet déjà commencé (pour repartir de zéro,
#    supprimez votre copie) ;
# 3. lance JupyterLab sur ce dossier, sans rien demander au réseau (ni nouvelles, ni mises à jour).
#
# Les arguments sont transmis à « jupyter lab » (ex. --no-browser, --port=8890).
set -euo pipefail
unset PYTHONDONTWRITEBYTECODE  # code compilé des modules gardé (voir scripts/setup.sh)
cd "$(dirname "$0")/.."

bash scripts/setup.sh --python-only
mkdir -p travaux-pratiques
for notebook in book/travaux-pratiques/*.ipynb; do
  target="travaux-pratiques/$(basename "$notebook")"
  if [ ! -e "$target" ]; then
    cp "$notebook" "$target"
    echo "[lab] carnet à compléter : $target" >&2
  fi
done
root=()
[ "$(id -u)" = "0" ] && root=(--allow-root)   # conteneurs, CI : JupyterLab refuse root sans cette option
echo "[lab] JupyterLab sur $(pwd)/travaux-pratiques — arrêt : Ctrl-C deux fois" >&2
# Hors ligne : ni nouvelles, ni recherche de mises à jour, gestionnaire d'extensions en lecture seule.
exec .venv/bin/jupyter lab --ServerApp.root_dir=travaux-pratiques \
  --LabApp.news_url=None --LabApp.check_for_updates_class=jupyterlab.NeverCheckForUpdate \
  --LabApp.extension_manager=readonly ${root[@]+"${root[@]}"} "$@"
