"""Encounter geometry of two ships: range, bearing, and the closest point of approach (CPA).

Both ships hold a constant velocity over ground (the straight-line prediction every collision
avoidance and every bridge ARPA makes). With the target's position and velocity relative to the own
ship, Δp = p_t − p_o and Δv = v_t − v_o (NED, metres and m/s), the range at time τ from now is
|Δp + Δv τ|, smallest at

    t_cpa = −(Δp·Δv) / |Δv|²,  clipped at 0 (ships moving apart are closest now),
    d_cpa = |Δp + Δv t_cpa|,

the standard closed form (e.g. Lenart 1983, "Collision threat parameters for a new radar display and
plot technique", J. Navigation 36(3); Fossen 2021 §12). When |Δv| = 0 the range never changes:
t_cpa = 0, d_cpa = |Δp|.

Angles: the true bearing of the target is atan2(Δe, Δn) (clockwise from north); its relative
bearing is that minus the own course, wrapped to (−π, π] — positive on the own starboard side.

Each quantity is one scalar kernel (the guidance's compiled loop calls them);
:func:`encounter_geometry` is their batch over any number of own/target pairs
(:func:`shipgnc.derive.per_ship`).
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.derive import per_ship
from shipgnc.kernels import kernel_function, wrap

#: the columns :func:`geometry_row` writes, in order
GEOMETRY_FIELDS = ("range", "bearing", "relative_bearing", "d_cpa", "t_cpa")


@kernel_function
def cpa(pn, pe, vn, ve, tn, te, tvn, tve):
    """(d_cpa [m], t_cpa [s]) of the own ship at (pn, pe) moving with (vn, ve) and a target at
    (tn, te) moving with (tvn, tve), both at constant velocity (module docstring):
    t_cpa = max(0, −(Δp·Δv)/|Δv|²), d_cpa = |Δp + Δv t_cpa|; |Δv| = 0 gives t_cpa = 0, d_cpa = |Δp|."""
    dn = tn - pn
    de = te - pe
    dvn = tvn - vn
    dve = tve - ve
    dv2 = dvn * dvn + dve * dve
    t_cpa = 0.0
    if dv2 > 0.0:
        t_cpa = -(dn * dvn + de * dve) / dv2
        if t_cpa < 0.0:
            t_cpa = 0.0
    return math.hypot(dn + dvn * t_cpa, de + dve * t_cpa), t_cpa


@kernel_function
def true_bearing(pn, pe, tn, te):
    """Bearing [rad] of the point (tn, te) seen from (pn, pe), clockwise from north, in (−π, π]:
    atan2(te − pe, tn − pn)."""
    return math.atan2(te - pe, tn - pn)


@kernel_function
def relative_bearing(pn, pe, course, tn, te):
    """Bearing [rad] of (tn, te) from (pn, pe) relative to ``course``, wrapped to (−π, π]:
    positive on the starboard side, ±π dead astern."""
    return wrap(math.atan2(te - pe, tn - pn) - course)


@kernel_function
def geometry_row(own, target, out):
    """One pair: own = [north, east, course, speed] over ground, target = [north, east, v_north,
    v_east]; writes out = [range, bearing, relative_bearing, d_cpa, t_cpa] (SI, radians)."""
    vn = own[3] * math.cos(own[2])
    ve = own[3] * math.sin(own[2])
    out[0] = math.hypot(target[0] - own[0], target[1] - own[1])
    out[1] = true_bearing(own[0], own[1], target[0], target[1])
    out[2] = relative_bearing(own[0], own[1], own[2], target[0], target[1])
    d_cpa, t_cpa = cpa(own[0], own[1], vn, ve, target[0], target[1], target[2], target[3])
    out[3] = d_cpa
    out[4] = t_cpa


def encounter_geometry(own, target) -> dict[str, np.ndarray]:
    """Range, bearing, relative bearing, d_cpa and t_cpa of every pair (:func:`geometry_row`), as
    arrays of the broadcast leading shape of ``own`` (..., 4) = [north, east, course, speed] and
    ``target`` (..., 4) = [north, east, v_north, v_east]."""
    own = np.asarray(own, dtype=float)
    target = np.asarray(target, dtype=float)
    for name, a in (("own", own), ("target", target)):
        if a.ndim < 1 or a.shape[-1] != 4:
            raise ValueError(f"{name}: last axis must have 4 entries, got shape {a.shape}")
    out = per_ship(geometry_row, "i i o")(own, target, len(GEOMETRY_FIELDS))
    return {name: out[..., k] for k, name in enumerate(GEOMETRY_FIELDS)}
