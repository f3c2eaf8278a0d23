#!/usr/bin/env bash
# Prépare tout ce dont la construction et les tests ont besoin, sans rien supposer de la machine :
#   - .venv/ : Python 3.11, 3.12 ou 3.13 avec requirements.txt (versions figées) et le paquet kalman_course (éditable) ;
#   - node_modules/ : MathJax et mermaid-cli (package-lock.json), sans téléchargement de navigateur ;
#   - book/vendor/ : les ressources web copiées pour être servies par le site lui-même (hors ligne) ;
#   - Chromium (paquet Debian) : rendu des diagrammes Mermaid à la construction et tests navigateur ;
#   - avec --pdf seulement : TeX Live (XeLaTeX, français, latexmk), polices et pdftotext (paquets Debian),
#     pour le livre en PDF.
# Interpréteur : la variable PYTHON s'il est donné (ex. PYTHON=/usr/bin/python3), sinon le premier
# Python pris en charge parmi python3, python3.13, python3.12, python3.11, /usr/bin/python3.
# Idempotent : une seconde exécution ne refait que ce qui a changé.
set -euo pipefail
# Python garde le code compilé de chaque module importé (__pycache__) : sans lui, chaque processus
# (noyaux des carnets, constructions, tests) recompile toutes ses bibliothèques, 7 s de calcul de plus
# pour numpy, scipy, matplotlib, Bokeh et Sphinx. Un environnement qui l'interdit
# (PYTHONDONTWRITEBYTECODE, posé par certaines images Docker) est corrigé pour ces commandes.
unset PYTHONDONTWRITEBYTECODE
cd "$(dirname "$0")/.."

log() { printf '[setup] %s\n' "$*" >&2; }

want_pdf=0
python_only=0   # --python-only : .venv seulement (scripts/lab.sh : ni Chromium, ni npm, ni ressources web)
system_later="" # --system-later FICHIER : paquets Debian installés en arrière-plan, sans les attendre
while [ "$#" -gt 0 ]; do
  case "$1" in
    --pdf) want_pdf=1 ;;
    --python-only) python_only=1 ;;
    --system-later)
      system_later=${2:?--system-later demande un fichier}
      shift ;;
    *) log "ERREUR : option inconnue « $1 » (options : --pdf, --python-only, --system-later FICHIER)"; exit 2 ;;
  esac
  shift
done

# Pythons pris en charge : ceux sur lesquels requirements.txt s'installe et les tests passent.
SUPPORTED_TEXT="3.11 (dès 3.11.2, celui de Debian 12), 3.12 (celui d'Ubuntu 24.04) et 3.13 (celui de Debian 13)"
python_version() { "$1" -c 'import sys; print("%d.%d.%d" % sys.version_info[:3])' 2>/dev/null; }
is_supported() { case "$1" in 3.11.0|3.11.1) return 1 ;; 3.11.*|3.12.*|3.13.*) return 0 ;; *) return 1 ;; esac; }

# --- paquets Debian et npm, en arrière-plan (pendant l'installation des dépendances Python) -------
# Chaque téléchargement attend surtout le réseau et le disque : apt-get, npm ci et pip tournent ensemble.
jobs_pids=()
start_job() {
  # start_job NOM COMMANDE… : lance COMMANDE en arrière-plan, son journal dans un fichier temporaire
  local name=$1; shift
  local logfile
  logfile=$(mktemp)
  ("$@" >"$logfile" 2>&1) &
  jobs_pids+=($!)
  eval "job_${name}_pid=$! job_${name}_log=$logfile"
}
wait_job() {
  # wait_job NOM : attend la commande (si elle tourne) ; en cas d'échec, montre son journal et s'arrête
  local name=$1 pid log
  eval "pid=\${job_${name}_pid:-} log=\${job_${name}_log:-}"
  [ -n "$pid" ] || return 0
  if ! wait "$pid"; then
    log "ERREUR : $name a échoué ; fin du journal :"
    tail -n 30 "$log" >&2
    exit 1
  fi
  eval "job_${name}_pid="
  rm -f "$log"
}
trap 'for p in "${jobs_pids[@]}"; do kill "$p" 2>/dev/null || true; done' EXIT

# Chromium sans écran (chromium-headless-shell) : le moteur de Chromium sans interface, fait pour
# l'automatisation (celui que Playwright prend d'office sans écran) ; un quart de calcul en moins que le
# navigateur complet pour la même page, et un paquet plus léger. Il dessine les diagrammes Mermaid à la
# construction et sert aux tests dans le navigateur.
# TeX Live, seulement pour le PDF (--pdf) : XeLaTeX + polyglossia (césure française), latexmk, les classes
# et extensions LaTeX de Sphinx, les polices FreeFont (celles de Sphinx avec XeLaTeX) et DejaVu, pdftotext
# (poppler-utils) pour les tests.
TEX_PACKAGES=(texlive-xetex texlive-lang-french texlive-latex-recommended texlive-latex-extra
  texlive-fonts-recommended texlive-plain-generic latexmk fonts-freefont-otf fonts-dejavu-core
  fonts-dejavu-extra poppler-utils)
