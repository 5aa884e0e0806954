"""Velocity obstacles with COLREG constraints after Kuwata, Wolf, Zarzhitsky & Huntsberger (2014),
"Safe maritime autonomous navigation with COLREGS, using velocity obstacles", IEEE J. Oceanic
Eng. 39(1), 110–119.

Velocity obstacle (VO) of target B for the own ship A: the own velocities v that, held with B's
velocity v_B, bring B within the combined safety radius r. With λ = p_B − p_A the line of sight and
w = v − v_B the relative velocity, v ∈ VO when the ray along w passes within r of B:

    w·λ > 0  and  |λ × w| / |w| ≤ r   ⇔  ∠(w, λ) ≤ α = asin(r / |λ|)

— a cone in velocity space with its apex at v_B, its axis along λ and half-angle α. A velocity on
its edge passes B at exactly r (a CPA of r). Only collisions within the horizon T count: the
relative motion enters the disc at t_in = (λ·ŵ − √(r² − d_⊥²)) / |w|, with d_⊥² = |λ|² − (λ·ŵ)²
the squared miss distance of the relative track, and v is in the VO when t_in ≤ T. Inside the
disc already (|λ| ≤ r) every closing velocity (w·λ > 0) is in it.

COLREG constraint (paper's V^H): in a head-on (rule 14) or a crossing in which the own ship gives
way (rules 15–16) — the situation from :mod:`shipgnc.colav.colreg`, judged from the nominal
velocity — the half-plane of velocities whose relative track leaves the target on the own starboard
side or meets it (λ × w ≤ 0, with × the NED cross product λ_n w_e − λ_e w_n: starboard to
starboard in a head-on, ahead of a crossing target) is excluded: the own ship passes port to port,
or astern of a crossing target.

Choice: among the candidates χ_n + Δχ (course offsets) × P·U_n (speed factors), the velocity
outside every VO and every COLREG half-plane nearest the nominal velocity (ties to the offset
nearest the last one); if there is none, the COLREG constraints are dropped first (avoiding the
collision comes before the rules' preferred side, rule 2(b)), and if still none the candidate whose
first entry into a safety disc is latest.

Defaults (:class:`VOConfig`): the paper does not publish its numbers as defaults; the combined
safety radius (50 m) and horizon (100 s) are those of :class:`~shipgnc.colav.sbmpc.SBMPCConfig`, so
that both methods are compared on the same safety distance, and the grid (±90° in 5° steps ×
{1, ¾, ½, ¼, 0}) spans SB-MPC's behaviours finer.

The per-ship memory ``z`` = [last course offset (rad)].
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
from pydantic import Field, model_validator

from shipgnc.colav.colreg import GIVE_WAY, HEAD_ON, ColregConfig, classify, colreg_params
from shipgnc.colav.sbmpc import batch_inputs, check_behaviours
from shipgnc.config_types import Positive, Strict
from shipgnc.derive import per_ship
from shipgnc.kernels import flat, kernel_function, wrap

#: length of the per-ship memory z = [last course offset (rad)]
VO_MEMORY = 1
_N_FIXED = 9  # parameters before the candidate grid (vo_params)


class VOConfig(Strict):
    """Velocity obstacles' safety radius, horizon, candidate grid and COLREG situations."""

    radius: Positive = Field(50.0, description="combined safety radius r of own ship and target [m]")
    horizon: Positive = Field(100.0, description="collisions later than this are not obstacles [s]")
    course_offsets_deg: list[float] = Field(
        default_factory=lambda: [float(a) for a in range(-90, 91, 5)],
        description="course offsets tried [deg], positive to starboard; must include 0")
    speed_factors: list[float] = Field(default_factory=lambda: [1.0, 0.75, 0.5, 0.25, 0.0],
                                       description="fractions of the nominal speed tried; must include 1")
    colreg: ColregConfig = Field(default_factory=ColregConfig,
                                 description="when a target is an encounter, and which")

    field_units: ClassVar[dict[str, str]] = {"radius": "m", "horizon": "s", "speed_factors": "1"}

    @model_validator(mode="after")
    def _check(self):
        check_behaviours(self.course_offsets_deg, self.speed_factors)
        return self


def vo_params(config: VOConfig | None = None) -> np.ndarray:
    """Flat parameters of :func:`vo_choose`: [radius, horizon, the 5 of
    :func:`~shipgnc.colav.colreg.colreg_params`, n_offsets, n_factors, offsets (rad), factors]."""
    c = config or VOConfig()
    # nearest the nominal first; of two equal offsets starboard (+) first, so that it wins ties
    offsets = sorted(c.course_offsets_deg, key=lambda a: (abs(a), -math.copysign(1.0, a)))
    factors = sorted(c.speed_factors, reverse=True)
    return flat(c.radius, c.horizon, colreg_params(c.colreg), len(offsets), len(factors),
                np.radians(offsets), factors)


