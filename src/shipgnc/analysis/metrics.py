"""Scenario metrics computed from a result Dataset, as notes 001-1.9–001-1.10 and note 003-3.8 define
them.

Each metric set is computed once, for every ship of a batch at once: ``*_arrays`` functions take
the logged series as arrays ``(time, ship)`` and return a dict of ``(ship,)`` arrays (NaN where a
figure does not exist), so that a study scores a chunk of members in one pass. The single-ship
functions (``*_metrics``) take a one-ship ``xarray.Dataset`` (see :mod:`shipgnc.sim.result`) and
return the same figures as plain Python numbers (``None`` where a figure does not exist, e.g. a run
that never settles). A metric's name carries the unit it is reported in.
"""

from __future__ import annotations

import itertools
import math

import numba
import numpy as np

from shipgnc.batchmath import time_mean, time_sum
from shipgnc.frames import path_frame, wrap_angle
from shipgnc.units import to_deg


def _sign(value: float) -> int:
    return int(np.sign(value))


def _at(ds, name: str, t: float) -> float:
    """Value of ``name`` at the sample nearest to ``t``."""
    return float(ds[name].sel(time=t, method="nearest"))


def _number(value) -> float | None:
    value = float(value)
    return value if math.isfinite(value) else None


def turn_window(times: np.ndarray, alpha_cmd: np.ndarray) -> tuple[float, float]:
    """Start and end of the first turn command (first sample with α_cmd ≠ 0, first one after it
    with α_cmd back at 0, or the end of the run)."""
    on = np.flatnonzero(alpha_cmd != 0)
    if on.size == 0:
        return float(times[0]), float(times[-1])
    start = on[0]
    off = np.flatnonzero(alpha_cmd[start:] == 0)
    end = start + off[0] if off.size else len(times) - 1
    return float(times[start]), float(times[end])


STERN_KICK_KEYS = ("initial_sway_sign", "initial_yaw_rate_sign", "steady_yaw_rate_sign",
                   "max_speed_mps", "final_speed_mps", "heading_change_deg",
                   "stern_kick_min_lateral_m", "steady_yaw_rate_rad_s", "final_heading_deg")


def stern_kick_metrics(ds) -> dict:
    """Metrics of the open-loop turn (note 001-1.9).

    With the turn commanded over [t_on, t_off]: ``initial_sway_sign`` and
    ``initial_yaw_rate_sign`` are the signs of v and r at t_on + dt; ``steady_yaw_rate_sign`` and
    ``steady_yaw_rate_rad_s`` use the mean r over the last 40 % of the turn ([8, 10] s in the
    document's sequence); ``heading_change_deg`` = ψ(t_off) − ψ(t_on); ``max_speed_mps`` and
    ``final_speed_mps`` use U = √(u² + v²); ``stern_kick_min_lateral_m`` is the least lateral
    offset of the CG during the turn, in the frame of the heading at t_on (positive to starboard).
    A run without a turn command has the speeds and the final heading only; the turn's figures
    are ``None`` and ``note`` names them and says why.
    """
    t = ds.time.values
    if t.size < 2 or not np.any(ds.alpha_cmd.values != 0):
        # no turn inside the run (a schedule without one, too short, or diverged first): the
        # speeds and the final heading exist, the turn's figures do not; the note says which
        speed = np.hypot(ds.u.values, ds.v.values)
        out = dict.fromkeys(STERN_KICK_KEYS)
        out.update(max_speed_mps=float(speed.max()), final_speed_mps=float(speed[-1]),
                   final_heading_deg=float(to_deg(ds.psi.values[-1])))
        undefined = [key for key, value in out.items() if value is None]
        why = ("the run holds a single sample" if t.size < 2 else
               "the thruster angle command alpha_cmd is 0 throughout the run (no turn window)")
        out["note"] = f"{', '.join(undefined)}: undefined, {why}"
        return out
    dt = float(t[1] - t[0])
    t_on, t_off = turn_window(t, ds.alpha_cmd.values)
    speed = np.hypot(ds.u.values, ds.v.values)
    steady = (t >= t_off - 0.4 * (t_off - t_on)) & (t <= t_off)
    r_steady = float(ds.r.values[steady].mean())
    turn = (t >= t_on) & (t <= t_off)
    _, lateral = path_frame(ds.north.values[turn], ds.east.values[turn], _at(ds, "north", t_on),
                            _at(ds, "east", t_on), _at(ds, "psi", t_on))
    return {
        "initial_sway_sign": _sign(_at(ds, "v", t_on + dt)),
        "initial_yaw_rate_sign": _sign(_at(ds, "r", t_on + dt)),
        "steady_yaw_rate_sign": _sign(r_steady),
        "max_speed_mps": float(speed.max()),
        "final_speed_mps": float(speed[-1]),
        "heading_change_deg": float(to_deg(_at(ds, "psi", t_off) - _at(ds, "psi", t_on))),
        "stern_kick_min_lateral_m": float(lateral.min()),
        "steady_yaw_rate_rad_s": r_steady,
        "final_heading_deg": float(to_deg(ds.psi.values[-1])),
    }


