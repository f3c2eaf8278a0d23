r"""Deux vols réels au-dessus de Toulouse, en ADS-B : l'hélicoptère du SAMU 31 et un vol de calibration.

Les avions et hélicoptères équipés diffusent leur position (GNSS) et leur vitesse sol par ADS-B ; le
réseau de récepteurs **The OpenSky Network** les enregistre. La bibliothèque ``traffic`` (X. Olive, licence
MIT) en livre des exemples ; le cours en garde un petit extrait (``data/*.csv.gz``, quelques dizaines de
ko) avec sa provenance (``data/adsb.json`` : version de traffic, roue, SHA-256 du fichier d'origine et de
l'extrait), régénérable par ``scripts/adsb_extract.py`` à partir de la roue de traffic. traffic n'est pas
une dépendance du cours.

* :func:`samu31` — l'hélicoptère SAMU 31 (17 mai 2019) : 6 min de vol, 278 positions à des instants
  irréguliers (0,4 à 8 s d'écart, les instants propres des positions), environ 790° de virages ;
* :func:`calibration_toulouse` — un vol de calibration des aides à la navigation (16 juin 2017) :
  3 h 27 min, une position toutes les 5 s, environ 38 tours complets de route (comptés sur les positions). Dans l'exemple de traffic,
  sa route est **tronquée à un entier signé sur 8 bits** (valeurs de −128 à 127 : 183° y devient −73) ; le
  chargeur la restaure (:func:`repair_int8_track`, le candidat modulo 256 le plus proche de la route
  déduite des positions). Lue telle quelle, elle compterait 77 « tours ».

Les positions (latitude, longitude WGS84) sont projetées dans le **plan tangent local** au premier point
(est, nord, en mètres ; ellipsoïde WGS84, hauteur 0 : l'altitude barométrique ne sert pas à la projection,
ce qui déplace les points de moins d'un mètre sur ces vols). Les vitesses sol (nœuds) et routes (degrés
depuis le nord, sens horaire) sont converties en composantes est et nord (m/s). Les altitudes sont
barométriques (pieds → mètres).
"""

from __future__ import annotations

import gzip
import hashlib
import json
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..core.results import freeze

__all__ = ["Flight", "Traffic", "samu31", "calibration_toulouse", "toulouse_traffic", "provenance",
           "enu_from_geodetic", "repair_int8_track", "FOOT", "KNOT"]

DATA = Path(__file__).resolve().parent / "data"
#: Un pied (m) et un nœud (m/s).
FOOT = 0.3048
KNOT = 1852.0 / 3600.0
#: Demi-grand axe (m) et aplatissement de l'ellipsoïde WGS84.
WGS84_A = 6378137.0
WGS84_F = 1.0 / 298.257223563

SOURCE = ("The OpenSky Network, via les exemples de la bibliothèque traffic (X. Olive, licence MIT) ; "
          "extrait livré avec kalman_course (provenance : kalman_course/datasets/data/adsb.json)")


