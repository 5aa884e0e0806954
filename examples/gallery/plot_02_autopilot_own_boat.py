"""
A heading autopilot on your own boat
====================================

The heading + speed autopilot (:class:`shipgnc.HeadingSpeedAutopilot`) designs its gains by pole
placement from the boat's parameters at construction, so it follows any parameter set. Here the
document-001 boat is made 50 % heavier (``with_`` returns a changed copy, validated), and the
same autopilot is built for both boats and run on the same heading steps.
"""

import matplotlib.pyplot as plt
import numpy as np

from shipgnc import HeadingSpeedAutopilot, ReferenceSchedule, VectoredThrustBoat, simulate
from shipgnc.viz.style import show_example

light = VectoredThrustBoat()                                   # preset "otter" (note 001-1.6)
heavy = VectoredThrustBoat(light.params.with_(m=120.0, I_z=21.7))
steps = ReferenceSchedule([0, 10, 40], np.radians([0, 45, -30]), [1.5, 1.5, 1.5])

fig, ax = plt.subplots(figsize=(8, 3.5))
for name, boat in (("80 kg (otter)", light), ("120 kg", heavy)):
    result = simulate(boat, np.zeros(6), t_end=70, dt=0.05,
                      controller=HeadingSpeedAutopilot(boat.params), guidance=steps)
    ax.plot(result.time, np.degrees(result.psi), label=name)
    print(name, "max heading error after 60 s:",
          round(float(np.degrees(abs(result.psi_error.sel(time=slice(60, None)))).max()), 3), "deg")
ax.step([0, 10, 40, 70], [0, 45, -30, -30], where="post", color="k", ls=":", label="ψ_d")
ax.set(xlabel="time [s]", ylabel="heading [deg]", title="same design rule, two boats")
ax.legend()
fig.tight_layout()
show_example()   # run as a script: saves the figure (and shows it where there is a display)
