"""Commande ``python -m kalman_course.practice`` : lister les exercices, écrire les carnets de l'étudiant.

.. code-block:: bash

    python -m kalman_course.practice --list                 # identifiant, titre, signature, erreurs reconnues
    python -m kalman_course.practice --notebooks DOSSIER    # carnets des TP (book/tp-*.md) sans les solutions
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from . import exercises
from .notebooks import write_student_notebooks

ROOT = Path(__file__).resolve().parents[2]


class _FrenchParser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # noqa: D401 — argparse
        self.print_usage(sys.stderr)
        print(f"erreur : {message}", file=sys.stderr)
        raise SystemExit(2)


def main(argv: list[str] | None = None) -> int:
    parser = _FrenchParser(prog="python -m kalman_course.practice", add_help=False,
                           usage="python -m kalman_course.practice [--list] [--notebooks DOSSIER] [--book DOSSIER]",
                           description="Travaux pratiques du cours : exercices et carnets de l'étudiant.")
    parser.add_argument("--list", action="store_true", help="liste les exercices et leurs erreurs classiques")
    parser.add_argument("--notebooks", metavar="DOSSIER", help="écrit les carnets de l'étudiant dans DOSSIER")
    parser.add_argument("--book", metavar="DOSSIER", default=str(ROOT / "book"),
                        help="dossier des pages du livre (par défaut : book/ du dépôt)")
    parser.add_argument("-h", "--help", action="help", help="affiche cette aide")
    args = parser.parse_args(argv)
    if not args.list and not args.notebooks:
        parser.error("donnez --list ou --notebooks DOSSIER")
    if args.list:
        for ex in exercises():
            print(f"{ex.id:22} {ex.title} — {ex.signature} (chapitre {ex.chapter})")
            for mistake in ex.mistakes:
                print(f"    · {mistake.id} : {mistake.title}")
    if args.notebooks:
        book = Path(args.book)
        if not book.is_dir():
            parser.error(f"dossier du livre introuvable : {book}")
        written = write_student_notebooks(book, Path(args.notebooks))
        for path in written:
            print(path)
        print(f"{len(written)} carnet(s) écrit(s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
