"""Simulation-based MPC collision avoidance (SB-MPC) after Johansen, Perez & Cristofaro (2016),
"Ship collision avoidance and COLREGS compliance using simulation-based control behavior selection
with predictive hazard assessment", IEEE Trans. Intell. Transp. Syst. 17(12), 3407–3422.

Between the path guidance and the autopilot: the guidance wants course χ_n and speed U_n; SB-MPC
picks a course offset χ from a finite set (−90°…+90° in 15° steps) and a speed factor P from
{1, ½, 0}, and commands χ_n + χ, P·U_n. Each of the candidate behaviours k is scored by predicting
the own ship on the straight line at that course and speed, and each target i at constant
velocity, at t_j = j·Δt, j = 1…T/Δt (the paper's hazard)::

    H_k = max_i max_j [ C_k^i R_k^i(t_j) + κ μ_k^i(t_j) ] + f(P, χ) + g(P, χ)

    R_k^i(t) = (1/t^p)·(d_safe / d_k^i(t))^q  if d_k^i(t) ≤ d_safe, else 0
        (inverse time to the event, growing as the predicted range d falls inside the safety
        distance; d is floored at 10⁻³·d_safe so that a predicted hit is a large finite cost)
    C_k^i = K_coll |v_k − v_i|²  (the collision's cost grows with the relative speed)
    μ_k^i(t) = 1 if the target is close (d ≤ d_close) on the own starboard side and the
        situation is head-on, or crossing while the own ship is not being overtaken (a
        candidate that leaves a give-way target on the starboard side: a port turn in a head-on
        or crossing, rules 14–15); sectors φ_AH (ahead), φ_OT (overtaking), φ_HO (head-on),
        φ_CR (crossing) between the predicted velocities, as in the paper
    f(P, χ) = k_P (1 − P) + k_χ(χ) χ²,  k_χ = k_χ,sb for χ > 0 (starboard), k_χ,p for χ < 0
    g(P, χ) = k_ΔP |P − P_last| + k_Δχ(χ − χ_last) (χ − χ_last)²  (change from the last choice)

and the behaviour of least H_k is applied until the next call. The paper's transitional cost
λτ (a COLREG-compliant manoeuvre abandoned midway) and its full-reverse behaviour P = −1 are not
used; the straight-line own-ship prediction is the one the paper's own simplified form uses.

μ as the paper writes it (``situation="predicted"``) judges HEAD-ON and CROSSED from each
behaviour's *predicted* velocity. In a right-angle crossing from starboard a 30° port turn then
makes the velocities meet at 60° < φ_CR: no longer "crossed", μ = 0, and with the collision beyond
the horizon that port turn (cost (k_χ,p + k_Δχ,p)(π/6)² ≈ 0.77) beats holding course (κ = 3) and
every compliant starboard turn — the manoeuvre rule 15 forbids (tests/test_colav_sbmpc.py shows it
by hand). The default, ``situation="encounter"``, judges the situation once, from the nominal
velocity and the present geometry, and only while the ships approach each other (Δp·Δv < 0); μ at
a predicted instant then applies while that pair still approaches (a target receding astern after
the passing is no longer an encounter). Each behaviour is still judged on which side it leaves the
target, as in the paper.

Defaults (:class:`SBMPCConfig`): the paper's behaviour set (course offsets and the speed factors it
keeps). The other values are ours, not a published parameter file's (the public SB-MPC codes of the
authors' group carry other numbers, file by file): T = 100 s, Δt = 5 s, d_close = 1000 m,
d_safe = 50 m, K_coll = 1, κ = 3, k_P = 3, k_ΔP = 2.5, k_χ,sb = 1.3, k_χ,p = 1.6,
k_Δχ,sb = 0.9, k_Δχ,p = 1.2, p = 1, q = 4, φ_AH = φ_OT = φ_CR = 68.5°, φ_HO = 22.5°. The
reasoning: the sectors are the paper's (68.5° and 22.5°, as in NTNU's public implementations);
p = 1 and q = 4 are the paper's exponents; T and d_close cover a closing pair of ships at 10 m/s
for the last kilometre; the weights rank the costs as the paper describes — κ (a COLREG
violation) above any admissible turn cost, port turns dearer than starboard ones
(k_χ,p > k_χ,sb), and a change of choice dearer to port than to starboard
(k_Δχ,p > k_Δχ,sb). Sign convention: χ, and the change χ − χ_last that selects k_Δχ, are
positive to starboard (NED, clockwise); a code whose course offsets are positive to port swaps the
two weights. Angles in the costs are in radians. d_safe = 50 m suits the small vessels of the
paper; for ships, scale it with their size.

The per-ship memory ``z`` = [χ_last, 1 − P_last]: zeros mean "the nominal behaviour last".
"""

