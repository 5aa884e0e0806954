"""Built-in scenarios and loading of scenario files, with ``key=value`` overrides."""

from __future__ import annotations

import copy
import functools
import os
import re
from importlib import resources
from pathlib import Path

import yaml

from shipgnc.errors import ConfigError
from shipgnc.scenarios.schema import Scenario, validate
from shipgnc.user_files import (  # noqa: F401  (MAX_*: the bounds, quoted by the tests)
    MAX_EXPANDED_NODES,
    MAX_NESTING,
    MAX_SCENARIO_BYTES,
    DuplicateKey,
    StrictLoader,
)
from shipgnc.user_files import read_text as _read_text
from shipgnc.user_files import read_yaml as _read_yaml

BUILTIN_PACKAGE = "shipgnc.scenarios.builtin"
#: a decimal number, exponent allowed (YAML 1.1 leaves ``1e-1`` a string)
NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")


def _builtin_files() -> dict[str, object]:
    root = resources.files(BUILTIN_PACKAGE)
    return {entry.name.removesuffix(".yaml"): entry for entry in root.iterdir()
            if entry.name.endswith(".yaml")}


def builtin_names() -> list[str]:
    """Names of the built-in scenarios, sorted."""
    return sorted(_builtin_files())


def list_scenarios() -> list[Scenario]:
    """Every built-in scenario, validated."""
    return [load_scenario(name) for name in builtin_names()]


@functools.lru_cache(maxsize=32)
def _parsed(text: str, source: str) -> object:
    """The YAML ``text`` parsed (memoised: a study loads its scenario once per chunk)."""
    return _read_yaml(text, source)


def raw_scenario(name_or_path: str) -> tuple[dict, str]:
    """The unvalidated mapping of a built-in name or a YAML path, and a label for messages."""
    builtins = _builtin_files()
    path = Path(name_or_path)
    if name_or_path in builtins:
        text, source = builtins[name_or_path].read_text(encoding="utf-8"), repr(name_or_path)
    elif path.suffix in (".yaml", ".yml") or path.exists():
        if path.is_dir():
            raise ConfigError(f"scenario file {str(path)!r} is a directory; give a .yaml file")
        if not path.exists():
            raise ConfigError(f"scenario file {str(path)!r}: no such file")
        source = repr(str(path))
        text = _read_text(path, source)
    else:
        raise ConfigError(f"unknown scenario {name_or_path!r}; built-in scenarios: "
                          f"{', '.join(sorted(builtins))} (or give a path to a .yaml file)")
    data = copy.deepcopy(_parsed(text, source))  # the caller may write into its mapping
    if not isinstance(data, dict):
        raise ConfigError(f"scenario {source}: expected a mapping of fields at the top level, "
                          f"got {type(data).__name__}")
    return data, source


def load_scenario(name_or_path: str, overrides: list[str] | tuple[str, ...] = ()) -> Scenario:
    """Load a built-in scenario by name or a YAML file by path, apply ``key=value`` overrides
    (dotted keys, YAML values: ``simulation.dt=0.01``, ``vessel.preset=otter-munk``) and validate."""
    if not isinstance(name_or_path, (str, os.PathLike)):
        raise ConfigError(f"scenario = {name_or_path!r}: expected a built-in scenario name or the "
                          f"path of a YAML file (a str or a path), not {type(name_or_path).__name__}")
    if isinstance(overrides, (str, bytes)) or not all(isinstance(o, str) for o in overrides):
        raise ConfigError(f"overrides = {overrides!r}: expected a list of 'KEY=VALUE' strings")
    data, source = raw_scenario(name_or_path)
    keys = []
    for item in overrides:
        key, value = parse_override(item)
        set_path(data, key, value)
        if value is not None:  # KEY=null clears a setting (e.g. controllers=null): never unused
            keys.append(key)
    try:
        scenario = validate(data, source)
    except ConfigError:
        if keys:  # an override into a section the scenario does not read: say that first
            try:
                base = validate(raw_scenario(name_or_path)[0], source)
            except ConfigError:
                base = None
            if base is not None:
                refuse_unused(base, keys)
        raise
    refuse_unused(scenario, keys)
    return scenario


def refuse_unused(scenario: Scenario, keys) -> None:
    """A ConfigError naming the first dotted key whose top-level section ``scenario`` does not
    read (:meth:`Scenario.used_sections`): such an override would be accepted and ignored."""
    used = scenario.used_sections()
    for key in keys:
        section = key.split(".", 1)[0]
        if section not in used:
            reads = [s for s in used if s not in ("name", "description", "document", "metrics",
                                                  "document_figures")]
            hint = ""
            if section == "case" and scenario.vessel.model == "catamaran":  # the older spelling
                hint = (f"; {scenario.name} is written with controller(s), guidance and runs "
                        "(e.g. guidance.omega, controller.Ts or runs.NAME.controller.Ts; "
                        "shipgnc show lists them)")
            raise ConfigError(f"--set {key}: scenario {scenario.name!r} does not use the section "
                              f"{section!r}, so the setting would be ignored; its sections: "
                              f"{', '.join(reads)}{hint}")
        for field in scenario.ignored_fields():
            if key == field or key.startswith(field + "."):
                raise ConfigError(f"--set {key}: vessel model {scenario.vessel.model!r} does not "
                                  f"read {field} (the runs of scenario {scenario.name!r} set it "
                                  f"themselves), so the setting would be ignored")


