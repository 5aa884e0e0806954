"""Turning circle (IMO MSC.137(76) §4.1; ``docs/trials.md``).

Rudder to δ₀ ± δ (35° or the maximum permissible) at execution, held. With the original course
along north and the execute position at the origin, for a turn to side s (+1 starboard, −1 port):

* **advance**: the north coordinate where the heading has changed 90° (s·Δψ = 90°);
* **transfer**: s·east at the 90° change; **tactical diameter**: s·east at the 180° change;
* **steady turning radius** U/|r| and **steady speed** U once r is steady (the yaw rate varies
  less than 2·10⁻⁴ |r| over max(60 s, 3 L/V)); **speed loss** 100·(1 − U_steady/V) %.

Positions are those of the body-fixed origin (the model's north/east state; midship for the
catalogue's Mariner and KVLCC2 — MSC.137(76) §4.2 measures the midship point), not of the
centre of gravity; interpolated linearly in the heading.
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.trials.core import (
    SIDES,
    at,
    crossing,
    finite,
    header,
    prepare,
    programme,
    run_parts,
    steady,
    steady_window,
)


def rudder_angle(ship, rudder_deg: float | None) -> float:
    """The turning rudder [deg]: the given one, else 35° or the maximum permissible if smaller."""
    from shipgnc.errors import require

    if rudder_deg is None:
        return min(35.0, math.degrees(ship.max_rudder))
    require(math.isfinite(rudder_deg) and 0 < rudder_deg <= math.degrees(ship.max_rudder) + 1e-9,
            "--rudder-deg", rudder_deg,
            f"must be in (0, {math.degrees(ship.max_rudder):g}] deg (the rudder's limit)")
    return float(rudder_deg)


def plan(ship, rudder_deg: float, sides=("starboard", "port"), *, t_max=None):
    """One ship per (speed, side), speed-major: rudder δ₀ + s·δ from t = 0."""
    n_speeds = ship.x0.shape[0]
    signs = np.tile(np.array([SIDES[s] for s in sides]), n_speeds)
    idx = np.repeat(np.arange(n_speeds), len(sides))
    lv = ship.l_over_v(0)
    if t_max is None:
        t_max = 3600.0 if lv is None else max(1800.0, 150.0 * lv)
    d = ship.delta0[idx] + signs * math.radians(rudder_deg)
    return programme(ship, "turning", signs.size, speed_index=idx, delta_a=d, delta_b=d, t_max=t_max)


def finished(ship, view, k: int, sl: slice) -> np.ndarray:
    """Done after a full 360° change of heading with a steady yaw rate."""
    psi = view.state("psi")[k, sl] - view.x[0, sl, view.index["psi"]]
    turned = np.abs(psi) >= 2 * math.pi
    return turned & steady(view.time, view.state("r")[:, sl], k, steady_window(ship))


def analyse(ship, hist, i: int, side: str) -> dict:
    s = SIDES[side]
    idx = hist.index
    psi = s * (hist.state("psi")[:, i] - hist.x[0, i, idx["psi"]])
    north, east = hist.state("north")[:, i], hist.state("east")[:, i]
    k90, k180 = crossing(psi, math.pi / 2), crossing(psi, math.pi)
    r_end = float(hist.state("r")[-1, i])
    U_end = float(hist.speed[-1, i])
    V = float(hist.speed[0, i])
    is_steady = bool(steady(hist.time, hist.state("r")[:, i:i + 1], hist.time.size - 1,
                            steady_window(ship))[0])
    return {
        "side": side,
        "advance_m": None if k90 is None else at(north, k90),
        "transfer_m": None if k90 is None else s * at(east, k90),
        "tactical_diameter_m": None if k180 is None else s * at(east, k180),
        "steady_turning_radius_m": finite(U_end / abs(r_end)) if r_end != 0 else None,
        "steady_speed_mps": U_end,
        "speed_loss_pct": 100.0 * (1.0 - U_end / V),
        "steady_yaw_rate_deg_s": math.degrees(r_end),
        "time_to_90_deg_s": None if k90 is None else at(hist.time, k90),
        "time_to_180_deg_s": None if k180 is None else at(hist.time, k180),
        "steady": is_steady,
    }


def turning_circle(vessel=None, rudder_deg: float | None = None, *, sides=("starboard", "port"),
                   speed_mps=None, ship=None, **kw) -> dict:
    """Run the turning circle to each of ``sides`` (and each of the speeds ``speed_mps``, a
    number or a sequence) as one batch; the figures per side.

    The top-level keys carry the first side's figures; ``sides`` holds every side's; with several
    speeds, ``speeds`` holds one such result per speed (the top level is the first speed's).
    """
    ship = ship if ship is not None else prepare(vessel, speed_mps, **kw)
    rudder_deg = rudder_angle(ship, rudder_deg)
    (hist,) = run_parts(ship, [(plan(ship, rudder_deg, sides), finished)])
    return collect(ship, hist, rudder_deg, sides)


def collect(ship, hist, rudder_deg, sides) -> dict:
    results = []
    for i in range(ship.x0.shape[0]):
        sub = hist.part(i * len(sides), (i + 1) * len(sides))
        per = {side: analyse(ship, sub, j, side) for j, side in enumerate(sides)}
        out = {"trial": "turning-circle", **header(ship, i), "rudder_deg": rudder_deg}
        out.update({k: v for k, v in per[sides[0]].items() if k != "side"})
        out["sides"] = per
        out["_history"] = sub
        results.append(out)
    if len(results) > 1:
        results[0] = {**results[0], "speeds": [{k: v for k, v in r.items()} for r in results]}
    return results[0]
