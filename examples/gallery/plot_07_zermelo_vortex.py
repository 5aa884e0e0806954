"""
A time-optimal route through a vortex
=====================================

Document 002's problem — the fastest route for a ship of constant speed through a current — with
the current of the built-in scenario ``zermelo-vortex``: a Lamb–Oseen vortex at the midpoint of the
document's start and target. Several extremals of the maximum principle reach the target; the
router's global sweep returns the fastest and lists the others with their status (notes 002-F2
and 002-F3 on :doc:`/002_zermelo_routing`).
"""

import matplotlib.pyplot as plt
import numpy as np

from shipgnc.environment.fields import LambOseenVortex
from shipgnc.routing.router import solve_route
from shipgnc.viz.style import show_example

NM, KN, H = 1852.0, 1852.0 / 3600.0, 3600.0
start, target = np.array([-1.86, 3.66]) * NM, np.zeros(2)
vortex = LambOseenVortex(gamma=2.0 * NM**2 / H, rc=0.5 * NM, centre=(-0.93 * NM, 1.83 * NM))
route = solve_route(vortex, 0.5 * KN, start, target, horizon=21 * H, method="pmp",
                    n_angles=480, n_steps=700, global_check=False)   # a coarse sweep, then a polish
print(f"fastest: {route.time_s / H:.4f} h; extremals found:",
      [(round(e["time_s"] / H, 3), e["status"]) for e in route.extremals])

fig, ax = plt.subplots(figsize=(6, 5.5))
n, e = np.meshgrid(np.linspace(-2.4, 0.6, 16) * NM, np.linspace(-0.6, 4.2, 18) * NM, indexing="ij")
v = vortex.velocity(0.0, n, e)
ax.quiver(e / NM, n / NM, v[..., 1], v[..., 0], color="0.6")
for extremal in route.extremal_paths:                # every extremal the sweep found
    _, y = extremal.sample(400)                      # y[:, 0] north, y[:, 1] east [m]
    ax.plot(y[:, 1] / NM, y[:, 0] / NM, lw=1, color="C1")
ds = route.to_dataset()
ax.plot(ds.east / NM, ds.north / NM, lw=2.5, color="C0", label=f"optimum {route.time_s / H:.2f} h")
ax.plot(*start[::-1] / NM, "ko")
ax.plot(*target[::-1] / NM, "k*", ms=12)
ax.set(xlabel="east [nm]", ylabel="north [nm]", aspect="equal", title="Lamb–Oseen vortex: routes A → B")
ax.legend(loc="lower left")
fig.tight_layout()
show_example()   # run as a script: saves the figure (and shows it where there is a display)