from __future__ import annotations

import math
from typing import ClassVar, Literal

import numpy as np
from pydantic import Field, model_validator

from shipgnc.config_types import NonNegative, Positive, Strict
from shipgnc.derive import per_ship
from shipgnc.kernels import flat, kernel_function, wrap

#: length of the per-ship memory z = [last course offset (rad), 1 − last speed factor]
SBMPC_MEMORY = 2
_N_FIXED = 21  # parameters before the behaviour set (sbmpc_params)


def check_behaviours(course_offsets_deg, speed_factors) -> None:
    """A candidate set holds the nominal (offset 0, factor 1), offsets in (−180°, 180°), factors
    in [0, 1]; else a ValueError naming the field."""
    if any(not -180.0 < a < 180.0 for a in course_offsets_deg) or 0.0 not in course_offsets_deg:
        raise ValueError(f"course_offsets_deg = {course_offsets_deg}: offsets in (-180, 180) "
                         "including 0 (the nominal course)")
    if any(not 0.0 <= f <= 1.0 for f in speed_factors) or 1.0 not in speed_factors:
        raise ValueError(f"speed_factors = {speed_factors}: factors in [0, 1] including 1 "
                         "(the nominal speed)")


class SBMPCConfig(Strict):
    """SB-MPC's behaviour set, prediction and cost weights (defaults and sources: module docstring)."""

    course_offsets_deg: list[float] = Field(
        default_factory=lambda: [float(a) for a in range(-90, 91, 15)],
        description="course offsets tried [deg], positive to starboard; must include 0")
    speed_factors: list[float] = Field(default_factory=lambda: [1.0, 0.5, 0.0],
                                       description="fractions of the nominal speed tried; must include 1")
    horizon: Positive = Field(100.0, description="prediction horizon T [s]")
    dt: Positive = Field(5.0, description="prediction sample time Δt [s]")
    d_safe: Positive = Field(50.0, description="safety distance: a predicted range inside it is a hazard [m]")
    d_close: Positive = Field(1000.0, description="range within which COLREG applies in μ [m]")
    k_coll: NonNegative = Field(1.0, description="K_coll, weight of the relative speed squared (m/s) in C")
    p_time: NonNegative = Field(1.0, description="exponent p of the inverse time to the event")
    q_distance: NonNegative = Field(4.0, description="exponent q of d_safe/d")
    kappa: NonNegative = Field(3.0, description="κ, cost of a COLREG violation")
    k_p: NonNegative = Field(3.0, description="k_P, cost of slowing down (1 − P)")
    k_chi_starboard: NonNegative = Field(1.3, description="k_χ for starboard offsets [1/rad²]")
    k_chi_port: NonNegative = Field(1.6, description="k_χ for port offsets [1/rad²]")
    k_dp: NonNegative = Field(2.5, description="k_ΔP, cost of changing the speed factor")
    k_dchi_starboard: NonNegative = Field(0.9, description="k_Δχ for a change to starboard [1/rad²]")
    k_dchi_port: NonNegative = Field(1.2, description="k_Δχ for a change to port [1/rad²]")
    ahead_deg: float = Field(68.5, gt=0, lt=180, description="φ_AH, sector of 'ahead' [deg]")
    overtaking_deg: float = Field(68.5, gt=0, lt=180, description="φ_OT, sector of overtaking [deg]")
    head_on_deg: float = Field(22.5, gt=0, lt=180, description="φ_HO, sector of head-on [deg]")
    crossing_deg: float = Field(68.5, gt=0, lt=180, description="φ_CR, sector of crossing [deg]")
    situation: Literal["encounter", "predicted"] = Field(
        "encounter", description="μ's head-on/crossing/overtaken judged once from the nominal velocity "
                                 "('encounter'), or from each behaviour's predicted velocity as the paper "
                                 "writes it ('predicted'; see the module docstring)")

    field_units: ClassVar[dict[str, str]] = {
        "speed_factors": "1", "horizon": "s", "dt": "s", "d_safe": "m", "d_close": "m", "k_coll": "1",
        "p_time": "1", "q_distance": "1", "kappa": "1", "k_p": "1", "k_chi_starboard": "1/rad²",
        "k_chi_port": "1/rad²", "k_dp": "1", "k_dchi_starboard": "1/rad²", "k_dchi_port": "1/rad²"}

    @model_validator(mode="after")
    def _check(self):
        check_behaviours(self.course_offsets_deg, self.speed_factors)
        if self.dt > self.horizon:
            raise ValueError(f"dt = {self.dt}: at most the horizon ({self.horizon} s)")
        return self


