"""The common part of every standard manoeuvring trial: approach, execute, batched integration.

Definitions follow the IMO Standards for Ship Manoeuvrability (MSC.137(76), 2002) and their
explanatory notes (MSC/Circ.1053); they are written out in ``docs/trials.md``.

* **Approach** (:func:`prepare`): steady straight running at the test speed V. A model with small
  constant side force/moment terms (a single screw, e.g. the Mariner's Y₀, N₀) needs a trim rudder
  δ₀ to run straight: the steady state with ψ̇ = r = 0 is solved by Newton's method on the model's
  own derivatives, unknowns (the non-kinematic states, δ₀), equations (their derivatives = 0,
  ψ̇ = 0). Every trial is executed from that state and reports the δ₀ it used.
* **Execute**: t = 0, position (0, 0), heading 0 (the original course points north) at the moment
  the rudder command changes; the rudder moves at its rate limit (the model's own steering machine
  when ``delta`` is a state, else :class:`~shipgnc.actuators.Actuator` slewing linearly).
* **Integration** (:func:`run`): one run of :func:`shipgnc.sim.simulator.simulate` (fixed-step
  RK4) over a batch ``(B, n)``: every ship of a trial (a spiral's rudder angles, both turning
  sides, several trials at once) is one array operation per RK stage; no Python loop over ships.
  Each ship follows a :class:`RudderProgramme` (piecewise-constant rudder, zig-zag reversals,
  phase switches when the yaw rate is steady, full astern), the run's controller
  (:class:`~shipgnc.trials.programme.ProgrammeController`), and the run ends when every ship's
  trial is complete. A vessel section (a vessel file's) is built as ``shipgnc run`` builds a
  scenario's (:func:`shipgnc.vessels.setup.vessel_setup`).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np

from shipgnc.errors import ConfigError, require
from shipgnc.models.base import names
from shipgnc.units import KNOT

#: sides of a turn: sign of the rudder (and of the heading change) for each
SIDES = {"starboard": 1.0, "port": -1.0}
#: steady-state test: the yaw rate over the last ``window`` seconds varies less than
#: ``STEADY_ABS + STEADY_REL * |r|`` [rad/s]
STEADY_ABS = 2e-6
STEADY_REL = 2e-4
#: the looser test that ends a spiral's approach turn (it only has to reach its branch)
SWITCH_REL = 1e-2


@dataclass(frozen=True, eq=False)
class TrialShip:
    """A vessel ready for trials at one or more test speeds (``x0``: (S, n), one row per speed).

    ``delta0`` [rad] (S,) is the trim rudder of the straight approach, ``inputs0`` (S, m) the
    inputs that hold it (rudder δ₀, propeller command, ...), ``speed`` [m/s] (S,) the approach
    speed over ground. ``length_m`` is None for a model given only by parameters (no IMO limits).
    ``models`` holds the model of each speed (catalogue models carry their speed as a parameter,
    e.g. the Mariner's U₀): a batch over several speeds evaluates each speed's model on its ships
    (:class:`Stacked`), still one integration of one batch.
    """

    model: object
    models: tuple
    name: str
    x0: np.ndarray
    inputs0: np.ndarray
    delta0: np.ndarray
    speed: np.ndarray
    length_m: float | None
    max_rudder: float
    rudder_rate: float
    can_reverse: bool
    full_astern: float | None
    source: str = ""
    dt: float = 0.5
    index: dict = field(default_factory=dict)
    steering_gear: str = "model"

    @property
    def steering_in_model(self) -> bool:
        """Whether the rudder angle is a state of the model (its own steering machine)."""
        return "delta" in self.index

    @property
    def n_inputs(self) -> int:
        return len(self.model.inputs)

    def l_over_v(self, i: int = 0) -> float | None:
        """L/V [s] at the i-th test speed (None without a length)."""
        return None if self.length_m is None else self.length_m / float(self.speed[i])


def _entry(vessel):
    """A catalogue entry from a name, a vessel section (a scenario's or a file's) or the entry
    itself; None for a plain model."""
    from shipgnc.vessels import get_vessel
    from shipgnc.vessels.config import CatalogueVesselConfig

    if isinstance(vessel, str):
        return get_vessel(vessel)
    if isinstance(vessel, CatalogueVesselConfig):
        return get_vessel(vessel.model)
    if hasattr(vessel, "build") and hasattr(vessel, "design_speed_mps"):
        return vessel
    return None


#: steering gears a trial can run with (``--steering-gear``)
STEERING_GEARS = ("solas", "model")


def solas_rudder_rate(entry=None) -> float:
    """SOLAS II-1 reg. 29.3.2 steering gear [rad/s]: 35° on one side to 30° on the other in
    28 s, i.e. 65°/28 s ≈ 2.32°/s on average; a model-scale catalogue vessel's rate Froude-scaled
    by √λ (time scales as √λ at equal Froude number)."""
    from shipgnc.vessels.base import SOLAS_RUDDER_RATE

    scale = 1.0 if entry is None else float(getattr(entry, "froude_scale", 1.0))
    return SOLAS_RUDDER_RATE * math.sqrt(scale)


def _refuse_course_unstable_linear(model, name: str) -> None:
    """A linear 3-DOF model of a course-unstable ship has no steady turn and its large-rudder
    manoeuvres grow without bound (:meth:`~shipgnc.vessels.linear.Linear3DOFVessel.sway_yaw_pole`):
    its trials would print numbers without meaning, so they are refused in one line."""
    pole = getattr(model, "sway_yaw_pole", None)
    if pole is None or (p := pole()) <= 0:
        return
    raise ConfigError(f"trial: the linear model of {name} is course-unstable (a pole at +{p:.3g} 1/s: "
                      f"a yaw disturbance doubles in {math.log(2) / p:.3g} s): a linear model has "
                      "no steady turn and its rudder manoeuvres grow without bound, so it has no "
                      "trials; its autopilot: shipgnc design autopilot")


def prepare(vessel, speed_mps=None, *, length_m: float | None = None,
            max_rudder_deg: float | None = None, rudder_rate_deg_s: float | None = None,
            dt: float | None = None, steering_gear: str = "model", name: str | None = None,
            **params) -> TrialShip:
    """Set a vessel up for trials: build it, solve the straight approach with its trim rudder.

    ``vessel``: a catalogue name (:mod:`shipgnc.vessels`), a catalogue entry, a vessel section
    (:class:`~shipgnc.vessels.config.CatalogueVesselConfig`: a vessel file's, a scenario's; built
    by :func:`~shipgnc.vessels.setup.vessel_setup` as ``shipgnc run`` builds it), or a model
    object (``Model`` protocol; then ``speed_mps`` is required unless the model has a speed
    ``U``). ``speed_mps``: one test speed or a sequence (a speed range: one batch); default the
    section's speed, else the design speed. ``name``: the vessel's name in the results.
    ``params`` go to the entry's ``build`` (e.g. K, T of ``nomoto``). The overrides
    ``length_m``, ``max_rudder_deg``, ``rudder_rate_deg_s`` replace the catalogue's values.
    ``steering_gear``: ``"model"`` — the rudder moves at the vessel's own rate (the catalogue's
    steering machine); ``"solas"`` — at the SOLAS steering gear's 65°/28 s (:func:`solas_rudder_rate`),
    the rate the IMO criteria presume. An explicit ``rudder_rate_deg_s`` argument wins over both
    (a ``rudder_rate_deg_s`` among ``params``, e.g. from a vessel file, is the vessel's own).
    """
    require(steering_gear in STEERING_GEARS, "--steering-gear", steering_gear,
            f"allowed: {', '.join(STEERING_GEARS)}")
    entry = _entry(vessel)
    if steering_gear == "solas" and rudder_rate_deg_s is None:  # (over a vessel file's own rate)
        rudder_rate_deg_s = math.degrees(solas_rudder_rate(entry))
    if entry is not None and rudder_rate_deg_s is not None:
        params = {**params, "rudder_rate_deg_s": rudder_rate_deg_s}  # the model's steering machine
    if entry is not None:
        from shipgnc.vessels.config import CatalogueVesselConfig
        from shipgnc.vessels.setup import vessel_setup

        section = vessel if isinstance(vessel, CatalogueVesselConfig) else None
        if speed_mps is None:
            speed_mps = getattr(section, "speed_mps", None) or entry.design_speed_mps
        speeds = np.atleast_1d(np.asarray(speed_mps, dtype=float))
        lo, hi = entry.speed_range_mps
        for s in speeds:
            require(math.isfinite(s) and lo - 1e-9 <= s <= hi + 1e-9, "--speed-kn", round(float(s) / KNOT, 4),
                    f"{entry.name} is valid for {lo / KNOT:.4g}-{hi / KNOT:.4g} kn "
                    f"({lo:.4g}-{hi:.4g} m/s)")
        setups = [vessel_setup(section or entry.name, float(s), name=name, **params) for s in speeds]
        models = [s.model for s in setups]
        model = models[0]
        name, source = setups[0].name, entry.source
        length = setups[0].length_m if length_m is None else length_m
        max_rudder, rate = setups[0].max_rudder, setups[0].rudder_rate
        can_reverse = setups[0].can_reverse
    else:
        model = vessel
        models = None
        require(hasattr(model, "derivatives") and hasattr(model, "states"), "vessel",
                type(model).__name__, "need a catalogue name or a model with derivatives() and states")
        if speed_mps is None:
            speed_mps = getattr(getattr(model, "params", model), "U", None)
        require(speed_mps is not None, "speed_mps", None, "give the test speed of a plain model [m/s]")
        speeds = np.atleast_1d(np.asarray(speed_mps, dtype=float))
        name, source = name or type(model).__name__, ""
        length = length_m
        lim = getattr(model, "input_limits", None)
        max_rudder = float(lim()[1][0]) if lim is not None else math.radians(35.0)
        rate = math.inf
        can_reverse = getattr(model, "full_astern", None) is not None
    _refuse_course_unstable_linear(model, name)
    if max_rudder_deg is not None:
        max_rudder = math.radians(max_rudder_deg)
    if rudder_rate_deg_s is not None:
        rate = math.radians(rudder_rate_deg_s)
    require(bool(np.all(np.isfinite(speeds)) and np.all(speeds > 0)), "speed_mps", speeds.tolist(),
            "test speeds must be finite and > 0 m/s")
    if length is not None:
        require(math.isfinite(length) and length > 0, "length_m", length, "must be > 0 m")
    state_names = names(model.states)
    index = {s: state_names.index(s) for s in ("north", "east", "psi", "u", "v", "r", "delta", "n")
             if s in state_names}
    for s in ("north", "east", "psi", "r"):
        require(s in index, f"vessel {name} states", state_names, f"a trial needs a state named {s!r}")
    models = [model] * speeds.size if models is None else models
    x0, inputs0 = [], []
    for m, s in zip(models, speeds, strict=True):  # set-up: one trim per speed (each speed's own model)
        xg = _straight_state(m, float(s), index)[None]
        xt, ut = trim(m, xg, _straight_inputs(m, xg[0], index)[None], index)
        x0.append(xt[0])
        inputs0.append(ut[0])
    x0, inputs0 = np.stack(x0), np.stack(inputs0)
    speed = np.array([float(np.hypot(*_velocity(m, x0[i], inputs0[i], index)))
                      for i, m in enumerate(models)])
    if dt is None:
        dt = default_dt(model, None if length is None else length / float(np.max(speeds)))
    require(math.isfinite(dt) and dt > 0, "dt", dt, "must be > 0 s")
    return TrialShip(model=model, models=tuple(models), name=name, x0=x0, inputs0=inputs0,
                     delta0=inputs0[:, 0].copy(),
                     speed=speed, length_m=length, max_rudder=float(max_rudder), rudder_rate=float(rate),
                     can_reverse=can_reverse, full_astern=getattr(model, "full_astern", None),
                     source=source, dt=float(dt), index=index, steering_gear=steering_gear)


#: the time steps :func:`default_dt` chooses from [s]
STEPS = (1.0, 0.5, 0.25, 0.2, 0.1, 0.05, 0.02, 0.01)


def default_dt(model, l_over_v: float | None) -> float:
    """The largest of :data:`STEPS` not above L/V/40 (0.5 s without a length) nor the steering
    machine's time constant ``T_delta`` (RK4 resolves the servo lag at h ≤ T_δ)."""
    target = 0.5 if l_over_v is None else l_over_v / 40.0
    t_delta = getattr(model, "T_delta", None)
    if isinstance(t_delta, (int, float)) and t_delta > 0:
        target = min(target, float(t_delta))
    return next((h for h in STEPS if h <= target + 1e-12), STEPS[-1])


def _straight_state(model, speed: float, index: dict) -> np.ndarray:
    make = getattr(model, "straight_state", None)
    if make is not None:
        x = np.array(make(speed), dtype=float)
    else:
        x = np.zeros(len(model.states))
        if "u" in index:
            x[index["u"]] = speed
    x[index["north"]] = x[index["east"]] = x[index["psi"]] = 0.0
    return x


def _straight_inputs(model, x: np.ndarray, index: dict) -> np.ndarray:
    """Inputs that hold straight running: rudder 0, other commands at their state (n_c = n)."""
    u = np.zeros(len(model.inputs))
    held = getattr(model, "straight_inputs", None)
    if held is not None:
        u[:] = np.asarray(held(x), dtype=float)
    else:
        state_names = names(model.states)
        for j, sig in enumerate(model.inputs[1:], start=1):
            base = sig.name[:-2] if sig.name.endswith("_c") else sig.name
            if base in state_names:
                u[j] = x[state_names.index(base)]
    u[0] = x[index["delta"]] if "delta" in index else 0.0
    return u


def _velocity(model, x, u, index):
    xd = model.derivatives(x, u)
    return xd[..., index["north"]], xd[..., index["east"]]


def trim(model, x_guess: np.ndarray, u_guess: np.ndarray, index: dict, *, tol: float = 1e-12,
         max_iter: int = 50) -> tuple[np.ndarray, np.ndarray]:
    """Steady straight running with its trim rudder, for a batch of guesses (S, n), (S, m).

    Unknowns: the non-kinematic states (all but north, east, ψ) and the rudder command δ₀;
    equations: their derivatives = 0 and ψ̇ = r = 0 (a square system). Newton with a
    finite-difference Jacobian and minimum-norm least-squares steps, so states the model keeps
    constant (a constant-speed model's u) stay at their guess. Returns (x0, inputs0).
    """
    x = np.array(x_guess, dtype=float)
    u = np.array(u_guess, dtype=float)
    n = x.shape[-1]
    kin = {index["north"], index["east"], index["psi"]}
    dyn = [i for i in range(n) if i not in kin]
    rows = [*dyn, index["psi"]]

    def pack(xx, uu):
        return np.concatenate([xx[..., dyn], uu[..., :1]], axis=-1)

    def unpack(z):
        xx, uu = x.copy(), u.copy()
        xx[..., dyn] = z[..., :-1]
        uu[..., 0] = z[..., -1]
        return xx, uu

    def residual(z):
        xx, uu = unpack(z)
        return model.derivatives(xx, uu)[..., rows]

    z = pack(x, u)
    for _ in range(max_iter):
        F = residual(z)
        if np.all(np.abs(F) < tol):
            break
        k = z.shape[-1]
        J = np.empty((*z.shape[:-1], len(rows), k))
        for j in range(k):
            h = 1e-7 * max(1.0, float(np.max(np.abs(z[..., j]))))
            zp = z.copy()
            zp[..., j] += h
            J[..., :, j] = (residual(zp) - F) / h
        step = np.stack([np.linalg.lstsq(J[s], -F[s], rcond=1e-12)[0] for s in range(z.shape[0])])
        z = z + step
        if np.all(np.abs(step) < 1e-13 * (1.0 + np.abs(z))):
            break
    F = residual(z)
    scale = 1e-6 * (1.0 + np.max(np.abs(z)))
    if not np.all(np.isfinite(z)) or np.any(np.abs(F) > scale):
        raise ConfigError(f"vessel {type(model).__name__}: no steady straight run found (trim rudder "
                          f"residual {float(np.max(np.abs(F))):.3g}); is the speed within the model's range?")
    return unpack(z)


@dataclass(eq=False)
class RudderProgramme:
    """The rudder (and propeller) programme of each ship in a batch, all arrays of shape (B,).

    Step ships: command ``delta_a`` until ``t_switch``, ``delta_b`` from then on. A ship with
    ``switch_when_steady`` moves its ``t_switch`` (inf until then) to the first check at which its
    yaw rate is steady to ``switch_rel`` (a spiral's approach turn, a pull-out's steady turn).
    Zig-zag ships
    (``zz_amp`` ≠ 0): command ``delta_a + s·|zz_amp|``, s = sign(zz_amp) at execution and reversed
    (:func:`shipgnc.trials.zigzag.reverse_rudder`) each time the heading has changed ``zz_psi`` from
    the original course in the direction s turns the ship. Yaw-rate autopilot ships (``r_ref``
    finite; the reverse spiral): command ``delta_a + kp·e + ki·∫e dt``, e = r_ref − r, the
    integral clipped so that its term stays within the rudder limit. ``astern``: the propeller command goes
    to full astern at t = 0 (stopping). ``kind`` names the trial each ship belongs to.
    """

    kind: np.ndarray
    speed_index: np.ndarray
    delta_a: np.ndarray
    delta_b: np.ndarray
    t_switch: np.ndarray
    switch_when_steady: np.ndarray
    zz_amp: np.ndarray
    zz_psi: np.ndarray
    switch_rel: np.ndarray
    r_ref: np.ndarray
    kp: np.ndarray
    ki: np.ndarray
    astern: np.ndarray
    t_max: np.ndarray
    x0: np.ndarray
    inputs0: np.ndarray

    @property
    def size(self) -> int:
        return self.delta_a.shape[0]

    @classmethod
    def concat(cls, programmes) -> RudderProgramme:
        programmes = list(programmes)
        return cls(**{f: np.concatenate([getattr(p, f) for p in programmes])
                      for f in cls.__dataclass_fields__})

    def part(self, start: int, stop: int) -> RudderProgramme:
        return RudderProgramme(**{f: getattr(self, f)[start:stop] for f in self.__dataclass_fields__})


def programme(ship: TrialShip, kind: str, n: int, *, speed_index=0, delta_a=None, delta_b=None,
              t_switch=math.inf, switch_when_steady=False, zz_amp=0.0, zz_psi=math.inf,
              switch_rel=STEADY_REL, r_ref=math.nan, kp=0.0, ki=0.0, astern=False,
              t_max=3600.0) -> RudderProgramme:
    """A programme of ``n`` ships of one trial kind (scalars broadcast; rudder angles absolute [rad])."""
    idx = np.broadcast_to(np.asarray(speed_index, dtype=int), (n,))
    d0 = ship.delta0[idx]

    def arr(v, default, dtype=float):
        return np.broadcast_to(np.asarray(default if v is None else v, dtype=dtype), (n,)).copy()

    return RudderProgramme(kind=np.full(n, kind, dtype=object), speed_index=idx.copy(),
                           delta_a=arr(delta_a, d0),
                           delta_b=arr(delta_b, d0), t_switch=arr(t_switch, math.inf),
                           switch_when_steady=arr(switch_when_steady, False, bool),
                           zz_amp=arr(zz_amp, 0.0), zz_psi=arr(zz_psi, math.inf),
                           switch_rel=arr(switch_rel, STEADY_REL), r_ref=arr(r_ref, math.nan),
                           kp=arr(kp, 0.0), ki=arr(ki, 0.0),
                           astern=arr(astern, False, bool), t_max=arr(t_max, 3600.0),
                           x0=ship.x0[idx].copy(), inputs0=ship.inputs0[idx].copy())


class Stacked:
    """One batch over ships whose models differ (one model per test speed): ``derivatives``
    evaluates each distinct model on its ships (``which``: the model index of each ship along
    the batch axis, the second-to-last axis of ``x``)."""

    def __init__(self, models, which):
        self.models = tuple(models)
        self.which = np.asarray(which)
        self.masks = [self.which == i for i in range(len(self.models))]
        first = self.models[0]
        self.states, self.inputs = first.states, first.inputs
        self.state_limits = first.state_limits

    @classmethod
    def of(cls, models, which):
        used = sorted(set(np.asarray(which).tolist()))
        if len(used) == 1:
            return models[used[0]]
        return cls(models, which)

    def derivatives(self, x, u, d=None):
        out = np.empty(np.broadcast_shapes(x.shape[:-1], u.shape[:-1]) + x.shape[-1:])
        for m, mask in zip(self.models, self.masks, strict=True):
            if np.any(mask):
                out[..., mask, :] = m.derivatives(x[..., mask, :], u[..., mask, :])
        return out


@dataclass(eq=False)
class History:
    """Samples of a batched trial run: ``time`` (T,), ``x`` (T, B, n), ``rudder`` (T, B) the
    applied rudder angle, ``command`` (T, B) the rudder command, ``speed`` (T, B) the speed over
    ground [m/s], plus the programme (with the switch times that happened)."""

    time: np.ndarray
    x: np.ndarray
    rudder: np.ndarray
    command: np.ndarray
    speed: np.ndarray
    programme: RudderProgramme
    index: dict

    def state(self, name: str) -> np.ndarray:
        return self.x[..., self.index[name]]

    def part(self, start: int, stop: int) -> History:
        return History(self.time, self.x[:, start:stop], self.rudder[:, start:stop],
                       self.command[:, start:stop], self.speed[:, start:stop],
                       self.programme.part(start, stop), self.index)


def steady(time: np.ndarray, r: np.ndarray, k: int, window: float, rel=STEADY_REL) -> np.ndarray:
    """Whether the yaw rate (T, B) has been steady over the ``window`` seconds before sample k:
    its spread is below ``STEADY_ABS + rel·|r|`` (``rel`` a scalar or per ship)."""
    dt = time[1] - time[0] if time.size > 1 else 1.0
    w = max(2, round(window / dt))
    if k < w:
        return np.zeros(r.shape[1], dtype=bool)
    seg = r[k - w:k + 1]
    spread = seg.max(axis=0) - seg.min(axis=0)
    return spread <= STEADY_ABS + rel * np.abs(seg[-1])


def steady_window(ship: TrialShip) -> float:
    """Seconds over which a yaw rate must stay constant to count as steady: 3 L/V, at least 60 s."""
    lv = ship.l_over_v(0)
    return 60.0 if lv is None else max(60.0, 3.0 * lv)


def trial_actuator(ship: TrialShip):
    """The trial's actuator: with the steering machine in the model (a ``delta`` state) the
    commands pass unchanged (the model slews its rudder); else the rudder channel saturates at
    ``max_rudder`` and slews at ``rudder_rate`` (linear within a step), the other inputs pass."""
    from shipgnc.actuators import Actuator

    m = ship.n_inputs
    lower, upper, rate = np.full(m, -np.inf), np.full(m, np.inf), np.full(m, np.inf)
    if not ship.steering_in_model:
        lower[0], upper[0], rate[0] = -ship.max_rudder, ship.max_rudder, ship.rudder_rate
    return Actuator(lower, upper, rate=rate, names=names(ship.model.inputs))


def run(ship: TrialShip, prog: RudderProgramme, finished, *, dt: float | None = None,
        check_every: float = 5.0) -> History:
    """Run the batch of ``prog`` from its approach states through
    :func:`~shipgnc.sim.simulator.simulate` (fixed-step RK4), its rudder programme the
    controller (:class:`~shipgnc.trials.programme.ProgrammeController`).

    ``finished(k, hist_view) -> (B,) bool`` is asked every ``check_every`` seconds; the run ends
    when every ship is finished or at its ``t_max`` (the largest of the batch).
    """
    from shipgnc.sim.simulator import simulate
    from shipgnc.trials.programme import ProgrammeController

    if np.any(prog.astern):
        require(ship.can_reverse and ship.full_astern is not None and ship.n_inputs > 1,
                "trial stopping", ship.name, "the vessel has no propulsion that can go full astern")
    model = Stacked.of(ship.models, prog.speed_index)
    h = ship.dt if dt is None else float(dt)
    n_steps = math.ceil(float(np.max(prog.t_max)) / h)
    actuator = trial_actuator(ship)
    pilot = ProgrammeController(ship, prog, finished, dt=h, n_steps=n_steps, actuator=actuator,
                                check_every=check_every)
    res = simulate(model, prog.x0, t_end=n_steps * h, dt=h, controller=pilot, actuator=actuator,
                   u0=prog.inputs0, backend="auto", attrs={"vessel": ship.name})
    X = np.stack([res[s.name].values for s in model.states], axis=-1)
    k_end = X.shape[0] - 1
    delta_c = model.inputs[0].name
    C = res[f"{delta_c}_cmd"].values
    R = X[..., ship.index["delta"]] if ship.steering_in_model else res[delta_c].values
    # speed over ground from the model's own kinematics (works without u, v states)
    u_all = np.broadcast_to(pilot.held, (k_end + 1, *pilot.held.shape)).copy()
    u_all[..., 0] = C if ship.steering_in_model else R
    xd = model.derivatives(X, u_all)
    U = np.hypot(xd[..., ship.index["north"]], xd[..., ship.index["east"]])
    return History(res["time"].values, X, R, C, U, prog, ship.index)


def run_parts(ship: TrialShip, parts, **kw) -> list[History]:
    """Run several trials' programmes as ONE batch; returns each part's history.

    ``parts``: sequence of ``(programme, finished)`` with ``finished(ship, view, k, sl)`` → (n,)
    bool for the part's slice ``sl`` of the batch.
    """
    parts = list(parts)
    sizes = [p.size for p, _ in parts]
    bounds = np.concatenate([[0], np.cumsum(sizes)]).astype(int)
    slices = [slice(int(a), int(b)) for a, b in itertools.pairwise(bounds)]
    prog = RudderProgramme.concat(p for p, _ in parts)

    def finished(k, view):
        out = np.zeros(prog.size, dtype=bool)
        for (_, fin), sl in zip(parts, slices, strict=True):
            out[sl] = fin(ship, view, k, sl)
        return out

    hist = run(ship, prog, finished, **kw)
    return [hist.part(sl.start, sl.stop) for sl in slices]


def crossing(values: np.ndarray, level: float, start: int = 0) -> float | None:
    """Fractional sample index where ``values`` (T,) first reaches ``level`` from below, after
    ``start``; None if never."""
    v = values[start:]
    hit = np.nonzero(v >= level)[0]
    if hit.size == 0:
        return None
    j = int(hit[0])
    if j == 0:
        return float(start)
    a, b = v[j - 1], v[j]
    return start + j - 1 + float((level - a) / (b - a)) if b != a else float(start + j)


def at(values: np.ndarray, fk: float) -> float:
    """Linear interpolation of ``values`` (T,) at fractional index ``fk``."""
    k = math.floor(fk)
    if k >= values.size - 1:
        return float(values[-1])
    w = fk - k
    return float((1 - w) * values[k] + w * values[k + 1])


def track_length(north: np.ndarray, east: np.ndarray) -> np.ndarray:
    """Distance travelled along the track up to each sample [m] (T,)."""
    seg = np.hypot(np.diff(north), np.diff(east))
    return np.concatenate([[0.0], np.cumsum(seg)])


def header(ship: TrialShip, i: int = 0) -> dict:
    """The keys every trial's JSON starts with: vessel, speeds, trim rudder, L/V."""
    lv = ship.l_over_v(i)
    return {"vessel": ship.name, "source": ship.source, "length_m": ship.length_m,
            "speed_mps": float(ship.speed[i]), "speed_kn": float(ship.speed[i] / KNOT),
            "trim_rudder_deg": float(np.degrees(ship.delta0[i])),
            "l_over_v_s": None if lv is None else float(lv), "dt_s": ship.dt,
            "steering_gear": ship.steering_gear, "rudder_rate_deg_s": float(np.degrees(ship.rudder_rate))}


def finite(x):
    """A float, or None for NaN/inf (JSON)."""
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None
