"""Line-of-sight (LOS) waypoint guidance, lookahead-based (spec 001 §1.10).

For leg k from P_k to P_{k+1} with path angle π_p, the along-track distance s and cross-track
error e (positive to starboard) come from :meth:`WaypointPath.project`; the desired heading is

    ψ_d = wrap(π_p − atan(e/Δ))

with lookahead Δ. The ship switches to leg k + 1 when s ≥ L_k − R_sw (R_sw = 0: crossing the
normal at the waypoint, the rule of spec 000). The task ends when s reaches the end of the last
leg. Batched: each ship has its own leg index.
"""

from __future__ import annotations

import numpy as np

from shipgnc.errors import require
from shipgnc.frames import wrap_angle
from shipgnc.guidance.path import WaypointPath
from shipgnc.models.base import Signal, state_index


class LOSGuidance:
    """Lookahead LOS guidance along a :class:`WaypointPath` at a constant speed set-point."""

    references = (
        Signal("psi_d", "rad", "desired heading", angle=True, tracks="psi"),
        Signal("u_d", "m/s", "desired surge speed", tracks="u"),
    )
    outputs = (
        Signal("cross_track_error", "m", "cross-track error, positive to starboard"),
        Signal("along_track", "m", "along-track distance on the active leg"),
        Signal("leg", "1", "active leg index (0-based)"),
    )

    def __init__(self, path: WaypointPath, *, lookahead: float, speed: float,
                 switch_radius: float = 0.0):
        require(np.isfinite(lookahead) and lookahead > 0, "guidance.lookahead", lookahead,
                "must be > 0 m")
        require(np.isfinite(speed) and speed > 0, "guidance.speed", speed, "must be > 0 m/s")
        require(np.isfinite(switch_radius) and switch_radius >= 0, "guidance.switch_radius",
                switch_radius, "must be >= 0 m")
        shortest = float(path.leg_lengths.min())
        require(switch_radius < shortest, "guidance.switch_radius", switch_radius,
                f"must be shorter than the shortest leg ({shortest:g} m)")
        self.path = path
        self.lookahead = float(lookahead)
        self.speed = float(speed)
        self.switch_radius = float(switch_radius)
        self.leg = None
        self.completion_time = None
        self._outputs: dict[str, np.ndarray] = {}

    def reset(self, batch_shape, model) -> None:
        self._i_north = state_index(model, "north")
        self._i_east = state_index(model, "east")
        self.leg = np.zeros(batch_shape, dtype=int)
        self.completion_time = np.full(batch_shape, np.nan)
        self._done = np.zeros(batch_shape, dtype=bool)

    def reference(self, t: float, x: np.ndarray) -> np.ndarray:
        north, east = x[..., self._i_north], x[..., self._i_east]
        last = self.path.n_legs - 1
        lengths = self.path.leg_lengths
        s, e = self.path.project(north, east, self.leg)
        switch = (self.leg < last) & (s >= lengths[self.leg] - self.switch_radius)
        if np.any(switch):
            self.leg = np.where(switch, self.leg + 1, self.leg)
            s, e = self.path.project(north, east, self.leg)
        newly_done = (self.leg == last) & (s >= lengths[last]) & ~self._done
        self.completion_time = np.where(newly_done, t, self.completion_time)
        self._done = self._done | newly_done
        psi_d = wrap_angle(self.path.leg_angles[self.leg] - np.arctan(e / self.lookahead))
        self._outputs = {"cross_track_error": e, "along_track": s, "leg": self.leg.astype(float)}
        return np.stack([psi_d, np.full_like(psi_d, self.speed)], axis=-1)

    def output_values(self) -> dict[str, np.ndarray]:
        return self._outputs

    def finished(self) -> np.ndarray:
        return self._done

    def waypoints_reached(self) -> np.ndarray:
        """Waypoints after the start whose leg was completed (switch or end of the last leg)."""
        return self.leg + self._done.astype(int)
