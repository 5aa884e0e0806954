"""Target ships that are vessels: their own steering model, heading autopilot and LOS along their
waypoints, integrated with the own ship inside the collision-avoidance guidance
(:class:`shipgnc.guidance.colav.ColavGuidance`), so that each batch member's targets evolve with it.

**Model reduction.** A target needs its track over ground, not its forces: it is reduced to the
constant-speed steering model that the vessel catalogue's autopilot models are (Norrbin 1963;
n₃ = 0 is the first-order Nomoto model, Nomoto et al. 1957)::

    T ṙ + r + n₃ r³ = K δ,    ψ̇ = r,    ṅ = U cos ψ,    ė = U sin ψ        (v = 0: course = heading)
    δ̇ = clip((δ_c − δ)/T_δ, −δ̇_max, δ̇_max)                                   (steering machine)

K, T, n₃ and U come from the catalogue: ``frigate`` is van Amerongen's (1982) table at U — the
catalogue's frigate *is* this model (:mod:`shipgnc.vessels.frigate`), steering machine |δ| ≤ 30°,
10°/s, T_δ = 1 s (MSS); ``nomoto`` takes K, T (n₃) given, e.g. identified from trials by
``shipgnc identify`` or reduced by :func:`shipgnc.models.nomoto_reduction.first_order_reduction`.
Surge and sway are left out: the speed is held (the avoidance gets course offsets only) and the
drift angle of a turn is neglected (course = heading).

**Autopilot** (the catalogue's PD heading autopilot, Fossen 2021 §15.3, without integral)::

    δ_c = clip(−K_P wrap(ψ − ψ_d) − K_D r, −δ_max, δ_max)

computed at each guidance sample and held in between (zero-order hold), ψ_d from lookahead LOS
along ``[start, *waypoints]`` (:func:`shipgnc.guidance.los.los_reference`, the own ship's law),
plus the held course offset of the target's own avoidance.

**Integration:** from one guidance sample to the next, classic RK4 of (n, e, ψ, r, δ) with δ_c held,
in sub-steps of at most :data:`MAX_STEP`, T_δ and T/2 (RK4's stability bound on the real axis is
|h λ| ≤ 2.785, and the lags have λ = −1/T_δ and −1/T; half of T keeps a margin for the n₃ r³ term).
A target whose state is no longer finite turns the own ship's references NaN, so that the run stops
as a divergence at that sample (the controller's command not finite) instead of scoring without it;
the message names the target (``guidance.targets[j]``) and its state
(:meth:`shipgnc.guidance.colav.ColavGuidance.divergence_cause`).

**Avoidance** (optional, ``sbmpc`` or ``vo``): the target runs the method with the own ship as its one
target, seen as ground truth (position and velocity over ground at the sample), course offsets only,
deciding every decision interval like the own ship and holding the offset in between.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from shipgnc.colav.sbmpc import sbmpc_choose
from shipgnc.colav.vo import vo_choose
from shipgnc.errors import ConfigError
from shipgnc.guidance.los import los_reference
from shipgnc.kernels import flat, kernel_function, wrap

#: the longest RK4 sub-step between two guidance samples [s]
MAX_STEP = 0.5
#: avoidance of a vessel target by name → code
AVOIDANCE = {"none": 0, "sbmpc": 1, "vo": 2}
#: parameters of one target before its LOS and method parameters (:meth:`VesselTarget.params`)
P_FIXED = 13
#: state of one target: n, e, ψ, r, δ, δ_c, t_last, LOS (6), next decision, course offset, then the
#: method's memory and the scratch (:data:`SCRATCH`)
S_FIXED = 15
#: scratch of one target: own (4), other (4), nominal (2), command (2), LOS outputs (4)
SCRATCH = 16
_LOS_Z = 7  # the LOS state's offset in a target's state


@dataclass(frozen=True)
class VesselTarget:
    """A target that steers (module docstring): at (``north``, ``east``) with heading ``psi`` [rad]
    at t = 0, speed ``U`` [m/s], Norrbin/Nomoto ``K`` [1/s], ``T`` [s], ``n3`` [s²/rad²], PD gains
    ``Kp`` [rad/rad], ``Kd`` [s], steering machine ``delta_max`` [rad], ``delta_rate`` [rad/s],
    ``T_delta`` [s]; LOS along ``waypoints`` (``(k, 2)``, after the start) with ``lookahead`` [m]
    and ``switch_radius`` [m]; ``avoidance`` ``none``, ``sbmpc`` or ``vo``."""

    north: float
    east: float
    psi: float
    U: float
    K: float
    T: float
    waypoints: np.ndarray
    n3: float = 0.0
    Kp: float = 1.0
    Kd: float = 20.0
    delta_max: float = math.radians(30.0)
    delta_rate: float = math.radians(10.0)
    T_delta: float = 1.0
    lookahead: float = 500.0
    switch_radius: float = 0.0
    avoidance: str = "none"
    mmsi: int = 0
    name: str = ""
    length: float = 100.0
    beam: float = 20.0
    source: str = "vessel"
    #: the scenario field the target comes from (``guidance.targets[j]``), named by its errors
    where: str = ""

    def __post_init__(self) -> None:
        wp = np.asarray(self.waypoints, dtype=float).reshape(-1, 2)
        object.__setattr__(self, "waypoints", wp)
        checks = (("speed", self.U, self.U > 0), ("vessel.K", self.K, self.K > 0),
                  ("vessel.T", self.T, self.T > 0), ("vessel.n3", self.n3, self.n3 >= 0),
                  ("vessel.Kp", self.Kp, self.Kp >= 0), ("vessel.Kd", self.Kd, self.Kd >= 0),
                  ("vessel.delta_max_deg", math.degrees(self.delta_max),
                   0 < self.delta_max <= math.pi / 2),
                  ("vessel.delta_rate_deg", math.degrees(self.delta_rate), self.delta_rate > 0),
                  ("vessel.T_delta", self.T_delta, self.T_delta > 0),
                  ("vessel.lookahead", self.lookahead, self.lookahead > 0))
        for name, value, ok in checks:
            if not (math.isfinite(value) and ok):
                raise ConfigError(f"{self.field(name)} = {value!r} is out of range")
        if wp.shape[0] == 0 or not np.all(np.isfinite(wp)):
            raise ConfigError(f"{self.field('waypoints')}: must be ≥ 1 finite [north, east]")
        if self.avoidance not in AVOIDANCE:
            raise ConfigError(f"{self.field('avoidance')} = {self.avoidance!r}; allowed: "
                              f"{', '.join(AVOIDANCE)}")

    @property
    def label(self) -> str:
        return self.name or (f"MMSI {self.mmsi}" if self.mmsi else "target")

    def field(self, name: str) -> str:
        """The config field ``name`` (``vessel.T``) of this target as an error names it:
        ``guidance.targets[j].vessel.T``, or without :attr:`where` the target's label and the
        field's last part."""
        return f"{self.where}.{name}" if self.where else f"{self.label}: {name.split('.')[-1]}"

    def start(self) -> tuple[float, float]:
        """(north, east) at t = 0."""
        return self.north, self.east

    def path(self):
        """The LOS path: the start, then the waypoints (a zero-length leg is refused)."""
        from shipgnc.paths import WaypointPath

        points = np.vstack([[self.north, self.east], self.waypoints])
        if np.any(np.hypot(*np.diff(points, axis=0).T) <= 0):
            raise ConfigError(f"{self.field('waypoints')}: repeat a point (or the start)")
        return WaypointPath(points)

    def los_params(self) -> np.ndarray:
        """:func:`los_reference`'s parameters with the target's own state (north at 0, east at 1)."""
        path = self.path()
        if self.switch_radius >= path.leg_lengths.min():
            raise ConfigError(f"{self.field('vessel.switch_radius')} = {self.switch_radius:g} m "
                              f"must be shorter than the shortest leg "
                              f"({path.leg_lengths.min():g} m)")
        return flat(0, 1, path.n_legs, self.lookahead, 0.0, self.U, self.switch_radius, 0.0,
                    path.waypoints[:-1, 0], path.waypoints[:-1, 1], path.leg_lengths,
                    path.leg_angles)

    def params(self, index: int, method_params: np.ndarray) -> np.ndarray:
        """``[j, K, T, n₃, U, K_P, K_D, δ_max, δ̇_max, T_δ, avoidance, n_los, n_mp, LOS…, method…]``
        (``index`` j the target's place among its member's targets)."""
        los = self.los_params()
        mp = method_params if self.avoidance != "none" else np.zeros(0)
        return flat(index, self.K, self.T, self.n3, self.U, self.Kp, self.Kd, self.delta_max,
                    self.delta_rate, self.T_delta, AVOIDANCE[self.avoidance], los.size, mp.size,
                    los, mp)

    def state(self, width: int) -> np.ndarray:
        """The initial state row (``width`` numbers): at rest on its heading, rudder midships, no
        sample yet."""
        z = np.zeros(width)
        z[:7] = (self.north, self.east, self.psi, 0.0, 0.0, 0.0, np.nan)
        z[_LOS_Z:_LOS_Z + 6] = (0.0, 0.0, 0.0, np.nan, np.nan, 0.0)
        return z


