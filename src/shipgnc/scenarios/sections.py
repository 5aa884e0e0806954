"""The sections of a scenario file, one pydantic model each: vessels, actuator, simulation,
controllers, guidance, disturbances, current, route, sensors, estimators.

Angles in scenario files are in degrees and say so in their names (``psi_deg``, ``alpha_deg``);
everything else is SI. Unknown fields are rejected, and every error names the field, the value and
what is allowed (:func:`~shipgnc.config_types.format_validation_error`). Which sections go together
(a controller that fits a vessel, the guidance it needs) is the component registry's
(:mod:`shipgnc.scenarios.components`); the whole scenario is :class:`~shipgnc.scenarios.schema.Scenario`.
"""

from __future__ import annotations

import itertools
import math
from typing import Annotated, ClassVar, Literal

from pydantic import AfterValidator, Field, field_validator, model_validator

from shipgnc.colav.sbmpc import SBMPCConfig
from shipgnc.colav.vo import VOConfig
from shipgnc.config_types import Finite, NonNegative, Positive, Strict
from shipgnc.errors import ConfigError

OffsetNm = Annotated[float, Field(ge=-1000, le=1000, allow_inf_nan=False)]
OffsetDeg = Annotated[float, Field(ge=-180, le=180, allow_inf_nan=False)]
#: a commanded heading, up to ten turns either way (beyond that a float's degrees lose meaning)
HeadingDeg = Annotated[float, Field(ge=-3600, le=3600, allow_inf_nan=False)]


def _in_time_order(entries: list) -> list:
    """A schedule's entries start at t = 0 and their times increase strictly."""
    times = [e.t for e in entries]
    if times[0] != 0:
        raise ValueError(f"the first entry must start at t = 0 (got t = {times[0]!r})")
    for a, b in itertools.pairwise(times):
        if not b > a:
            raise ValueError(f"times must increase strictly (t = {a!r} is followed by t = {b!r})")
    return entries


# --------------------------------------------------------------------------- vessel, actuator

BOAT_PRESETS = ("otter", "doc-eq7", "doc-printed", "otter-munk")
BOAT_PARAM_NAMES = ("m", "X_udot", "Y_vdot", "I_z", "N_rdot", "X_u", "Y_v", "N_r", "N_rr",
                    "munk_factor", "L_m", "T_min", "T_max", "alpha_max", "alpha_max_deg")


class VesselConfig(Strict):
    """``vessel`` for document 001's boat: a named parameter preset and overrides."""

    field_units: ClassVar[dict[str, str]] = {
        "params": "SI, per parameter (alpha_max rad, alpha_max_deg deg)"}

    model: Literal["vectored-thrust-boat"] = "vectored-thrust-boat"
    preset: Literal["otter", "doc-eq7", "doc-printed", "otter-munk"] = "otter"
    params: dict[str, Finite] = Field(default_factory=dict)

    @field_validator("params")
    @classmethod
    def _known_params(cls, params: dict[str, float]) -> dict[str, float]:
        for key in params:
            if key not in BOAT_PARAM_NAMES:
                raise ValueError(f"unknown parameter {key!r}; allowed: {', '.join(BOAT_PARAM_NAMES)}")
        if "alpha_max" in params and "alpha_max_deg" in params:
            raise ValueError("give alpha_max (rad) or alpha_max_deg, not both")
        return params


#: note 003-B8's rudder rate [°/s], 2.32·√70 (the same number as models.cybership2.DELTA_RATE_DEG_S)
CYBERSHIP_RUDDER_RATE_DEG_S = 2.32 * math.sqrt(70.0)


class CyberShipVesselConfig(Strict):
    """``vessel`` for CyberShip II (document 003): rudder force model, steering machine, propellers."""

    field_units: ClassVar[dict[str, str]] = {"propeller_rps": "1/s"}

    model: Literal["cybership2"]
    rudder_model: Literal["table1", "skjetne"] = "table1"
    propeller_rps: Positive = 8.13
    rudder_max_deg: Annotated[float, Field(gt=0, le=90, allow_inf_nan=False)] = 35.0
    #: steering-machine rate limit; null for none (note 003-B8 compares both). Default IMO's
    #: 2.32°/s Froude-scaled by √70: 19.4105…°/s (``models.cybership2.DELTA_RATE_DEG_S``; the
    #: indicative figures of note 003-3.8 used it rounded to 19.4)
    rudder_rate_deg_s: Positive | None = CYBERSHIP_RUDDER_RATE_DEG_S
    #: ``ramp`` — the rudder slews linearly within a step; ``hold`` — the slewed value is held over
    #: the step (a discrete rate limiter, the setting of document 003's indicative figures)
    rudder_rate_mode: Literal["ramp", "hold"] = "ramp"

    def surge_equilibrium(self) -> float:
        """The straight run's surge speed [m/s] at ``propeller_rps``: 2T(n, u) = d₁₁(u)u, δ = 0
        (0.29583… m/s at 8.13 rps, note 003-3.5)."""
        from shipgnc.models.cybership2 import CyberShip2Params, surge_equilibrium

        return surge_equilibrium(CyberShip2Params(rudder_model=self.rudder_model), self.propeller_rps)


MARINER_PARAM_NAMES = ("a", "b", "c", "r1", "r2", "f", "W", "S")


class MarinerVesselConfig(Strict):
    """``vessel`` for document 000's Mariner (de Wit–Oppe model (25)).

    ``params_paper``: coefficients in the **document's units** (min, nm, rad; note 000-0.1),
    e.g. ``{r1: 0.0375}`` for the sign-flipped sway coupling; converted to SI at the model boundary.
    The steering machine: ``rudder_max_deg``, ``rudder_rate_deg_s`` (null: no rate limit).
    """

    field_units: ClassVar[dict[str, str]] = {"params_paper": "the document's units (min, nm, rad)"}

    model: Literal["mariner"]
    params_paper: dict[str, Finite] = Field(default_factory=dict)
    rudder_max_deg: Annotated[float, Field(gt=0, le=90, allow_inf_nan=False)] = 35.0
    rudder_rate_deg_s: Positive | None = 3.8
    rudder_rate_mode: Literal["ramp", "hold"] = "ramp"

    @field_validator("params_paper")
    @classmethod
    def _known_params(cls, params: dict[str, float]) -> dict[str, float]:
        for key, value in params.items():
            if key not in MARINER_PARAM_NAMES:
                raise ValueError(f"unknown parameter {key!r}; allowed: {', '.join(MARINER_PARAM_NAMES)}")
            if abs(value) > 1e6:
                raise ValueError(f"{key} = {value!r}: beyond ±1e6 in the document's units (its "
                                 "coefficients are of order 1)")
        from shipgnc.errors import ConfigError
        from shipgnc.models.mariner import PAPER_UNITS, MarinerParams

        try:
            MarinerParams.from_paper_units(**params)
        except ConfigError as exc:  # name the paper-unit value the user gave
            field, _, rest = str(exc).partition(" = ")
            name = field.rsplit(".", 1)[-1]
            rule = rest.partition(": ")[2].strip()
            given = params.get(name)
            unit = PAPER_UNITS[name][0] if name in PAPER_UNITS else ""
            message = f"{name} = {given!r} {unit}: {rule}" if given is not None else str(exc)
            raise ValueError(message) from None
        return params

    def surge_equilibrium(self) -> float:
        """The Mariner's service speed U = S/f [m/s] (its surge is not a state)."""
        from shipgnc.models.mariner import MarinerParams

        return MarinerParams.from_paper_units(**self.params_paper).U


