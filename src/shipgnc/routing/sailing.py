"""Sailing a solved route in the simulation loop (note 002-2.9.7 ``zermelo-sail``).

A route gives a heading programme ψ(t) and a ground track; a ship sails it through the *same* current
field object the router used:

* ``path`` — LOS guidance (:class:`~shipgnc.guidance.los.LOSGuidance`, integral LOS against the crab
  angle, note 001-1.17) through waypoints sampled on the route's track, with the vessel's heading
  autopilot (closed loop on position);
* ``programme`` — the optimal heading programme ψ(t) as the autopilot's set-point (open loop on
  position, closed on heading);
* ``legs`` — a few constant-heading legs (:meth:`~shipgnc.routing.result.RouteResult.constant_heading_legs`),
  open loop on position too.

**The boat in a current** (:class:`BoatInCurrent`). Document 001's boat with the current as relative
velocity (Fossen 2021 §10.3; note 001-1.17): the state's u, v are the velocities through the water,
ν_r = ν − ν_c, and

    η̇ = J(ψ) ν_r + [v_N, v_E, 0]ᵀ(η, t),     M ν̇_r + C(ν_r) ν_r + D(ν_r) ν_r = τ

(the body equations (9)–(11') of document 001 in ν_r). This is Fossen's model for an irrotational,
slowly varying current; the current's spatial acceleration and the water's rotation (k/2 for a shear)
are left out — both small against the boat's own dynamics here (k/2 ≈ 4·10⁻³ rad/s, yaw time
constant 1 s). The disturbance vector is document 001's ``[X_env, Y_env, N_env]`` plus the current
``[current_north, current_east]`` [m/s], filled by :class:`FieldCurrent` at every RK stage.

**The Mariner** (:func:`mariner_sail`). Document 000's de Wit–Oppe model
(:class:`~shipgnc.models.mariner.MarinerWitOppe`, U = S/f = 15 kn), its current added to the kinematics
(eq. (25): ẋ = u cos ψ − v sin ψ + c_N, ẏ = u sin ψ + v cos ψ + c_E) from the route's field on the ship's
clock (:class:`ShiftedField`, every RK stage), steered either by the heading autopilot
(:class:`~shipgnc.control.feedback_linearization.HeadingFL`) on a heading programme ψ(t) or by a path
controller with its own waypoints (e.g. :class:`~shipgnc.control.feedback_linearization.LOSFL`, integral
LOS feeding the FL yaw loop, note 000-0.5).

**Arrival** (:func:`arrival`). A ship has arrived when it comes within the acceptance radius R of the
target; its arrival time is the first such instant (interpolated between samples). A ship that never
comes within R has *not arrived*: no arrival time, only its closest approach (the miss distance).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from shipgnc.derive import per_ship
from shipgnc.environment.fields import field_velocity
from shipgnc.kernels import Kernel, NotCompiled, kernel_function
from shipgnc.models.base import Signal, kernel_derivatives
from shipgnc.models.fossen3dof import DISTURBANCES, VectoredThrustBoat, boat_rhs

CURRENT = (
    Signal("current_north", "m/s", "current over ground, north component"),
    Signal("current_east", "m/s", "current over ground, east component"),
)


class BoatInCurrent:
    """Document 001's boat with a current as relative velocity (see the module docstring).

    States as :class:`~shipgnc.models.fossen3dof.VectoredThrustBoat`'s, with u and v the surge and
    sway velocities *through the water*; disturbances ``[X_env, Y_env, N_env, current_north,
    current_east]``."""

    disturbances = (*DISTURBANCES, *CURRENT)

    def __init__(self, boat: VectoredThrustBoat):
        self.boat = boat
        self.params = boat.params
        self.preset_name = boat.preset_name
        self.length = boat.length
        self.beam = boat.beam
        self.states = boat.states
        self.inputs = boat.inputs
        self.state_limits = boat.state_limits

    def input_limits(self):
        return self.boat.input_limits()

    def derivatives(self, x, u, d=None):
        """ẋ: the batch of :func:`boat_current_rhs` (the boat's own equations with ν_r, plus the
        current in the kinematics)."""
        return kernel_derivatives(self, boat_current_rhs, self.boat.kernel().params, x, u, d)

    def kernel(self) -> Kernel:
        """:meth:`derivatives` for the composed loop (:func:`boat_current_rhs`)."""
        return Kernel(boat_current_rhs, self.boat.kernel().params)


@kernel_function
def boat_current_rhs(x, u, d, p, xdot):
    """ẋ of :class:`BoatInCurrent` for one ship (Fossen 2021 §10.3, the state's u, v through the
    water): η̇ = J(ψ) ν_r + [d₃, d₄, 0]ᵀ, and ν̇_r of document 001's equations (9)–(11') with the
    forces d[0:3] (:func:`~shipgnc.models.fossen3dof.boat_rhs`). Not the boat's own current model
    (:func:`shipgnc.models.fossen3dof.boat_current_rhs`, whose state is ν over ground); a
    disturbance of three forces only is still water."""
    boat_rhs(x, u, d, p, xdot)
    if d.shape[0] >= 5:
        xdot[0] = xdot[0] + d[3]
        xdot[1] = xdot[1] + d[4]


class FieldCurrent:
    """The disturbance ``[0, 0, 0, v_N, v_E]`` of :class:`BoatInCurrent`: a routing current field
    (:mod:`shipgnc.environment.fields`) at the ship's position, at time ``t0 + t`` (the ship's clock starts
    at the route's departure t0); evaluated at every RK stage."""

    per_stage = True

    def __init__(self, field, t0: float = 0.0):
        self.field, self.t0 = field, float(t0)

    def reset(self, batch_shape, rng=None) -> None:
        pass

    def __call__(self, t, x):
        """The batch of :func:`field_current_sample`; a field without a compiled form (gridded
        data, whose domain is checked) in numpy: its own ``velocity``."""
        if self.kernel_reason() is None:
            x = np.asarray(x, dtype=float)
            z = np.empty((math.prod(x.shape[:-1]), 0))  # neither z nor w is read
            return per_ship(field_current_sample, "t i z p i o")(t, x, z, self._params(), z[0], 5)
        v = self.field.velocity(self.t0 + t, x[..., 0], x[..., 1])
        zeros = np.zeros((*v.shape[:-1], 3))
        return np.concatenate([zeros, v], axis=-1)

    def kernel_reason(self) -> str | None:
        try:
            self._params()
        except NotCompiled as exc:
            return str(exc)
        return None

    def _params(self):
        make = getattr(self.field, "current_kernel", None)
        if not callable(make):
            raise NotCompiled(f"current {type(self.field).__name__} has no kernel")
        function, params = make(t0=self.t0)
        if function is not field_velocity:
            raise NotCompiled(f"current {type(self.field).__name__}: its current_kernel() is not "
                              "shipgnc.environment.fields.field_velocity")
        return params

    def kernel(self, batch_shape, dt: float | None = None) -> Kernel:
        """:meth:`__call__` for the composed loop (:func:`field_current_sample`)."""
        return Kernel(field_current_sample, self._params())