@dataclass(frozen=True, eq=False)
class Flight:
    r"""Un vol ADS-B, temps en secondes depuis la première position.

    Positions (``T`` instants, ceux des messages de position eux-mêmes) : ``t`` (T,) s ; ``east``,
    ``north`` (T,) m dans le plan tangent au premier point ; ``altitude`` (T,) m (barométrique) ;
    ``groundspeed`` (T,) m/s et ``track`` (T,) degrés (route, depuis le nord, sens horaire) : la dernière
    vitesse connue à cet instant.

    Vitesses (``V`` messages de vitesse, datés à la seconde de l'enregistrement qui les porte) :
    ``velocity_t`` (V,) s, ``velocity_east``, ``velocity_north`` (V,) m/s.

    ``name``, ``description``, ``start_utc`` (date et heure de la première position, UTC), ``source``.
    """

    name: str
    description: str
    start_utc: str
    t: np.ndarray
    east: np.ndarray
    north: np.ndarray
    altitude: np.ndarray
    groundspeed: np.ndarray
    track: np.ndarray
    velocity_t: np.ndarray
    velocity_east: np.ndarray
    velocity_north: np.ndarray
    source: str = SOURCE

    def __post_init__(self) -> None:
        for name in ("t", "east", "north", "altitude", "groundspeed", "track", "velocity_t", "velocity_east",
                     "velocity_north"):
            object.__setattr__(self, name, freeze(getattr(self, name)))

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def duration(self) -> float:
        """Durée entre la première et la dernière position (s)."""
        return float(self.t[-1] - self.t[0])

    @property
    def dt(self) -> np.ndarray:
        """Écarts entre positions successives (T − 1,) s."""
        return np.diff(self.t)

    @property
    def turn_degrees(self) -> float:
        """Somme des changements de route (degrés, en valeur absolue) entre messages de vitesse successifs."""
        heading = np.unwrap(np.deg2rad(90.0 - np.rad2deg(np.arctan2(self.velocity_north, self.velocity_east))))
        return float(np.rad2deg(np.abs(np.diff(heading)).sum()))

    def __repr__(self) -> str:
        return f"<Vol {self.name} : {len(self)} positions, {self.velocity_t.size} vitesses, {self.duration:.0f} s>"


def enu_from_geodetic(lat_deg, lon_deg, lat0_deg: float, lon0_deg: float) -> tuple[np.ndarray, np.ndarray]:
    r"""Coordonnées est et nord (m) dans le plan tangent local en :math:`(\varphi_0, \lambda_0)`, de points
    de latitude et longitude données (degrés, WGS84, hauteur 0) : passage par les coordonnées
    cartésiennes terrestres (ECEF) puis rotation,

    .. math::

        e = -\sin\lambda_0\,\Delta X + \cos\lambda_0\,\Delta Y,\qquad
        n = -\sin\varphi_0\cos\lambda_0\,\Delta X - \sin\varphi_0\sin\lambda_0\,\Delta Y + \cos\varphi_0\,\Delta Z .
    """
    e2 = WGS84_F * (2.0 - WGS84_F)

    def ecef(lat, lon):
        phi, lam = np.deg2rad(lat), np.deg2rad(lon)
        N = WGS84_A / np.sqrt(1.0 - e2 * np.sin(phi) ** 2)
        return N * np.cos(phi) * np.cos(lam), N * np.cos(phi) * np.sin(lam), N * (1.0 - e2) * np.sin(phi)

    X, Y, Z = ecef(np.asarray(lat_deg, float), np.asarray(lon_deg, float))
    X0, Y0, Z0 = ecef(float(lat0_deg), float(lon0_deg))
    dX, dY, dZ = X - X0, Y - Y0, Z - Z0
    phi0, lam0 = np.deg2rad(lat0_deg), np.deg2rad(lon0_deg)
    east = -np.sin(lam0) * dX + np.cos(lam0) * dY
    north = -np.sin(phi0) * np.cos(lam0) * dX - np.sin(phi0) * np.sin(lam0) * dY + np.cos(phi0) * dZ
    return east, north


@lru_cache(maxsize=1)
def provenance() -> dict:
    """La provenance de l'extrait (``data/adsb.json``) : version de traffic, roue, SHA-256…"""
    return json.loads((DATA / "adsb.json").read_text(encoding="utf-8"))


def _read_extract(info: dict) -> tuple[tuple[str, ...], np.ndarray]:
    """En-tête et valeurs de l'extrait décrit par ``info`` (entrée de la provenance) ; vérifie son SHA-256."""
    data = gzip.decompress((DATA / info["extract"]).read_bytes())
    if hashlib.sha256(data).hexdigest() != info["extract_sha256"]:
        raise RuntimeError(f"L'extrait {info['extract']} ne correspond pas à sa provenance (SHA-256) : "
                           "régénérez-le par scripts/adsb_extract.py.")
    lines = data.decode("utf-8").splitlines()
    header = tuple(lines[0].split(","))
    table = np.array([[float(v) if v else np.nan for v in line.split(",")] for line in lines[1:]])
    return header, table