class CatamaranThrusterConfig(Strict):
    """``vessel.thruster``: the thruster lag (22) of document 004, T_t δ̇ = k_t v_a − δ (S8)."""

    field_units: ClassVar[dict[str, str]] = {"T_t": "s", "k_t": "1"}

    #: true lag time constant
    T_t: Positive = 2.0
    #: true gain
    k_t: Positive = 1.0


class CatamaranSpreadConfig(Strict):
    """``vessel.spread``: ``n`` plants drawn from ``seed`` (S10, check 16), each factor uniform in
    its [low, high] range, drawn in the order J, m_x, m_y."""

    field_units: ClassVar[dict[str, str]] = {"J_factor": "1", "m_x_factor": "1", "m_y_factor": "1"}

    #: number of ships (one batched run)
    n: Annotated[int, Field(ge=1)] = 40
    #: seed of the draws
    seed: Annotated[int, Field(ge=0, lt=2**63)] = 10
    #: range of the multiplier of J (yaw inertia)
    J_factor: tuple[Positive, Positive] = (0.7, 1.3)
    #: range of the multiplier of m_x
    m_x_factor: tuple[Positive, Positive] = (0.9, 1.1)
    #: range of the multiplier of m_y
    m_y_factor: tuple[Positive, Positive] = (0.9, 1.1)


class CatamaranVesselConfig(Strict):
    """``vessel`` for document 004's twin-azimuth catamaran: parameter preset (note 004-4.4).

    ``si-consistent`` (default): the physically consistent hull (SI units, sway Coriolis sign
    corrected, hull lift [A]); ``si`` (printed Coriolis sign) and ``paper`` (the listing's mixed
    units) are the document's reproductions, flagged in figures and metrics."""

    field_units: ClassVar[dict[str, str]] = {"params": "SI, per parameter"}

    model: Literal["catamaran"]
    preset: Literal["si-consistent", "si", "paper"] = "si-consistent"
    #: sway Coriolis sign, the printed model's or the consistent one (note 004-4.3); None means the
    #: preset's (consistent for ``si-consistent``, printed for ``si`` and ``paper``)
    coriolis: Literal["printed", "consistent"] | None = None
    #: resistance below V_m, the quadratic continuation or the literal fit (note 004-4.3)
    low_speed: Literal["continued", "literal"] = "continued"
    #: other :class:`CatamaranParams` overrides (SI), e.g. ``{J_zz: 4.0e6, T_v: 18000}``
    params: dict[str, Finite] = Field(default_factory=dict)
    #: the plant's true thruster lag (22) (null = the ideal thruster, δ̇ = u); the controller's
    #: model keeps the ideal one
    thruster: CatamaranThrusterConfig | None = None
    #: plant uncertainty, that many ships in one batched run, each with its own masses and
    #: inertia (the controller's model keeps the nominal ones)
    spread: CatamaranSpreadConfig | None = None

    def overrides(self) -> dict:
        """Parameter overrides of the preset (the defaults left out): the catamaran itself, plant
        and the controller's model alike."""
        out = dict(self.params)
        if self.coriolis is not None:
            out["coriolis"] = self.coriolis
        if self.low_speed != "continued":
            out["low_speed"] = self.low_speed
        return out


CATAMARAN_BUILDERS = ("turn", "steps", "fixed-angle", "sine", "heading", "actuator", "montecarlo",
                      "compare")


class CatamaranCaseConfig(Strict):
    """Document 004's case (note 004-4.7): a ``builder`` of :mod:`shipgnc.cases.catamaran` and its
    keyword ``options`` (checked against the builder's signature when the scenario is built)."""

    field_units: ClassVar[dict[str, str]] = {"options": "SI, per option"}

    builder: Literal["turn", "steps", "fixed-angle", "sine", "heading", "actuator", "montecarlo",
                     "compare"]
    options: dict[str, Finite | int | bool | str | None] = Field(default_factory=dict)



class ActuatorConfig(Strict):
    """``actuator``: dynamics between command and thruster (defaults: none, as in document 001)."""

    field_units: ClassVar[dict[str, str]] = {"thrust_time_constant": "s", "thrust_rate": "N/s",
        "angle_time_constant": "s"}

    #: first-order lag of the thrust behind its command (0 = none)
    thrust_time_constant: NonNegative = 0.0
    #: thrust rate limit (null = none)
    thrust_rate: Positive | None = None
    #: first-order lag of the thruster angle behind its command (0 = none)
    angle_time_constant: NonNegative = 0.0
    #: thruster angle rate limit (null = none)
    angle_rate_deg_s: Positive | None = None


class InitialState(Strict):
    """``simulation.initial_state``. ``u: null``: the vessel's straight-run surge equilibrium,
    computed when the scenario is validated (``shipgnc show`` prints the number): CyberShip II's
    at ``vessel.propeller_rps`` (2T(n, u) = d₁₁(u)u, δ = 0; 0.29583… m/s at 8.13 rps, note 003-3.5), the
    Mariner's U = S/f."""

    field_units: ClassVar[dict[str, str]] = {"north": "m", "east": "m", "u": "m/s", "v": "m/s"}

    #: position north of the origin
    north: Finite = 0.0
    #: position east of the origin
    east: Finite = 0.0
    #: heading, clockwise from north
    psi_deg: Finite = 0.0
    #: surge speed (null = the straight-run equilibrium)
    u: Finite | None = 0.0
    #: sway speed
    v: Finite = 0.0
    #: yaw rate
    r_deg_s: Finite = 0.0


class SimulationConfig(Strict):
    """``simulation``: step, duration, integrator, seed, initial state."""

    field_units: ClassVar[dict[str, str]] = {"dt": "s", "t_end": "s", "rtol": "1",
        "atol": "SI units of each state", "log_every": "samples"}

    #: integration and control step
    dt: Positive = 0.05
    #: duration (a whole number of steps)
    t_end: Positive
    #: fixed-step ``rk4`` or scipy's adaptive ``solve_ivp``
    integrator: Literal["rk4", "solve_ivp"] = "rk4"
    #: the ``solve_ivp`` method
    method: Literal["RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA"] = "RK45"
    #: ``solve_ivp`` relative tolerance
    rtol: Positive = 1e-3
    #: ``solve_ivp`` absolute tolerance
    atol: Positive = 1e-6
    #: seed of every random draw (noise, waves, Monte Carlo); null draws a fresh one each
    #: run, recorded in the result
    seed: Annotated[int, Field(ge=0, lt=2**63)] | None = None  # an int64: what NetCDF stores
    #: the loop, ``numpy``, ``compiled`` (numba), or ``auto`` (compiled where it can)
    backend: Literal["auto", "numpy", "compiled"] = "auto"
    #: keep every n-th sample in the result (large batches); metrics use the kept samples
    log_every: Annotated[int, Field(ge=1)] = 1
    #: the state at t = 0
    initial_state: InitialState = Field(default_factory=InitialState)

    @model_validator(mode="after")
    def _whole_steps(self) -> SimulationConfig:
        from shipgnc.sim.simulator import whole_steps  # (the rule's one check: the loop's)

        whole_steps(self.t_end, self.dt, section="simulation")
        return self


# --------------------------------------------------------------------------- controllers

class CommandEntry(Strict):
    field_units: ClassVar[dict[str, str]] = {"t": "s", "T": "N"}
    t: NonNegative
    T: Finite
    alpha_deg: Finite
    label: str = ""


class Navigated(Strict):
    """What a controller reads when the scenario has navigation: ``truth`` (the true
    state, as without navigation), ``measurement`` (the held sensor values) or ``estimate`` (the
    estimator's); default: the estimate when there is an estimator, else the measurement when
    there are sensors, else the truth. A comparison can so set the same law on each."""

    field_units: ClassVar[dict[str, str]] = {"Ts": "s"}

    sees: Literal["truth", "measurement", "estimate"] | None = None


