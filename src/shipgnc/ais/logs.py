"""A logged AIS file as target tracks: one :class:`~shipgnc.colav.tracks.TargetTrack` per MMSI in a
local plane.

Accepted files (UTF-8 text; blank lines and lines starting with ``#`` are skipped):

NMEA
    ``!AIVDM``/``!AIVDO`` sentences (any two-letter talker), one per line, multi-sentence messages on
    consecutive lines; each message's time [UTC] from, in this order:

    * an NMEA 4.0 tag block before the sentence, ``\\c:<unix time>[,...]*hh\\!AIVDM,...``
      (seconds, or milliseconds when above 10¹¹; the tag block's checksum is checked);
    * a leading time and a space, comma or semicolon: unix seconds or ISO 8601
      (``2024-01-15T06:30:00Z !AIVDM,...``; a time without zone is UTC);
    * the US Coast Guard's trailing fields, the last an integer unix time
      (``!AIVDM,...,0*5D,s28089,d-103,...,1242958962``).

    Read: message types 1, 2, 3, 18, 19 (positions) and 5, 24 (name and dimensions).

CSV
    A header line naming the columns (any order, case-insensitive; ``,`` ``;`` or tab separated):
    MMSI; time (``BaseDateTime``, ``# Timestamp``, ``timestamp``, ``time``, ``datetime``, ``t``:
    ISO 8601, ``dd/mm/yyyy HH:MM:SS`` as the Danish Maritime Authority writes it, or unix seconds);
    ``LAT``/``latitude`` and ``LON``/``longitude`` [deg]; ``SOG`` [kn]; ``COG`` [deg]; optional
    ``Heading`` [deg]. NOAA MarineCadastre and Danish Maritime Authority files read as they are.

A value the AIS message calls 'not available' (SOG 102.3 kn, COG 360°, heading 511, latitude 91°,
longitude 181°) or an empty field is missing: a report without a position is left out; one without
speed or course gets the velocity of its neighbouring positions (central difference), or, when the
speed is 0, none. Two reports of one MMSI at one time are one report if they agree (the same message
heard twice), an error if they differ.

Bad input raises :class:`~shipgnc.errors.ConfigError` naming the line and field: an unreadable line, a
message type not read (unless ``skip_unknown``), a sentence without a time, times of one MMSI going
back, an MMSI with no position report (left out with ``skip_unknown``).
"""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from shipgnc.ais import nmea
from shipgnc.colav.tracks import TargetTrack
from shipgnc.errors import ConfigError
from shipgnc.units import KNOT

_CHK = re.compile(r"\*[0-9A-Fa-f]{2}")
_AIS_HEAD = re.compile(r"^!([A-Z0-9]{2})(VDM|VDO),")  # talkers: AI, BS, B1, B2, ...


@dataclass(frozen=True)
class Report:
    """One decoded message: where it stood (``line``, the first of its sentences), its UTC time
    ``time`` [unix s], ``own`` for ``!AIVDO``."""

    line: int
    time: float
    msg: nmea.PositionReport | nmea.StaticData
    own: bool = False


def _parse_time(text: str, where: str) -> float:
    s = text.strip()
    try:
        return float(s)
    except ValueError:
        pass
    for fmt in ("%d/%m/%Y %H:%M:%S", "%d/%m/%Y %H:%M"):
        try:
            return datetime.strptime(s, fmt).replace(tzinfo=timezone.utc).timestamp()
        except ValueError:
            pass
    try:
        d = datetime.fromisoformat(s.replace("Z", "+00:00").replace(" ", "T", 1))
    except ValueError:
        raise ConfigError(f"{where} = {text.strip()!r}: not a time (unix seconds, ISO 8601 or "
                          "dd/mm/yyyy HH:MM:SS)") from None
    if d.tzinfo is None:
        d = d.replace(tzinfo=timezone.utc)
    return d.timestamp()


def _split_nmea_line(raw: str, where: str) -> tuple[str, float | None]:
    """(sentence, time or None) of one NMEA line, the time from a tag block, a leading time or the
    USCG trailing fields."""
    from pyais.messages import TagBlock

    line, time = raw.strip(), None
    if line.startswith("\\"):
        end = line.find("\\", 1)
        if end < 0:
            raise ConfigError(f"{where}: tag block '\\…' without its closing backslash")
        tb = TagBlock(line[1:end].encode("ascii", "replace"))
        tb.init()
        if not tb.is_valid:
            raise ConfigError(f"{where}: tag block {line[:end + 1]!r} has a wrong or missing checksum")
        if tb.receiver_timestamp is not None:
            c = _parse_time(tb.receiver_timestamp, f"{where}: tag block time c")
            time = c / 1000.0 if c > 1e11 else c
        line = line[end + 1:].strip()
    elif not line.startswith("!") and "!" in line:
        head, line = line[:line.index("!")], line[line.index("!"):]
        time = _parse_time(head.strip().rstrip(",;").strip(), f"{where}: leading time")
    m = _CHK.search(line)
    if m and m.end() < len(line):  # fields after the checksum: the USCG format ends with unix time
        trailing = line[m.end():].split(",")
        line = line[:m.end()]
        if time is None and trailing[-1].strip().isdigit():
            time = float(trailing[-1])
    return line, time


