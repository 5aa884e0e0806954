"""Waypoint paths: straight legs between waypoints in NED, with the path-fixed frame; the leg
tracker of document 000 (A6), written once as a scalar kernel (:func:`track_leg`) that component
kernels call and whose batch over ships (:func:`shipgnc.derive.per_ship`) is
:meth:`LegTracker.update`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from shipgnc.derive import per_ship
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
    the last leg is a half-line. Batched: one leg index per ship; :meth:`update` is the batch of
    the scalar kernel :func:`track_leg` (:func:`leg_update`), which component kernels call.
    """

    def __init__(self, path: WaypointPath):
        require(isinstance(path, WaypointPath), "controller.path", type(path).__name__,
                "must be a WaypointPath")
        self.path = path
        self.leg: np.ndarray | None = None
        self._table = leg_table(path)

    def reset(self, batch_shape) -> None:
        self.leg = np.zeros(tuple(batch_shape), dtype=int)

    def update(self, north, east) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Switch legs where due; return along-track x_r, cross-track y_r [m] and the leg angle ψ_r0."""
        require(self.leg is not None, "controller", "LegTracker", "call reset(batch_shape) first")
        shape = np.shape(north)
        position = np.stack(np.broadcast_arrays(np.asarray(north, dtype=float),
                                                np.asarray(east, dtype=float)), axis=-1)
        z = np.array(np.broadcast_to(self.leg, shape), dtype=float).reshape(-1, 1)
        out = per_ship(leg_update, "i z p o")(position, z, self._table, 3)
        self.leg = z[:, 0].astype(int).reshape(shape)
        return out[..., 0], out[..., 1], out[..., 2]


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


@kernel_function
def leg_update(position, z, p, out):
    """:meth:`LegTracker.update` for one ship at ``position`` = [north, east]: its leg ``z[0]``
    after any due switches (:func:`track_leg`), ``out`` = [x_r, y_r, π_p of the leg]; ``p`` a
    :func:`leg_table` block."""
    leg, x_r, y_r = track_leg(position[0], position[1], int(z[0]), p, 0)
    z[0] = leg
    out[0] = x_r
    out[1] = y_r
    out[2] = leg_value(p, 0, LEG_ANGLE, leg)