def series(ds, name: str) -> np.ndarray:
    """The logged variable ``name`` as a float array ``(time, ship)`` (one column for one ship)."""
    values = np.asarray(ds[name].values, dtype=float)
    return values.reshape(values.shape[0], -1)


def _scalar(value, kind=float):
    """A figure of a one-ship array as a plain number (``None`` where it does not exist)."""
    value = float(value)
    return kind(value) if math.isfinite(value) else None


def heading_step_arrays(t, psi_error, psi_d, alpha, thrust, thrust_cmd, u, step_times,
                        tolerance_deg: float = 2.0) -> dict:
    """The heading-step figures of :func:`heading_step_metrics` for every ship: arrays
    ``(time, ship)`` in SI → ``(ship,)`` arrays (``settling_times_s``: ``(step, ship)``)."""
    t = np.asarray(t, dtype=float)
    err = to_deg(psi_error)
    bounds = [*step_times, t[-1] + 1.0]
    settling, overshoot = [], []
    for t_k, t_next in itertools.pairwise(bounds):
        window = (t >= t_k - 1e-9) & (t < t_next - 1e-9)
        if not window.any():
            continue
        e_w, t_w = err[window], t[window]
        bad = np.abs(e_w) > tolerance_deg
        after_last_bad = e_w.shape[0] - bad[::-1].argmax(axis=0)  # index after the last bad sample
        settle_at = t_w[np.minimum(after_last_bad, t_w.size - 1)] - t_k
        settling.append(np.where(~bad.any(axis=0), 0.0,
                                 np.where(after_last_bad < t_w.size, settle_at, np.nan)))
        earlier = np.flatnonzero(t < t_k - 1e-9)
        before = psi_d[earlier[-1]] if earlier.size else psi_d[0]
        direction = np.sign(wrap_angle(psi_d[window][0] - before))
        overshoot.append(np.maximum(0.0, np.max(direction * e_w, axis=0)))
    n_ships = err.shape[1]
    steps = np.array(settling).reshape(-1, n_ships)
    settle = (np.max(steps, axis=0) if steps.shape[0] else np.full(n_ships, np.nan))  # NaN if any
    return {
        "heading_rmse_deg": np.sqrt(time_mean(err**2)),
        "settling_time_s": settle,
        "overshoot_deg": np.max(np.array(overshoot), axis=0) if overshoot else np.zeros(n_ships),
        "max_thruster_angle_deg": to_deg(np.abs(alpha).max(axis=0)),
        "max_thrust_n": thrust.max(axis=0),
        "settling_times_s": steps,
        "max_thrust_cmd_n": thrust_cmd.max(axis=0),
        "final_speed_mps": u[-1],
    }


