"""The ``vessel:`` section of a catalogue vessel (``shipgnc vessels``), validated: used by a
scenario's schema, by ``shipgnc trial --vessel FILE`` and by the vessel YAML ``shipgnc identify``
writes."""

from __future__ import annotations

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

    model: Literal["mariner-cst", "frigate", "kvlcc2", "kvlcc2-l7", "linear-3dof", "nomoto",
                   "nomoto2"]
    speed_mps: Positive | None = None
    K: Finite | None = None
    T: Finite | None = None
    T1: Finite | None = None
    T2: Finite | None = None
    T3: Finite | None = None
    a0: Finite | None = None
    a1: Finite | None = None
    a2: Finite | None = None
    a3: Finite | None = None
    M: Matrix3 | None = None
    N: Matrix3 | None = None
    B: Finite | Annotated[list[Finite], Field(min_length=3, max_length=3)] | Annotated[
        list[Annotated[list[Finite], Field(min_length=1, max_length=1)]],
        Field(min_length=3, max_length=3)] | None = None
    L: Finite | None = None
    Cb: Finite | None = None
    R66: Finite | None = None
    xg: Finite | None = None
    T_surge: Finite | None = None
    T_n: Positive | None = None
    rudder_max_deg: Annotated[float, Field(gt=0, le=90, allow_inf_nan=False)] | None = None
    rudder_rate_deg_s: Positive | None = None
    rudder_time_constant_s: Positive | None = None

    def params(self) -> dict:
        """The entry's parameters given (None left out)."""
        return {k: v for k, v in self.model_dump(exclude={"model", "speed_mps"}).items()
                if v is not None}

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

    def scalar_params(self) -> dict[str, float]:
        """The section's numeric parameters given (the matrices and ``speed_mps`` left out): what
        a study may perturb as ``vessel.params.NAME``, e.g. ``Cb`` of a vessel built from its
        main dimensions."""
        return {k: float(v) for k, v in self.params().items() if isinstance(v, (int, float))}

    def with_params(self, **changes: float):
        """The model rebuilt with some of :meth:`scalar_params` changed, validated as the file
        would be (a one-line ConfigError naming the field and its rule)."""
        from pydantic import ValidationError

        from shipgnc.config_types import format_validation_error

        allowed = self.scalar_params()
        for key in changes:
            if key not in allowed:
                raise ConfigError(f"vessel.params.{key}: not a parameter given in the {self.model} "
                                  f"vessel section; allowed: {', '.join(sorted(allowed))}")
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