@kernel_function
def field_current_sample(t, x, z, p, w, d):
    """d = [0, 0, 0, v_N, v_E]: the field's velocity at the ship's position (north, east) = (x[0],
    x[1]) at time t0 + t (:func:`~shipgnc.environment.fields.field_velocity`)."""
    vn, ve = field_velocity(t, x[0], x[1], p, 0)
    d[0] = 0.0
    d[1] = 0.0
    d[2] = 0.0
    d[3] = vn
    d[4] = ve


@dataclass
class Arrival:
    """How a sailed run ended against the acceptance radius (module docstring)."""

    arrived: bool
    time_s: float | None  #: first time within the radius, after departure [s]; None if not arrived
    miss_m: float  #: closest approach to the target [m]
    closest_time_s: float  #: when the closest approach happened, after departure [s]
    radius_m: float


def arrival(ds, target, radius: float) -> Arrival:
    """First entry into the disc of ``radius`` [m] about ``target`` (linear between samples), and the
    closest approach over the whole run."""
    time = ds["time"].values
    dist = np.hypot(ds["north"].values - target[0], ds["east"].values - target[1])
    ok = np.isfinite(dist)
    k_min = int(np.argmin(np.where(ok, dist, np.inf)))
    miss, t_min = float(dist[k_min]), float(time[k_min])
    inside = np.flatnonzero(ok & (dist <= radius))
    if inside.size == 0:
        return Arrival(False, None, miss, t_min, float(radius))
    k = int(inside[0])
    t_in = float(time[k])
    if k > 0 and dist[k - 1] > radius:  # interpolate the crossing of the radius
        f = (dist[k - 1] - radius) / (dist[k - 1] - dist[k])
        t_in = float(time[k - 1] + f * (time[k] - time[k - 1]))
    return Arrival(True, t_in, miss, t_min, float(radius))


