"""COLREG situation of the own ship towards one target (COLREGs 1972, rules 13–17).

From the own ship's position, course and speed over ground and the target's position and velocity
(:mod:`shipgnc.colav.geometry`), with β the target's bearing relative to the own course and α the
own ship's bearing relative to the target's course (both wrapped to (−π, π], positive to
starboard):

0 ``safe``       no risk of collision: d_cpa > ``d_risk``, or t_cpa = 0 (opening), or
                 t_cpa > ``t_risk`` (rule 7 judged from the CPA, as bridge CPA/TCPA alarms do);
3 ``overtaken``  the target comes up from more than 22.5° abaft the own beam, |β| > 112.5°
                 (rule 13(b)): the target keeps clear, the own ship stands on (rule 17);
2 ``overtaking`` the own ship comes up from more than 22.5° abaft the target's beam, |α| > 112.5°
                 (rule 13): the own ship keeps clear;
1 ``head_on``    the target is ahead, |β| ≤ φ, on a reciprocal or nearly reciprocal course,
                 |χ_t − χ_o − π| ≤ φ (rule 14); φ = 6° after Tam & Bucknall (2010, "Collision
                 risk assessment for ships", J. Mar. Sci. Technol. 15) — both alter to starboard;
4 ``give_way``   crossing with the target on the own starboard side, 0 ≤ β ≤ 112.5° (rule 15):
                 the own ship keeps clear (rule 16) and avoids crossing ahead;
5 ``stand_on``   crossing with the target on the own port side, −112.5° ≤ β < 0 (rule 17): the own
                 ship keeps course and speed.

The checks run in this order (overtaking takes precedence over crossing, rule 13(a)). A target
slower than ``min_speed`` has no course: it cannot overtake nor meet head-on, and the own ship,
coming up with it, keeps clear (``overtaking``). An own ship slower than ``min_speed`` overtakes
nobody and meets nobody head-on.
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
from pydantic import Field

from shipgnc.colav.geometry import cpa
from shipgnc.config_types import NonNegative, Positive, Strict
from shipgnc.derive import per_ship
from shipgnc.kernels import flat, kernel_function, wrap

SAFE, HEAD_ON, OVERTAKING, OVERTAKEN, GIVE_WAY, STAND_ON = range(6)
#: the situations' names, indexed by code
SITUATIONS = ("safe", "head_on", "overtaking", "overtaken", "give_way", "stand_on")
#: the codes in which the own ship must keep out of the way (rules 13, 14, 15/16)
OWN_GIVES_WAY = (HEAD_ON, OVERTAKING, GIVE_WAY)


class ColregConfig(Strict):
    """When there is a risk of collision, and the sectors of rules 13 and 14."""

    d_risk: Positive = Field(1852.0, description="CPA distance below which a risk of collision exists [m] "
                                                 "(1 nm, a common bridge CPA alarm)")
    t_risk: Positive = Field(1200.0, description="time to CPA within which the risk is acted on [s] "
                                                 "(20 min, a common bridge TCPA alarm)")
    head_on_deg: float = Field(6.0, gt=0, lt=90, description="half-width of the head-on sectors of "
                               "bearing and reciprocal course (Tam & Bucknall 2010)")
    abaft_deg: float = Field(112.5, gt=90, lt=180, description="relative bearing beyond which a ship "
                             "comes up from abaft the beam (rule 13: 22.5° abaft)")
    min_speed: NonNegative = Field(0.1, description="speed below which a ship has no course [m/s]")

    field_units: ClassVar[dict[str, str]] = {"d_risk": "m", "t_risk": "s", "min_speed": "m/s"}


def colreg_params(config: ColregConfig | None = None) -> np.ndarray:
    """Flat parameters of :func:`situation`: [d_risk, t_risk, head-on half-width, abaft limit
    (radians), min_speed]."""
    c = config or ColregConfig()
    return flat(c.d_risk, c.t_risk, math.radians(c.head_on_deg), math.radians(c.abaft_deg), c.min_speed)


@kernel_function
def classify(pn, pe, course, speed, tn, te, tvn, tve, p):
    """The situation code (module docstring) of an own ship at (pn, pe) with ``course``, ``speed``
    towards a target at (tn, te) moving with (tvn, tve); ``p`` from :func:`colreg_params`."""
    d_risk, t_risk, head_on, abaft, min_speed = p[0], p[1], p[2], p[3], p[4]
    vn = speed * math.cos(course)
    ve = speed * math.sin(course)
    d_cpa, t_cpa = cpa(pn, pe, vn, ve, tn, te, tvn, tve)
    if d_cpa > d_risk or t_cpa <= 0.0 or t_cpa > t_risk:
        return SAFE
    own_moves = speed >= min_speed
    target_moves = math.hypot(tvn, tve) >= min_speed
    beta = wrap(math.atan2(te - pe, tn - pn) - course)
    if not target_moves:
        return OVERTAKING
    alpha = wrap(math.atan2(pe - te, pn - tn) - math.atan2(tve, tvn))
    if abs(beta) > abaft:
        return OVERTAKEN
    if own_moves and abs(alpha) > abaft:
        return OVERTAKING
    if own_moves and abs(beta) <= head_on and abs(wrap(math.atan2(tve, tvn) - course - math.pi)) <= head_on:
        return HEAD_ON
    if beta >= 0.0:
        return GIVE_WAY
    return STAND_ON


@kernel_function
def situation(own, target, p):
    """:func:`classify` for own = [north, east, course, speed], target = [north, east, v_north,
    v_east]."""
    return classify(own[0], own[1], own[2], own[3], target[0], target[1], target[2], target[3], p)


def situations(own, target, config: ColregConfig | None = None) -> np.ndarray:
    """Situation codes (int) of every own/target pair (leading shapes broadcast), the batch of
    :func:`situation`; names in :data:`SITUATIONS`."""
    own = np.asarray(own, dtype=float)
    target = np.asarray(target, dtype=float)
    for name, a in (("own", own), ("target", target)):
        if a.ndim < 1 or a.shape[-1] != 4:
            raise ValueError(f"{name}: last axis must have 4 entries, got shape {a.shape}")
    return per_ship(situation, "i i p -> r")(own, target, colreg_params(config)).astype(int)
