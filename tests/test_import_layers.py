"""Layers point one way: a module imports only from its own layer or the layers below it, at module
level and inside functions alike (an import moved into a function to dodge a cycle is still a
dependency). The layers, lowest first::

    core       errors, units, frames, paths, timeseries, streams, batchmath, params, kernels, outputs,
               interrupts, lifeline, memory, user_files, config_types
    physics    models, actuators, environment, routing.fields, routing.field_spec
    gnc        guidance, control, navigation
    sim        sim
    analysis   analysis, identify, trials, vessels, routing (the router and its checks)
    studies    scenarios, cases, study, rl
    front      viz, cli, modules that draw or write a run's files (``*.figures``, ``identify.report``,
               ``study.summary``, ``scenarios.write``), ``__main__``

The check reads every module's ``import`` statements (ast); nothing is imported. ``KNOWN`` lists
the dependencies that still point up, each with what removes it: the test fails on a new one, and
on a listed one that is gone (so the list only shrinks).
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "shipgnc"

LAYERS = [
    ("core", ("errors", "units", "frames", "paths", "timeseries", "streams", "batchmath", "params",
              "kernels", "outputs", "interrupts", "lifeline", "memory", "user_files", "config_types", "")),
    ("physics", ("models", "actuators", "environment", "routing.fields", "routing.field_spec")),
    ("gnc", ("guidance", "control", "navigation")),
    ("sim", ("sim",)),
    ("analysis", ("analysis", "identify", "trials", "vessels", "routing")),
    ("studies", ("scenarios", "cases", "study", "rl")),
    ("front", ("viz", "cli", "cli_identify", "cli_route", "cli_sweep", "cli_trials", "cli_vessels", "cli_design",
               "__main__", "trials.figures", "identify.report", "routing.figures", "study.summary",
               "scenarios.write")),
]

#: dependencies that still point up: (importer, imported) module prefixes → what removes it
KNOWN: dict[tuple[str, str], str] = {
}


def layer_of(module: str) -> int:
    """The layer of ``module`` (dotted, without ``shipgnc.``; the package itself is ``""``): its
    longest listed prefix. A module no layer lists fails :func:`test_every_module_has_a_layer`."""
    best, level = -1, None
    for i, (_, prefixes) in enumerate(LAYERS):
        for p in prefixes:
            if (module == p or (p and module.startswith(p + "."))) and len(p) > best:
                best, level = len(p), i
    assert level is not None, f"shipgnc.{module} is in no layer: add it to LAYERS"
    return level


def modules() -> dict[str, Path]:
    out = {}
    for path in SRC.rglob("*.py"):
        parts = list(path.relative_to(SRC).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def imports(path: Path, known: set[str]) -> set[str]:
    """The shipgnc modules ``path`` imports (without ``shipgnc.``), anywhere in the file; ``from
    package import module`` counts as the module, and so does a ``"shipgnc.module:function"``
    string (the component registry's builders, imported when first used)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and re.fullmatch(
                r"shipgnc(\.\w+)+:\w+", node.value):
            module = node.value.partition(":")[0].removeprefix("shipgnc.")
            if module in known:
                found.add(module)
            continue
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names = [f"{node.module}.{a.name}" if f"{node.module}.{a.name}".removeprefix("shipgnc.") in known
                     else node.module for a in node.names]
        else:
            continue
        found |= {n.removeprefix("shipgnc").lstrip(".") for n in names if n.split(".")[0] == "shipgnc"}
    return found


def upward() -> dict[tuple[str, str], list[str]]:
    """Every import that points to a higher layer: (importer, imported) → the importing modules."""
    known_modules = modules()
    out: dict[tuple[str, str], list[str]] = {}
    for name, path in known_modules.items():
        for target in imports(path, set(known_modules)):
            if target == "__version__" or target.startswith("__version__"):
                continue
            if layer_of(target) > layer_of(name):
                out.setdefault((name, target), []).append(str(path.relative_to(SRC.parent)))
    return out


def test_every_module_has_a_layer():
    for name in modules():
        layer_of(name)


def test_layers_point_one_way():
    found = upward()
    new = {pair: where for pair, where in found.items() if pair not in KNOWN}
    assert not new, "imports pointing to a higher layer:\n" + "\n".join(
        f"  {a} ({LAYERS[layer_of(a)][0]}) -> {b} ({LAYERS[layer_of(b)][0]})" for a, b in sorted(new))
    gone = sorted(set(KNOWN) - set(found))
    assert not gone, f"no longer imported: remove from KNOWN: {gone}"