def heading_step_metrics(ds, step_times, tolerance_deg: float = 2.0) -> dict:
    """Metrics of heading-step tracking (note 001-1.10), with e_ψ = wrap(ψ − ψ_d).

    ``heading_rmse_deg``: RMS of e_ψ over the run. For each step at t_k, its settling time is the
    first sample time after which |e_ψ| ≤ 2° holds until the next step (or the end), minus t_k;
    ``settling_time_s`` is the largest (``None`` if some step never settles). ``overshoot_deg``:
    the largest max(0, sign(Δψ_d)·e_ψ) after a step. ``max_thruster_angle_deg`` and
    ``max_thrust_n`` use the applied input; ``max_thrust_cmd_n`` the command.
    """
    a = heading_step_arrays(ds.time.values, series(ds, "psi_error"), series(ds, "psi_d"),
                            series(ds, "alpha"), series(ds, "T"), series(ds, "T_cmd"),
                            series(ds, "u"), step_times, tolerance_deg)
    out = {key: _scalar(value[0]) for key, value in a.items() if key != "settling_times_s"}
    out["settling_times_s"] = [_scalar(v) for v in a["settling_times_s"][:, 0]]
    out["overshoot_deg"] = float(a["overshoot_deg"][0])
    return {key: out[key] for key in a}


def waypoint_arrays(t, leg, along, cross, alpha, leg_lengths, capture_distance: float = 20.0) -> dict:
    """The waypoint figures of :func:`waypoint_metrics` for every ship: arrays ``(time, ship)`` →
    ``(ship,)`` arrays; each ship's samples after its own completion are left out."""
    t = np.asarray(t, dtype=float)
    leg = np.asarray(leg).astype(int)
    last = len(leg_lengths) - 1
    done = (leg == last) & (along >= leg_lengths[last])
    any_done = done.any(axis=0)
    end = np.where(any_done, done.argmax(axis=0) + 1, t.size)  # samples kept, per ship
    keep = np.arange(t.size)[:, None] < end
    captured = keep & (along >= capture_distance)
    n_captured = captured.sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        rms = np.sqrt(time_sum(np.where(captured, cross**2, 0.0)) / n_captured)
    peak = np.max(np.where(captured, np.abs(cross), -np.inf), axis=0)
    peak_all = np.max(np.where(keep & np.isfinite(cross), np.abs(cross), -np.inf), axis=0)
    return {
        "completion_time_s": np.where(any_done, t[done.argmax(axis=0)], np.nan),
        "crosstrack_rms_m": np.where(n_captured > 0, rms, np.nan),
        "crosstrack_max_m": np.where(n_captured > 0, peak, np.nan),
        "crosstrack_max_all_m": np.where(np.isfinite(peak_all), peak_all, np.nan),
        "waypoints_reached": np.max(np.where(keep, leg, -1), axis=0) + any_done,
        "max_thruster_angle_deg": to_deg(np.max(np.where(keep, np.abs(alpha), -np.inf), axis=0)),
        "final_crosstrack_m": np.take_along_axis(cross, (end - 1)[None, :], axis=0)[0],
    }


def waypoint_metrics(ds, leg_lengths, capture_distance: float = 20.0) -> dict:
    """Metrics of waypoint following (note 001-1.10).

    ``completion_time_s``: first sample at which the along-track distance reaches the end of the
    last leg (``None`` if never). ``crosstrack_max_m`` / ``crosstrack_rms_m``: max |e| and RMS of
    e over the samples with along-track distance ≥ ``capture_distance`` (20 m) on their own leg —
    the first 20 m of every leg, where the boat turns onto it and overshoots, are left out (the
    window of note 001-1.10). ``crosstrack_max_all_m``: max |e| over the whole run, the turns onto
    each leg included.
    ``waypoints_reached``: waypoints after the start whose leg was completed. Samples after the
    completion are left out (a ship of a batch keeps sailing until every ship is done).
    """
    a = waypoint_arrays(ds.time.values, series(ds, "leg"), series(ds, "along_track"),
                        series(ds, "cross_track_error"), series(ds, "alpha"), leg_lengths,
                        capture_distance)
    out = {key: _scalar(value[0]) for key, value in a.items()}
    out["waypoints_reached"] = int(a["waypoints_reached"][0])
    out["final_crosstrack_m"] = float(a["final_crosstrack_m"][0])
    return out


