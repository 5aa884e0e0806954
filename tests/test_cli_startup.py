"""A command imports what it uses: the command line's module is light, and ``shipgnc run`` reaches its
first simulation step without the modules that only write, draw or route (their import is the
start-up a user waits through). Module lists, not timings: how long the start takes is
``benchmarks/bench_startup.py``'s to measure."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"

#: heavy libraries and packages that ``run`` needs only after its loop (the Dataset, the files, the
#: figures) or never (the router, the other commands' work)
NOT_BEFORE_FIRST_STEP = ("xarray", "pandas", "matplotlib", "dask", "distributed", "scipy.optimize",
                         "scipy.interpolate", "scipy.signal", "shipgnc.viz", "shipgnc.routing",
                         "shipgnc.study", "shipgnc.trials", "shipgnc.identify")

#: what ``import shipgnc.cli`` leaves alone (the command line parses before any work)
NOT_AT_CLI_IMPORT = ("numpy", "numba", "scipy", "xarray", "pandas", "matplotlib", "pydantic",
                     "shipgnc.scenarios", "shipgnc.sim", "shipgnc.models", "shipgnc.routing",
                     "shipgnc.viz")


def _modules(code: str, tmp_path) -> list[str]:
    out = tmp_path / "modules.json"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")]),
           "MPLBACKEND": "Agg"}
    done = subprocess.run([sys.executable, "-c", code, str(out)], env=env, cwd=tmp_path, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return json.loads(out.read_text(encoding="utf-8"))


def _loaded(modules: list[str], names: tuple[str, ...]) -> list[str]:
    return sorted({n for n in names for m in modules if m == n or m.startswith(n + ".")})


def test_importing_the_command_line_is_light(tmp_path):
    modules = _modules("import json, sys\nimport shipgnc.cli\n"
                       "open(sys.argv[1], 'w').write(json.dumps(sorted(sys.modules)))\n", tmp_path)
    assert not _loaded(modules, NOT_AT_CLI_IMPORT)


def test_run_reaches_its_first_step_without_what_it_does_not_use(tmp_path):
    """``shipgnc run boat-stern-kick --no-figures`` stopped at the entry of its loop (the numpy loop or
    the composed loop's driver, whichever the run takes): the modules imported by then."""
    code = """
import json, os, sys
import shipgnc.sim.compiled as compiled
import shipgnc.sim.simulator as simulator

def first_step(*args, **kwargs):
    with open(OUT, "w") as f:
        f.write(json.dumps(sorted(sys.modules)))
    os._exit(0)

OUT = sys.argv.pop(1)
simulator.run_numpy = compiled.drive = first_step
sys.argv = ["shipgnc", "run", "boat-stern-kick", "--no-figures", "--out", "out"]
from shipgnc.cli import main
main()
"""
    modules = _modules(code, tmp_path)
    assert "shipgnc.scenarios.runner" in modules  # the hook did stop the run at its first step
    assert not _loaded(modules, NOT_BEFORE_FIRST_STEP)
