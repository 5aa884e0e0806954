"""The scenario schema: what a scenario YAML file may contain, validated by pydantic.

Angles in scenario files are in degrees and say so in their names (``psi_deg``, ``alpha_deg``);
everything else is SI. Unknown fields are rejected, and every error names the field, the value and
what is allowed (:func:`format_validation_error`).
"""

from __future__ import annotations

import itertools
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from shipgnc.errors import ConfigError

Finite = Annotated[float, Field(allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False)]


class Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


# --------------------------------------------------------------------------- vessel, actuator

BOAT_PRESETS = ("otter", "doc-eq7", "doc-printed", "otter-munk")
BOAT_PARAM_NAMES = ("m", "X_udot", "Y_vdot", "I_z", "N_rdot", "X_u", "Y_v", "N_r", "N_rr",
                    "munk_factor", "L_m", "T_min", "T_max", "alpha_max", "alpha_max_deg")


class VesselConfig(Strict):
    """``vessel``: the model, a named parameter preset and overrides of single parameters."""

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


class ActuatorConfig(Strict):
    """``actuator``: dynamics between command and thruster (defaults: none, as in document 001)."""

    thrust_time_constant: NonNegative = 0.0
    thrust_rate: Positive | None = None
    angle_time_constant: NonNegative = 0.0
    angle_rate_deg_s: Positive | None = None


class InitialState(Strict):
    north: Finite = 0.0
    east: Finite = 0.0
    psi_deg: Finite = 0.0
    u: Finite = 0.0
    v: Finite = 0.0
    r_deg_s: Finite = 0.0


class SimulationConfig(Strict):
    """``simulation``: step, duration, integrator, seed, initial state."""

    dt: Positive = 0.05
    t_end: Positive
    integrator: Literal["rk4", "solve_ivp"] = "rk4"
    method: Literal["RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA"] = "RK45"
    rtol: Positive = 1e-3
    atol: Positive = 1e-6
    seed: Annotated[int, Field(ge=0)] | None = None
    backend: Literal["auto", "numpy", "compiled"] = "auto"
    initial_state: InitialState = Field(default_factory=InitialState)

    @model_validator(mode="after")
    def _whole_steps(self) -> SimulationConfig:
        n = round(self.t_end / self.dt)
        if n < 1 or abs(n * self.dt - self.t_end) > 1e-9 * max(1.0, self.t_end):
            raise ValueError(f"t_end = {self.t_end!r} must be a whole multiple of dt = {self.dt!r}")
        return self


# --------------------------------------------------------------------------- controllers

class CommandEntry(Strict):
    t: NonNegative
    T: Finite
    alpha_deg: Finite
    label: str = ""


class OpenLoopConfig(Strict):
    """Document 001's hand-written command sequence: piecewise-constant (T, α) from time t."""

    type: Literal["open-loop"]
    schedule: Annotated[list[CommandEntry], Field(min_length=1)]

    @field_validator("schedule")
    @classmethod
    def _ordered(cls, schedule: list[CommandEntry]) -> list[CommandEntry]:
        _check_times([e.t for e in schedule])
        return schedule


class HeadingSpeedConfig(Strict):
    """The boat's heading + speed autopilot (spec 001 §1.10)."""

    type: Literal["heading-speed"]
    Ts: Positive = 0.05
    omega_ref: Positive = 1.0
    omega: Positive = 1.0
    omega_u: Positive = 1.0
    yaw_feedforward: bool = True


ControllerConfig = Annotated[OpenLoopConfig | HeadingSpeedConfig, Field(discriminator="type")]


# --------------------------------------------------------------------------- guidance

class ReferenceEntry(Strict):
    t: NonNegative
    psi_deg: Finite
    u: Positive


class ScheduleGuidanceConfig(Strict):
    """Heading and speed set-points from time t on."""

    type: Literal["schedule"]
    schedule: Annotated[list[ReferenceEntry], Field(min_length=1)]

    @field_validator("schedule")
    @classmethod
    def _ordered(cls, schedule: list[ReferenceEntry]) -> list[ReferenceEntry]:
        _check_times([e.t for e in schedule])
        return schedule


class LOSConfig(Strict):
    """Lookahead LOS along waypoints ``[[north, east], ...]`` in m."""

    type: Literal["los"]
    waypoints: Annotated[list[tuple[Finite, Finite]], Field(min_length=2)]
    lookahead: Positive = 8.0
    speed: Positive = 1.5
    switch_radius: NonNegative = 5.0
    capture_distance: NonNegative = 20.0


