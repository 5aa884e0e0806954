"""IMO Standards for Ship Manoeuvrability (MSC.137(76), 2002, §5) and the full trial set.

Criteria (L in m, V in m/s, L/V in s; ``docs/trials.md``):

* turning ability (35° turning circle, each side): advance ≤ 4.5 L, tactical diameter ≤ 5 L;
* initial turning ability (10° rudder): distance along the track by the 10° heading change ≤ 2.5 L
  (taken from the 10°/10° zig-zag's first phase, which is exactly that manoeuvre);
* yaw checking and course keeping: 10°/10° first overshoot ≤ 10° if L/V < 10 s, ≤ 20° if
  L/V ≥ 30 s, else (5 + ½ L/V)°; 10°/10° second overshoot ≤ 25° if L/V < 10 s, ≤ 40° if
  L/V ≥ 30 s, else (17.5 + 0.75 L/V)°; 20°/20° first overshoot ≤ 25°;
* stopping: track reach ≤ 15 L (an Administration may allow up to 20 L for large ships).

Each criterion takes the worse of the two sides. The criteria presume a steering gear that meets
SOLAS II-1 reg. 29 (35° to 30° the other side in 28 s): ``shipgnc trial`` runs with it unless
``--steering-gear model`` (the vessel's own rate). :func:`run_all` runs every trial (turning both
sides, 10/10 and 20/20 both sides, the spiral, the pull-out and, when the vessel can reverse,
stopping) as ONE batch and returns their figures with the criteria report.
"""

from __future__ import annotations

from shipgnc.errors import ConfigError


def first_overshoot_limit_10(l_over_v: float) -> float:
    """Limit of the 10°/10° first overshoot [deg] for L/V [s] (MSC.137(76) 5.4.1)."""
    if l_over_v < 10.0:
        return 10.0
    if l_over_v >= 30.0:
        return 20.0
    return 5.0 + 0.5 * l_over_v


def second_overshoot_limit_10(l_over_v: float) -> float:
    """Limit of the 10°/10° second overshoot [deg] for L/V [s] (MSC.137(76) 5.4.2)."""
    if l_over_v < 10.0:
        return 25.0
    if l_over_v >= 30.0:
        return 40.0
    return 17.5 + 0.75 * l_over_v


#: limit of the 20°/20° first overshoot [deg] (MSC.137(76) 5.4.3)
FIRST_OVERSHOOT_LIMIT_20 = 25.0


def _worst(results: dict, key: str):
    vals = [s.get(key) for s in results["sides"].values()]
    if any(v is None for v in vals):
        return None
    return max(vals)


def _criterion(name, value, limit, unit, note=""):
    ok = None if value is None or limit is None else bool(value <= limit)
    out = {"criterion": name, "value": value, "limit": limit, "unit": unit, "pass": ok}
    if note:
        out["note"] = note
    return out


def criteria(length_m: float | None, speed_mps: float, turning: dict, zz10: dict, zz20: dict,
             stopping: dict | str | None) -> list[dict]:
    """The MSC.137(76) criteria with value, limit and pass (None when not computable).

    ``stopping``: the stopping figures, or a string saying why there are none.
    """
    if length_m is None:
        note = "the vessel has no length: the criteria in ship lengths cannot be evaluated"
        L = lv = None
    else:
        note = ""
        L = float(length_m)
        lv = L / float(speed_mps)

    def lim(f):
        return None if L is None else f(L)

    out = [
        _criterion("turning ability: advance", _worst(turning, "advance_m"), lim(lambda L: 4.5 * L), "m",
                   note),
        _criterion("turning ability: tactical diameter", _worst(turning, "tactical_diameter_m"),
                   lim(lambda L: 5.0 * L), "m", note),
        _criterion("initial turning: distance to 10° heading change (10° rudder)",
                   _worst(zz10, "initial_turning_distance_m"), lim(lambda L: 2.5 * L), "m", note),
        _criterion("yaw checking: 10°/10° first overshoot", _worst(zz10, "first_overshoot_deg"),
                   None if lv is None else first_overshoot_limit_10(lv), "deg", note),
        _criterion("course keeping: 10°/10° second overshoot", _worst(zz10, "second_overshoot_deg"),
                   None if lv is None else second_overshoot_limit_10(lv), "deg", note),
        _criterion("yaw checking: 20°/20° first overshoot", _worst(zz20, "first_overshoot_deg"),
                   FIRST_OVERSHOOT_LIMIT_20, "deg"),
    ]
    if isinstance(stopping, dict):
        out.append(_criterion("stopping: track reach (full astern)", stopping.get("track_reach_m"),
                              lim(lambda L: 15.0 * L), "m",
                              note or "an Administration may allow up to 20 L for large ships"))
    else:
        out.append(_criterion("stopping: track reach (full astern)", None,
                              lim(lambda L: 15.0 * L), "m", str(stopping or "not run")))
    return out


def run_all(vessel=None, *, speed_mps=None, rudder_deg: float | None = None, ship=None,
            sides=("starboard", "port"), spiral_max_deg: float | None = None,
            steering_gear: str = "solas", **kw) -> dict:
    """Every trial of the IMO set plus spiral and pull-out, as ONE batch; figures and criteria.
    A ship prepared here has the SOLAS steering gear the criteria presume (``steering_gear``,
    :func:`shipgnc.trials.core.prepare`); a given ``ship`` keeps its own."""
    from shipgnc.trials import pullout, spiral, stopping, turning, zigzag
    from shipgnc.trials.core import header, prepare, run_parts

    ship = ship if ship is not None else prepare(vessel, speed_mps, steering_gear=steering_gear, **kw)
    rudder = turning.rudder_angle(ship, rudder_deg)
    angles, spiral_parts = spiral.parts(ship, spiral_max_deg)
    parts = [(turning.plan(ship, rudder, sides), turning.finished),
             (zigzag.plan(ship, 10.0, 10.0, sides), zigzag.finished),
             (zigzag.plan(ship, 20.0, 20.0, sides), zigzag.finished),
             *spiral_parts,
             (pullout.plan(ship, rudder, sides), pullout.finished)]
    try:
        parts.append((stopping.plan(ship), stopping.finished))
        stop_error = None
    except ConfigError as exc:
        stop_error = str(exc)
    hists = run_parts(ship, parts)
    res_turn = turning.collect(ship, hists[0], rudder, sides)
    res10 = zigzag.collect(ship, hists[1], 10.0, 10.0, sides)
    res20 = zigzag.collect(ship, hists[2], 20.0, 20.0, sides)
    res_spiral = spiral.collect(ship, hists[3], angles, hists[4])
    res_pull = pullout.collect(ship, hists[5], rudder, sides)
    res_stop = stopping.collect(ship, hists[6]) if stop_error is None else {"error": stop_error}
    crit = criteria(ship.length_m, float(ship.speed[0]), res_turn, res10, res20,
                    res_stop if stop_error is None else stop_error)
    evaluated = [c["pass"] for c in crit if c["pass"] is not None]
    return {"trial": "all", **header(ship),
            "imo": {"criteria": crit, "all_pass": all(evaluated) if evaluated else None},
            "turning-circle": res_turn, "zigzag-10/10": res10, "zigzag-20/20": res20,
            "spiral": res_spiral, "pull-out": res_pull, "stopping": res_stop}


__all__ = ["FIRST_OVERSHOOT_LIMIT_20", "criteria", "first_overshoot_limit_10", "run_all",
           "second_overshoot_limit_10"]
