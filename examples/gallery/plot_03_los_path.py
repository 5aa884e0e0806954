"""
Following a path with line-of-sight guidance
============================================

:class:`shipgnc.LOSGuidance` turns a :class:`shipgnc.WaypointPath` into a heading and speed
reference for the autopilot; the boat starts 10 m to port of the first leg (as in the built-in
scenario ``boat-los``). Two look-ahead distances show the trade between a fast capture and
overshoot.
"""

import matplotlib.pyplot as plt
import numpy as np

from shipgnc import HeadingSpeedAutopilot, LOSGuidance, VectoredThrustBoat, WaypointPath, simulate
from shipgnc.viz.style import show_example

boat = VectoredThrustBoat()
path = WaypointPath(np.array([[0.0, 0.0], [60.0, 0.0], [60.0, 60.0], [0.0, 60.0]]))   # north, east [m]
x0 = np.array([0.0, -10.0, 0.0, 0.0, 0.0, 0.0])

fig, ax = plt.subplots(figsize=(5.5, 5))
ax.plot(path.waypoints[:, 1], path.waypoints[:, 0], "k--", lw=1, label="path")
for lookahead in (4.0, 12.0):
    result = simulate(boat, x0, t_end=130, dt=0.05, controller=HeadingSpeedAutopilot(boat.params),
                      guidance=LOSGuidance(path, lookahead=lookahead, speed=1.5))
    ax.plot(result.east, result.north, label=f"look-ahead {lookahead:g} m")
ax.set(xlabel="east [m]", ylabel="north [m]", aspect="equal", title="LOS guidance, boat of document 001")
ax.legend(loc="center")
fig.tight_layout()
show_example()   # run as a script: saves the figure (and shows it where there is a display)
