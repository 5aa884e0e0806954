"""Figures a report can use: the sweep's panels are titled in words and their axes carry the
metric's unit (from its name, the project's rule: a metric named ``*_deg`` is in degrees), and the
course comparison keeps its labels inside the figure and names its one controller by its law."""

from __future__ import annotations

import re

import numpy as np
import pytest
import xarray as xr

from shipgnc.units import axis_label, metric_label


@pytest.mark.parametrize(("name", "title", "unit"), [
    ("settling_time_s", "settling time", "s"),
    ("heading_rmse_deg", "heading rmse", "deg"),
    ("rudder_rate_rms_deg_s", "rudder rate rms", "deg/s"),
    ("crosstrack_rms_after_leg1_nm", "crosstrack rms after leg1", "nm"),
    ("final_speed_mps", "final speed", "m/s"),
    ("max_thrust_n", "max thrust", "N"),
    ("zero_dynamics_pole_per_min", "zero dynamics pole", "1/min"),
    ("settle_time_min", "settle time", "min"),
    ("position_est_rmse_m", "position est rmse", "m"),
    ("yaw_rate_overshoot_pct", "yaw rate overshoot", "%"),
    ("final_yaw_rate_rad_s", "final yaw rate", "rad/s"),
    ("waypoints_reached", "waypoints reached", None),
    ("settled_fraction", "settled fraction", None),
    ("psi_E", "psi E", None),
])
def test_a_metric_name_gives_its_title_and_unit(name, title, unit):
    assert metric_label(name) == (title, unit)
    assert axis_label(name) == (f"{title} [{unit}]" if unit else title)


def _study(grid: bool):
    rng = np.random.default_rng(0)
    dims = ("controller.omega_ref", "member") if grid else ("member",)
    shape = (3, 8) if grid else (8,)
    data = {k: (dims, rng.normal(10.0, 1.0, shape)) for k in
            ("settling_time_s", "heading_rmse_deg", "max_thrust_n", "waypoints_reached")}
    data["diverged"] = (dims, np.zeros(shape))
    coords = {"member": np.arange(8)}
    if grid:
        coords["controller.omega_ref"] = [0.5, 1.0, 2.0]
    return xr.Dataset(data, coords=coords, attrs={"scenario": "boat-autopilot"})


@pytest.mark.parametrize("grid", [False, True])
def test_sweep_panels_have_titles_in_words_and_units(tmp_path, monkeypatch, grid):
    from matplotlib.figure import Figure

    from shipgnc.viz.study_summary import spread_figure

    figures = []
    monkeypatch.setattr(Figure, "savefig", lambda self, *a, **k: figures.append(self))
    spread_figure(_study(grid), tmp_path / "sweep.png")
    axes = [ax for ax in figures[0].axes if ax.get_visible()]
    assert len(axes) == 4
    for ax, name in zip(axes, ("settling_time_s", "heading_rmse_deg", "max_thrust_n",
                               "waypoints_reached"), strict=True):
        assert "_" not in ax.get_title() and ax.get_title().lower() == metric_label(name)[0]
        value_label = ax.get_ylabel() if grid else ax.get_xlabel()
        assert value_label == axis_label(name)
        other = ax.get_xlabel() if grid else ax.get_ylabel()
        assert other == ("controller.omega_ref" if grid else "members")


def test_course_comparison_keeps_its_labels_inside_and_names_the_law():
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from shipgnc.scenarios.registry import load_scenario
    from shipgnc.viz.comparison import course_comparison
    from shipgnc.viz.run_files import controller_title

    title = controller_title(load_scenario("mariner-cst-heading").controller)
    assert title == "course autopilot pd: Kp = 1, Kd = 40"
    t = np.linspace(0.0, 100.0, 201)
    series = {title: {"time": t, "u": np.full_like(t, 7.7), "psi": np.radians(30.0) * (1 - np.exp(-t / 20)),
                      "psi_d": np.full_like(t, np.radians(30.0)), "delta": np.radians(5.0) * np.exp(-t / 10)}}
    fig = course_comparison(series, title="mariner-cst-heading", rudder_limit_deg=40.0)
    FigureCanvasAgg(fig).draw()
    renderer = fig.canvas.get_renderer()
    box = fig.bbox
    labels = [ax.yaxis.label for ax in fig.axes if ax.get_ylabel()]
    assert [label.get_text() for label in labels] == ["u [m/s]", "ψ [deg]", "δ [deg]"]
    for text in [*labels, *(ax.title for ax in fig.axes if ax.get_title())]:
        extent = text.get_window_extent(renderer)
        assert extent.x0 >= box.x0 and extent.x1 <= box.x1 and extent.y1 <= box.y1, text.get_text()


#: one built-in scenario per kind of figure a run writes (dashboard, stern-kick close-up, course
#: comparison of one and of several controllers, path tracking, catamaran), shortened
FIGURE_SCENARIOS = [("boat-stern-kick", 20), ("boat-los-gnss", 30), ("cybership-calm", 60),
                    ("mariner-cst-heading", 100), ("mariner-lqr", 600), ("catamaran-turn", 30),
                    ("catamaran-compare", 30)]
UNIT = re.compile(r"\[[^\]]+\]")


def _label(ax, axis: str) -> str:
    """The axis' label, or that of an axis it shares this axis with (a shared axis is labelled
    once, on the outer row or column)."""
    group = ax.get_shared_x_axes() if axis == "x" else ax.get_shared_y_axes()
    for other in [ax, *group.get_siblings(ax)]:
        text = other.get_xlabel() if axis == "x" else other.get_ylabel()
        if text:
            return text
    return ""


@pytest.mark.parametrize(("scenario", "t_end"), FIGURE_SCENARIOS)
def test_every_axis_of_a_run_s_figures_has_labels_with_units(scenario, t_end, tmp_path, monkeypatch):
    """The figures ``shipgnc run`` writes, opened as matplotlib artists: every axis that draws data
    has an x and a y label (its own or its shared row's / column's), each with a unit in
    brackets (every quantity these figures draw has one: time, position, speed, angle, rate,
    force)."""
    import shipgnc.viz.dashboard as dashboard
    from shipgnc.scenarios.runner import run_scenario
    from shipgnc.viz.run_files import write_outputs

    monkeypatch.setenv("SHIPGNC_FIGURE_PROCESS", "0")  # drawn here, so that they can be opened
    figures = []
    save = dashboard.save_figure
    monkeypatch.setattr(dashboard, "save_figure",
                        lambda fig, path, *a, **k: figures.append((path.name, fig)) or save(fig, path, *a, **k))
    run = run_scenario(scenario, overrides=[f"simulation.t_end={t_end}"])
    write_outputs(run, tmp_path / "out", figures=True)
    assert figures
    bad = []
    for name, fig in figures:
        for ax in fig.axes:
            if not ax.get_visible() or not (ax.lines or ax.collections or ax.patches or ax.images):
                continue
            for axis in ("x", "y"):
                text = _label(ax, axis)
                if not UNIT.search(text):
                    bad.append(f"{name}: {axis} label {text!r} (panel {ax.get_title()!r})")
    assert not bad, "\n".join(bad)
