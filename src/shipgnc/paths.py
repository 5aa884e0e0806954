"""Waypoint paths: straight legs between waypoints in NED, with the path-fixed frame; the leg
tracker of document 000 (A6) and its scalar form for component kernels (:func:`track_leg`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from shipgnc.errors import require
from shipgnc.frames import path_frame
from shipgnc.kernels import flat, kernel_function


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

    Switching rule of document 000 (A6): leg i + 1 becomes active once x_r ≥ |P_i P_{i+1}| on leg i
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


# ----------------------------------------------------------------------------------------------
# the leg tracker for component kernels (shipgnc.kernels)
# ----------------------------------------------------------------------------------------------

def leg_table(path: WaypointPath) -> np.ndarray:
    """A path's legs as a flat parameter block for :func:`track_leg`: ``[n, start north (n),
    start east (n), cos π_p (n), sin π_p (n), length (n), π_p (n)]`` (cos, sin by numpy, the values
    :meth:`WaypointPath.project` forms)."""
    angles = path.leg_angles
    return flat(path.n_legs, path.waypoints[:-1, 0], path.waypoints[:-1, 1], np.cos(angles),
                np.sin(angles), path.leg_lengths, angles)


#: offsets within a :func:`leg_table` block of n legs: column j starts at 1 + j·n
LEG_NORTH, LEG_EAST, LEG_COS, LEG_SIN, LEG_LENGTH, LEG_ANGLE = range(6)


@kernel_function
def track_leg(north, east, leg, p, o):
    """:meth:`LegTracker.update` for one ship (switching rule A6 of document 000, several switches in
    one sample allowed): ``(leg, x_r, y_r)`` after any due switches, with the path frame of
    :func:`shipgnc.frames.path_frame` (s = Δn cos π_p + Δe sin π_p, e = −Δn sin π_p + Δe cos π_p).

    ``p[o:]`` is a :func:`leg_table` block; a NaN position switches nothing (as numpy's compare).
    """
    n = int(p[o])
    last = n - 1
    while True:
        dn = north - p[o + 1 + leg]
        de = east - p[o + 1 + n + leg]
        c = p[o + 1 + 2 * n + leg]
        s = p[o + 1 + 3 * n + leg]
        x_r = dn * c + de * s
        y_r = -dn * s + de * c
        if leg < last and x_r >= p[o + 1 + 4 * n + leg]:
            leg += 1
        else:
            return leg, x_r, y_r


@kernel_function
def leg_value(p, o, column, leg):
    """Column ``column`` (:data:`LEG_COS`, :data:`LEG_ANGLE`, ...) of leg ``leg`` in the
    :func:`leg_table` block ``p[o:]``."""
    return p[o + 1 + column * int(p[o]) + leg]
