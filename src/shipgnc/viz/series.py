"""A result's plotted variables as plain arrays (no matplotlib, no xarray import needed)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from shipgnc.errors import ConfigError

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
