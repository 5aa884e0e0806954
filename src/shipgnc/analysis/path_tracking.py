"""Path-tracking metrics of document 000 (note 000-0.8), batched over ships.

Computed on the logged samples from the path-frame errors the controllers log
(``cross_track_error`` y_r [m], ``heading_error`` ψ_r [rad], ``leg``) and the applied rudder
``delta`` [rad]; reported in the document's units as the names say (min, nm, deg). "Leg 1" is the
time before the first leg switch.

* ``settle_time_min``: first time after which |y_r| < 0.05 nm holds for the rest of leg 1
  (null if never);
* ``overshoot_nm``: largest y_r of opposite sign to y_r(0) on leg 1, as a magnitude (0 if y_r
  never crosses, and 0 for a start on the path line, |y_r(0)| < 1 mm);
* ``crosstrack_max_after_leg1_nm``, ``crosstrack_rms_after_leg1_nm``: max |y_r| and RMS of y_r
  from the first switch to the end (null if leg 1 never ends);
* ``final_crosstrack_nm``, ``final_heading_error_deg``, ``final_rudder_deg``: means over the last
  10 min (signed; the heading error's is the circular mean, so a ship near ψ_r = ±180° reads
  ±180°, not 0);
* ``rudder_rms_deg``; ``saturation_fraction``: share of samples with |δ| at δ_max;
* ``stable`` (the one definition, :func:`shipgnc.analysis.metrics.stable_arrays`): the run
  reached its end without the divergence guard, |y_r| stayed below max(3 nm, 2|y_r(0)|) (note 000-0.8, [A]),
  over the last 20 % of the run y_r oscillates about its trend by at most 0.05 nm (the
  settling band) and the rudder is not pinned at both limits ±δ_max (no limit cycle, no
  saturated oscillation), and the ship is not ``reversed``;
* ``reversed``: the run ends with |heading error| > 90° (the final heading error above, the
  circular mean over the last 10 min): the reversed equilibrium ψ_r = π of note 000-0.5, a ship
  sailing its leg backwards with y_r bounded, which is not tracking.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from shipgnc.analysis.metrics import stable_arrays
from shipgnc.units import MINUTE, NAUTICAL_MILE, to_deg

#: |y_r| below which leg 1 counts as settled [m] (0.05 nm)
SETTLE_BAND = 0.05 * NAUTICAL_MILE
#: window of the "final" means [s] (10 min)
FINAL_WINDOW = 10.0 * MINUTE
#: bound on |y_r| for ``stable`` [m]: max(3 nm, 2 |y_r(0)|)
STABLE_BOUND = 3.0 * NAUTICAL_MILE
#: |y_r(0)| below which a start counts as on the path line [m] (no side to overshoot to)
ON_LINE = 1e-3

PATH_TRACKING_KEYS = ("settle_time_min", "overshoot_nm", "crosstrack_max_after_leg1_nm",
                      "crosstrack_rms_after_leg1_nm", "final_crosstrack_nm",
                      "final_heading_error_deg", "final_rudder_deg", "rudder_rms_deg",
                      "saturation_fraction", "stable", "reversed")
#: the keys reported as true|false
BOOL_KEYS = ("stable", "reversed")
#: |final heading error| beyond which a run counts as ``reversed`` [deg]
REVERSED_DEG = 90.0


#: ships scored together: every figure is the ship's own, and a block's temporaries (a few
#: arrays of time × block) stay small where a whole batch's would each be as large as the log
SHIPS_PER_BLOCK = 64


def path_tracking_arrays(time, y_r, psi_r, leg, delta, *, delta_max: float, reached_end) -> dict:
    """The metrics for every ship at once: arrays ``(time, ship)`` in SI → dict of ``(ship,)``
    float arrays in the reported units (NaN where a figure does not exist; ``stable`` and
    ``reversed`` as bool),
    plus ``final_abs_crosstrack_nm``, the mean |y_r| over the last 10 min.

    ``reached_end``: bool per ship (or one bool), False when the run stopped early (divergence).
    Samples after a run stopped (NaN padding) are ignored. The ships are scored in blocks of
    :data:`SHIPS_PER_BLOCK` (each figure is a ship's own: the same numbers, less memory).
    """
    t = np.asarray(time, dtype=float)
    y, psi, lg, d = (np.asarray(a, dtype=float).reshape(t.size, -1) for a in (y_r, psi_r, leg, delta))
    reached = np.broadcast_to(np.asarray(reached_end, dtype=bool), (y.shape[1],))
    blocks = [_path_tracking_block(t, y[:, i:i + SHIPS_PER_BLOCK], psi[:, i:i + SHIPS_PER_BLOCK],
                                   lg[:, i:i + SHIPS_PER_BLOCK], d[:, i:i + SHIPS_PER_BLOCK],
                                   delta_max, reached[i:i + SHIPS_PER_BLOCK])
              for i in range(0, max(y.shape[1], 1), SHIPS_PER_BLOCK)]
    return {key: np.concatenate([b[key] for b in blocks]) for key in blocks[0]}


def _path_tracking_block(t, y, psi, lg, d, delta_max: float, reached_end) -> dict:
    """:func:`path_tracking_arrays` of one block of ships.

    The sums run in compiled passes over the samples (:func:`_leg_pass`, :func:`_score_pass`),
    each added in time order as :func:`~shipgnc.batchmath.time_sum` adds the masked series (the
    same bits, without a time × block array per mask and figure)."""
    valid = np.isfinite(y) & np.isfinite(lg)
    n_t = y.shape[0]
    first_switch, t_last = _leg_pass(t, y, lg)
    has_switch = first_switch < n_t  # a first sample of leg 2+
    y0 = y[0]
    on_line = np.abs(y0) < ON_LINE
    final_from = t_last - FINAL_WINDOW - 1e-9  # the last 10 min of each ship's samples
    # sin ψ_r, cos ψ_r on the rows that hold a final window (numpy's, as on the whole series)
    k_min = _first_row_at(t, final_from)
    s = _score_pass(t, y, lg, d, np.sin(psi[k_min:]), np.cos(psi[k_min:]), k_min, first_switch,
                    final_from, -np.sign(y0), SETTLE_BAND, delta_max * (1.0 - 1e-9))
    (n_leg1, last_out, opposite, max_after, sum_after, n_after, n_final, sum_sin, sum_cos, sum_y,
     sum_abs, sum_d, sum_dd, n_applied, n_saturated) = s

    # settle time: the sample after the last leg-1 sample outside the band
    settle_idx = np.where(last_out >= 0, last_out + 1, 0)
    settled = (settle_idx < n_leg1) & (n_leg1 > 0)
    settle = np.where(settled, t[np.minimum(settle_idx, n_t - 1)] / MINUTE, np.nan)
    overshoot = np.where(on_line, 0.0, np.maximum(opposite, 0.0) / NAUTICAL_MILE)
    with np.errstate(invalid="ignore", divide="ignore"):
        max_after = np.where(has_switch, max_after, np.nan)
        rms_after = np.where(has_switch, np.sqrt(sum_after / n_after), np.nan)
        rudder_rms = np.sqrt(sum_dd / n_applied)
        saturation = n_saturated / n_applied
        final_sin, final_cos = sum_sin / n_final, sum_cos / n_final
        final_y, final_abs, final_d = sum_y / n_final, sum_abs / n_final, sum_d / n_final
    bound = np.maximum(STABLE_BOUND, 2.0 * np.abs(y0))
    final_heading = to_deg(np.arctan2(final_sin, final_cos))
    reversed_ = np.abs(final_heading) > REVERSED_DEG  # NaN (no valid sample) compares False
    verdict = stable_arrays(t, np.where(valid, y, np.nan), bound=bound,
                            oscillation_tol=SETTLE_BAND, reached=reached_end,
                            actuator=np.where(valid, d, np.nan), actuator_max=delta_max)
    return path_tracking_figures(
        settle_time_min=settle, overshoot_nm=overshoot, max_after=max_after, rms_after=rms_after,
        final_y=final_y, final_heading_deg=final_heading, final_delta=final_d,
        rudder_rms=rudder_rms, saturation=saturation, stable=verdict["stable"] & ~reversed_,
        reversed_=reversed_, final_abs=final_abs)


def path_tracking_figures(*, settle_time_min, overshoot_nm, max_after, rms_after, final_y,
                          final_heading_deg, final_delta, rudder_rms, saturation, stable,
                          reversed_, final_abs=None) -> dict:
    """The metric dict of :data:`PATH_TRACKING_KEYS` (and ``final_abs_crosstrack_nm`` when
    ``final_abs`` is given) from each ship's finished values, the one place the keys and their
    units are written: lengths in m (``max_after``, ``rms_after``: max |y_r| and RMS y_r after
    leg 1; ``final_y``, ``final_abs``: mean y_r and |y_r| over the last 10 min) → nm, angles in
    rad (``final_delta``, ``rudder_rms``) → deg; the settle time [min], overshoot [nm] and final
    heading error [deg] as given. Whether scored from the log (:func:`path_tracking_arrays`) or
    from the loop's accumulators (:func:`shipgnc.analysis.accumulated.path_tracking`)."""
    out = {
        "settle_time_min": settle_time_min,
        "overshoot_nm": overshoot_nm,
        "crosstrack_max_after_leg1_nm": max_after / NAUTICAL_MILE,
        "crosstrack_rms_after_leg1_nm": rms_after / NAUTICAL_MILE,
        "final_crosstrack_nm": final_y / NAUTICAL_MILE,
        "final_heading_error_deg": final_heading_deg,
        "final_rudder_deg": to_deg(final_delta),
        "rudder_rms_deg": to_deg(rudder_rms),
        "saturation_fraction": saturation,
        "stable": stable,
        "reversed": reversed_,
    }
    if final_abs is not None:
        out["final_abs_crosstrack_nm"] = final_abs / NAUTICAL_MILE
    return out


def _first_row_at(t, thresholds) -> int:
    """The first sample whose time reaches the lowest of ``thresholds`` (0 for none)."""
    if thresholds.size == 0:
        return t.size
    hit = t >= thresholds.min()
    return int(hit.argmax()) if hit.any() else t.size


@numba.njit(cache=True, error_model="numpy")
def _leg_pass(t, y, lg):
    """Per ship of ``(time, ship)`` series: the first valid sample past leg 1 (``leg > 0``;
    ``n_t`` if none) and the time of the last valid sample (−∞ if none); valid: y_r and leg
    finite."""
    n_t, n = y.shape
    first_switch = np.full(n, n_t, dtype=np.int64)
    t_last = np.full(n, -np.inf)
    for k in range(n_t):
        for m in range(n):
            if np.isfinite(y[k, m]) and np.isfinite(lg[k, m]):
                if lg[k, m] > 0 and first_switch[m] == n_t:
                    first_switch[m] = k
                if t[k] > t_last[m]:
                    t_last[m] = t[k]
    return first_switch, t_last


@numba.njit(cache=True, error_model="numpy")
def _score_pass(t, y, lg, d, sin_psi, cos_psi, k_min, first_switch, final_from, side, band,
                saturated_at):
    """The counts, extrema and sums of :func:`_path_tracking_block`, per ship, in one pass over
    the samples. Each sum is that of ``time_sum(np.where(mask, value, 0.0))``: every sample added
    in time order, a masked one as +0.0, the first onto −0.0 (the additive identity, so the
    total starts as the first sample's value). ``sin_psi``, ``cos_psi``: rows ``k_min`` on (no
    final window starts before). Maxima propagate NaN as ``np.max``."""
    n_t, n = y.shape
    n_leg1 = np.zeros(n, dtype=np.int64)
    last_out = np.full(n, -1, dtype=np.int64)
    opposite = np.full(n, -np.inf)
    max_after = np.full(n, -np.inf)
    sum_after = np.full(n, -0.0)
    n_after = np.zeros(n, dtype=np.int64)
    n_final = np.zeros(n, dtype=np.int64)
    sums = np.full((5, n), -0.0)  # sin ψ_r, cos ψ_r, y_r, |y_r|, δ (0 where not finite)
    sum_dd = np.full(n, -0.0)
    n_applied = np.zeros(n, dtype=np.int64)
    n_saturated = np.zeros(n, dtype=np.int64)
    for k in range(n_t):
        for m in range(n):
            yk, dk = y[k, m], d[k, m]
            valid = np.isfinite(yk) and np.isfinite(lg[k, m])
            leg1 = valid and k < first_switch[m]
            after = valid and k >= first_switch[m]
            if leg1:
                n_leg1[m] += 1
                if not (abs(yk) < band):
                    last_out[m] = k
                v = side[m] * yk
                if not np.isnan(opposite[m]) and (np.isnan(v) or v > opposite[m]):
                    opposite[m] = v
            if after:
                n_after[m] += 1
                if abs(yk) > max_after[m]:
                    max_after[m] = abs(yk)
            sum_after[m] += yk * yk if after else 0.0
            applied = valid and np.isfinite(dk)
            if applied:
                n_applied[m] += 1
                if abs(dk) >= saturated_at:
                    n_saturated[m] += 1
            sum_dd[m] += dk * dk if applied else 0.0
            if k < k_min:
                for j in range(5):
                    sums[j, m] += 0.0
                continue
            final = valid and t[k] >= final_from[m]
            if final:
                n_final[m] += 1
                sums[0, m] += sin_psi[k - k_min, m]
                sums[1, m] += cos_psi[k - k_min, m]
                sums[2, m] += yk
                sums[3, m] += abs(yk)
                sums[4, m] += dk if np.isfinite(dk) else 0.0
            else:
                for j in range(5):
                    sums[j, m] += 0.0
    return (n_leg1, last_out, opposite, max_after, sum_after, n_after, n_final, sums[0], sums[1],
            sums[2], sums[3], sums[4], sum_dd, n_applied, n_saturated)


def _series(ds, name: str) -> np.ndarray:
    values = np.asarray(ds[name].values, dtype=float)
    return values.reshape(values.shape[0], -1)


def path_tracking_metrics(ds, *, delta_max: float, diverged: bool = False) -> dict:
    """Note 000-0.8 metrics of a single-ship result (plain numbers, ``None`` where undefined)."""
    arrays = path_tracking_arrays(ds["time"].values, _series(ds, "cross_track_error"),
                                  _series(ds, "heading_error"), _series(ds, "leg"),
                                  _series(ds, "delta"), delta_max=delta_max,
                                  reached_end=not diverged)
    out = {}
    for key in PATH_TRACKING_KEYS:
        value = arrays[key][0]
        out[key] = bool(value) if key in BOOL_KEYS else (
            float(value) if math.isfinite(value) else None)
    return out


def montecarlo_summary(ds, *, delta_max: float, diverged: bool = False) -> dict:
    """Distribution of the path-tracking metrics over the ships of a batch result.

    ``runs``; ``settled_fraction`` and ``stable_fraction``; ``on_path_at_end_fraction``: runs whose
    mean |y_r| over the last 10 min is inside the settling band (0.05 nm) — a ship that ends
    off the path without oscillating (still approaching it, or held off by a bias) can be
    ``stable`` but is not on the path; median and 95th percentile of
    ``settle_time_min`` (a ship that never settles counts as +∞, so a percentile it reaches is
    null) and of ``crosstrack_rms_after_leg1_nm`` (a ship that never finishes leg 1 counts as +∞
    too: leaving them out would flatter a controller whose failures stay on leg 1).
    """
    arrays = path_tracking_arrays(ds["time"].values, _series(ds, "cross_track_error"),
                                  _series(ds, "heading_error"), _series(ds, "leg"),
                                  _series(ds, "delta"), delta_max=delta_max,
                                  reached_end=not diverged)
    return montecarlo_figures(arrays)


def montecarlo_figures(arrays: dict) -> dict:
    """:func:`montecarlo_summary` of the ships' figures ``arrays`` (:func:`path_tracking_arrays`'
    dict, or the same figures scored inside the loop)."""
    settle = np.where(np.isnan(arrays["settle_time_min"]), np.inf, arrays["settle_time_min"])
    rms = np.where(np.isnan(arrays["crosstrack_rms_after_leg1_nm"]), np.inf,
                   arrays["crosstrack_rms_after_leg1_nm"])

    def pct(values, q):
        if values.size == 0:
            return None
        value = float(np.percentile(values, q, method="higher"))
        return value if math.isfinite(value) else None

    on_path = arrays["final_abs_crosstrack_nm"] < SETTLE_BAND / NAUTICAL_MILE
    return {
        "runs": int(settle.size),
        "settled_fraction": float(np.isfinite(settle).mean()),
        "stable_fraction": float(arrays["stable"].mean()),
        "on_path_at_end_fraction": float(on_path.mean()),
        "settle_time_min_median": pct(settle, 50),
        "settle_time_min_p95": pct(settle, 95),
        "crosstrack_rms_after_leg1_nm_median": pct(rms, 50),
        "crosstrack_rms_after_leg1_nm_p95": pct(rms, 95),
    }
