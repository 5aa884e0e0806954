"""Route figures (note 002-2.9.6): every extremal drawn with the global one highlighted,
isochrones labelled with their times, the current arrows with a scale key, titles from the data."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.quiver import QuiverKey

from shipgnc.environment.fields import LambOseenVortex, shear
from shipgnc.routing.router import solve_route
from shipgnc.units import KNOT, NAUTICAL_MILE
from shipgnc.viz.route_figures import route_figure

NM = NAUTICAL_MILE

H = 3600.0
A, B = np.array([-1.86, 3.66]) * NM, np.zeros(2)


@pytest.fixture
def drawn(monkeypatch):
    """The figures route_figure draws, kept open."""
    figures = []
    monkeypatch.setattr(plt, "close", lambda fig=None: figures.append(fig))
    return figures


def test_vortex_figure_draws_every_extremal(tmp_path, drawn):
    """Note 002-F2: three extremals reach B within 30 h; all three are drawn, the global one
    (6.519975 h) thicker, the conjugate point of the third starred."""
    field = LambOseenVortex(2 * NM**2 / H, 0.5 * NM, (-0.93 * NM, 1.83 * NM))
    res = solve_route(field, 0.5 * KNOT, A, B, method="pmp", horizon=30 * H)
    route_figure(res, tmp_path / "v.png", nautical=True, title="vortex")
    ax = drawn[0].axes[0]
    lines = [ln for ln in ax.get_lines() if ln.get_label().startswith(("global optimum", "extremal "))]
    assert len(lines) == len(res.extremals) == 3
    widths = sorted(ln.get_linewidth() for ln in lines)
    assert widths[-1] > widths[0]  # the global one highlighted
    assert any(ln.get_label().startswith("conjugate point") for ln in ax.get_lines())
    assert any(isinstance(a, QuiverKey) and "kn" in a.text.get_text() for a in ax.get_children())
    assert ax.get_title(loc="left").startswith("vortex: ") and "3 extremals" in ax.get_title(loc="left")


def test_isochrones_carry_their_times(tmp_path, drawn):
    """The document's case with the level set: hourly fronts up to the 10.9 h arrival, each labelled
    in hours (the route's unit)."""
    res = solve_route(shear(-0.5 / H), 0.5 * KNOT, A, B, method="auto", horizon=30 * H,
                      grid_spacing=0.08 * NM)
    route_figure(res, tmp_path / "p.png", nautical=True)
    ax = drawn[0].axes[0]
    labels = {t.get_text() for t in ax.texts}
    hourly = {f"{k} h" for k in range(1, 11)}
    assert len(labels & hourly) >= 8  # a front or two may lie outside the chart
    assert any(isinstance(a, QuiverKey) for a in ax.get_children())
    assert "10.9 h" in ax.get_title(loc="left")
