"""COLREG compliance scores of one own ship's logged encounter, after Woerner (2016, MIT PhD thesis
"Multi-contact protocol-constrained collision avoidance for autonomous marine vehicles") and
Woerner, Benjamin, Novitzky & Leonard (2019, "Quantifying protocol evaluation for autonomous
collision avoidance", Autonomous Robots 43): each rule a score in [0, 1], 1 fully compliant, made
of a safety score times (1 − penalty) factors. Post-processing of a run, in numpy.

Per target, from its detection (the first sample with range ≤ ``r_detect``, or the first sample)
to its CPA (the sample of least range), with χ₀, U₀ the own course and speed at detection:

safety   from the CPA distance r (piecewise linear, Woerner's form):
         1 for r ≥ r_safe; 1 − γ_nm (r_safe − r)/(r_safe − r_nm) down to the near-miss range r_nm;
         1 − γ_nm − γ_col (r_nm − r)/(r_nm − r_col) down to r_col; 0 below (γ_nm + γ_col = 1).
delay    p_delay = clip((r_early − r_act)/(r_early − r_late), 0, 1), r_act the range when the own
         ship first alters course by ≥ Δχ_md or speed by ≥ ΔU_md·U₀ (1 if it never does):
         action taken at r_early or more is early, at r_late or less too late (rule 16 "early").
apparent p_na = 1 − min(1, max(Δχ_max/Δχ_app, ΔU_max/(ΔU_app·U₀))), Δχ_max the largest course
         change and ΔU_max the largest speed reduction before CPA: a course change of Δχ_app
         (30°) or a speed reduction of ΔU_app (half the speed) is readily apparent (rules 8(b), 16
         "substantial").
rule_16  (own ship gives way: head-on, overtaking, crossing give-way)
         s_16 = safety · (1 − p_delay) · (1 − p_na).
rule_14  (head-on) s_14 = s_16 · (1 − p_nsb) · (1 − p_sts): p_nsb = 1 unless the first course
         alteration is to starboard, p_sts = 1 when the target passes on the own starboard side
         (relative bearing at CPA > 0) instead of port to port.
rule_15  (crossing give-way) s_15 = s_16 · (1 − p_ahead): p_ahead = 1 when the own ship crosses
         ahead of the target (at CPA it is forward of the target's beam).
rule_17  (stand-on: crossing stand-on, being overtaken) s_17 = safety · (1 − p_change) ·
         (1 − p_port): p_change = min(1, max(Δχ/Δχ_app, |ΔU|/(ΔU_app·U₀))) over the changes made
         while the range exceeds r_late (rule 17(a)(i): keep course and speed; closer, 17(a)(ii)
         and (b) allow action), p_port = 1 for a port turn ≥ Δχ_md towards a target on the port
         side (rule 17(c)).

Woerner's algorithms carry more terms (aspect at CPA, multi-contact weighting); these are the
terms of the three behaviours the rules name. Thresholds (:class:`ComplianceConfig`) are ours,
in the ranges of open-sea practice: r_safe 0.5 nm, r_early 1 nm, r_late 0.5 nm; γ_nm = 0.4.
The scores of several targets combine as their minimum (the worst encounter); a rule that no
encounter invokes is NaN.
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
from pydantic import Field, model_validator

from shipgnc.colav.colreg import GIVE_WAY, HEAD_ON, OVERTAKEN, OVERTAKING, SAFE, STAND_ON
from shipgnc.config_types import Positive, Strict
from shipgnc.frames import wrap_angle

#: the scores :func:`compliance_scores` returns, each in [0, 1] (NaN where no encounter applies)
SCORES = ("safety", "rule_14", "rule_15", "rule_16", "rule_17")


class ComplianceConfig(Strict):
    """Ranges and thresholds of the compliance scores (module docstring)."""

    r_collision: Positive = Field(50.0, description="CPA at or below which the safety score is 0 [m]")
    r_near_miss: Positive = Field(250.0, description="near-miss CPA [m]")
    r_safe: Positive = Field(926.0, description="CPA from which the safety score is 1 [m] (0.5 nm)")
    gamma_near_miss: float = Field(0.4, ge=0, le=1, description="safety lost between r_safe and r_near_miss")
    r_detect: Positive = Field(3704.0, description="range at which an encounter starts [m] (2 nm)")
    r_early: Positive = Field(1852.0, description="action at or beyond this range is early [m] (1 nm)")
    r_late: Positive = Field(926.0, description="action at or within this range is too late [m]")
    course_change_app_deg: float = Field(30.0, gt=0, lt=180, description="a readily apparent course change")
    speed_change_app: float = Field(0.5, gt=0, le=1, description="a readily apparent speed reduction, "
                                                                 "fraction of the speed")
    course_change_md_deg: float = Field(5.0, gt=0, lt=180, description="smallest course change that is "
                                                                       "a manoeuvre")
    speed_change_md: float = Field(0.1, gt=0, le=1, description="smallest speed change that is a "
                                                                "manoeuvre, fraction of the speed")

    field_units: ClassVar[dict[str, str]] = {
        "r_collision": "m", "r_near_miss": "m", "r_safe": "m", "gamma_near_miss": "1", "r_detect": "m",
        "r_early": "m", "r_late": "m", "speed_change_app": "1", "speed_change_md": "1"}

    @model_validator(mode="after")
    def _check(self):
        if not self.r_collision < self.r_near_miss < self.r_safe:
            raise ValueError(f"r_collision < r_near_miss < r_safe required, got {self.r_collision}, "
                             f"{self.r_near_miss}, {self.r_safe}")
        if not self.r_late < self.r_early:
            raise ValueError(f"r_late = {self.r_late}: must be below r_early = {self.r_early}")
        return self


def safety_score(r_cpa, config: ComplianceConfig | None = None):
    """Woerner's piecewise-linear safety score of a CPA distance (module docstring)."""
    c = config or ComplianceConfig()
    r = np.asarray(r_cpa, dtype=float)
    g_nm, g_col = c.gamma_near_miss, 1.0 - c.gamma_near_miss
    near = 1.0 - g_nm * (c.r_safe - r) / (c.r_safe - c.r_near_miss)
    close = 1.0 - g_nm - g_col * (c.r_near_miss - r) / (c.r_near_miss - c.r_collision)
    return np.where(r >= c.r_safe, 1.0, np.where(r >= c.r_near_miss, near,
                                                 np.where(r >= c.r_collision, close, 0.0)))


