"""Line-of-sight (LOS) waypoint guidance, lookahead-based (note 001-1.10).

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

**Adaptive LOS** (``adaptive_gain`` γ > 0; Fossen, Pettersen & Galeazzi 2015, IEEE TCST 23(2),
820–827; Fossen 2021 §12.4.3) estimates the crab angle β = χ − ψ that a current or a steady side
force imposes, and steers it out::

    ψ_d = wrap(π_p − β̂ − atan(e/Δ)),   β̂̇ = γ U Δ e / √(Δ² + e²)

with U the speed set-point (Fossen 2023, IEEE TCST 31(6):2887–2894, folds U into γ). Linearised
about the path, with the heading tracked, ė = U_g (β − β̂ − e/Δ) (U_g the speed over ground) and
the error poles are s² + (U_g/Δ)s + γ U U_g: γ = U_g / (4 U Δ²) ≈ 1/(4Δ²) is critically damped.
β̂ is a guidance state (per ship, integrated like e_int and restarted at 0 on each new leg) logged
as ``crab_angle_est``. Integral and adaptive LOS are alternatives: at most one of the two gains
may be > 0.

The ship switches to leg k + 1 when s ≥ L_k − R_sw (R_sw = 0: crossing the normal at the
waypoint, the rule of document 000). The task ends when s reaches the end of the last
leg. Batched: each ship has its own leg index.
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.errors import require
from shipgnc.guidance.base import kernel_reference
from shipgnc.kernels import Kernel, flat, kernel_function, wrap
from shipgnc.models.base import Signal, state_index
from shipgnc.paths import WaypointPath


class LOSGuidance:
    """Lookahead LOS guidance (optionally integral or adaptive LOS) along a :class:`WaypointPath`
    at a constant speed set-point; works with any model that has ``north`` and ``east`` states."""

    references = (
        Signal("psi_d", "rad", "desired heading", angle=True, tracks="psi"),
        Signal("u_d", "m/s", "desired surge speed", tracks="u"),
    )
    outputs = (
        Signal("cross_track_error", "m", "cross-track error, positive to starboard"),
        Signal("along_track", "m", "along-track distance on the active leg"),
        Signal("leg", "1", "active leg index (0-based)"),
    )
    #: the extra output of adaptive LOS (``adaptive_gain`` > 0), after the three above
    crab_angle_signal = Signal("crab_angle_est", "rad", "crab-angle estimate of adaptive LOS",
                               angle=True)

    def __init__(self, path: WaypointPath, *, lookahead: float, speed: float,
                 switch_radius: float = 0.0, integral_gain: float = 0.0,
                 adaptive_gain: float = 0.0):
        require(np.isfinite(lookahead) and lookahead > 0, "guidance.lookahead", lookahead,
                "must be > 0 m")
        require(np.isfinite(speed) and speed > 0, "guidance.speed", speed, "must be > 0 m/s")
        require(np.isfinite(switch_radius) and switch_radius >= 0, "guidance.switch_radius",
                switch_radius, "must be >= 0 m")
        require(np.isfinite(integral_gain) and integral_gain >= 0, "guidance.integral_gain",
                integral_gain, "must be >= 0 (0 = plain LOS)")
        require(np.isfinite(adaptive_gain) and adaptive_gain >= 0, "guidance.adaptive_gain",
                adaptive_gain, "must be >= 0 rad/m² (0 = no crab-angle estimate)")
        require(not (integral_gain > 0 and adaptive_gain > 0), "guidance.integral_gain, adaptive_gain",
                (integral_gain, adaptive_gain),
                "integral LOS and adaptive LOS are alternatives: set one of the two gains to 0")
        shortest = float(path.leg_lengths.min())
        require(switch_radius < shortest, "guidance.switch_radius", switch_radius,
                f"must be shorter than the shortest leg ({shortest:g} m)")
        self.path = path
        self.lookahead = float(lookahead)
        self.speed = float(speed)
        self.switch_radius = float(switch_radius)
        self.integral_gain = float(integral_gain)
        self.adaptive_gain = float(adaptive_gain)
        if self.adaptive_gain > 0:  # fixed per configuration: the logged signals follow it
            self.outputs = (*LOSGuidance.outputs, LOSGuidance.crab_angle_signal)
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
        self.beta_hat = np.zeros(batch_shape)
        self._t_last: float | None = None

    def reference(self, t: float, x: np.ndarray) -> np.ndarray:
        """``[ψ_d, u_d]`` for every ship: the batch of :func:`los_reference`."""
        references, self._outputs = kernel_reference(self, t, x)
        return references

    def output_values(self) -> dict[str, np.ndarray]:
        return self._outputs

    def finished(self) -> np.ndarray:
        return self._done

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`reference` for the composed loop (:func:`los_reference`); per-ship state
        ``[leg, done, e_int, t_last (NaN before the first sample), completion_time, β̂]``."""
        path = self.path
        params = flat(self._i_north, self._i_east, path.n_legs, self.lookahead,
                      self.integral_gain, self.speed, self.switch_radius, self.adaptive_gain,
                      path.waypoints[:-1, 0], path.waypoints[:-1, 1], path.leg_lengths,
                      path.leg_angles)
        state = np.stack([self.leg, self._done, self.e_int,
                          np.full(batch_shape, np.nan if self._t_last is None else self._t_last),
                          self.completion_time, self.beta_hat], axis=-1)

        def restore(z: np.ndarray) -> None:
            z = z.reshape(*batch_shape, 6)
            self.leg = z[..., 0].astype(int)
            self._done = z[..., 1] > 0
            self.e_int = z[..., 2].copy()
            t_last = z.reshape(-1, 6)[0, 3] if z.size else np.nan
            self._t_last = None if np.isnan(t_last) else float(t_last)
            self.completion_time = z[..., 4].copy()
            self.beta_hat = z[..., 5].copy()

        return Kernel(los_reference, params, state, restore=restore)

    def waypoints_reached(self) -> np.ndarray:
        """Waypoints after the start whose leg was completed (switch or end of the last leg)."""
        return self.leg + self._done.astype(int)


