"""Empreinte du paquet kalman_course : SHA-256 de ses fichiers .py (chemins relatifs et contenus).

Le cache d'exécution de Jupyter Book ne connaît que le code des cellules : une page calculée par une
ancienne version du paquet y resterait. ``scripts/build.sh`` et la construction des tests comparent
cette empreinte à celle écrite à côté du cache (``_build/.kalman_course.sha``) et n'utilisent le cache
que si elles sont égales. Usage : ``python scripts/package_hash.py`` imprime l'empreinte.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
#: Fichier, à côté du cache d'exécution, qui donne l'empreinte du paquet qui a rempli ce cache.
STAMP_NAME = ".kalman_course.sha"


def package_hash(root: Path = ROOT) -> str:
    """Empreinte de ``root/kalman_course/**/*.py``, indépendante de l'ordre du système de fichiers."""
    digest = hashlib.sha256()
    package = root / "kalman_course"
    for path in sorted(package.rglob("*.py"), key=lambda p: p.relative_to(package).as_posix()):
        rel = path.relative_to(package).as_posix().encode()
        data = path.read_bytes()
        digest.update(len(rel).to_bytes(8, "big") + rel + len(data).to_bytes(8, "big") + data)
    return digest.hexdigest()


if __name__ == "__main__":
    print(package_hash())