@kernel_function
def _rates(psi, r, delta, delta_c, p):
    """(ṅ, ė, ψ̇, ṙ, δ̇) of the reduced model (module docstring)."""
    K, T, n3, U, rate, T_delta = p[1], p[2], p[3], p[4], p[8], p[9]
    d_delta = min(max((delta_c - delta) / T_delta, -rate), rate)
    return (U * math.cos(psi), U * math.sin(psi), r, (K * delta - r - n3 * r * r * r) / T,
            d_delta)


@kernel_function
def integrate_vessel(s, p, h):
    """Advance the target's (n, e, ψ, r, δ) = ``s[:5]`` by ``h`` [s] with δ_c = ``s[5]`` held:
    classic RK4 in equal sub-steps of at most MAX_STEP, T_δ and T/2 (the servo's and the yaw
    rate's lags, which would make a longer RK4 step unstable: its stability bound is 2.785 × the lag)."""
    n_sub = max(1, math.ceil(h / min(MAX_STEP, p[9], 0.5 * p[2]) - 1e-9))
    dt = h / n_sub
    dc = s[5]
    for _ in range(n_sub):
        n0, e0, psi, r, d = s[0], s[1], s[2], s[3], s[4]
        a = _rates(psi, r, d, dc, p)
        b = _rates(psi + 0.5 * dt * a[2], r + 0.5 * dt * a[3], d + 0.5 * dt * a[4], dc, p)
        c = _rates(psi + 0.5 * dt * b[2], r + 0.5 * dt * b[3], d + 0.5 * dt * b[4], dc, p)
        f = _rates(psi + dt * c[2], r + dt * c[3], d + dt * c[4], dc, p)
        s[0] = n0 + dt / 6.0 * (a[0] + 2.0 * b[0] + 2.0 * c[0] + f[0])
        s[1] = e0 + dt / 6.0 * (a[1] + 2.0 * b[1] + 2.0 * c[1] + f[1])
        s[2] = psi + dt / 6.0 * (a[2] + 2.0 * b[2] + 2.0 * c[2] + f[2])
        s[3] = r + dt / 6.0 * (a[3] + 2.0 * b[3] + 2.0 * c[3] + f[3])
        s[4] = d + dt / 6.0 * (a[4] + 2.0 * b[4] + 2.0 * c[4] + f[4])