@kernel_function
def los_reference(t, x, z, p, ref, out):
    """One sample of (integral / adaptive) LOS guidance for one ship (module docstring; note
    001-1.10, Fossen 2021 §12.4)::

        (s, e) = path frame of the active leg (s along-track, e cross-track, to starboard)
        leg += 1 once s ≥ L_leg − R_sw (not past the last leg; e_int, β̂ restart at 0)
        ė_int = Δ e/((e + σ e_int)² + Δ²),   β̂̇ = γ U Δ e/√(Δ² + e²)   (forward Euler over h)
        ψ_d = wrap(π_p − β̂ − atan((e + σ e_int)/Δ)),   u_d = U

    finished once s reaches the end of the last leg. ``z`` = [leg, done, e_int, t_last (NaN
    before the first sample), completion_time, β̂]; ``out`` = [e, s, leg(, β̂)]."""
    n_legs = int(p[2])
    D, sigma, speed, R_sw, gamma = p[3], p[4], p[5], p[6], p[7]
    north, east = x[int(p[0])], x[int(p[1])]
    o_n, o_e = p[8:8 + n_legs], p[8 + n_legs:8 + 2 * n_legs]
    lengths, angles = p[8 + 2 * n_legs:8 + 3 * n_legs], p[8 + 3 * n_legs:8 + 4 * n_legs]
    leg = int(z[0])
    last = n_legs - 1
    s, e = _project(north, east, o_n[leg], o_e[leg], angles[leg])
    if leg < last and s >= lengths[leg] - R_sw:
        leg += 1
        s, e = _project(north, east, o_n[leg], o_e[leg], angles[leg])
        z[2] = 0.0
        z[5] = 0.0
    if leg == last and s >= lengths[last] and z[1] == 0.0:
        z[4] = t
        z[1] = 1.0
    if sigma > 0 and not math.isnan(z[3]):
        h = t - z[3]
        q = e + sigma * z[2]
        z[2] = z[2] + h * D * e / (q * q + D * D)
    if gamma > 0 and not math.isnan(z[3]):
        h = t - z[3]
        z[5] = z[5] + h * gamma * speed * D * e / math.sqrt(D * D + e * e)
    z[3] = t
    z[0] = leg
    ref[0] = wrap(angles[leg] - z[5] - math.atan((e + sigma * z[2]) / D))
    ref[1] = speed
    out[0], out[1], out[2] = e, s, float(leg)
    if gamma > 0:
        out[3] = z[5]
    return z[1] != 0.0


@kernel_function
def _project(north, east, origin_north, origin_east, angle):
    """:func:`shipgnc.frames.path_frame` for one point: (along-track s, cross-track e)."""
    dn, de = north - origin_north, east - origin_east
    c, s = math.cos(angle), math.sin(angle)
    return dn * c + de * s, -dn * s + de * c
