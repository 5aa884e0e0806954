"""Pull-out (Bech 1966; ``docs/trials.md``): from a steady turn, the rudder back to δ₀.

Each side is one ship of one batch: rudder δ₀ ± δ until the turn is steady (the yaw rate varies
less than 2·10⁻⁴ |r| over max(60 s, 3 L/V)), then δ₀, held until r is steady again. A
directionally stable ship's yaw rate decays to zero from both sides; a directionally unstable
one keeps a residual yaw rate, of opposite signs for the two sides, which bounds the height of
its spiral loop.
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.trials.core import SIDES, header, prepare, programme, run_parts, steady, steady_window
from shipgnc.trials.spiral import finished  # the same two-phase programme: steady, switch, steady

#: a residual yaw rate below this [deg/s] counts as zero (the steady test's own resolution)
ZERO_DEG_S = 1e-3


def plan(ship, rudder_deg: float, sides=("starboard", "port"), *, t_max=None):
    signs = np.array([SIDES[s] for s in sides])
    d0 = float(ship.delta0[0])
    lv = ship.l_over_v(0)
    if t_max is None:
        t_max = 4000.0 if lv is None else max(2400.0, 200.0 * lv)
    return programme(ship, "pull-out", len(sides), delta_a=d0 + signs * math.radians(rudder_deg),
                     delta_b=d0, switch_when_steady=True, t_max=t_max)


def collect(ship, hist, rudder_deg, sides=("starboard", "port")) -> dict:
    r = hist.state("r")
    ts = hist.programme.t_switch
    ok = steady(hist.time, r, hist.time.size - 1, steady_window(ship))
    before, after, per = {}, {}, {}
    for j, side in enumerate(sides):
        k = round(ts[j] / (hist.time[1] - hist.time[0])) if np.isfinite(ts[j]) else None
        before[side] = None if k is None else float(np.degrees(r[min(k, r.shape[0] - 1), j]))
        after[side] = float(np.degrees(r[-1, j]))
        per[side] = {"turn_yaw_rate_deg_s": before[side], "residual_yaw_rate_deg_s": after[side],
                     "rudder_returned_at_s": None if k is None else float(ts[j]),
                     "steady": bool(ok[j])}
    stable = all(abs(v) < ZERO_DEG_S for v in after.values())
    return {"trial": "pull-out", **header(ship), "rudder_deg": rudder_deg,
            "residual_yaw_rate_deg_s": after, "turn_yaw_rate_deg_s": before,
            "stable": stable, "sides": per, "_history": hist}


def pull_out(vessel=None, rudder_deg: float | None = None, *, sides=("starboard", "port"),
             speed_mps=None, ship=None, **kw) -> dict:
    """The pull-out from a steady turn at δ₀ ± ``rudder_deg`` (default: the turning rudder)."""
    from shipgnc.trials.turning import rudder_angle

    ship = ship if ship is not None else prepare(vessel, speed_mps, **kw)
    rudder_deg = rudder_angle(ship, rudder_deg)
    (hist,) = run_parts(ship, [(plan(ship, rudder_deg, sides), finished)])
    return collect(ship, hist, rudder_deg, sides)
