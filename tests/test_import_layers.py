"""Layers point one way: a module imports only from its own layer or the layers below it, at module
level and inside functions alike (an import moved into a function to dodge a cycle is still a
dependency). The layers are the packages of ``[tool.importlinter]`` in ``pyproject.toml``, lowest
last::

    front      viz, cli*, __main__
    studies    scenarios, cases, study, rl
    analysis   analysis, identify, trials, vessels, routing
    sim        sim
    gnc        guidance, control, navigation
    physics    models, actuators, environment
    paths      paths (waypoint paths, the leg tracker: its batch derived from its kernel)
    derive     derive (the batch over ships derived from a scalar kernel), derived_cache
    core       errors, units, frames, timeseries, streams, batchmath, params, kernels, jit_cache,
               outputs, interrupts, lifeline, memory, user_files, config_types

import-linter checks the contract (its ``exhaustive`` option: every package and top-level module
has a layer). What it cannot see is checked here too: a ``"shipgnc.module:function"`` string, the
component registry's builders, imported when first used.
"""

from __future__ import annotations

import ast
import json
import os
import re
import subprocess
import sys
from pathlib import Path

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10 (import-linter brings tomli there)
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "shipgnc"
CONTRACT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["importlinter"]


def layers() -> list[set[str]]:
    """The contract's layers, lowest first, each the set of its packages and modules."""
    (contract,) = CONTRACT["contracts"]
    return [{name.strip() for name in layer.split(":")} for layer in reversed(contract["layers"])]


def layer_of(module: str) -> int:
    """The layer of ``shipgnc.module`` (dotted, without ``shipgnc.``): its top-level package's."""
    top = module.split(".")[0]
    for i, names in enumerate(layers()):
        if top in names:
            return i
    raise AssertionError(f"shipgnc.{module} is in no layer: add {top!r} to [tool.importlinter] in pyproject.toml")


def test_the_contract_is_kept():
    """import-linter on the source tree (not an installed copy): the layers contract holds."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(SRC.parent), os.environ.get("PYTHONPATH", "")])}
    code = ("import sys; from importlinter.cli import lint_imports; "
            "sys.exit(lint_imports(config_filename='pyproject.toml', no_cache=True, no_logo=True))")
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "1 kept, 0 broken" in done.stdout, done.stdout


def test_ignored_imports_are_the_moved_modules_only():
    """The contract's exceptions are the old names of modules that moved up into ``viz`` (kept for one
    release): each re-exports exactly the module it names, and nothing else is excused."""
    (contract,) = CONTRACT["contracts"]
    for rule in contract.get("ignore_imports", []):
        old, new = (s.strip().removeprefix("shipgnc.") for s in rule.split("->"))
        shim = SRC.joinpath(*old.split("."), "__init__.py")
        assert shim.is_file(), f"{rule}: shipgnc.{old} is not a re-exporting package"
        assert f"import shipgnc.{new} as _moved" in shim.read_text(encoding="utf-8"), rule
        assert new.startswith("viz."), rule


def test_builder_strings_point_one_way():
    """``"shipgnc.module:function"`` strings (imported when first used) obey the same layers."""
    found = []
    for path in SRC.rglob("*.py"):
        parts = list(path.relative_to(SRC).with_suffix("").parts)
        module = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and re.fullmatch(
                    r"shipgnc(\.\w+)+:\w+", node.value):
                target = node.value.partition(":")[0].removeprefix("shipgnc.")
                if module and layer_of(target) > layer_of(module):
                    found.append(f"shipgnc.{module} -> {node.value}")
    assert not found, "builder strings pointing to a higher layer:\n  " + "\n  ".join(found)


MOVED = {"routing.fields": "environment.fields", "routing.field_spec": "environment.field_spec",
         "scenarios.write": "viz.run_files", "study.summary": "viz.study_summary",
         "routing.figures": "viz.route_figures", "trials.figures": "viz.trial_figures",
         "identify.report": "viz.identify_report"}


def test_old_module_names_are_the_moved_modules():
    """Each old name imports (with a DeprecationWarning) as the very module at its new place, so
    ``from shipgnc.scenarios.write import write_outputs`` and monkeypatching through it keep working."""
    code = ("import importlib, json, warnings\n"
            f"moved = {MOVED!r}\n"
            "out = {}\n"
            "for old, new in moved.items():\n"
            "    with warnings.catch_warnings(record=True) as w:\n"
            "        warnings.simplefilter('always')\n"
            "        a = importlib.import_module('shipgnc.' + old)\n"
            "    out[old] = [a is importlib.import_module('shipgnc.' + new),\n"
            "                [str(x.message) for x in w if x.category is DeprecationWarning]]\n"
            "print(json.dumps(out))\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(SRC.parent), os.environ.get("PYTHONPATH", "")])}
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout)
    for old, new in MOVED.items():
        same, warned = out[old]
        assert same, f"shipgnc.{old} is not shipgnc.{new}"
        assert f"shipgnc.{old} is now shipgnc.{new}" in warned, (old, warned)