#: share of the run (or of each reference segment) whose end must show no sustained oscillation
STABLE_FINAL_FRACTION = 0.2
#: share of a final window's samples at *each* actuator limit above which the actuator counts as
#: pinned at saturation in alternating sign (a bang-bang limit cycle)
STABLE_PINNED_FRACTION = 0.05
#: the heading error's oscillation amplitude above which a course-keeping run is not stable [deg]
COURSE_OSCILLATION_DEG = 5.0
#: the heading error a course-keeping run must stay below to be bounded [deg]
COURSE_BOUND_DEG = 90.0
#: ``settled``: |Δψ| within this band [deg] over the last window [s] of the run
COURSE_SETTLE_BAND_DEG = 2.0
COURSE_SETTLE_WINDOW_S = 30.0


def stable_arrays(t, error, *, bound, oscillation_tol, reached=True, diverged=False,
                  actuator=None, actuator_max=None, segments=None,
                  final_fraction: float = STABLE_FINAL_FRACTION,
                  pinned_fraction: float = STABLE_PINNED_FRACTION) -> dict:
    """Whether each run of a batch is **stable**: bounded *and* converged; the one definition of
    ``stable`` for every metric set of shipgnc.

    Arrays ``(time, ship)`` (NaN after a ship's run stopped); ``error`` is the tracked error (a
    heading error [rad], a cross-track error [m]) and ``bound`` / ``oscillation_tol`` are in its
    unit (``bound`` a number or a ``(ship,)`` array). A run is stable when all of:

    1. *reached*: it ran to its end, and the divergence guard did not stop it (``diverged``);
    2. *bounded*: |e| < ``bound`` on every sample;
    3. *no limit cycle*: over the final window — the last ``final_fraction`` (20 %) of the run, or
       of each segment when ``segments`` labels the samples (a new segment wherever the label
       changes, e.g. each course step) — the error's oscillation amplitude
       A = ½ (max ρ − min ρ), with ρ the error minus its least-squares straight line over the
       window (a slow monotone approach is not an oscillation), is at most ``oscillation_tol``;
    4. *no saturated oscillation*: in no final window does the ``actuator`` sit at +``actuator_max``
       *and* at −``actuator_max`` on at least ``pinned_fraction`` (5 %) of the samples each.

    Returns ``stable`` (bool), ``bounded`` (bool), ``oscillation`` (the largest A over the final
    windows, in the error's unit) and ``saturated_oscillation`` (bool), each ``(ship,)``.
    """
    t = np.asarray(t, dtype=float)
    e = np.asarray(error, dtype=float).reshape(t.size, -1)
    n_ships = e.shape[1]
    finite = np.isfinite(e)
    bound = np.broadcast_to(np.asarray(bound, dtype=float), (n_ships,))
    bounded = np.all(~finite | (np.abs(np.where(finite, e, 0.0)) < bound), axis=0)
    labels = (np.zeros(t.size) if segments is None
              else np.asarray(segments, dtype=float).reshape(t.size))
    starts = np.flatnonzero(np.r_[True, labels[1:] != labels[:-1]])
    ends = np.r_[starts[1:], t.size]
    amplitude = np.zeros(n_ships)
    pinned = np.zeros(n_ships, dtype=bool)
    act = None if actuator is None else np.asarray(actuator, dtype=float).reshape(t.size, -1)
    has_act = act is not None and actuator_max is not None
    limit = float(actuator_max) * (1.0 - 1e-6) if has_act else 0.0
    act = np.broadcast_to(act, e.shape) if has_act else e[:0]  # as np.where would broadcast it
    for i0, i1 in zip(starts, ends, strict=True):
        # each ship's own final window: the last fraction of its finite samples in this segment
        t_first, t_last = _segment_span(t, e, i0, i1)
        with np.errstate(invalid="ignore"):  # a ship without a finite sample here: no window
            window_from = t_last - final_fraction * (t_last - t_first) - 1e-9
            center = 0.5 * (t_first + t_last)
        n, s_t, s_e, s_tt, s_te, n_high, n_low = _window_sums(t, e, act, has_act, i0, i1,
                                                              window_from, center, limit)
        if not np.any(n >= 3):
            continue
        with np.errstate(invalid="ignore", divide="ignore"):
            det = n * s_tt - s_t * s_t
            slope = np.where(det > 0, (n * s_te - s_t * s_e) / det, 0.0)
            intercept = np.where(n > 0, (s_e - slope * s_t) / n, 0.0)
        rho_max, rho_min = _residual_range(t, e, i0, i1, window_from, center, slope, intercept)
        half_range = 0.5 * (rho_max - rho_min)
        amplitude = np.maximum(amplitude, np.where(n >= 3, half_range, 0.0))
        if has_act:
            with np.errstate(invalid="ignore", divide="ignore"):
                high = n_high / n
                low = n_low / n
            pinned |= (n >= 3) & (high >= pinned_fraction) & (low >= pinned_fraction)
    reached = np.broadcast_to(np.asarray(reached, dtype=bool), (n_ships,))
    diverged = np.broadcast_to(np.asarray(diverged, dtype=bool), (n_ships,))
    stable = reached & ~diverged & bounded & (amplitude <= oscillation_tol) & ~pinned
    return {"stable": stable, "bounded": bounded, "oscillation": amplitude,
            "saturated_oscillation": pinned}


