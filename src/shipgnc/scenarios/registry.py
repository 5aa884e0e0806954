"""Built-in scenarios and loading of scenario files, with ``key=value`` overrides."""

from __future__ import annotations

import re
from importlib import resources
from pathlib import Path

import yaml

from shipgnc.errors import ConfigError
from shipgnc.scenarios.schema import Scenario, validate

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


#: bounds on a scenario file, checked before it is parsed: its size, the nesting of its sections
#: and the number of nodes once YAML aliases are expanded (a few hundred bytes of nested aliases
#: can stand for billions of nodes)
MAX_SCENARIO_BYTES = 1 << 20
MAX_NESTING = 64
MAX_EXPANDED_NODES = 200_000


class _StrictLoader(yaml.SafeLoader):
    """YAML's safe loader that refuses a key given twice in one mapping (the last would win)."""

    def construct_mapping(self, node, deep=False):
        seen: dict[object, int] = {}
        for key_node, _ in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge":  # ``<<: *base``: merged, may be overridden
                continue
            key = self.construct_object(key_node, deep=deep)
            if isinstance(key, (str, int, float, bool)) and key in seen:
                raise _DuplicateKey(key, seen[key], key_node.start_mark.line + 1)
            if isinstance(key, (str, int, float, bool)):
                seen[key] = key_node.start_mark.line + 1
        return super().construct_mapping(node, deep=deep)


class _DuplicateKey(Exception):
    def __init__(self, key: object, first: int, again: int):
        super().__init__(key, first, again)
        self.key, self.first, self.again = key, first, again


def _excerpt(text: object, limit: int = 60) -> str:
    """``repr`` of a value cut to ``limit`` characters, for messages about hostile input."""
    shown = repr(text)
    return shown if len(shown) <= limit else shown[: limit - 3] + "..."


def _check_shape(text: str, source: str) -> None:
    """Refuse nesting deeper than ``MAX_NESTING`` and alias expansion beyond
    ``MAX_EXPANDED_NODES`` before anything is built (one pass over the parser's events, then
    one pass over the composed node graph counting each shared node once per reference)."""
    depth = 0
    for event in yaml.parse(text, Loader=yaml.SafeLoader):
        if isinstance(event, (yaml.MappingStartEvent, yaml.SequenceStartEvent)):
            depth += 1
            if depth > MAX_NESTING:
                line = event.start_mark.line + 1
                raise ConfigError(f"scenario {source}: nested more than {MAX_NESTING} levels deep "
                                  f"(at line {line}); a scenario needs a handful")
        elif isinstance(event, (yaml.MappingEndEvent, yaml.SequenceEndEvent)):
            depth -= 1
    root = yaml.compose(text, Loader=yaml.SafeLoader)
    if root is None:
        return
    expanded: dict[int, int] = {}
    order, stack = [], [root]
    while stack:  # post-order without recursion: a node's size after its children's
        node = stack.pop()
        if id(node) in expanded:
            continue
        expanded[id(node)] = -1
        order.append(node)
        for child in _children(node):
            if id(child) not in expanded:
                stack.append(child)
    for node in reversed(order):
        expanded[id(node)] = 1 + sum(expanded[id(c)] for c in _children(node)
                                     if expanded[id(c)] > 0)
        if expanded[id(node)] > MAX_EXPANDED_NODES:
            raise ConfigError(f"scenario {source}: its aliases expand to more than "
                              f"{MAX_EXPANDED_NODES:,} values; a scenario needs a few hundred")


def _children(node) -> list:
    if isinstance(node, yaml.MappingNode):
        return [part for pair in node.value for part in pair]
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    return []


def _read_yaml(text: str, source: str) -> object:
    try:
        _check_shape(text, source)
        return yaml.load(text, Loader=_StrictLoader)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or "invalid YAML"
        raise ConfigError(f"scenario {source}: not valid YAML{where}: {problem}") from None
    except _DuplicateKey as dup:
        raise ConfigError(f"scenario {source}: key {_excerpt(dup.key)} given twice (lines "
                          f"{dup.first} and {dup.again}); give each field once") from None
    except RecursionError:
        raise ConfigError(f"scenario {source}: nested too deeply to read") from None


def _read_text(path: Path, source: str) -> str:
    """The file's text, refused when larger than ``MAX_SCENARIO_BYTES`` or not UTF-8."""
    try:
        size = path.stat().st_size
        if size > MAX_SCENARIO_BYTES:
            raise ConfigError(f"scenario {source}: {size:,} bytes; scenario files are limited "
                              f"to {MAX_SCENARIO_BYTES:,} bytes")
        with path.open("rb") as handle:  # a device or FIFO reports size 0: read at most the cap
            data = handle.read(MAX_SCENARIO_BYTES + 1)
    except OSError as exc:
        raise ConfigError(f"scenario {source}: cannot read ({exc.strerror or exc})") from None
    if len(data) > MAX_SCENARIO_BYTES:
        raise ConfigError(f"scenario {source}: more than {MAX_SCENARIO_BYTES:,} bytes; "
                          f"scenario files are limited to that")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ConfigError(f"scenario {source}: not UTF-8 text (byte {exc.start} is "
                          f"0x{data[exc.start]:02x}); save the file as UTF-8") from None


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
    data = _read_yaml(text, source)
    if not isinstance(data, dict):
        raise ConfigError(f"scenario {source}: expected a mapping of fields at the top level, "
                          f"got {type(data).__name__}")
    return data, source


def load_scenario(name_or_path: str, overrides: list[str] | tuple[str, ...] = ()) -> Scenario:
    """Load a built-in scenario by name or a YAML file by path, apply ``key=value`` overrides
    (dotted keys, YAML values: ``simulation.dt=0.01``, ``vessel.preset=otter-munk``) and validate."""
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
            raise ConfigError(f"--set {key}: scenario {scenario.name!r} does not use the section "
                              f"{section!r}, so the setting would be ignored; its sections: "
                              f"{', '.join(reads)}")


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
        value = yaml.load(text, Loader=_StrictLoader)
    except (yaml.YAMLError, _DuplicateKey, RecursionError):
        value = text
    if isinstance(value, str) and NUMBER.fullmatch(text.strip()):
        value = float(value)  # YAML 1.1 reads 1e-1 (no dot) as a string; "1e-1" stays one
    return key, value


def set_path(data: dict, key: str, value: object) -> None:
    """Set ``data[k1][k2]... = value`` for a dotted key; integer parts index lists."""
    parts = key.split(".")
    node: object = data
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


def scenario_yaml(scenario: Scenario) -> str:
    """The scenario as YAML (what ``shipgnc show`` prints): every field that acts on this
    scenario, with its value or default; sections that cannot change its run are left out
    (``actuator`` beyond the boat, ``quality`` beyond document 003's index, ``vessel`` of a route)."""
    data = scenario.model_dump(mode="json", exclude_none=True)
    if scenario.route is not None:
        data.pop("vessel", None)
    if scenario.route is not None or scenario.vessel.model != "vectored-thrust-boat":
        data.pop("actuator", None)
    if scenario.metrics != "course-quality":
        data.pop("quality", None)
    return yaml.safe_dump(data, sort_keys=False)
