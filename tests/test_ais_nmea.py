"""AIS messages through pyais: a round trip keeps every field to the message's resolution
(ITU-R M.1371-5: 1/10 000 min of latitude/longitude, 0.1 kn, 0.1°, 1° heading), and published example
sentences decode to their published values (gpsd's ``test/sample.aivdm``, BSD licence, decodes checked
there with the noaadata tools and the Maritec decoder)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgnc.ais import nmea
from shipgnc.ais.nmea import PositionReport, StaticData
from shipgnc.errors import ConfigError
from shipgnc.units import KNOT

LATLON_RES = 1 / 600000  # deg: 1/10 000 minute
SOG_RES = 0.1 * KNOT
COG_RES = math.radians(0.1)


def _angle(a, b):
    return abs((a - b + math.pi) % (2 * math.pi) - math.pi)


@pytest.mark.parametrize("msg_type", [1, 2, 3, 18])
@pytest.mark.parametrize("own", [False, True])
def test_round_trip_within_message_resolution(msg_type, own):
    rng = np.random.default_rng(37 + msg_type)
    for _ in range(200):
        r = PositionReport(mmsi=int(rng.integers(200000000, 799999999)), lat=rng.uniform(-89.9, 89.9),
                           lon=rng.uniform(-179.9, 179.9), sog=rng.uniform(0, 102.2) * KNOT,
                           cog=rng.uniform(0, 2 * math.pi), heading=rng.uniform(0, 2 * math.pi),
                           msg_type=msg_type, second=int(rng.integers(0, 60)))
        lines = nmea.encode_position(r, own=own)
        assert lines[0].startswith("!AIVDO" if own else "!AIVDM")
        d = nmea.decode(*lines)
        assert (d.mmsi, d.msg_type, d.second) == (r.mmsi, msg_type, r.second)
        assert abs(d.lat - r.lat) <= LATLON_RES and abs(d.lon - r.lon) <= LATLON_RES
        assert abs(d.sog - r.sog) <= SOG_RES / 2 + 1e-9
        assert _angle(d.cog, r.cog) <= COG_RES / 2 + 1e-9
        assert _angle(d.heading, r.heading) <= math.radians(0.5) + 1e-9


def test_not_available_values_are_missing_both_ways():
    r = PositionReport(mmsi=244000001, lat=None, lon=None, sog=None, cog=None, heading=None, rot=None)
    f = nmea.position_fields(r)
    assert (f["lat"], f["lon"], f["speed"], f["course"], f["heading"], f["turn"]) == (91.0, 181.0, 102.3,
                                                                                     360.0, 511, -128)
    d = nmea.decode(*nmea.encode_position(r))
    assert (d.lat, d.lon, d.sog, d.cog, d.heading, d.rot) == (None,) * 6
    assert not d.has_position


def test_rate_of_turn_round_trip():
    """ROT_AIS = 4.733 √ROT: one raw step is 2·√ROT/4.733 °/min at ROT; pyais rounds to 1 °/min.
    ±127 and ±128 °/min are rates like any other, not the codes ±127/−128 of the raw field."""
    for rot_deg_min in (0.0, 10.0, -25.0, 300.0, -700.0, 127.0, -127.0, 128.0, -128.0):
        r = PositionReport(mmsi=244000002, lat=55.0, lon=12.0, sog=3.0, cog=1.0, heading=1.0,
                           rot=rot_deg_min * nmea.DEG_PER_MIN)
        d = nmea.decode(*nmea.encode_position(r))
        step = 2 * math.sqrt(abs(rot_deg_min)) / 4.733 + 1.0
        assert abs(d.rot / nmea.DEG_PER_MIN - rot_deg_min) <= step


# (sentence, mmsi, type, lat, lon, SOG kn, COG deg, heading deg or None, ROT deg/min or None)
GPSD_POSITIONS = [
    ("!AIVDM,1,1,,A,15RTgt0PAso;90TKcjM8h6g208CQ,0*4A", 371798000, 1, 48.38163333333, -123.395383333, 12.3,
     224.0, 215, None),  # ROT -127: turning left faster than 5°/30 s, rate unknown
    ("!AIVDM,1,1,,A,16SteH0P00Jt63hHaa6SagvJ087r,0*42", 440348000, 1, 43.08015, -70.7582, 0.0, 93.4, None,
     None),
    ("!AIVDM,1,1,,B,25Cjtd0Oj;Jp7ilG7=UkKBoB0<06,0*60", 356302000, 2, 40.392358333, -71.626143333, 13.9,
     87.7, 91, None),
    ("!AIVDM,1,1,,A,38Id705000rRVJhE7cl9n;160000,0*40", 563808000, 3, 36.91, -76.327533333, 0.0, 252.0, 352,
     0.0),
    ("!AIVDM,1,1,,A,B52K>;h00Fc>jpUlNV@ikwpUoP06,0*4C", 338087471, 18, 40.68454, -74.072131667, 0.1, 79.6,
     None, None),
    ("!AIVDM,1,1,,A,B52KB8h006fu`Q6:g1McCwb5oP06,0*00", 338088483, 18, 43.11555833, -70.8111966, 0.0, 171.6,
     None, None),
    ("!AIVDM,1,1,,B,B5O6hr00<veEKmUaMFdEow`UWP06,0*4F", 368161000, 18, 39.480925, -72.2338483333, 5.1, 34.9,
     None, None),
]


@pytest.mark.parametrize("case", GPSD_POSITIONS, ids=lambda c: f"type{c[2]}-{c[1]}")
def test_published_position_reports_decode_to_their_values(case):
    sentence, mmsi, t, lat, lon, sog_kn, cog_deg, hdg, rot = case
    d = nmea.decode(sentence)
    assert (d.mmsi, d.msg_type) == (mmsi, t)
    assert abs(d.lat - lat) <= LATLON_RES and abs(d.lon - lon) <= LATLON_RES
    assert d.sog == pytest.approx(sog_kn * KNOT, abs=1e-9)
    assert _angle(d.cog, math.radians(cog_deg)) <= 1e-9
    assert (d.heading is None) if hdg is None else _angle(d.heading, math.radians(hdg)) <= 1e-9
    assert (d.rot is None) if rot is None else d.rot == pytest.approx(rot * nmea.DEG_PER_MIN)


def test_published_static_data_decode_to_their_values():
    d = nmea.decode("!AIVDM,2,1,1,A,55?MbV02;H;s<HtKR20EHE:0@T4@Dn2222222216L961O5Gf0NSQEp6ClRp8,0*1C",
                    "!AIVDM,2,2,1,A,88888888880,2*25")
    assert d == StaticData(mmsi=351759000, name="EVER DIADEM", callsign="3FOF8", ship_type=70, to_bow=225,
                           to_stern=70, to_port=1, to_starboard=31, msg_type=5)
    assert (d.length, d.beam) == (295.0, 32.0)
    a = nmea.decode("!AIVDM,1,1,,A,H42O55i18tMET00000000000000,2*6D")
    b = nmea.decode("!AIVDM,1,1,,A,H42O55lti4hhhilD3nink000?050,0*40")
    assert (a.mmsi, a.part, a.name) == (271041815, 0, "PROGUY")
    assert (b.mmsi, b.part, b.callsign, b.ship_type) == (271041815, 1, "TC6163", 60)
    assert (b.to_bow, b.to_stern, b.to_port, b.to_starboard) == (0, 15, 0, 5)


@pytest.mark.parametrize("msg_type", [5, 24])
def test_static_round_trip(msg_type):
    s = StaticData(mmsi=219000123, name="OWN SHIP", callsign="OXAB2", ship_type=70, to_bow=120, to_stern=30,
                   to_port=12, to_starboard=13, msg_type=msg_type)
    lines = nmea.encode_static(s, own=True)
    if msg_type == 5:
        d = nmea.decode(*lines)
        assert d == s
    else:
        a, b = nmea.decode(lines[0]), nmea.decode(lines[1])
        assert a.name == s.name and (b.callsign, b.to_bow, b.to_stern, b.to_port, b.to_starboard) == (
            "OXAB2", 120, 30, 12, 13)


def test_bad_sentences_say_what_is_wrong():
    with pytest.raises(ConfigError, match=r"type 4 \(base station report\) is not read"):
        nmea.decode("!AIVDM,1,1,,A,403OviQuMGCqWrRO9>E6fE700@GO,0*4D")
    with pytest.raises(ConfigError, match="checksum"):
        nmea.decode("!AIVDM,1,1,,A,15RTgt0PAso;90TKcjM8h6g208CQ,0*4B")
    with pytest.raises(ConfigError, match="not a readable AIS sentence"):
        nmea.decode("$GPGGA,163929.85,3824.11,S,14435.82,E,1,10,0.98,1113.0,M,-21.3,M,25,10*53")
    with pytest.raises(ConfigError, match="sog"):
        nmea.encode_position(PositionReport(mmsi=244000003, lat=1.0, lon=1.0, sog=200.0))
    with pytest.raises(ConfigError, match="mmsi"):
        nmea.encode_position(PositionReport(mmsi=0, lat=1.0, lon=1.0))