def _read_nmea(lines: list[str], skip_unknown: bool, untimed: str = "refuse") -> list[Report]:
    import pyais
    from pyais.exceptions import AISBaseException

    out: list[Report] = []
    last_time = None  # the latest line's time: an untimed message's with untimed = "previous"
    pending: dict[tuple, tuple[int, float | None, list[str]]] = {}
    for no, raw in enumerate(lines, start=1):
        if not raw.strip() or raw.lstrip().startswith("#"):
            continue
        where = f"line {no}"
        sentence, time = _split_nmea_line(raw, where)
        if time is not None:
            last_time = time
        elif untimed == "previous":
            time = last_time
        head = _AIS_HEAD.match(sentence)
        if head is None:
            if skip_unknown:
                continue
            raise ConfigError(f"{where}: {sentence[:24]!r}… is not an AIS sentence (!AIVDM or !AIVDO)")
        parts = sentence.split(",")
        try:
            count, num = int(parts[1]), int(parts[2])
        except (IndexError, ValueError):
            raise ConfigError(f"{where}: {sentence[:40]!r}: fragment count and number unreadable") from None
        key = (head.group(2), parts[3], parts[4] if len(parts) > 4 else "")
        if count > 1:
            if num == 1:
                pending[key] = (no, time, [sentence])
                continue
            first = pending.get(key)
            if first is None or len(first[2]) != num - 1:
                raise ConfigError(f"{where}: fragment {num} of {count} without the fragments before it")
            first[2].append(sentence)
            if num < count:
                continue
            del pending[key]
            msg_line, time, frags = first
        else:
            msg_line, frags = no, [sentence]
        where = f"line {msg_line}"
        try:
            msg = pyais.decode(*frags, error_if_checksum_invalid=True)
        except (AISBaseException, ValueError, IndexError, KeyError, TypeError) as exc:
            if skip_unknown:
                continue
            raise ConfigError(f"{where}: not a readable AIS sentence "
                              f"({type(exc).__name__}: {exc})") from None
        try:
            decoded = nmea.from_message(msg)
        except ConfigError as exc:
            if skip_unknown:
                continue
            raise ConfigError(f"{where}: {exc} (skip_unknown / --skip-unknown leaves such "
                              "lines out)") from None
        if time is None:
            raise ConfigError(f"{where}: no time for this message: put an NMEA 4.0 tag block "
                              "'\\c:<unix time>*hh\\' or a leading time before the sentence"
                              + (" (untimed = 'previous': no line before it has one)"
                                 if untimed == "previous" else ""))
        out.append(Report(line=msg_line, time=time, msg=decoded, own=head.group(2) == "VDO"))
    if pending:
        line, _, frags = min(pending.values())
        raise ConfigError(f"line {line}: a message of {frags[0].split(',')[1]} fragments ends after "
                          f"fragment {len(frags)}")
    return out


_COLUMNS = {
    "mmsi": ("mmsi",),
    "time": ("basedatetime", "base_date_time", "# timestamp", "timestamp", "time", "datetime", "t"),
    "lat": ("lat", "latitude"),
    "lon": ("lon", "long", "longitude"),
    "sog": ("sog",),
    "cog": ("cog",),
    "heading": ("heading", "true_heading", "hdg"),
}


def _number(text: str, where: str) -> float | None:
    s = text.strip()
    if s == "" or s.lower() in ("nan", "na", "none", "unknown"):
        return None
    try:
        v = float(s)
    except ValueError:
        raise ConfigError(f"{where} = {s!r}: not a number") from None
    if not math.isfinite(v):
        return None
    return v


