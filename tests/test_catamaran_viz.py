"""Document 004 figure functions return matplotlib Figures (no pyplot) from result Datasets."""

from __future__ import annotations

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
