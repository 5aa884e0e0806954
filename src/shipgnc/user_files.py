"""A user's file read within bounds (scenario and vessel YAML, GeoJSON polygons): at most a cap of
bytes (:func:`read_capped`: a device or a FIFO reports size 0, so the cap is on what is read). For
YAML, the nesting of its sections and the values its aliases expand to are checked before anything
is built (a few hundred bytes of nested aliases can stand for billions of nodes) and a key given
twice is an error (YAML would keep the last). Every refusal is one
:class:`~shipgnc.errors.ConfigError` naming the file."""

from __future__ import annotations

from pathlib import Path

import yaml

from shipgnc.errors import ConfigError

#: bounds on a scenario file, checked before it is parsed: its size, the nesting of its sections
#: and the number of nodes once YAML aliases are expanded (a few hundred bytes of nested aliases
#: can stand for billions of nodes)
MAX_SCENARIO_BYTES = 1 << 20
MAX_NESTING = 64
MAX_EXPANDED_NODES = 200_000


class StrictLoader(yaml.SafeLoader):
    """YAML's safe loader that refuses a key given twice in one mapping (the last would win)."""

    def construct_mapping(self, node, deep=False):
        seen: dict[object, int] = {}
        for key_node, _ in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge":  # ``<<: *base``: merged, may be overridden
                continue
            key = self.construct_object(key_node, deep=deep)
            if isinstance(key, (str, int, float, bool)) and key in seen:
                raise DuplicateKey(key, seen[key], key_node.start_mark.line + 1)
            if isinstance(key, (str, int, float, bool)):
                seen[key] = key_node.start_mark.line + 1
        return super().construct_mapping(node, deep=deep)


class DuplicateKey(Exception):
    def __init__(self, key: object, first: int, again: int):
        super().__init__(key, first, again)
        self.key, self.first, self.again = key, first, again


def excerpt(text: object, limit: int = 60) -> str:
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


def read_yaml(text: str, source: str) -> object:
    """The YAML ``text`` of ``source`` parsed strictly (bounds and duplicate keys checked first)."""
    try:
        _check_shape(text, source)
        return yaml.load(text, Loader=StrictLoader)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or "invalid YAML"
        raise ConfigError(f"scenario {source}: not valid YAML{where}: {problem}") from None
    except DuplicateKey as dup:
        raise ConfigError(f"scenario {source}: key {excerpt(dup.key)} given twice (lines "
                          f"{dup.first} and {dup.again}); give each field once") from None
    except RecursionError:
        raise ConfigError(f"scenario {source}: nested too deeply to read") from None


def read_capped(path, limit: int, where: str, kind: str) -> bytes:
    """At most ``limit`` bytes of ``path``; a ConfigError starting with ``where`` if it cannot be
    read or holds more (``kind`` names the files limited, e.g. "scenario files")."""
    try:
        with open(path, "rb") as handle:
            data = handle.read(limit + 1)
    except OSError as exc:
        raise ConfigError(f"{where}: cannot read ({exc.strerror or exc})") from None
    if len(data) > limit:
        raise ConfigError(f"{where}: more than {limit:,} bytes ({limit / 2**20:g} MiB); {kind} are "
                          "limited to that")
    return data


def read_text(path: Path, source: str) -> str:
    """The file's text, refused when larger than ``MAX_SCENARIO_BYTES`` or not UTF-8."""
    data = read_capped(path, MAX_SCENARIO_BYTES, f"scenario {source}", "scenario files")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ConfigError(f"scenario {source}: not UTF-8 text (byte {exc.start} is "
                          f"0x{data[exc.start]:02x}); save the file as UTF-8") from None
