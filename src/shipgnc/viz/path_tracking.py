"""Document 000's figures: tracks on the path (Fig. 3), heading (Fig. 4), rudder (Fig. 5), with the
controllers overlaid; and the spread of a Monte Carlo batch.

Drawn from plain arrays (:func:`path_series`, :func:`montecarlo_series`) in the document's units
for display (time in min, positions in nm, angles in deg), so a worker process needs no xarray.
North is up and east to the right (NED, the document's x up, y right under the caption reading).

**Unbounded runs**: a run whose |y_r| passes the ``stable`` bound max(3 nm, 2|y_r(0)|)
of note 000-0.8 (the literal FL, 18 nm off after 100 min) would swamp the axes. Every run is
still drawn, but the axes limits come from the bounded runs: Fig. 3 adds a panel with every track
whole, Fig. 4 marks the unbounded runs as leaving the frame, Fig. 5 draws them in a panel of
their own. Titles say what is drawn (how many runs, which are unbounded).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from shipgnc.errors import ConfigError
from shipgnc.units import MINUTE, NAUTICAL_MILE
from shipgnc.viz import style

if TYPE_CHECKING:  # matplotlib is imported where a figure is drawn: the series helpers need none
    from matplotlib.figure import Figure

PATH_KEYS = ("time", "north", "east", "psi", "heading_error", "cross_track_error", "delta", "leg")
#: one colour per controller of document 000 (others cycle through the tab10 palette)
CONTROLLER_COLORS = {"lqr_paper": "#9467bd", "lqr": "#1f77b4", "fl_paper": "#d62728",
                     "fl_lookahead": "#2ca02c", "los_fl": "#ff7f0e", "los_fl_oracle": "#8c564b",
                     "controller": "#1f77b4"}
#: the ``stable`` bound of note 000-0.8: |y_r| < max(3 nm, 2 |y_r(0)|)
BOUND_NM = 3.0
#: margin around the bounded runs' data (fraction of the span)
MARGIN = 0.06
#: Monte Carlo tracks drawn per controller (the statistics use every run)
TRACKS_DRAWN = 200


def _color(name: str, i: int) -> str:
    return CONTROLLER_COLORS.get(name, f"C{i % 10}")


def path_series(result, controller: str | None) -> dict[str, np.ndarray]:
    """One controller's plotted variables (first ship), NaN padding of an early stop removed."""
    ds = result.sel(controller=controller) if controller is not None and "controller" in result.dims \
        else result
    if "ship" in ds.dims:
        ds = ds.isel(ship=0)
    keep = np.isfinite(ds["north"].values)
    return {k: np.asarray(ds[k].values, dtype=float)[keep] for k in PATH_KEYS if k in ds}


def _waypoint_plot(ax, waypoints) -> None:
    wp = np.asarray(waypoints, dtype=float) / NAUTICAL_MILE
    last = wp[-1] + 0.6 * (wp[-1] - wp[-2])  # the last leg is a half-line: draw it on
    ax.plot(wp[:, 1], wp[:, 0], "o", color=style.COLORS["waypoint"], markersize=4, zorder=3)
    ax.plot([*wp[:, 1], last[1]], [*wp[:, 0], last[0]], color=style.COLORS["path"], linewidth=1.2,
            linestyle="--", label="path", zorder=1)


def is_bounded(data: Mapping[str, np.ndarray]) -> bool:
    """Whether a run keeps |y_r| below the ``stable`` bound max(3 nm, 2|y_r(0)|) (note 000-0.8)."""
    y = np.asarray(data.get("cross_track_error", ()), dtype=float)
    y = y[np.isfinite(y)]
    if y.size == 0:
        return True
    return bool(np.max(np.abs(y)) < max(BOUND_NM * NAUTICAL_MILE, 2.0 * abs(y[0])))


def split_bounded(series: Mapping[str, Mapping[str, np.ndarray]]) -> tuple[list[str], list[str]]:
    """(bounded, unbounded) run names; all runs count as bounded when none is (nothing to frame)."""
    bounded = [n for n, d in series.items() if is_bounded(d)]
    unbounded = [n for n in series if n not in bounded]
    return (bounded, unbounded) if bounded else (list(series), [])


def _limits(arrays, margin: float = MARGIN) -> tuple[float, float]:
    values = np.concatenate([np.ravel(np.asarray(a, dtype=float)) for a in arrays])
    values = values[np.isfinite(values)]
    low, high = float(values.min()), float(values.max())
    pad = margin * (high - low) if high > low else max(1.0, abs(low)) * margin
    return low - pad, high + pad


def _max_offset_nm(data) -> float:
    y = np.asarray(data["cross_track_error"], dtype=float)
    return float(np.nanmax(np.abs(y))) / NAUTICAL_MILE


