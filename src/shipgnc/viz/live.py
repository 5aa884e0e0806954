"""Live telemetry: the dashboard as a simulator observer (note 001-1.11, ``shipgnc run … --live``).

The simulation loop stays free of plotting: :func:`~shipgnc.sim.simulator.simulate` calls
``observer(t, x, command, applied)`` at every sample. :class:`LiveDashboard` buffers the samples
and redraws the :class:`~shipgnc.viz.dashboard.DashboardLayout` at most every ``redraw_interval``
seconds of wall time (artist ``set_data``, ``canvas.draw_idle()``, ``flush_events()``); when a
redraw takes longer than that, the pause after it is at least as long as the redraw, so the
simulation keeps at least half of the wall time. An
optional ``realtime`` factor paces the run against the wall clock (1.0 = real time). Closing
the window raises :class:`~shipgnc.sim.simulator.StopSimulation`, which ends the run cleanly and
keeps the result gathered so far.

Example::

    live = LiveDashboard(t_end=30.0, limits={"T": (0, 200), "alpha": (-0.785, 0.785)})
    result = simulate(boat, x0, t_end=30.0, dt=0.05, controller=ctrl, observer=live)
    live.finish()   # last redraw; the window stays open until plt.show() or live.close()
"""

from __future__ import annotations

import math
import os
import sys
import time as _time
from collections.abc import Mapping

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

from shipgnc.errors import ConfigError
from shipgnc.sim.simulator import StopSimulation
from shipgnc.viz import style
from shipgnc.viz.dashboard import DashboardLayout, nice_interval

_KEYS = ("time", "north", "east", "psi", "u", "v", "r", "T_cmd", "alpha_cmd", "T", "alpha")