class OpenLoopConfig(Strict):
    """Document 001's hand-written command sequence: piecewise-constant (T, α) from time t."""

    type: Literal["open-loop"]
    schedule: Annotated[list[CommandEntry], Field(min_length=1), AfterValidator(_in_time_order)]


class HeadingSpeedConfig(Navigated):
    """The boat's heading + speed autopilot (note 001-1.10)."""

    field_units: ClassVar[dict[str, str]] = {"omega_ref": "rad/s", "omega": "rad/s",
        "omega_u": "rad/s"}

    type: Literal["heading-speed"]
    Ts: Positive | None = None  # sampling period [s]; None: the simulation's dt
    #: bandwidth of the heading reference model
    omega_ref: Positive = 1.0
    #: closed-loop heading bandwidth (pole placement)
    omega: Positive = 1.0
    #: closed-loop speed bandwidth
    omega_u: Positive = 1.0
    #: feed the reference's nonlinear yaw damping N_rr·|r|·r forward
    yaw_feedforward: bool = True


COURSE_CONTROLLERS = ("pd", "smc_printed", "smc_consistent", "smc_tuned", "smc_identified")


COURSE_GAINS = {
    "pd": ("Kp", "Kd"),
    "smc_printed": ("design_model", "lam1", "lam2", "eta", "phi", "omega_n", "zeta"),
    "smc_consistent": ("design_model", "lam1", "lam2", "eta", "phi", "omega_n", "zeta"),
    "smc_tuned": ("design_model", "lam1", "lam2", "eta_rudder", "phi"),
    "smc_identified": ("lam1", "lam2", "eta_rudder", "phi"),
}


class CourseControllerConfig(Navigated):
    """Document 003's course autopilots for CyberShip II (note 003-3.2): ``variant`` picks the law;
    gains left out take the document's values (``smc_tuned``: the documented retuned ones).

    PD (eq. 3): ``Kp``, ``Kd``. SMC (eq. 9–15): the design model (``eq18`` as printed, ``eq17``,
    ``eq16``), eigenvalues ``lam1``, ``lam2`` [1/s], switching gain ``eta`` and boundary layer
    ``phi``, reference model ``omega_n`` [rad/s], ``zeta``; ``smc_tuned`` takes its switching gain
    as a rudder angle ``eta_rudder`` [rad] (η_h = η_δ |hᵀB_h|). ``smc_identified``: the same law
    and settings on the first-order Nomoto model identified from the plant's 20°/20° zig-zag
    (``design_model: identified`` gives that model to the other SMC variants too).
    """

    field_units: ClassVar[dict[str, str]] = {"Kp": "1", "Kd": "s", "lam1": "1/s", "lam2": "1/s",
        "eta": "unit of σ per s (σ = hᵀx̃, SI)", "eta_rudder": "rad",
        "phi": "unit of σ (σ = hᵀx̃, SI)", "omega_n": "rad/s", "zeta": "1",
        "bandwidth": "rad/s"}

    type: Literal["course"]
    variant: Literal["pd", "smc_printed", "smc_consistent", "smc_tuned", "smc_identified"] = "pd"
    #: with ``auto``, a catalogue vessel's PD gains are designed from its linearised yaw response
    #: (:mod:`shipgnc.vessels.autopilot_design`) to ``bandwidth`` [rad/s] (default: the rule's)
    #: and damping ``zeta``
    design: Literal["auto"] | None = None
    bandwidth: Positive | None = None
    Ts: Positive | None = None  # sampling period [s]; None: the simulation's dt
    Kp: Positive | None = None
    Kd: NonNegative | None = None
    design_model: Literal["eq18", "eq17", "eq16", "identified"] | None = None
    lam1: Annotated[float, Field(lt=0, allow_inf_nan=False)] | None = None
    lam2: Annotated[float, Field(lt=0, allow_inf_nan=False)] | None = None
    eta: Positive | None = None
    eta_rudder: Positive | None = None
    phi: Positive | None = None
    omega_n: Positive | None = None
    zeta: Positive | None = None

    @model_validator(mode="after")
    def _gains_fit_the_variant(self) -> CourseControllerConfig:
        allowed = COURSE_GAINS[self.variant]
        if self.design == "auto":
            if self.variant != "pd":
                raise ValueError(f"design: auto designs the pd autopilot, not variant {self.variant!r}")
            allowed = ("bandwidth", "zeta")
        elif self.bandwidth is not None:
            raise ValueError("bandwidth applies to design: auto only")
        for name in ("Kp", "Kd", "design_model", "lam1", "lam2", "eta", "eta_rudder", "phi",
                     "omega_n", "zeta"):
            if getattr(self, name) is not None and name not in allowed:
                where = "design: auto (gains designed)" if self.design else f"variant {self.variant!r}"
                raise ValueError(f"{name} does not apply to {where}; its settings: {', '.join(allowed)}")
        return self

    def gains(self) -> dict:
        """The settings given (the rest keep the controller's defaults)."""
        return {k: v for k, v in self.model_dump(exclude={"type", "variant", "Ts", "sees", "design",
                                                          "bandwidth"}).items()
                if v is not None}


class PathLQRConfig(Navigated):
    """Document 000's LQR with integral action (note 000-0.4): designed from ``Q``, ``R`` in the
    document's units (min / nm / rad; R = 1 as stated, R = 0.5 reproduces the print), or the gain
    ``K_paper`` = [k_y, k_ψ, k_r, k_e] used as given (min / nm / rad; the print: [3.4, 3.2, 1, 0.45]).
    ``anti_windup``: conditional integration while the rudder saturates (the document has none)."""

    field_units: ClassVar[dict[str, str]] = {"Q": "the document's units (min, nm, rad)", "R": "1",
        "K_paper": "the document's units (min, nm, rad)"}

    type: Literal["lqr"]
    Ts: Positive | None = None  # sampling period [s]; None: the simulation's dt
    Q: tuple[NonNegative, NonNegative, NonNegative, NonNegative] | None = None
    R: Positive | None = None
    K_paper: tuple[Finite, Finite, Finite, Finite] | None = None
    anti_windup: bool = False

    @model_validator(mode="after")
    def _gain_or_design(self) -> PathLQRConfig:
        if self.K_paper is not None and (self.Q is not None or self.R is not None):
            raise ValueError("give K_paper (a gain used as is) or Q and R (a design), not both "
                             "(set Q and R to null to use K_paper)")
        return self


class OutputFLConfig(Navigated):
    """Document 000's feedback linearisation of the output z = y_r + l sin ψ_r (note 000-0.5):
    ``lookahead_nm`` l = 0 is the literal design (``fl_paper``, unstable), 0.1 nm the sound variant;
    gains of (23) in the document's units. ``knows_disturbance``: b_r and d_y known (A13)."""

    field_units: ClassVar[dict[str, str]] = {"k1_per_min2": "1/min²"}

    type: Literal["fl"]
    Ts: Positive | None = None  # sampling period [s]; None: the simulation's dt
    lookahead_nm: NonNegative = 0.0
    k1_per_min2: Positive = 0.18
    k2_per_min: Positive = 0.7
    knows_disturbance: bool = True