def _target_samples(track, t):
    """(north, east, v_north, v_east) of a target at the times ``t``: a TargetTrack-like object
    (``at``) or an (n_t, 4) array sampled at ``t``."""
    if hasattr(track, "at"):
        return tuple(np.asarray(a, dtype=float) * np.ones_like(t) for a in track.at(t))
    a = np.asarray(track, dtype=float)
    if a.shape != (t.size, 4):
        raise ValueError(f"target track: shape {a.shape}, expected ({t.size}, 4) = [north, east, "
                         "v_north, v_east] at every time")
    return a[:, 0], a[:, 1], a[:, 2], a[:, 3]


def _encounter_code(codes) -> int:
    """The encounter's situation: the code given, or the first non-safe code of a time series."""
    codes = np.atleast_1d(np.asarray(codes)).astype(int)
    risky = codes[codes != SAFE]
    return int(risky[0]) if risky.size else SAFE


def encounter_scores(t, own_north, own_east, own_course, own_speed, target, code,
                     config: ComplianceConfig | None = None) -> dict[str, float]:
    """The scores (module docstring) of the own ship's log against one target in situation
    ``code``, with the diagnostics ``cpa_m``, ``t_cpa_s``, ``action_range_m``,
    ``course_change_max_deg``, ``speed_reduction_max`` (fraction)."""
    c = config or ComplianceConfig()
    tn, te, tvn, tve = _target_samples(target, t)
    dn, de = tn - own_north, te - own_east
    rng = np.hypot(dn, de)
    k_cpa = int(np.argmin(rng))
    inside = np.nonzero(rng <= c.r_detect)[0]
    k0 = int(inside[0]) if inside.size else 0
    k0 = min(k0, k_cpa)
    window = slice(k0, k_cpa + 1)
    d_chi = wrap_angle(own_course[window] - own_course[k0])
    u0 = max(float(own_speed[k0]), 1e-9)
    d_u = (own_speed[window] - own_speed[k0]) / u0
    chi_md, chi_app = math.radians(c.course_change_md_deg), math.radians(c.course_change_app_deg)
    acted = (np.abs(d_chi) >= chi_md) | (np.abs(d_u) >= c.speed_change_md)
    k_act = int(np.argmax(acted)) if acted.any() else None
    r_act = float(rng[window][k_act]) if k_act is not None else 0.0
    chi_max = float(np.max(np.abs(d_chi)))
    slow_max = float(max(0.0, -np.min(d_u)))

    safety = float(safety_score(rng[k_cpa], c))
    p_delay = 1.0 if k_act is None else float(np.clip((c.r_early - r_act) / (c.r_early - c.r_late), 0.0, 1.0))
    p_na = 1.0 - min(1.0, max(chi_max / chi_app, slow_max / c.speed_change_app))
    scores = {name: math.nan for name in SCORES}
    scores["safety"] = safety
    if code in (HEAD_ON, OVERTAKING, GIVE_WAY):
        s16 = safety * (1.0 - p_delay) * (1.0 - p_na)
        scores["rule_16"] = s16
        if code == HEAD_ON:
            turns = np.nonzero(np.abs(d_chi) >= chi_md)[0]
            p_nsb = 0.0 if turns.size and d_chi[turns[0]] > 0.0 else 1.0
            beta_cpa = wrap_angle(math.atan2(de[k_cpa], dn[k_cpa]) - own_course[k_cpa])
            p_sts = 1.0 if beta_cpa > 0.0 else 0.0
            scores["rule_14"] = s16 * (1.0 - p_nsb) * (1.0 - p_sts)
        elif code == GIVE_WAY:
            alpha_cpa = wrap_angle(math.atan2(-de[k_cpa], -dn[k_cpa]) - math.atan2(tve[k_cpa], tvn[k_cpa]))
            p_ahead = 1.0 if abs(alpha_cpa) < math.pi / 2 else 0.0
            scores["rule_15"] = s16 * (1.0 - p_ahead)
    elif code in (STAND_ON, OVERTAKEN):
        far = rng[window] > c.r_late
        p_change = min(1.0, max(float(np.max(np.abs(d_chi[far]), initial=0.0)) / chi_app,
                                float(np.max(np.abs(d_u[far]), initial=0.0)) / c.speed_change_app))
        beta = wrap_angle(np.arctan2(de[window], dn[window]) - own_course[window])
        p_port = 1.0 if np.any((d_chi <= -chi_md) & (beta < 0.0)) else 0.0
        scores["rule_17"] = safety * (1.0 - p_change) * (1.0 - p_port)
    scores.update(cpa_m=float(rng[k_cpa]), t_cpa_s=float(t[k_cpa] - t[0]), action_range_m=r_act,
                  course_change_max_deg=math.degrees(chi_max), speed_reduction_max=slow_max)
    return scores


