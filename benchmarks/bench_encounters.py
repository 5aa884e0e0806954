"""Speed of the encounter sweep: ``shipgnc encounters --mc N --method sbmpc`` over the standard set.

    python benchmarks/bench_encounters.py [--mc 1000] [--numpy-mc 10]

Times, back to back in one run, the standard set (five encounter types) with ``--mc`` perturbed
variants of each, every member a 20-minute encounter (dt 0.5 s) of the frigate under SB-MPC
(deciding every 5 s, 13 course offsets, a 100 s horizon at 5 s), as one batched run, the log
kept every 20th step (10 s; the command keeps every 10th, 5 s):

(a) the composed compiled loop (``backend="auto"``), after a warm-up that compiles or loads the
    loop from its disk cache (its serial form and the parallel one a batch of 256 ships or more
    runs);
(b) the numpy loop (``backend="numpy"``: the guidance still runs its compiled kernel per ship,
    through the derived batch), on ``--numpy-mc`` variants of each type (it is slow).

Reports encounters/s and ship-steps/s (one ship-step: one ship over one simulation step) and
writes ``benchmarks/results/bench_encounters.json``, with the process's CPU time and the load
average beside the wall time (on a shared machine the wall time measures the other jobs too).
Target: (a) ≥ 100 encounters/s on 2 cores.
"""

from __future__ import annotations

import argparse
import datetime as dt_
import json
import os
import platform
import time
from pathlib import Path

RESULTS = Path(__file__).resolve().parent / "results"


def run(mc: int, backend: str, seed: int = 1) -> dict:
    from shipgnc.study import encounters as E

    members = E.standard_members(["sbmpc"], mc=mc, seed=seed)
    start, cpu = time.perf_counter(), time.process_time()
    result = E.run_members(members, backend=backend, log_every=20)
    wall, cpu = time.perf_counter() - start, time.process_time() - cpu
    collisions = int(result.scores["collision"].sum())
    return {"backend": backend, "encounters": len(members), "seconds": wall, "cpu_seconds": cpu,
            "encounters_per_s": len(members) / wall, "ship_steps_per_s": result.ship_steps / wall,
            "encounters_per_cpu_s": len(members) / cpu, "collisions": collisions,
            "load_average": os.getloadavg()[0]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--mc", type=int, default=1000)
    parser.add_argument("--numpy-mc", type=int, default=10)
    args = parser.parse_args()
    # warm-up: compile or load the composed loop, serial and parallel (from 256 ships on)
    run(1, "auto")
    run(60, "auto")
    rows = [run(args.mc, "auto"), run(args.numpy_mc, "numpy")]
    for row in rows:
        print(f"{row['backend']:>6}: {row['encounters']:6d} encounters in {row['seconds']:8.2f} s: "
              f"{row['encounters_per_s']:8.1f} encounters/s, {row['ship_steps_per_s']:.3g} "
              f"ship-steps/s; {row['encounters_per_cpu_s']:.1f} encounters per CPU-second; "
              f"{row['collisions']} collisions; load average {row['load_average']:.1f}")
    speedup = rows[0]["encounters_per_s"] / rows[1]["encounters_per_s"]
    print(f"compiled / numpy: {speedup:.1f}x")
    RESULTS.mkdir(exist_ok=True)
    record = {"date": dt_.datetime.now(dt_.timezone.utc).isoformat(timespec="seconds"),
              "machine": platform.machine(), "python": platform.python_version(),
              "cpus": os.cpu_count(), "numba_threads": os.environ.get("NUMBA_NUM_THREADS"),
              "target_encounters_per_s": 100, "runs": rows, "compiled_over_numpy": speedup}
    path = RESULTS / "bench_encounters.json"
    path.write_text(json.dumps(record, indent=2) + "\n", encoding="utf-8")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