@lru_cache(maxsize=None)
def _table(name: str) -> tuple[tuple[str, ...], np.ndarray]:
    """En-tête et valeurs de l'extrait du vol ``name`` ; vérifie son SHA-256 contre la provenance."""
    return _read_extract(provenance()["flights"][name])


def _velocity_reports(time_ms: np.ndarray, speed_kt: np.ndarray, track_deg: np.ndarray, t0_ms: float):
    """Les enregistrements dont la vitesse a changé depuis le précédent (un nouveau message de vitesse)."""
    changed = np.ones(time_ms.size, dtype=bool)
    changed[1:] = (np.diff(speed_kt) != 0) | (np.diff(track_deg) != 0)
    gs, tr = speed_kt[changed] * KNOT, np.deg2rad(track_deg[changed])
    return (time_ms[changed] - t0_ms) / 1000.0, gs * np.sin(tr), gs * np.cos(tr)


def repair_int8_track(track_deg: np.ndarray, east: np.ndarray, north: np.ndarray, t: np.ndarray) -> np.ndarray:
    r"""Restaure une route (degrés) **tronquée à un entier signé sur 8 bits** (−128…127), défaut de
    l'exemple « calibration » de traffic : la vraie route :math:`\theta \in [0, 360)` vérifie
    :math:`\theta \equiv v \pmod{256}`, donc vaut :math:`v \bmod 256` ou :math:`v \bmod 256 + 256` (si
    < 360) ; on garde le candidat le plus proche de la route déduite des positions (différences centrées)."""
    ve, vn = np.gradient(east, t), np.gradient(north, t)
    course = np.rad2deg(np.arctan2(ve, vn)) % 360.0
    low = np.mod(track_deg, 256.0)
    high = low + 256.0
    gap = lambda a: np.abs((a - course + 180.0) % 360.0 - 180.0)  # noqa: E731
    return np.where((high < 360.0) & (gap(high) < gap(low)), high, low)


