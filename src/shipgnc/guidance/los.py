"""Line-of-sight (LOS) waypoint guidance, lookahead-based (spec 001 §1.10).

For leg k from P_k to P_{k+1} with path angle π_p, the along-track distance s and cross-track
error e (positive to starboard) come from :meth:`WaypointPath.project`; the desired heading is

    ψ_d = wrap(π_p − atan(e/Δ))

with lookahead Δ. **Integral LOS** (``integral_gain`` σ > 0; Børhaug, Pavlov & Pettersen 2008,
Fossen 2021 §12.4) adds an integral of the cross-track error against currents and other steady
side forces, which plain LOS leaves as a standing offset (it steers the crab angle only once
atan(e/Δ) equals it)::

    ψ_d = wrap(π_p − atan((e + σ e_int)/Δ)),   ė_int = Δ e / ((e + σ e_int)² + Δ²)

e_int is integrated (forward Euler) between the guidance samples and restarts at 0 on each new
leg; far from the path the denominator slows the integration, which limits wind-up.

The ship switches to leg k + 1 when s ≥ L_k − R_sw (R_sw = 0: crossing the normal at the
waypoint, the rule of spec 000). The task ends when s reaches the end of the last
leg. Batched: each ship has its own leg index.
"""

from __future__ import annotations

import numpy as np

from shipgnc.errors import require
from shipgnc.frames import wrap_angle
from shipgnc.guidance.path import WaypointPath
from shipgnc.models.base import Signal, state_index


class LOSGuidance:
    """Lookahead LOS guidance (optionally integral LOS) along a :class:`WaypointPath` at a constant
    speed set-point; works with any model that has ``north`` and ``east`` states."""

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
                 switch_radius: float = 0.0, integral_gain: float = 0.0):
        require(np.isfinite(lookahead) and lookahead > 0, "guidance.lookahead", lookahead,
                "must be > 0 m")
        require(np.isfinite(speed) and speed > 0, "guidance.speed", speed, "must be > 0 m/s")
        require(np.isfinite(switch_radius) and switch_radius >= 0, "guidance.switch_radius",
                switch_radius, "must be >= 0 m")
        require(np.isfinite(integral_gain) and integral_gain >= 0, "guidance.integral_gain",
                integral_gain, "must be >= 0 (0 = plain LOS)")
        shortest = float(path.leg_lengths.min())
        require(switch_radius < shortest, "guidance.switch_radius", switch_radius,
                f"must be shorter than the shortest leg ({shortest:g} m)")
        self.path = path
        self.lookahead = float(lookahead)
        self.speed = float(speed)
        self.switch_radius = float(switch_radius)
        self.integral_gain = float(integral_gain)
        self.leg = None
        self.completion_time = None
        self._outputs: dict[str, np.ndarray] = {}

    def reset(self, batch_shape, model) -> None:
        self._i_north = state_index(model, "north")
        self._i_east = state_index(model, "east")
        self.leg = np.zeros(batch_shape, dtype=int)
        self.completion_time = np.full(batch_shape, np.nan)
        self._done = np.zeros(batch_shape, dtype=bool)
        self.e_int = np.zeros(batch_shape)
        self._t_last: float | None = None

    def reference(self, t: float, x: np.ndarray) -> np.ndarray:
        north, east = x[..., self._i_north], x[..., self._i_east]
        last = self.path.n_legs - 1
        lengths = self.path.leg_lengths
        s, e = self.path.project(north, east, self.leg)
        switch = (self.leg < last) & (s >= lengths[self.leg] - self.switch_radius)
        if np.any(switch):
            self.leg = np.where(switch, self.leg + 1, self.leg)
            s, e = self.path.project(north, east, self.leg)
            self.e_int = np.where(switch, 0.0, self.e_int)
        newly_done = (self.leg == last) & (s >= lengths[last]) & ~self._done
        self.completion_time = np.where(newly_done, t, self.completion_time)
        self._done = self._done | newly_done
        D, sigma = self.lookahead, self.integral_gain
        if sigma > 0 and self._t_last is not None:
            h = t - self._t_last
            self.e_int = self.e_int + h * D * e / ((e + sigma * self.e_int) ** 2 + D * D)
        self._t_last = t
        psi_d = wrap_angle(self.path.leg_angles[self.leg] - np.arctan((e + sigma * self.e_int) / D))
        self._outputs = {"cross_track_error": e, "along_track": s, "leg": self.leg.astype(float)}
        return np.stack([psi_d, np.full_like(psi_d, self.speed)], axis=-1)

    def output_values(self) -> dict[str, np.ndarray]:
        return self._outputs

    def finished(self) -> np.ndarray:
        return self._done

    def waypoints_reached(self) -> np.ndarray:
        """Waypoints after the start whose leg was completed (switch or end of the last leg)."""
        return self.leg + self._done.astype(int)
