#!/usr/bin/env bash
# Installe requirements.txt (versions figées) dans un environnement virtuel, par uv : « uv pip install »
# télécharge les roues en parallèle et les installe sans les compiler d'avance (Python compile à l'import
# les modules qui servent) : 16 s dans un environnement neuf, contre 48 s pour pip, et trois fois moins de
# calcul. uv lui-même est figé dans requirements.txt et installé d'abord par pip.
# Usage : bash scripts/install_requirements.sh VENV [--editable | --lab]   (--editable : le paquet kalman_course
# aussi, en mode éditable ; --lab : seulement ce que demandent les travaux pratiques, scripts/lab-requirements.txt
# — numpy, scipy, matplotlib, JupyterLab et son paquet de langue française —, aux versions de requirements.txt,
# puis le paquet, en montrant la progression : scripts/lab.sh). Journal : VENV/install.log ; en cas d'échec, sa fin et le code 1.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=${1:?utilisation : bash scripts/install_requirements.sh VENV [--editable]}
python=$venv/bin/python
logfile=$venv/install.log
fail() {
  echo "[installation] ERREUR : $1 ; fin du journal ($logfile) :" >&2
  grep -v "^WARNING: Location" "$logfile" | tail -n 30 >&2
  exit 1
}
uv_pin=$(grep -E '^uv==' requirements.txt) || { echo "[installation] ERREUR : uv n'est pas figé dans requirements.txt" >&2; exit 1; }
"$python" -m pip install -q --no-compile --disable-pip-version-check "$uv_pin" >"$logfile" 2>&1 \
  || fail "pip install $uv_pin a échoué"
if [ "${2:-}" = "--lab" ]; then
  # Les dépendances du paquet (pyproject.toml), le noyau et JupyterLab en français ; les versions de
  # requirements.txt servent de contraintes (rien d'autre n'est installé : ni Jupyter Book, ni Sphinx, ni les
  # bibliothèques de référence des tests, ni Playwright). La progression d'uv s'affiche.
  echo "[installation] numpy, scipy, matplotlib, JupyterLab (en français) et le paquet du cours, par uv…" >&2
  "$venv/bin/uv" pip install --python "$python" -r scripts/lab-requirements.txt -c requirements.txt 2>&1 \
    | tee -a "$logfile" >&2
  [ "${PIPESTATUS[0]}" = 0 ] || fail "uv pip install (environnement des TP) a échoué"
  "$venv/bin/uv" pip install --python "$python" --no-deps -e . 2>&1 | tee -a "$logfile" >&2
  [ "${PIPESTATUS[0]}" = 0 ] || fail "l'installation du paquet kalman_course a échoué"
  exit 0
fi
"$venv/bin/uv" pip install --python "$python" --quiet -r requirements.txt >>"$logfile" 2>&1 \
  || fail "uv pip install -r requirements.txt a échoué"
if [ "${2:-}" = "--editable" ]; then
  "$venv/bin/uv" pip install --python "$python" --quiet --no-deps -e . >>"$logfile" 2>&1 \
    || fail "l'installation du paquet kalman_course (uv pip install -e .) a échoué"
fi
