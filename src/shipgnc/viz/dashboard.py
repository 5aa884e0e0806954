"""The telemetry dashboard (note 001-1.11) and the stern-kick close-up (note 001-1.14 item 4).

Figures are drawn from a result ``xarray.Dataset`` only (no simulation, no I/O except
:func:`save_figure`). :class:`DashboardLayout` owns the axes and artists of the dashboard; the
static :func:`dashboard` fills it once, the live observer (:mod:`shipgnc.viz.live`) fills it
sample by sample, so the layout exists in one place.

Layout (``matplotlib.gridspec``): on the left, full height, the track in NED with East on the
horizontal axis and North up, equal aspect, with the path, the start, boat outlines at regular
intervals and at the final time, and the thrust arrow at the transom. On the right, on a shared
time axis: u and v; r; ψ (with ψ_d and ψ_r); T_cmd vs T; α_cmd vs α.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import FancyArrow, Patch, Polygon

from shipgnc.errors import ConfigError
from shipgnc.viz import style
from shipgnc.viz.series import (  # noqa: F401  (re-exported)
    INPUT_KEYS,
    REFERENCE_KEYS,
    STATE_KEYS,
    decimate_series,
    result_series,
    select_ship,
)

#: variables the dashboard draws, in SI units (angles in rad); the states are required

# figure margins [in]
_LEFT, _RIGHT, _BOTTOM, _TOP, _TITLE_LINE, _GAP = 0.72, 0.22, 0.58, 0.25, 0.24, 0.95


# --------------------------------------------------------------------------- geometry
def boat_outline(north: float, east: float, psi: float, length: float, beam: float) -> np.ndarray:
    """Corners ``(east, north)`` of the pentagon outline (bow point, shoulders, transom) of a boat.

    The CG is at the middle of the length; the bow point is ``length/2`` ahead, the shoulders at
    ``length/6`` ahead, the transom corners ``length/2`` behind, ``±beam/2`` to the sides.
    """
    half_l, half_b = 0.5 * length, 0.5 * beam
    body = np.array([[half_l, 0.0], [length / 6.0, half_b], [-half_l, half_b],
                     [-half_l, -half_b], [length / 6.0, -half_b]])  # (x forward, y starboard)
    c, s = math.cos(psi), math.sin(psi)
    d_north = c * body[:, 0] - s * body[:, 1]
    d_east = s * body[:, 0] + c * body[:, 1]
    return np.column_stack([east + d_east, north + d_north])


def thrust_arrow(north: float, east: float, psi: float, thrust: float, alpha: float,
                 lever_arm: float, scale: float) -> tuple[float, float, float, float]:
    """``(east, north, d_east, d_north)`` of the thrust arrow, its head at the thruster point.

    The thruster sits ``lever_arm`` behind the CG on the centre line; the arrow points along the
    thrust vector (angle ψ + α in NED) and is ``scale · T`` long, drawn from behind the transom so
    that it pushes on it.
    """
    c, s = math.cos(psi), math.sin(psi)
    tip_n, tip_e = north - lever_arm * c, east - lever_arm * s
    length = scale * max(thrust, 0.0)
    d_n, d_e = length * math.cos(psi + alpha), length * math.sin(psi + alpha)
    return tip_e - d_e, tip_n - d_n, d_e, d_n


def lateral_offset(north, east, origin_north: float, origin_east: float, heading: float):
    """Position to starboard of the line through the origin along ``heading`` [m] (note 001-1.8)."""
    return (-(np.asarray(north) - origin_north) * math.sin(heading)
            + (np.asarray(east) - origin_east) * math.cos(heading))


def nice_interval(duration: float, count: int = 10) -> float:
    """A round time step (1, 2, 2.5, 5 × 10^k s) giving about ``count`` intervals over ``duration``."""
    if not math.isfinite(duration) or duration <= 0:
        return 1.0
    raw = duration / count
    base = 10.0 ** math.floor(math.log10(raw))
    for step in (1.0, 2.0, 2.5, 5.0, 10.0):
        if raw <= step * base * 1.0001:
            return step * base
    return 10.0 * base


# --------------------------------------------------------------------------- data access
# --------------------------------------------------------------------------- layout
class DashboardLayout:
    """Axes and artists of the telemetry dashboard on ``fig``; :meth:`update` fills them.

    Parameters
    ----------
    references : which of ``psi_d``, ``psi_r`` get a line in the heading panel.
    t_end : fixed end of the time axis (live mode); ``None`` follows the data.
    thrust_scale : arrow length per newton [m/N]; default one boat length at the upper T limit,
        else at ``thrust_reference`` [N], else at the largest T of the first update.
    legend_loc : legend place in the time panels: ``"best"`` for static figures, a fixed corner
        for live redraws (faster). The track's legend is always placed at ``"best"``.
    """

    def __init__(self, fig, *, title: str = "", waypoints=None, limits: Mapping | None = None,
                 outline: tuple[float, float] = (2.0, 1.08), lever_arm: float = 1.0,
                 references: Sequence[str] = (), t_end: float | None = None,
                 thrust_scale: float | None = None, thrust_reference: float | None = None,
                 boat_every: float | None = None, legend_loc: str = "best"):
        self.fig = fig
        self.length, self.beam = _check_outline(outline)
        if not (isinstance(lever_arm, (int, float)) and math.isfinite(lever_arm) and lever_arm >= 0):
            raise ConfigError(f"lever_arm = {lever_arm!r}: must be a finite number >= 0 m")
        self.lever_arm = float(lever_arm)
        self.limits = _check_limits(limits)
        self.t_end = t_end
        self.legend_loc = legend_loc
        t_ref = self.limits["T"][1] if "T" in self.limits else thrust_reference
        if thrust_scale is None:
            thrust_scale = self.length / t_ref if t_ref and t_ref > 0 else None
        self.thrust_scale = thrust_scale  # None: set from the data at the first update
        self._grid(title)
        self._track_artists(waypoints, boat_every)
        self._time_artists(references)

    # ---- construction
    def _grid(self, title: str) -> None:
        fig = self.fig
        width, height = fig.get_size_inches()
        n_title = len(title.splitlines()) if title else 0
        top = _TOP + (_TITLE_LINE * n_title + 0.12 if n_title else 0.0)
        grid = fig.add_gridspec(1, 2, left=_LEFT / width, right=1 - _RIGHT / width,
                                bottom=_BOTTOM / height, top=1 - top / height,
                                width_ratios=(1.0, 1.12), wspace=_GAP / (0.5 * width))
        right = grid[0, 1].subgridspec(5, 1, hspace=0.13)
        self.ax_track = fig.add_subplot(grid[0, 0])
        axes = [fig.add_subplot(right[0, 0])]
        axes += [fig.add_subplot(right[i, 0], sharex=axes[0]) for i in range(1, 5)]
        self.ax_uv, self.ax_r, self.ax_psi, self.ax_T, self.ax_alpha = axes
        self.time_axes = axes
        if title:
            fig.suptitle(title, fontsize=style.TITLE_SIZE,
                         y=1 - (_TOP * 0.6) / height, va="top")

    def _track_artists(self, waypoints, boat_every) -> None:
        ax = self.ax_track
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("East y [m]", fontsize=style.LABEL_SIZE)
        ax.set_ylabel("North x [m]", fontsize=style.LABEL_SIZE)
        ax.tick_params(labelsize=style.TICK_SIZE)
        ax.grid(True, linewidth=0.4, alpha=0.5)
        if waypoints is not None:
            wp = _check_waypoints(waypoints)
            ax.plot(wp[:, 1], wp[:, 0], color=style.COLORS["path"], linestyle="--", linewidth=1.2,
                    marker="o", markersize=5, markerfacecolor="white",
                    markeredgecolor=style.COLORS["waypoint"], label="path, waypoints", zorder=1)
            for i, (n, e) in enumerate(wp):
                ax.annotate(f"WP{i}", (e, n), xytext=(5, 5), textcoords="offset points",
                            fontsize=7, color=style.COLORS["waypoint"])
        (self.track_line,) = ax.plot([], [], color=style.COLORS["track"], linewidth=1.6,
                                     label="track", zorder=4.5)
        (self.start_marker,) = ax.plot([], [], linestyle="none", marker="o", markersize=7,
                                       color=style.COLORS["start"], label="start", zorder=5)
        self.boat = Polygon(np.zeros((5, 2)), closed=True, facecolor=style.COLORS["boat_fill_now"],
                            edgecolor=style.COLORS["boat_edge"], linewidth=1.0, zorder=6)
        ax.add_patch(self.boat)
        self.arrow = FancyArrow(0, 0, 0, 0, width=0.1 * self.beam, head_width=0.4 * self.beam,
                                head_length=0.3 * self.beam, length_includes_head=True,
                                color=style.COLORS["thrust"], zorder=7)
        self.arrow.set_visible(False)
        ax.add_patch(self.arrow)
        self.boat_every = boat_every
        self.n_outlines = 0

    def _time_artists(self, references: Sequence[str]) -> None:
        c, lim = style.COLORS, self.limits
        ax = self.ax_uv
        ax.axhline(0.0, **style.ZERO)
        (self.u_line,) = ax.plot([], [], color=c["u"], **style.APPLIED, label="u")
        (self.v_line,) = ax.plot([], [], color=c["v"], **style.APPLIED, label="v")
        ax.set_ylabel("u, v [m/s]", fontsize=style.LABEL_SIZE)

        ax = self.ax_r
        ax.axhline(0.0, **style.ZERO)
        (self.r_line,) = ax.plot([], [], color=c["r"], **style.APPLIED, label="r")
        ax.set_ylabel("r [deg/s]", fontsize=style.LABEL_SIZE)

        ax = self.ax_psi
        (self.psi_line,) = ax.plot([], [], color=c["psi"], **style.APPLIED, label="ψ")
        self.psi_d_line = self.psi_r_line = None
        if "psi_d" in references:
            (self.psi_d_line,) = ax.plot([], [], **style.REFERENCE, label="ψ_d")
        if "psi_r" in references:
            (self.psi_r_line,) = ax.plot([], [], **style.REFERENCE_MODEL, label="ψ_r")
        ax.set_ylabel("ψ [deg]", fontsize=style.LABEL_SIZE)

        ax = self.ax_T
        (self.T_line,) = ax.plot([], [], color=c["T"], **style.APPLIED, **style.HELD, label="T")
        (self.T_cmd_line,) = ax.plot([], [], **style.COMMANDED, **style.HELD, label="T_cmd")
        if "T" in lim:
            for k, value in enumerate(lim["T"]):
                ax.axhline(value, **style.LIMIT, label="limits" if k == 0 else None)
        ax.set_ylabel("T [N]", fontsize=style.LABEL_SIZE)

        ax = self.ax_alpha
        ax.axhline(0.0, **style.ZERO)
        (self.alpha_line,) = ax.plot([], [], color=c["alpha"], **style.APPLIED, **style.HELD,
                                     label="α")
        (self.alpha_cmd_line,) = ax.plot([], [], **style.COMMANDED, **style.HELD, label="α_cmd")
        if "alpha" in lim:
            for k, value in enumerate(lim["alpha"]):
                ax.axhline(style.to_deg(value), **style.LIMIT, label="limits" if k == 0 else None)
        ax.set_ylabel("α [deg]", fontsize=style.LABEL_SIZE)
        ax.set_xlabel("time t [s]", fontsize=style.LABEL_SIZE)

        for ax in self.time_axes:
            ax.grid(True, linewidth=0.4, alpha=0.5)
            ax.tick_params(labelsize=style.TICK_SIZE)
            ax.yaxis.set_label_coords(-0.075, 0.5)
            if ax is not self.ax_alpha:
                ax.tick_params(labelbottom=False)
        if self.t_end is not None:
            self.ax_uv.set_xlim(0.0, self.t_end)

    def legends(self) -> None:
        """(Re)draw the legends once the artists hold data."""
        loc = self.legend_loc
        for ax in self.time_axes:
            ax.legend(loc=loc, ncol=3, **style.LEGEND)
        handles, labels = self.ax_track.get_legend_handles_labels()
        handles.append(Patch(facecolor=style.COLORS["boat_fill_now"],
                             edgecolor=style.COLORS["boat_edge"], linewidth=1.0))
        labels.append(f"boat {self.length:g} × {self.beam:g} m, now")
        if self.boat_every:
            handles.append(Patch(facecolor=style.COLORS["boat_fill"],
                                 edgecolor=style.COLORS["boat_edge"], linewidth=0.8))
            labels.append(f"boat every {self.boat_every:g} s")
        handles.append(Patch(facecolor=style.COLORS["thrust"], edgecolor="none"))
        labels.append("thrust (∝ T)")
        self.ax_track.legend(handles, labels, loc="best", **style.LEGEND)

    # ---- drawing
    def add_boat(self, north: float, east: float, psi: float, thrust: float = 0.0,
                 alpha: float = 0.0) -> None:
        """A fixed (ghost) outline with its thrust arrow, e.g. every ``boat_every`` seconds."""
        ax = self.ax_track
        ax.add_patch(Polygon(boat_outline(north, east, psi, self.length, self.beam), closed=True,
                             facecolor=style.COLORS["boat_fill"], edgecolor=style.COLORS["boat_edge"],
                             linewidth=0.8, alpha=0.9, zorder=3))
        if self.thrust_scale and np.isfinite(thrust) and thrust > 1e-9:
            x, y, dx, dy = thrust_arrow(north, east, psi, thrust, alpha, self.lever_arm,
                                        self.thrust_scale)
            ax.add_patch(FancyArrow(x, y, dx, dy, width=0.08 * self.beam, head_width=0.3 * self.beam,
                                    head_length=min(0.25 * self.beam, math.hypot(dx, dy)),
                                    length_includes_head=True, color=style.COLORS["thrust"],
                                    alpha=0.7, zorder=4))
        self.n_outlines += 1

    def update(self, data: Mapping[str, np.ndarray], *, rescale: bool = True) -> None:
        """Set every artist from ``data`` (SI arrays keyed like the result variables + ``time``)."""
        t = np.asarray(data["time"], dtype=float)
        if t.size == 0:
            return
        north, east = np.asarray(data["north"], float), np.asarray(data["east"], float)
        psi_rad = np.asarray(data["psi"], float)
        self.track_line.set_data(east, north)
        self.start_marker.set_data(east[:1], north[:1])
        n_now, e_now, psi_now = float(north[-1]), float(east[-1]), float(psi_rad[-1])
        if all(map(math.isfinite, (n_now, e_now, psi_now))):
            self.boat.set_xy(boat_outline(n_now, e_now, psi_now, self.length, self.beam))
            self._update_arrow(data, n_now, e_now, psi_now)

        self.u_line.set_data(t, data["u"])
        self.v_line.set_data(t, data["v"])
        self.r_line.set_data(t, style.to_deg(np.asarray(data["r"], float)))
        psi_deg = style.unwrap_deg(psi_rad)
        self.psi_line.set_data(t, psi_deg)
        for line, key in ((self.psi_d_line, "psi_d"), (self.psi_r_line, "psi_r")):
            if line is not None and key in data:
                line.set_data(t, style.align_deg(data[key], np.radians(psi_deg)))
        for line, key, deg in ((self.T_line, "T", False), (self.T_cmd_line, "T_cmd", False),
                               (self.alpha_line, "alpha", True),
                               (self.alpha_cmd_line, "alpha_cmd", True)):
            if key in data:
                values = np.asarray(data[key], float)
                line.set_data(t, style.to_deg(values) if deg else values)
        if rescale:
            self.rescale(t)

    def _update_arrow(self, data, north: float, east: float, psi: float) -> None:
        thrust = float(data["T"][-1]) if "T" in data else float("nan")
        alpha = float(data["alpha"][-1]) if "alpha" in data else 0.0
        if self.thrust_scale is None and "T" in data:
            t_max = float(np.nanmax(np.abs(data["T"]))) if np.any(np.isfinite(data["T"])) else 0.0
            self.thrust_scale = self.length / t_max if t_max > 0 else None
        if not (self.thrust_scale and math.isfinite(thrust) and thrust > 1e-9 and math.isfinite(alpha)):
            self.arrow.set_visible(False)
            return
        x, y, dx, dy = thrust_arrow(north, east, psi, thrust, alpha, self.lever_arm, self.thrust_scale)
        self.arrow.set_data(x=x, y=y, dx=dx, dy=dy,
                            head_length=min(0.3 * self.beam, math.hypot(dx, dy)))
        self.arrow.set_visible(True)

    def rescale(self, t: np.ndarray | None = None) -> None:
        """Fit the axes to the data (the time axis to ``t_end`` when it is fixed)."""
        for ax in (self.ax_track, *self.time_axes):
            ax.relim()
            ax.autoscale_view()
        t_hi = self.t_end
        if t_hi is None and t is not None and t.size:
            t_hi = float(t[-1])
        if t_hi is not None and t_hi > 0:
            self.ax_uv.set_xlim(0.0 if t is None or not t.size else min(0.0, float(t[0])), t_hi)


def _check_outline(outline) -> tuple[float, float]:
    try:
        length, beam = (float(v) for v in outline)
    except (TypeError, ValueError):
        raise ConfigError(f"outline = {outline!r}: must be (length, beam) in m") from None
    if not (length > 0 and beam > 0 and math.isfinite(length) and math.isfinite(beam)):
        raise ConfigError(f"outline = {outline!r}: length and beam must be finite and > 0 m")
    return length, beam


def _check_limits(limits) -> dict[str, tuple[float, float]]:
    if limits is None:
        return {}
    if not isinstance(limits, Mapping):
        raise ConfigError(f"limits = {limits!r}: must be a dict like {{'T': (0, 200), 'alpha': "
                          "(-0.785, 0.785)}} in SI units")
    out = {}
    for key, pair in limits.items():
        try:
            lo, hi = (float(v) for v in pair)
        except (TypeError, ValueError):
            raise ConfigError(f"limits[{key!r}] = {pair!r}: must be (lower, upper)") from None
        out[key] = (lo, hi)
    return out


def _check_waypoints(waypoints) -> np.ndarray:
    wp = np.asarray(waypoints, dtype=float)
    if wp.ndim != 2 or wp.shape[1] != 2 or not np.all(np.isfinite(wp)):
        raise ConfigError(f"waypoints: shape {wp.shape}; must be finite (north, east) pairs in m, "
                          "shape (n, 2)")
    return wp


# --------------------------------------------------------------------------- public figures
def dashboard(result, *, title: str = "", waypoints=None, limits: Mapping | None = None,
              outline: tuple[float, float] = (2.0, 1.08), lever_arm: float = 1.0, ship=0,
              boat_every: float | None = None):
    """The telemetry dashboard of one ship of ``result`` (note 001-1.11) as a Figure.

    Parameters
    ----------
    result : a run's ``xarray.Dataset`` (time coordinate; north, east, psi, u, v, r, and the
        commanded/applied inputs T_cmd, T, alpha_cmd, alpha; psi_d and psi_r when present).
    title : the figure title (scenario, preset, key metrics).
    waypoints : ``(n, 2)`` (north, east) [m] of the path, drawn when given.
    limits : actuator limits in SI, e.g. ``{"T": (0, 200), "alpha": (-0.785, 0.785)}``; drawn as lines.
    outline : ``(length, beam)`` of the boat outline [m].
    lever_arm : distance from the CG back to the thruster [m], where the thrust arrow ends.
    ship : index along the batch dimension of a batched result.
    boat_every : time between the outlines drawn on the track [s]; default about ten per run
        (fewer when the track is shorter than twenty boat lengths).
    """
    ds = select_ship(result, ship)
    data = result_series(ds)
    t = data["time"]
    duration = float(t[-1] - t[0])
    if boat_every is None:  # about ten outlines, fewer on a short track (two lengths apart)
        steps = np.hypot(np.diff(data["north"]), np.diff(data["east"]))
        travelled = float(np.nansum(steps)) if steps.size else 0.0
        length = _check_outline(outline)[0]
        boat_every = nice_interval(duration, int(min(10, max(1, travelled // (2.0 * length)))))
    elif not (isinstance(boat_every, (int, float)) and math.isfinite(boat_every) and boat_every > 0):
        raise ConfigError(f"boat_every = {boat_every!r}: must be a number > 0 s")
    fig = Figure(figsize=style.DASHBOARD_SIZE)  # no pyplot: no window, no global registry
    t_max = float(np.nanmax(np.abs(data["T"]))) if "T" in data and np.any(np.isfinite(data["T"])) else None
    try:
        layout = DashboardLayout(fig, title=title, waypoints=waypoints, limits=limits,
                                 outline=outline, lever_arm=lever_arm, thrust_reference=t_max,
                                 references=[k for k in REFERENCE_KEYS if k in data],
                                 boat_every=boat_every)
        for i in _ghost_indices(t, boat_every):
            layout.add_boat(data["north"][i], data["east"][i], data["psi"][i],
                            data["T"][i] if "T" in data else 0.0,
                            data["alpha"][i] if "alpha" in data else 0.0)
        layout.update(decimate_series(data))  # a long run: its envelope at the figure's resolution
        layout.legends()
    except Exception:
        close_figure(fig)
        raise
    return fig


def _ghost_indices(t: np.ndarray, every: float) -> list[int]:
    """Sample indices at t0, t0 + every, ... (not the last sample, which is drawn as 'now')."""
    marks = np.arange(t[0], t[-1] - 0.25 * every, every)
    idx = np.searchsorted(t, marks - 1e-9 * max(1.0, abs(t[-1])))
    return sorted({int(i) for i in idx if i < t.size - 1})


def stern_kick_closeup(result, *, lever_arm: float = 1.0, t0: float | None = None,
                       duration: float = 3.0, length: float = 2.0, ship=0, title: str | None = None):
    """Lateral position of the CG, the bow and the stern after a thruster step (note 001-1.14, 4).

    y is measured to starboard of the line through the CG position at ``t0`` along the heading at
    ``t0`` (the frame of the initial heading). The bow is ``length/2`` ahead of the CG, the stern
    (thruster point) ``lever_arm`` behind it. ``t0`` defaults to the first time ``alpha_cmd``
    becomes nonzero. The lower panel shows the CG alone in millimetres, where the non-minimum-phase
    start (the CG first moves away from the turn) is visible.
    """
    ds = select_ship(result, ship)
    data = result_series(ds)
    t = data["time"]
    if t0 is None:
        key = "alpha_cmd" if "alpha_cmd" in data else "alpha"
        if key not in data:
            raise ConfigError("stern_kick_closeup: the result has no alpha_cmd; pass t0")
        nonzero = np.flatnonzero(np.abs(data[key]) > 0)
        if nonzero.size == 0:
            raise ConfigError("stern_kick_closeup: alpha_cmd is zero throughout (no thruster step); "
                              "pass t0")
        i0 = int(nonzero[0])
    else:
        if not (t[0] <= t0 <= t[-1]):
            raise ConfigError(f"t0 = {t0!r}: must lie within the run, {t[0]:g}..{t[-1]:g} s")
        i0 = int(np.argmin(np.abs(t - t0)))
    if not (isinstance(duration, (int, float)) and duration > 0):
        raise ConfigError(f"duration = {duration!r}: must be a number > 0 s")
    start = float(t[i0])
    lead = 0.1 * duration
    window = (t >= start - lead - 1e-9) & (t <= start + duration + 1e-9)
    north, east, psi = data["north"], data["east"], data["psi"]
    n0, e0, psi0 = float(north[i0]), float(east[i0]), float(psi[i0])
    c, s = np.cos(psi), np.sin(psi)
    half = 0.5 * length
    y_cg = lateral_offset(north, east, n0, e0, psi0)
    y_bow = lateral_offset(north + half * c, east + half * s, n0, e0, psi0)
    y_stern = lateral_offset(north - lever_arm * c, east - lever_arm * s, n0, e0, psi0)

    fig = Figure(figsize=style.SMALL_SIZE)
    ax, ax_cg = fig.subplots(2, 1, sharex=True,
                             gridspec_kw={"height_ratios": (1.4, 1.0), "hspace": 0.1})
    tw = t[window]
    for values, key, label in ((y_bow, "bow", f"bow (+{half:g} m)"), (y_cg, "cg", "CG"),
                               (y_stern, "stern", f"stern / thruster (−{lever_arm:g} m)")):
        ax.plot(tw, values[window], color=style.COLORS[key], linewidth=1.8, label=label)
    ax_cg.plot(tw, 1e3 * y_cg[window], color=style.COLORS["cg"], linewidth=1.8, label="CG")
    for a in (ax, ax_cg):
        a.axhline(0.0, **style.ZERO)
        a.axvline(start, **style.LIMIT)
        a.grid(True, linewidth=0.4, alpha=0.5)
        a.tick_params(labelsize=style.TICK_SIZE)
    alpha_text = ""
    if "alpha_cmd" in data:
        alpha_deg = float(style.to_deg(data["alpha_cmd"][i0]))
        alpha_text = f", α_cmd = {_minus(f'{alpha_deg:.3g}')}°"
    ax.set_ylabel("y to starboard [m]", fontsize=style.LABEL_SIZE)
    ax.legend(loc="best", **style.LEGEND)
    ax_cg.set_ylabel("y of the CG [mm]", fontsize=style.LABEL_SIZE)
    ax_cg.set_xlabel("time t [s]", fontsize=style.LABEL_SIZE)
    after = window & (t >= start)
    if np.any(after):
        idx = np.flatnonzero(after)
        k = idx[int(np.argmin(y_cg[idx]))]
        y_min = 1e3 * y_cg[k]
        if y_min < 0:
            # zoom on the kick: the CG soon moves metres to starboard
            ax_cg.set_ylim(2.4 * y_min, -2.4 * y_min)
            ax_cg.plot([t[k]], [y_min], marker="o", color=style.COLORS["cg"])
            ax_cg.annotate(f"min {_minus(f'{y_min:.1f}')} mm at {t[k]:.2f} s", (t[k], y_min),
                           xytext=(0, -8), textcoords="offset points", fontsize=8, ha="center",
                           va="top")
            later = idx[idx > k]
            crossing = later[y_cg[later] > 0]
            if crossing.size:
                tc = t[crossing[0]]
                ax_cg.axvline(tc, color=style.COLORS["cg"], linewidth=0.8, linestyle=":")
                ax_cg.annotate(f"y > 0 from {tc:.2f} s", (tc, 1.0), xytext=(-5, -4),
                               xycoords=ax_cg.get_xaxis_transform(), textcoords="offset points",
                               fontsize=8, ha="right", va="top")
    ax_cg.text(start, 1.0, " step", transform=ax_cg.get_xaxis_transform(), fontsize=8,
               va="top", color=style.COLORS["limit"])
    if title is None:
        title = (f"Stern kick: lateral position in the frame of the heading at t0 = {start:.2f} s"
                 f"{alpha_text}")
    fig.suptitle(title, fontsize=style.LABEL_SIZE + 1)
    fig.subplots_adjust(left=0.12, right=0.97, bottom=0.09, top=0.92)
    ax.set_xlim(tw[0], tw[-1])
    return fig


def _minus(text: str) -> str:
    """Typographic minus signs, as on the axes."""
    return text.replace("-", "\u2212")


def save_figure(fig, path) -> Path:
    """Write ``fig`` as PNG (``style.DPI``) to ``path``, creating its folder, and close it.

    A path without a suffix gets ``.png``; returns the path written.
    """
    path = Path(path)
    if not path.suffix:
        path = path.with_suffix(".png")
    elif path.suffix.lower() != ".png":
        close_figure(fig)
        raise ConfigError(f"figure path {str(path)!r}: figures are written as PNG (use a .png name)")
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        fig.savefig(path, dpi=style.DPI, format="png")
    finally:
        close_figure(fig)
    return path


def close_figure(fig) -> None:
    """Release a figure: pyplot-managed ones (live windows) are closed through pyplot."""
    if getattr(fig.canvas, "manager", None) is not None:
        import matplotlib.pyplot as plt

        plt.close(fig)