def compliance_scores(t, own_north, own_east, own_course, own_speed, tracks, situation_codes,
                      config: ComplianceConfig | None = None) -> dict[str, float]:
    """The scores of :data:`SCORES` of one own ship's log (times ``t`` [s], position [m], course
    [rad] and speed [m/s] over ground) against its targets (``tracks``: TargetTrack-like objects
    or (n_t, 4) arrays at ``t``), each in the situation of ``situation_codes`` (one code per
    target, or one time series per target whose first non-safe code counts): the minimum over the
    targets of each score, NaN where no encounter invokes the rule."""
    t = np.asarray(t, dtype=float)
    own = [np.asarray(a, dtype=float) for a in (own_north, own_east, own_course, own_speed)]
    for name, a in zip(("own_north", "own_east", "own_course", "own_speed"), own, strict=True):
        if a.shape != t.shape:
            raise ValueError(f"{name}: shape {a.shape}, expected the shape of t {t.shape}")
    if len(tracks) != len(situation_codes):
        raise ValueError(f"situation_codes: {len(situation_codes)} entries for {len(tracks)} targets")
    result = {name: math.nan for name in SCORES}
    for track, codes in zip(tracks, situation_codes, strict=True):
        scores = encounter_scores(t, *own, track, _encounter_code(codes), config)
        for name in SCORES:
            if not math.isnan(scores[name]):
                result[name] = scores[name] if math.isnan(result[name]) else min(result[name], scores[name])
    return result
