"""Every built-in family through the composed compiled loop and through the numpy loop, side by
side in one run.

    python benchmarks/bench_families.py [--quick] [--only NAME ...]

For each family (the setup of a built-in scenario's first controller, its initial state repeated
over the batch) and each batch size (1 000 and 10 000 ships; ``--quick``: 1 000), times
``simulate(..., backend="compiled")`` (the scenario's steps, at most 4 000 or about 6 s) and
``backend="numpy"`` (as many steps as fit in about 8 s, from a short probe run: numpy's rate does
not depend on the run length), the log thinned to about 100 samples, and prints ship-steps/s and
the ratio. The first-compile cost of each family is measured in a fresh
process with empty numba and shipgnc caches (``NUMBA_CACHE_DIR``, ``SHIPGNC_CACHE_DIR``), and
``shipgnc run NAME --no-figures`` end to end in a fresh process with warm caches. Targets (speed
for every combination): ≥ 1e7 ship-steps/s compiled (wave loads ≥ 1e6) and ≥ 20× numpy.
Writes ``benchmarks/results/bench_families.json``.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_boat import machine_info, write_report

#: family: built-in scenario whose first controller's setup it times
FAMILIES = {
    "boat open loop": "boat-stern-kick",
    "boat autopilot": "boat-autopilot",
    "boat LOS": "boat-los",
    "Mariner LQR": "mariner-lqr",
    "Mariner LOS-FL": "mariner-los-fl",
    "Mariner FL look-ahead": "mariner-fl-lookahead",
    "CyberShip calm": "cybership-calm",
    "CyberShip waves": "cybership-waves",
    "catamaran yaw rate": "catamaran-turn",
    "catamaran heading": "catamaran-heading",
}
#: seconds a compiled timing may take (the wave loads: ≈ 3e5 ship-steps/s)
COMPILED_SECONDS = 6.0
#: seconds a numpy timing may take (its steps are chosen from a short probe run)
NUMPY_SECONDS = 8.0
#: most steps of one timing
MAX_STEPS = 4000


def family_setup(scenario_name: str):
    """(model, x0 of one ship, simulate keyword arguments, steps) of a scenario's first run."""
    from shipgnc.scenarios.registry import load_scenario
    from shipgnc.scenarios.runner import build, simulation_of

    scenario = load_scenario(scenario_name)
    setup = build(scenario)
    sim = simulation_of(scenario, setup)
    x0 = np.asarray(setup.x0, dtype=float)
    kwargs = {"dt": sim.dt, "controller": setup.controller, "actuator": setup.actuator,
              "guidance": setup.guidance, "disturbance": setup.disturbance, "u0": setup.u0}
    return setup.model, x0.reshape(-1, x0.shape[-1])[0], kwargs, round(sim.t_end / sim.dt)


def time_run(model, x0, kwargs, n_ships: int, n_steps: int, backend: str, repeats: int) -> float:
    """Best ship-steps/s of ``repeats`` runs of ``n_ships`` ships over ``n_steps`` steps (the
    steps run: a run whose guidance finishes, e.g. a LOS route, ends there)."""
    from shipgnc.sim.simulator import simulate

    dt = kwargs["dt"]
    batch = np.tile(x0, (n_ships, 1))
    options = {**kwargs, "t_end": n_steps * dt, "log_every": max(1, n_steps // 100), "seed": 1,
               "backend": backend, "on_divergence": "stop"}
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        ds = simulate(model, batch, **options)
        best = min(best, time.perf_counter() - start)
    steps_run = round(float(ds.time.values[-1]) / dt)
    return n_ships * steps_run / best


def fresh_process(code: str, env: dict) -> float:
    start = time.perf_counter()
    subprocess.run([sys.executable, "-c", code], check=True, env={**os.environ, **env},
                   capture_output=True)
    return time.perf_counter() - start


def first_compile(scenario_name: str) -> float:
    """Seconds of a 2-step run of the family in a fresh process with empty caches, minus the same
    process's import cost."""
    here = str(Path(__file__).resolve().parent)
    code = (f"import sys; sys.path.insert(0, {here!r}); from bench_families import family_setup, "
            f"time_run; m, x, k, _ = family_setup({scenario_name!r}); "
            "time_run(m, x, k, 1, 2, 'compiled', 1)")
    with tempfile.TemporaryDirectory() as numba_dir, tempfile.TemporaryDirectory() as loops:
        env = {"NUMBA_CACHE_DIR": numba_dir, "SHIPGNC_CACHE_DIR": loops}
        cold = fresh_process(code, env)
        imports = fresh_process(code.replace("time_run(m, x, k, 1, 2, 'compiled', 1)", "pass"), env)
    return cold - imports


def cli_seconds(scenario_name: str) -> float:
    """``shipgnc run NAME --no-figures`` end to end (warm caches: run once before timing)."""
    with tempfile.TemporaryDirectory() as out:
        command = [sys.executable, "-m", "shipgnc.cli", "run", scenario_name, "--no-figures",
                   "--out", out]
        subprocess.run(command, check=False, capture_output=True)
        start = time.perf_counter()
        subprocess.run(command, check=False, capture_output=True)
        return time.perf_counter() - start


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="1 000 ships only, one repeat")
    parser.add_argument("--only", nargs="*", help="scenario names of the families to time")
    args = parser.parse_args(argv)
    sizes = (1000,) if args.quick else (1000, 10_000)
    repeats = 1 if args.quick else 2
    rows = []
    header = (f"{'family':<22} {'scenario':<22} {'ships':>6} {'compiled':>10} {'numpy':>10} "
              f"{'ratio':>6} {'compile s':>9} {'run s':>6}")
    print("ship-steps/s, same steps and ships for both loops")
    print(header)
    for family, name in FAMILIES.items():
        if args.only and name not in args.only:
            continue
        model, x0, kwargs, steps = family_setup(name)
        time_run(model, x0, kwargs, 2, 2, "compiled", 1)  # load or compile the loop first
        compile_s = first_compile(name)
        run_s = cli_seconds(name)
        for n in sizes:
            probe = time_run(model, x0, kwargs, n, 20, "compiled", 1)
            n_steps = int(max(20, min(steps, MAX_STEPS, COMPILED_SECONDS * probe / n)))
            compiled = time_run(model, x0, kwargs, n, n_steps, "compiled", repeats)
            probe = time_run(model, x0, kwargs, n, 3, "numpy", 1)  # ship-steps/s, roughly
            numpy_steps = int(max(3, min(n_steps, NUMPY_SECONDS * probe / n)))
            numpy = time_run(model, x0, kwargs, n, numpy_steps, "numpy", 1)
            row = {"family": family, "scenario": name, "ships": n, "steps": n_steps,
                   "compiled_ship_steps_per_s": compiled, "numpy_ship_steps_per_s": numpy,
                   "numpy_steps": numpy_steps, "ratio": compiled / numpy,
                   "first_compile_s": compile_s, "cli_run_s": run_s}
            rows.append(row)
            print(f"{family:<22} {name:<22} {n:>6} {compiled:>10.3g} {numpy:>10.3g} "
                  f"{compiled / numpy:>6.0f} {compile_s:>9.1f} {run_s:>6.2f}")
    write_report("bench_families", {"machine": machine_info(), "results": rows}, args.quick)
    return {"results": rows}


if __name__ == "__main__":
    main()