@numba.njit(cache=True, error_model="numpy")
def _segment_span(t, e, i0, i1):
    """First and last time of each ship's finite samples ``i0 <= k < i1`` (+∞, −∞ if none)."""
    n = e.shape[1]
    t_first, t_last = np.full(n, np.inf), np.full(n, -np.inf)
    for k in range(i0, i1):
        for m in range(n):
            if np.isfinite(e[k, m]):
                t_first[m] = min(t_first[m], t[k])
                t_last[m] = max(t_last[m], t[k])
    return t_first, t_last


@numba.njit(cache=True, error_model="numpy")
def _window_sums(t, e, act, has_act, i0, i1, window_from, center, limit):
    """Over each ship's final window (its finite samples ``i0 <= k < i1`` from ``window_from``
    on): the sample count n, Σ tc, Σ e, Σ tc², Σ tc·e (tc = t − ``center``) and the counts of
    ``act`` ≥ ``limit`` and ≤ −``limit``. Each sum is ``time_sum`` of the masked series over
    the whole log, to the bit: the samples added in time order, a masked one as +0.0, the first
    onto −0.0 (the additive identity)."""
    n_t, n = e.shape
    out = np.full((7, n), -0.0)
    if i0 > 0:
        out += 0.0  # the samples before the segment
    for k in range(i0, i1):
        for m in range(n):
            ek = e[k, m]
            if np.isfinite(ek) and t[k] >= window_from[m]:
                tc = t[k] - center[m]
                out[0, m] += 1.0
                out[1, m] += tc
                out[2, m] += ek
                out[3, m] += tc * tc
                out[4, m] += tc * ek
                out[5, m] += 1.0 if has_act and act[k, m] >= limit else 0.0
                out[6, m] += 1.0 if has_act and act[k, m] <= -limit else 0.0
            else:
                for j in range(7):
                    out[j, m] += 0.0
    if i1 < n_t:
        out += 0.0  # the samples after it
    return out[0], out[1], out[2], out[3], out[4], out[5], out[6]


@numba.njit(cache=True, error_model="numpy")
def _residual_range(t, e, i0, i1, window_from, center, slope, intercept):
    """Largest and smallest residual ρ = e − (intercept + slope·tc) over each ship's final
    window (see :func:`_window_sums`; −∞, +∞ if empty; NaN propagates as in ``np.max``)."""
    n = e.shape[1]
    high, low = np.full(n, -np.inf), np.full(n, np.inf)
    for k in range(i0, i1):
        for m in range(n):
            ek = e[k, m]
            if np.isfinite(ek) and t[k] >= window_from[m]:
                rho = ek - (intercept[m] + slope[m] * (t[k] - center[m]))
                if not np.isnan(high[m]) and (np.isnan(rho) or rho > high[m]):
                    high[m] = rho
                if not np.isnan(low[m]) and (np.isnan(rho) or rho < low[m]):
                    low[m] = rho
    return high, low


