"""Commande : ``python -m kalman_course.figures --out DOSSIER [--format png,svg,pdf] [--only NOM] [--list]``."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import matplotlib
from tqdm import tqdm

from . import REGISTRY, draw

FORMATS = ("png", "svg", "pdf")
# Métadonnées sans date : des fichiers identiques d'une régénération à l'autre.
_FIXED_METADATA = {"png": None, "svg": {"Date": None}, "pdf": {"CreationDate": None}}


class _FrenchHelpFormatter(argparse.HelpFormatter):
    def add_usage(self, usage, actions, groups, prefix=None):
        return super().add_usage(usage, actions, groups, prefix="utilisation : ")


class _FrenchParser(argparse.ArgumentParser):
    """``argparse`` dont les textes fixes (utilisation, erreur, aide) sont en français."""

    def error(self, message: str):
        self.print_usage(sys.stderr)
        self.exit(2, f"{self.prog} : erreur : {message}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _FrenchParser(
        prog="python -m kalman_course.figures",
        description="Régénère les figures du cours « Filtre de Kalman » dans des fichiers.",
        formatter_class=_FrenchHelpFormatter,
        add_help=False,
    )
    parser._optionals.title = "options"
    parser.add_argument("-h", "--help", action="help", help="afficher cette aide et quitter")
    parser.add_argument("--out", type=Path, help="dossier de sortie (créé si besoin)")
    parser.add_argument(
        "--format",
        default="png",
        help="formats séparés par des virgules parmi png, svg, pdf (défaut : png)",
    )
    parser.add_argument("--only", action="append", metavar="NOM", help="ne produire que cette figure (répétable)")
    parser.add_argument("--dpi", type=int, default=150, help="résolution des PNG (défaut : 150)")
    parser.add_argument("--list", action="store_true", help="lister les figures disponibles et quitter")
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.list:
        for spec in REGISTRY.values():
            print(f"{spec.name:32s} [{spec.chapter}] {spec.title}")
        return 0
    if args.out is None:
        parser.error("l'option --out DOSSIER est obligatoire (ou --list)")
    formats = [f.strip().lower() for f in args.format.split(",") if f.strip()]
    unknown = [f for f in formats if f not in FORMATS]
    if unknown or not formats:
        parser.error(f"format(s) inconnu(s) : {', '.join(unknown) or '(aucun)'} ; choisir parmi {', '.join(FORMATS)}")
    selected = args.only or list(REGISTRY)
    missing = [name for name in selected if name not in REGISTRY]
    if missing:
        parser.error(f"figure(s) inconnue(s) : {', '.join(missing)} (voir --list)")
    args.out.mkdir(parents=True, exist_ok=True)
    written = 0
    # Date retirée des métadonnées et identifiants SVG déterministes (réglage local à cette boucle) :
    # deux régénérations écrivent les mêmes octets.
    with matplotlib.rc_context({"svg.hashsalt": "kalman-course"}):
        for name in tqdm(selected, desc="figures", unit="fig", file=sys.stderr):
            fig = draw(name)
            for fmt in formats:
                fig.savefig(args.out / f"{name}.{fmt}", dpi=args.dpi, metadata=_FIXED_METADATA[fmt])
                written += 1
    print(f"{written} fichier(s) écrit(s) dans {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
