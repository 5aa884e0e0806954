"""The ``colav`` metric set: how an own ship came through its encounters.

Per member of a run (one encounter each), from the logged own-ship track and the targets' states
(the result's ``target`` dimension, :meth:`shipgnc.guidance.colav.ColavGuidance.add_targets`):

* ``min_range_m``, ``t_min_range_s`` — the smallest distance to any target over the run and when:
  the realised closest point of approach (CPA); ``cpa_target`` the target it was to (0-based);
* ``collision`` — 1 when the minimum range fell below the safety radius (the ship domain,
  ``guidance.safety_radius``), else 0: a collision is a scored outcome, the run goes on;
* ``distance_lost_m``, ``time_lost_s`` — how far the ship is behind the nominal voyage at the end:
  the nominal distance U_n·t_end (at most the path's length) less the distance made good along the
  path (the legs completed plus the along-track distance on the active leg), and that distance at
  the nominal speed, ΔT = ΔS / U_n;
* ``max_cross_track_m`` — the largest cross-track deviation from the nominal path.
"""

from __future__ import annotations

import numpy as np

#: the keys of :func:`colav_arrays`, in order
COLAV_KEYS = ("min_range_m", "t_min_range_s", "cpa_target", "collision", "distance_lost_m",
              "time_lost_s", "max_cross_track_m")


def colav_arrays(t, north, east, target_north, target_east, leg, along_track, cross_track, *,
                 leg_lengths, speed: float, safety_radius: float) -> dict[str, np.ndarray]:
    """The metric set for a batch: ``t`` (time,), own-ship ``north``, ``east``, ``leg``,
    ``along_track``, ``cross_track`` (time, member), targets (time, member, target), NaN for a
    member's absent targets; returns (member,) arrays keyed by :data:`COLAV_KEYS`."""
    t = np.asarray(t, dtype=float)
    rng = np.hypot(target_north - north[..., None], target_east - east[..., None])
    flat = np.where(np.isnan(rng), np.inf, rng).reshape(t.size, rng.shape[1], -1)
    n_members = flat.shape[1]
    if flat.shape[2] == 0:  # no targets at all
        min_range = np.full(n_members, np.inf)
        k = np.zeros(n_members, dtype=int)
        j = np.zeros(n_members, dtype=int)
    else:
        per_time = flat.min(axis=2)
        k = np.argmin(per_time, axis=0)
        min_range = per_time[k, np.arange(n_members)]
        j = np.argmin(flat[k, np.arange(n_members)], axis=1)
    starts = np.concatenate([[0.0], np.cumsum(leg_lengths)])
    last_leg = np.asarray(leg[-1], dtype=int)
    made_good = starts[last_leg] + np.asarray(along_track[-1], dtype=float)
    nominal = min(speed * (t[-1] - t[0]), float(starts[-1]))
    lost = nominal - made_good
    return {
        "min_range_m": min_range,
        "t_min_range_s": np.where(np.isfinite(min_range), t[k], np.nan),
        "cpa_target": np.where(np.isfinite(min_range), j, -1).astype(float),
        "collision": (min_range < safety_radius).astype(float),
        "distance_lost_m": lost,
        "time_lost_s": lost / speed,
        "max_cross_track_m": np.nanmax(np.abs(cross_track), axis=0),
    }


def batch_arrays(result, guidance, safety_radius: float) -> dict[str, np.ndarray]:
    """:func:`colav_arrays` of a result with a member dimension (or none: one member)."""
    def two(name):
        a = result[name].values
        return a.reshape(a.shape[0], -1)

    tn, te = result["target_north"].values, result["target_east"].values
    tn, te = tn.reshape(tn.shape[0], -1, tn.shape[-1]), te.reshape(te.shape[0], -1, te.shape[-1])
    return colav_arrays(result["time"].values, two("north"), two("east"), tn, te, two("leg"),
                        two("along_track"), two("cross_track_error"),
                        leg_lengths=guidance.path.leg_lengths, speed=guidance.speed,
                        safety_radius=safety_radius)


def score(scenario, result, setup) -> dict:
    """The ``colav`` metric set of one run (the registry's scorer)."""
    arrays = batch_arrays(result, setup.guidance, scenario.guidance.safety_radius)
    out = {}
    for key in COLAV_KEYS:
        value = float(arrays[key][0])
        out[key] = int(value) if key in ("collision", "cpa_target") else value
    return out
