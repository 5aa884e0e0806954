"""Figures a report can use: the sweep's panels are titled in words and their axes carry the
metric's unit (from its name, the project's rule: a metric named ``*_deg`` is in degrees), the
course comparison keeps its labels inside the figure and names its one controller by its law, and
the figures of every built-in scenario, of ``shipgnc trial all`` and of ``shipgnc sweep``, opened
as matplotlib artists, label every axis with a quantity and its unit, have titles and name their
curves in a legend."""

from __future__ import annotations

import re
from pathlib import Path

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


#: how each built-in scenario is shortened for the figure check (the figures' kinds, labels and
#: legends do not depend on the length of the run): a simulated scenario runs ``simulation.t_end``
#: = 30 s unless listed; Monte Carlo scenarios run a few members; routes a coarser level-set grid;
#: every simulation on the numpy loop (no compilation on a cold kernel cache)
SHORT = {
    "mariner-compare": ["simulation.t_end=600"],
    "mariner-fl-lookahead": ["simulation.t_end=600"],
    "mariner-fl-paper": ["simulation.t_end=600"],
    "mariner-los-ekf": ["simulation.t_end=600"],
    "mariner-los-fl": ["simulation.t_end=600"],
    "mariner-lqr": ["simulation.t_end=600"],
    "mariner-cst-heading": ["simulation.t_end=100"],
    "mariner-montecarlo": ["simulation.t_end=600", "montecarlo.runs=8"],
    "mariner-montecarlo-wide": ["simulation.t_end=600", "montecarlo.runs=8"],
    "cybership-calm": ["simulation.t_end=60"],
    "catamaran-montecarlo": ["simulation.t_end=30", "case.options.n=20"],
    "zermelo-paper": ["route.grid=0.2"],
    "zermelo-shoal": ["route.grid=0.2"],
    "zermelo-vortex": [],
    "zermelo-sail": ["sail.backend=numpy"],
    "zermelo-sail-mariner": ["sail.dt=1", "sail.backend=numpy"],
}
#: a label's quantity and its unit in brackets: "heading ψ [deg]"
UNIT = re.compile(r"\w.*\[[^\]]+\]")
#: the unitless quantities figures may draw, with what they count
UNITLESS = {"ships": "Monte Carlo members in a histogram bin",
            "members": "sweep members in a histogram bin"}


def _short(name: str) -> list[str]:
    items = SHORT.get(name, ["simulation.t_end=30"])
    if any(item.startswith("simulation.") for item in items):
        items = [*items, "simulation.backend=numpy"]
    return items


def _label(ax, axis: str) -> str:
    """The axis' label, or that of an axis it shares this axis with (a shared axis is labelled
    once, on the outer row or column)."""
    group = ax.get_shared_x_axes() if axis == "x" else ax.get_shared_y_axes()
    for other in [ax, *group.get_siblings(ax)]:
        text = other.get_xlabel() if axis == "x" else other.get_ylabel()
        if text:
            return text
    return ""


def _problems(name: str, fig) -> list[str]:
    """What keeps ``fig`` from a report: every axis that draws data has an x and a y label (its
    own or its shared row's / column's) naming a quantity with its unit in brackets (or a
    documented unitless count, :data:`UNITLESS`), a title (its own, any of the three positions, or
    the figure's), and an axis drawing several curves a legend in the figure naming them."""
    suptitle = fig._suptitle.get_text() if fig._suptitle is not None else ""
    legends = [*fig.legends, *(ax.get_legend() for ax in fig.axes if ax.get_legend() is not None)]
    names = [t.get_text() for legend in legends for t in legend.get_texts()]
    bad = []
    if any(not n.strip() or n.startswith("_") for n in names):
        bad.append(f"{name}: a legend entry without a name: {names}")
    for ax in fig.axes:
        if not ax.get_visible() or not (ax.lines or ax.collections or ax.patches or ax.images):
            continue
        titles = [ax.get_title(loc=loc) for loc in ("left", "center", "right")]
        where = f"panel {next((t for t in titles if t), '')!r} of {name}"
        for axis in ("x", "y"):
            text = _label(ax, axis)
            if not (UNIT.search(text) or text in UNITLESS):
                bad.append(f"{where}: {axis} label {text!r}")
        if not any(titles) and not suptitle:
            bad.append(f"{where}: no title")
        curves = [line for line in ax.lines if len(line.get_xdata()) > 2]
        if len(curves) >= 2 and not legends:
            bad.append(f"{where}: {len(curves)} curves and no legend")
    return bad


@pytest.fixture
def drawn(monkeypatch):
    """The figures a command saves, as matplotlib figures (drawn in this process)."""
    from matplotlib.figure import Figure

    monkeypatch.setenv("SHIPGNC_FIGURE_PROCESS", "0")
    figures = []
    save = Figure.savefig

    def keep(self, path, *args, **kwargs):
        figures.append((Path(str(path)).name, self))
        return save(self, path, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", keep)
    return figures


def test_the_figure_check_covers_every_built_in_scenario():
    from shipgnc.scenarios.registry import builtin_names

    assert set(SHORT) <= set(builtin_names())
    assert len(builtin_names()) == len(set(builtin_names()))


def _built_in_names() -> list[str]:
    from shipgnc.scenarios.registry import builtin_names

    return builtin_names()


@pytest.mark.parametrize("scenario", _built_in_names())
def test_every_built_in_scenario_s_figures_are_ready_for_a_report(scenario, tmp_path, drawn):
    """``shipgnc run`` of every built-in scenario (shortened, :data:`SHORT`): its figures,
    opened as matplotlib artists, pass :func:`_problems`."""
    from typer.testing import CliRunner

    from shipgnc.cli import app

    sets = [arg for item in _short(scenario) for arg in ("--set", item)]
    out = CliRunner().invoke(app, ["run", scenario, *sets, "--out", str(tmp_path / "run")])
    assert out.exit_code == 0, out.output
    assert drawn, "no figure"
    bad = [p for name, fig in drawn for p in _problems(name, fig)]
    assert not bad, "\n".join(bad)


def test_trial_figures_are_ready_for_a_report(tmp_path, drawn):
    """``shipgnc trial all``'s figures (turning circle, zig-zags, spiral, pull-out) pass
    :func:`_problems`."""
    from typer.testing import CliRunner

    from shipgnc.cli import app

    out = CliRunner().invoke(app, ["trial", "all", "--vessel", "mariner-cst", "--out",
                                   str(tmp_path / "trials")])
    assert out.exit_code == 0, out.output
    assert {name for name, _ in drawn} >= {"turning_circle.png", "zigzag_10_10.png", "spiral.png",
                                           "pull_out.png"}
    bad = [p for name, fig in drawn for p in _problems(name, fig)]
    assert not bad, "\n".join(bad)


def test_sweep_figure_is_ready_for_a_report(tmp_path, drawn):
    """``shipgnc sweep``'s figure (a Monte Carlo over the initial heading) passes
    :func:`_problems`."""
    from typer.testing import CliRunner

    from shipgnc.cli import app

    out = CliRunner().invoke(app, ["sweep", "boat-autopilot", "--mc", "4", "--perturb",
                                   "psi_deg=uniform:-10,10", "--set", "simulation.t_end=30",
                                   "--out", str(tmp_path / "sweep")])
    assert out.exit_code == 0, out.output
    assert [name for name, _ in drawn] == ["sweep.png"]
    bad = [p for name, fig in drawn for p in _problems(name, fig)]
    assert not bad, "\n".join(bad)
