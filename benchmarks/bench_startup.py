"""Start-up of the command line: what a fresh process spends before it works.

    python benchmarks/bench_startup.py [--quick]

Times, each a fresh ``python -m shipgnc`` process (the numba disk cache already filled by a first,
untimed run):

(a) ``shipgnc run boat-stern-kick --no-figures``: process start → its first simulation step (the entry
    of the loop that steps the plant: the numpy loop, or the composed loop's driver before it loads
    or compiles its kernel), in wall seconds and in the process's CPU seconds; then the whole command.
    The modules imported by then are counted, and the heavy ones that the run does not need named.
(b) ``shipgnc route`` on document 002's shear case (nautical units, ``--json``): the whole process,
    against the same route solved by :func:`shipgnc.routing.router.solve_route` in a process that has
    solved it once already (the warm library call). The difference is the command's start-up: imports,
    numba's start and its cache loads.

On a shared machine wall times grow with the load (printed beside them); CPU seconds do not, and are
the figures to compare between runs. Writes ``benchmarks/results/bench_startup.json``
(``..._quick.json`` with ``--quick``).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_boat import machine_info, write_report

#: a first step's time is taken by wrapping the loops' entry points as their modules load
#: (``sys.argv[1]`` is the parent's clock just before it started the process)
FIRST_STEP_HOOK = r"""
import atexit, importlib.abc, importlib.util, json, sys, time
T0 = float(sys.argv.pop(1))
OUT = sys.argv.pop(1)
marks = {}
WATCH = {"shipgnc.sim.simulator": "run_numpy", "shipgnc.sim.compiled": "drive"}

def first_step():
    if "first_step_s" not in marks:
        marks["first_step_s"] = time.time() - T0
        marks["first_step_cpu_s"] = time.process_time()
        marks["modules"] = sorted(sys.modules)

class Hook(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path, target=None):
        if name not in WATCH:
            return None
        attr = WATCH.pop(name)
        if not WATCH:
            sys.meta_path.remove(self)
        spec = importlib.util.find_spec(name)
        load = spec.loader.exec_module
        def exec_module(module):
            load(module)
            inner = getattr(module, attr)
            def wrapped(*a, **k):
                first_step()
                return inner(*a, **k)
            setattr(module, attr, wrapped)
        spec.loader.exec_module = exec_module
        return spec

def done():  # an exit handler: the command ends by os._exit once they ran (shipgnc.__main__)
    marks["exit_s"] = time.time() - T0
    marks["exit_cpu_s"] = time.process_time()
    with open(OUT, "w", encoding="utf-8") as f:
        json.dump(marks, f)

atexit.register(done)
sys.meta_path.insert(0, Hook())
sys.argv[0] = "shipgnc"
from shipgnc.__main__ import main
main()
"""

WARM_ROUTE = r"""
import json, sys, time
from shipgnc.routing import parse_field, solve_route
from shipgnc.units import KNOT, NAUTICAL_MILE

field = parse_field("shear:k=-0.5", "nautical")
a, b = [-1.86 * NAUTICAL_MILE, 3.66 * NAUTICAL_MILE], [0.0, 0.0]
solve_route(field, 0.5 * KNOT, a, b)  # warm: imports, numba's start, kernels loaded
best = []
for _ in range(int(sys.argv[1])):
    t, c = time.perf_counter(), time.process_time()
    res = solve_route(field, 0.5 * KNOT, a, b)
    best.append((time.perf_counter() - t, time.process_time() - c))
