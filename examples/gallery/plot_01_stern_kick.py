"""
Stern kick: the wrong-way start of a turn
=========================================

Document 001's open-loop manoeuvre (built-in scenario ``boat-stern-kick``): a 2 m boat with one
vectored thruster runs straight, then turns its thrust vector to α = −15° at t = 5 s. The centre of
gravity first moves to port before the starboard turn carries it to starboard — the lateral
position is non-minimum-phase (note 001-1.8, on :doc:`/001_vectored_thrust_boat`).
"""

import matplotlib.pyplot as plt
import numpy as np

from shipgnc.scenarios.runner import run_scenario
from shipgnc.viz.style import show_example

run = run_scenario("boat-stern-kick")
res = run.result                                   # xarray.Dataset, dims (time,)
print({k: round(v, 4) for k, v in run.metrics.items() if isinstance(v, float)})

fig, (ax_track, ax_kick) = plt.subplots(1, 2, figsize=(9, 4))
ax_track.plot(res.east, res.north)
ax_track.set(xlabel="east [m]", ylabel="north [m]", title="track (north up)", aspect="equal")
t = res.time.values
window = (t >= 4.5) & (t <= 8.0)
ax_kick.plot(t[window], 100 * res.east.values[window])
ax_kick.axhline(0.0, color="k", lw=0.5)
ax_kick.axvline(5.0, color="grey", ls=":")
i = int(np.argmin(res.east.values))
ax_kick.annotate(f"{100 * res.east.values[i]:.1f} cm at {t[i]:.2f} s", (t[i], 100 * res.east.values[i]),
                 xytext=(6.2, -2.5), arrowprops={"arrowstyle": "->"})
ax_kick.set(xlabel="time [s]", ylabel="east of the CG [cm]", title="the kick: first to port")
fig.tight_layout()
show_example()   # run as a script: saves the figure (and shows it where there is a display)