class LOSFLConfig(Navigated):
    """LOS guidance feeding an exact FL of the yaw loop (note 000-0.5, ``los_fl``): look-ahead
    ``delta_nm`` Δ, yaw-loop gains in the document's units. By default the controller does **not**
    know the disturbances: integral LOS (gain ``integral_gain_nm_min`` κ, default U/4 =
    0.0625 nm/min, critically damped) removes the offset of the unknown current and yaw bias, and
    ẏ_r comes from successive positions. ``knows_disturbance: true`` is the
    document's oracle: b_r and d_y handed to the law (crab compensation −asin(d_y/u), A13) and
    κ = 0 unless set."""

    field_units: ClassVar[dict[str, str]] = {"kp_per_min2": "1/min²",
        "integral_gain_nm_min": "nm/min"}

    type: Literal["los-fl"]
    Ts: Positive | None = None  # sampling period [s]; None: the simulation's dt
    delta_nm: Positive = 0.5
    kp_per_min2: Positive = 1.0
    kd_per_min: Positive = 2.0
    knows_disturbance: bool = False
    integral_gain_nm_min: Annotated[float, Field(ge=0, le=10, allow_inf_nan=False)] | None = None

    @property
    def integral_gain(self) -> float:
        """κ in the document's nm/min: as set, else 0.0625 without disturbance knowledge, 0 with."""
        if self.integral_gain_nm_min is not None:
            return self.integral_gain_nm_min
        return 0.0 if self.knows_disturbance else 0.0625


class YawRateFSMConfig(Strict):
    """``controller`` type ``yaw-rate-fsm``: document 004's finite-state yaw-rate law (20) (ω̄
    from the model) or (21) (the measured r), eq. (20)–(21), designed on the scenario's vessel
    (preset and overrides), its reference the scenario's ``guidance`` (yaw rate, sine or heading
    capture). ``T_u``, ``h`` [s]: the law's time constants (null: the preset's, note 004-4.7 —
    2.5 s for ``si`` and ``si-consistent``, 0.1 s and 0.0625 s for ``paper``); ``Ts`` [s]: a
    sampled law (null: continuous, the document's mode)."""

    field_units: ClassVar[dict[str, str]] = {"T_u": "s", "h": "s", "Ts": "s", "T_a": "s",
        "k_a": "1"}

    type: Literal["yaw-rate-fsm"]
    law: Literal[20, 21] = 21
    T_u: Positive | None = None
    h: Positive | None = None
    Ts: Positive | None = None
    #: the thruster lag the law assumes, through the actuator inverse (23) (null = none, the law
    #: commands δ̇)
    T_a: Positive | None = None
    #: the thruster gain the law assumes with ``T_a`` (null = 1)
    k_a: Positive | None = None


class YawRateBaselineConfig(Strict):
    """``controller`` types ``yaw-rate-place`` (pole placement at the FSM's poles −1/T_u, −1/h),
    ``yaw-rate-pi-design`` (a PI designed on the Nomoto model for the same poles, with
    anti-windup) and ``yaw-rate-pi`` (law (20) with cos δ frozen, the PI of note 004-4.11.3):
    document 004's comparison baselines on the nominal model, fed by the scenario's yaw-rate
    guidance. ``T_u``, ``h`` [s]: null = the preset's (as ``yaw-rate-fsm``); ``Ts`` [s]: null =
    continuous."""

    field_units: ClassVar[dict[str, str]] = {"T_u": "s", "h": "s", "Ts": "s"}

    type: Literal["yaw-rate-place", "yaw-rate-pi-design", "yaw-rate-pi"]
    T_u: Positive | None = None
    h: Positive | None = None
    Ts: Positive | None = None


class HeadingLQRConfig(Strict):
    """``controller`` type ``heading-lqr``: the LQR heading autopilot of note 004-4.11.3 on the
    nominal model, tracking the ramp of heading capture (17) to ``psi_target_rad`` (K*) at
    ``omega_c`` [rad/s] itself (no guidance section)."""

    field_units: ClassVar[dict[str, str]] = {"omega_c": "rad/s", "Ts": "s"}

    type: Literal["heading-lqr"]
    psi_target_rad: Finite = 0.8
    omega_c: Positive = 0.0022
    Ts: Positive | None = None


class FixedAngleConfig(Strict):
    """``controller`` type ``fixed-angle`` (S5): no law; the thruster starts at ``delta_rad`` and
    stays there. null: the document's 0.6 rad for the printed-sign presets; on the consistent
    hull (no steady turn at 0.6 rad) the angle of the steady turn at r = 0.036434 rad/s, the
    0.6 rad run's rate in ``si``."""

    type: Literal["fixed-angle"]
    delta_rad: Finite | None = None


# --------------------------------------------------------------------------- guidance

class ReferenceEntry(Strict):
    field_units: ClassVar[dict[str, str]] = {"t": "s", "u": "m/s"}
    t: NonNegative
    psi_deg: HeadingDeg
    u: Positive


class ScheduleGuidanceConfig(Strict):
    """Heading and speed set-points from time t on."""

    type: Literal["schedule"]
    schedule: Annotated[list[ReferenceEntry], Field(min_length=1), AfterValidator(_in_time_order)]


class LOSConfig(Strict):
    """Lookahead LOS along waypoints ``[[north, east], ...]`` in m."""

    field_units: ClassVar[dict[str, str]] = {"waypoints": "m", "lookahead": "m", "speed": "m/s",
        "switch_radius": "m", "capture_distance": "m", "integral_gain": "m/s",
        "adaptive_gain": "rad/m²"}

    type: Literal["los"]
    #: ``[[north, east], ...]``, sailed in order
    waypoints: Annotated[list[tuple[Finite, Finite]], Field(min_length=2)]
    #: lookahead distance Δ along the leg
    lookahead: Positive = 8.0
    #: speed reference
    speed: Positive = 1.5
    #: switch to the next leg within this distance of the waypoint
    switch_radius: NonNegative = 5.0
    #: the cross-track metrics score each leg from this far along it (the turn onto it left out)
    capture_distance: NonNegative = 20.0
    #: σ of integral LOS against currents and steady side forces (0 = plain LOS)
    integral_gain: NonNegative = 0.0
    #: γ [rad/m²] of adaptive LOS, the crab-angle estimate (0 = none; not with integral_gain)
    adaptive_gain: NonNegative = 0.0

    @model_validator(mode="after")
    def _one_correction(self) -> LOSConfig:
        if self.integral_gain > 0 and self.adaptive_gain > 0:
            raise ValueError("integral_gain and adaptive_gain are alternatives (integral LOS or "
                             "adaptive LOS): set one of the two to 0")
        return self


class CourseEntry(Strict):
    field_units: ClassVar[dict[str, str]] = {"t": "s"}
    t: NonNegative
    psi_deg: HeadingDeg


class CourseScheduleConfig(Strict):
    """Course set-points ψ_d from time t on (no speed reference: the propellers are held)."""

    type: Literal["course-schedule"]
    schedule: Annotated[list[CourseEntry], Field(min_length=1), AfterValidator(_in_time_order)]


class PathConfig(Strict):
    """Document 000's waypoint path (note 000-A4): ``points_nm`` as printed in the document, read as
    ``caption`` (pairs are (y, x): plot-horizontal then plot-vertical; default), ``text`` (the same
    first three points, then a half-line parallel to OX) or ``literal`` (pairs are (x, y)).
    x is north, y east (NED); the last leg is a half-line; switching as in A6."""

    type: Literal["path"]
    reading: Literal["caption", "text", "literal"] = "caption"
    points_nm: Annotated[list[tuple[Finite, Finite]], Field(min_length=2)] = Field(
        default_factory=lambda: [(0.0, 0.0), (0.0, 10.0), (4.0, 12.0), (12.0, 18.0)])

    @model_validator(mode="after")
    def _enough_points(self) -> PathConfig:
        if self.reading == "text" and len(self.points_nm) < 3:
            raise ValueError("reading 'text' needs at least three points (the third leg starts at "
                             "the third)")
        for a, b in itertools.pairwise(self.points_nm):
            if a == b:
                raise ValueError(f"points_nm: {list(a)} is repeated (a zero-length leg)")
            if max(abs(v) for v in (*a, *b)) > 1e5:
                raise ValueError(f"points_nm: {list(b)} is beyond ±1e5 nm")
        return self