def _finish_time_axis(axes, title: str, fig) -> None:
    for ax in axes:
        ax.grid(True, linewidth=0.4, alpha=0.5)
        ax.tick_params(labelsize=style.TICK_SIZE)
    axes[-1].set_xlabel("time t [min]", fontsize=style.LABEL_SIZE)
    axes[0].legend(loc="best", **style.LEGEND)
    if title:
        fig.suptitle(title, fontsize=style.LABEL_SIZE + 1)


def _draw_tracks(ax, series, waypoints, unbounded, *, labels: bool) -> None:
    _waypoint_plot(ax, waypoints)
    for i, (name, data) in enumerate(series.items()):
        label = name
        if labels and name in unbounded:
            label = f"{name}: unbounded, leaves the frame ({_max_offset_nm(data):.1f} nm off)"
        ax.plot(data["east"] / NAUTICAL_MILE, data["north"] / NAUTICAL_MILE, color=_color(name, i),
                label=label if labels else name, linewidth=1.6)
        ax.plot(data["east"][0] / NAUTICAL_MILE, data["north"][0] / NAUTICAL_MILE, "o",
                color=style.COLORS["start"], markersize=5)
    ax.set_xlabel("east y [nm]", fontsize=style.LABEL_SIZE)
    ax.set_ylabel("north x [nm]", fontsize=style.LABEL_SIZE)
    ax.grid(True, linewidth=0.4, alpha=0.5)
    ax.tick_params(labelsize=style.TICK_SIZE)


def tracks_figure(series: Mapping[str, Mapping[str, np.ndarray]], waypoints, *,
                  title: str = "") -> Figure:
    """Fig. 3: the ships' tracks on the path, north up, in nm. The axes frame the path and the
    bounded runs; with an unbounded run a second panel shows every track whole."""
    _check(series)
    bounded, unbounded = split_bounded(series)
    from matplotlib.figure import Figure

    fig = Figure(figsize=(12.5 if unbounded else 7.5, 8.0))
    if unbounded:
        ax, ax_all = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.6, 1]})
    else:
        ax, ax_all = fig.subplots(), None
    _draw_tracks(ax, series, waypoints, unbounded, labels=True)
    wp = np.asarray(waypoints, dtype=float) / NAUTICAL_MILE
    east = [wp[:, 1]] + [series[n]["east"] / NAUTICAL_MILE for n in bounded]
    north = [wp[:, 0]] + [series[n]["north"] / NAUTICAL_MILE for n in bounded]
    ax.set_xlim(*_limits(east))
    ax.set_ylim(*_limits(north))
    ax.set_aspect("equal", adjustable="box")
    ax.legend(loc="best", **style.LEGEND)
    if ax_all is not None:
        _draw_tracks(ax_all, series, waypoints, unbounded, labels=False)
        ax_all.set_aspect("equal", adjustable="datalim")
        ax_all.set_title("every track whole", fontsize=style.LABEL_SIZE)
    heading = title or "tracks on the path (document 000, Fig. 3)"
    note = f"{len(series)} runs"
    if unbounded:
        note += f"; unbounded: {', '.join(unbounded)} (framed by the {len(bounded)} bounded runs)"
    fig.suptitle(f"{heading}\n{note}", fontsize=style.LABEL_SIZE + 1)
    return fig


def heading_figure(series: Mapping[str, Mapping[str, np.ndarray]], *, title: str = "") -> Figure:
    """Fig. 4: heading ψ, heading error ψ_r and cross-track error y_r against time."""
    _check(series)
    bounded, unbounded = split_bounded(series)
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10.0, 8.0))
    axes = fig.subplots(3, 1, sharex=True)
    panels = {0: [], 1: [], 2: []}
    for i, (name, data) in enumerate(series.items()):
        t, color = data["time"] / MINUTE, _color(name, i)
        values = (style.unwrap_deg(data["psi"]), style.to_deg(data["heading_error"]),
                  data["cross_track_error"] / NAUTICAL_MILE)
        label = f"{name}: unbounded, leaves the frame" if name in unbounded else name
        for k, v in enumerate(values):
            axes[k].plot(t, v, color=color, label=label if k == 0 else None, linewidth=1.4)
            if name in bounded:
                panels[k].append(v)
    if unbounded:  # the limits of the bounded runs (the unbounded ones run off the frame)
        for k, ax in enumerate(axes):
            ax.set_ylim(*_limits(panels[k]))
    axes[0].set_ylabel("heading ψ [deg]", fontsize=style.LABEL_SIZE)
    axes[1].set_ylabel("heading error ψ_r [deg]", fontsize=style.LABEL_SIZE)
    axes[2].set_ylabel("cross-track y_r [nm]", fontsize=style.LABEL_SIZE)
    for ax in axes[1:]:
        ax.axhline(0.0, **style.ZERO)
    note = f"{len(series)} runs" + (f"; unbounded, off the frame: {', '.join(unbounded)}"
                                     if unbounded else "")
    _finish_time_axis(axes, f"{title or 'heading and path errors (document 000, Fig. 4)'}\n{note}",
                      fig)
    return fig


