"""The encounter sweep's tracks figure marks the CPA as scored: at ``t_min_range_s`` (kept by the
guidance at every step), not at the nearest sample of the thinned log."""

import math

from shipgnc.study import encounters as E
from shipgnc.study import trafficgen as tg
from shipgnc.viz.encounter_figures import tracks_figure


def test_cpa_marked_at_the_scored_time_and_range():
    members = E.standard_members(["none"], specs=(tg.STANDARD[3],))
    result = E.run_members(members, backend="numpy", keep_results=True, log_every=70)
    fig = tracks_figure(result)
    (line,) = [ln for ln in fig.axes[0].lines if ln.get_marker() == "o"]
    x, y = line.get_data()
    # no avoidance: the own ship sails a straight line, so its position interpolated between
    # 35 s log samples (the CPA at 720 s falls between two; the nearest is 15 s off, 190 m at
    # 12.7 m/s closing) is exact to the autopilot's hold of the course (well under a metre)
    assert abs(math.hypot(x[1] - x[0], y[1] - y[0]) - result.scores["min_range_m"][0]) < 0.5