class YawRateGuidanceConfig(Strict):
    """A constant yaw-rate reference ω* [rad/s] (document 004, S3/S4: 0.08, 0.008, 0.00072)."""

    field_units: ClassVar[dict[str, str]] = {"omega": "rad/s"}

    type: Literal["yaw-rate"]
    omega: Finite = 0.08


class YawRateSineConfig(Strict):
    """The sine yaw-rate reference of S6, ω* = ``amplitude`` sin(8πt/t_f) with t_f = 1 500 s
    (``reading: pi``, C11) or sin(8t/t_f) (``literal``); ``amplitude`` [rad/s]."""

    field_units: ClassVar[dict[str, str]] = {"amplitude": "rad/s"}

    type: Literal["yaw-rate-sine"]
    amplitude: Finite = 0.0072
    reading: Literal["pi", "literal"] = "pi"


class SteadyTurnGuidanceConfig(Strict):
    """A constant yaw-rate reference ω* equal to the hull's steady yaw rate at thruster angle
    ``delta_rad`` (S5's "same angle" run); null: the ``fixed-angle`` controller's default angle."""

    type: Literal["steady-turn"]
    delta_rad: Finite | None = None


class HeadingCaptureConfig(Strict):
    """Heading capture (17) of S7: ω* = ±``omega_c`` [rad/s] until the heading ``psi_target_rad``
    (K*, the document's 0.8 rad) is reached, then 0; ``ramp_s`` > 0 replaces the jump to 0 by a
    ramp of that length (the same area, so the same heading)."""

    field_units: ClassVar[dict[str, str]] = {"omega_c": "rad/s"}

    type: Literal["heading-capture"]
    psi_target_rad: Finite = 0.8
    omega_c: Positive = 0.0022
    ramp_s: NonNegative = 0.0


# --------------------------------------------------------------------------- disturbance

class ConstantForceConfig(Strict):
    """Constant body-frame force and moment [X N, Y N, N N·m] (a current: the scenario's
    ``current`` section, which combines with it)."""

    field_units: ClassVar[dict[str, str]] = {"values": "N, N, N·m"}

    type: Literal["constant"]
    values: tuple[Finite, Finite, Finite]


Triple = tuple[NonNegative, NonNegative, NonNegative]


class GaussianForceConfig(Strict):
    """Seeded Gaussian force/moment noise [N, N, N·m], held over each step, in one of three forms
    (:class:`~shipgnc.environment.disturbance.GaussianForceNoise`):

    * ``psd`` — white noise of two-sided spectral density S [N²·s, N²·s, N²·m²·s]: the held value
      has σ = √(S/dt), so the vessel's response does not depend on ``simulation.dt``;
    * ``sigma_per_step`` (or its old name ``std``) — σ per step whatever the step: the old form,
      whose effect scales like √dt (``sigma_per_step: σ`` at dt₀ is ``psd: σ²·dt₀``);
    * ``stationary_std`` with ``time_constant`` [s] — a first-order Gauss–Markov process.
    """

    field_units: ClassVar[dict[str, str]] = {"psd": "N²·s, N²·s, N²·m²·s",
        "sigma_per_step": "N, N, N·m", "std": "N, N, N·m", "stationary_std": "N, N, N·m",
        "time_constant": "s", "mean": "N, N, N·m"}

    type: Literal["gaussian"]
    psd: Triple | None = None
    sigma_per_step: Triple | None = None
    std: Triple | None = None
    stationary_std: Triple | None = None
    time_constant: Positive | None = None
    mean: tuple[Finite, Finite, Finite] = (0.0, 0.0, 0.0)

    @model_validator(mode="after")
    def _one_form(self) -> GaussianForceConfig:
        given = [n for n in ("psd", "sigma_per_step", "std", "stationary_std")
                 if getattr(self, n) is not None]
        if len(given) != 1:
            raise ValueError(f"give exactly one of psd (white noise, N²·s), sigma_per_step (σ per "
                             f"step; old name std) or stationary_std with time_constant "
                             f"(Gauss-Markov); got {', '.join(given) or 'none'}")
        if (self.time_constant is None) != (self.stationary_std is None):
            raise ValueError("time_constant and stationary_std go together (the Gauss-Markov form)")
        return self

    @property
    def per_step_std(self):
        """σ per step of the per-step form (``sigma_per_step`` or its old name ``std``)."""
        return self.sigma_per_step if self.sigma_per_step is not None else self.std


class CurrentConfig(Strict):
    """``current``: an earth-fixed current on the vessel, as relative velocity (Fossen 2021 §10.3;
    :mod:`shipgnc.environment.current_field`). ``field``: the router's FIELD string in SI
    (``uniform:north=0,east=0.5`` [m/s], ``shear:k=..``, ``rotation:..``, vortices, a NetCDF file)
    or ``gauss-markov:speed=0.5,direction=90,speed_std=0.05,speed_tau=600,direction_std=10,
    direction_tau=900`` (m/s, degrees, s), joined with ``+``. A plain string is the ``field``.
    Combines with the force ``disturbance`` (constant, gaussian, waves; the Mariner's b_r and wave
    noise). Vessels: those whose registry entry takes a current
    (:data:`shipgnc.scenarios.schema.CURRENT_VESSELS`) — the boat, CyberShip II and the catamaran (its state
    holds the velocity over ground, the hull forces see ν_r = ν − ν_c) and the Mariner (its u, r are
    through the water; the current is added to its kinematics). A catamaran scenario's current acts
    on every run of its case. The Mariner's document-000 cross current ``d_y_nm_min`` is a second,
    legacy current: with a ``current`` section it must be 0, and a controller that
    ``knows_disturbance`` (the document's oracle) is refused, since it knows b_r and d_y only."""

    field: Annotated[str, Field(min_length=1)]

    @model_validator(mode="before")
    @classmethod
    def _string(cls, data):
        return {"field": data} if isinstance(data, str) else data

    @field_validator("field")
    @classmethod
    def _parses(cls, text: str) -> str:
        from shipgnc.environment.current_field import parse_current

        try:
            parse_current(text)
        except ConfigError as exc:
            raise ValueError(str(exc)) from None
        return text

    def build(self):
        """The current object (:func:`~shipgnc.environment.current_field.parse_current`)."""
        from shipgnc.environment.current_field import parse_current

        return parse_current(self.field)


class WavesConfig(Strict):
    """Irregular waves from a spectrum and the wave loads they put on the hull (note 003-3.6).

    ``hs`` [m] and ``t0`` [s] at model scale (1:70 Froude-correct: 3 m → 42.9 mm; the document's
    printed 5 mm is selectable; ``hs: 0`` is calm water, no wave load); ``t0`` is the modal period
    (the peak period for JONSWAP; unused by the one-parameter ``pm``); ``heading_deg``: the
    direction the waves travel to, clockwise from north (head seas for a ship on course 0°:
    ψ_f = 180°). Loads: Froude–Krylov pressure of each component integrated over the hull box
    (:class:`shipgnc.environment.waves.FroudeKrylovWaveLoads`), times ``gains`` (surge, sway,
    yaw; default 1 = the Froude–Krylov loads themselves, no diffraction). Calibration
    (docs/003_cybership_autopilot.md, "Wave-load calibration"): with gains 1 the
    wave-frequency heading RMS on the ±30° legs of ``cybership-waves`` is the linear-response
    (RAO) estimate of :meth:`FroudeKrylovWaveLoads.linear_response`, ≈ 0.2°.
    """

    field_units: ClassVar[dict[str, str]] = {"hs": "m", "t0": "s", "gamma": "1", "gains": "1"}

    type: Literal["waves"]
    spectrum: Literal["modified-pm", "jonswap", "pm"] = "modified-pm"
    hs: NonNegative = 0.0429
    t0: Positive = 0.8
    gamma: Annotated[float, Field(ge=1, allow_inf_nan=False)] = 3.3
    heading_deg: Finite = 180.0
    components: Annotated[int, Field(ge=4, le=2000)] = 200
    gains: tuple[NonNegative, NonNegative, NonNegative] = (1.0, 1.0, 1.0)