def rudder_figure(series: Mapping[str, Mapping[str, np.ndarray]], *, title: str = "",
                  rudder_limit_deg: float | None = None) -> Figure:
    """Fig. 5: the applied rudder angle δ against time, with its limits. Unbounded runs (their
    rudder usually hard over, to and fro) get a panel of their own below the bounded runs."""
    _check(series)
    bounded, unbounded = split_bounded(series)
    groups = [bounded] + ([unbounded] if unbounded else [])
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10.0, 4.5 + 2.8 * (len(groups) - 1)))
    axes = fig.subplots(len(groups), 1, sharex=True, squeeze=False)[:, 0]
    notes = []
    for ax, names in zip(axes, groups, strict=True):
        for name in names:
            i = list(series).index(name)
            delta = style.to_deg(series[name]["delta"])
            label = name
            if name in unbounded and rudder_limit_deg is not None:
                share = float(np.mean(np.abs(delta) >= rudder_limit_deg - 1e-6))
                label = f"{name}: unbounded run, at the limit {100 * share:.0f} % of the time"
            ax.plot(series[name]["time"] / MINUTE, delta, color=_color(name, i), label=label,
                    linewidth=1.2)
        if rudder_limit_deg is not None:
            for sign in (-1, 1):
                ax.axhline(sign * rudder_limit_deg, **style.LIMIT)
        ax.axhline(0.0, **style.ZERO)
        ax.set_ylabel("rudder δ [deg]", fontsize=style.LABEL_SIZE)
        ax.legend(loc="best", **style.LEGEND)
    if unbounded:
        notes.append(f"{len(bounded)} bounded runs (top), unbounded: {', '.join(unbounded)} (below)")
    else:
        notes.append(f"{len(series)} runs")
    _finish_time_axis(list(axes), f"{title or 'rudder angle (document 000, Fig. 5)'}\n{notes[0]}",
                      fig)
    return fig


def montecarlo_series(result, controller: str, *, tracks: int = TRACKS_DRAWN) -> dict[str, np.ndarray]:
    """Tracks (the first ``tracks`` ships) and the cross-track error of every ship, for the spread
    figure: arrays ``(time, ship)``."""
    ds = result.sel(controller=controller) if "controller" in result.dims else result
    return {"time": np.asarray(ds["time"].values, dtype=float),
            "north": np.asarray(ds["north"].values[:, :tracks], dtype=float),
            "east": np.asarray(ds["east"].values[:, :tracks], dtype=float),
            "cross_track_error": np.asarray(ds["cross_track_error"].values, dtype=float)}


def montecarlo_figure(series: Mapping[str, Mapping[str, np.ndarray]], waypoints, *,
                      title: str = "") -> Figure:
    """Spread of a batch: tracks on the path (left) and the cross-track error's median and 5–95 %
    band against time (right), one row per controller."""
    _check(series)
    names = list(series)
    from matplotlib.figure import Figure

    fig = Figure(figsize=(13.0, 5.2 * len(names)))
    axes = fig.subplots(len(names), 2, squeeze=False, gridspec_kw={"width_ratios": [1, 1.6]})
    for i, name in enumerate(names):
        data, color = series[name], _color(name, i)
        ax_track, ax_err = axes[i]
        _waypoint_plot(ax_track, waypoints)
        ax_track.plot(data["east"] / NAUTICAL_MILE, data["north"] / NAUTICAL_MILE, color=color,
                      linewidth=0.5, alpha=0.25)
        ax_track.set_aspect("equal", adjustable="datalim")
        ax_track.set_xlabel("east y [nm]", fontsize=style.LABEL_SIZE)
        ax_track.set_ylabel("north x [nm]", fontsize=style.LABEL_SIZE)
        ax_track.set_title(f"{name}: {data['north'].shape[1]} of "
                           f"{data['cross_track_error'].shape[1]} tracks", fontsize=style.LABEL_SIZE)
        t = data["time"] / MINUTE
        y = data["cross_track_error"] / NAUTICAL_MILE
        with np.errstate(invalid="ignore"):
            low, mid, high = np.nanpercentile(y, [5, 50, 95], axis=1)
        ax_err.fill_between(t, low, high, color=color, alpha=0.25, label="5–95 %")
        ax_err.plot(t, mid, color=color, linewidth=1.6, label="median")
        ax_err.axhline(0.0, **style.ZERO)
        ax_err.set_ylabel("cross-track y_r [nm]", fontsize=style.LABEL_SIZE)
        ax_err.set_xlabel("time t [min]", fontsize=style.LABEL_SIZE)
        ax_err.legend(loc="best", **style.LEGEND)
        for ax in (ax_track, ax_err):
            ax.grid(True, linewidth=0.4, alpha=0.5)
            ax.tick_params(labelsize=style.TICK_SIZE)
    if title:
        fig.suptitle(title, fontsize=style.LABEL_SIZE + 1)
    return fig


def _check(series) -> None:
    if not series:
        raise ConfigError("path-tracking figure: no controller series to draw")
