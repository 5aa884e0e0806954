"""The rudder of ``cybership-waves-observer`` before and after the wave-filtering loop was designed
as one (docs/navigation.md, "The loop through the observer").

    python docs/observer_loop.py        # writes docs/figures/observer-loop-rudder.png, prints the figures

Before: document 003's PD (K_P = 2, K_D = 50) on the passive observer with its default gains
(ω_c = 1.2 ω₀, ω_lf = ω₀/10 in every DOF, ζ_lf = 1); after: the scenario as shipped. Both in the
scenario's seeded sea, beside the PD on the raw sensors (``pd_measured``).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from shipgnc.scenarios.runner import run_scenario

OUT = Path(__file__).resolve().parent / "figures" / "observer-loop-rudder.png"
SCENARIO = "cybership-waves-observer"
BEFORE = ["estimator.omega_c_rad_s=null", "estimator.omega_lf_rad_s=null", "estimator.zeta_lf=1.0",
          "controllers={pd_measured: {type: course, variant: pd, Kp: 2.0, Kd: 50.0, "
          "sees: measurement}, pd_observer: {type: course, variant: pd, Kp: 2.0, Kd: 50.0, "
          "sees: estimate}}"]
KEYS = ("J", "psi_E", "delta_E", "rudder_rate_rms_deg_s", "rudder_rate_limit_fraction",
        "rudder_travel_deg", "min_surge_mps")


def runs():
    """(before, after) scenario runs."""
    return run_scenario(SCENARIO, overrides=BEFORE), run_scenario(SCENARIO)


def figure(directory: Path = OUT.parent) -> list[Path]:
    """Draw the rudder angle and heading of the three PD runs into ``directory``."""
    before, after = runs()
    fig, axes = plt.subplots(3, 1, figsize=(9, 9), constrained_layout=True)
    series = [("pd_measured (raw sensors)", before.result.sel(controller="pd_measured"), "0.6"),
              ("pd_observer before (K_P 2, K_D 50, default gains)",
               before.result.sel(controller="pd_observer"), "tab:red"),
              ("pd_observer after (the loop designed as one)",
               after.result.sel(controller="pd_observer"), "tab:blue")]
    for label, ds, colour in series:
        t = ds.time.values
        axes[0].plot(t, np.degrees(ds.delta.values), color=colour, lw=0.6, label=label)
        axes[1].plot(t, np.degrees(ds.delta.values), color=colour, lw=0.9, label=label)
        axes[2].plot(t, np.degrees(ds.psi.values), color=colour, lw=0.9, label=label)
    d = after.result.sel(controller="pd_observer")
    axes[2].plot(d.time.values, np.degrees(d.psi_d.values), "k--", lw=0.8, label="ψ_d")
    axes[0].set_ylabel("rudder δ [°]")
    axes[0].set_title(f"{SCENARIO}: the rudder over the run")
    axes[1].set_xlim(150, 180)
    axes[1].set_ylabel("rudder δ [°]")
    axes[1].set_title("a 30 s stretch of the −30° leg")
    axes[2].set_ylabel("heading ψ [°]")
    axes[2].set_xlabel("time [s]")
    for ax in axes:
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8, loc="upper right")
    axes[2].legend(fontsize=8, loc="upper right")
    out = Path(directory) / OUT.name
    fig.savefig(out, dpi=90)
    plt.close(fig)
    for name, run in (("before", before), ("after", after)):
        for key in ("pd_measured", "pd_observer"):
            m = run.metrics[key]
            print(name, key, {k: round(m[k], 4) for k in KEYS})
    return [out]


if __name__ == "__main__":
    print(figure()[0])
