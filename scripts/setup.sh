#!/usr/bin/env bash
# Prépare tout ce dont la construction et les tests ont besoin, sans rien supposer de la machine :
#   - .venv/ : Python 3.11 avec requirements.txt (versions figées) et le paquet kalman_course (éditable) ;
#   - node_modules/ : MathJax et mermaid-cli (package-lock.json), sans téléchargement de navigateur ;
#   - book/vendor/ : les ressources web copiées pour être servies par le site lui-même (hors ligne) ;
#   - Chromium (paquet Debian) : rendu des diagrammes Mermaid à la construction et tests navigateur.
# Idempotent : une seconde exécution ne refait que ce qui a changé.
set -euo pipefail
cd "$(dirname "$0")/.."

log() { printf '[setup] %s\n' "$*" >&2; }

# --- Chromium (Debian) --------------------------------------------------------------------------
if [ ! -x /usr/bin/chromium ]; then
  if [ "$(id -u)" = "0" ] && command -v apt-get >/dev/null; then
    log "installation de Chromium (apt-get install chromium)…"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null
  else
    log "ERREUR : Chromium est introuvable (/usr/bin/chromium). Installez le paquet Debian « chromium »"
    log "         (sudo apt-get install chromium) puis relancez."
    exit 1
  fi
fi

# --- Python -------------------------------------------------------------------------------------
PYTHON_BIN=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
  log "création de l'environnement virtuel .venv"
  "$PYTHON_BIN" -m venv .venv
fi
stamp=.venv/.requirements.sha
want=$(cat requirements.txt pyproject.toml | sha256sum | cut -d' ' -f1)
pip_quiet() {
  # pip dans un journal ; en cas d'échec, on montre la fin du journal et on s'arrête.
  local logfile=.venv/pip-install.log
  if ! .venv/bin/python -m pip install -q --disable-pip-version-check "$@" >"$logfile" 2>&1; then
    log "ERREUR : pip install $* a échoué ; fin du journal ($logfile) :"
    grep -v "^WARNING: Location" "$logfile" | tail -n 30 >&2
    exit 1
  fi
}
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ]; then
  log "installation des dépendances Python (requirements.txt)…"
  pip_quiet -r requirements.txt
  pip_quiet --no-deps -e .
  .venv/bin/python -c "import kalman_course, kalman_course.interactive, filterpy, myst_nb" \
    || { log "ERREUR : installation Python incomplète"; exit 1; }
  echo "$want" > "$stamp"
fi

# --- npm ----------------------------------------------------------------------------------------
stamp_npm=node_modules/.lock.sha
want_npm=$(sha256sum package-lock.json | cut -d' ' -f1)
if [ ! -f "$stamp_npm" ] || [ "$(cat "$stamp_npm")" != "$want_npm" ]; then
  log "installation des ressources npm (npm ci)…"
  PUPPETEER_SKIP_DOWNLOAD=true npm ci --no-audit --no-fund --loglevel=error >&2
  echo "$want_npm" > "$stamp_npm"
fi

# --- ressources web locales ---------------------------------------------------------------------
.venv/bin/python scripts/vendor_assets.py
