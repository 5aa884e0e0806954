"""Stopping: full astern from the test speed (IMO MSC.137(76) §4.3; ``docs/trials.md``).

At execution the propeller command goes to full astern (``model.full_astern``) with the rudder
held at δ₀. The ship is dead in the water when its surge speed u first reaches zero; then

* **track reach**: the distance travelled along the path, **head reach**: along the original
  course (north), **lateral deviation**: across it (east), **time** from execution.

A vessel without propulsion that can go astern (``can_reverse`` False) gets a one-line error
instead of an invented result (exit code 2 on the command line).
"""

from __future__ import annotations

import numpy as np

from shipgnc.errors import ConfigError
from shipgnc.trials.core import at, crossing, header, prepare, programme, run_parts, track_length


def check(ship) -> None:
    if not ship.can_reverse or ship.full_astern is None or ship.n_inputs < 2:
        raise ConfigError(f"trial stopping: vessel {ship.name} has no propulsion that can go full "
                          "astern (can_reverse is false), so it has no stopping trial")


def plan(ship, *, t_max=None):
    check(ship)
    lv = ship.l_over_v(0)
    if t_max is None:
        t_max = 3600.0 if lv is None else max(1800.0, 150.0 * lv)
    return programme(ship, "stopping", 1, astern=True, t_max=t_max)


def finished(ship, view, k: int, sl: slice) -> np.ndarray:
    return view.state("u")[k, sl] <= 0.0


def collect(ship, hist) -> dict:
    north, east = hist.state("north")[:, 0], hist.state("east")[:, 0]
    u = hist.state("u")[:, 0]
    k = crossing(-u, 0.0)
    dist = track_length(north, east)
    out = {"trial": "stopping", **header(ship), "full_astern": float(ship.full_astern),
           "track_reach_m": None if k is None else at(dist, k),
           "head_reach_m": None if k is None else at(north, k),
           "lateral_deviation_m": None if k is None else at(east, k),
           "time_s": None if k is None else at(hist.time, k),
           "_history": hist}
    return out


def stopping(vessel=None, *, speed_mps=None, ship=None, **kw) -> dict:
    """The full-astern stopping trial (module docstring)."""
    ship = ship if ship is not None else prepare(vessel, speed_mps, **kw)
    (hist,) = run_parts(ship, [(plan(ship), finished)])
    return collect(ship, hist)
