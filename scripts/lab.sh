#!/usr/bin/env bash
# Ouvre JupyterLab, en français et hors ligne, sur les carnets des travaux pratiques.
#
# 1. l'environnement : .venv/ s'il est déjà complet (machine de l'enseignant, bash scripts/setup.sh), sinon
#    .venv-tp/, qui ne reçoit que ce que demandent les TP : numpy, scipy, matplotlib, JupyterLab et son paquet
#    de langue française, aux versions de requirements.txt, et le paquet du cours (scripts/install_requirements.sh
#    --lab, progression affichée ; ni Jupyter Book, ni Sphinx, ni Playwright) ;
# 2. copie les carnets à compléter (book/travaux-pratiques/tp1-….ipynb à tp5-…, sans les solutions) dans votre
#    dossier de travail travaux-pratiques/, sans jamais écraser un carnet déjà commencé (pour repartir de zéro,
#    supprimez votre copie) ;
# 3. lance JupyterLab sur ce dossier, en français (kalman_course/practice/jupyterlab/overrides.json), sans rien
#    demander au réseau : ni nouvelles (la question en anglais ne s'affiche pas), ni mises à jour.
#
# Options : --install-only (prépare l'environnement et s'arrête) ; les autres arguments sont transmis à
# « jupyter lab » (--no-browser, --port=8890…). Variables : PYTHON (l'interpréteur de .venv-tp/),
# KALMAN_TP_VENV (un autre dossier d'environnement).
set -euo pipefail
unset PYTHONDONTWRITEBYTECODE  # code compilé des modules gardé (voir scripts/setup.sh)
cd "$(dirname "$0")/.."
log() { printf '[lab] %s\n' "$*" >&2; }

install_only=0
args=()
for arg in "$@"; do
  if [ "$arg" = "--install-only" ]; then install_only=1; else args+=("$arg"); fi
done

ready() { [ -x "$1/bin/jupyter" ] && "$1/bin/python" -c "import kalman_course, jupyterlab, jupyterlab_language_pack_fr_FR" 2>/dev/null; }
venv=${KALMAN_TP_VENV:-}
if [ -z "$venv" ]; then
  if ready .venv; then venv=.venv; else venv=.venv-tp; fi
fi
stamp=$venv/.lab.sha
want=$(cat requirements.txt pyproject.toml | sha256sum | cut -d' ' -f1)
if [ "$venv" != .venv ] && { [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ] || ! ready "$venv"; }; then
  # le même choix d'interpréteur que scripts/setup.sh : PYTHON, sinon le premier Python pris en charge
  supported() { "$1" -c 'import sys; sys.exit(not ((3, 11, 2) <= sys.version_info[:3] < (3, 14)))' 2>/dev/null; }
  python=${PYTHON:-}
  if [ -z "$python" ]; then
    for candidate in python3 python3.13 python3.12 python3.11 /usr/bin/python3; do
      if command -v "$candidate" >/dev/null && supported "$(command -v "$candidate")"; then
        python=$(command -v "$candidate"); break
      fi
    done
  fi
  if [ -z "$python" ] || ! supported "$python"; then
    log "ERREUR : il faut Python 3.11 (dès 3.11.2), 3.12 ou 3.13. Installez-en un, ou indiquez-le :"
    log "         PYTHON=/chemin/vers/python3.12 bash scripts/lab.sh"
    exit 1
  fi
  log "environnement des TP $venv ($("$python" --version 2>&1)) : une seule fois, quelques minutes au premier lancement"
  rm -rf "$venv"
  "$python" -m venv "$venv" || { log "ERREUR : « $python -m venv » a échoué (Debian/Ubuntu : sudo apt-get install python3-venv)"; exit 1; }
  bash scripts/install_requirements.sh "$venv" --lab
  echo "$want" > "$stamp"
fi
# JupyterLab en français, sans nouvelles ni recherche de mises à jour (réglages par défaut de l'environnement)
mkdir -p "$venv/share/jupyter/lab/settings"
cp kalman_course/practice/jupyterlab/overrides.json "$venv/share/jupyter/lab/settings/overrides.json"
[ "$install_only" = 1 ] && { log "environnement prêt : $venv"; exit 0; }

mkdir -p travaux-pratiques
for notebook in book/travaux-pratiques/*.ipynb; do
  target="travaux-pratiques/$(basename "$notebook")"
  if [ ! -e "$target" ]; then
    cp "$notebook" "$target"
    log "carnet à compléter : $target"
  fi
done
root=()
[ "$(id -u)" = "0" ] && root=(--allow-root)   # conteneurs, CI : JupyterLab refuse root sans cette option
log "JupyterLab sur $(pwd)/travaux-pratiques — arrêt : Ctrl-C deux fois"
# Hors ligne : ni nouvelles, ni recherche de mises à jour, gestionnaire d'extensions en lecture seule.
exec "$venv/bin/jupyter" lab --ServerApp.root_dir=travaux-pratiques \
  --LabApp.news_url=None --LabApp.check_for_updates_class=jupyterlab.NeverCheckForUpdate \
  --LabApp.extension_manager=readonly ${root[@]+"${root[@]}"} ${args[@]+"${args[@]}"}