class MarinerDisturbanceConfig(Strict):
    """Document 000's disturbances in its units (notes 000-0.6, 000-A9–000-A11): yaw acceleration
    ``b_r_rad_min2`` added to ṙ, cross current ``d_y_nm_min`` along east (``current_frame:
    global``, the default: earth-fixed) or across the active leg (``path``: the document's reading,
    A10, which turns the current at every waypoint; every document-000 scenario sets it), and
    narrow-band wave noise added to ṙ of
    RMS ``wave_sigma_rad_min2`` (0 = off), period ``wave_period`` [s], damping ``wave_zeta``
    (seeded by ``simulation.seed``).

    ``wave_heading_sigma_deg`` calibrates the noise to a sea state instead: σ_w =
    ω₀²·σ_ψw, ω₀ = 2π/``wave_period``, so that the free ship's wave-frequency heading has RMS
    σ_ψw (its yaw rate σ_ψw·ω₀; :func:`shipgnc.environment.filtered_noise.calibrated_yaw_sigma`).
    Set it or ``wave_sigma_rad_min2``, not both.

    Any other current (a field, Gauss–Markov, gridded data) is the scenario's ``current`` section
    (:class:`CurrentConfig`); with one, ``d_y_nm_min`` must be 0 and the section may be left out
    (then b_r = 0 and no waves)."""

    field_units: ClassVar[dict[str, str]] = {"b_r_rad_min2": "rad/min²", "d_y_nm_min": "nm/min",
        "wave_sigma_rad_min2": "rad/min²", "wave_period": "s", "wave_zeta": "1"}

    type: Literal["mariner"]
    b_r_rad_min2: Finite = 0.1
    d_y_nm_min: Finite = 0.04
    current_frame: Literal["path", "global"] = "global"
    wave_sigma_rad_min2: Annotated[float, Field(ge=0, le=100, allow_inf_nan=False)] = 0.0
    wave_heading_sigma_deg: Annotated[float, Field(ge=0, le=30, allow_inf_nan=False)] | None = None
    wave_period: Annotated[float, Field(ge=0.5, le=600, allow_inf_nan=False)] = 8.0
    wave_zeta: Annotated[float, Field(gt=0, le=10, allow_inf_nan=False)] = 0.1

    @model_validator(mode="after")
    def _one_wave_level(self) -> MarinerDisturbanceConfig:
        if self.wave_heading_sigma_deg is not None and self.wave_sigma_rad_min2 > 0:
            raise ValueError(
                f"wave_heading_sigma_deg = {self.wave_heading_sigma_deg} and wave_sigma_rad_min2 = "
                f"{self.wave_sigma_rad_min2}: set one wave level, not both (wave_heading_sigma_deg: "
                "null to use the literal wave_sigma_rad_min2)")
        return self

    @property
    def wave_sigma(self) -> float:
        """RMS of the wave yaw acceleration in SI [rad/s²]: calibrated from
        ``wave_heading_sigma_deg`` when set, else ``wave_sigma_rad_min2``."""
        if self.wave_heading_sigma_deg is not None:
            from shipgnc.environment.filtered_noise import calibrated_yaw_sigma

            return calibrated_yaw_sigma(math.radians(self.wave_heading_sigma_deg), self.wave_period)
        return self.wave_sigma_rad_min2 / 3600.0

    @property
    def b_r(self) -> float:
        """b_r in SI [rad/s²]."""
        return self.b_r_rad_min2 / 3600.0

    @property
    def d_y(self) -> float:
        """d_y in SI [m/s]."""
        return self.d_y_nm_min * 1852.0 / 60.0


# --------------------------------------------------------------------------- scenario

class RouteConfig(Strict):
    """Document 002's routing problem (document 002): as ``shipgnc route`` takes it. With ``units:
    nautical`` positions and ``radius``/``grid`` are in nm, ``speed`` in kn, ``horizon``/``depart``
    in h and the FIELD parameters as the route command reads them (k, ω in 1/h, Γ in nm²/h);
    ``obstacles``: polygons of [north, east] vertices in the same length unit."""

    field_units: ClassVar[dict[str, str]] = {"start": "m (nm with units: nautical)",
        "target": "m (nm with units: nautical)", "speed": "m/s (kn with units: nautical)",
        "obstacles": "m (nm with units: nautical)", "radius": "m (nm with units: nautical)",
        "depart": "s (h with units: nautical)", "horizon": "s (h with units: nautical)",
        "grid": "m (nm with units: nautical)"}

    units: Literal["si", "nautical"] = "si"
    start: tuple[Finite, Finite]
    target: tuple[Finite, Finite]
    speed: Positive
    field: Annotated[str, Field(min_length=1)]
    method: Literal["auto", "pmp", "levelset", "graph"] = "auto"
    obstacles: list[Annotated[list[tuple[Finite, Finite]], Field(min_length=3)]] = Field(default_factory=list)
    radius: NonNegative = 0.0
    depart: NonNegative = 0.0
    horizon: Positive | None = None
    grid: Positive | None = None

    def unit_of(self, name: str) -> str | None:
        """The unit of a length, speed or time field in this route's ``units``."""
        unit = self.field_units.get(name)
        if unit is None:
            return None
        si, _, nautical = unit.partition(" (")
        return nautical.split(" with")[0] if self.units == "nautical" else si


class SailConfig(Strict):
    """The route sailed by a ship (note 002-2.9.7; :mod:`shipgnc.scenarios.routing`), SI units.

    ``vessel``: ``vectored-thrust-boat`` (document 001's Otter-class boat, ``preset``, with a current
    as relative velocity, under its heading and speed autopilot) sails the route three ways: as a path
    (LOS through ``path_points`` waypoints on the route's track, ``lookahead`` [m], default four boat
    lengths, integral LOS gain ``integral_gain``), by the optimal heading programme, and by ``legs``
    constant-heading legs. ``mariner`` (document 000's Mariner under a feedback-linearising heading
    autopilot, the route's speed must be its U = 15 kn) sails the last two. A ship has arrived when
    it comes within ``acceptance_radius`` [m] of the target (default ``acceptance_lengths`` vessel
    lengths, Fossen's circle-of-acceptance rule R = 2 L); otherwise the run reports ``arrived:
    false``, no arrival time and its miss distance (closest approach)."""

    field_units: ClassVar[dict[str, str]] = {"dt": "s", "margin": "1", "acceptance_radius": "m",
        "acceptance_lengths": "vessel lengths", "lookahead": "m", "integral_gain": "m/s"}

    vessel: Literal["vectored-thrust-boat", "mariner"] = "vectored-thrust-boat"
    #: the boat's parameter preset (note 001-1.6); unused by the Mariner
    preset: Literal["otter", "doc-eq7", "doc-printed", "otter-munk"] = "otter"
    legs: Annotated[int, Field(ge=1, le=50)] = 4
    #: simulation step [s]; default 0.1 s for the boat, 0.3 s for the Mariner
    dt: Positive | None = None
    #: run this long past the optimal arrival time (fraction of it); a ship not within the
    #: acceptance radius by then has not arrived
    margin: Annotated[float, Field(ge=0, le=2, allow_inf_nan=False)] = 0.5
    acceptance_radius: Positive | None = None
    acceptance_lengths: Positive = 2.0
    path_points: Annotated[int, Field(ge=2, le=2000)] = 40
    lookahead: Positive | None = None
    integral_gain: NonNegative = 0.0
    #: the simulation loop of the sailed runs, as ``simulation.backend`` (a route scenario has no
    #: simulation section): auto, numpy, or compiled (the composed loop, or an error naming why not)
    backend: Literal["auto", "numpy", "compiled"] = "auto"


