"""The encounters page's figure of targets that steer (:mod:`shipgnc.guidance.vessel_targets`):
``colav-head-on`` with the target a frigate, both ships running SB-MPC; and a right-angle crossing
from port, the own ship standing on while the give-way target avoids with velocity obstacles or
with SB-MPC. Tracks with a dot every minute and the scored CPA."""

from __future__ import annotations

import json
import math
from pathlib import Path

#: the frigate's speed [m/s] (the built-in's own ship)
U = 9.0
#: panel title → (own method, targets)
CASES = {
    "head-on, both SB-MPC": ("sbmpc", [{
        "name": "target", "north": 11112.0, "east": 50.0, "course_deg": 180.0, "speed": U,
        "vessel": {"model": "frigate"}, "avoidance": "sbmpc"}]),
    "crossing, give-way target VO": ("none", [{
        "name": "target", "north": U * 900.0, "east": -7.0 * 900.0, "course_deg": 90.0,
        "speed": 7.0, "vessel": {"model": "frigate"}, "avoidance": "vo"}]),
    "crossing, give-way target SB-MPC": ("none", [{
        "name": "target", "north": U * 900.0, "east": -7.0 * 900.0, "course_deg": 90.0,
        "speed": 7.0, "vessel": {"model": "frigate"}, "avoidance": "sbmpc"}]),
}


def run_case(method: str, targets, t_end: float = 1100.0):
    """``colav-head-on`` (one run) with ``method`` and ``targets``."""
    from shipgnc.scenarios.registry import load_scenario
    from shipgnc.scenarios.runner import run_scenario

    scenario = load_scenario("colav-head-on", ["runs=null", f"guidance.method={method}",
                                               f"simulation.t_end={t_end}",
                                               f"guidance.targets={json.dumps(targets)}"])
    return run_scenario(scenario)


def document_figures(directory) -> list[Path]:
    """``vessel-targets.png`` into ``directory``."""
    import matplotlib.pyplot as plt
    import numpy as np

    fig, axes = plt.subplots(1, len(CASES), figsize=(13, 5.2))
    for ax, (title, (method, targets)) in zip(axes, CASES.items(), strict=True):
        run = run_case(method, targets)
        ds, m = run.result, run.metrics
        t = ds["time"].values
        n, e = ds["north"].values, ds["east"].values
        tn, te = ds["target_north"].values[:, 0], ds["target_east"].values[:, 0]
        window = (t > m["t_min_range_s"] - 240.0) & (t < m["t_min_range_s"] + 240.0)
        minute = window & (np.mod(t, 60.0) < 1e-9)
        ax.plot(e[window], n[window], color="C0", label=f"own ship ({method})")
        ax.plot(te[window], tn[window], color="C3", label=f"target ({targets[0]['avoidance']})")
        ax.plot(e[minute], n[minute], "o", color="C0", ms=3)
        ax.plot(te[minute], tn[minute], "o", color="C3", ms=3)
        k = int(np.argmin(np.abs(t - m["t_min_range_s"])))
        ax.plot([e[k], te[k]], [n[k], tn[k]], "k--", lw=1,
                label=f"CPA {m['min_range_m']:.0f} m at {m['t_min_range_s']:.0f} s")
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("east [m]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.legend(fontsize=8, loc="lower right" if math.isfinite(m["min_range_m"]) else None)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("north [m]")
    fig.suptitle("Targets that steer: frigate targets with their own autopilot and avoidance "
                 "(4 minutes either side of the CPA, dots every minute)", fontsize=11)
    fig.tight_layout()
    path = Path(directory) / "vessel-targets.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return [path]
