#!/usr/bin/env bash
# Lance tous les tests : paquet (contre filterpy), construction du livre et du PDF, site dans Chromium
# headless. Installe d'abord ce qu'il faut (scripts/setup.sh). Arguments supplémentaires transmis à pytest.
# Les constructions se font dans un dossier temporaire : _build/ (site, cache, empreinte) reste intact.
# Le test du PDF demande TeX Live : installé ici en CI (CI=true), sinon par « bash scripts/setup.sh --pdf »
# (sans TeX Live, hors CI, ce test est sauté avec un message).
set -euo pipefail
cd "$(dirname "$0")/.."
case "${CI:-}" in
  ""|false|0) bash scripts/setup.sh ;;
  *) bash scripts/setup.sh --pdf ;;
esac
exec .venv/bin/python -m pytest "$@"
