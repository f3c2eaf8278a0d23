#!/usr/bin/env bash
# Imprime le chemin d'un interpréteur Python X.Y qui fonctionne (« bash scripts/find_python.sh 3.13 »),
# ou sort avec le code 1 s'il n'y en a pas : pythonX.Y sur le PATH, /usr/bin, /usr/local/bin, puis les
# versions installées par pyenv (dont les « shims » ne répondent que si la version est choisie).
set -uo pipefail
want=${1:?utilisation : bash scripts/find_python.sh X.Y}
works() { [ -x "$1" ] && [ "$("$1" -c 'import sys; print("%d.%d" % sys.version_info[:2])' 2>/dev/null)" = "$want" ]; }
candidates=()
command -v "python$want" >/dev/null 2>&1 && candidates+=("$(command -v "python$want")")
candidates+=("/usr/bin/python$want" "/usr/local/bin/python$want")
if command -v pyenv >/dev/null 2>&1; then
  root=$(pyenv root 2>/dev/null)
  for v in $(pyenv versions --bare 2>/dev/null | grep -E "^${want//./\\.}\.[0-9]+$" | sort -t. -k3 -n -r); do
    candidates+=("$root/versions/$v/bin/python$want")
  done
fi
for candidate in "${candidates[@]}"; do
  if works "$candidate"; then echo "$candidate"; exit 0; fi
done
exit 1
