"""The ``vessel:`` section of a catalogue vessel (``shipgnc vessels``), validated: used by a
scenario's schema, by ``shipgnc trial --vessel FILE`` and by the vessel YAML ``shipgnc identify``
writes."""

from __future__ import annotations

import math
from typing import Annotated, ClassVar, Literal

from pydantic import Field, model_validator

from shipgnc.config_types import Finite, Matrix3, Positive, Strict
from shipgnc.errors import ConfigError

#: the vessel catalogue's models (``shipgnc vessels``; :mod:`shipgnc.vessels`)
CATALOGUE_VESSELS = ("mariner-cst", "frigate", "kvlcc2", "kvlcc2-l7", "linear-3dof", "nomoto",
                     "nomoto2")


class CatalogueVesselConfig(Strict):
    """``vessel`` from the catalogue (``shipgnc vessels``; :mod:`shipgnc.vessels`), SI: the model
    at ``speed_mps`` (default: its design speed) with the entry's parameters, e.g. ``K``, ``T``
    for ``nomoto``, ``M``, ``N``, ``B`` (or ``L``, ``B``, ``T``, ``Cb``, ...) for ``linear-3dof``;
    the steering machine ``rudder_max_deg``, ``rudder_rate_deg_s``, ``rudder_time_constant_s``.
    The vessel starts in its steady straight run at that speed (``initial_state`` sets position,
    heading and yaw rate)."""

    field_units: ClassVar[dict[str, str]] = {"K": "1/s",
        "T": "s (nomoto: time constant) or m (linear-3dof: draught)", "T1": "s", "T2": "s",
        "T3": "s", "a0": "rad/s", "a1": "1", "a2": "s/rad", "a3": "s²/rad²",
        "M": "kg, kg·m, kg·m² (SI)", "N": "kg/s, kg·m/s, kg·m²/s (SI)",
        "B": "m (linear-3dof beam) or N/rad, N·m/rad (input matrix)", "L": "m", "Cb": "1",
        "R66": "m", "xg": "m", "T_surge": "s", "T_n": "s"}

    #: the catalogue model (``shipgnc vessels``)
    model: Literal["mariner-cst", "frigate", "kvlcc2", "kvlcc2-l7", "linear-3dof", "nomoto",
                   "nomoto2"]
    #: the speed the model is built at (null = the model's design speed)
    speed_mps: Positive | None = None
    #: Nomoto gain (``nomoto``, ``nomoto2``)
    K: Finite | None = None
    #: Nomoto time constant (``nomoto``), or the draught (``linear-3dof`` from main dimensions)
    T: Finite | None = None
    #: ``nomoto2`` time constants T₁, T₂ (poles) and T₃ (zero)
    T1: Finite | None = None
    #: see T1
    T2: Finite | None = None
    #: see T1
    T3: Finite | None = None
    #: Norrbin's yaw-rate polynomial a₃r³ + a₂r² + a₁r + a₀ (``nomoto``; default 0)
    a0: Finite | None = None
    #: Norrbin's a₁ (see a0; default 1)
    a1: Finite | None = None
    #: Norrbin's a₂ (see a0; default 0)
    a2: Finite | None = None
    #: Norrbin's a₃ (see a0; default 0)
    a3: Finite | None = None
    #: ``linear-3dof`` mass matrix M (rigid body and added mass, surge–sway–yaw)
    M: Matrix3 | None = None
    #: ``linear-3dof`` linear damping matrix N
    N: Matrix3 | None = None
    #: the beam (``linear-3dof`` from main dimensions), or the rudder input matrix (with M, N)
    B: Finite | Annotated[list[Finite], Field(min_length=3, max_length=3)] | Annotated[
        list[Annotated[list[Finite], Field(min_length=1, max_length=1)]],
        Field(min_length=3, max_length=3)] | None = None
    #: length between perpendiculars (``linear-3dof`` from main dimensions)
    L: Finite | None = None
    #: block coefficient (``linear-3dof`` from main dimensions)
    Cb: Finite | None = None
    #: yaw radius of gyration (null = 0.27 L above 100 m, else 0.25 L)
    R66: Finite | None = None
    #: longitudinal centre of gravity from midships, positive forward (null = 0)
    xg: Finite | None = None
    #: surge time constant (null = L in seconds, as Fossen's shipClarke83)
    T_surge: Finite | None = None
    #: engine (propeller rate) time constant of the KVLCC2 (null = the model's)
    T_n: Positive | None = None
    #: rudder angle limit (null = the model's)
    rudder_max_deg: Annotated[float, Field(gt=0, le=90, allow_inf_nan=False)] | None = None
    #: rudder rate limit of the steering machine (null = the model's)
    rudder_rate_deg_s: Positive | None = None
    #: steering machine time constant (null = the model's)
    rudder_time_constant_s: Positive | None = None

    def params(self) -> dict:
        """The entry's parameters given (None left out)."""
        return {k: v for k, v in self.model_dump(exclude={"model", "speed_mps"}).items()
                if v is not None}

    def unit_of(self, name: str) -> str | None:
        """The unit of ``T`` and ``B`` for this model: a Nomoto time constant [s] or a draught
        [m]; a beam [m] or the rudder input matrix (None: the generic :attr:`field_units`)."""
        dimensions = self.model == "linear-3dof" and self.M is None
        if name == "T" and self.model in ("nomoto", "linear-3dof"):
            return "m" if dimensions else "s"
        if name == "B" and self.model == "linear-3dof":
            return "m" if dimensions else "N/rad, N·m/rad"
        return None

    def optional_fields(self) -> tuple[str, ...]:
        """The fields this model may take beside those given: ``speed_mps``, the entry's
        parameters and the steering machine (:data:`~shipgnc.vessels.catalogue.STEERING_PARAMS`);
        a ``linear-3dof`` from main dimensions does not list the matrices, nor one from matrices
        the dimensions."""
        from shipgnc.vessels.catalogue import STEERING_PARAMS, get_vessel

        names = ("speed_mps", *get_vessel(self.model).param_names, *STEERING_PARAMS)
        given = set(self.params())
        if self.model == "linear-3dof":
            exclusive = ({"M", "N"} if given & {"L", "T", "Cb"}
                         else {"L", "T", "Cb", "R66", "xg", "T_surge"} if given & {"M", "N"}
                         else set())
            names = tuple(n for n in names if n not in exclusive)
        return tuple(n for n in names if n not in given)

    def surge_equilibrium(self) -> float:
        """The steady straight run's surge speed [m/s] (``initial_state.u: null``)."""
        return float(self.build().straight_state()[3])

    def build(self):
        """The model (:meth:`shipgnc.vessels.VesselEntry.build`); it keeps this section as
        ``vessel_config``, so a study can rebuild it with a parameter changed
        (:meth:`with_params`)."""
        from shipgnc.vessels.catalogue import get_vessel

        model = get_vessel(self.model).build(self.speed_mps, **self.params())
        object.__setattr__(model, "vessel_config", self)  # frozen dataclass: set once, here
        return model

    def scalar_params(self, model=None) -> dict[str, float]:
        """What a study may perturb as ``vessel.params.NAME``: the section's numeric parameters
        given (e.g. ``Cb`` of a vessel built from its main dimensions; the matrices and
        ``speed_mps`` left out), the steering machine's ``rudder_max_deg``,
        ``rudder_rate_deg_s``, ``rudder_time_constant_s`` and the entry's other parameters the
        model holds (e.g. the KVLCC2's ``T_n``) at the values of ``model`` (default: this section
        built)."""
        out = {k: float(v) for k, v in self.params().items()
               if isinstance(v, (int, float)) and not isinstance(v, bool)}
        from shipgnc.vessels.catalogue import get_vessel

        model = self.build() if model is None else model
        held = {"rudder_max_deg": math.degrees(model.delta_max),
                "rudder_rate_deg_s": math.degrees(model.delta_rate),
                "rudder_time_constant_s": model.T_delta}
        for name in get_vessel(self.model).param_names:
            value = getattr(model, name, None)
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                held[name] = value
        for name, value in held.items():
            out.setdefault(name, float(value))
        return out

    def with_params(self, **changes: float):
        """The model rebuilt with some of :meth:`scalar_params` changed, validated as the file
        would be (a one-line ConfigError naming the field and its rule)."""
        from pydantic import ValidationError

        from shipgnc.config_types import format_validation_error

        allowed = self.scalar_params()
        changes = {k: v for k, v in changes.items() if k not in allowed or v != allowed[k]}
        for key in changes:
            if key not in allowed:
                raise ConfigError(f"vessel.params.{key}: not a number of the {self.model} vessel "
                                  f"section; allowed: {', '.join(sorted(allowed))}")
        try:
            config = type(self).model_validate({**self.model_dump(exclude_none=True), **changes})
        except ValidationError as exc:
            raise ConfigError(format_validation_error(exc, "vessel").removeprefix("scenario ")) from None
        return config.build()

    @model_validator(mode="after")
    def _builds(self) -> CatalogueVesselConfig:
        try:
            self.build()
        except ConfigError as exc:
            raise ValueError(str(exc)) from None
        return self
