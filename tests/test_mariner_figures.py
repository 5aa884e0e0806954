"""Document 000's Figs. 3–5 draw every run, frame the bounded ones and say so:
an unbounded run (the literal FL, 18 nm off) must not swamp the axes of the readable runs."""

from __future__ import annotations

import numpy as np
import pytest

from shipgnc.units import MINUTE, NAUTICAL_MILE
from shipgnc.viz import path_tracking as pt

NM = NAUTICAL_MILE
WAYPOINTS = np.array([[0, 0], [10, 0], [12, 4], [18, 12]]) * NM


def _run(offset_nm: float, end_nm: float, n: int = 200, delta_deg: float = 5.0):
    """A run on leg 1 from ``offset_nm`` east to ``end_nm`` east while sailing 10 nm north."""
    t = np.linspace(0.0, 100 * MINUTE, n)
    y = np.linspace(offset_nm, end_nm, n) * NM
    return {"time": t, "north": np.linspace(0, 10, n) * NM, "east": y, "psi": np.zeros(n),
            "heading_error": np.zeros(n), "cross_track_error": y, "leg": np.zeros(n),
            "delta": np.radians(np.full(n, delta_deg))}


SERIES = {"lqr": _run(-1.5, 0.0), "los_fl": _run(-1.5, 0.05),
          "fl_paper": _run(-1.5, -18.0, delta_deg=35.0), "fl_lookahead": _run(-1.5, 0.016)}


def _lines(fig, name):
    return [line for ax in fig.axes for line in ax.get_lines()
            if (line.get_label() or "").startswith(name)]


def test_bound_is_the_stable_bound():
    assert pt.split_bounded(SERIES) == (["lqr", "los_fl", "fl_lookahead"], ["fl_paper"])
    assert pt.is_bounded(_run(-4.0, 7.9))  # 2|y_r(0)| = 8 nm when the start is beyond 1.5 nm
    assert not pt.is_bounded(_run(-1.0, 3.1))


def test_tracks_every_run_drawn_and_framed_by_the_bounded_ones():
    fig = pt.tracks_figure(SERIES, WAYPOINTS)
    main, whole = fig.axes[0], fig.axes[1]
    for name in SERIES:  # each run in the framed panel and in the whole view
        assert len([ln for ln in main.get_lines() if ln.get_label().startswith(name)]) == 1, name
        assert len([ln for ln in whole.get_lines() if ln.get_label() == name]) == 1, name
    assert any("leaves the frame" in ln.get_label() for ln in _lines(fig, "fl_paper"))
    low, high = main.get_xlim()
    assert low > -3.0 and high >= 12.0  # the path and the 1.5 nm start, not 18 nm west
    assert whole.get_xlim()[0] < -17.0  # the whole view shows the diverging track
    assert "unbounded: fl_paper" in fig._suptitle.get_text()
    assert "4 runs" in fig._suptitle.get_text()


def test_tracks_without_unbounded_runs_have_one_panel():
    bounded = {k: v for k, v in SERIES.items() if k != "fl_paper"}
    fig = pt.tracks_figure(bounded, WAYPOINTS)
    assert len(fig.axes) == 1 and "3 runs" in fig._suptitle.get_text()


def test_rudder_unbounded_run_in_its_own_panel():
    fig = pt.rudder_figure(SERIES, rudder_limit_deg=35.0)
    top, bottom = fig.axes[0], fig.axes[1]
    top_names = {ln.get_label() for ln in top.get_lines() if not ln.get_label().startswith("_")}
    assert top_names == {"lqr", "los_fl", "fl_lookahead"}
    (label,) = [ln.get_label() for ln in bottom.get_lines() if not ln.get_label().startswith("_")]
    assert label.startswith("fl_paper") and "100 %" in label  # hard over in this synthetic run
    assert "(below)" in fig._suptitle.get_text()


def test_heading_axes_limits_from_the_bounded_runs():
    fig = pt.heading_figure(SERIES)
    for name in SERIES:  # three panels each
        assert sum(len([ln for ln in ax.get_lines() if ln.get_color() == pt._color(name, i)])
                   for ax in fig.axes for i in [list(SERIES).index(name)]) == 3, name
    low, high = fig.axes[2].get_ylim()  # cross-track panel [nm]
    assert low > -2.0 and high < 1.0
    assert low == pytest.approx(-1.5 - pt.MARGIN * 1.55, abs=0.01)
