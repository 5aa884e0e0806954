"""
A head-on encounter: no avoidance, SB-MPC, velocity obstacles
=============================================================

The built-in ``colav-head-on``: the frigate sails north at 9 m/s; a ship of the same speed comes the
other way 6 nmi ahead, 150 m to starboard of the own track. Three runs: no avoidance (the baseline,
a collision inside the 200 m domain), simulation-based MPC (Johansen, Perez & Cristofaro 2016) and
velocity obstacles with COLREG constraints (Kuwata et al. 2014). Both methods alter to starboard
and pass port to port, as rule 14 asks (:doc:`/encounters`).
"""

import matplotlib.pyplot as plt
import numpy as np

from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import run_scenario
from shipgnc.viz.style import show_example

run = run_scenario(load_scenario("colav-head-on", ["simulation.t_end=900"]))
res = run.result                                   # dims (controller, time); targets on 'target'
for name, m in run.metrics.items():
    print(f"{name:6s} CPA {m['min_range_m']:6.1f} m at {m['t_min_range_s']:5.0f} s, "
          f"collision {m['collision']}, time lost {m['time_lost_s']:.1f} s")

fig, (ax_track, ax_course) = plt.subplots(1, 2, figsize=(10, 4.5))
for name in res.controller.values:
    r = res.sel(controller=name)
    ax_track.plot(r.east, r.north, label=f"own ship: {name}")
    ax_course.plot(r.time / 60, np.degrees(r.course_cmd), label=name)
target = res.sel(controller="none").isel(target=0)
ax_track.plot(target.target_east, target.target_north, "k--", lw=1, label="target")
ax_track.set(xlabel="east [m]", ylabel="north [m]", xlim=(-1500, 1500), ylim=(3000, 9000),
             title="tracks near the CPA")
ax_track.set_aspect("equal")
ax_course.set(xlabel="time [min]", ylabel="commanded course [deg]",
              title="course: starboard first")
ax_track.legend(fontsize=8)
ax_course.legend(fontsize=8)
fig.tight_layout()
show_example()   # run as a script: saves the figure (and shows it where there is a display)
