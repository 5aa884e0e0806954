"""Write the field reference pages from the schema: ``docs/reference/scenario-fields.md`` (every
section of a scenario file, :class:`shipgnc.scenarios.schema.Scenario`) and
``docs/reference/vessel-file.md`` (a vessel file, :class:`shipgnc.vessels.config.
CatalogueVesselConfig`, with the catalogue's models). Each field: its type and allowed values, its
default, its unit (:func:`shipgnc.config_types.field_unit`) and the note beside it in the source.

Run ``python docs/make_reference.py`` after changing a section; tests/test_field_reference.py
checks that the committed pages are the ones this writes.
"""

from __future__ import annotations

import inspect
import re
import sys
import types
import typing
from pathlib import Path

import annotated_types as at
import yaml
from pydantic import BaseModel
from pydantic.fields import FieldInfo

from shipgnc.config_types import field_unit, sections

HERE = Path(__file__).resolve().parent
PAGES = ("scenario-fields.md", "vessel-file.md")

_ROLE = re.compile(r":[a-z:]+:`~?([^`<]*?)(?: <[^>]*>)?`")
_FIELD_LINE = re.compile(r"^    (\w+): ")


def text(doc: str) -> str:
    """reStructuredText of a docstring or comment as Markdown: ``code`` → `code`, a role
    :class:`~a.B` → `B`."""
    doc = _ROLE.sub(lambda m: f"`{m.group(1).split('.')[-1] if '~' in m.group(0) else m.group(1)}`",
                    doc)
    return doc.replace("``", "`")


def cell(value: str) -> str:
    return value.replace("|", "\\|").replace("\n", " ")


def notes(cls: type, trailing_comments: bool = True) -> dict[str, str]:
    """The comment beside each field in the class's source: ``#:`` lines above it (what autodoc
    shows on the API pages), or a ``# ...`` after it on its line."""
    out: dict[str, str] = {}
    pending: list[str] = []
    for line in inspect.getsource(cls).splitlines():
        stripped = line.strip()
        if stripped.startswith("#:"):
            pending.append(stripped[2:].strip())
            continue
        match = _FIELD_LINE.match(line)
        if match and not stripped.startswith(("def ", "@")):
            trailing = line.partition("  # ")[2].strip() if trailing_comments else ""
            if trailing.startswith(("noqa", "type:")):
                trailing = ""
            note = "\n".join(pending) or trailing
            if note:
                out[match.group(1)] = note
        pending = [] if not stripped.startswith("#") else pending
    return out


def _unwrap(annotation) -> tuple[object, list]:
    metadata = []
    while typing.get_origin(annotation) is typing.Annotated:
        annotation, *extra = typing.get_args(annotation)
        for item in extra:
            metadata.extend(item.metadata if isinstance(item, FieldInfo) else [item])
    return annotation, metadata


def _bounds(metadata: list) -> str:
    words = []
    for item in metadata:
        for kind, attr, symbol in ((at.Gt, "gt", ">"), (at.Ge, "ge", "≥"), (at.Lt, "lt", "<"),
                                   (at.Le, "le", "≤")):
            if isinstance(item, kind):
                words.append(f"{symbol} {_number(getattr(item, attr))}")
        if isinstance(item, at.MinLen) and item.min_length > 0:
            words.append(f"at least {_entries(item.min_length)}")
        if isinstance(item, at.MaxLen):
            words.append(f"at most {_entries(item.max_length)}")
    return ", ".join(words)


def _entries(n: int) -> str:
    return f"{n} {'entry' if n == 1 else 'entries'}"


def _number(value) -> str:
    if isinstance(value, int) and abs(value) >= 2**31:
        exponent = value.bit_length() - 1
        return f"2^{exponent}" if value == 2**exponent else str(value)
    return f"{value:g}" if isinstance(value, float) else str(value)


