"""Régénère l'extrait ADS-B livré avec le paquet (kalman_course/datasets/data/) à partir de la roue de traffic.

Deux vols des données d'exemple de la bibliothèque traffic (X. Olive, licence MIT ; données de The OpenSky
Network) : l'hélicoptère SAMU 31 au-dessus de Toulouse (``ambulances/samu31.json.gz``) et le vol de
calibration de Toulouse (``calibration/toulouse.json.gz``) ; et le trafic de cinq vols autour de
Toulouse-Blagnac (:data:`TRAFFIC`, fenêtres de 5 min, dans ``toulouse_traffic.csv.gz``). traffic n'est **pas** une dépendance du cours
(il tire onnxruntime, pyarrow…) : on lit ses fichiers JSON compressés directement dans la roue, sans
l'installer ni l'importer.

Usage ::

    .venv/bin/python -m pip download traffic==2.13 --no-deps -d /tmp/traffic
    .venv/bin/python scripts/adsb_extract.py /tmp/traffic/traffic-2.13-py3-none-any.whl

Écrit, pour chaque vol, ``<nom>.csv.gz`` (les colonnes utiles de toutes les lignes, valeurs recopiées
telles quelles) et ``adsb.json`` (provenance : version de traffic, roue, SHA-256 de la roue, de chaque
fichier d'origine et de chaque extrait décompressé). Deux exécutions sur la même roue écrivent les mêmes
octets.
"""

from __future__ import annotations

import argparse
import gzip
import hashlib
import io
import json
import re
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "kalman_course" / "datasets" / "data"

#: Vol → (fichier dans la roue, colonnes gardées (nom dans le JSON → nom dans l'extrait), description).
FLIGHTS = {
    "samu31": (
        "traffic/data/samples/ambulances/samu31.json.gz",
        {"timestamp": "timestamp_ms", "last_position": "last_position_ms", "latitude": "latitude_deg",
         "longitude": "longitude_deg", "altitude": "altitude_ft", "groundspeed": "groundspeed_kt",
         "track": "track_deg"},
        "Hélicoptère SAMU 31 (indicatif SAMU31, icao24 39ac45) au-dessus de Toulouse, 17 mai 2019",
    ),
    "calibration_toulouse": (
        "traffic/data/samples/calibration/toulouse.json.gz",
        {"timestamp": "timestamp_ms", "latitude": "latitude_deg", "longitude": "longitude_deg",
         "altitude": "altitude_ft", "groundspeed": "groundspeed_kt", "track": "track_deg"},
        "Vol de calibration (indicatif CALIBRA, icao24 39b415) au-dessus de Toulouse, 16 juin 2017",
    ),
}


#: Le trafic autour de Toulouse-Blagnac (partie « Plusieurs cibles ») : cinq vols des mêmes exemples de traffic,
#: chacun pris sur une fenêtre de ``TRAFFIC_WINDOW_S`` secondes (plus ``TRAFFIC_MARGIN_S`` de part et d'autre,
#: pour interpoler aux bords). Ces vols ont eu lieu des jours différents : la scène les **rejoue sur une
#: horloge commune** (l'instant 0 de chacun est le début de sa fenêtre). Les débuts de fenêtre ont été choisis
#: pour que les trajectoires, toutes dans un rectangle de 22 km sur 14 km au sud-est de l'aérodrome, se croisent
#: (croisements à moins de 500 m au même instant). Indicatif → (fichier dans la roue, début de la fenêtre en ms
#: UTC, description).
TRAFFIC_WINDOW_S = 300
TRAFFIC_MARGIN_S = 10
TRAFFIC = {
    "SAMU31": ("traffic/data/samples/ambulances/samu31.json.gz", 1558092215000,
               "Hélicoptère SAMU 31 (icao24 39ac45), 17 mai 2019"),
    "PXR31F": ("traffic/data/samples/surveys/pixair_toulouse.json.gz", 1554028344000,
               "Avion de prise de vues aériennes Pixair (icao24 39b861), lignes de relevé au-dessus de Toulouse, "
               "31 mars 2019"),
    "CALIBRA": ("traffic/data/samples/calibration/toulouse.json.gz", 1497602210000,
                "Vol de calibration (icao24 39b415), 16 juin 2017"),
    "SAVAN03": ("traffic/data/samples/collections/savan.json.gz", 1647935011000,
                "Vol de calibration SAVAN03 (icao24 39b415), départ de Blagnac, 22 mars 2022"),
    "SAVAN11": ("traffic/data/samples/collections/savan.json.gz", 1648449558000,
                "Vol de calibration SAVAN11 (icao24 39b415), départ de Blagnac, 28 mars 2022"),
}
#: Colonnes gardées pour le trafic (``last_position`` : vide dans les fichiers qui ne l'ont pas).
TRAFFIC_COLUMNS = {"timestamp": "timestamp_ms", "last_position": "last_position_ms", "latitude": "latitude_deg",
                   "longitude": "longitude_deg", "altitude": "altitude_ft", "groundspeed": "groundspeed_kt",
                   "track": "track_deg"}
#: Origine du plan tangent commun : l'aérodrome de Toulouse-Blagnac (coordonnées arrondies).
TRAFFIC_ORIGIN = {"name": "Toulouse-Blagnac (LFBO)", "latitude_deg": 43.6289, "longitude_deg": 1.3636}


def sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _value(v) -> str:
    if v is None:
        return ""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ValueError(f"valeur non numérique dans les données : {v!r}")
    return repr(v)