class LiveDashboard:
    """Observer that draws the telemetry dashboard while the simulation runs.

    Parameters
    ----------
    t_end : end time of the run [s] (fixes the time axis; the last sample is always drawn).
    waypoints, limits, title, outline, lever_arm : as for :func:`shipgnc.viz.dashboard.dashboard`.
    realtime : ``None`` runs as fast as possible; a factor > 0 paces simulated time against the
        wall clock (1.0 = real time, 2.0 = twice as fast).
    redraw_interval : minimum wall time between redraws [s]; a slow redraw stretches the pause
        to its own duration. 0 redraws at every sample.
    require_interactive : raise :class:`~shipgnc.errors.ConfigError` on a backend that cannot
        open a window (Agg). Tests pass ``False`` to drive the observer headless.
    ship : which ship of a batched run is drawn (index into the flattened batch).
    boat_every : time between the outlines left on the track [s]; default about ten per run.
    """

    def __init__(self, t_end: float, *, waypoints=None, limits: Mapping | None = None,
                 title: str = "", realtime: float | None = None, redraw_interval: float = 0.1,
                 require_interactive: bool = True, ship: int = 0,
                 outline: tuple[float, float] = (2.0, 1.08), lever_arm: float = 1.0,
                 boat_every: float | None = None):
        backend = matplotlib.get_backend()
        self.interactive = style.is_interactive_backend(backend)
        if require_interactive and not self.interactive:
            raise ConfigError(_backend_message(backend))
        _positive("t_end", t_end)
        if realtime is not None:
            _positive("realtime", realtime)
        if not (isinstance(redraw_interval, (int, float)) and math.isfinite(redraw_interval)
                and redraw_interval >= 0):
            raise ConfigError(f"redraw_interval = {redraw_interval!r}: must be a number >= 0 s")
        if not isinstance(ship, (int, np.integer)) or isinstance(ship, bool) or ship < 0:
            raise ConfigError(f"ship = {ship!r}: must be an integer index >= 0")
        if boat_every is None:
            boat_every = nice_interval(float(t_end), 10)
        else:
            _positive("boat_every", boat_every)
        self.t_end = float(t_end)
        self.realtime = None if realtime is None else float(realtime)
        self.redraw_interval = float(redraw_interval)
        self.ship = int(ship)
        self.boat_every = float(boat_every)

        self.fig = plt.figure(figsize=style.DASHBOARD_SIZE)
        try:
            self.layout = DashboardLayout(self.fig, title=title, waypoints=waypoints, limits=limits,
                                          outline=outline, lever_arm=lever_arm, references=(),
                                          t_end=self.t_end, boat_every=self.boat_every,
                                          legend_loc="upper right")
            self.layout.legends()
        except Exception:
            plt.close(self.fig)
            raise
        self._buffers: dict[str, list[float]] = {k: [] for k in _KEYS}
        self._next_boat = 0.0
        self._closed = False
        self._last_draw = -math.inf
        self._draw_seconds = 0.0
        self._wall0: float | None = None
        self._t0 = 0.0
        self.n_samples = 0
        self.n_redraws = 0
        self.fig.canvas.mpl_connect("close_event", self._on_close)
        if self.interactive:
            plt.show(block=False)
            self.fig.canvas.flush_events()

    # ---- observer protocol
    def __call__(self, t: float, x, command, applied) -> None:
        """Buffer one sample; redraw if due; pace; raise StopSimulation once the window is closed."""
        if self.closed:
            raise StopSimulation("live dashboard window closed")
        x, command, applied = (self._pick(a) for a in (x, command, applied))
        t = float(t)
        if self._wall0 is None:
            self._wall0, self._t0 = _time.perf_counter(), t
        buf = self._buffers
        buf["time"].append(t)
        for key, value in zip(("north", "east", "psi", "u", "v", "r"), x[:6], strict=True):
            buf[key].append(float(value))
        buf["T_cmd"].append(float(command[0]))
        buf["alpha_cmd"].append(float(command[1]))
        buf["T"].append(float(applied[0]))
        buf["alpha"].append(float(applied[1]))
        self.n_samples += 1
        if t >= self._next_boat - 1e-9 and t < self.t_end - 0.25 * self.boat_every:
            self.layout.add_boat(*(float(v) for v in x[:3]), float(applied[0]), float(applied[1]))
            self._next_boat += self.boat_every
            while self._next_boat <= t:
                self._next_boat += self.boat_every
        last = t >= self.t_end - 1e-9
        # at most every redraw_interval, and never more than half of the wall time spent drawing
        # (redraw_interval = 0: at every sample)
        wait = max(self.redraw_interval, self._draw_seconds) if self.redraw_interval > 0 else 0.0
        if last or _time.perf_counter() - self._last_draw >= wait:
            self.redraw()
        if self.realtime is not None:
            self._pace(t)
        if self.closed:
            raise StopSimulation("live dashboard window closed")

    def _pick(self, values) -> np.ndarray:
        values = np.asarray(values, dtype=float)
        if values.ndim <= 1:
            return values
        flat = values.reshape(-1, values.shape[-1])
        if self.ship >= flat.shape[0]:
            raise ConfigError(f"ship = {self.ship}: the run has only {flat.shape[0]} ships")
        return flat[self.ship]

    # ---- drawing
    def data(self) -> dict[str, np.ndarray]:
        """The buffered samples as arrays (SI), keyed like the result variables plus ``time``."""
        return {k: np.asarray(v, dtype=float) for k, v in self._buffers.items()}

    def redraw(self) -> None:
        """Push the buffered samples to the artists and let the canvas draw them."""
        if self.closed or not self._buffers["time"]:
            return
        start = _time.perf_counter()
        self.layout.update(self.data())
        canvas = self.fig.canvas
        canvas.draw_idle()
        canvas.flush_events()
        self.n_redraws += 1
        self._last_draw = _time.perf_counter()
        self._draw_seconds = self._last_draw - start

    def finish(self, *, block: bool = False) -> None:
        """Draw the last samples (a run may end before ``t_end``); ``block`` keeps the window open."""
        self.redraw()
        if block and self.interactive and not self.closed:
            plt.show(block=True)

    def close(self) -> None:
        """Close the window (later calls raise StopSimulation)."""
        self._closed = True
        plt.close(self.fig)

    @property
    def closed(self) -> bool:
        """True once the window has been closed (by the user or by ``plt.close``)."""
        if not self._closed and not plt.fignum_exists(self.fig.number):
            self._closed = True
        return self._closed

    def _on_close(self, _event) -> None:
        self._closed = True

    def _pace(self, t: float) -> None:
        """Wait until the wall clock catches up with ``t / realtime``, keeping the window responsive."""
        target = self._wall0 + (t - self._t0) / self.realtime
        while not self.closed:
            remaining = target - _time.perf_counter()
            if remaining <= 0:
                break
            if self.interactive:
                self.fig.canvas.flush_events()
            _time.sleep(min(remaining, 0.02))


def _positive(name: str, value) -> None:
    if not (isinstance(value, (int, float)) and not isinstance(value, bool)
            and math.isfinite(value) and value > 0):
        raise ConfigError(f"{name} = {value!r}: must be a number > 0")


def _backend_message(backend: str) -> str:
    no_display = sys.platform.startswith("linux") and not (
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    reason = "no display" if no_display else "non-interactive"
    return (f"--live needs an interactive matplotlib backend; the current backend is "
            f"{backend.lower()!r} ({reason}). Set MPLBACKEND=TkAgg or run without --live")