def _read_csv(lines: list[str]) -> list[Report]:
    first = next(i for i, ln in enumerate(lines) if ln.strip())
    header_line = lines[first]
    delim = max((",", ";", "\t"), key=header_line.count)
    rows = csv.reader(lines[first:], delimiter=delim)
    header = [h.strip().lower() for h in next(rows)]
    col = {}
    for field, names in _COLUMNS.items():
        hit = next((header.index(n) for n in names if n in header), None)
        if hit is None and field != "heading":
            raise ConfigError(f"CSV header (line {first + 1}) has no {field} column; accepted names: "
                              f"{', '.join(names)}")
        col[field] = hit
    out: list[Report] = []
    for no, row in enumerate(rows, start=first + 2):
        if not row or not any(c.strip() for c in row) or row[0].lstrip().startswith("#"):
            continue
        if len(row) < len(header):
            raise ConfigError(f"line {no}: {len(row)} fields, the header names {len(header)}")
        name = {f: header[i] for f, i in col.items() if i is not None}
        try:
            mmsi = int(row[col["mmsi"]].strip())
        except ValueError:
            raise ConfigError(f"line {no}: field {name['mmsi']} = {row[col['mmsi']]!r}: "
                              "not an MMSI") from None
        time = _parse_time(row[col["time"]], f"line {no}: field {name['time']}")
        v = {f: _number(row[col[f]], f"line {no}: field {name[f]}") for f in ("lat", "lon", "sog", "cog")}
        hdg = None
        if col["heading"] is not None:
            hdg = _number(row[col["heading"]], f"line {no}: field {name['heading']}")
        lat, lon = v["lat"], v["lon"]
        if lat is not None and lon is not None and (abs(lat) > 90 or abs(lon) > 180):
            if abs(lat) >= 91 or abs(lon) >= 181:  # the 'not available' codes
                lat = lon = None
            else:
                raise ConfigError(f"line {no}: ({lat:g}, {lon:g}): latitude must be within ±90° and "
                                  "longitude within ±180°")
        sog_kn = v["sog"]
        sog = None if sog_kn is None or not 0 <= sog_kn < nmea.SOG_NA_KN - 1e-9 else sog_kn * KNOT
        cog = None if v["cog"] is None or not 0 <= v["cog"] < 360.0 else math.radians(v["cog"])
        heading = None if hdg is None or not 0 <= hdg < 360.0 else math.radians(hdg)
        out.append(Report(line=no, time=time, msg=nmea.PositionReport(
            mmsi=mmsi, lat=None if lon is None else lat, lon=None if lat is None else lon, sog=sog, cog=cog,
            heading=heading, msg_type=0)))  # msg_type 0: a CSV row, not a message
    return out


def read_reports(path, *, skip_unknown: bool = False, untimed: str = "refuse") -> list[Report]:
    """Every message of a logged AIS file (NMEA or CSV, see the module) in file order.

    ``untimed``: a message with no time of its own is refused (``"refuse"``), or takes the time
    of the latest line before it that has one (``"previous"``: a feed that stamps most lines, such
    as the Norwegian Coastal Administration's, where about one line in eight comes without a tag
    block; its time is then late or early by the feed's spacing, a second or so)."""
    if untimed not in ("refuse", "previous"):
        raise ConfigError(f"untimed = {untimed!r}: allowed: refuse, previous")
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8", errors="strict")
    except FileNotFoundError:
        raise ConfigError(f"AIS log {p}: no such file") from None
    except (UnicodeDecodeError, IsADirectoryError) as exc:
        raise ConfigError(f"AIS log {p}: not a UTF-8 text file ({type(exc).__name__})") from None
    lines = text.splitlines()
    body = [ln.strip() for ln in lines if ln.strip()]
    if not body:
        raise ConfigError(f"AIS log {p}: empty")
    first = body[0]
    try:
        if "mmsi" in first.lower() and "!" not in first:
            return _read_csv(lines)
        return _read_nmea(lines, skip_unknown, untimed)
    except ConfigError as exc:
        raise ConfigError(f"AIS log {p}: {exc}") from None


def _velocities(t, north, east, vn, ve, lines, mmsi) -> tuple[np.ndarray, np.ndarray]:
    """Plane velocities where reported, else the central difference of the neighbouring positions."""
    missing = ~(np.isfinite(vn) & np.isfinite(ve))
    if not missing.any():
        return vn, ve
    if t.size < 2:
        raise ConfigError(f"line {lines[0]}: MMSI {mmsi} has no speed or course and no second position "
                          "to derive them from")
    dn, de = np.gradient(north, t), np.gradient(east, t)
    return np.where(missing, dn, vn), np.where(missing, de, ve)