tex_ready() {
  command -v xelatex >/dev/null && command -v latexmk >/dev/null && command -v pdftotext >/dev/null \
    && kpsewhich polyglossia.sty >/dev/null && kpsewhich hyph-fr.tex >/dev/null \
    && kpsewhich fncychap.sty >/dev/null && [ -n "$(fc-list FreeSerif)" ]
  # pas de « fc-list | grep -q » : avec pipefail, grep -q qui s'arrête tôt fait échouer fc-list (SIGPIPE)
}
apt_packages=()
apt_why=()
if [ "$python_only" = 0 ] && [ ! -x /usr/bin/chromium-headless-shell ]; then
  apt_packages+=(chromium-headless-shell)
  apt_why+=("Chromium sans écran")
fi
if [ "$want_pdf" = 1 ] && ! tex_ready; then
  apt_packages+=("${TEX_PACKAGES[@]}")
  apt_why+=("TeX Live pour le PDF (XeLaTeX, français)")
  # En CI seulement (machine jetable, CI=true) : l'installation de TeX Live construit tous ses formats
  # (fmtutil --all, 50 s de calcul) ; le cours n'utilise que XeLaTeX. Un fmtutil.cnf local (prioritaire)
  # désactive ceux de LuaLaTeX, de LaTeX et pdfLaTeX (4 s de calcul chacun) et les variantes « -dev » :
  # 47 s de calcul en moins. (Sur la machine d'un étudiant, rien n'est changé ; un format désactivé se
  # construirait au premier usage.)
  case "${CI:-}" in
    ""|false|0) ;;
    *)
      if [ "$(id -u)" = "0" ] && [ ! -e /etc/texmf/web2c/fmtutil.cnf ]; then
        mkdir -p /etc/texmf/web2c
        cat >/etc/texmf/web2c/fmtutil.cnf <<'CNF'
# Écrit par scripts/setup.sh en CI : formats inutiles au cours, désactivés (« #! »).
#! dvilualatex luatex language.dat,language.dat.lua dvilualatex.ini
#! dvilualatex-dev luatex language.dat,language.dat.lua dvilualatex.ini
#! lualatex luahbtex language.dat,language.dat.lua lualatex.ini
#! lualatex-dev luahbtex language.dat,language.dat.lua lualatex.ini
#! latex pdftex language.dat -translate-file=cp227.tcx *latex.ini
#! latex-dev pdftex language.dat -translate-file=cp227.tcx *latex.ini
#! pdflatex pdftex language.dat -translate-file=cp227.tcx *pdflatex.ini
#! pdflatex-dev pdftex language.dat -translate-file=cp227.tcx *pdflatex.ini
#! xelatex-dev xetex language.dat -etex xelatex.ini
CNF
      fi
      ;;
  esac
fi
if [ "${#apt_packages[@]}" -gt 0 ]; then
  why=${apt_why[0]}${apt_why[1]:+ et ${apt_why[1]}}
  if [ "$(id -u)" = "0" ] && command -v apt-get >/dev/null; then
    apt_command=(bash -c 'apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "$@"'
                 apt-get "${apt_packages[@]}")
    if [ -n "$system_later" ]; then
      # scripts/test.sh : les carnets n'ont besoin ni de Chromium ni de TeX Live ; la construction du site et
      # le PDF attendent la fin de l'installation (scripts/wait_system.sh), qui écrit son code dans le fichier.
      log "installation de $why (apt-get install ${apt_packages[*]}), en arrière-plan…"
      rm -f "$system_later"
      ( "${apt_command[@]}"; echo $? >"$system_later.code"; mv "$system_later.code" "$system_later" ) \
        >"$system_later.log" 2>&1 </dev/null &
    else
      log "installation de $why (apt-get install ${apt_packages[*]}), en parallèle des dépendances Python…"
      start_job apt "${apt_command[@]}"
    fi
  else
    log "ERREUR : $why manque. Installez les paquets Debian suivants puis relancez :"
    log "         sudo apt-get install --no-install-recommends ${apt_packages[*]}"
    exit 1
  fi
elif [ -n "$system_later" ]; then
  echo 0 >"$system_later"
fi

stamp_npm=node_modules/.lock.sha
want_npm=$(sha256sum package-lock.json | cut -d' ' -f1)
if [ "$python_only" = 0 ] && { [ ! -f "$stamp_npm" ] || [ "$(cat "$stamp_npm")" != "$want_npm" ]; }; then
  log "installation des ressources npm (npm ci), en parallèle des dépendances Python…"
  start_job npm env PUPPETEER_SKIP_DOWNLOAD=true npm ci --no-audit --no-fund --loglevel=error --prefer-offline