GuidanceConfig = Annotated[ScheduleGuidanceConfig | LOSConfig, Field(discriminator="type")]


# --------------------------------------------------------------------------- disturbance

class ConstantForceConfig(Strict):
    """Constant body-frame force and moment [X N, Y N, N N·m]."""

    type: Literal["constant"]
    values: tuple[Finite, Finite, Finite]


class GaussianForceConfig(Strict):
    """Seeded white Gaussian force/moment, new sample each step (std [N, N, N·m])."""

    type: Literal["gaussian"]
    std: tuple[NonNegative, NonNegative, NonNegative]
    mean: tuple[Finite, Finite, Finite] = (0.0, 0.0, 0.0)


DisturbanceConfig = Annotated[ConstantForceConfig | GaussianForceConfig,
                              Field(discriminator="type")]

# --------------------------------------------------------------------------- scenario

METRIC_SETS = ("stern-kick", "heading-steps", "waypoints", "none")


class Scenario(Strict):
    """A complete, runnable scenario."""

    name: Annotated[str, Field(min_length=1, pattern=r"^[A-Za-z0-9_.\-]+$")]
    description: str = ""
    document: str = ""
    metrics: Literal["stern-kick", "heading-steps", "waypoints", "none"] = "none"
    vessel: VesselConfig = Field(default_factory=VesselConfig)
    actuator: ActuatorConfig = Field(default_factory=ActuatorConfig)
    simulation: SimulationConfig
    controller: ControllerConfig
    guidance: GuidanceConfig | None = None
    disturbance: DisturbanceConfig | None = None

    @model_validator(mode="after")
    def _consistent(self) -> Scenario:
        if self.controller.type == "heading-speed" and self.guidance is None:
            raise ValueError("controller 'heading-speed' needs a guidance section "
                             "(type: schedule or los)")
        needs = {"heading-steps": "schedule", "waypoints": "los"}
        wanted = needs.get(self.metrics)
        if wanted and (self.guidance is None or self.guidance.type != wanted):
            raise ValueError(f"metrics = {self.metrics!r} needs guidance type {wanted!r}")
        if self.metrics == "stern-kick" and self.controller.type != "open-loop":
            raise ValueError("metrics = 'stern-kick' needs controller type 'open-loop'")
        Ts = getattr(self.controller, "Ts", self.simulation.dt)
        ratio = Ts / self.simulation.dt
        if round(ratio) < 1 or abs(round(ratio) - ratio) > 1e-9 * ratio:
            raise ValueError(f"controller.Ts = {Ts!r} must be a whole multiple of "
                             f"simulation.dt = {self.simulation.dt!r}")
        return self


def _check_times(times: list[float]) -> None:
    if times[0] != 0:
        raise ValueError(f"the first entry must start at t = 0 (got t = {times[0]!r})")
    for a, b in itertools.pairwise(times):
        if not b > a:
            raise ValueError(f"times must increase strictly (t = {a!r} is followed by t = {b!r})")


def format_validation_error(error: ValidationError, source: str) -> str:
    """One line naming each bad field, its value and the rule, e.g.
    ``scenario 'x.yaml': simulation.dt = -1: Input should be greater than 0``."""
    parts = []
    for item in error.errors():
        loc = _location(item["loc"])
        msg = item["msg"].removeprefix("Value error, ")
        value = item.get("input")
        if item["type"] == "extra_forbidden":
            parts.append(f"{loc}: unknown field (check the spelling; see `shipgnc show`)")
        elif item["type"] == "missing":
            parts.append(f"{loc}: required field is missing")
        elif isinstance(value, (dict, list)) and len(repr(value)) > 60:
            parts.append(f"{loc or 'scenario'}: {msg}")
        else:
            parts.append(f"{loc or 'scenario'} = {value!r}: {msg}")
    return f"scenario {source}: " + "; ".join(parts)


def _location(loc: tuple) -> str:
    """Dotted field path without pydantic's union tag (``controller.open-loop.schedule`` →
    ``controller.schedule``)."""
    parts = [str(p) for p in loc]
    if len(parts) > 1 and parts[0] in ("controller", "guidance", "disturbance"):
        del parts[1]
    return ".".join(parts)


def validate(data: object, source: str) -> Scenario:
    """Validate raw scenario data, raising :class:`ConfigError` with a one-line message."""
    if not isinstance(data, dict):
        raise ConfigError(f"scenario {source}: expected a mapping of fields at the top level, "
                          f"got {type(data).__name__}")
    try:
        return Scenario.model_validate(data)
    except ValidationError as exc:
        raise ConfigError(format_validation_error(exc, source)) from None