print(json.dumps({"wall_s": min(w for w, _ in best), "cpu_s": min(c for _, c in best), "method": res.method}))
"""

ROUTE_ARGS = ["route", "--start=-1.86,3.66", "--target", "0,0", "--speed", "0.5", "--field", "shear:k=-0.5",
              "--units", "nautical", "--json"]

#: modules a scenario run of the numpy loop does not need before its first step
NOT_BEFORE_FIRST_STEP = ("xarray", "pandas", "matplotlib", "dask", "distributed", "scipy.optimize",
                         "scipy.interpolate", "shipgnc.routing", "shipgnc.viz", "shipgnc.cli_route",
                         "shipgnc.cli_sweep", "shipgnc.cli_trials", "shipgnc.cli_identify",
                         "shipgnc.cli_vessels", "shipgnc.cli_design")


def _children_cpu() -> float:
    use = resource.getrusage(resource.RUSAGE_CHILDREN)
    return use.ru_utime + use.ru_stime


def first_step(args: list[str], out_dir: Path) -> dict:
    """One fresh ``shipgnc`` process with the first-step hook: its marks (wall from the parent's clock)."""
    marks_file = out_dir / "marks.json"
    start = time.time()
    done = subprocess.run([sys.executable, "-c", FIRST_STEP_HOOK, repr(start), str(marks_file), *args],
                          capture_output=True, text=True, check=False)
    end = time.time() - start  # the process gone: its exit included
    if done.returncode != 0:
        raise SystemExit(f"shipgnc {' '.join(args)} failed:\n{done.stderr}")
    return {**json.loads(marks_file.read_text(encoding="utf-8")), "process_s": end}


def route_process() -> dict:
    """One fresh ``shipgnc route`` process: wall and CPU seconds (user + system)."""
    cpu, start = _children_cpu(), time.perf_counter()
    subprocess.run([sys.executable, "-m", "shipgnc", *ROUTE_ARGS], capture_output=True, check=True)
    return {"wall_s": time.perf_counter() - start, "cpu_s": _children_cpu() - cpu}


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats")
    args = parser.parse_args(argv)
    repeats = 2 if args.quick else 5
    report: dict = {"machine": machine_info(), "repeats": repeats}
    with tempfile.TemporaryDirectory() as tmp:
        out_dir = Path(tmp)
        run_args = ["run", "boat-stern-kick", "--no-figures", "--out", str(out_dir / "run"), "--overwrite"]
        first_step(run_args, out_dir)  # fills numba's cache (a first run compiles what it needs)
        runs = [first_step(run_args, out_dir) for _ in range(repeats)]
        route_process()
        routes = [route_process() for _ in range(repeats)]
    warm = json.loads(subprocess.run([sys.executable, "-c", WARM_ROUTE, str(repeats)], capture_output=True,
                                     text=True, check=True).stdout)
    heavy = sorted({m for m in runs[0]["modules"] for h in NOT_BEFORE_FIRST_STEP
                    if m == h or m.startswith(h + ".")})
    best = min  # best of the repeats, as the other benchmarks (the load only ever adds)
    report["run"] = {
        "first_step_wall_s": best(r["first_step_s"] for r in runs),
        "first_step_cpu_s": best(r["first_step_cpu_s"] for r in runs),
        "command_wall_s": best(r["exit_s"] for r in runs),
        "process_wall_s": best(r["process_s"] for r in runs),
        "modules_at_first_step": len(runs[0]["modules"]),
        "unneeded_at_first_step": sorted({m.split(".")[0] if m.split(".")[0] != "shipgnc" else m
                                          for m in heavy}),
    }
    report["route"] = {
        "process_wall_s": best(r["wall_s"] for r in routes),
        "process_cpu_s": best(r["cpu_s"] for r in routes),
        "warm_call_wall_s": warm["wall_s"],
        "warm_call_cpu_s": warm["cpu_s"],
        "method": warm["method"],
    }
    r, q = report["run"], report["route"]
    q["start_up_wall_s"] = q["process_wall_s"] - q["warm_call_wall_s"]
    q["start_up_cpu_s"] = q["process_cpu_s"] - q["warm_call_cpu_s"]
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs; "
          f"best of {repeats} fresh processes")
    print(f"(a) shipgnc run boat-stern-kick --no-figures: process start -> first step "
          f"{r['first_step_wall_s']:.2f} s wall, {r['first_step_cpu_s']:.2f} s CPU (target <= 1.0 s);")
    print(f"    whole command {r['command_wall_s']:.2f} s, the process with its exit "
          f"{r['process_wall_s']:.2f} s; "
          f"{r['modules_at_first_step']} modules imported by then")
    print(f"    imported before the first step and not needed by it: {r['unneeded_at_first_step'] or 'none'}")
    print(f"(b) shipgnc route (002 shear, --json): process {q['process_wall_s']:.2f} s wall, "
          f"{q['process_cpu_s']:.2f} s CPU; warm solve_route {q['warm_call_wall_s']:.2f} s wall, "
          f"{q['warm_call_cpu_s']:.2f} s CPU ({q['method']})")
    print(f"    start-up = process - warm call: {q['start_up_wall_s']:.2f} s wall, "
          f"{q['start_up_cpu_s']:.2f} s CPU (target <= 1.5 s)")
    write_report("bench_startup", report, args.quick)
    return report


if __name__ == "__main__":
    main()