@kernel_function
def entry_time(ln, le, wn, we, r):
    """Time [s] at which a target at line of sight (ln, le) from the own ship, approached with
    relative velocity w = (wn, we) = v − v_B, comes within ``r``: (λ·ŵ − √(r² − d_⊥²))/|w| with
    d_⊥² = |λ|² − (λ·ŵ)² the squared miss distance of the relative track; 0 inside the disc while
    closing; inf if never.
    v is in the velocity obstacle (cone of half-angle asin(r/|λ|) about λ, apex v_B) iff this is
    finite."""
    rng = math.hypot(ln, le)
    closing = ln * wn + le * we
    if closing <= 0.0:
        return math.inf
    if rng <= r:
        return 0.0
    w = math.hypot(wn, we)
    along = closing / w  # distance along the relative track to its closest point, λ·ŵ
    miss2 = rng * rng - along * along  # the miss distance squared
    if miss2 > r * r:
        return math.inf
    return (along - math.sqrt(r * r - max(miss2, 0.0))) / w


@kernel_function
def leaves_to_starboard(ln, le, wn, we):
    """True when the relative track w leaves the target at line of sight λ on the own starboard
    side or meets it, λ × w ≤ 10⁻⁹|λ||w| (a collision course, λ × w = 0, included whatever its
    round-off): the side rule 14 and rules 15–16 forbid to a give-way ship."""
    return ln * we - le * wn <= 1e-9 * math.hypot(ln, le) * math.hypot(wn, we)


@kernel_function
def vo_choose(t, own, targets, n_targets, nominal, p, z, out):
    """Velocity-obstacle choice at time t (module docstring): own = [north, east, course, speed]
    over ground; targets = n_max·4 numbers [north, east, v_north, v_east], the first ``n_targets``
    rows valid; nominal = [course, speed] the path guidance wants; p from :func:`vo_params`;
    z = [last offset] (updated); writes out = [course command, speed command]."""
    radius, horizon = p[0], p[1]
    n_offsets = int(p[7])
    n_factors = int(p[8])
    n = int(n_targets)
    cp = p[2:7]
    # per target, once: must the own ship give way (COLREG half-plane)? can it be met within T?
    gives_way = np.zeros(n, dtype=np.bool_)
    near = np.zeros(n, dtype=np.bool_)
    for i in range(n):
        tn, te, tvn, tve = targets[4 * i], targets[4 * i + 1], targets[4 * i + 2], targets[4 * i + 3]
        code = classify(own[0], own[1], nominal[0], nominal[1], tn, te, tvn, tve, cp)
        gives_way[i] = code == HEAD_ON or code == GIVE_WAY
        reach = (abs(nominal[1]) + math.hypot(tvn, tve)) * horizon + radius
        near[i] = math.hypot(tn - own[0], te - own[1]) <= reach
    best_level = 3  # 0: clear of VO and COLREG, 1: clear of VO, 2: neither
    best_cost = math.inf
    best_chi = 0.0
    best_factor = 1.0
    for a in range(n_offsets):
        if best_level == 0 and best_chi == 0.0 and best_factor == 1.0:
            break  # the nominal velocity (the first candidate) is clear: nothing is nearer
        chi = p[_N_FIXED + a]
        course = nominal[0] + chi
        for b in range(n_factors):
            factor = p[_N_FIXED + n_offsets + b]
            speed = factor * nominal[1]
            vn = speed * math.cos(course)
            ve = speed * math.sin(course)
            in_vo = False
            breaks_colreg = False
            first_entry = math.inf
            for i in range(n):
                if not (near[i] or gives_way[i]):
                    continue
                ln, le = targets[4 * i] - own[0], targets[4 * i + 1] - own[1]
                wn, we = vn - targets[4 * i + 2], ve - targets[4 * i + 3]
                if near[i]:
                    t_in = entry_time(ln, le, wn, we, radius)
                    if t_in < first_entry:
                        first_entry = t_in
                    if t_in <= horizon:
                        in_vo = True
                if gives_way[i] and leaves_to_starboard(ln, le, wn, we):
                    breaks_colreg = True
            level = 2 if in_vo else (1 if breaks_colreg else 0)
            dvn = vn - nominal[1] * math.cos(nominal[0])
            dve = ve - nominal[1] * math.sin(nominal[0])
            if level == 2:
                cost = -first_entry  # nothing clear: the latest first entry
            else:
                cost = dvn * dvn + dve * dve + 1e-9 * (chi - z[0]) ** 2  # ties: nearest the last
            if level < best_level or (level == best_level and cost < best_cost):
                best_level = level
                best_cost = cost
                best_chi = chi
                best_factor = factor
    z[0] = best_chi
    out[0] = nominal[0] if best_chi == 0.0 else wrap(nominal[0] + best_chi)
    out[1] = best_factor * nominal[1]


@kernel_function
def _vo_row(t, own, targets, n_targets, nominal, p, z, out):
    """:func:`vo_choose` with ``n_targets`` given as a one-element row (for the batch)."""
    vo_choose(t, own, targets, int(n_targets[0]), nominal, p, z, out)


def vo_batch(t, own, targets, n_targets, nominal, params, z) -> np.ndarray:
    """:func:`vo_choose` for every ship (:func:`shipgnc.derive.per_ship`): own (n, 4), targets
    (n, n_max·4), n_targets (n,), nominal (n, 2), params from :func:`vo_params`, z (n, 1) updated
    in place; returns the commands (n, 2)."""
    own, targets, n_targets, nominal = batch_inputs(own, targets, n_targets, nominal)
    return per_ship(_vo_row, "t i i i i p z o")(t, own, targets, n_targets, nominal, params, z, 2)