fi

# --- Python -------------------------------------------------------------------------------------
# PYTHON donné : ce Python (un .venv fait avec un autre est refait). Sinon : le .venv existant s'il est
# d'un Python pris en charge, ou le premier Python pris en charge trouvé.
base_of() { "$1" -c 'import os, sys; print(os.path.realpath(sys._base_executable))' 2>/dev/null || echo "?"; }
venv_v=""
[ -x .venv/bin/python ] && venv_v=$(python_version .venv/bin/python || echo "?")
if [ -n "${PYTHON:-}" ]; then
  PYTHON_BIN=$PYTHON
  v=$(python_version "$PYTHON_BIN") || { log "ERREUR : PYTHON=$PYTHON n'est pas un interpréteur Python utilisable."; exit 1; }
  if ! is_supported "$v"; then
    log "ERREUR : PYTHON=$PYTHON est Python $v. Pythons pris en charge : $SUPPORTED_TEXT."
    exit 1
  fi
  if [ -n "$venv_v" ] && [ "$(base_of .venv/bin/python)" != "$(base_of "$PYTHON_BIN")" ]; then
    log ".venv utilise Python $venv_v ($(base_of .venv/bin/python)) ; on le refait avec PYTHON=$PYTHON ($v)"
    rm -rf .venv
  fi
elif [ -n "$venv_v" ] && is_supported "$venv_v"; then
  PYTHON_BIN=$(base_of .venv/bin/python)
else
  PYTHON_BIN=""
  seen=""
  for candidate in python3 python3.13 python3.12 python3.11 /usr/bin/python3; do
    command -v "$candidate" >/dev/null || continue
    v=$(python_version "$candidate") || continue
    if is_supported "$v"; then PYTHON_BIN=$(command -v "$candidate"); break; fi
    seen="$seen $candidate ($v)"
  done
  if [ -z "$PYTHON_BIN" ]; then
    log "ERREUR : aucun Python pris en charge trouvé${seen:+ (trouvé :$seen)}."
    log "         Pythons pris en charge : $SUPPORTED_TEXT."
    log "         Installez-en un, ou indiquez-le : PYTHON=/chemin/vers/python3.12 bash scripts/setup.sh"
    exit 1
  fi
  [ -n "$seen" ] && log "non pris en charge :$seen ; Pythons pris en charge : $SUPPORTED_TEXT."
  if [ -n "$venv_v" ]; then
    log ".venv utilise Python $venv_v, non pris en charge ; on le refait"
    rm -rf .venv
  fi
fi
if [ ! -x .venv/bin/python ]; then
  v=$(python_version "$PYTHON_BIN")
  log "création de l'environnement virtuel .venv (Python $v, $PYTHON_BIN)"
  if ! "$PYTHON_BIN" -m venv .venv; then
    rm -rf .venv
    log "ERREUR : « $PYTHON_BIN -m venv » a échoué. Sur Debian/Ubuntu : sudo apt-get install python3-venv"
    exit 1
  fi
fi
v=$(python_version .venv/bin/python)
stamp=.venv/.requirements.sha
want=$( (cat requirements.txt pyproject.toml; echo "$v") | sha256sum | cut -d' ' -f1)
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ]; then
  log "installation des dépendances Python (requirements.txt par uv, Python $v)…"
  bash scripts/install_requirements.sh .venv --editable \
    || { log "Pythons pris en charge : $SUPPORTED_TEXT."; exit 1; }
  .venv/bin/python -c "import kalman_course, kalman_course.interactive, filterpy, myst_nb" \
    || { log "ERREUR : installation Python incomplète"; exit 1; }
  echo "$want" > "$stamp"
fi
# Configuration des noyaux de .venv (retire l'avis « TCP without encryption » : voir ce fichier).
mkdir -p .venv/etc/ipython
cmp -s scripts/ipython_kernel_config.py .venv/etc/ipython/ipython_kernel_config.py \
  || cp scripts/ipython_kernel_config.py .venv/etc/ipython/ipython_kernel_config.py

# --- npm et paquets Debian : fin ---------------------------------------------------------------
if [ -n "${job_npm_pid:-}" ]; then
  wait_job npm
  echo "$want_npm" > "$stamp_npm"
fi
wait_job apt
if [ "$want_pdf" = 1 ] && [ -z "$system_later" ] && ! tex_ready; then
  log "ERREUR : TeX Live installé mais incomplet (xelatex, latexmk, polyglossia, césure fr)"
  exit 1
fi

[ "$python_only" = 1 ] && exit 0

# --- ressources web locales ---------------------------------------------------------------------
.venv/bin/python scripts/vendor_assets.py