def route_waypoints(route, n: int) -> np.ndarray:
    """``n`` points on the route's ground track, equally spaced in time from start to target [m]."""
    _, north, east, _ = route.sample(max(int(n), 2))
    pts = np.column_stack([north, east])
    keep = np.concatenate([[True], np.hypot(*np.diff(pts, axis=0).T) > 1e-6])
    return pts[keep]


def boat_sail(route, field, mode: str, *, preset: str = "otter", dt: float = 0.05,
              t_end: float, heading=None, n_points: int = 40, lookahead: float | None = None,
              integral_gain: float = 0.0, seed: int = 0, backend: str = "auto"):
    """One run of the Otter-class boat (:class:`BoatInCurrent`) under its heading and speed autopilot
    (:class:`~shipgnc.control.heading_speed.HeadingSpeedAutopilot`, as in ``boat-los``) at the route's
    speed through the water, through ``field`` from the route's start.

    ``mode``: ``"path"`` (LOS through ``n_points`` route waypoints, ``lookahead`` [m], default four boat
    lengths; ``integral_gain`` σ of integral LOS) or ``"heading"`` (``heading(t)`` [rad], absolute time,
    as the set-point at every control sample). Starts on the route's initial heading at speed V through
    the water. Returns the ``xarray.Dataset`` of the run.
    """
    from shipgnc.sim.simulator import simulate

    run = boat_sail_run(route, field, mode, preset=preset, dt=dt, t_end=t_end, heading=heading,
                        n_points=n_points, lookahead=lookahead, integral_gain=integral_gain)
    return simulate(run.model, run.x0, **run.options, seed=seed, backend=backend)


@dataclass
class SailRun:
    """One sailed run, ready for ``simulate(model, x0, **options)`` (``options``: ``t_end``,
    ``dt``, ``controller``, ``actuator``, ``guidance``, ``disturbance``)."""

    model: object
    x0: np.ndarray
    options: dict


def boat_sail_run(route, field, mode: str, *, preset: str = "otter", dt: float = 0.05,
                  t_end: float, heading=None, n_points: int = 40, lookahead: float | None = None,
                  integral_gain: float = 0.0) -> SailRun:
    """The run :func:`boat_sail` simulates (its arguments), not yet simulated."""
    from shipgnc.actuators import Actuator
    from shipgnc.control.heading_speed import HeadingSpeedAutopilot
    from shipgnc.guidance.los import LOSGuidance
    from shipgnc.guidance.schedule import ReferenceSchedule
    from shipgnc.paths import WaypointPath

    boat = VectoredThrustBoat.from_preset(preset)
    model = BoatInCurrent(boat)
    V, t0 = float(route.speed), float(route.t0)
    steps = max(1, math.ceil(t_end / dt))
    x0 = np.array([route.start[0], route.start[1], float(route.heading(t0)), V, 0.0, 0.0])
    if mode == "path":
        guidance = LOSGuidance(WaypointPath(route_waypoints(route, n_points)),
                               lookahead=4.0 * boat.length if lookahead is None else lookahead,
                               speed=V, integral_gain=integral_gain)
    elif mode == "heading":
        samples = np.arange(steps + 1) * dt
        psi = np.asarray([float(heading(t0 + t)) for t in samples]) if not _takes_arrays(heading) \
            else np.asarray(heading(t0 + samples), dtype=float)
        guidance = ReferenceSchedule(samples, psi, np.full(samples.size, V))
    else:
        raise ValueError(f"mode = {mode!r}: allowed path, heading")
    return SailRun(model, x0, {"t_end": steps * dt, "dt": dt,
                               "controller": HeadingSpeedAutopilot(boat.params, Ts=dt),
                               "actuator": Actuator.for_model(model), "guidance": guidance,
                               "disturbance": FieldCurrent(field, t0)})


