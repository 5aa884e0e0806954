"""Logged AIS files to target tracks: the accepted NMEA time forms and CSV layouts, distances in the
local plane against the geodesic (pyproj.Geod, Karney 2013), velocities, and every bad input as one
ConfigError naming the line or field. Outside case: a real ORBCOMM satellite AIS excerpt with NMEA 4.10
tag blocks from libais's test data (Apache-2.0, tests/data/ais/README.md)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from pyproj import Geod

from shipgnc.ais import nmea
from shipgnc.ais.logs import read_log, read_reports
from shipgnc.ais.nmea import PositionReport
from shipgnc.ais.write import tag_block
from shipgnc.errors import ConfigError
from shipgnc.units import KNOT

DATA = Path(__file__).parent / "data" / "ais"
GEOD = Geod(ellps="WGS84")
T0 = 1_700_000_000


def _pos(mmsi, lat, lon, sog_kn=10.0, cog_deg=45.0, msg_type=1, own=False):
    r = PositionReport(mmsi=mmsi, lat=lat, lon=lon, sog=None if sog_kn is None else sog_kn * KNOT,
                       cog=None if cog_deg is None else math.radians(cog_deg), heading=None, msg_type=msg_type)
    return nmea.encode_position(r, own=own)[0]


def _write(tmp_path, lines, name="log.nmea"):
    p = tmp_path / name
    p.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return p


def test_tag_block_log_to_tracks_with_geodesic_distances(tmp_path):
    lines = ["# two ships off Skagen", tag_block(T0) + _pos(219000001, 57.7, 10.6, 12.0, 30.0),
             tag_block(T0) + _pos(219000002, 57.75, 10.7, 8.0, 200.0, msg_type=18),
             tag_block(T0 + 60) + _pos(219000001, 57.705, 10.608, 12.0, 30.0),
             tag_block(T0 + 65) + _pos(219000002, 57.749, 10.699, 8.0, 200.0, msg_type=18)]
    tracks, origin = read_log(_write(tmp_path, lines))
    # the centre: the mean of the four reports' unit vectors; for points a few km apart, to first
    # order in their spread, latitude's arithmetic mean and longitude's mean weighted by cos φ
    lat = np.array([57.7, 57.75, 57.705, 57.749])
    lon = np.array([10.6, 10.7, 10.608, 10.699])
    w = np.cos(np.radians(lat))
    assert origin == pytest.approx((lat.mean(), (w * lon).sum() / w.sum()), abs=1e-5)
    a, b = tracks
    assert (a.mmsi, b.mmsi, a.source) == (219000001, 219000002, "ais")
    assert a.t.tolist() == [0.0, 60.0] and b.t.tolist() == [0.0, 65.0]
    for tr, (lat0, lon0, lat1, lon1) in ((a, (57.7, 10.6, 57.705, 10.608)), (b, (57.75, 10.7, 57.749, 10.699))):
        _, _, d = GEOD.inv(lon0, lat0, lon1, lat1)
        assert math.hypot(tr.north[1] - tr.north[0], tr.east[1] - tr.east[0]) == pytest.approx(d, rel=2e-4)
    # velocity: 12 kn on 030° true, turned into the plane by the meridian convergence (< 0.1° here)
    assert math.hypot(a.v_north[0], a.v_east[0]) == pytest.approx(12.0 * KNOT, rel=1e-9)
    assert math.degrees(math.atan2(a.v_east[0], a.v_north[0])) == pytest.approx(30.0, abs=0.1)
    # a given origin is kept; the first ship then sits where the geodesic from the origin puts it
    tracks, origin = read_log(_write(tmp_path, lines), origin=(57.7, 10.6))
    assert origin == (57.7, 10.6) and abs(tracks[0].north[0]) < 1e-6 and abs(tracks[0].east[0]) < 1e-6


def test_leading_and_trailing_time_forms(tmp_path):
    lines = [f"2023-11-14T22:13:20Z {_pos(219000003, 55.0, 12.0)}",
             f"{T0 + 10}.5;{_pos(219000003, 55.001, 12.0)}",
             _pos(219000003, 55.002, 12.0) + f",s28089,d-103,T39.44353985,x147521,r08TPHI1,{T0 + 20}",
             tag_block(T0 * 1000 + 30000) + _pos(219000003, 55.003, 12.0)]
    reps = read_reports(_write(tmp_path, lines))
    assert [r.time - T0 for r in reps] == [0.0, 10.5, 20.0, 30.0]  # milliseconds in a tag block read as such


def test_own_ship_static_data_and_multi_sentence_messages(tmp_path):
    static = nmea.encode_static(nmea.StaticData(mmsi=219000004, name="KRONPRINS", to_bow=100, to_stern=50,
                                                to_port=10, to_starboard=12))
    lines = [tag_block(T0) + s for s in static] + [tag_block(T0 + 1) + _pos(219000004, 56.0, 11.0, own=True),
                                                  tag_block(T0 + 11) + _pos(219000004, 56.001, 11.0, own=True)]
    (tr,), _ = read_log(_write(tmp_path, lines))
    assert (tr.name, tr.length, tr.beam, tr.source) == ("KRONPRINS", 150.0, 22.0, "ais-own")


def test_missing_speed_takes_the_neighbours_velocity_and_a_duplicate_is_one_report(tmp_path):
    p1 = _pos(219000005, 56.0, 11.0, 10.0, 0.0)
    lines = [tag_block(T0) + p1, tag_block(T0) + p1,  # the same report heard twice
             tag_block(T0 + 10) + _pos(219000005, 56.0005, 11.0, None, None),
             tag_block(T0 + 20) + _pos(219000005, 56.001, 11.0, 10.0, 0.0)]
    (tr,), _ = read_log(_write(tmp_path, lines), origin=(56.0, 11.0))
    assert tr.t.size == 3
    _, _, d = GEOD.inv(11.0, 56.0, 11.0, 56.001)
    assert tr.v_north[1] == pytest.approx(d / 20.0, rel=1e-3) and abs(tr.v_east[1]) < 1e-3


def test_csv_marinecadastre_and_dma_layouts(tmp_path):
    mc = tmp_path / "mc.csv"
    mc.write_text("MMSI,BaseDateTime,LAT,LON,SOG,COG,Heading,VesselName\n"
                  "367000001,2023-06-15T00:00:00,40.60,-74.00,10.0,90.0,511.0,A\n"
                  "367000001,2023-06-15T00:01:00,40.60,-73.9937,10.0,90.0,88.0,A\n"
                  "367000002,2023-06-15T00:00:30,40.61,-74.01,0.0,360.0,511,B\n", encoding="utf-8")
    (a, b), _ = read_log(mc)
    assert a.t.tolist() == [0.0, 60.0] and b.t.tolist() == [30.0]
    assert math.hypot(a.v_north[0], a.v_east[0]) == pytest.approx(10.0 * KNOT)
    assert (b.v_north[0], b.v_east[0]) == (0.0, 0.0)  # at rest, COG 360 (not available) needs no course
    dma = tmp_path / "dma.csv"
    dma.write_text("# Timestamp,Type of mobile,MMSI,Latitude,Longitude,Navigational status,ROT,SOG,COG,Heading\n"
                   "15/06/2023 00:00:00,Class A,219000006,55.70,12.60,Under way using engine,0.0,8.0,180.0,181\n"
                   "15/06/2023 00:00:10,Class A,219000006,55.6994,12.60,Under way using engine,0.0,8.0,180.0,181\n",
                   encoding="utf-8")
    (c,), _ = read_log(dma)
    assert c.t.tolist() == [0.0, 10.0] and c.v_north[0] == pytest.approx(-8.0 * KNOT, rel=1e-6)


def _raises(path, match, **kw):
    with pytest.raises(ConfigError, match=match) as err:
        read_log(path, **kw)
    assert "\n" not in str(err.value)
    return str(err.value)


def test_bad_input_one_line_each(tmp_path):
    ok = tag_block(T0) + _pos(219000007, 56.0, 11.0)
    base_station = tag_block(T0 + 1) + "!AIVDM,1,1,,A,403OviQuMGCqWrRO9>E6fE700@GO,0*4D"
    _raises(_write(tmp_path, [ok, base_station]), r"line 2: AIS message type 4 \(base station report\) is not read")
    (tr,), _ = read_log(_write(tmp_path, [ok, base_station]), skip_unknown=True)
    assert tr.t.size == 1
    _raises(_write(tmp_path, [tag_block(T0 + 5) + _pos(219000007, 56.0, 11.0),
                              tag_block(T0 + 6) + _pos(219000008, 56.0, 11.1),
                              tag_block(T0) + _pos(219000007, 56.001, 11.0)]),
            r"line 3: MMSI 219000007 at 2023-11-14T22:13:20.00Z is earlier than its report at line 1")
    static = nmea.encode_static(nmea.StaticData(mmsi=219000009, name="NOPOS"), seq_id=3)
    _raises(_write(tmp_path, [ok, *(tag_block(T0) + s for s in static)]),
            r"MMSI 219000009 \(first at line 2\) has no position report")
    _raises(_write(tmp_path, [ok, "IamNotAnAisMessage"]), r"line 2: 'IamNotAnAisMessage'… is not an AIS sentence")
    _raises(_write(tmp_path, [ok, ok[:-2] + "00"]), r"line 2: not a readable AIS sentence \(InvalidNMEAChecksum")
    _raises(_write(tmp_path, [_pos(219000007, 56.0, 11.0)]), r"line 1: no time for this message")
    _raises(_write(tmp_path, ["\\c:1700000000*00\\" + _pos(219000007, 56.0, 11.0)]),
            r"line 1: tag block .* wrong or missing checksum")
    _raises(_write(tmp_path, [f"yesterday {_pos(219000007, 56.0, 11.0)}"]), r"line 1: leading time = 'yesterday'")
    _raises(_write(tmp_path, [tag_block(T0) + static[1]]), r"line 1: fragment 2 of 2 without the fragments")
    _raises(_write(tmp_path, [ok, tag_block(T0) + static[0]]), r"line 2: a message of 2 fragments ends after")
    csv = tmp_path / "bad.csv"
    csv.write_text("MMSI,BaseDateTime,LAT,SOG,COG\n1,2023-01-01T00:00:00,1,2,3\n", encoding="utf-8")
    _raises(csv, r"CSV header \(line 1\) has no lon column; accepted names: lon, long, longitude")
    csv.write_text("MMSI,BaseDateTime,LAT,LON,SOG,COG\n219000010,2023-01-01T00:00:00,north,2,3,4\n", encoding="utf-8")
    _raises(csv, r"line 2: field lat = 'north': not a number")
    csv.write_text("MMSI,BaseDateTime,LAT,LON,SOG,COG\n219000010,2023-13-01T00:00:00,1,2,3,4\n", encoding="utf-8")
    _raises(csv, r"line 2: field basedatetime = '2023-13-01T00:00:00': not a time")
    _raises(tmp_path / "absent.nmea", "no such file")
    _raises(_write(tmp_path, [""]), "empty")
    _raises(_write(tmp_path, ["# nothing but a comment"]), "no position report in the file")
    _raises(_write(tmp_path, [ok]), r"origin = \(95, 0\)", origin=(95, 0))


def test_outside_case_orbcomm_tag_block_excerpt(tmp_path):
    """libais's test/data/tagblock.nmea: real satellite AIS (ORBCOMM receivers, 10 Dec 2014) with NMEA
    4.10 tag blocks, a two-sentence type 5 split around another message, three type-1 reports of one
    ship that arrive out of time order, as satellite AIS does."""
    src = DATA / "libais-tagblock.nmea"
    reps = read_reports(src)
    assert [r.line for r in reps] == [2, 1, 4, 5]  # the type 5 completes at line 3, stands at line 1
    static = reps[1].msg
    assert (static.mmsi, static.name, static.callsign) == (219005012, "ROSINANTE", "XPD5019")
    assert [r.msg.mmsi for r in reps if isinstance(r.msg, PositionReport)] == [224651000] * 3
    msg = _raises(src, r"MMSI 219005012 \(first at line 1\) has no position report")
    assert "libais-tagblock.nmea" in msg
    lines = src.read_text().splitlines()
    only_positions = _write(tmp_path, [lines[1], lines[3], lines[4]])
    _raises(only_positions, r"line 2: MMSI 224651000 at 2014-12-10T00:35:22.00Z is earlier than its report "
                            r"at line 1 \(2014-12-10T00:41:53.00Z\)")
    (tr,), _ = read_log(_write(tmp_path, [lines[4], lines[3], lines[1]]))  # in time order it reads
    assert tr.t.tolist() == [0.0, 161.0, 552.0]
    assert np.all(np.abs(np.hypot(tr.v_north, tr.v_east) - np.array([1.2, 1.1, 1.2]) * KNOT) < 1e-9)


def test_far_apart_ships_are_refused_and_the_centre_spans_the_antimeridian(tmp_path):
    """A ship beyond the local plane's 60 km (scale 10⁻⁴) is one line naming its MMSI and its
    geodesic distance; the data's centre is the mean of earth-centred unit vectors, so two ships
    either side of 180° are centred on it, not at longitude 0."""
    from shipgnc.ais.plane import centre

    far = tmp_path / "far.csv"
    far.write_text("MMSI,BaseDateTime,LAT,LON,SOG,COG\n"
                   "219000010,2023-01-01T00:00:00,57.7,11.9,10,0\n"
                   "503000001,2023-01-01T00:00:10,-33.86,151.2,10,0\n", encoding="utf-8")
    _, _, d = GEOD.inv(11.9, 57.7, 151.2, -33.86)
    _raises(far, r"MMSI 219000010 is \d+ km from the local plane's origin")
    msg = _raises(far, r"MMSI 503000001 is \d+ km", origin=(57.7, 11.9))
    assert f"{d / 1000:.0f} km" in msg
    lat, lon = centre([0.0, 0.0], [179.9, -179.9])
    assert abs(lat) < 1e-9 and abs(abs(lon) - 180.0) < 1e-9
    across = tmp_path / "across.csv"
    across.write_text("MMSI,BaseDateTime,LAT,LON,SOG,COG\n"
                      "512000001,2023-01-01T00:00:00,-40.0,179.95,10,0\n"
                      "512000002,2023-01-01T00:00:10,-40.0,-179.95,10,0\n", encoding="utf-8")
    (a, b), origin = read_log(across)
    assert abs(abs(origin[1]) - 180.0) < 1e-6
    _, _, gap = GEOD.inv(179.95, -40.0, -179.95, -40.0)
    assert math.hypot(a.north[0] - b.north[0], a.east[0] - b.east[0]) == pytest.approx(gap, rel=2e-4)
