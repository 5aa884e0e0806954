"""Figures and live telemetry (notes 001-1.11, 001-1.14), headless on Agg."""

import matplotlib

matplotlib.use("Agg")

import subprocess
import sys

import matplotlib.image as mpimg
import matplotlib.pyplot as plt
import numpy as np
import pytest
import xarray as xr

from shipgnc.control.heading_speed import HeadingSpeedAutopilot
from shipgnc.control.open_loop import OpenLoopSchedule
from shipgnc.errors import ConfigError
from shipgnc.guidance.los import LOSGuidance
from shipgnc.guidance.schedule import ReferenceSchedule
from shipgnc.models.fossen3dof import VectoredThrustBoat
from shipgnc.paths import WaypointPath
from shipgnc.sim.simulator import StopSimulation, simulate
from shipgnc.viz import style
from shipgnc.viz.dashboard import dashboard, save_figure, stern_kick_closeup
from shipgnc.viz.live import LiveDashboard

LIMITS = {"T": (0.0, 200.0), "alpha": (-np.radians(45.0), np.radians(45.0))}
WAYPOINTS = [[0.0, 0.0], [25.0, 0.0], [25.0, 25.0]]


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def boat():
    return VectoredThrustBoat()


def _stern_kick_schedule():
    return OpenLoopSchedule([0.0, 2.0, 6.0], [[0.0, 0.0], [150.0, np.radians(-15.0)], [150.0, 0.0]])


@pytest.fixture(scope="module")
def open_loop(boat):
    return simulate(boat, np.zeros(6), t_end=12.0, dt=0.05, controller=_stern_kick_schedule(),
                    backend="numpy")


@pytest.fixture(scope="module")
def autopilot(boat):
    guidance = ReferenceSchedule([0.0, 2.0, 10.0], np.radians([0.0, 45.0, -30.0]), [1.5, 1.5, 1.5])
    return simulate(boat, np.zeros(6), t_end=18.0, dt=0.05, guidance=guidance,
                    controller=HeadingSpeedAutopilot(boat.params), backend="numpy")


@pytest.fixture(scope="module")
def los(boat):
    guidance = LOSGuidance(WaypointPath(WAYPOINTS), lookahead=8.0, speed=1.5, switch_radius=5.0)
    return simulate(boat, np.array([0.0, -5.0, 0.0, 0.0, 0.0, 0.0]), t_end=60.0, dt=0.1,
                    guidance=guidance, controller=HeadingSpeedAutopilot(boat.params, Ts=0.1),
                    backend="numpy")


def _assert_png(path, min_bytes=20_000):
    assert path.is_file()
    assert path.stat().st_size > min_bytes
    image = mpimg.imread(path)[..., :3]
    assert image.var() > 1e-3  # not blank
    assert np.mean(image.min(axis=-1) < 0.9) > 0.02  # a fair share of drawn (non-white) pixels


def _line(ax, label):
    lines = [line for line in ax.get_lines() if line.get_label() == label]
    assert lines, f"no line labelled {label!r}"
    return lines[0]


def test_dashboard_open_loop_png(open_loop, tmp_path):
    fig = dashboard(open_loop, title="boat-stern-kick (short)", limits=LIMITS)
    assert fig.get_suptitle() == "boat-stern-kick (short)"
    track_ax = fig.axes[0]
    assert track_ax.get_xlabel().startswith("East") and track_ax.get_ylabel().startswith("North")
    track = _line(track_ax, "track")
    np.testing.assert_allclose(track.get_xdata(), open_loop["east"].values)
    np.testing.assert_allclose(track.get_ydata(), open_loop["north"].values)
    # commanded dashed, applied solid; the α limits drawn at ±45°
    alpha_ax = fig.axes[5]
    assert _line(alpha_ax, "α_cmd").get_linestyle() == "--"
    assert _line(alpha_ax, "α").get_linestyle() == "-"
    limit_values = {round(float(line.get_ydata()[0]), 6) for line in alpha_ax.get_lines()
                    if line.get_color() == style.COLORS["limit"]}
    assert {45.0, -45.0} <= limit_values
    np.testing.assert_allclose(_line(fig.axes[2], "r").get_ydata(),
                               np.degrees(open_loop["r"].values))
    path = save_figure(fig, tmp_path / "open_loop.png")
    _assert_png(path)
    assert fig.canvas.manager is None  # a static figure: no window, nothing left in pyplot


def test_dashboard_autopilot_png(autopilot, tmp_path):
    fig = dashboard(autopilot, title="boat-autopilot (short)", limits=LIMITS)
    psi_ax = fig.axes[3]
    labels = {line.get_label() for line in psi_ax.get_lines()}
    assert {"ψ", "ψ_d", "ψ_r"} <= labels
    np.testing.assert_allclose(_line(psi_ax, "ψ_d").get_ydata()[-1], -30.0, atol=1e-9)
    _assert_png(save_figure(fig, tmp_path / "autopilot.png"))