class MonteCarloConfig(Strict):
    """A batch of ``runs`` ships in one simulation, each with its own initial offset and sea.

    The initial state is ``simulation.initial_state`` plus an offset drawn uniformly from
    ``east_offset_nm`` added to east (a cross-track offset under the caption and text readings,
    whose first leg points north) and a heading offset drawn uniformly from
    ``heading_offset_deg``; each ship gets its own wave realisation (same ``simulation.seed``,
    same batch). The divergence guard stops the whole batch at the first ship that trips it."""

    #: number of ships in the batch
    runs: Annotated[int, Field(ge=1, le=100_000)] = 1000
    east_offset_nm: tuple[OffsetNm, OffsetNm] = (-1.0, 1.0)
    heading_offset_deg: tuple[OffsetDeg, OffsetDeg] = (-20.0, 20.0)

    @model_validator(mode="after")
    def _ordered(self) -> MonteCarloConfig:
        for name in ("east_offset_nm", "heading_offset_deg"):
            low, high = getattr(self, name)
            if not low <= high:
                raise ValueError(f"{name} = [{low}, {high}]: need low <= high")
        return self


class QualityConfig(Strict):
    """Quality index J = Σ(Δψ² + λδ²) of document 003 eq. (2)."""

    field_units: ClassVar[dict[str, str]] = {"lam": "1"}

    lam: NonNegative = 1.0


# --------------------------------------------------------------------------- collision avoidance

class TargetLegEntry(Strict):
    """From time ``t`` on, the target holds ``course_deg`` and ``speed`` over ground."""

    field_units: ClassVar[dict[str, str]] = {"t": "s", "speed": "m/s"}
    t: NonNegative
    course_deg: HeadingDeg
    speed: NonNegative


class TargetVesselConfig(Strict):
    """The steering of a vessel target (:mod:`shipgnc.guidance.vessel_targets`): ``model``
    ``frigate`` (van Amerongen's 1982 K, T, n₃ at the target's ``speed``, the catalogue's frigate)
    or ``nomoto`` (``K``, ``T`` and ``n3`` given, e.g. identified from trials); the PD heading
    autopilot ``Kp``, ``Kd``; the steering machine; lookahead LOS along the target's waypoints."""

    field_units: ClassVar[dict[str, str]] = {
        "K": "1/s", "T": "s", "n3": "s²/rad²", "Kp": "1", "Kd": "s", "delta_max_deg": "deg",
        "delta_rate_deg": "deg/s", "T_delta": "s", "lookahead": "m", "switch_radius": "m"}

    model: Literal["frigate", "nomoto"] = "frigate"
    K: Positive | None = None
    T: Positive | None = None
    n3: NonNegative | None = None
    Kp: NonNegative = 1.0
    Kd: NonNegative = 20.0
    delta_max_deg: Annotated[float, Field(gt=0, le=90, allow_inf_nan=False)] = 30.0
    delta_rate_deg: Positive = 10.0
    T_delta: Positive = 1.0
    lookahead: Positive = 500.0
    switch_radius: NonNegative = 0.0

    @model_validator(mode="after")
    def _gains_for_nomoto(self):
        given = [k for k in ("K", "T", "n3") if getattr(self, k) is not None]
        if self.model == "frigate" and given:
            raise ValueError(f"{', '.join(given)} with model frigate: its K, T, n3 follow from "
                             "the speed (van Amerongen 1982); use model: nomoto to give them")
        if self.model == "nomoto" and (self.K is None or self.T is None):
            raise ValueError("model nomoto needs K [1/s] and T [s]")
        return self


class TargetConfig(Strict):
    """A target ship: at (``north``, ``east``) at t = 0. Kinematic: holding ``course_deg`` and
    ``speed`` over ground, or following ``schedule`` (course and speed from each entry's time on;
    the first entry at t = 0 replaces ``course_deg`` and ``speed``). A vessel (``vessel`` given):
    steered by its own autopilot at ``speed`` along ``waypoints`` (from its start; none: straight
    on ``course_deg``), its heading at t = 0 ``course_deg`` (default: toward its first waypoint),
    running its own ``avoidance`` against the own ship."""

    field_units: ClassVar[dict[str, str]] = {"north": "m", "east": "m", "speed": "m/s",
                                             "length": "m", "beam": "m", "waypoints": "m"}

    name: str = ""
    mmsi: Annotated[int, Field(ge=0, le=999_999_999)] = 0
    north: Finite
    east: Finite
    course_deg: HeadingDeg = 0.0
    speed: NonNegative = 0.0
    schedule: Annotated[list[TargetLegEntry], Field(min_length=1),
                        AfterValidator(_in_time_order)] | None = None
    length: Positive = 100.0
    beam: Positive = 20.0
    #: a vessel target's steering model and autopilot (null = a kinematic target)
    vessel: TargetVesselConfig | None = None
    #: a vessel target's waypoints ``[[north, east], ...]`` after its start
    waypoints: Annotated[list[tuple[Finite, Finite]], Field(min_length=1)] | None = None
    #: a vessel target's own collision avoidance (seeing the own ship as it is)
    avoidance: Literal["none", "sbmpc", "vo"] = "none"

    @model_validator(mode="after")
    def _schedule_or_course(self):
        given = sorted({"course_deg", "speed"} & self.model_fields_set)
        if self.schedule is not None and given:
            raise ValueError(f"{' and '.join(given)} with a schedule: give one or the other "
                             "(the schedule's entries set course and speed)")
        if self.vessel is None:
            # as written back by ``shipgnc show``: the defaults (no waypoints, avoidance none) pass
            extra = [name for name, unset in (("avoidance", "none"), ("waypoints", None))
                     if name in self.model_fields_set and getattr(self, name) not in (unset, [])]
            if extra:
                raise ValueError(f"{' and '.join(extra)} need{'s' if len(extra) == 1 else ''} a "
                                 "vessel target (give vessel: "
                                 "{model: frigate}); a kinematic target follows its schedule")
        elif self.schedule is not None:
            raise ValueError("schedule with a vessel target: a vessel follows its waypoints")
        elif self.speed <= 0:
            raise ValueError("a vessel target needs speed > 0 m/s")
        return self

    def vessel_target(self, label: str = "target", where: str = ""):
        """The vessel target as a :class:`~shipgnc.guidance.vessel_targets.VesselTarget`: K, T,
        n₃ of its model at its speed, heading ``course_deg`` or toward the first waypoint; its
        errors name the field ``where`` (``guidance.targets[j]``)."""
        from shipgnc.guidance.vessel_targets import VesselTarget

        v = self.vessel
        if v.model == "frigate":
            from shipgnc.vessels.frigate import frigate_gains

            K, T, n3 = frigate_gains(self.speed)
        else:
            K, T, n3 = v.K, v.T, v.n3 or 0.0
        if self.waypoints:
            first = self.waypoints[0]
            bearing = math.atan2(first[1] - self.east, first[0] - self.north)
            psi = math.radians(self.course_deg) if "course_deg" in self.model_fields_set \
                else bearing
            waypoints = self.waypoints
        else:
            psi = math.radians(self.course_deg)
            far = 1e3 * self.speed * 3600.0  # a thousand hours on: the straight run
            waypoints = [(self.north + far * math.cos(psi), self.east + far * math.sin(psi))]
        return VesselTarget(
            north=self.north, east=self.east, psi=psi, U=self.speed, K=K, T=T, n3=n3,
            waypoints=waypoints, Kp=v.Kp, Kd=v.Kd,
            delta_max=math.radians(v.delta_max_deg), delta_rate=math.radians(v.delta_rate_deg),
            T_delta=v.T_delta, lookahead=v.lookahead, switch_radius=v.switch_radius,
            avoidance=self.avoidance, mmsi=self.mmsi, name=self.name or label,
            length=self.length, beam=self.beam, where=where)

    def track(self, label: str = "target"):
        """The target as a :class:`~shipgnc.colav.tracks.TargetTrack`: one sample per leg, each
        leg's start reached by sailing the previous leg (exact dead reckoning)."""
        from shipgnc.colav.tracks import TargetTrack

        legs = self.schedule or [TargetLegEntry(t=0.0, course_deg=self.course_deg, speed=self.speed)]
        t, north, east, vn, ve = [], [], [], [], []
        n, e = self.north, self.east
        for k, leg in enumerate(legs):
            if k:
                dt = leg.t - t[-1]
                n, e = n + vn[-1] * dt, e + ve[-1] * dt
            t.append(leg.t)
            north.append(n)
            east.append(e)
            vn.append(leg.speed * math.cos(math.radians(leg.course_deg)))
            ve.append(leg.speed * math.sin(math.radians(leg.course_deg)))
        return TargetTrack(t=t, north=north, east=east, v_north=vn, v_east=ve, mmsi=self.mmsi,
                           name=self.name or label, length=self.length, beam=self.beam)


