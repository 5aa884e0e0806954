"""Results as data: one ``xarray.Dataset`` per run, saved and loaded as NetCDF.

Layout: a ``time`` coordinate [s], then the batch dimensions (``ship`` by default) when the run is
batched. Every state, commanded input (``<input>_cmd``), applied input, reference, tracking error
(``<state>_error``) and logged guidance/controller signal is a variable with ``units`` and
``long_name`` in its attrs. Run metadata (integrator, dt, Ts, scenario, divergence status) are
dataset attrs, numbers and strings only, so the file round-trips through NetCDF.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from shipgnc.errors import ConfigError
from shipgnc.outputs import write_netcdf


def time_coordinate(t):
    """Sample times ``k·dt`` as the ``time`` coordinate holds them: k·dt carries float noise
    (121.05000000000001), rounded to 1e-9 s so that times read and select cleanly."""
    return np.round(t, 9)


def build_dataset(log, batch_shape: tuple[int, ...], batch_dims: tuple[str, ...] | None,
                  attrs: dict) -> xr.Dataset:
    """Turn a loop's :class:`~shipgnc.sim.simulator.Log` into a labelled Dataset."""
    batch_dims = batch_dim_names(batch_shape, batch_dims)
    dims = ("time", *batch_dims)
    variables = {name: (dims, values, log.signals[name].attrs())
                 for name, values in log.data.items()}
    time = time_coordinate(log.time)
    coords = {"time": ("time", time, {"units": "s", "long_name": "time"})}
    for dim, size in zip(batch_dims, batch_shape, strict=True):
        coords[dim] = (dim, np.arange(size))
    status = {k: (int(v) if isinstance(v, (bool, np.bool_)) else v)
              for k, v in log.status.items()}
    clean = {k: _netcdf_attr(v) for k, v in {**attrs, **status}.items() if v is not None}
    return xr.Dataset(variables, coords=coords, attrs=clean)


def batch_dim_names(batch_shape: tuple[int, ...], batch_dims: tuple[str, ...] | None
                    ) -> tuple[str, ...]:
    """The names of a run's batch dimensions: ``batch_dims``, or ``("ship",)`` for one batch
    axis and ``batch0, batch1, ...`` for several."""
    if batch_dims is None:
        batch_dims = ("ship",) if len(batch_shape) == 1 else tuple(
            f"batch{i}" for i in range(len(batch_shape)))
    if len(batch_dims) != len(batch_shape):
        raise ConfigError(f"batch_dims = {batch_dims!r}: need {len(batch_shape)} names for a "
                          f"batch of shape {batch_shape}")
    return tuple(batch_dims)


def _netcdf_attr(value):
    if isinstance(value, (bool, np.bool_)):
        return int(value)
    if isinstance(value, (int, float, str, np.integer, np.floating)):
        return value
    return str(value)


def save(result: xr.Dataset, path: str | Path) -> Path:
    """Write ``result`` as NetCDF (h5netcdf engine; a failed write is one OSError, see
    :func:`shipgnc.outputs.write_netcdf`)."""
    return write_netcdf(result, Path(path))


def load(path: str | Path) -> xr.Dataset:
    """Read a result written by :func:`save` (fully loaded; the file is closed)."""
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"result file {str(path)!r}: no such file")
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        return ds.load()
