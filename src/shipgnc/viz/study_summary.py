"""A study's outputs: the Dataset on disk, the summary table and the spread figure."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from shipgnc.errors import ConfigError
from shipgnc.outputs import write_netcdf

#: a Dataset above this size goes to Zarr (when the ``[dist]`` extra brings zarr), else NetCDF
ZARR_MIN_BYTES = 2 * 1024**3
QUANTILES = {"median": 0.5, "p5": 0.05, "p95": 0.95}


#: prefixes of a member's drawn inputs (plant parameters, initial-state fields), not metrics
DRAWN_PREFIXES = ("param_", "initial_state_")


def metric_names(ds) -> list[str]:
    """The per-member summary metrics (every variable but the ``series_*`` time series and an
    interrupted study's ``finished`` flags; the drawn ``param_*`` and ``initial_state_*`` are among
    them, so the summary shows their spread)."""
    return [str(k) for k in ds.data_vars if not str(k).startswith("series_") and k != "finished"]


def summary_rows(ds) -> list[dict]:
    """Median, p5 and p95 over the members of each metric, one row per grid point (and controller);
    NaN members (a figure that does not exist, e.g. a run that never settles) are left out and
    counted in ``<metric>_missing``. Members that diverged are left out of every metric's figures
    (their figures are those of a partial run; ``diverged`` itself and the drawn ``param_*`` and
    ``initial_state_*`` keep every member) and counted in ``diverged_members``."""
    cell_dims = [d for d in ds[metric_names(ds)[0]].dims if d != "member"] if metric_names(ds) else []
    stacked = ds[metric_names(ds)]
    if cell_dims:
        stacked = stacked.stack(cell=cell_dims)
        cells = list(range(stacked.sizes["cell"]))
    else:
        cells = [None]
    rows = []
    for c in cells:
        cell = stacked if c is None else stacked.isel(cell=c)
        row = {d: _plain(cell[d].values) for d in cell_dims}
        diverged = (np.asarray(cell["diverged"].values, dtype=float) > 0 if "diverged" in cell
                    else np.zeros(cell.sizes.get("member", 1), dtype=bool))
        row["diverged_members"] = int(np.sum(diverged))
        for name in metric_names(ds):
            values = np.asarray(cell[name].values, dtype=float)
            if name != "diverged" and not name.startswith(DRAWN_PREFIXES) and values.shape == diverged.shape:
                values = values[~diverged]
            finite = values[np.isfinite(values)]
            for label, q in QUANTILES.items():
                row[f"{name}_{label}"] = float(np.quantile(finite, q)) if finite.size else None
            row[f"{name}_missing"] = int(values.size - finite.size)
        rows.append(row)
    return rows


def _plain(value):
    value = np.asarray(value).item()
    return value.decode() if isinstance(value, bytes) else value


def save_dataset(ds, out: Path) -> Path:
    """``sweep.nc`` (NetCDF), or ``sweep.zarr`` when the study is large and zarr is installed."""
    if ds.nbytes >= ZARR_MIN_BYTES:
        try:
            import zarr  # noqa: F401
        except ImportError:
            pass
        else:
            path = out / "sweep.zarr"
            ds.to_zarr(path, mode="w", consolidated=False)
            return path
    path = out / "sweep.nc"
    encoded = ds.copy()
    for name in encoded.coords:  # the grid keys may hold strings: NetCDF wants them as str
        if encoded[name].dtype == object:
            encoded[name] = encoded[name].astype(str)
    return write_netcdf(encoded, path)


def load_dataset(path: str | Path):
    """A saved study (``sweep.nc`` or ``sweep.zarr``)."""
    import xarray as xr

    path = Path(path)
    if not path.exists():
        raise ConfigError(f"{str(path)!r}: no such study file")
    if path.suffix == ".zarr":
        return xr.open_zarr(path, consolidated=False).load()
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        return ds.load()


def spread_figure(ds, path: Path, *, max_metrics: int = 6) -> Path:
    """Each metric against the first grid key: the median line and the p5–p95 band of the members
    (one line per value of the other grid keys and controllers); a histogram without a grid. The
    members' drawn plant parameters and initial states (``param_*``, ``initial_state_*``) are
    inputs, not metrics: left out."""
    from shipgnc.units import axis_label, metric_label
    from shipgnc.viz.style import DPI, new_figure

    names = [n for n in metric_names(ds) if n != "diverged" and not n.startswith(DRAWN_PREFIXES)
             and np.isfinite(np.asarray(ds[n].values, dtype=float)).any()][:max_metrics]
    if not names:
        names = ["diverged"]
    ncols = min(3, len(names))
    nrows = -(-len(names) // ncols)
    fig, axes = new_figure(nrows, ncols, size=(4.6 * ncols, 3.4 * nrows))
    axes = axes.ravel()
    grid_dims = [d for d in ds[names[0]].dims if d not in ("member", "controller")]
    for ax, name in zip(axes, names, strict=False):
        da = ds[name]
        if not grid_dims:
            _histograms(ax, da)
            ax.set_xlabel(axis_label(name))
        else:
            _bands(ax, da, grid_dims[0])
            ax.set_ylabel(axis_label(name))
        title = metric_label(name)[0]
        ax.set_title(title[:1].upper() + title[1:])
    for ax in axes[len(names):]:
        ax.set_visible(False)
    title = f"{ds.attrs.get('scenario', 'study')}: {ds.sizes.get('member', 1)} members per point"
    if grid_dims:
        title += " (line: median; band: p5–p95)"
    fig.suptitle(title)
    fig.savefig(path, dpi=DPI)
    return path


def _others(da, keep: list[str]):
    """Every combination of the dimensions other than ``keep``: (label, selection) pairs."""
    other = [d for d in da.dims if d not in keep]
    if not other:
        return [("", {})]
    stacked = da.stack(rest=other)
    out = []
    for i in range(stacked.sizes["rest"]):
        sel = {d: stacked[d].values[i] for d in other}
        out.append((", ".join(f"{d}={_plain(v)}" for d, v in sel.items()), sel))
    return out


def _bands(ax, da, x_dim: str) -> None:
    from shipgnc.viz.style import LEGEND

    labels = [_plain(v) for v in da[x_dim].values]
    numeric = all(isinstance(v, (int, float)) for v in labels)
    x = np.asarray(labels, dtype=float) if numeric else np.arange(len(labels))
    for label, sel in _others(da, [x_dim, "member"]):
        values = np.asarray(da.sel(sel).transpose(x_dim, "member").values, dtype=float)
        stats = np.full((3, len(x)), np.nan)
        for i, row in enumerate(values):
            finite = row[np.isfinite(row)]
            if finite.size:
                stats[:, i] = np.quantile(finite, [0.05, 0.5, 0.95])
        line = ax.plot(x, stats[1], marker="o", label=label or "median")[0]
        ax.fill_between(x, stats[0], stats[2], color=line.get_color(), alpha=0.2)
    if not numeric:
        ax.set_xticks(x, [str(v) for v in labels])
    ax.set_xlabel(x_dim)
    if len(_others(da, [x_dim, "member"])) > 1:
        ax.legend(**LEGEND)


def _histograms(ax, da) -> None:
    from matplotlib.ticker import MaxNLocator

    from shipgnc.viz.style import LEGEND

    for label, sel in _others(da, ["member"]):
        values = np.asarray(da.sel(sel).values, dtype=float)
        finite = values[np.isfinite(values)]
        if finite.size:
            ax.hist(finite, bins=min(40, max(5, finite.size // 5)), alpha=0.6, label=label or None)
    ax.set_ylabel("members")
    ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    if len(_others(da, ["member"])) > 1:
        ax.legend(**LEGEND)