def type_text(annotation, shown: set[type], metadata: list | None = None) -> str:
    """The field's type in words, with its allowed range: ``number > 0``, ``one of `rk4`,
    `solve_ivp```, ``[number ≥ 0] × 3``, a link to a nested section. ``metadata``: the field's
    own constraints (pydantic keeps those of a field's outer ``Annotated`` there)."""
    annotation, inner = _unwrap(annotation)
    metadata = [*(metadata or []), *inner]
    lengths = {type(m): m for m in metadata if isinstance(m, (at.MinLen, at.MaxLen))}
    fixed = (lengths[at.MinLen].min_length if at.MinLen in lengths and at.MaxLen in lengths
             and lengths[at.MinLen].min_length == lengths[at.MaxLen].max_length else None)
    if fixed is not None:
        metadata = [m for m in metadata if not isinstance(m, (at.MinLen, at.MaxLen))]
    bounds = _bounds(metadata)
    origin, args = typing.get_origin(annotation), typing.get_args(annotation)
    if origin is typing.Literal:
        return "one of " + ", ".join(f"`{a}`" for a in args)
    if origin in (typing.Union, types.UnionType):
        kinds = [type_text(a, shown) for a in args if a is not type(None)]
        return " or ".join(dict.fromkeys(kinds))
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        name = annotation.__name__
        return f"[{name}](#{name.lower()})" if annotation in shown else name
    if origin in (list, tuple, dict):
        if origin is dict:
            inner = f"mapping of name → {type_text(args[1], shown)}"
        elif origin is tuple and args and args[-1] is not Ellipsis:
            parts = [type_text(a, shown) for a in args]
            inner = (f"[{parts[0]}] × {len(parts)}" if len(set(parts)) == 1
                     else "[" + ", ".join(parts) + "]")
        elif fixed is not None:
            inner = f"[{type_text(args[0], shown)}] × {fixed}"
        else:
            inner = f"list of {type_text(args[0], shown)}"
        return f"{inner} ({bounds})" if bounds else inner
    word = {float: "number", int: "integer", bool: "true or false", str: "text"}.get(
        annotation, getattr(annotation, "__name__", str(annotation)))
    if annotation is str:
        bounds = bounds.replace("at least 1 entry", "not empty").replace("entries", "characters")
    return f"{word} {bounds}" if bounds else word


def default_text(field: FieldInfo) -> str:
    if field.is_required():
        return "required"
    value = field.get_default(call_default_factory=True)
    if isinstance(value, BaseModel):
        return "its defaults"
    if isinstance(value, tuple):
        value = list(value)
    dumped = yaml.safe_dump(value, default_flow_style=True, width=10**6).strip()
    return f"`{dumped.removesuffix('...').strip()}`"


def _where(root: type) -> dict[type, str]:
    """Where each section sits in a file, as a dotted path (``simulation.initial_state``,
    ``controllers.NAME``, ``sensors[]``)."""
    where: dict[type, str] = {root: "(top level)"}

    def visit(cls: type, prefix: str) -> None:
        for name, field in cls.model_fields.items():
            path = f"{prefix}{name}"
            for model, suffix in _models(field.annotation):
                if model not in where:
                    where[model] = path + suffix
                    visit(model, path + suffix + ".")

    visit(root, "")
    return where


def _models(annotation, suffix: str = ""):
    annotation, _ = _unwrap(annotation)
    origin, args = typing.get_origin(annotation), typing.get_args(annotation)
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        yield annotation, suffix
    elif origin is dict:
        yield from _models(args[1], suffix + ".NAME")
    elif origin is list:
        yield from _models(args[0], suffix + "[]")
    else:
        for arg in args:
            yield from _models(arg, suffix)


def _tag(cls: type) -> str:
    for key in ("type", "model"):
        field = cls.model_fields.get(key)
        if field is not None:
            args = typing.get_args(_unwrap(field.annotation)[0])
            if len(args) == 1:
                return f", `{key}: {args[0]}`"
    return ""


def section_text(cls: type, where: str, shown: set[type], level: str = "##") -> str:
    rows = ["| field | type and allowed values | default | unit | note |",
            "|---|---|---|---|---|"]
    comments = notes(cls)
    for name, field in cls.model_fields.items():
        unit = field_unit(cls, name) or ""
        note = field.description or comments.get(name, "")
        rows.append(f"| `{name}` | {cell(type_text(field.annotation, shown, field.metadata))} | "
                    f"{cell(default_text(field))} | {cell(unit)} | {cell(text(note))} |")
    doc = text(inspect.cleandoc(cls.__doc__ or ""))
    where_line = f"In a file at `{where}`{_tag(cls)}." if where != "(top level)" else \
        "The top level of the file."
    return "\n\n".join(part for part in (f"{level} {cls.__name__}", where_line, doc,
                                         "\n".join(rows)) if part)


INTRO_UNITS = (
    "The **unit** column is the unit of a number as the file gives it: angles in degrees where "
    "the field's name says so (`psi_deg`, `rudder_rate_deg_s`), everything else SI unless the "
    "unit says otherwise (a document's own units: min, nm); `1` is a pure number. `shipgnc show "
    "NAME` prints a scenario with these units as comments after its fields, and a vessel's "
    "optional fields commented out.")