def extract_csv(raw_gz: bytes, columns: dict[str, str]) -> str:
    """Le CSV des colonnes ``columns`` de toutes les lignes du JSON compressé ``raw_gz``, trié par temps."""
    rows = json.loads(gzip.decompress(raw_gz))
    if not isinstance(rows, list) or not rows:
        raise ValueError("le fichier d'origine n'est pas une liste d'enregistrements")
    rows = sorted(rows, key=lambda r: r["timestamp"])
    lines = [",".join(columns.values())]
    for r in rows:
        lines.append(",".join(_value(r.get(key)) for key in columns))
    return "\n".join(lines) + "\n"


def extract_traffic(zf: zipfile.ZipFile) -> tuple[str, dict]:
    """Le CSV du trafic (colonne ``aircraft`` : rang du vol dans :data:`TRAFFIC`, puis :data:`TRAFFIC_COLUMNS`) et
    sa provenance, vol par vol : fichier d'origine, SHA-256, fenêtre, nombre de lignes."""
    lines = [",".join(["aircraft", *TRAFFIC_COLUMNS.values()])]
    aircraft = []
    for rank, (callsign, (member, start_ms, description)) in enumerate(TRAFFIC.items()):
        raw = zf.read(member)
        rows = json.loads(gzip.decompress(raw))
        lo, hi = start_ms - 1000 * TRAFFIC_MARGIN_S, start_ms + 1000 * (TRAFFIC_WINDOW_S + TRAFFIC_MARGIN_S)
        kept = sorted((r for r in rows if r.get("callsign") == callsign and lo <= r["timestamp"] <= hi),
                      key=lambda r: r["timestamp"])
        if not kept:
            raise ValueError(f"aucune ligne de {callsign} dans {member} entre {lo} et {hi} ms")
        for r in kept:
            lines.append(",".join([str(rank)] + [_value(r.get(key)) for key in TRAFFIC_COLUMNS]))
        aircraft.append({
            "callsign": callsign,
            "icao24": kept[0].get("icao24"),
            "description": description,
            "source_file": member,
            "source_sha256": sha256(raw),
            "window_start_ms": start_ms,
            "rows": len(kept),
        })
    info = {
        "description": "Cinq vols autour de Toulouse-Blagnac, enregistrés des jours différents et rejoués sur une "
                       "horloge commune (instant 0 : début de la fenêtre de chaque vol)",
        "window_s": TRAFFIC_WINDOW_S,
        "margin_s": TRAFFIC_MARGIN_S,
        "origin": TRAFFIC_ORIGIN,
        "columns": ["aircraft", *TRAFFIC_COLUMNS.values()],
        "aircraft": aircraft,
    }
    return "\n".join(lines) + "\n", info


def extract(wheel: Path, out: Path = OUT) -> dict:
    """Lit les deux vols dans la roue ``wheel`` et écrit les extraits et leur provenance dans ``out``."""
    match = re.match(r"traffic-([^-]+)-", wheel.name)
    if not match:
        raise SystemExit(f"{wheel.name} n'est pas une roue de traffic (traffic-<version>-….whl)")
    wheel_bytes = wheel.read_bytes()
    provenance = {
        "library": "traffic",
        "traffic_version": match.group(1),
        "wheel": wheel.name,
        "wheel_sha256": sha256(wheel_bytes),
        "licence": "MIT (traffic, © Xavier Olive)",
        "data": "The OpenSky Network (https://opensky-network.org), exemples de la bibliothèque traffic",
        "regenerate": "python -m pip download traffic==<version> --no-deps ; python scripts/adsb_extract.py <roue>",
        "flights": {},
    }
    out.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(io.BytesIO(wheel_bytes)) as zf:
        for name, (member, columns, description) in FLIGHTS.items():
            raw = zf.read(member)
            text = extract_csv(raw, columns)
            data = text.encode("utf-8")
            (out / f"{name}.csv.gz").write_bytes(gzip.compress(data, compresslevel=9, mtime=0))
            provenance["flights"][name] = {
                "description": description,
                "source_file": member,
                "source_sha256": sha256(raw),
                "rows": text.count("\n") - 1,
                "columns": list(columns.values()),
                "extract": f"{name}.csv.gz",
                "extract_sha256": sha256(data),
            }
        text, info = extract_traffic(zf)
        data = text.encode("utf-8")
        (out / "toulouse_traffic.csv.gz").write_bytes(gzip.compress(data, compresslevel=9, mtime=0))
        provenance["traffic"] = {**info, "rows": text.count("\n") - 1, "extract": "toulouse_traffic.csv.gz",
                                 "extract_sha256": sha256(data)}
    (out / "adsb.json").write_text(json.dumps(provenance, ensure_ascii=False, indent=2) + "\n", encoding="utf-8")
    return provenance


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("wheel", type=Path, help="la roue traffic-<version>-py3-none-any.whl (pip download)")
    parser.add_argument("--out", type=Path, default=OUT, help="dossier des extraits (par défaut, celui du paquet)")
    args = parser.parse_args(argv)
    prov = extract(args.wheel, args.out)
    for name, info in prov["flights"].items():
        print(f"{name} : {info['rows']} lignes de {info['source_file']} (SHA-256 {info['source_sha256'][:16]}…)")
    traffic = prov["traffic"]
    print(f"trafic de Toulouse-Blagnac : {traffic['rows']} lignes de {len(traffic['aircraft'])} vols")
    print(f"provenance : {args.out / 'adsb.json'}")


if __name__ == "__main__":
    sys.exit(main())
