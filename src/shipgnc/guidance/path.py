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


class LegTracker:
    """Active leg of each ship on a :class:`WaypointPath` and its path-frame position.

    Switching rule of spec 000 (A6): leg i + 1 becomes active once x_r ≥ |P_i P_{i+1}| on leg i
    (the ship crosses the normal through P_{i+1}); several switches in one sample are allowed;
    the last leg is a half-line. Batched: one leg index per ship.
    """

    def __init__(self, path: WaypointPath):
        require(isinstance(path, WaypointPath), "controller.path", type(path).__name__,
                "must be a WaypointPath")
        self.path = path
        self.leg: np.ndarray | None = None

    def reset(self, batch_shape) -> None:
        self.leg = np.zeros(tuple(batch_shape), dtype=int)

    def update(self, north, east) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Switch legs where due; return along-track x_r, cross-track y_r [m] and the leg angle ψ_r0."""
        require(self.leg is not None, "controller", "LegTracker", "call reset(batch_shape) first")
        path = self.path
        last = path.n_legs - 1
        leg = np.broadcast_to(self.leg, np.shape(north)).copy()
        for _ in range(path.n_legs):
            x_r, y_r = path.project(north, east, leg)
            switch = (leg < last) & (x_r >= path.leg_lengths[leg])
            if not np.any(switch):
                break
            leg = np.where(switch, leg + 1, leg)
        else:
            x_r, y_r = path.project(north, east, leg)
        self.leg = leg
        return np.asarray(x_r, dtype=float), np.asarray(y_r, dtype=float), path.leg_angles[leg]
