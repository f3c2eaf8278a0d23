#!/usr/bin/env bash
# Lance tous les tests : paquet (contre filterpy), construction du livre, site dans Chromium headless.
# Installe d'abord ce qu'il faut (scripts/setup.sh). Arguments supplémentaires transmis à pytest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
exec .venv/bin/python -m pytest "$@"
