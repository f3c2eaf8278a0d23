#!/usr/bin/env bash
# Attend la fin de l'installation des paquets Debian (Chromium sans écran, TeX Live) que
# « scripts/setup.sh --system-later FICHIER » a lancée en arrière-plan (scripts/test.sh le fait : les carnets
# s'exécutent pendant ce temps) ; échoue, avec la fin du journal d'apt-get, si elle a échoué.
# Usage : bash scripts/wait_system.sh [FICHIER]   (défaut : $KALMAN_SYSTEM_SETUP ; sans l'un ni l'autre : rien à attendre)
set -euo pipefail
status=${1:-${KALMAN_SYSTEM_SETUP:-}}
[ -n "$status" ] || exit 0
for _ in $(seq 1 1800); do
  [ -f "$status" ] && break
  sleep 1
done
if [ ! -f "$status" ]; then
  echo "[setup] ERREUR : l'installation des paquets Debian n'a pas fini en 30 min ($status.log)" >&2
  exit 1
fi
code=$(cat "$status")
if [ "$code" != 0 ]; then
  echo "[setup] ERREUR : l'installation des paquets Debian a échoué (code $code) ; fin du journal ($status.log) :" >&2
  tail -n 30 "$status.log" >&2 || true
  exit 1
fi
