"""What each part of ``shipgnc run mariner-montecarlo`` costs, in CPU seconds
(``time.process_time``) of one process.

    NUMBA_NUM_THREADS=1 MPLBACKEND=Agg python benchmarks/mariner_montecarlo_parts.py

Imports; loading the scenario; building the controllers (the LQR design); the Monte Carlo batch
of each controller scored inside the compiled loop (:mod:`shipgnc.scenarios.montecarlo`): the
loop with its wave-noise tables (drawn by the first controller, read by the second), the ships
whose ``stable`` verdict is left to their own log run again, the summary, the result Dataset;
writing ``result.nc``; the figure worker's part (its imports and ``montecarlo.png``), here in this
process. The command line runs the figures beside the simulation in a worker process and the
loop on every core, so its wall time is less than the sum.
"""

from __future__ import annotations

import functools
import importlib
import tempfile
import time
from pathlib import Path

COST: dict[str, float] = {}


def _timed(module: str, name: str, label: str, owner: str | None = None) -> None:
    """Add the CPU time of every call of ``module.name`` (or ``module.owner.name``) to ``label``."""
    holder = importlib.import_module(module)
    if owner is not None:
        holder = getattr(holder, owner)
    fn = getattr(holder, name)

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        start = time.process_time()
        try:
            return fn(*args, **kwargs)
        finally:
            COST[label] = COST.get(label, 0.0) + time.process_time() - start

    setattr(holder, name, wrapper)


def main() -> None:
    t0 = time.process_time()
    import xarray  # noqa: F401  (the result's)

    import shipgnc.cli
    COST["imports (command line, xarray)"] = time.process_time() - t0
    start = time.process_time()
    from shipgnc.scenarios.registry import load_scenario

    scenario = load_scenario("mariner-montecarlo")
    COST["load the scenario"] = time.process_time() - start
    from shipgnc.scenarios import runner

    _timed("shipgnc.scenarios.runner", "build", "build (the LQR design)")
    _timed("shipgnc.scenarios.montecarlo", "run", "Monte Carlo batches (both controllers)")
    _timed("shipgnc.sim.scored", "run_scored", "  compiled loop, scored, with its tables")
    _timed("shipgnc.environment.filtered_noise", "at_times", "    wave-noise tables",
           owner="SecondOrderNoise")
    _timed("shipgnc.scenarios.montecarlo", "_scored_from_log", "  undecided ships run again")
    _timed("shipgnc.analysis.path_tracking", "montecarlo_figures", "  summary")
    _timed("shipgnc.sim.result", "build_dataset", "  result Dataset")
    start = time.process_time()
    run = runner.run_scenario(scenario)
    COST["run_scenario"] = time.process_time() - start

    from shipgnc.sim.result import save
    from shipgnc.viz.run_files import figure_job

    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        start = time.process_time()
        save(run.result, out / "result.nc")
        COST["write result.nc"] = time.process_time() - start
        start = time.process_time()
        job = figure_job(run, out)
        COST["the figure's series"] = time.process_time() - start
        start = time.process_time()
        import matplotlib

        matplotlib.use("Agg")
        import shipgnc.viz.dashboard  # noqa: F401  (what the figure worker imports)
        from shipgnc.viz.figures import render_figures
        COST["figure worker: imports"] = time.process_time() - start
        start = time.process_time()
        render_figures(job)
        COST["figure worker: montecarlo.png"] = time.process_time() - start
    COST["total"] = time.process_time() - t0
    for label, seconds in COST.items():
        print(f"{label:45s} {seconds:6.2f} s")


if __name__ == "__main__":
    main()
