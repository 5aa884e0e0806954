"""Document 004 figure functions return matplotlib Figures (no pyplot) from result Datasets."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from shipgnc.cases import catamaran as C
from shipgnc.models.catamaran import Catamaran, preset
from shipgnc.viz import catamaran as V


def test_figures_from_short_runs():
    ds = C.turn("si", t_end=20.0)["law21"].run()
    heading = C.heading("si", 21, 0.1, 0.02, t_end=20.0)
    hd = heading.run()
    figs = [V.fig_phi3(ds, Catamaran.from_preset("si")), V.fig_yaw_rate_laws({"law (21)": ds}, reference=0.08),
            V.fig_turn(ds), V.fig_transients({"a": ds}), V.fig_sine(ds), V.fig_heading(hd, 0.1),
            V.fig_turning_characteristic({"si": preset("si")})]
    assert all(isinstance(f, Figure) for f in figs)


def _fake_runs(keys, n=50):
    import xarray as xr

    t = np.linspace(0.0, 100.0, n)
    out = {}
    for i, k in enumerate(keys):
        data = {s: ("time", np.sin(t / (10.0 + i)) * 0.01 * (i + 1)) for s in V.STATE_ORDER}
        out[k] = xr.Dataset(data, coords={"time": t})
    return out


def _lines(fig) -> int:
    """Data lines drawn (reference lines: axhline/axvline are excluded by their 2-point x data)."""
    return sum(1 for ax in fig.axes for line in ax.get_lines() if len(line.get_xdata()) > 2)


def test_every_run_is_drawn_and_titles_come_from_the_data():
    compare = _fake_runs([f"{c}/{k}" for c in ("S3", "S4") for k in ("law20", "law21", "place",
                                                                      "pi_design", "pi")]
                         + ["S7/law21", "S7/place", "S7/lqr"])
    figs = dict((name, fig) for fig, name in V.scenario_figures(
        compare, {"builder": "compare", "model_note": "note", "heading_target": 0.8}, "catamaran-compare"))
    assert _lines(figs["yaw_rate.png"]) == 10 and _lines(figs["heading.png"]) == 3
    actuator = _fake_runs(["ideal", "T2_k1", "T3_k1", "T1_k1", "T2_k0.8", "T2_k1.2"])
    (fig, _), = V.scenario_figures(actuator, {"builder": "actuator", "model_note": "printed Coriolis "
                                              "sign (reproduction)"}, "catamaran-actuator")
    assert _lines(fig) == 6
    title = fig.axes[0].get_title()
    assert "Figs. 2–3" not in title and "T2_k1.2" in title and "reproduction" in title
    steps = _fake_runs(["law20@0.008", "law21@0.008", "law20@0.00072", "law21@0.00072"])
    figs = dict((name, fig) for fig, name in V.scenario_figures(
        steps, {"builder": "steps", "preset": "paper", "model_note": "paper units (unit-inconsistent)"},
        "catamaran-steps"))
    assert _lines(figs["fig2_3_yaw_rate.png"]) == 4
    fixed = _fake_runs(["fixed", "law20_same_angle", "law20@0.00072"])
    (fig, _), = V.scenario_figures(fixed, {"builder": "fixed-angle"}, "catamaran-fixed-angle")
    assert _lines(fig) == 3 * 3  # u, v, r panels
    many = _fake_runs([f"run{i}" for i in range(25)])
    assert _lines(V.fig_yaw_rate_laws(many)) == 25


def test_turn_figure_frames_the_transient_and_names_the_law():
    runs = _fake_runs(["law20", "law21"])
    figs = dict((name, fig) for fig, name in V.scenario_figures(runs, {"builder": "turn", "omega": 0.04},
                                                                 "catamaran-turn"))
    fig = figs["turn.png"]
    assert "law (21)" in fig._suptitle.get_text()
    assert "ω* = 0.04 rad/s" in fig._suptitle.get_text()  # the run's reference, not the default's
    zoom = [ax for ax in fig.axes if "transient" in ax.get_title()]
    assert zoom and all(ax.get_xlim()[1] <= 65.0 for ax in zoom)
    assert _lines(figs["yaw_rate.png"]) == 2


def test_montecarlo_figure_from_a_batch():
    ds = C.montecarlo(n=8, seed=1, t_end=20.0).run()
    bands = V.batch_bands(ds)
    assert bands["ships"] == 8 and bands["r"].shape == (5, ds.time.size)
    (fig, name), = V.scenario_figures({"montecarlo": bands}, {"builder": "montecarlo", "omega": 0.06},
                                      "catamaran-montecarlo")
    assert name == "montecarlo.png" and "8 ships" in fig._suptitle.get_text()


def test_sine_and_heading_name_the_law_and_draw_every_run():
    """A scenario of controllers may run another law or several: the figure's title names the
    law that ran (not the document's (21)), and a second run gets a figure of every run."""
    runs = _fake_runs(["mine", "law21"])
    figs = dict((name, fig) for fig, name in V.scenario_figures(
        runs, {"builder": "sine", "laws": {"mine": 20, "law21": 21}}, "catamaran-sine"))
    assert "law (20)" in figs["fig7_sine.png"]._suptitle.get_text()
    assert _lines(figs["yaw_rate.png"]) >= 2
    figs = dict((name, fig) for fig, name in V.scenario_figures(
        runs, {"builder": "heading", "heading_target": 0.8, "laws": {"mine": 20}}, "catamaran-heading"))
    assert "law (20)" in figs["fig8_heading.png"]._suptitle.get_text()
    assert _lines(figs["heading.png"]) == 2