class ShiftedField:
    """A current field seen by a ship whose clock starts at the departure t0: ``__call__(t, x)`` is
    ``field(t0 + t, x)``; evaluated at every RK stage (``per_stage``), the disturbance protocol of
    :class:`~shipgnc.models.mariner.MarinerDisturbance`'s ``current``."""

    def __init__(self, field, t0: float):
        self.field, self.t0 = field, float(t0)
        self.per_stage = True

    def reset(self, batch_shape, rng=None) -> None:
        pass

    def __call__(self, t, x):
        return self.field(self.t0 + t, x)

    def current_kernel(self):
        """The field's compiled form evaluated at t0 + t (raises NotCompiled without one)."""
        make = getattr(self.field, "current_kernel", None)
        if not callable(make):
            raise NotCompiled(f"current {type(self.field).__name__} has no kernel")
        return make(t0=self.t0)


def mariner_sail(route, field, heading, *, dt: float, t_end: float, seed: int = 0,
                 backend: str = "auto", model=None, controller=None, guidance=None):
    """Simulate document 000's Mariner steering ``heading(t)`` [rad] from the route's start through
    ``field`` (module docstring).

    ``route``: anything with ``start``, ``target`` (north, east) [m] and ``t0`` [s] (the departure on the
    field's clock). Returns ``(dataset, closest_s, miss_m)``: the run, the time of the closest approach to
    the route's target and that distance (an arrival is judged by the acceptance radius instead,
    :func:`arrival`). ``backend`` as :func:`~shipgnc.sim.simulator.simulate`'s. ``model``: a
    :class:`~shipgnc.models.mariner.MarinerWitOppe` (default the document's, U = 15 kn; the ship starts at
    its U on the heading ``heading(t0)``). ``controller`` and ``guidance``: a path controller and the
    path it follows (e.g. :class:`~shipgnc.control.feedback_linearization.LOSFL` on a
    :class:`~shipgnc.guidance.path.PathGuidance` through waypoints, as
    :func:`shipgnc.routing.geo.sail.sail_check` sails a chart's route) instead of
    :class:`~shipgnc.control.feedback_linearization.HeadingFL` on ``heading``, which then only gives the
    initial heading.
    """
    from shipgnc.sim.simulator import simulate

    run = mariner_sail_run(route, field, heading, dt=dt, t_end=t_end, model=model,
                           controller=controller, guidance=guidance)
    ds = simulate(run.model, run.x0, **run.options, seed=seed, backend=backend)
    distance = np.hypot(ds["north"].values - route.target[0], ds["east"].values - route.target[1])
    k = int(np.argmin(distance))
    return ds, float(ds["time"].values[k]), float(distance[k])


def mariner_sail_run(route, field, heading, *, dt: float, t_end: float, model=None,
                     controller=None, guidance=None) -> SailRun:
    """The run :func:`mariner_sail` simulates (its arguments), not yet simulated."""
    from shipgnc.control.feedback_linearization import HeadingFL
    from shipgnc.guidance.schedule import HeadingProfile
    from shipgnc.models.mariner import MarinerDisturbance, MarinerWitOppe, rudder

    model = MarinerWitOppe() if model is None else model
    p = model.params
    t0 = route.t0
    x0 = np.array([route.start[0], route.start[1], float(heading(t0)), p.U, 0.0])
    steps = max(1, math.ceil(t_end / dt))
    # the autopilot samples every step (Ts = dt): the programme's table for the compiled loop
    samples = np.arange(steps + 1) * dt
    if controller is None:
        guidance = HeadingProfile(lambda t: heading(t0 + t), samples=samples)
    return SailRun(model, x0, {
        "t_end": steps * dt, "dt": dt,
        "controller": HeadingFL(p, Ts=dt) if controller is None else controller,
        "actuator": rudder(p), "guidance": guidance,
        "disturbance": MarinerDisturbance(0.0, current=ShiftedField(field, t0))})


def _takes_arrays(fn) -> bool:
    try:
        out = np.asarray(fn(np.array([0.0, 1.0])), dtype=float)
    except Exception:
        return False
    return out.shape == (2,)