def sbmpc_params(config: SBMPCConfig | None = None) -> np.ndarray:
    """Flat parameters of :func:`sbmpc_choose`: 21 numbers (module docstring's order, angles in
    radians), then the course offsets [rad] and the speed factors."""
    c = config or SBMPCConfig()
    offsets = sorted(c.course_offsets_deg, key=abs)  # the nominal first: it wins every tie
    factors = sorted(c.speed_factors, reverse=True)
    return flat(c.horizon, c.dt, c.d_safe, c.d_close, c.k_coll, c.p_time, c.q_distance, c.kappa,
                c.k_p, c.k_chi_starboard, c.k_chi_port, c.k_dp, c.k_dchi_starboard, c.k_dchi_port,
                math.radians(c.ahead_deg), math.radians(c.overtaking_deg), math.radians(c.head_on_deg),
                math.radians(c.crossing_deg), len(offsets), len(factors),
                float(c.situation == "encounter"), np.radians(offsets), factors)


@kernel_function
def colreg_situation(dn, de, d, vn, ve, tvn, tve, p):
    """The paper's situation predicates for a target at (dn, de) from the own ship (range d > 0),
    own velocity (vn, ve), target velocity (tvn, tve): 1.0 when the target is HEAD-ON, or CROSSED
    and not OVERTAKEN (own ship not being overtaken), else 0.0 — the situations in which leaving the
    target on the own starboard side while close violates COLREG (μ, module docstring)."""
    u = math.hypot(vn, ve)
    ut = math.hypot(tvn, tve)
    if u < 0.05 or ut < 0.05:
        return 0.0
    dot = vn * tvn + ve * tve
    ahead = (vn * dn + ve * de) > math.cos(p[14]) * u * d
    head_on = ahead and dot < -math.cos(p[16]) * u * ut
    crossed = dot < math.cos(p[17]) * u * ut
    overtaken = dot > math.cos(p[15]) * u * ut and u < ut
    if head_on or (crossed and not overtaken):
        return 1.0
    return 0.0


@kernel_function
def behaviour_cost(own, targets, n_targets, course, speed, nominal, p):
    """max over targets and predicted instants of C R + κ μ (module docstring) for the own ship
    at own[0:2] holding ``course`` and ``speed`` from now on."""
    horizon, dt, d_safe, d_close = p[0], p[1], p[2], p[3]
    k_coll, p_time, q_dist, kappa = p[4], p[5], p[6], p[7]
    encounter_mode = p[20] > 0.5
    vn = speed * math.cos(course)
    ve = speed * math.sin(course)
    n_steps = int(horizon / dt + 1e-9)
    worst = 0.0
    for i in range(n_targets):
        tn, te, tvn, tve = targets[4 * i], targets[4 * i + 1], targets[4 * i + 2], targets[4 * i + 3]
        c_coll = k_coll * ((vn - tvn) ** 2 + (ve - tve) ** 2)
        situation = 0.0
        if encounter_mode:  # the situation now, from the nominal velocity (module docstring)
            dn0, de0 = tn - own[0], te - own[1]
            vn0, ve0 = nominal[1] * math.cos(nominal[0]), nominal[1] * math.sin(nominal[0])
            d0 = math.hypot(dn0, de0)
            if d0 > 0.0 and dn0 * (tvn - vn0) + de0 * (tve - ve0) < 0.0:  # approaching
                situation = colreg_situation(dn0, de0, d0, vn0, ve0, tvn, tve, p)
        for j in range(1, n_steps + 1):
            t = j * dt
            dn = tn + tvn * t - (own[0] + vn * t)
            de = te + tve * t - (own[1] + ve * t)
            d = math.hypot(dn, de)
            cost = 0.0
            if d <= d_close and d > 0.0 and wrap(math.atan2(de, dn) - course) > 0.0:  # close, starboard
                if not encounter_mode:  # as written: the situation of the predicted velocities
                    situation = colreg_situation(dn, de, d, vn, ve, tvn, tve, p)
                    cost = kappa * situation
                elif dn * (tvn - vn) + de * (tve - ve) < 0.0:  # until the ships have passed
                    cost = kappa * situation
            if d <= d_safe:
                cost += c_coll / t ** p_time * (d_safe / max(d, 1e-3 * d_safe)) ** q_dist
            if cost > worst:
                worst = cost
    return worst


