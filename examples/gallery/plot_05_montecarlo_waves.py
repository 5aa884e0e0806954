"""
A Monte Carlo in waves
======================

``mariner-montecarlo`` runs many Mariners in one batched simulation per controller, each with its
own initial offset and its own wave realisation (a sea calibrated to 0.5° wave-frequency heading
motion). This example keeps 20 ships per controller and the first 25 minutes (at four times the
document's step), and draws the cross-track error of every ship with their median.
"""

import matplotlib.pyplot as plt

from shipgnc.scenarios.runner import run_scenario
from shipgnc.viz.style import show_example

NM = 1852.0
run = run_scenario("mariner-montecarlo", overrides=["montecarlo.runs=20", "simulation.t_end=1500",
                                                     "simulation.dt=1.2", "simulation.backend=numpy",
                                                     "simulation.seed=7"])
res = run.result
print(res.psi.dims)                                # ('controller', 'time', 'ship')
for name, m in run.metrics.items():
    print(name, {k: m[k] for k in ("runs", "stable_fraction", "settled_fraction")})

fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), sharey=True)
for ax, name in zip(axes, res.controller.values, strict=True):
    y = res.sel(controller=name).cross_track_error / NM
    ax.plot(res.time / 60, y, color="C0", lw=0.5, alpha=0.4)
    ax.plot(res.time / 60, y.median("ship"), color="k", lw=2, label="median")
    ax.axhline(0, color="grey", lw=0.5)
    ax.set(xlabel="time [min]", title=f"{name}: 20 ships in waves")
axes[0].set_ylabel("cross-track error [nm]")
axes[0].legend()
fig.tight_layout()
show_example()   # run as a script: saves the figure (and shows it where there is a display)