def read_log(path, *, origin=None, skip_unknown: bool = False, t0: float | None = None,
             reports: list[Report] | None = None, untimed: str = "refuse",
             left_out: list[int] | None = None) -> tuple[list[TargetTrack], tuple[float, float]]:
    """The targets of a logged AIS file, one track per MMSI (sorted by MMSI), and the origin.

    Positions are in the local plane about ``origin`` (lat, lon) [deg] — given, or the centre of the
    data (:func:`shipgnc.ais.plane.centre`, the mean of the reports' earth-centred unit vectors) —
    the geo router's projection (:class:`shipgnc.ais.plane.LocalPlane`); a ship's report farther
    than 60 km from it is a ConfigError naming its MMSI and distance. Velocities over ground are
    turned into the plane's axes. Times are seconds after ``t0`` [unix s] (default: the file's
    earliest message). Names and lengths come
    from static data (types 5, 24) where the file has them. ``!AIVDO`` tracks (the logging ship) have
    ``source = "ais-own"``, the others ``"ais"``. ``reports``: the file's reports if already read
    (:func:`read_reports`); ``untimed``: as :func:`read_reports` takes it. An MMSI heard only by
    its static data (no position report) is an error, or with ``skip_unknown`` left out and added
    to ``left_out`` (when given)."""
    from shipgnc.ais.plane import LocalPlane, centre, check_origin, check_range

    if reports is None:
        reports = read_reports(path, skip_unknown=skip_unknown, untimed=untimed)
    where = f"AIS log {Path(path)}"
    by_mmsi: dict[int, list[Report]] = {}
    static: dict[int, dict] = {}
    first_line: dict[int, int] = {}
    for r in reports:
        first_line.setdefault(r.msg.mmsi, r.line)
        if isinstance(r.msg, nmea.StaticData):
            s = static.setdefault(r.msg.mmsi, {})
            if r.msg.name:
                s["name"] = r.msg.name
            if r.msg.length:
                s["length"] = r.msg.length
            if r.msg.beam:
                s["beam"] = r.msg.beam
            continue
        if r.msg.has_position:
            by_mmsi.setdefault(r.msg.mmsi, []).append(r)
    for mmsi, line in sorted(first_line.items(), key=lambda kv: kv[1]):
        if mmsi not in by_mmsi and not skip_unknown:
            raise ConfigError(f"{where}: MMSI {mmsi} (first at line {line}) has no position report "
                              "(--skip-unknown leaves it out)")
        if mmsi not in by_mmsi and left_out is not None:
            left_out.append(mmsi)
    if not by_mmsi:
        raise ConfigError(f"{where}: no position report in the file")
    lat_all = np.array([r.msg.lat for rs in by_mmsi.values() for r in rs])
    lon_all = np.array([r.msg.lon for rs in by_mmsi.values() for r in rs])
    if origin is None:
        origin = centre(lat_all, lon_all)
    origin = check_origin(origin)
    plane = LocalPlane(origin)
    for mmsi in sorted(by_mmsi):
        check_range(origin, [r.msg.lat for r in by_mmsi[mmsi]], [r.msg.lon for r in by_mmsi[mmsi]],
                    f"{where}: MMSI {mmsi}")
    if t0 is None:
        t0 = min(r.time for r in reports)
    tracks = []
    for mmsi in sorted(by_mmsi):
        kept: list[Report] = []
        for r in by_mmsi[mmsi]:
            if kept and r.time < kept[-1].time:
                raise ConfigError(f"{where}: line {r.line}: MMSI {mmsi} at {utc_text(r.time)} is earlier "
                                  f"than its report at line {kept[-1].line} ({utc_text(kept[-1].time)}); "
                                  "times must not go back")
            if kept and r.time == kept[-1].time:
                a, b = kept[-1].msg, r.msg
                if (a.lat, a.lon, a.sog, a.cog) == (b.lat, b.lon, b.sog, b.cog):
                    continue  # the same report heard twice
                raise ConfigError(f"{where}: line {r.line}: MMSI {mmsi} reports a different position at "
                                  f"the time of line {kept[-1].line} ({utc_text(r.time)})")
            kept.append(r)
        t = np.array([r.time for r in kept]) - t0
        lat = np.array([r.msg.lat for r in kept])
        lon = np.array([r.msg.lon for r in kept])
        sog = np.array([np.nan if r.msg.sog is None else r.msg.sog for r in kept])
        cog = np.array([np.nan if r.msg.cog is None else r.msg.cog for r in kept])
        cog = np.where(np.isnan(cog) & (sog == 0.0), 0.0, cog)  # at rest: no course needed
        north, east = plane.to_plane(lat, lon)
        vn, ve = plane.velocity_to_plane(lat, lon, sog, cog)
        vn, ve = _velocities(t, north, east, vn, ve, [r.line for r in kept], mmsi)
        s = static.get(mmsi, {})
        tracks.append(TargetTrack(t=t, north=north, east=east, v_north=vn, v_east=ve, mmsi=mmsi,
                                  name=s.get("name", ""), length=s.get("length", 100.0),
                                  beam=s.get("beam", 20.0),
                                  source="ais-own" if any(r.own for r in kept) else "ais"))
    return tracks, origin


def utc_text(t: float) -> str:
    """A unix time as ISO 8601 UTC to the hundredth of a second."""
    return datetime.fromtimestamp(t, tz=timezone.utc).strftime("%Y-%m-%dT%H:%M:%S.%f")[:-4] + "Z"
