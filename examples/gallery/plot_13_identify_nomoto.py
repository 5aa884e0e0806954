"""
A model from a logged run: Nomoto's K and T from a noisy zig-zag
================================================================

``shipgnc.identify`` fits a steering model to a log by least squares, with 95 % intervals and a
score on a held-out last part of the log (``shipgnc identify LOG --model nomoto1`` on the command
line). Here the "log" is van Amerongen's frigate (catalogue ``frigate``, K = 0.18 s⁻¹ and T = 27 s
at 9 m/s) sailing a 20°/20° zig-zag, with gyro noise added to the yaw rate; the fit recovers K and
T within a few per cent (see :doc:`/trials`).
"""

import matplotlib.pyplot as plt
import numpy as np

from shipgnc.identify import identify_nomoto1
from shipgnc.trials.zigzag import zigzag
from shipgnc.viz.style import show_example

zz = zigzag("frigate", 20.0, 20.0, sides=("starboard",), speed_mps=9.0)
hist = zz["_history"]
t, rudder, r = hist.time, hist.rudder[:, 0], hist.state("r")[:, 0]
rng = np.random.default_rng(7)                          # seeded: the same noise every run
r_measured = r + np.radians(0.02) * rng.standard_normal(r.size)

fit = identify_nomoto1(t, rudder, r_measured, holdout=0.3, speed=9.0)
for name, p in fit.parameters.items():
    print(f"{name} = {p.value:.4g} [{p.ci95[0]:.4g}, {p.ci95[1]:.4g}] {p.unit}")
print("held-out NRMSE:", {k: round(v, 3) for k, v in fit.nrmse_holdout.items() if v is not None})

fig, ax = plt.subplots(figsize=(8, 3.5))
ax.plot(t, np.degrees(r_measured), lw=0.6, label="measured r (noisy)")
ax.plot(fit.t, np.degrees(fit.simulated["r"]), label="re-simulated Nomoto model")
ax.axvline(fit.t[fit.split], color="grey", ls=":", label="held out from here")
ax.set(xlabel="time [s]", ylabel="yaw rate [deg/s]", title="frigate 20°/20° zig-zag")
ax.legend()
fig.tight_layout()
show_example()   # run as a script: saves the figure (and shows it where there is a display)
