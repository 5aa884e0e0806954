"""
Reading a result.nc with xarray
===============================

``shipgnc run NAME --out DIR`` writes ``DIR/result.nc``: every logged series with its units and
description, on labelled dimensions, plus the scenario's settings in the attributes. The same file
is written here from Python (what ``run`` does), then read back as a user of the command line would,
with nothing but xarray.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import xarray as xr

from shipgnc.scenarios.runner import run_scenario
from shipgnc.viz.style import show_example

out = Path(tempfile.mkdtemp())
run_scenario("boat-autopilot").result.to_netcdf(out / "result.nc")   # shipgnc run boat-autopilot --out DIR

ds = xr.open_dataset(out / "result.nc")
print(ds.sizes, "|", ", ".join(list(ds.data_vars)[:8]), "...")
print("psi:", ds.psi.attrs)


def in_degrees(angle, name):
    """An angle variable [rad] in degrees, labelled so (its own attrs say rad)."""
    out = np.degrees(angle).rename(name)
    out.attrs = {"long_name": name, "units": "deg"}
    return out


fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
in_degrees(ds.psi, "heading").plot(ax=ax1, label="ψ")
in_degrees(ds.psi - ds.psi_error, "heading").plot(ax=ax1, ls=":", label="ψ_d")
ax1.legend()
ds.u.plot(ax=ax2)
ax2.set_title("")
fig.tight_layout()
ds.close()
show_example()   # run as a script: saves the figure (and shows it where there is a display)
