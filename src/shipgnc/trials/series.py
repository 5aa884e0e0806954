"""A trial's time series as NetCDF (``shipgnc trial … --out DIR`` writes one file per manoeuvre).

Each file holds, over ``time`` [s] (zero at execution) and ``run`` (the batch: sides, rudder
angles, speeds — in the order of the trial's JSON), the vessel's states by name, the applied rudder
``delta`` and its command ``delta_c`` [rad], and the speed over ground ``speed`` [m/s]: the log
``shipgnc identify FILE.nc --ship RUN`` reads, so a simulated zig-zag can be fitted as a measured one.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

#: units of the catalogue's common states (others are written without a unit)
UNITS = {"north": "m", "east": "m", "psi": "rad", "u": "m/s", "v": "m/s", "r": "rad/s", "n": "1/s"}


def histories(res: dict, name: str | None = None):
    """(file stem, History) for every manoeuvre in a trial result (``all``: each trial's)."""
    if name is None:
        name = res.get("trial", "trial")
        if "angles" in res:
            name = f"{name}-{res['angles']}"
    if "_history" in res:
        yield re.sub(r"[^A-Za-z0-9]+", "_", name).strip("_"), res["_history"]
    for key, value in res.items():
        if isinstance(value, dict) and not str(key).startswith("_"):
            yield from histories(value, str(key))


def dataset(hist, *, title: str):
    """The labelled time series of one batched trial run."""
    import xarray as xr

    dims = ("time", "run")
    data = {}
    for state, column in hist.index.items():
        if state == "delta":
            continue  # the applied rudder below (also for models without a steering machine)
        attrs = {"units": UNITS[state]} if state in UNITS else {}
        data[state] = (dims, np.asarray(hist.x[..., column], float), attrs)
    data["delta"] = (dims, np.asarray(hist.rudder, float), {"units": "rad", "long_name": "rudder angle"})
    data["delta_c"] = (dims, np.asarray(hist.command, float), {"units": "rad", "long_name": "rudder command"})
    data["speed"] = (dims, np.asarray(hist.speed, float), {"units": "m/s", "long_name": "speed over ground"})
    coords = {"time": ("time", np.asarray(hist.time, float), {"units": "s"}),
              "run": ("run", np.arange(hist.x.shape[1]))}
    return xr.Dataset(data, coords=coords, attrs={"title": title, "source": "shipgnc trial"})


def write_series(res: dict, directory) -> list[Path]:
    """One NetCDF file per manoeuvre of ``res`` in ``directory``; returns the paths."""
    from shipgnc.sim.result import save

    out = []
    for stem, hist in histories(res):
        out.append(save(dataset(hist, title=f"{res.get('vessel', '')} {stem}".strip()),
                        Path(directory) / f"{stem}.nc"))
    return out
