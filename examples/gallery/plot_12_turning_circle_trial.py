"""
IMO trials of a catalogue vessel: turning circle and zig-zag
============================================================

``shipgnc.trials`` runs the standard manoeuvres of IMO resolution MSC.137(76) on any catalogue
vessel (``shipgnc vessels``) as one batch. Here Chislett & Strøm-Tejsen's Mariner (``mariner-cst``)
turns with 35° of rudder to each side and sails the 20°/20° zig-zag; the criteria report checks the
figures against the L-dependent limits (see :doc:`/trials`). Same as
``shipgnc trial all --vessel mariner-cst``.
"""

import matplotlib.pyplot as plt
import numpy as np

from shipgnc.trials import turning_circle
from shipgnc.trials.zigzag import zigzag
from shipgnc.viz.style import show_example

turn = turning_circle("mariner-cst", 35.0)              # both sides, one batch
zz = zigzag("mariner-cst", 20.0, 20.0, sides=("starboard",))
print(f"trim rudder {turn['trim_rudder_deg']:.3f}°, L/V = {turn['l_over_v_s']:.1f} s")
for side, figures in turn["sides"].items():
    print(side, {k: round(figures[k], 1) for k in ("advance_m", "transfer_m", "tactical_diameter_m")})
print(f"20°/20° first overshoot {zz['first_overshoot_deg']:.2f}°, second {zz['second_overshoot_deg']:.2f}°")

hist = turn["_history"]
fig, (ax_track, ax_zz) = plt.subplots(1, 2, figsize=(10, 4.5))
north, east = hist.state("north"), hist.state("east")
for j in range(north.shape[1]):
    ax_track.plot(east[:, j], north[:, j])
ax_track.set(xlabel="east [m]", ylabel="north [m]", title="35° turning circles (execute at 0, 0)",
             aspect="equal")
hz = zz["_history"]
ax_zz.plot(hz.time, np.degrees(hz.state("psi")[:, 0] - hz.state("psi")[0, 0]), label="heading change")
ax_zz.plot(hz.time, np.degrees(hz.rudder[:, 0]), label="rudder")
ax_zz.set(xlabel="time [s]", ylabel="[deg]", title="20°/20° zig-zag, starboard first")
ax_zz.legend()
fig.tight_layout()
show_example()   # run as a script: saves the figure (and shows it where there is a display)
