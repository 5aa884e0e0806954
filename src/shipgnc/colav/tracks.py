"""A target ship's track: the one form every source of targets gives the own ship's guidance.

A kinematic target (constant course and speed, or a schedule of them), an AIS report stream (decoded
from NMEA or a CSV log, or simulated from a true track with the AIS reporting rules) and a replayed
log all become a :class:`TargetTrack`: time-stamped samples of position and velocity over ground in the
local NED plane (north, east in metres; SI everywhere). Between samples a target is dead-reckoned from
the last sample at or before ``t`` (constant velocity), which is exact for a constant-velocity target
given one sample and is what a ship's collision avoidance does with AIS reports. Before its first
sample a target is absent: NaN states, left out of the avoidance and the range bookkeeping.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from shipgnc.errors import ConfigError


@dataclass(frozen=True)
class TargetTrack:
    """Samples of one target: ``t`` [s] strictly increasing, ``north``, ``east`` [m],
    ``v_north``, ``v_east`` [m/s] over ground; ``mmsi`` its identity, ``name`` for tables and
    figures, ``length``/``beam`` [m] for outlines and safety domains."""

    t: np.ndarray
    north: np.ndarray
    east: np.ndarray
    v_north: np.ndarray
    v_east: np.ndarray
    mmsi: int = 0
    name: str = ""
    length: float = 100.0
    beam: float = 20.0
    source: str = field(default="kinematic")

    def __post_init__(self) -> None:
        arrays = {}
        for name in ("t", "north", "east", "v_north", "v_east"):
            a = np.atleast_1d(np.asarray(getattr(self, name), dtype=float))
            if a.ndim != 1 or not np.all(np.isfinite(a)):
                raise ConfigError(f"target {self.label}: {name} must be a finite 1-D array")
            arrays[name] = a
            object.__setattr__(self, name, a)
        n = arrays["t"].size
        if n == 0 or any(a.size != n for a in arrays.values()):
            raise ConfigError(f"target {self.label}: t, north, east, v_north, v_east must have the "
                              f"same length ≥ 1, got {[a.size for a in arrays.values()]}")
        if n > 1 and np.any(np.diff(arrays["t"]) <= 0):
            k = int(np.argmax(np.diff(arrays["t"]) <= 0)) + 1
            raise ConfigError(f"target {self.label}: times must increase, sample {k} at "
                              f"t = {arrays['t'][k]:g} s follows t = {arrays['t'][k - 1]:g} s")

    @property
    def label(self) -> str:
        return self.name or (f"MMSI {self.mmsi}" if self.mmsi else "target")

    @classmethod
    def constant(cls, north: float, east: float, course: float, speed: float, *, t0: float = 0.0,
                 **kw) -> TargetTrack:
        """A target at (north, east) at ``t0`` holding ``course`` [rad, clockwise from north] and
        ``speed`` [m/s] over ground."""
        return cls(t=[t0], north=[north], east=[east], v_north=[speed * math.cos(course)],
                   v_east=[speed * math.sin(course)], **kw)

    def at(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(north, east, v_north, v_east) at times ``t``, dead-reckoned from the last sample at or
        before each time; NaN before the first sample (the target is not there yet: an AIS target
        exists from its first report on)."""
        t = np.asarray(t, dtype=float)
        k = np.clip(np.searchsorted(self.t, t, side="right") - 1, 0, self.t.size - 1)
        dt = t - self.t[k]
        absent = t < self.t[0]
        return tuple(np.where(absent, np.nan, a) for a in (
            self.north[k] + self.v_north[k] * dt, self.east[k] + self.v_east[k] * dt,
            self.v_north[k], self.v_east[k]))

    def table(self) -> np.ndarray:
        """The samples as one (n, 5) array ``[t, north, east, v_north, v_east]`` (for kernels)."""
        return np.column_stack([self.t, self.north, self.east, self.v_north, self.v_east])
