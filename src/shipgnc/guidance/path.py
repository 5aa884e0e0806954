"""Waypoint paths: straight legs between waypoints in NED, with the path-fixed frame."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from shipgnc.errors import require
from shipgnc.frames import path_frame


@dataclass(frozen=True, eq=False)
class WaypointPath:
    """A polyline through ``waypoints`` (array (k, 2) of [north, east] in m), k ≥ 2."""

    waypoints: np.ndarray

    def __post_init__(self) -> None:
        wp = np.asarray(self.waypoints, dtype=float)
        require(wp.ndim == 2 and wp.shape[1] == 2 and wp.shape[0] >= 2, "guidance.waypoints",
                wp.tolist() if wp.size < 40 else wp.shape,
                "need at least two [north, east] pairs")
        require(bool(np.all(np.isfinite(wp))), "guidance.waypoints", wp.tolist(),
                "coordinates must be finite")
        lengths = np.hypot(*np.diff(wp, axis=0).T)
        bad = np.flatnonzero(lengths <= 0)
        require(bad.size == 0, "guidance.waypoints",
                wp[bad[0]].tolist() if bad.size else None,
                "consecutive waypoints must differ (zero-length leg)")
        object.__setattr__(self, "waypoints", wp)
        d = np.diff(wp, axis=0)
        #: length of each leg [m]
        object.__setattr__(self, "leg_lengths", lengths)
        #: path angle π_p of each leg, clockwise from north [rad]
        object.__setattr__(self, "leg_angles", np.arctan2(d[:, 1], d[:, 0]))

    @property
    def n_legs(self) -> int:
        return self.waypoints.shape[0] - 1

    def project(self, north, east, leg):
        """Along-track ``s`` and cross-track ``e`` (positive to starboard) on leg ``leg`` (batched)."""
        leg = np.asarray(leg)
        start = self.waypoints[leg]
        return path_frame(north, east, start[..., 0], start[..., 1], self.leg_angles[leg])
