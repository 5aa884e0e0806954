"""The ``colav`` metric set: how an own ship came through its encounters.

Per member of a run (one encounter each), from the logged outputs of the collision-avoidance guidance
(:class:`shipgnc.guidance.colav.ColavGuidance`):

* ``min_range_m``, ``t_min_range_s`` — the smallest distance to any target over the run and when:
  the realised closest point of approach (CPA), kept by the guidance at each of its samples
  (``range_min``), so a thinned log loses nothing; ``cpa_target`` the target it was to (0-based);
* ``collision`` — 1 when the minimum range fell below the safety radius (the ship domain,
  ``guidance.safety_radius``), else 0: a collision is a scored outcome, the run goes on;
* ``distance_lost_m``, ``time_lost_s`` — how far the ship is behind the nominal voyage at the end:
  the nominal distance U_n·t_end (at most the path's length) less the distance made good along the
  path (the legs completed plus the along-track distance on the active leg), and that distance at
  the nominal speed, ΔT = ΔS / U_n;
* ``max_cross_track_m`` — the largest cross-track deviation from the nominal path.
"""

from __future__ import annotations

import math

import numpy as np

#: the keys of :func:`colav_arrays`, in order
COLAV_KEYS = ("min_range_m", "t_min_range_s", "cpa_target", "collision", "distance_lost_m",
              "time_lost_s", "max_cross_track_m")


def colav_arrays(t, range_min, t_range_min, target_range_min, leg, along_track, cross_track, *,
                 leg_lengths, speed: float, safety_radius: float) -> dict[str, np.ndarray]:
    """The metric set for a batch: ``t`` (time,); the guidance's running least range, its time and
    target, ``leg``, ``along_track``, ``cross_track`` (time, member); returns (member,) arrays keyed
    by :data:`COLAV_KEYS`."""
    t = np.asarray(t, dtype=float)
    min_range = np.asarray(range_min[-1], dtype=float)
    starts = np.concatenate([[0.0], np.cumsum(leg_lengths)])
    made_good = starts[np.asarray(leg[-1], dtype=int)] + np.asarray(along_track[-1], dtype=float)
    nominal = min(speed * (t[-1] - t[0]), float(starts[-1]))
    lost = nominal - made_good
    return {
        "min_range_m": min_range,
        "t_min_range_s": np.asarray(t_range_min[-1], dtype=float),
        "cpa_target": np.asarray(target_range_min[-1], dtype=float),
        "collision": (min_range < safety_radius).astype(float),
        "distance_lost_m": lost,
        "time_lost_s": lost / speed,
        "max_cross_track_m": np.nanmax(np.abs(cross_track), axis=0),
    }


def _two(result, name) -> np.ndarray:
    """The variable ``name`` of a result as (time, member) (a single run: one member)."""
    a = result[name].values
    return a.reshape(a.shape[0], -1)


def batch_arrays(result, guidance, safety_radius: float) -> dict[str, np.ndarray]:
    """:func:`colav_arrays` of a result with a member dimension (or none: one member)."""
    def two(name):
        return _two(result, name)

    return colav_arrays(result["time"].values, two("range_min"), two("t_range_min"),
                        two("target_range_min"), two("leg"), two("along_track"),
                        two("cross_track_error"), leg_lengths=guidance.path.leg_lengths,
                        speed=guidance.speed, safety_radius=safety_radius)


def score(scenario, result, setup) -> dict:
    """The ``colav`` metric set of one run (the registry's scorer)."""
    arrays = batch_arrays(result, setup.guidance, scenario.guidance.safety_radius)
    out = {}
    for key in COLAV_KEYS:
        value = float(arrays[key][0])
        if not math.isfinite(value):  # no target at all: no CPA
            out[key] = None
        else:
            out[key] = int(value) if key in ("collision", "cpa_target") else value
    return out


def compliance_arrays(result, members_tracks, codes, configs=None) -> dict[str, np.ndarray]:
    """COLREG compliance after Woerner (:func:`shipgnc.colav.compliance.compliance_scores`) of
    every member of a batch result: ``members_tracks`` one list of targets per member, ``codes``
    their situations at t = 0 (member, target), ``configs`` one ComplianceConfig per member (None:
    the defaults). Returns (member,) arrays: each rule's score
    (``rule_14`` … ``rule_17``, NaN where no encounter invokes it) and ``compliance``, the least
    score of the rules the member's encounters invoke (the safety score is ``safety``)."""
    from shipgnc.colav.compliance import SCORES, compliance_scores
    from shipgnc.guidance.colav import course_over_ground

    t = result["time"].values

    def two(name):
        return _two(result, name)

    north, east, psi, u = two("north"), two("east"), two("psi"), two("u")
    v = two("v") if "v" in result else np.zeros_like(u)
    course, speed = course_over_ground.py_func(psi, u, v), np.hypot(u, v)
    out = {name: np.full(len(members_tracks), np.nan) for name in (*SCORES, "compliance")}
    for k, tracks in enumerate(members_tracks):
        scores = compliance_scores(t, north[:, k], east[:, k], course[:, k], speed[:, k], tracks,
                                   list(codes[k][:len(tracks)]),
                                   None if configs is None else configs[k])
        for name in SCORES:
            out[name][k] = scores[name]
        rules = [scores[name] for name in SCORES if name != "safety" and not np.isnan(scores[name])]
        out["compliance"][k] = min(rules) if rules else np.nan
    return out
