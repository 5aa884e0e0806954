"""AIS messages in NMEA 0183 (``!AIVDM`` received, ``!AIVDO`` own ship), encoded and decoded by
``pyais``; SI at the boundary.

Read and written: position reports of Class A (message types 1, 2, 3) and Class B (18), static data
(types 5 and 24, parts A and B). Field meanings and resolutions are those of ITU-R M.1371-5, Annex 8
(the gpsd "AIVDM/AIVDO protocol decoding" page sets them out field by field):

========  ===============================  =================  ============================
field     message                          resolution         not available
========  ===============================  =================  ============================
latitude  1/10 000 min (1/600 000 deg)     ±90°               91° (181° longitude)
SOG       0.1 kn                           0 … 102.2 kn       102.3 kn (raw 1023)
COG       0.1°, clockwise from true N      0 … 359.9°         360.0° (raw 3600)
heading   1°, true                         0 … 359°           511
ROT       ROT_AIS = 4.733 √abs(ROT) °/min  ±126 ↔ ±708 °/min  −128; ±127: > 5°/30 s, no TI
========  ===============================  =================  ============================

Here: speeds in m/s (1 kn = 1852/3600 m/s), angles in radians, course and heading clockwise from true
north in [0, 2π), rate of turn in rad/s (positive to starboard); a field that is not available is
``None``. A rate of turn sent as ±127 (turning, rate unknown) is ``None`` too. ``pyais`` rounds the
decoded rate of turn to whole degrees per minute; the reporting rules only ask whether it exceeds a few
degrees per minute.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from shipgnc.errors import ConfigError
from shipgnc.units import KNOT

POSITION_TYPES = (1, 2, 3, 18)
STATIC_TYPES = (5, 24)
#: message types whose content :func:`decode` returns (19: Class B extended, position and static)
READ_TYPES = (1, 2, 3, 5, 18, 19, 24)
TYPE_NAMES = {1: "Class A position", 2: "Class A position", 3: "Class A position",
              4: "base station report", 5: "Class A static and voyage data", 6: "addressed binary",
              7: "binary acknowledge", 8: "broadcast binary", 9: "SAR aircraft position",
              10: "UTC inquiry", 11: "UTC response", 12: "addressed safety", 13: "safety acknowledge",
              14: "broadcast safety", 15: "interrogation", 16: "assignment mode command",
              17: "DGNSS broadcast", 18: "Class B position", 19: "Class B extended position",
              20: "data link management", 21: "aid to navigation", 22: "channel management",
              23: "group assignment", 24: "Class B static data", 25: "single slot binary",
              26: "multiple slot binary", 27: "long-range position"}

SOG_NA_KN = 102.3
COG_NA_DEG = 360.0
HEADING_NA = 511
DEG_PER_MIN = math.pi / 180.0 / 60.0  #: rad/s per degree per minute


def read_types_text() -> str:
    return "1, 2, 3 (Class A position), 18, 19 (Class B position), 5, 24 (static data)"


@dataclass(frozen=True)
class PositionReport:
    """A position report, SI: ``sog`` [m/s], ``cog``/``heading`` [rad, clockwise from true north],
    ``rot`` [rad/s, + to starboard]; ``None`` where the message says 'not available'.
    ``second`` is the UTC second of the fix (60–63: not available / manual / dead reckoning /
    inoperative); ``status`` the navigational status (Class A; 15 = not defined)."""

    mmsi: int
    lat: float | None
    lon: float | None
    sog: float | None = None
    cog: float | None = None
    heading: float | None = None
    rot: float | None = None
    msg_type: int = 1
    status: int = 15
    second: int = 60

    @property
    def has_position(self) -> bool:
        return self.lat is not None and self.lon is not None


@dataclass(frozen=True)
class StaticData:
    """Static data (type 5, or one part of type 24): name, call sign, ship type and the antenna's
    distances to bow, stern, port and starboard [m]; ``length``/``beam`` their sums (None when both
    are 0, 'not available')."""

    mmsi: int
    name: str = ""
    callsign: str = ""
    ship_type: int = 0
    to_bow: int = 0
    to_stern: int = 0
    to_port: int = 0
    to_starboard: int = 0
    msg_type: int = 5
    part: int | None = None

    @property
    def length(self) -> float | None:
        n = self.to_bow + self.to_stern
        return float(n) if n > 0 else None

    @property
    def beam(self) -> float | None:
        n = self.to_port + self.to_starboard
        return float(n) if n > 0 else None


def _to_rad(deg: float) -> float:
    return math.radians(deg) % (2 * math.pi)


def _rot_from_ais(turn) -> float | None:
    """pyais gives the rate of turn in °/min (rounded; raw ±126 reads ±709), or a TurnRate member
    for the codes ±127 (turning, rate unknown) and −128 (not available)."""
    from pyais.constants import TurnRate

    if turn is None or isinstance(turn, TurnRate) or not isinstance(turn, (int, float)):
        return None
    return float(turn) * DEG_PER_MIN


def decode(*sentences: str | bytes) -> PositionReport | StaticData:
    """Decode one AIS message (all fragments of a multi-sentence one) to SI.

    Raises ConfigError: a sentence pyais cannot read (naming pyais's reason), a message type other
    than those read here (naming it)."""
    import pyais
    from pyais.exceptions import AISBaseException

    try:
        msg = pyais.decode(*sentences, error_if_checksum_invalid=True)
    except AISBaseException as exc:
        raise ConfigError(f"not a readable AIS sentence ({type(exc).__name__}: {exc})") from None
    except (ValueError, IndexError, KeyError, TypeError) as exc:
        raise ConfigError(f"not a readable AIS sentence ({exc})") from None
    return from_message(msg)


def from_message(msg) -> PositionReport | StaticData:
    """A decoded pyais message in SI (see :func:`decode`)."""
    t = int(msg.msg_type)
    if t not in READ_TYPES:
        raise ConfigError(f"AIS message type {t} ({TYPE_NAMES.get(t, 'unknown')}) is not read; types "
                          f"read: {read_types_text()}")
    mmsi = int(msg.mmsi)
    if t == 24:
        part = int(msg.partno)
        if part == 0:
            return StaticData(mmsi=mmsi, name=(msg.shipname or "").strip(), msg_type=24, part=0)
        return StaticData(mmsi=mmsi, callsign=(msg.callsign or "").strip(), ship_type=int(msg.ship_type),
                          to_bow=int(getattr(msg, "to_bow", 0)), to_stern=int(getattr(msg, "to_stern", 0)),
                          to_port=int(getattr(msg, "to_port", 0)),
                          to_starboard=int(getattr(msg, "to_starboard", 0)), msg_type=24, part=1)
    if t == 5:
        return StaticData(mmsi=mmsi, name=(msg.shipname or "").strip(), callsign=(msg.callsign or "").strip(),
                          ship_type=int(msg.ship_type), to_bow=int(msg.to_bow), to_stern=int(msg.to_stern),
                          to_port=int(msg.to_port), to_starboard=int(msg.to_starboard), msg_type=5)
    lat, lon = float(msg.lat), float(msg.lon)
    has_pos = abs(lat) <= 90.0 and abs(lon) <= 180.0
    sog_kn, cog_deg, hdg = float(msg.speed), float(msg.course), int(msg.heading)
    return PositionReport(
        mmsi=mmsi, lat=lat if has_pos else None, lon=lon if has_pos else None,
        sog=None if sog_kn >= SOG_NA_KN - 1e-9 else sog_kn * KNOT,
        cog=None if cog_deg >= COG_NA_DEG - 1e-9 else _to_rad(cog_deg),
        heading=None if hdg >= 360 else _to_rad(hdg),
        rot=_rot_from_ais(msg.turn) if t in (1, 2, 3) else None,
        msg_type=t, status=int(getattr(msg, "status", 15)) if t in (1, 2, 3) else 15,
        second=int(msg.second))


def check_mmsi(mmsi: int, what: str) -> None:
    """An MMSI outside [1, 2^30) (the 30-bit field of every message): ConfigError naming ``what``."""
    if not 0 < mmsi < 2**30:
        raise ConfigError(f"{what} = {mmsi}: must be a 9-digit identity in [1, 2^30)")


def _check(name: str, value, lo: float, hi: float, unit: str) -> None:
    if value is not None and not (math.isfinite(value) and lo <= value <= hi):
        raise ConfigError(f"AIS report {name} = {value!r}: must be in [{lo:g}, {hi:g}] {unit} or None "
                          "(not available)")


def position_fields(r: PositionReport) -> dict:
    """The report as pyais message fields (AIS units, the 'not available' codes for ``None``)."""
    if r.msg_type not in POSITION_TYPES:
        raise ConfigError(f"AIS position report msg_type = {r.msg_type}: must be one of {POSITION_TYPES}")
    check_mmsi(r.mmsi, "AIS report mmsi")
    _check("lat", r.lat, -90.0, 90.0, "deg")
    _check("lon", r.lon, -180.0, 180.0, "deg")
    _check("sog", r.sog, 0.0, 102.2 * KNOT, "m/s")
    _check("cog", r.cog, -4 * math.pi, 4 * math.pi, "rad")
    _check("heading", r.heading, -4 * math.pi, 4 * math.pi, "rad")
    cog = COG_NA_DEG if r.cog is None else round(math.degrees(r.cog % (2 * math.pi)), 1) % 360.0
    hdg = HEADING_NA if r.heading is None else round(math.degrees(r.heading % (2 * math.pi))) % 360
    fields = dict(msg_type=r.msg_type, mmsi=r.mmsi,
                  lat=91.0 if r.lat is None else r.lat, lon=181.0 if r.lon is None else r.lon,
                  speed=SOG_NA_KN if r.sog is None else round(r.sog / KNOT, 1),
                  course=cog, heading=hdg, second=min(max(int(r.second), 0), 63))
    if r.msg_type in (1, 2, 3):
        fields["status"] = r.status
        if r.rot is None:
            fields["turn"] = -128
        else:
            rot_deg_min = r.rot / DEG_PER_MIN  # pyais encodes ROT_AIS = round(4.733 √|ROT|)
            turn = math.copysign(min(abs(rot_deg_min), 708.0), rot_deg_min)
            if abs(turn) in (127.0, 128.0):  # pyais reads these as the codes ±127/−128: nudge off
                turn = math.nextafter(turn, 0.0)  # (same ROT_AIS: 4.733 √127 = 53.3, √128: 53.5)
            fields["turn"] = turn
    else:
        fields["cs"] = 1  # a Class B "CS" (carrier-sense) unit
    return fields


def encode_position(r: PositionReport, *, own: bool = False, channel: str = "A") -> list[str]:
    """NMEA sentences (``!AIVDO`` if ``own`` else ``!AIVDM``) of a position report."""
    from pyais.encode import encode_dict

    return encode_dict(position_fields(r), talker_id="AI", sentence_type="VDO" if own else "VDM",
                       radio_channel=channel)


def encode_static(s: StaticData, *, own: bool = False, channel: str = "A", seq_id: int = 0) -> list[str]:
    """NMEA sentences of static data: type 5 (two sentences) or, for ``msg_type=24``, parts A and B."""
    from pyais.encode import encode_dict

    check_mmsi(s.mmsi, "AIS static data mmsi")
    kind = "VDO" if own else "VDM"
    dims = dict(to_bow=min(s.to_bow, 511), to_stern=min(s.to_stern, 511), to_port=min(s.to_port, 63),
                to_starboard=min(s.to_starboard, 63))
    if s.msg_type == 24:
        a = encode_dict(dict(msg_type=24, mmsi=s.mmsi, partno=0, shipname=s.name[:20]), talker_id="AI",
                        sentence_type=kind, radio_channel=channel)
        b = encode_dict(dict(msg_type=24, mmsi=s.mmsi, partno=1, ship_type=s.ship_type,
                             callsign=s.callsign[:7], **dims), talker_id="AI", sentence_type=kind,
                        radio_channel=channel)
        return a + b
    if s.msg_type != 5:
        raise ConfigError(f"AIS static data msg_type = {s.msg_type}: must be 5 or 24")
    return encode_dict(dict(msg_type=5, mmsi=s.mmsi, shipname=s.name[:20], callsign=s.callsign[:7],
                            ship_type=s.ship_type, **dims), talker_id="AI", sentence_type=kind,
                       radio_channel=channel, seq_id=seq_id % 10)
