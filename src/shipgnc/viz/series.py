"""A result's plotted variables as plain arrays (no matplotlib, no xarray import needed)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from shipgnc.errors import ConfigError
from shipgnc.viz.style import unwrap_rad

STATE_KEYS = ("north", "east", "psi", "u", "v", "r")
INPUT_KEYS = ("T_cmd", "alpha_cmd", "T", "alpha")
REFERENCE_KEYS = ("psi_d", "psi_r")


def select_ship(result, ship=0):
    """The dataset of one ship: ``ship`` indexes the batch dimension (``{dim: i}`` for several).

    A one-ship series dict (from :func:`result_series`) is returned as it is.
    """
    if not hasattr(result, "dims"):
        return result
    extra = [d for d in result.dims if d != "time"]
    if not extra:
        return result
    if isinstance(ship, Mapping):
        return result.isel(dict(ship))
    if not isinstance(ship, (int, np.integer)) or isinstance(ship, bool):
        raise ConfigError(f"ship = {ship!r}: must be an integer index (or a dict of batch indices)")
    if len(extra) == 1:
        size = result.sizes[extra[0]]
        if not -size <= ship < size:
            raise ConfigError(f"ship = {ship}: the result has {size} ships ({extra[0]} = 0..{size - 1})")
        return result.isel({extra[0]: int(ship)})
    flat = result.stack(_ship=extra)
    size = flat.sizes["_ship"]
    if not -size <= ship < size:
        raise ConfigError(f"ship = {ship}: the result has {size} ships over {extra}")
    return flat.isel(_ship=int(ship)).drop_vars(["_ship", *extra], errors="ignore")


def result_series(ds) -> dict[str, np.ndarray]:
    """The dashboard's variables of a one-ship dataset as float arrays (SI), ``time`` included.

    Also accepts such a dict (what a figure worker receives: no xarray needed there).
    """
    if isinstance(ds, Mapping) and not hasattr(ds, "coords"):
        if "time" not in ds or any(k not in ds for k in STATE_KEYS):
            raise ConfigError(f"result series: need 'time' and the states {', '.join(STATE_KEYS)}")
        return {k: np.asarray(v, dtype=float) for k, v in ds.items()}
    if "time" not in ds.coords:
        raise ConfigError("result: no 'time' coordinate (not a shipgnc result dataset)")
    missing = [k for k in STATE_KEYS if k not in ds]
    if missing:
        raise ConfigError(f"result: missing variable(s) {', '.join(missing)}; the dashboard needs "
                          f"the states {', '.join(STATE_KEYS)}")
    out = {"time": np.asarray(ds["time"].values, dtype=float)}
    for key in (*STATE_KEYS, *INPUT_KEYS, *REFERENCE_KEYS):
        if key in ds:
            out[key] = np.asarray(ds[key].values, dtype=float).reshape(-1)
    if out["time"].size == 0:
        raise ConfigError("result: no samples (empty time axis)")
    return out


#: buckets of a long series drawn on a figure: about its width in pixels (a figure of 6–12 in at 100–150 dpi)
FIGURE_BUCKETS = 1500


def decimate_series(data: Mapping[str, np.ndarray], buckets: int = FIGURE_BUCKETS) -> dict[str, np.ndarray]:
    """A series dict (:func:`result_series`) thinned for drawing: no more than a pixel column's worth of
    samples per bucket of the time axis, keeping in each bucket its first and last sample and, for every
    variable, the samples of its minimum and maximum (min/max decimation: the drawn envelope is the full
    series' envelope, as a line of all the samples would draw it at that width: the M4 aggregation of
    Jugel et al., PVLDB 7(10), 2014, with buckets of equal sample count).
    Series of at most ``4 * buckets`` samples are returned as they are. Each bucket's argmin/argmax is
    taken on a view of the arrays (no copy of a long log); a bucket with a NaN keeps the NaN's sample
    (a gap stays a gap). ``psi`` is unwrapped first (a turn between kept samples must not fold)."""
    t = np.asarray(data["time"])
    n = t.size
    if n <= 4 * buckets:
        return dict(data)
    size = -(-n // buckets)  # samples per bucket
    whole = (n // size) * size
    keep = [np.arange(0, n, size), np.arange(size - 1, whole, size), np.array([n - 1])]
    out = dict(data)
    if "psi" in out:  # continuous, so that a turn between kept samples does not fold
        out["psi"] = unwrap_rad(out["psi"])
    for key, values in out.items():
        values = np.asarray(values)
        if key == "time" or values.shape != t.shape:
            continue
        blocks = values[:whole].reshape(-1, size)
        base = np.arange(0, whole, size)
        keep += [base + np.argmin(blocks, axis=1), base + np.argmax(blocks, axis=1)]
        tail = values[whole:]
        if tail.size:
            keep += [np.array([whole + np.argmin(tail), whole + np.argmax(tail)])]
    idx = np.unique(np.concatenate(keep))
    return {k: (np.asarray(v)[idx] if np.shape(v) == t.shape else v) for k, v in out.items()}