def test_dashboard_los_png(los, tmp_path):
    fig = dashboard(los, title="boat-los (short)", waypoints=WAYPOINTS, limits=LIMITS, boat_every=5.0)
    path_line = _line(fig.axes[0], "path, waypoints")
    np.testing.assert_allclose(path_line.get_xdata(), [0.0, 0.0, 25.0])  # east
    np.testing.assert_allclose(path_line.get_ydata(), [0.0, 25.0, 25.0])  # north
    _assert_png(save_figure(fig, tmp_path / "los"))  # .png added
    assert (tmp_path / "los.png").is_file()


def test_dashboard_batched_draws_the_chosen_ship(boat, tmp_path):
    x0 = np.zeros((2, 6))
    x0[1, 1] = 5.0  # ship 1 starts 5 m east
    result = simulate(boat, x0, t_end=8.0, dt=0.1, controller=_stern_kick_schedule(), backend="numpy")
    fig = dashboard(result, ship=1, limits=LIMITS)
    np.testing.assert_allclose(_line(fig.axes[0], "track").get_xdata(),
                               result["east"].isel(ship=1).values)
    _assert_png(save_figure(fig, tmp_path / "batched.png"))
    with pytest.raises(ConfigError, match="ship"):
        dashboard(result, ship=2)


def test_heading_panel_does_not_jump_at_180_degrees():
    t = np.linspace(0.0, 10.0, 101)
    psi = np.radians(170.0) + np.radians(2.0) * t  # 170° → 190°, unwrapped
    psi_d = np.angle(np.exp(1j * np.radians(185.0))) * np.ones_like(t)  # wrapped: −175°
    zeros = np.zeros_like(t)
    ds = xr.Dataset({k: ("time", v) for k, v in dict(
        north=zeros, east=zeros, psi=psi, u=zeros, v=zeros, r=np.full_like(t, np.radians(2.0)),
        T_cmd=zeros, alpha_cmd=zeros, T=zeros, alpha=zeros, psi_d=psi_d).items()},
        coords={"time": t})
    fig = dashboard(ds)
    psi_ax = fig.axes[3]
    shown_psi = _line(psi_ax, "ψ").get_ydata()
    shown_psi_d = _line(psi_ax, "ψ_d").get_ydata()
    assert np.max(np.abs(np.diff(shown_psi))) < 1.0
    np.testing.assert_allclose(shown_psi_d, 185.0, atol=1e-9)


def test_stern_kick_closeup(open_loop, tmp_path):
    fig = stern_kick_closeup(open_loop)
    ax = fig.axes[0]
    t = _line(ax, "CG").get_xdata()
    assert t[0] < 2.0 <= t[-1] and t[-1] <= 2.0 + 3.0 + 1e-9  # default t0: the α step at 2 s
    y_cg = _line(ax, "CG").get_ydata()
    assert y_cg.min() < -0.01  # the CG first moves to port (stern kick), then to starboard
    assert y_cg[-1] > 0
    stern = next(line for line in ax.get_lines() if line.get_label().startswith("stern"))
    assert stern.get_ydata().min() < y_cg.min()
    _assert_png(save_figure(fig, tmp_path / "closeup.png"))
    with pytest.raises(ConfigError, match="t0"):
        stern_kick_closeup(open_loop.isel(time=slice(0, 10)))  # no α step yet


def test_save_figure_only_png(open_loop, tmp_path):
    with pytest.raises(ConfigError, match="PNG"):
        save_figure(dashboard(open_loop), tmp_path / "figure.pdf")


def _sample(k):
    t = 0.1 * k
    x = np.array([0.5 * t, 0.1 * t, 0.01 * t, 0.5, 0.0, 0.01])
    return t, x, np.array([150.0, -0.2]), np.array([150.0, -0.2])


def test_live_dashboard_artists_grow_with_samples():
    live = LiveDashboard(t_end=1.0, limits=LIMITS, title="live", redraw_interval=0.0,
                         require_interactive=False)
    track = _line(live.layout.ax_track, "track")
    for k in range(3):
        live(*_sample(k))
        assert len(track.get_xdata()) == k + 1
        assert len(live.layout.T_cmd_line.get_ydata()) == k + 1
    np.testing.assert_allclose(track.get_ydata(), [0.0, 0.05, 0.1])  # north
    np.testing.assert_allclose(live.layout.alpha_line.get_ydata(), np.degrees(-0.2))


def test_live_dashboard_as_observer_sees_every_sample(boat):
    live = LiveDashboard(t_end=4.0, limits=LIMITS, redraw_interval=1e6, require_interactive=False)
    result = simulate(boat, np.zeros(6), t_end=4.0, dt=0.05, controller=_stern_kick_schedule(),
                      observer=live, backend="numpy")
    assert live.n_samples == result.sizes["time"]
    assert live.n_redraws == 2  # the first sample, then the last one (redraw throttled)
    np.testing.assert_allclose(_line(live.layout.ax_track, "track").get_xdata(), result["east"].values)


def test_live_dashboard_batched_run_draws_one_ship(boat):
    x0 = np.zeros((2, 6))
    x0[1, 0] = 3.0
    live = LiveDashboard(t_end=10.0, ship=1, redraw_interval=1e6, require_interactive=False)
    result = simulate(boat, x0, t_end=1.0, dt=0.1, controller=_stern_kick_schedule(), observer=live,
                      backend="numpy")
    np.testing.assert_allclose(live.data()["north"], result["north"].isel(ship=1).values)