@kernel_function
def sbmpc_choose(t, own, targets, n_targets, nominal, p, z, out):
    """SB-MPC at time t: own = [north, east, course, speed] over ground; targets = n_max·4 numbers
    [north, east, v_north, v_east] of which the first ``n_targets`` rows hold; nominal = [course,
    speed] the path guidance wants; p from :func:`sbmpc_params`; z = [χ_last, 1 − P_last] (updated);
    writes out = [course command, speed command]. Picks the behaviour of least H_k (module docstring)."""
    n_offsets = int(p[18])
    n_factors = int(p[19])
    n = int(n_targets)
    chi_last = z[0]
    p_last = 1.0 - z[1]
    best = math.inf
    best_chi = 0.0
    best_factor = 1.0
    for a in range(n_offsets):
        chi = p[_N_FIXED + a]
        k_chi = p[9] if chi > 0.0 else p[10]
        d_chi = chi - chi_last
        k_dchi = p[12] if d_chi > 0.0 else p[13]
        for b in range(n_factors):
            factor = p[_N_FIXED + n_offsets + b]
            cost = (p[8] * (1.0 - factor) + k_chi * chi * chi
                    + p[11] * abs(factor - p_last) + k_dchi * d_chi * d_chi)
            if cost >= best:
                continue  # the hazard term is ≥ 0: this behaviour cannot win
            cost += behaviour_cost(own, targets, n, nominal[0] + chi, factor * nominal[1], nominal, p)
            if cost < best:
                best = cost
                best_chi = chi
                best_factor = factor
    z[0] = best_chi
    z[1] = 1.0 - best_factor
    out[0] = nominal[0] if best_chi == 0.0 else wrap(nominal[0] + best_chi)
    out[1] = best_factor * nominal[1]


@kernel_function
def _sbmpc_row(t, own, targets, n_targets, nominal, p, z, out):
    """:func:`sbmpc_choose` with ``n_targets`` given as a one-element row (for the batch)."""
    sbmpc_choose(t, own, targets, int(n_targets[0]), nominal, p, z, out)


def batch_inputs(own, targets, n_targets, nominal):
    """The numpy entries' inputs checked and shaped: own (n, 4), targets (n, 4·n_max), n_targets
    (n, 1) as floats, nominal (n, 2); a ValueError names the first bad one."""
    own = np.atleast_2d(np.asarray(own, dtype=float))
    targets = np.atleast_2d(np.asarray(targets, dtype=float))
    nominal = np.atleast_2d(np.asarray(nominal, dtype=float))
    counts = np.atleast_1d(np.asarray(n_targets, dtype=float)).reshape(-1, 1)
    if own.shape[-1] != 4:
        raise ValueError(f"own: last axis must be [north, east, course, speed], got shape {own.shape}")
    if nominal.shape[-1] != 2:
        raise ValueError(f"nominal: last axis must be [course, speed], got shape {nominal.shape}")
    if targets.shape[-1] % 4:
        raise ValueError(f"targets: last axis must hold 4 numbers per target, got shape {targets.shape}")
    if np.any(counts < 0) or np.any(counts > targets.shape[-1] // 4) or np.any(counts != np.round(counts)):
        raise ValueError(f"n_targets: whole numbers from 0 to {targets.shape[-1] // 4} (the targets' "
                         f"rows), got {counts.ravel().tolist()}")
    return own, targets, counts, nominal


def sbmpc_batch(t, own, targets, n_targets, nominal, params, z) -> np.ndarray:
    """:func:`sbmpc_choose` for every ship (:func:`shipgnc.derive.per_ship`): own (n, 4), targets
    (n, n_max·4), n_targets (n,), nominal (n, 2), params from :func:`sbmpc_params`, z (n, 2)
    updated in place; returns the commands (n, 2)."""
    own, targets, n_targets, nominal = batch_inputs(own, targets, n_targets, nominal)
    return per_ship(_sbmpc_row, "t i i i i p z o")(t, own, targets, n_targets, nominal, params, z, 2)