@kernel_function
def vessel_target_sample(t, own, p, s, memory, interval):
    """One guidance sample of one vessel target (module docstring): integrate from its last
    sample to ``t``, LOS, its avoidance against ``own`` = the own ship ``[n, e, χ, U]`` every
    ``interval`` seconds, then the autopilot's rudder command, held to the next sample."""
    if not math.isnan(s[6]) and t > s[6]:
        integrate_vessel(s, p, t - s[6])
    s[6] = t
    n_los, n_mp, avoid = int(p[11]), int(p[12]), int(p[10])
    w = S_FIXED + memory
    mine, other, nominal, cmd = s[w:w + 4], s[w + 4:w + 8], s[w + 8:w + 10], s[w + 10:w + 12]
    los_reference(t, s, s[_LOS_Z:_LOS_Z + 6], p[P_FIXED:P_FIXED + n_los], nominal, s[w + 12:w + 16])
    if avoid > 0 and t >= s[13] - 1e-9 * max(1.0, abs(t)):
        U = p[4]
        mine[0], mine[1], mine[2], mine[3] = s[0], s[1], s[2], U
        other[0], other[1] = own[0], own[1]
        other[2], other[3] = own[3] * math.cos(own[2]), own[3] * math.sin(own[2])
        nominal[1] = U
        mp = p[P_FIXED + n_los:P_FIXED + n_los + n_mp]
        zm = s[S_FIXED:S_FIXED + memory]
        if avoid == 1:
            sbmpc_choose(t, mine, other, 1, nominal, mp, zm, cmd)
        else:
            vo_choose(t, mine, other, 1, nominal, mp, zm, cmd)
        s[13] = t + interval
        s[14] = wrap(cmd[0] - nominal[0])
    psi_d = wrap(nominal[0] + s[14])
    raw = -p[5] * wrap(s[2] - psi_d) - p[6] * s[3]
    s[5] = min(max(raw, -p[7]), p[7])


@kernel_function
def vessel_targets(t, own, pv, width_p, zv, width_z, n_vessels, memory, interval, targets,
                   present, hold):
    """Every vessel target of one ship at ``t`` (:func:`vessel_target_sample`): appended to the
    avoidance's ``targets`` after the ``present`` kinematic ones, the least range ``hold[3:6]``
    kept; returns the new count of targets present, or −1 when a target's state is not finite."""
    for k in range(n_vessels):
        p = pv[k * width_p:(k + 1) * width_p]
        s = zv[k * width_z:(k + 1) * width_z]
        vessel_target_sample(t, own, p, s, memory, interval)
        m = 4 * present
        targets[m], targets[m + 1] = s[0], s[1]
        targets[m + 2], targets[m + 3] = p[4] * math.cos(s[2]), p[4] * math.sin(s[2])
        present += 1
        d = math.hypot(s[0] - own[0], s[1] - own[1])
        if not (math.isfinite(d) and math.isfinite(s[2])):
            return -1
        if d < hold[3]:
            hold[3], hold[4], hold[5] = d, t, p[0]
    return present