def _segments_of(reference) -> np.ndarray | None:
    """Segment labels ``(time,)`` of a piecewise-constant reference shared by the batch (a
    schedule): a new segment at every change. It is read from the ship with the most finite
    samples (a ship whose run stopped early is NaN afterwards), NaNs carried forward, so a stopped
    ship does not cut the others' segments."""
    if reference is None:
        return None
    ref = np.asarray(reference, dtype=float)
    ref = ref.reshape(ref.shape[0], -1)
    ref = ref[:, int(np.argmax(np.isfinite(ref).sum(axis=0)))]
    finite = np.isfinite(ref)
    if not finite.any():
        return np.zeros(ref.shape[0], dtype=int)
    last = np.maximum.accumulate(np.where(finite, np.arange(ref.size), 0))
    filled = ref[last]
    filled[: int(np.argmax(finite))] = ref[int(np.argmax(finite))]
    changed = np.r_[False, np.abs(np.diff(filled)) > 1e-12]
    return np.cumsum(changed)


def actuator_motion_arrays(t, actuator) -> tuple[np.ndarray, np.ndarray]:
    """RMS rate [unit/s] and travel Σ|Δa| [unit] of an actuator series ``(time, ship)`` (samples
    after a ship's run stopped, NaN, are left out)."""
    t = np.asarray(t, dtype=float)
    a = np.asarray(actuator, dtype=float).reshape(t.size, -1)
    step = np.diff(a, axis=0)
    ok = np.isfinite(step)
    step0 = np.where(ok, step, 0.0)
    dt = np.diff(t)[:, None]
    with np.errstate(invalid="ignore", divide="ignore"):
        rate_rms = np.sqrt(time_sum(np.where(ok, (step0 / dt) ** 2, 0.0)) / time_sum(ok))
    return np.where(time_sum(ok) > 0, rate_rms, np.nan), time_sum(np.abs(step0))


def rudder_rate_limit(actuator) -> float | None:
    """The steering machine's rudder rate limit [rad/s] (channel ``delta`` of ``actuator``), None
    without an actuator or that channel."""
    if actuator is None or "delta" not in actuator.names:
        return None
    return float(actuator.rate[actuator.names.index("delta")])


def rate_limit_fraction(t, actuator, rate: float | None, rel_tol: float = 1e-6) -> np.ndarray:
    """Fraction of the sample intervals in which the actuator series ``(time, ship)`` moves at its
    rate limit ``rate`` [unit/s]: |Δa/Δt| ≥ rate (1 − ``rel_tol``) (a rate-limited steering
    machine moves exactly rate·Δt then). NaN without a finite rate limit or samples."""
    t = np.asarray(t, dtype=float)
    a = np.asarray(actuator, dtype=float).reshape(t.size, -1)
    step = np.diff(a, axis=0)
    ok = np.isfinite(step)
    if rate is None or not np.isfinite(rate):
        return np.full(a.shape[1], np.nan)
    with np.errstate(invalid="ignore"):
        at_limit = ok & (np.abs(step) / np.diff(t)[:, None] >= rate * (1.0 - rel_tol))
    n = time_sum(ok)
    return np.where(n > 0, time_sum(at_limit) / np.maximum(n, 1), np.nan)