def test_closed_window_stops_the_run_cleanly(boat):
    live = LiveDashboard(t_end=2.0, redraw_interval=1e6, require_interactive=False)
    live(*_sample(0))
    plt.close(live.fig)
    with pytest.raises(StopSimulation):
        live(*_sample(1))
    closed = LiveDashboard(t_end=2.0, require_interactive=False)
    closed.close()
    result = simulate(boat, np.zeros(6), t_end=2.0, dt=0.05, controller=_stern_kick_schedule(),
                      observer=closed, backend="numpy")
    assert result.attrs["stopped_early"] == 1
    assert result.sizes["time"] == 1  # the result gathered so far is kept


def test_live_on_agg_needs_interactive_backend():
    with pytest.raises(ConfigError) as info:
        LiveDashboard(t_end=1.0)
    message = str(info.value)
    assert "'agg'" in message and "--live" in message and "\n" not in message


def test_live_realtime_pacing():
    live = LiveDashboard(t_end=1.0, realtime=10.0, redraw_interval=1e6, require_interactive=False)
    import time

    start = time.perf_counter()
    for k in range(4):  # 0.3 s of simulated time at 10× → at least 0.03 s of wall time
        live(*_sample(k))
    assert time.perf_counter() - start >= 0.03


def test_style_helpers():
    np.testing.assert_allclose(style.unwrap_deg([3.0, -3.0]), np.degrees([3.0, 2 * np.pi - 3.0]))
    np.testing.assert_allclose(style.align_deg(-np.pi + 0.1, np.pi), np.degrees(np.pi + 0.1))
    assert style.is_interactive_backend("agg") is False
    assert style.is_interactive_backend("TkAgg") is True
    assert style.use_headless_backend().lower() == "agg"


def test_bad_arguments_name_the_field(open_loop):
    n_open = len(plt.get_fignums())
    with pytest.raises(ConfigError, match="outline"):
        dashboard(open_loop, outline=(2.0, -1.0))
    with pytest.raises(ConfigError, match="waypoints"):
        dashboard(open_loop, waypoints=[1.0, 2.0, 3.0])
    with pytest.raises(ConfigError, match="realtime"):
        LiveDashboard(t_end=1.0, realtime=0.0, require_interactive=False)
    assert len(plt.get_fignums()) == n_open  # no figure left behind


def test_import_shipgnc_does_not_import_matplotlib():
    code = "import sys, shipgnc; sys.exit('matplotlib' in sys.modules)"
    assert subprocess.run([sys.executable, "-c", code], check=False).returncode == 0


def _long_turn(n):
    """A steady turn (ψ = r·t wrapped to (−π, π], closed form) with one spike in u and in T."""
    t = np.linspace(0.0, 1000.0, n)
    psi_true = 0.05 * t
    data = {"time": t, "north": np.cos(psi_true), "east": np.sin(psi_true),
            "psi": np.angle(np.exp(1j * psi_true)), "u": np.ones(n), "v": np.zeros(n),
            "r": np.full(n, 0.05), "T": np.sin(t), "alpha": np.cos(3 * t)}
    data["u"][n // 3 + 7] = 9.0  # a one-sample spike must stay drawn
    data["T"][2 * n // 3 + 1] = -5.0
    return data


def test_a_long_series_is_drawn_from_its_envelope_at_the_figures_resolution():
    """decimate_series keeps at most a bounded number of samples, the first and last, every variable's
    minimum and maximum (the one-sample spikes), and the turn's heading unwrapped as ψ = r·t."""
    from shipgnc.viz.series import FIGURE_BUCKETS, decimate_series

    n = 400_001
    data = _long_turn(n)
    thin = decimate_series(data)
    kept = thin["time"].size
    assert kept <= 2 * FIGURE_BUCKETS * (len(data) - 1) + FIGURE_BUCKETS + 2 and kept < n // 10
    assert thin["time"][0] == data["time"][0] and thin["time"][-1] == data["time"][-1]
    for key in ("north", "east", "u", "T", "alpha"):
        assert thin[key].min() == data[key].min() and thin[key].max() == data[key].max(), key
    psi_deg = style.unwrap_deg(thin["psi"])
    np.testing.assert_allclose(psi_deg, np.degrees(0.05 * thin["time"]), atol=1e-6)
    short = {k: v[:1000] for k, v in data.items()}
    assert decimate_series(short)["time"].size == 1000


def test_the_dashboard_draws_a_long_run_from_its_envelope():
    """The dashboard's time lines carry the decimated series (not the whole log): the u line reaches the
    spike, and holds far fewer points than the log."""
    data = _long_turn(400_001)
    fig = dashboard(data)
    try:
        lines = [ln for ax in fig.axes for ln in ax.get_lines() if len(ln.get_xdata()) > 2]
        assert lines and max(len(ln.get_xdata()) for ln in lines) < 100_000
        assert max(float(np.nanmax(ln.get_ydata())) for ln in lines) >= 9.0
    finally:
        plt.close(fig)
