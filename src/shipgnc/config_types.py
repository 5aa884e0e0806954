"""Validated configuration's shared pieces (pydantic): finite and positive numbers, a strict model
(unknown fields refused, frozen), a 3 × 3 matrix, and the one-line message of a failed validation
— for the scenario schema and the vessel catalogue's sections alike."""

from __future__ import annotations

from typing import Annotated

from pydantic import BaseModel, ConfigDict, Field, ValidationError

Finite = Annotated[float, Field(allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
Matrix3 = Annotated[list[Annotated[list[Finite], Field(min_length=3, max_length=3)]],
                    Field(min_length=3, max_length=3)]


class Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


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
    """Dotted field path without pydantic's union tags (``controller.open-loop.schedule`` →
    ``controller.schedule``; ``controllers.pd.course.Ts`` → ``controllers.pd.Ts``)."""
    parts = [str(p) for p in loc]
    if len(parts) > 1 and parts[0] in ("controller", "guidance", "disturbance", "vessel"):
        del parts[1]
    elif len(parts) > 2 and parts[0] == "controllers":
        del parts[2]
    return ".".join(parts)