def scenario_page() -> str:
    from shipgnc.scenarios.schema import Scenario

    classes = sections(Scenario)
    where = _where(Scenario)
    shown = set(classes)
    head = "\n\n".join([
        "# Scenario file fields",
        "Every field a scenario YAML file may hold, section by section, as the schema validates "
        "it (unknown fields are refused with the field's name). Which sections go together — a "
        "controller that fits the vessel, the guidance it needs — is checked when the file is "
        "read; [concepts](../concepts.md) describes them, and a vessel file is "
        "[its own page](vessel-file.md).",
        INTRO_UNITS,
        "Sections: " + ", ".join(f"[{c.__name__}](#{c.__name__.lower()})" for c in classes) + "."])
    body = [section_text(cls, where[cls], shown) for cls in classes]
    return "\n\n".join([head, *body]) + "\n"


#: the worked example of the vessel page: a 12 m workboat from its main dimensions
EXAMPLE = {"vessel": {"model": "linear-3dof", "speed_mps": 5.14, "L": 12.0, "B": 4.0, "T": 1.2,
                      "Cb": 0.5, "rudder_max_deg": 35.0, "rudder_rate_deg_s": 20.0,
                      "rudder_time_constant_s": 0.2}}


def vessel_page() -> str:
    from shipgnc.vessels.catalogue import STEERING_PARAMS, VESSELS
    from shipgnc.vessels.config import CatalogueVesselConfig
    from shipgnc.vessels.files import vessel_config

    vessel_config(EXAMPLE, "the example")  # the page's example is a valid vessel file
    example = yaml.safe_dump(EXAMPLE, sort_keys=False).strip()
    rows = ["| model | what | length [m] | design speed [m/s] | speed range [m/s] | "
            "rudder limit [deg] | rudder rate [deg/s] | its parameters |",
            "|---|---|---|---|---|---|---|---|"]
    for name, entry in VESSELS.items():
        length = "—" if entry.length_m is None else _number(entry.length_m)
        low, high = entry.speed_range_mps
        params = ", ".join(f"`{p}`" for p in entry.param_names) or "—"
        rows.append(f"| `{name}` | {cell(entry.title)} | {length} | "
                    f"{entry.design_speed_mps:.4g} | {low:.3g}–{high:.3g} | "
                    f"{_degrees(entry.max_rudder_rad)} | {_degrees(entry.max_rudder_rate_rad_s)} | "
                    f"{params} |")
    return "\n\n".join([
        "# Vessel file",
        "A vessel file describes one ship of the vessel catalogue (`shipgnc vessels`) for "
        "`shipgnc trial --vessel FILE`, for a scenario's `vessel:` section and for a study; "
        "`shipgnc identify` writes one. It is a YAML mapping `vessel: {model: NAME, ...}` (or the "
        "mapping alone): the catalogue model, its speed and its parameters, and the steering "
        "machine (" + ", ".join(f"`{p}`" for p in STEERING_PARAMS) + "), which every model "
        "takes. Fields left out keep the model's own values.",
        "For example, a 12 m workboat from its main dimensions (Clarke's regression for the "
        "hydrodynamic derivatives), at 10 kn, with a small craft's steering machine (20 °/s, "
        "time constant 0.2 s: fast enough for `shipgnc design autopilot` to hold this "
        "course-unstable hull):",
        f"```yaml\n{example}\n```",
        INTRO_UNITS,
        section_text(CatalogueVesselConfig, "vessel", set(), level="##"),
        "## The catalogue's models",
        "The parameters each model takes beside `speed_mps` and the steering machine. `nomoto` "
        "needs `K` and `T` (with any of `a0`…`a3`, the Norrbin model); `nomoto2` needs `K`, `T1`, "
        "`T2`, `T3`; `linear-3dof` needs the matrices `M`, `N`, `B` or the main dimensions `L`, "
        "`B`, `T`, `Cb` (with `R66`, `xg`, `T_surge` optional), not both. A speed outside the "
        "model's range is refused. The vessels of the five documents (the Otter-class boat, "
        "CyberShip II, the Mariner, the catamaran) are set in a scenario's `vessel:` section: "
        "[scenario fields](scenario-fields.md).",
        "\n".join(rows)]) + "\n"


def _degrees(radians: float) -> str:
    import math

    return f"{math.degrees(radians):.3g}"


def pages() -> dict[str, str]:
    """The reference pages by file name, as this script writes them."""
    return {"scenario-fields.md": scenario_page(), "vessel-file.md": vessel_page()}


def main() -> None:
    out = HERE / "reference"
    out.mkdir(exist_ok=True)
    for name, page in pages().items():
        (out / name).write_text(page, encoding="utf-8")
        print(out / name, file=sys.stderr)


if __name__ == "__main__":
    main()
