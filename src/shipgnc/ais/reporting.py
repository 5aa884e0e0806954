"""What the own ship sees of a target through AIS: reports at the intervals the AIS standard sets,
position noise, lost reports, and every value quantised by the message.

Reporting intervals (ITU-R M.1371-5, Annex 1, Table 1 for Class A; Table 2 for Class B):

==========================================  =======  ============  ============
ship's dynamic condition                    Class A  Class B "SO"  Class B "CS"
==========================================  =======  ============  ============
at anchor or moored, not faster than 3 kn   3 min    —             —
at anchor or moored, faster than 3 kn       10 s     —             —
not faster than 2 kn (Class B)              —        3 min         3 min
0–14 kn (Class B: 2–14 kn)                  10 s     30 s          30 s
0–14 kn and changing course                 3⅓ s     30 s          30 s
14–23 kn                                    6 s      15 s          30 s
14–23 kn and changing course                2 s      15 s          30 s
faster than 23 kn (changing course or not)  2 s      5 s           30 s
==========================================  =======  ============  ============

"Changing course" is a rate of turn above ``turning`` (default 5° per 30 s, the rate beyond which
the message's ROT field reads "turning, more than 5°/30 s", ITU-R M.1371-5 Annex 8 Table 45); the
table's bounds are read as 0 ≤ v ≤ 14 kn, 14 < v ≤ 23 kn, v > 23 kn.
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.colav.tracks import TargetTrack
from shipgnc.errors import ConfigError
from shipgnc.units import KNOT

CLASSES = ("A", "B-SO", "B-CS")
TURNING = math.radians(5.0) / 30.0  #: rad/s: 5° per 30 s


def interval(speed: float, rot: float = 0.0, *, ais_class: str = "A", anchored: bool = False,
             turning: float = TURNING) -> float:
    """The reporting interval [s] of a ship at ``speed`` [m/s] over ground turning at ``rot`` [rad/s]
    (see the module's table)."""
    if ais_class not in CLASSES:
        raise ConfigError(f"ais_class = {ais_class!r}: must be one of {', '.join(CLASSES)}")
    if not (math.isfinite(speed) and speed >= 0):
        raise ConfigError(f"speed = {speed!r}: must be a finite speed ≥ 0 m/s")
    kn = speed / KNOT
    changing = abs(rot) > turning
    if ais_class == "A":
        if anchored:
            return 180.0 if kn <= 3.0 else 10.0
        if kn <= 14.0:
            return 10.0 / 3.0 if changing else 10.0
        if kn <= 23.0:
            return 2.0 if changing else 6.0
        return 2.0
    if kn <= 2.0:
        return 180.0
    if ais_class == "B-CS":
        return 30.0
    return 30.0 if kn <= 14.0 else 15.0 if kn <= 23.0 else 5.0


def turn_rates(t, course) -> np.ndarray:
    """Rate of course change [rad/s] over each interval of the samples ``t`` [s], ``course`` [rad]
    (the last interval's for the last sample; 0 for a single sample)."""
    t, course = np.asarray(t, float), np.asarray(course, float)
    if t.size < 2:
        return np.zeros(t.size)
    dc = np.mod(np.diff(course) + math.pi, 2 * math.pi) - math.pi
    rate = dc / np.diff(t)
    return np.append(rate, rate[-1])


def _turn_rates(track: TargetTrack) -> np.ndarray:
    """:func:`turn_rates` of a track's samples."""
    return turn_rates(track.t, np.arctan2(track.v_east, track.v_north))


def report_times(track: TargetTrack, *, t_end: float, t_start: float | None = None, ais_class: str = "A",
                 anchored: bool = False, turning: float = TURNING,
                 every: float | None = None) -> np.ndarray:
    """The times [s] a target transmits between ``t_start`` (default, and at the earliest, its first
    sample) and ``t_end`` inclusive: each report schedules the next one an interval later, the
    interval set by the speed and rate of turn at the report — or ``every`` [s], a fixed interval
    (None: the standard's)."""
    t = float(track.t[0] if t_start is None else max(t_start, track.t[0]))  # none before it exists
    if not (math.isfinite(t_end) and t_end >= t):
        raise ConfigError(f"t_end = {t_end!r}: must be a finite time ≥ the first report at t = {t:g} s")
    if every is not None:
        if not (math.isfinite(every) and every > 0):
            raise ConfigError(f"every = {every!r}: must be a fixed reporting interval > 0 s, or None")
        return t + every * np.arange(math.floor((t_end - t) / every + 1e-9) + 1)
    rates = _turn_rates(track)
    times = []
    while t <= t_end + 1e-9:
        times.append(t)
        _, _, vn, ve = track.at(t)
        k = int(np.clip(np.searchsorted(track.t, t, side="right") - 1, 0, track.t.size - 1))
        t += interval(float(math.hypot(vn, ve)), float(rates[k]), ais_class=ais_class, anchored=anchored,
                      turning=turning)
    return np.asarray(times)


def observe(track: TargetTrack, *, seed: int, position_noise_m: float = 0.0, dropout: float = 0.0,
            t_end: float, t_start: float | None = None, ais_class: str = "A", anchored: bool = False,
            origin=(0.0, 0.0), turning: float = TURNING, every: float | None = None,
            lost_ok: bool = False) -> TargetTrack | None:
    """The target as the own ship's AIS receiver sees it.

    Reports at :func:`report_times` (``every``: a fixed interval [s] instead of the standard's);
    each is lost with probability ``dropout`` (independently); the
    position of a received one is the true one plus Gaussian noise of standard deviation
    ``position_noise_m`` [m] in north and in east; then position, speed and course go through the
    message (:func:`shipgnc.ais.nmea.encode_position` → ``decode``, positions placed on the earth with
    the local plane about ``origin``), so they carry the message's resolution (1/10 000 min, 0.1 kn,
    0.1°). The same ``seed`` (an int or a ``numpy.random.SeedSequence``) gives the same reports.
    Every report lost: None with ``lost_ok``, else a ConfigError."""
    from shipgnc.ais import nmea
    from shipgnc.ais.plane import LocalPlane

    if not (math.isfinite(position_noise_m) and position_noise_m >= 0):
        raise ConfigError(f"position_noise_m = {position_noise_m!r}: must be a finite length ≥ 0 m")
    if not (0.0 <= dropout < 1.0):
        raise ConfigError(f"dropout = {dropout!r}: must be a probability in [0, 1)")
    times = report_times(track, t_end=t_end, t_start=t_start, ais_class=ais_class, anchored=anchored,
                         turning=turning, every=every)
    rng = np.random.default_rng(seed)
    kept = rng.random(times.size) >= dropout
    noise = rng.normal(0.0, 1.0, (times.size, 2)) * position_noise_m
    times, noise = times[kept], noise[kept]
    if times.size == 0:
        if lost_ok:
            return None
        raise ConfigError(f"target {track.label}: every one of its AIS reports was lost "
                          f"(dropout = {dropout:g})")
    north, east, vn, ve = track.at(times)
    k = np.clip(np.searchsorted(track.t, times, side="right") - 1, 0, track.t.size - 1)
    rates = _turn_rates(track)[k]
    plane = LocalPlane(origin)
    lat, lon = plane.to_geo(north + noise[:, 0], east + noise[:, 1])
    sog, cog = plane.velocity_to_true(lat, lon, vn, ve)
    msg_type = 1 if ais_class == "A" else 18
    mmsi = track.mmsi or 999999999
    out = np.empty((times.size, 4))
    for i in range(times.size):
        r = nmea.PositionReport(mmsi=mmsi, lat=float(lat[i]), lon=float(lon[i]),
                                sog=min(float(sog[i]), 102.2 * KNOT), cog=float(cog[i]),
                                heading=float(cog[i]), rot=float(rates[i]), msg_type=msg_type,
                                status=5 if anchored else 0,
                                second=int(times[i]) % 60)
        d = nmea.decode(*nmea.encode_position(r))
        out[i] = d.lat, d.lon, d.sog, d.cog
    n, e = plane.to_plane(out[:, 0], out[:, 1])
    v_n, v_e = plane.velocity_to_plane(out[:, 0], out[:, 1], out[:, 2], out[:, 3])
    return TargetTrack(t=times, north=n, east=e, v_north=v_n, v_east=v_e, mmsi=track.mmsi,
                       name=track.name, length=track.length, beam=track.beam, source="ais")


def seen_tracks(tracks, *, seed: int, t_end: float, member: int | tuple = 0, **options) -> list:
    """What the own ship's AIS receiver makes of each of ``tracks`` (:func:`observe` with
    ``options``) up to ``t_end`` [s]: one :class:`TargetTrack` per target, or None for a target
    every one of whose reports was lost (never heard, so never avoided). Target ``j`` of batch
    member ``member`` (a number, or a tuple of numbers such as (situation, variant)) draws from
    ``SeedSequence([seed, *member, j])``: the same seed gives the same reports, and adding a target
    or a member leaves the others' reports as they were."""
    key = [int(k) for k in (member if isinstance(member, tuple) else (member,))]
    out = []
    for j, track in enumerate(tracks):
        if track.t[0] > t_end:  # appears after the run: never heard
            out.append(None)
            continue
        rng_seed = np.random.SeedSequence([int(seed), *key, j])
        out.append(observe(track, seed=rng_seed, t_end=t_end, lost_ok=True, **options))
    return out
