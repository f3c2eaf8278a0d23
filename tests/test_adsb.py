"""Les vols ADS-B livrés avec le paquet : provenance, intégrité de l'extrait, faits annoncés par le cours,
projection dans le plan tangent contre pymap3d, cohérence des vitesses avec les positions, et le script qui
régénère l'extrait à partir de la roue de traffic."""

from __future__ import annotations

import gzip
import hashlib
import importlib.util
import json
import os
import zipfile
from pathlib import Path

import numpy as np
import pymap3d
import pytest

import kalman_course as kc
from kalman_course.datasets import adsb

ROOT = Path(__file__).resolve().parent.parent


def _script():
    spec = importlib.util.spec_from_file_location("adsb_extract", ROOT / "scripts" / "adsb_extract.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_provenance_names_traffic_its_licence_and_the_hashes():
    prov = adsb.provenance()
    assert prov["traffic_version"] == "2.13" and prov["wheel"] == "traffic-2.13-py3-none-any.whl"
    assert "MIT" in prov["licence"] and "OpenSky" in prov["data"]
    for info in prov["flights"].values():
        for key in ("source_sha256", "extract_sha256"):
            assert len(info[key]) == 64 and int(info[key], 16) >= 0
        data = gzip.decompress((adsb.DATA / info["extract"]).read_bytes())
        assert hashlib.sha256(data).hexdigest() == info["extract_sha256"]
        assert data.decode().count("\n") - 1 == info["rows"]
    size = sum((adsb.DATA / i["extract"]).stat().st_size for i in prov["flights"].values())
    assert size < 80_000, "l'extrait doit rester petit (quelques dizaines de ko)"


def test_samu31_is_the_helicopter_the_course_describes():
    f = kc.datasets.samu31()
    assert len(f) == 278 and f.start_utc.startswith("2019-05-17")
    assert 340 < f.duration < 350                       # 6 min
    assert 0.35 < f.dt.min() < 0.45 and 7.5 < f.dt.max() < 8.0
    assert 780 < f.turn_degrees < 800                   # environ 790° de virages
    assert f.east[0] == 0.0 and f.north[0] == 0.0
    assert np.all(np.diff(f.t) > 0) and np.all(np.diff(f.velocity_t) > 0)


def test_calibration_flight_is_the_long_one():
    f = kc.datasets.calibration_toulouse()
    assert len(f) == 2492 and f.start_utc.startswith("2017-06-16")
    assert f.duration == pytest.approx(3 * 3600 + 27 * 60 + 35)
    assert np.allclose(f.dt, 5.0)
    # environ 38 tours de route, comptés sur la route déduite des positions (en vol)
    course = np.unwrap(np.arctan2(np.gradient(f.east, f.t), np.gradient(f.north, f.t))[f.groundspeed > 15.0])
    assert 37 < np.abs(np.diff(course)).sum() / (2 * np.pi) < 40


def test_calibration_track_was_truncated_to_a_signed_byte_and_is_restored():
    """Dans l'exemple de traffic, la route du vol de calibration tient entre −128 et 127 (un entier signé sur
    8 bits) ; lue telle quelle, elle ferait 77 « tours » et contredirait les positions de 100° en médiane."""
    header, table = adsb._table("calibration_toulouse")
    raw = table[:, header.index("track_deg")]
    assert raw.min() >= -128 and raw.max() <= 127 and (raw < 0).mean() > 0.3
    restored = kc.datasets.calibration_toulouse().track
    assert np.all((restored >= 0) & (restored < 360))
    assert np.allclose(np.mod(restored - raw[np.unique(table[:, 0], return_index=True)[1]], 256.0), 0.0)
    f = kc.datasets.calibration_toulouse()
    course = np.rad2deg(np.arctan2(np.gradient(f.east, f.t), np.gradient(f.north, f.t)))
    flying = f.groundspeed > 15.0
    gap = lambda track: np.median(np.abs((track - course + 180.0) % 360.0 - 180.0)[flying])  # noqa: E731
    assert gap(restored) < 2.0 and gap(raw[np.unique(table[:, 0], return_index=True)[1]]) > 90.0


@pytest.mark.parametrize("loader", [kc.datasets.samu31, kc.datasets.calibration_toulouse])
def test_local_tangent_plane_equals_pymap3d(loader):
    name = loader().name
    header, table = adsb._table(name)
    col = {h: table[:, i] for i, h in enumerate(header)}
    lat, lon = col["latitude_deg"], col["longitude_deg"]
    e, n = adsb.enu_from_geodetic(lat, lon, lat[0], lon[0])
    e_ref, n_ref, _ = pymap3d.geodetic2enu(lat, lon, 0.0, lat[0], lon[0], 0.0)
    assert np.max(np.abs(e - e_ref)) < 1e-6 and np.max(np.abs(n - n_ref)) < 1e-6


@pytest.mark.parametrize("loader", [kc.datasets.samu31, kc.datasets.calibration_toulouse])
def test_reported_velocity_agrees_with_the_positions(loader):
    """Unités et axes : la vitesse déduite des positions successives (différences finies dans le plan
    tangent) et la vitesse sol annoncée (nœuds → m/s, route → composantes) se rejoignent."""
    f = loader()
    moving = f.groundspeed[1:] > 20.0
    v_fd = np.c_[np.diff(f.east), np.diff(f.north)] / f.dt[:, None]
    speed_ratio = np.hypot(*v_fd.T)[moving] / f.groundspeed[1:][moving]
    assert abs(np.median(speed_ratio) - 1.0) < 0.03
    course_fd = np.rad2deg(np.arctan2(v_fd[:, 0], v_fd[:, 1]))
    gap = (course_fd - f.track[1:] + 180.0) % 360.0 - 180.0
    assert np.median(np.abs(gap[moving])) < 5.0


def _fake_wheel(path: Path, version="9.9") -> Path:
    """Une roue de traffic factice : les fichiers des vols et du trafic, quelques lignes chacun (les lignes de
    l'hélicoptère tombent dans sa fenêtre du trafic ; une ligne d'un autre indicatif, ou hors fenêtre, est
    écartée du trafic)."""
    traffic = _script().TRAFFIC
    t0 = traffic["SAMU31"][1]
    rows_samu = [
        {"timestamp": t0 + 2000, "last_position": t0 + 1900, "latitude": 43.6, "longitude": 1.4, "altitude": 1000.0,
         "groundspeed": 80.5, "track": 90.0, "callsign": "SAMU31", "icao24": "39ac45"},
        {"timestamp": t0 + 1000, "last_position": t0 + 900, "latitude": 43.59, "longitude": 1.39, "altitude": 975.0,
         "groundspeed": 80, "track": 89.5, "callsign": "SAMU31", "icao24": "39ac45"},
    ]
    members = {"traffic/data/samples/ambulances/samu31.json.gz": rows_samu,
               "traffic/data/samples/calibration/toulouse.json.gz": []}
    for callsign, (member, start, _) in traffic.items():
        if callsign != "SAMU31":
            members.setdefault(member, []).extend([
                {"timestamp": start + 5000 * i, "latitude": 43.5, "longitude": 1.5, "altitude": 100, "groundspeed": 100,
                 "track": 0, "callsign": callsign} for i in range(3)])
            members[member].append({"timestamp": start - 60_000, "latitude": 43.5, "longitude": 1.5, "altitude": 100,
                                    "groundspeed": 100, "track": 0, "callsign": callsign})  # hors fenêtre
    members["traffic/data/samples/calibration/toulouse.json.gz"].append(
        {"timestamp": 1, "latitude": 43.0, "longitude": 1.0, "altitude": 100, "groundspeed": 100, "track": 0,
         "callsign": "AUTRE"})
    wheel = path / f"traffic-{version}-py3-none-any.whl"
    with zipfile.ZipFile(wheel, "w") as zf:
        for member, rows in members.items():
            zf.writestr(member, gzip.compress(json.dumps(rows).encode(), mtime=0))
    return wheel


def test_extract_script_rebuilds_the_extract_from_a_wheel(tmp_path):
    script = _script()
    wheel = _fake_wheel(tmp_path)
    out = tmp_path / "out"
    prov = script.extract(wheel, out)
    assert prov["traffic_version"] == "9.9"
    assert prov["wheel_sha256"] == hashlib.sha256(wheel.read_bytes()).hexdigest()
    with zipfile.ZipFile(wheel) as zf:
        raw = zf.read("traffic/data/samples/ambulances/samu31.json.gz")
    info = prov["flights"]["samu31"]
    assert info["source_sha256"] == hashlib.sha256(raw).hexdigest() and info["rows"] == 2
    t0 = script.TRAFFIC["SAMU31"][1]
    text = gzip.decompress((out / "samu31.csv.gz").read_bytes()).decode()
    assert text.splitlines() == [
        "timestamp_ms,last_position_ms,latitude_deg,longitude_deg,altitude_ft,groundspeed_kt,track_deg",
        f"{t0 + 1000},{t0 + 900},43.59,1.39,975.0,80,89.5",      # trié par temps, valeurs recopiées telles quelles
        f"{t0 + 2000},{t0 + 1900},43.6,1.4,1000.0,80.5,90.0",
    ]
    # le trafic : les lignes de chaque indicatif dans sa fenêtre, rang du vol en tête
    traffic = prov["traffic"]
    assert [a["callsign"] for a in traffic["aircraft"]] == list(script.TRAFFIC)
    assert [a["rows"] for a in traffic["aircraft"]] == [2, 3, 3, 3, 3] and traffic["rows"] == 14
    lines = gzip.decompress((out / traffic["extract"]).read_bytes()).decode().splitlines()
    assert lines[0] == "aircraft,timestamp_ms,last_position_ms,latitude_deg,longitude_deg,altitude_ft,groundspeed_kt,track_deg"
    assert lines[1] == f"0,{t0 + 1000},{t0 + 900},43.59,1.39,975.0,80,89.5"
    assert lines[3].startswith(f"1,{script.TRAFFIC['PXR31F'][1]},,43.5,1.5,")  # sans last_position : vide
    first = {p.name: p.read_bytes() for p in out.iterdir()}
    script.extract(wheel, out)
    assert {p.name: p.read_bytes() for p in out.iterdir()} == first  # mêmes octets à chaque régénération


@pytest.mark.skipif(not os.environ.get("TRAFFIC_WHEEL"), reason="TRAFFIC_WHEEL (roue de traffic téléchargée) non défini")
def test_shipped_extract_is_what_the_script_writes_from_the_real_wheel(tmp_path):
    """``pip download traffic==2.13 --no-deps`` puis TRAFFIC_WHEEL=<roue> : l'extrait livré est régénéré à
    l'identique."""
    prov = _script().extract(Path(os.environ["TRAFFIC_WHEEL"]), tmp_path)
    assert prov == adsb.provenance()
    for info in [*prov["flights"].values(), prov["traffic"]]:
        assert (tmp_path / info["extract"]).read_bytes() == (adsb.DATA / info["extract"]).read_bytes()


# --------------------------------------------------------------------------- trafic de Toulouse-Blagnac (issue 37)


def test_toulouse_traffic_replays_five_flights_on_a_common_clock():
    traffic = kc.datasets.toulouse_traffic()
    prov = adsb.provenance()["traffic"]
    assert traffic.names == ("SAMU31", "PXR31F", "CALIBRA", "SAVAN03", "SAVAN11")
    assert traffic.window == 300.0 and len({f.start_utc[:10] for f in traffic.flights}) == 5  # cinq jours
    data = gzip.decompress((adsb.DATA / prov["extract"]).read_bytes())
    assert hashlib.sha256(data).hexdigest() == prov["extract_sha256"] and data.decode().count("\n") - 1 == prov["rows"]
    assert (adsb.DATA / prov["extract"]).stat().st_size < 40_000
    for f, plane in zip(traffic.flights, prov["aircraft"]):
        # l'instant 0 de chaque vol est le début de sa fenêtre ; les positions la couvrent (marge de 10 s)
        assert f.t[0] <= 0.0 < 300.0 <= f.t[-1] and np.all(np.diff(f.t) > 0)
        assert f.start_utc == adsb._utc(plane["window_start_ms"])
        assert np.diff(f.t).max() <= 13.0 + 1e-9  # au plus 13 s entre deux positions (Pixair : 8 s en médiane)


def test_toulouse_traffic_shares_the_tangent_plane_at_blagnac():
    traffic = kc.datasets.toulouse_traffic()
    prov = adsb.provenance()["traffic"]
    header, table = adsb._read_extract(prov)
    col = {h: table[:, i] for i, h in enumerate(header)}
    lat0, lon0 = traffic.origin
    for rank, f in enumerate(traffic.flights):
        rows = col["aircraft"] == rank
        time = col["last_position_ms"][rows] if np.isfinite(col["last_position_ms"][rows]).all() else col["timestamp_ms"][rows]
        first = np.unique(time, return_index=True)[1]
        e, n, _ = pymap3d.geodetic2enu(col["latitude_deg"][rows][first], col["longitude_deg"][rows][first], 0.0,
                                       lat0, lon0, 0.0)
        assert np.max(np.abs(f.east - e)) < 1e-6 and np.max(np.abs(f.north - n)) < 1e-6


def test_toulouse_traffic_tracks_cross_in_a_small_region():
    """Les cinq trajectoires tiennent dans un rectangle de 25 km sur 15 km autour de l'aérodrome et se croisent :
    plusieurs paires passent à moins de 500 m l'une de l'autre au même instant de l'horloge commune."""
    traffic = kc.datasets.toulouse_traffic()
    t = np.arange(0.0, 300.0 + 1e-9, 1.0)
    p = traffic.positions(t)
    assert p.shape == (t.size, 5, 2)
    assert np.ptp(p[..., 0]) < 25e3 and np.ptp(p[..., 1]) < 15e3
    close = [(i, j) for i in range(5) for j in range(i + 1, 5) if np.linalg.norm(p[:, i] - p[:, j], axis=1).min() < 500.0]
    assert len(close) >= 4
    f = traffic.flights[0]
    k = np.searchsorted(f.t, 100.0)
    w = (100.0 - f.t[k - 1]) / (f.t[k] - f.t[k - 1])  # interpolation linéaire entre deux positions
    np.testing.assert_allclose(traffic.positions([100.0])[0, 0], [(1 - w) * f.east[k - 1] + w * f.east[k],
                                                                  (1 - w) * f.north[k - 1] + w * f.north[k]])
