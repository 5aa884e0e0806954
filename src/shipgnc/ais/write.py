"""The own ship and its targets as an NMEA AIS log for a chart plotter to replay.

The own ship's reports are ``!AIVDO`` (an AIS unit's own-vessel sentence), the targets' ``!AIVDM``:
position reports (type 1, Class A) at the reporting intervals of ITU-R M.1371-5 Table 1 by speed and
rate of turn (:func:`shipgnc.ais.reporting.interval`) or a fixed ``interval``, and static data (type 5:
name, dimensions) with the first report and every 6 minutes (the Class A static-data interval of
ITU-R M.1371-5 Annex 2 §4.3.1).

Each line carries its UTC time as an NMEA 4.10 tag block, ``\\c:<unix seconds>*hh\\!AIVDM,...``, so
the log replays in time (``shipgnc.ais.logs.read_log`` and the tools that read tag blocks: pyais,
libais, gpsd). Report times are whole seconds, as the tag block's ``c`` field is: an interval of 3⅓ s
is written as 3 s. OpenCPN reads ``!AIVDM``/``!AIVDO`` from a file through its VDR plug-in, which
replays line by line at a rate it is given rather than by these times; OpenCPN's issue tracker reports
sentences with a tag block being dropped (OpenCPN issue 4692), so ``tag_blocks=False`` writes the plain
sentences, one report per line in time order, for it.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from shipgnc.ais import nmea
from shipgnc.ais.reporting import interval as ais_interval
from shipgnc.ais.reporting import turn_rates
from shipgnc.colav.tracks import TargetTrack
from shipgnc.errors import ConfigError

STATIC_EVERY = 360.0  #: s between static-data messages (ITU-R M.1371-5: every 6 min)
_KEYS = ("north", "east", "sog", "cog")


def tag_block(unix_time: float) -> str:
    """``\\c:<unix seconds>*hh\\``: the NMEA 4.10 tag block of a receiver time (checksum: XOR of the
    characters between the backslash and ``*``, two hex digits)."""
    from pyais.util import checksum

    payload = f"c:{round(unix_time)}"
    return f"\\{payload}*{checksum(payload.encode()):02X}\\"


def _ship(name: str, t: np.ndarray, ship) -> dict:
    """Arrays north, east [m], sog [m/s], cog, heading [rad, plane] at the samples ``t``."""
    if isinstance(ship, TargetTrack):
        n, e, vn, ve = ship.at(t)
        cog = np.mod(np.arctan2(ve, vn), 2 * np.pi)
        return dict(north=n, east=e, sog=np.hypot(vn, ve), cog=cog, heading=cog)
    if not isinstance(ship, dict):
        raise ConfigError(f"{name}: must be a dict of arrays (north, east, sog, cog[, heading]) or a "
                          "TargetTrack")
    missing = [k for k in _KEYS if k not in ship]
    if missing:
        raise ConfigError(f"{name}: no {', '.join(missing)} (needs north, east [m], sog [m/s], cog [rad]; "
                          "heading [rad] optional)")
    out = {}
    for k in (*_KEYS, "heading"):
        if k not in ship:
            continue
        a = np.broadcast_to(np.asarray(ship[k], float), t.shape)
        if not np.all(np.isfinite(a)):
            raise ConfigError(f"{name}.{k}: must be finite at every one of the {t.size} times")
        out[k] = a
    if np.any(out["sog"] < 0):
        raise ConfigError(f"{name}.sog: must be ≥ 0 m/s")
    out.setdefault("heading", out["cog"])
    return out


def _report_indices(t: np.ndarray, sog: np.ndarray, cog: np.ndarray, interval: float | None) -> np.ndarray:
    """Sample indices of the reports: the first sample, then each the interval after the last, in
    whole seconds."""
    rot = turn_rates(t, cog)
    idx, tr = [], float(t[0])
    while tr <= t[-1] + 1e-9:
        k = int(np.searchsorted(t, tr - 1e-9))
        if k >= t.size:
            break
        idx.append(k)
        step = interval if interval is not None else ais_interval(float(sog[k]), float(rot[k]))
        tr = float(t[k]) + max(1.0, round(step))
    return np.asarray(idx, dtype=int)


def write_log(path, t, own: dict, targets, origin, own_mmsi: int, target_mmsis, interval: float | None = None,
              *, start_time: float = 1.7e9, names=None, tag_blocks: bool = True, lengths=None) -> Path:
    """Write the own ship (``!AIVDO``) and the targets (``!AIVDM``) as an NMEA AIS log.

    ``t`` [s]: sample times (increasing); ``own``: dict of arrays at ``t``: ``north``, ``east`` [m] in
    the local plane about ``origin`` (lat, lon) [deg], ``sog`` [m/s], ``cog`` and optional ``heading``
    [rad, clockwise from the plane's north]; ``targets``: such dicts or
    :class:`~shipgnc.colav.tracks.TargetTrack` (evaluated at ``t``); ``target_mmsis``: one MMSI each.
    ``interval`` [s]: fixed reporting interval, or None for the AIS rules. ``start_time``: the unix time
    of ``t[0]`` (whole seconds). ``names``: the ships' names (own first) for the static data;
    ``lengths``: (length, beam) [m] each (own first). Returns the path."""
    from shipgnc.ais.plane import LocalPlane

    t = np.asarray(t, float)
    if t.ndim != 1 or t.size == 0 or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise ConfigError("t: must be a 1-D array of increasing finite times [s]")
    if interval is not None and not (math.isfinite(interval) and interval >= 1.0):
        raise ConfigError(f"interval = {interval!r}: must be ≥ 1 s, or None for the AIS reporting rules")
    targets = list(targets)
    mmsis = [int(own_mmsi), *(int(m) for m in target_mmsis)]
    if len(mmsis) != len(targets) + 1:
        raise ConfigError(f"target_mmsis: {len(mmsis) - 1} MMSIs for {len(targets)} targets")
    if len(set(mmsis)) != len(mmsis):
        raise ConfigError(f"own_mmsi, target_mmsis = {mmsis}: every ship needs its own MMSI")
    for m in mmsis:
        nmea.check_mmsi(m, "MMSI")
    if names is None:
        names = ["OWN SHIP", *(f"TARGET {i + 1}" for i in range(len(targets)))]
    names = list(names)
    lengths = list(lengths) if lengths is not None else [None] * len(mmsis)
    plane = LocalPlane(origin)
    ships = [_ship("own", t, own), *(_ship(f"targets[{i}]", t, s) for i, s in enumerate(targets))]
    lines: list[tuple[float, int, list[str]]] = []
    for j, (ship, mmsi) in enumerate(zip(ships, mmsis, strict=True)):
        is_own = j == 0
        present = np.flatnonzero(np.isfinite(ship["north"]))  # a track reports from its first sample
        if present.size == 0:
            continue
        idx = present[_report_indices(t[present], ship["sog"][present], ship["cog"][present],
                                      interval)]
        # the report's time is the tag block's whole second: the position is interpolated there
        unix_all = np.round(start_time + t[idx] - t[0])
        t_rep = unix_all - start_time + t[0]
        lat, lon = plane.to_geo(np.interp(t_rep, t[present], ship["north"][present]),
                                np.interp(t_rep, t[present], ship["east"][present]))
        vn, ve = ship["sog"][idx] * np.cos(ship["cog"][idx]), ship["sog"][idx] * np.sin(ship["cog"][idx])
        sog, cog = plane.velocity_to_true(lat, lon, vn, ve)
        hdg = plane.heading_to_true(lat, lon, ship["heading"][idx])
        if np.any(sog > 102.2 * nmea.KNOT):
            raise ConfigError(f"{names[j]}: speed {sog.max():.1f} m/s is beyond what AIS can report "
                              "(102.2 kn)")
        dims = lengths[j]
        half = {} if dims is None else dict(to_bow=round(dims[0] / 2), to_stern=round(dims[0] / 2),
                                            to_port=round(dims[1] / 2), to_starboard=round(dims[1] / 2))
        static = nmea.StaticData(mmsi=mmsi, name=str(names[j]).upper()[:20], msg_type=5, **half)
        last_static = -math.inf
        for i in range(idx.size):
            unix = float(unix_all[i])
            if unix - last_static >= STATIC_EVERY:
                lines.append((unix, j, nmea.encode_static(static, own=is_own, seq_id=j)))
                last_static = unix
            r = nmea.PositionReport(mmsi=mmsi, lat=float(lat[i]), lon=float(lon[i]), sog=float(sog[i]),
                                    cog=float(cog[i]), heading=float(hdg[i]), msg_type=1, status=0,
                                    second=round(unix) % 60)
            lines.append((unix, j, nmea.encode_position(r, own=is_own)))
    lines.sort(key=lambda x: (x[0], x[1]))
    p = Path(path)
    with p.open("w", encoding="ascii", newline="\n") as f:
        for unix, _, sentences in lines:
            for s in sentences:
                f.write((tag_block(unix) + s if tag_blocks else s) + "\n")
    return p