def course_quality_arrays(t, psi_error, delta, u, *, lam: float = 1.0, t_end: float | None = None,
                          diverged=False, psi=None, psi_z=None,
                          bound_deg: float = COURSE_BOUND_DEG,
                          settle_window_s: float = COURSE_SETTLE_WINDOW_S,
                          settle_band_deg: float = COURSE_SETTLE_BAND_DEG,
                          psi_d=None, delta_max: float | None = None,
                          oscillation_deg: float = COURSE_OSCILLATION_DEG,
                          delta_rate: float | None = None) -> dict:
    """The figures of :func:`course_quality_metrics` for every ship: arrays ``(time, ship)`` →
    ``(ship,)`` arrays; samples after a ship's run stopped (NaN padding) are left out."""
    t = np.asarray(t, dtype=float)[:, None]
    dpsi = -psi_error  # psi_error = wrap(ψ − ψ_d)
    finite = np.isfinite(dpsi)
    dpsi0 = np.where(finite, dpsi, 0.0)
    psi_E = time_sum(dpsi0**2)
    delta_E = lam * time_sum(np.where(finite, delta, 0.0) ** 2)
    t_last = np.max(np.where(finite, t, -np.inf), axis=0)
    last = finite.shape[0] - 1 - finite[::-1].argmax(axis=0)
    reached = np.ones_like(t_last, dtype=bool) if t_end is None else t_last >= t_end - 1e-9
    late = finite & (t >= t_last - settle_window_s)
    dpsi_deg = np.abs(to_deg(dpsi0))
    delta_arr = np.asarray(delta, dtype=float)
    verdict = stable_arrays(t[:, 0], dpsi, bound=math.radians(bound_deg),
                            oscillation_tol=math.radians(oscillation_deg), reached=reached,
                            diverged=diverged, actuator=delta_arr, actuator_max=delta_max,
                            segments=_segments_of(psi_d))
    rate_rms, travel = actuator_motion_arrays(t[:, 0], delta_arr)
    out = {
        "psi_E": psi_E,
        "delta_E": delta_E,
        "J": psi_E + delta_E,
        "min_surge_mps": np.min(np.where(np.isfinite(u), u, np.inf), axis=0),
        "final_heading_error_deg": to_deg(np.take_along_axis(dpsi0, last[None, :], axis=0)[0]),
        "max_rudder_deg": to_deg(np.max(np.where(finite, np.abs(delta), -np.inf), axis=0)),
        "rudder_rate_rms_deg_s": to_deg(rate_rms),
        "rudder_rate_limit_fraction": rate_limit_fraction(t[:, 0], delta_arr, delta_rate),
        "rudder_travel_deg": to_deg(travel),
        "stable": verdict["stable"],
        "settled": np.all(~late | (dpsi_deg <= settle_band_deg), axis=0),
    }
    if psi_z is not None:
        ref = np.where(finite & np.isfinite(psi_z), wrap_angle(psi_z - psi), np.nan)
        known = np.isfinite(ref).any(axis=0)
        out["psi_E_ref"] = np.where(known, time_sum(np.where(np.isfinite(ref), ref**2, 0.0)), np.nan)
    else:
        out["psi_E_ref"] = np.full(psi_E.shape, np.nan)
    return out


def course_quality_metrics(ds, *, lam: float = 1.0, t_end: float | None = None,
                           diverged: bool = False, bound_deg: float = COURSE_BOUND_DEG,
                           settle_window_s: float = COURSE_SETTLE_WINDOW_S,
                           settle_band_deg: float = COURSE_SETTLE_BAND_DEG,
                           delta_max: float | None = None,
                           oscillation_deg: float = COURSE_OSCILLATION_DEG,
                           delta_rate: float | None = None) -> dict:
    """Document 003's quality index and course-keeping figures (notes 003-3.1, 003-3.8).

    On every sample t_i: Δψ_i = wrap(ψ_d − ψ_i) [rad]; ``psi_E`` = Σ Δψ_i², ``delta_E`` = λ Σ δ_i²
    with the applied rudder δ [rad], ``J`` = ``psi_E`` + ``delta_E`` (eq. 2). ``min_surge_mps``,
    ``final_heading_error_deg`` (Δψ at the last sample), ``max_rudder_deg`` (applied).
    J does not see how hard the rudder works; beside it: ``rudder_rate_rms_deg_s``, the RMS of
    the applied rudder rate Δδ_i/Δt_i, and ``rudder_travel_deg`` = Σ|Δδ_i|, the rudder's total
    travel (wear of the steering machine); ``rudder_rate_limit_fraction`` the fraction of the
    sample intervals the rudder moves at the steering machine's rate limit ``delta_rate`` [rad/s]
    (:func:`rate_limit_fraction`; None without a rate limit).

    ``stable`` (:func:`stable_arrays`): the run reached ``t_end`` without the divergence guard,
    |Δψ| stayed below 90°, and over the last 20 % of each course step (a segment of constant
    ψ_d) the heading error's oscillation about its trend is at most ``oscillation_deg`` (5°) in
    amplitude and the rudder is not pinned at both limits ±``delta_max`` (default: the result's
    ``delta_max`` attribute; none checked if absent) — a limit cycle is not stable. Extras:
    ``settled`` (|Δψ| ≤ 2° over the last 30 s) and ``psi_E_ref`` (Σ wrap(ψ_z − ψ)² against the
    reference model, for controllers that have one; note 003-B11).
    """
    has_ref = "psi_z" in ds
    if delta_max is None and "delta_max" in ds.attrs:
        delta_max = float(ds.attrs["delta_max"])
    a = course_quality_arrays(ds.time.values, series(ds, "psi_error"), series(ds, "delta"),
                              series(ds, "u"), lam=lam, t_end=t_end, diverged=diverged,
                              psi=series(ds, "psi") if has_ref else None,
                              psi_z=series(ds, "psi_z") if has_ref else None,
                              bound_deg=bound_deg, settle_window_s=settle_window_s,
                              settle_band_deg=settle_band_deg,
                              psi_d=series(ds, "psi_d") if "psi_d" in ds else None,
                              delta_max=delta_max, oscillation_deg=oscillation_deg,
                              delta_rate=delta_rate)
    out = {key: _scalar(value[0]) for key, value in a.items()}
    out["stable"], out["settled"] = bool(a["stable"][0]), bool(a["settled"][0])
    return out


