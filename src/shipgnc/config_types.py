"""Validated configuration's shared pieces (pydantic): finite and positive numbers, a strict model
(unknown fields refused, frozen), a 3 × 3 matrix, and the one-line message of a failed validation
— for the scenario schema and the vessel catalogue's sections alike."""

from __future__ import annotations

from typing import Annotated, ClassVar

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from shipgnc.errors import ConfigError

Finite = Annotated[float, Field(allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False)]
Matrix3 = Annotated[list[Annotated[list[Finite], Field(min_length=3, max_length=3)]],
                    Field(min_length=3, max_length=3)]


class Strict(BaseModel):
    """A configuration section: unknown fields refused, frozen. A subclass names the units of
    its fields whose name does not carry one (:func:`field_unit`) in ``field_units``."""

    model_config = ConfigDict(extra="forbid", frozen=True)
    #: units of fields whose name carries none (or a misleading one), e.g. ``{"lookahead": "m"}``;
    #: "1" for a dimensionless number. Subclasses add to their bases' (:func:`field_unit`).
    field_units: ClassVar[dict[str, str]] = {}


#: the unit of a dimensionless number in ``field_units``
DIMENSIONLESS = "1"


def field_unit(model: type, name: str) -> str | None:
    """The unit of field ``name`` of configuration section ``model``: from ``field_units`` of the
    class or its bases, else from the unit suffix of the name (:func:`shipgnc.units.metric_label`:
    ``psi_deg`` → deg, ``speed_mps`` → m/s); None for a field without a unit (a name, a choice,
    a flag) or one not yet documented. ``"1"`` (:data:`DIMENSIONLESS`): a pure number."""
    from shipgnc.units import metric_label

    for cls in model.__mro__:
        units = vars(cls).get("field_units") or {}
        if name in units:
            return units[name]
    return metric_label(name)[1]


def format_validation_error(error: ValidationError, source: str) -> str:
    """One line naming each bad field, its value and the rule, e.g.
    ``scenario 'x.yaml': simulation.dt = -1: Input should be greater than 0``."""
    parts = []
    for item in error.errors():
        loc = _location(item["loc"])
        msg = item["msg"].removeprefix("Value error, ")
        value = item.get("input")
        if isinstance((item.get("ctx") or {}).get("error"), ConfigError) and msg.startswith(loc):
            parts.append(msg)  # a check shared with the loop (e.g. sim.simulator.whole_steps):
            # its message names the field (within the section), the value and the rule itself
        elif item["type"] == "extra_forbidden":
            parts.append(f"{loc}: unknown field (check the spelling; see `shipgnc show`)")
        elif item["type"] == "missing":
            parts.append(f"{loc}: required field is missing")
        elif isinstance(value, (dict, list)) and len(repr(value)) > 60:
            parts.append(f"{loc or 'scenario'}: {msg}")
        else:
            parts.append(f"{loc or 'scenario'} = {value!r}: {msg}")
    return f"scenario {source}: " + "; ".join(parts)


def _location(loc: tuple) -> str:
    """Dotted field path without pydantic's union tags (``controller.open-loop.schedule`` →
    ``controller.schedule``; ``controllers.pd.course.Ts`` → ``controllers.pd.Ts``)."""
    parts = [str(p) for p in loc]
    if len(parts) > 1 and parts[0] in ("controller", "guidance", "disturbance", "vessel"):
        del parts[1]
    elif len(parts) > 2 and parts[0] == "controllers":
        del parts[2]
    return ".".join(parts)


def value_unit(section: BaseModel, name: str) -> str | None:
    """The unit of field ``name`` as this section reads it: its ``unit_of(name)`` where the unit
    depends on another field (a catalogue vessel's ``T``: a time constant or a draught), else
    :func:`field_unit`."""
    unit_of = getattr(section, "unit_of", None)
    unit = unit_of(name) if unit_of is not None else None
    return unit if unit is not None else field_unit(type(section), name)


def sections(root: type[BaseModel]) -> list[type[BaseModel]]:
    """``root`` and every model its fields hold, nested (through unions, lists, dicts), in the
    order of the fields: the sections of a schema, for its reference page and its checks."""
    import typing

    found: list[type[BaseModel]] = []

    def models_in(annotation) -> None:
        if isinstance(annotation, type) and issubclass(annotation, BaseModel):
            if annotation not in found:
                found.append(annotation)
                for field in annotation.model_fields.values():
                    models_in(field.annotation)
            return
        for arg in typing.get_args(annotation):
            models_in(arg)

    models_in(root)
    return found