def _utc(ms: float) -> str:
    import datetime

    return datetime.datetime.fromtimestamp(ms / 1000.0, tz=datetime.timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC")


def _flight(name: str, time_column: str) -> Flight:
    header, table = _table(name)
    return _build_flight(name, provenance()["flights"][name]["description"],
                         {h: table[:, i] for i, h in enumerate(header)}, time_column)


def _build_flight(name: str, description: str, col: dict[str, np.ndarray], time_column: str,
                  origin: tuple[float, float] | None = None, t0_ms: float | None = None) -> Flight:
    """Un vol à partir des colonnes de son extrait : une ligne par position (sa première apparition dans la
    colonne ``time_column``), projetée dans le plan tangent en ``origin`` (latitude, longitude ; par défaut la
    première position), temps comptés depuis ``t0_ms`` (par défaut la première position)."""
    pos_ms = col[time_column]
    first = np.unique(pos_ms, return_index=True)[1]  # une ligne par position (sa première apparition)
    t0 = pos_ms[first[0]] if t0_ms is None else t0_ms
    lat, lon = col["latitude_deg"][first], col["longitude_deg"][first]
    east, north = enu_from_geodetic(lat, lon, *((lat[0], lon[0]) if origin is None else origin))
    t = (pos_ms[first] - t0) / 1000.0
    track = col["track_deg"]
    if np.nanmin(track) < 0.0:  # route tronquée sur 8 bits (vol de calibration) : restaurée par les positions
        if time_column != "timestamp_ms":  # pragma: no cover (seul le vol de calibration est concerné)
            raise RuntimeError(f"Route négative dans {name} : restauration non prévue.")
        track = repair_int8_track(track, east, north, t)
    vt, ve, vn = _velocity_reports(col["timestamp_ms"], col["groundspeed_kt"], track, t0)
    return Flight(
        name=name,
        description=description,
        start_utc=_utc(t0),
        t=t,
        east=east,
        north=north,
        altitude=col["altitude_ft"][first] * FOOT,
        groundspeed=col["groundspeed_kt"][first] * KNOT,
        track=track[first],
        velocity_t=vt,
        velocity_east=ve,
        velocity_north=vn,
    )


def samu31() -> Flight:
    r"""L'hélicoptère SAMU 31 au-dessus de Toulouse (17 mai 2019, 6 min) : 278 positions à leurs instants
    propres (``last_position`` d'OpenSky), irréguliers (0,4 à 8 s), et ses messages de vitesse."""
    return _flight("samu31", "last_position_ms")


def calibration_toulouse() -> Flight:
    r"""Le vol de calibration de Toulouse (16 juin 2017, 3 h 27 min, une position toutes les 5 s)."""
    return _flight("calibration_toulouse", "timestamp_ms")


@dataclass(frozen=True, eq=False)
class Traffic:
    r"""Plusieurs vols rejoués sur une **horloge commune**, dans un **plan tangent commun**.

    ``flights`` : les :class:`Flight` (``t`` en secondes depuis le début de la fenêtre de chaque vol ; ``east``,
    ``north`` en mètres dans le plan tangent à ``origin``) ; ``window`` : durée commune des fenêtres (s) ;
    ``origin`` : (latitude, longitude) de l'origine (degrés) et ``origin_name`` ; ``description``, ``source``."""

    flights: tuple
    window: float
    origin: tuple
    origin_name: str
    description: str
    source: str = SOURCE

    def __len__(self) -> int:
        return len(self.flights)

    @property
    def names(self) -> tuple[str, ...]:
        """Les indicatifs des vols."""
        return tuple(f.name for f in self.flights)

    def positions(self, t) -> np.ndarray:
        r"""Positions (est, nord) de chaque vol aux instants ``t`` (K,) de l'horloge commune : (K, A, 2) m,
        interpolées linéairement entre les positions ADS-B de chaque vol."""
        t = np.asarray(t, dtype=float)
        return np.stack([np.stack([np.interp(t, f.t, f.east), np.interp(t, f.t, f.north)], axis=-1)
                         for f in self.flights], axis=1)

    def __repr__(self) -> str:
        return f"<Trafic : {len(self)} vols ({', '.join(self.names)}), fenêtres de {self.window:.0f} s>"


@lru_cache(maxsize=1)
def toulouse_traffic() -> Traffic:
    r"""Cinq vols autour de Toulouse-Blagnac (hélicoptère SAMU 31, avion de prises de vues Pixair, vol de
    calibration de 2017, deux vols de calibration SAVAN de 2022), pris chacun sur une fenêtre de 5 min et
    **rejoués sur une horloge commune** : ils ont volé des jours différents, la scène les superpose (l'instant
    0 de chacun est le début de sa fenêtre, choisie pour que les trajectoires se croisent). Positions dans le
    plan tangent à l'aérodrome de Toulouse-Blagnac ; instants propres des positions (``last_position``
    d'OpenSky) quand le fichier d'origine les donne."""
    info = provenance()["traffic"]
    header, table = _read_extract(info)
    col = {h: table[:, i] for i, h in enumerate(header)}
    origin = (info["origin"]["latitude_deg"], info["origin"]["longitude_deg"])
    flights = []
    for rank, plane in enumerate(info["aircraft"]):
        rows = col["aircraft"] == rank
        own = {h: v[rows] for h, v in col.items()}
        time_column = "last_position_ms" if np.isfinite(own["last_position_ms"]).all() else "timestamp_ms"
        flights.append(_build_flight(plane["callsign"], plane["description"], own, time_column, origin=origin,
                                     t0_ms=float(plane["window_start_ms"])))
    return Traffic(tuple(flights), float(info["window_s"]), origin, info["origin"]["name"], info["description"])