class AISLogConfig(Strict):
    """Targets replayed from a logged AIS file (NMEA or CSV, :func:`shipgnc.ais.logs.read_log`):
    one target per MMSI (the logging ship's own ``!AIVDO`` reports left out), dead-reckoned between
    its reports; positions in the local plane about ``origin`` (lat, lon) [deg], where the own
    ship's ``simulation.initial_state`` (north, east) is; null: the centre of the data."""

    field_units: ClassVar[dict[str, str]] = {"origin": "deg"}

    path: Annotated[str, Field(min_length=1)]
    origin: tuple[Annotated[float, Field(ge=-90, le=90)],
                  Annotated[float, Field(ge=-180, le=180)]] | None = None
    #: a message without a time of its own is refused (``refuse``), or takes the time of the line
    #: before it (``previous``)
    untimed: Literal["refuse", "previous"] = "refuse"


class AISAwarenessConfig(Strict):
    """How the own ship hears its targets with ``awareness: ais``
    (:func:`shipgnc.ais.reporting.seen_tracks`): each target's reports at the ITU-R M.1371-5
    intervals of its speed and rate of turn (or every ``interval``), each lost with probability
    ``dropout``, its position off by Gaussian noise of ``position_noise_m`` in north and in east,
    every value through the message's resolution; between reports the last one is dead-reckoned
    from its SOG and COG; positions go through the message about ``ais_log.origin`` (else
    0°, 0°). Target j draws from ``SeedSequence([seed, 0, j])``."""

    field_units: ClassVar[dict[str, str]] = {"position_noise_m": "m", "dropout": "1",
                                             "interval": "s", "seed": "1"}

    #: seed of the noise and the dropouts (the same seed, the same reports)
    seed: Annotated[int, Field(ge=0)] = 0
    #: standard deviation of the reported position's error, in north and in east
    position_noise_m: NonNegative = 0.0
    #: probability that a report is lost
    dropout: Annotated[float, Field(ge=0, lt=1)] = 0.0
    #: the targets' AIS class, ``A``, ``B-SO`` or ``B-CS`` (their reporting intervals)
    ais_class: Literal["A", "B-SO", "B-CS"] = "A"
    #: the targets report as at anchor or moored (Class A every 3 min when not faster than 3 kn)
    anchored: bool = False
    #: a fixed reporting interval instead of the standard's (null = the standard's)
    interval: Positive | None = None


class ColavConfig(Strict):
    """Collision avoidance between the path guidance and the autopilot
    (:mod:`shipgnc.guidance.colav`): lookahead LOS along ``waypoints`` gives the nominal course,
    ``method`` turns it away from the ``targets`` (``none``: the nominal, the baseline)."""

    field_units: ClassVar[dict[str, str]] = {"waypoints": "m", "lookahead": "m", "speed": "m/s",
                                             "switch_radius": "m", "safety_radius": "m",
                                             "decision_interval": "s"}

    type: Literal["colav"]
    #: ``none`` (the nominal course, the baseline), ``sbmpc`` (simulation-based MPC) or ``vo``
    #: (velocity obstacles with COLREG constraints)
    method: Literal["none", "sbmpc", "vo"] = "none"
    #: SB-MPC's behaviour set, horizon and weights (Johansen, Perez & Cristofaro 2016)
    sbmpc: SBMPCConfig = Field(default_factory=SBMPCConfig)
    #: the velocity obstacles' safety radius, horizon and candidates (Kuwata et al. 2014)
    vo: VOConfig = Field(default_factory=VOConfig)
    #: the avoidance method decides every this many seconds (its choice held in between)
    decision_interval: NonNegative = 5.0
    #: ``[[north, east], ...]``, sailed in order (the nominal path)
    waypoints: Annotated[list[tuple[Finite, Finite]], Field(min_length=2)]
    #: lookahead distance Δ of the nominal LOS
    lookahead: Positive = 500.0
    #: nominal speed over ground (null = the vessel's straight-run speed)
    speed: Positive | None = None
    #: switch to the next leg within this distance of the waypoint
    switch_radius: NonNegative = 0.0
    #: the ship domain of the ``colav`` metrics (a target closer than this is a collision)
    safety_radius: Positive = 200.0
    #: the target ships
    targets: list[TargetConfig] = Field(default_factory=list)
    #: more targets, replayed from a logged AIS file
    ais_log: AISLogConfig | None = None
    #: what the avoidance sees of the targets, ``truth`` (their true tracks) or ``ais`` (their
    #: AIS reports as ``ais`` sets them; kinematic and logged targets only, not vessel targets);
    #: the ``colav`` scores are against the truth either way
    awareness: Literal["truth", "ais"] = "truth"
    #: the AIS reception of ``awareness: ais``
    ais: AISAwarenessConfig = Field(default_factory=AISAwarenessConfig)

    @model_validator(mode="after")
    def _ais_sees_tracks(self):
        vessels = [j for j, target in enumerate(self.targets) if target.vessel is not None]
        if self.awareness == "ais" and vessels:
            raise ValueError(f"awareness ais with a vessel target (targets[{vessels[0]}].vessel): "
                             "AIS awareness sees kinematic and logged targets only; use awareness: "
                             "truth, or a course and speed or schedule for that target")
        return self


# the navigation sections live with their components, beside their registry records
# (shipgnc.navigation.sensors, .ekf, .passive_observer); re-exported here by their old home
from shipgnc.navigation.ekf import EKFConfig  # noqa: E402, F401
from shipgnc.navigation.passive_observer import PassiveObserverConfig  # noqa: E402, F401
from shipgnc.navigation.sensors import (  # noqa: E402, F401
    MAX_SENSOR_ERROR,
    CompassConfig,
    GNSSConfig,
    GyroConfig,
    SpeedLogConfig,
)
from shipgnc.navigation.sensors import SensorConfigBase as _SensorBase  # noqa: E402, F401

