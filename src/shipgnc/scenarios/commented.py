"""The YAML ``shipgnc show`` prints, annotated: each field's unit as a comment after its value
(``lookahead: 8.0  # m``), and the vessel's optional fields that are not set, commented out
(``# rudder_rate_deg_s: null  # deg/s, optional``). Comments only: the text reads back as the same
scenario. Units come from the sections (:func:`shipgnc.config_types.field_unit`)."""

from __future__ import annotations

import yaml
from pydantic import BaseModel

from shipgnc.config_types import DIMENSIONLESS, value_unit


def unit_comment(section: BaseModel, name: str) -> str | None:
    """``"m"``, ``"dimensionless"`` or None: the comment after field ``name`` of ``section``."""
    unit = value_unit(section, name)
    return "dimensionless" if unit == DIMENSIONLESS else unit


def commented_yaml(text: str, scenario: BaseModel) -> str:
    """``text`` (the scenario's YAML dump) with unit comments and the vessel's optional fields."""
    lines = text.splitlines()
    notes: dict[int, str] = {}
    _walk(yaml.compose(text), scenario, notes)
    for line, note in notes.items():
        lines[line] += f"  # {note}"
    vessel = getattr(scenario, "vessel", None)
    start = next((i for i, s in enumerate(lines) if s.startswith("vessel:")), None)
    if isinstance(vessel, BaseModel) and start is not None:
        end = start + 1
        while end < len(lines) and lines[end].startswith((" ", "-")):
            end += 1
        lines[end:end] = [f"  # {line}" for line in optional_lines(vessel)]
    return "\n".join(lines) + "\n"


def optional_lines(vessel: BaseModel) -> list[str]:
    """``name: null  # unit, optional`` for each optional field of a vessel section left unset
    (a catalogue vessel: the parameters its model takes, :meth:`optional_fields`)."""
    names = [name for name in type(vessel).model_fields if getattr(vessel, name) is None]
    if hasattr(vessel, "optional_fields"):
        names = [name for name in names if name in vessel.optional_fields()]
    out = []
    for name in names:
        unit = unit_comment(vessel, name)
        out.append(f"{name}: null  # {unit + ', ' if unit else ''}optional")
    return out


def _walk(node, obj, notes: dict[int, str]) -> None:
    """Note each field's unit on the line of its key, where its value starts on that line and ends
    there (a scalar, a flow collection) or on a later one (a block collection); a value spread
    over lines from the key's (a folded string) gets none."""
    if isinstance(node, yaml.MappingNode):
        for key_node, value_node in node.value:
            key = key_node.value
            if isinstance(obj, BaseModel):
                child = getattr(obj, key, None)
                unit = unit_comment(obj, key) if key in type(obj).model_fields else None
                line = key_node.start_mark.line
                if unit and (value_node.start_mark.line > line
                             or value_node.end_mark.line == line):
                    notes[line] = unit
            else:
                child = obj.get(key) if isinstance(obj, dict) else None
            _walk(value_node, child, notes)
    elif isinstance(node, yaml.SequenceNode) and isinstance(obj, (list, tuple)):
        for item_node, item in zip(node.value, obj, strict=False):
            _walk(item_node, item, notes)