def navigation_arrays(ds, navigation=None) -> dict[str, np.ndarray]:
    """The navigation figures of a run with sensors / an estimator, ``(ship,)`` arrays
    over every logged sample where the quantity exists (NaN-free samples only):

    ``heading_est_rmse_deg`` √mean(wrap(ψ̂ − ψ)²), ``position_est_rmse_m`` √mean((N̂ − N)² + (Ê − E)²),
    ``heading_meas_rmse_deg`` √mean(wrap(ψ_meas − ψ)²) over the valid compass samples, and
    ``nees_mean`` the mean normalised estimation error squared (its expectation is ``nees_dim``,
    the number of model states the NEES is taken over, for a consistent filter: Bar-Shalom, Li &
    Kirubarajan 2001, §5.4.2), ``nis_mean`` the mean normalised innovation squared over the
    samples with a measurement (its expectation ``nis_dim``, the mean number of scalar
    measurements at those samples). ``nees_dim`` needs the run's ``navigation`` (a Kalman filter's
    mapped states). Keys whose signals the run did not log are absent."""
    out: dict[str, np.ndarray] = {}

    def rms(error: np.ndarray) -> np.ndarray:
        with np.errstate(invalid="ignore"):
            return np.sqrt(np.nanmean(error ** 2, axis=0))

    if "psi_hat" in ds:
        out["heading_est_rmse_deg"] = to_deg(rms(wrap_angle(series(ds, "psi_hat") - series(ds, "psi"))))
    if "north_hat" in ds and "east_hat" in ds:
        out["position_est_rmse_m"] = rms(np.hypot(series(ds, "north_hat") - series(ds, "north"),
                                                  series(ds, "east_hat") - series(ds, "east")))
    if "psi_meas" in ds:
        out["heading_meas_rmse_deg"] = to_deg(rms(wrap_angle(series(ds, "psi_meas")
                                                             - series(ds, "psi"))))
    if "nees" in ds:
        with np.errstate(invalid="ignore"):
            out["nees_mean"] = np.nanmean(series(ds, "nees"), axis=0)
        dim = getattr(getattr(navigation, "estimator", None), "nees_dim", None)
        if dim is not None:
            out["nees_dim"] = np.full(out["nees_mean"].shape, float(dim))
    if "nis" in ds and "nis_dim" in ds:
        nis, nd = series(ds, "nis"), series(ds, "nis_dim")
        seen = nd > 0
        with np.errstate(invalid="ignore", divide="ignore"):
            count = seen.sum(axis=0)
            out["nis_mean"] = np.where(count > 0, np.where(seen, nis, 0.0).sum(axis=0) / count,
                                       np.nan)
            out["nis_dim"] = np.where(count > 0, np.where(seen, nd, 0.0).sum(axis=0) / count,
                                      np.nan)
    return out