def parse_override(item: str) -> tuple[str, object]:
    """``"a.b=1.5"`` → ``("a.b", 1.5)``; the value is read as YAML (numbers, lists, strings)."""
    key, sep, text = item.partition("=")
    key = key.strip()
    if not sep or not key or any(not part for part in key.split(".")):
        raise ConfigError(f"--set {item!r}: expected KEY=VALUE with a dotted key, "
                          f"e.g. simulation.dt=0.01")
    if not text.strip():
        raise ConfigError(f"--set {item!r}: missing value after '='")
    try:
        value = yaml.load(text, Loader=StrictLoader)
    except (yaml.YAMLError, DuplicateKey, RecursionError):
        value = text
    if isinstance(value, str) and NUMBER.fullmatch(text.strip()):
        value = float(value)  # YAML 1.1 reads 1e-1 (no dot) as a string; "1e-1" stays one
    return key, value


def set_path(data: dict, key: str, value: object) -> None:
    """Set ``data[k1][k2]... = value`` for a dotted key; integer parts index lists."""
    parts = key.split(".")
    node: object = data
    if len(parts) > 2 and parts[0] == "runs" and isinstance(data.get("runs"), dict):
        # a run's name may hold dots (law20@0.008, T2_k0.8): the longest name that exists
        for n in range(len(parts) - 1, 1, -1):
            if ".".join(parts[1:n]) in data["runs"]:
                parts = ["runs", ".".join(parts[1:n]), *parts[n:]]
                break
    for depth, part in enumerate(parts):
        last = depth == len(parts) - 1
        where = ".".join(parts[: depth + 1])
        if isinstance(node, dict):
            if last:
                node[part] = value
            else:
                node = node.setdefault(part, {})
        elif isinstance(node, list):
            if not part.lstrip("-").isdigit() or not -len(node) <= int(part) < len(node):
                raise ConfigError(f"--set {key}: {where!r} is not a valid index "
                                  f"(the list has {len(node)} entries)")
            if last:
                node[int(part)] = value
            else:
                node = node[int(part)]
        else:
            raise ConfigError(f"--set {key}: {'.'.join(parts[:depth])!r} is a value "
                              f"({node!r}), not a section")


def _drop_default_nulls(model, data: dict) -> None:
    """Remove from ``data`` (``model``'s dump) the ``null`` fields whose default is null: a null
    that is not the default (a GNSS ``rate_hz: null``, every control sample, against 1 Hz) stays,
    so that the printed scenario reads back as the same scenario."""
    from pydantic import BaseModel

    for name, field in type(model).model_fields.items():
        value = getattr(model, name)
        if value is None:
            if field.get_default(call_default_factory=True) is None:
                data.pop(name, None)
        elif isinstance(value, BaseModel):
            _drop_default_nulls(value, data[name])
        elif isinstance(value, (list, tuple)):
            for item, dumped in zip(value, data[name], strict=True):
                if isinstance(item, BaseModel):
                    _drop_default_nulls(item, dumped)
        elif isinstance(value, dict):
            for key, item in value.items():
                if isinstance(item, BaseModel):
                    _drop_default_nulls(item, data[name][key])


def scenario_yaml(scenario: Scenario) -> str:
    """The scenario as YAML (what ``shipgnc show`` prints): every field that acts on this
    scenario, with its value or default, so that each line is one a ``--set`` can change;
    sections it does not read (:meth:`Scenario.used_sections`: ``actuator`` beyond the boat,
    ``quality`` beyond document 003's index, ``vessel`` of a route) and fields its vessel
    ignores (:meth:`Scenario.ignored_fields`) are left out; ``runs`` as given (a ``case``
    section, the older spelling, printed as the runs it makes).
    Each field's unit is a comment after it, and the vessel's optional fields not set are listed
    commented out (:func:`~shipgnc.scenarios.commented.commented_yaml`)."""
    from shipgnc.scenarios.commented import commented_yaml

    data = scenario.model_dump(mode="json")
    _drop_default_nulls(scenario, data)
    used = set(scenario.used_sections())
    data = {key: value for key, value in data.items() if key in used}
    for field in scenario.ignored_fields():
        *parents, leaf = field.split(".")
        node = data
        for part in parents:
            node = node.get(part, {}) if isinstance(node, dict) else {}
        if isinstance(node, dict):
            node.pop(leaf, None)
    return commented_yaml(yaml.safe_dump(data, sort_keys=False), scenario)
