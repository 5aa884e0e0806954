"""The ``vessel:`` section of a catalogue vessel (``shipgnc vessels``), validated: used by a
scenario's schema, by ``shipgnc trial --vessel FILE`` and by the vessel YAML ``shipgnc identify``
writes."""

from __future__ import annotations

from typing import Annotated, Literal

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

    def surge_equilibrium(self) -> float:
        """The steady straight run's surge speed [m/s] (``initial_state.u: null``)."""
        return float(self.build().straight_state()[3])

    def build(self):
        """The model (:meth:`shipgnc.vessels.VesselEntry.build`)."""
        from shipgnc.vessels.catalogue import get_vessel

        return get_vessel(self.model).build(self.speed_mps, **self.params())

    @model_validator(mode="after")
    def _builds(self) -> CatalogueVesselConfig:
        try:
            self.build()
        except ConfigError as exc:
            raise ValueError(str(exc)) from None
        return self
