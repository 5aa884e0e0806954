"""Direct spiral (Dieudonné 1953; ``docs/trials.md``): steady yaw rate against rudder angle.

A spiral steps the rudder from +δ_max down to −δ_max and back, each angle held until r is
steady. Here every (angle, sweep direction) is one ship of ONE batch: the ship first turns
steadily at the sweep's starting rudder (δ₀ + δ_max for the descending sweep, δ₀ − δ_max for the
ascending one), then its rudder goes to its angle δ_k and is held until r is steady. Coming from
the steady turn at the sweep's start, the ship settles on the branch a slow sweep would still be
on (for a one-degree-of-freedom yaw equation exactly: from above the highest equilibrium r
decreases monotonically to it), so the two directions trace the two branches of a directionally
unstable ship's hysteresis loop at the cost of one run.

**Loop width** [deg]: the rudder range over which the two branches differ (their yaw rates differ
by more than 1 % of the largest steady yaw rate of the sweep). With grid angles δ_lo … δ_hi
differing, each branch's end lies between a differing angle and its neighbour outside; the
estimate δ_hi − δ_lo + (one grid step) is good to ± one step, so the default grid is dense near δ₀.
A stable ship has identical branches: width 0.

**Reverse spiral** (Bech 1966): a yaw-rate autopilot (PI, k_p = 5 L/U, integral time 5 L/U;
L = 20 U s for a model without a length) holds each of a set of yaw rates
r = (U/L)·r′, r′ ∈ ±{0, 0.01, …, 0.15}, and the steady rudder it needs is recorded. It traces the
unstable middle branch a direct spiral jumps over, so the loop width is read off the curve δ(r)
exactly: the largest fall of δ along increasing r (δ's local maximum minus its local minimum;
0 for a monotonic curve). ``loop_width_deg`` is that value when every reverse point settled and it
found a loop, else the direct spiral's grid estimate (both are reported): a reverse grid that does
not reach the loop's turning points sees a monotonic curve.
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.trials.core import (
    SWITCH_REL,
    finite,
    header,
    prepare,
    programme,
    run_parts,
    steady,
    steady_window,
)

#: default rudder offsets from δ₀ [deg] (positive half; mirrored), dense near zero for the loop
GRID = (25.0, 20.0, 15.0, 10.0, 8.0, 6.0, 5.0, 4.0, 3.0, 2.5, 2.0, 1.5, 1.0, 0.5, 0.0)
#: a spiral point is steady when its yaw rate varies less than ``STEADY_ABS + SPIRAL_REL·|r|`` over
#: the steady window (a point of a curve: looser than a turning circle's 2·10⁻⁴)
SPIRAL_REL = 1e-3
#: branches differ where their yaw rates differ by more than this fraction of the largest one
DIFFER = 0.01


def angles(ship, max_deg: float | None = None, grid=None) -> np.ndarray:
    """Rudder angles of the sweep [deg], descending, centred on the trim rudder δ₀."""
    g = np.asarray(GRID if grid is None else grid, dtype=float)
    if max_deg is not None:
        from shipgnc.trials.turning import rudder_angle

        max_deg = rudder_angle(ship, max_deg)
        g = g * (max_deg / g.max())
    half = np.unique(np.abs(g))
    offsets = np.concatenate([-half[::-1], half[1:]] if half[0] == 0 else [-half[::-1], half])
    return (math.degrees(float(ship.delta0[0])) + offsets)[::-1]


def plan(ship, rudder_deg: np.ndarray, *, t_max=None):
    """Two ships per angle: descending sweep (from δ₀ + max), ascending sweep (from δ₀ − max)."""
    d = np.radians(np.asarray(rudder_deg, dtype=float))
    d0 = float(ship.delta0[0])
    top = d0 + np.max(np.abs(d - d0))
    start = np.concatenate([np.full(d.size, top), np.full(d.size, 2 * d0 - top)])
    lv = ship.l_over_v(0)
    if t_max is None:
        t_max = 4000.0 if lv is None else max(2400.0, 200.0 * lv)
    return programme(ship, "spiral", 2 * d.size, delta_a=start, delta_b=np.concatenate([d, d]),
                     switch_when_steady=True, switch_rel=SWITCH_REL, t_max=t_max)


def finished(ship, view, k: int, sl: slice) -> np.ndarray:
    """Done once the approach turn switched and the yaw rate is steady again a window later."""
    w = steady_window(ship)
    t = view.time[k]
    ts = view.programme.t_switch[sl]
    return (t - ts >= w) & steady(view.time, view.state("r")[:, sl], k, w, SPIRAL_REL)


def loop_width(rudder_deg: np.ndarray, r_desc: np.ndarray, r_asc: np.ndarray) -> float:
    """Loop width [deg] from the two branches on the grid (module docstring)."""
    scale = max(float(np.max(np.abs(r_desc))), float(np.max(np.abs(r_asc))), 1e-12)
    differ = np.abs(r_desc - r_asc) > DIFFER * scale
    if not np.any(differ):
        return 0.0
    d = np.sort(np.asarray(rudder_deg)[differ])
    step = float(np.min(np.abs(np.diff(np.sort(rudder_deg)))))
    return float(d[-1] - d[0] + step)


#: nondimensional yaw rates r′ = r L/U of the reverse spiral (positive half; mirrored)
REVERSE_GRID = (0.0, 0.01, 0.02, 0.03, 0.05, 0.075, 0.1, 0.15)


def _l_eff(ship) -> float:
    return ship.length_m if ship.length_m is not None else 20.0 * float(ship.speed[0])


def reverse_rates(ship, grid=None) -> np.ndarray:
    """Yaw rates [rad/s] of the reverse spiral, ascending."""
    g = np.unique(np.abs(np.asarray(REVERSE_GRID if grid is None else grid, dtype=float)))
    g = np.concatenate([-g[::-1], g[1:]] if g[0] == 0 else [-g[::-1], g])
    return g * float(ship.speed[0]) / _l_eff(ship)


def reverse_plan(ship, r_ref: np.ndarray, *, t_max=None):
    """One ship per commanded yaw rate, each under the PI yaw-rate autopilot from t = 0."""
    lu = _l_eff(ship) / float(ship.speed[0])
    kp = 5.0 * lu
    lv = ship.l_over_v(0)
    if t_max is None:
        t_max = 4000.0 if lv is None else max(2400.0, 100.0 * lv)
    return programme(ship, "reverse-spiral", len(r_ref), r_ref=r_ref, kp=kp, ki=kp / (5.0 * lu),
                     t_max=t_max)


def reverse_finished(ship, view, k: int, sl: slice) -> np.ndarray:
    w = steady_window(ship)
    if view.time[k] < 2 * w:
        return np.zeros(sl.stop - sl.start, dtype=bool)
    return (steady(view.time, view.state("r")[:, sl], k, w, SPIRAL_REL)
            & steady(view.time, view.rudder[:, sl], min(k, view.rudder.shape[0] - 1), w, SPIRAL_REL))


def reverse_loop_width(r_ref: np.ndarray, rudder: np.ndarray) -> float:
    """Largest fall of the rudder along increasing yaw rate [same unit as ``rudder``] (0 if none),
    its local maximum and minimum refined by a parabola through the three points about each.

    The overall trend (δ rises with r for a rudder that turns the bow to starboard) is taken
    from the ends of the curve."""
    order = np.argsort(r_ref)
    rr = np.asarray(r_ref, dtype=float)[order]
    d = np.asarray(rudder, dtype=float)[order]
    trend = 1.0 if d[-1] >= d[0] else -1.0
    d = trend * d
    peak = np.maximum.accumulate(d)
    fall = peak - d
    j = int(np.argmax(fall))
    if fall[j] <= 0:
        return 0.0
    i = int(np.argmax(d[:j + 1]))  # the local maximum before the largest fall

    def vertex(k, sign):  # the extreme of the parabola through the three points about k
        if 0 < k < d.size - 1:
            a, b, c = np.polyfit(rr[k - 1:k + 2], d[k - 1:k + 2], 2)
            if sign * a < 0:
                return max(d[k], c - b * b / (4 * a)) if sign > 0 else min(d[k], c - b * b / (4 * a))
        return d[k]

    return float(vertex(i, 1.0) - vertex(j, -1.0))


def collect(ship, hist, rudder_deg, rev_hist=None) -> dict:
    n = len(rudder_deg)
    r = np.degrees(hist.state("r")[-1])
    w = steady_window(ship)
    ok = steady(hist.time, hist.state("r"), hist.time.size - 1, w, SPIRAL_REL)
    r_desc, r_asc = r[:n], r[n:]
    width_direct = loop_width(rudder_deg, r_desc, r_asc)
    out = {"trial": "spiral", **header(ship),
           "rudder_deg": [float(a) for a in rudder_deg],
           "yaw_rate_deg_s": {"descending": [float(v) for v in r_desc],
                              "ascending": [float(v) for v in r_asc]},
           "steady": {"descending": [bool(v) for v in ok[:n]], "ascending": [bool(v) for v in ok[n:]]},
           "loop_width_direct_deg": width_direct}
    width = width_direct
    if rev_hist is not None:
        r_ref = rev_hist.programme.r_ref
        rud = np.degrees(rev_hist.rudder[-1])
        rev_ok = (steady(rev_hist.time, rev_hist.state("r"), rev_hist.time.size - 1, w, SPIRAL_REL)
                  & steady(rev_hist.time, rev_hist.rudder, rev_hist.time.size - 1, w, SPIRAL_REL))
        width_rev = reverse_loop_width(r_ref, rud)
        if width_rev < 1e-3:  # a monotonic curve up to the rudder's settling noise
            width_rev = 0.0
        out["reverse"] = {"yaw_rate_deg_s": [float(v) for v in np.degrees(r_ref)],
                          "rudder_deg": [float(v) for v in rud],
                          "steady": [bool(v) for v in rev_ok], "loop_width_deg": width_rev}
        if bool(np.all(rev_ok)) and width_rev > 0:
            width = width_rev
        out["_reverse_history"] = rev_hist
    out.update({"loop_width_deg": width,
                "loop_height_deg_s": finite(np.max(np.abs(r_desc - r_asc))) if width > 0 else 0.0,
                "stable": width == 0.0, "_history": hist})
    return out


def parts(ship, max_deg=None, grid=None, reverse=True):
    """The (programme, finished) parts of a spiral: direct, then (optionally) reverse."""
    a = angles(ship, max_deg, grid)
    out = [(plan(ship, a), finished)]
    if reverse:
        out.append((reverse_plan(ship, reverse_rates(ship)), reverse_finished))
    return a, out


def spiral(vessel=None, max_deg: float | None = None, *, grid=None, reverse: bool = True,
           speed_mps=None, ship=None, **kw) -> dict:
    """The direct spiral of ``vessel`` (both sweep directions) and the reverse spiral, one batch."""
    ship = ship if ship is not None else prepare(vessel, speed_mps, **kw)
    a, ps = parts(ship, max_deg, grid, reverse)
    hists = run_parts(ship, ps)
    return collect(ship, hists[0], a, hists[1] if reverse else None)
