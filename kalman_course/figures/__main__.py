"""Commande : ``python -m kalman_course.figures --out DOSSIER [--format png,svg,pdf] [--only NOM] [--list]``."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from tqdm import tqdm

from . import REGISTRY, draw

FORMATS = ("png", "svg", "pdf")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m kalman_course.figures",
        description="Régénère les figures du cours « Filtre de Kalman » dans des fichiers.",
    )
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
    for name in tqdm(selected, desc="figures", unit="fig", file=sys.stderr):
        fig = draw(name)
        for fmt in formats:
            # metadata figée : deux régénérations donnent les mêmes fichiers
            meta = {"Date": None} if fmt in ("pdf", "svg") else {}
            fig.savefig(args.out / f"{name}.{fmt}", dpi=args.dpi, metadata=meta or None)
            written += 1
    print(f"{written} fichier(s) écrit(s) dans {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
