"""Metric sets scored inside the compiled loop: which accumulators each needs
(:mod:`shipgnc.sim.score_template`: running maxima, sums of squares, first and last values, the
settling band's last exit, each in a time window known before the run) and its formulas finished
from them, giving the figures of the metric set's ``*_arrays`` function on the logged series
(:mod:`shipgnc.analysis.metrics`).

:func:`plan_for` returns the :class:`Accumulators` of a scenario's metric set, or None for a set
that is scored from the logged series (its run then logs every step, as before).

``heading-steps`` (:func:`shipgnc.analysis.metrics.heading_step_arrays`, note 001-1.10): per
heading step k, in its window ``t_k − 10⁻⁹ ≤ t < t_{k+1} − 10⁻⁹``: the band exit of
``|e_ψ| ≤ 2°`` (settling time: the first sample after the last one outside, minus t_k; 0 if none
was outside; NaN if the last one is), the largest ``±e_ψ`` [deg] (overshoot: the one of the sign of
the step ``sign(wrap(ψ_d(first sample) − ψ_d(last sample before)))``), ψ_d's first value in the
window and its last before it; over the run: ``Σ e_ψ²`` [deg²] in time order (the RMSE), max
``|α|``, max T, max T_cmd, the last u. Each is the series formula's own arithmetic on the same
values, so the figures are the same to the bit.

``path-tracking`` (:func:`shipgnc.analysis.path_tracking.path_tracking_arrays`, note 000-0.8):
leg 1 is each ship's samples before its first with ``leg > 0`` (a gate on the switch); on it the
band ``|y_r| < 0.05 nm``'s last exit and the largest ±y_r, from the switch on max |y_r| and
Σ y_r²; over the last 10 min Σ sin ψ_r, Σ cos ψ_r, Σ y_r, Σ δ; over the run Σ δ², the
samples at ±δ_max, max |y_r| and y_r(0). ``stable``'s residual half-range A about the least-squares
line over the final 20 % (:func:`shipgnc.analysis.metrics.stable_arrays`) needs the window's
samples after the fit; it lies between ½ [(e_max − b·tc(e_max)) − (e_min − b·tc(e_min))] and
½ [e_max − e_min + |b| (tc_last − tc_first)] (b the fitted slope, tc the centred time), so a ship
whose bounds fall on one side of the band by more than :data:`MARGIN` has its verdict, and the
others (and any ship with a non-finite sample) are marked :data:`NEEDS_LOG`: the caller scores
them from their logged series.

``course-quality`` (:func:`shipgnc.analysis.metrics.course_quality_arrays`, notes 003-3.1,
003-3.8): J's sums Σ Δψ², Σ δ² and Σ wrap(ψ_z − ψ)² in time order (rectangle rule on every sample,
as eq. 2), the rudder's steps (RMS rate, travel, steps at the rate limit), extremes and last
values; ``stable`` per course step, whose final windows are foreseen from the schedule and
checked in the loop, each bounded on :data:`BLOCKS` blocks (:func:`course_quality`).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from shipgnc.frames import wrap_angle
from shipgnc.sim.result import time_coordinate
from shipgnc.units import to_deg

# the kinds of shipgnc.sim.score_template (its module constants; that module is source only)
(MAX, MAX_ABS, SUM_SQUARES, LAST, FIRST, BAND_EXIT, SUM, COUNT, SWITCH, LAST_OUT, SUM_TC,
 ARGMAX, DIFF, WRAP_DIFF_SQUARES) = range(14)
#: accumulator kinds that start from −∞ (the others from 0)
_FROM_MINUS_INF = (MAX, MAX_ABS, ARGMAX)
#: a window's edges as the series formulas draw them (a sample at t_k − 1e-9 or later)
EDGE = 1e-9
#: metric sets scored inside the loop
IN_LOOP_SETS = ("heading-steps", "path-tracking", "course-quality", "none")
#: the key of :attr:`Accumulators.finish`'s mask of the ships to score from their logged series
NEEDS_LOG = "needs_log"
#: how far [m] the bounds on ``stable``'s residual half-range must clear the band to decide it
#: (the series formula's own round-off is below 1e-11 m at the 10⁴ m of a Mariner's y_r)
MARGIN = 1e-6
#: blocks of a ``course-quality`` final window, each with its own extremes (:func:`_calm`)
BLOCKS = 8


@dataclass(frozen=True)
class Accumulators:
    """The accumulators of a metric set (see :class:`shipgnc.sim.compose.ScoreArrays`): ``ops``
    (m, 3), ``span`` (m, 4), ``init`` (3 m,) and ``finish(acc)`` → the metric arrays (ships,),
    and under :data:`NEEDS_LOG` (if present) the ships to score from their logged series."""

    ops: np.ndarray
    span: np.ndarray
    init: np.ndarray
    finish: Callable[[np.ndarray], dict]


class _Plan:
    """Accumulators added one by one, by log signal name."""

    def __init__(self, signals) -> None:
        self.columns = {name: i for i, name in enumerate(signals)}
        self.rows: list[tuple[int, int, int, float, float, float, float]] = []
        self.start: dict[int, float] = {}

    def add(self, name: str, kind: int, start=-math.inf, end=math.inf, arg=1.0, level=0.0,
            gate=-1, init=None) -> int:
        """Index of a new accumulator of signal ``name`` (``init``: its first number's start,
        else −∞ or 0 by kind)."""
        self.rows.append((self.columns[name], kind, gate, start, end, arg, level))
        if init is not None:
            self.start[len(self.rows) - 1] = init
        return len(self.rows) - 1

    def build(self, finish) -> Accumulators:
        ops = np.array([r[:3] for r in self.rows], dtype=np.int64).reshape(-1, 3)
        span = np.array([r[3:] for r in self.rows], dtype=np.float64).reshape(-1, 4)
        init = np.zeros(3 * len(self.rows))
        for m, kind in enumerate(ops[:, 1]):
            init[3 * m] = self.start.get(m, -math.inf if kind in _FROM_MINUS_INF else 0.0)
            if kind == DIFF:  # no previous sample yet
                init[3 * m + 2] = math.nan
        return Accumulators(ops, span, init, finish)


def plan_for(scenario, setup, signals, n_steps: int, dt: float) -> Accumulators | None:
    """The accumulators of ``scenario.metrics`` for a run of ``n_steps`` steps of ``dt`` whose log
    has ``signals`` (in column order), or None when the set is scored from the series (also: a
    run with navigation, whose estimate errors are scored from the series)."""
    if scenario.metrics not in IN_LOOP_SETS or setup.navigation is not None:
        return None
    if scenario.metrics == "none":  # nothing to score: no accumulator, and no log
        return _Plan(signals).build(lambda acc: {})
    t = time_coordinate(np.arange(n_steps + 1) * dt)  # the sample times of a log of every step
    if scenario.metrics == "path-tracking":
        delta_max = float(setup.model.params.delta_max)
        return path_tracking(signals, t, delta_max) if delta_max > 0 else None
    if scenario.metrics == "course-quality":
        return course_quality(scenario, setup, signals, t, dt)
    return heading_steps(signals, t, setup.guidance.step_times)


def heading_steps(signals, t: np.ndarray, step_times, tolerance_deg: float = 2.0) -> Accumulators:
    """The accumulators of ``heading-steps`` (see the module) for a run sampled at ``t``."""
    plan = _Plan(signals)
    deg = 180.0 / math.pi  # units.to_deg's factor
    windows = []
    first_psi_d = plan.add("psi_d", FIRST)
    for t_k, t_next in itertools.pairwise([*step_times, t[-1] + 1.0]):
        if not ((t >= t_k - EDGE) & (t < t_next - EDGE)).any():
            continue
        lo, hi = t_k - EDGE, t_next - EDGE
        windows.append((t_k, plan.add("psi_error", BAND_EXIT, lo, hi, deg, tolerance_deg),
                        plan.add("psi_error", MAX, lo, hi, deg), plan.add("psi_error", MAX, lo, hi, -deg),
                        plan.add("psi_d", FIRST, lo, hi), plan.add("psi_d", LAST, -math.inf, lo)))
    squares = plan.add("psi_error", SUM_SQUARES, arg=deg)
    alpha, thrust = plan.add("alpha", MAX_ABS), plan.add("T", MAX)
    thrust_cmd, speed = plan.add("T_cmd", MAX), plan.add("u", LAST)

    def finish(acc: np.ndarray) -> dict:
        a = acc.reshape(acc.shape[0], -1, 3)
        settling, overshoot = [], []
        for t_k, band, up, down, first, before in windows:
            settle_at = time_coordinate(a[:, band, 1]) - t_k
            settling.append(np.where(a[:, band, 0] == 0.0, 0.0, settle_at))
            prior = np.where(a[:, before, 1] != 0.0, a[:, before, 0], a[:, first_psi_d, 0])
            direction = np.sign(wrap_angle(a[:, first, 0] - prior))
            peak = np.where(direction > 0, a[:, up, 0], np.where(direction < 0, a[:, down, 0], 0.0))
            overshoot.append(np.maximum(0.0, peak))
        n_ships = acc.shape[0]
        steps = np.array(settling).reshape(-1, n_ships)
        return {
            "heading_rmse_deg": np.sqrt(a[:, squares, 0] / a[:, squares, 1]),
            "settling_time_s": np.max(steps, axis=0) if steps.shape[0] else np.full(n_ships, np.nan),
            "overshoot_deg": np.max(np.array(overshoot), axis=0) if overshoot else np.zeros(n_ships),
            "max_thruster_angle_deg": to_deg(a[:, alpha, 0]),
            "max_thrust_n": a[:, thrust, 0],
            "max_thrust_cmd_n": a[:, thrust_cmd, 0],
            "final_speed_mps": a[:, speed, 0],
        }

    return plan.build(finish)


def path_tracking(signals, t: np.ndarray, delta_max: float, *, final_abs: bool = False) -> Accumulators:
    """The accumulators of ``path-tracking`` (see the module) for a run sampled at ``t``, rudder
    limit ``delta_max`` > 0 [rad]; ``final_abs``: also Σ |y_r| over the last 10 min, for
    ``final_abs_crosstrack_nm`` (a Monte Carlo summary's ``on_path_at_end_fraction``)."""
    from shipgnc.analysis import path_tracking as pt
    from shipgnc.analysis.metrics import STABLE_FINAL_FRACTION, STABLE_PINNED_FRACTION
    from shipgnc.units import MINUTE, NAUTICAL_MILE

    plan = _Plan(signals)
    y, psi, leg, rudder = "cross_track_error", "heading_error", "leg", "delta"
    switch = plan.add(leg, SWITCH)  # first: a gated accumulator reads its switch of this sample
    before, after = 2 * switch, 2 * switch + 1
    out = plan.add(y, LAST_OUT, level=pt.SETTLE_BAND, gate=before)
    up, down = plan.add(y, MAX, gate=before), plan.add(y, MAX, arg=-1.0, gate=before)
    after_max, after_sq = plan.add(y, MAX_ABS, gate=after), plan.add(y, SUM_SQUARES, gate=after)
    # the last 10 min; the series sums start from −0.0 and add +0.0 for each sample before
    final_from = t[-1] - pt.FINAL_WINDOW - 1e-9
    zero = -0.0 if final_from <= t[0] else 0.0
    sin_psi, cos_psi = (plan.add(psi, SUM, final_from, level=f, init=zero) for f in (1.0, 2.0))
    y_sum = plan.add(y, SUM, final_from, init=zero)
    d_sum = plan.add(rudder, SUM, final_from, init=zero)
    abs_sum = plan.add(y, SUM, final_from, level=3.0, init=zero) if final_abs else None
    d_sq = plan.add(rudder, SUM_SQUARES)
    saturated_at = delta_max * (1.0 - 1e-9)
    sat = [plan.add(rudder, COUNT, arg=sign, level=saturated_at) for sign in (1.0, -1.0)]
    peak, y0 = plan.add(y, MAX_ABS), plan.add(y, FIRST)
    finite = [peak] + [plan.add(name, MAX_ABS) for name in (psi, leg, rudder)]  # NaN sticks
    # stable_arrays' final window (one segment: the run)
    window_from = t[-1] - STABLE_FINAL_FRACTION * (t[-1] - t[0]) - 1e-9
    center = 0.5 * (t[0] + t[-1])
    e_sum, te_sum = plan.add(y, SUM, window_from), plan.add(y, SUM_TC, window_from, level=center)
    e_max, e_min = plan.add(y, ARGMAX, window_from), plan.add(y, ARGMAX, window_from, arg=-1.0)
    limit = delta_max * (1.0 - 1e-6)
    pinned_at = [plan.add(rudder, COUNT, window_from, arg=sign, level=limit) for sign in (1.0, -1.0)]
    tc = t[t >= window_from] - center
    n_w, s_t, s_tt = float(tc.size), float(tc.sum()), float((tc * tc).sum())

    def finish(acc: np.ndarray) -> dict:
        a = acc.reshape(acc.shape[0], -1, 3)
        n_t = t.size
        has_switch = a[:, switch, 0] != 0.0
        settle_idx, n_leg1 = a[:, out, 0], a[:, out, 1]
        settled = (settle_idx < n_leg1) & (n_leg1 > 0)
        settle = np.where(settled, t[np.minimum(settle_idx, n_t - 1).astype(np.int64)] / MINUTE,
                          np.nan)
        first = a[:, y0, 0]
        side = -np.sign(first)
        opposite = np.where(side > 0, a[:, up, 0], np.where(side < 0, a[:, down, 0], 0.0))
        overshoot = np.where(np.abs(first) < pt.ON_LINE, 0.0,
                             np.maximum(opposite, 0.0) / NAUTICAL_MILE)
        with np.errstate(invalid="ignore", divide="ignore"):
            max_after = np.where(has_switch, a[:, after_max, 0], np.nan)
            rms_after = np.where(has_switch, np.sqrt(a[:, after_sq, 0] / a[:, after_sq, 1]), np.nan)
            rudder_rms = np.sqrt(a[:, d_sq, 0] / a[:, d_sq, 1])
            saturation = (a[:, sat[0], 0] + a[:, sat[1], 0]) / a[:, d_sq, 1]
            n_final = a[:, sin_psi, 1]
            final_sin, final_cos = a[:, sin_psi, 0] / n_final, a[:, cos_psi, 0] / n_final
            final_y, final_d = a[:, y_sum, 0] / n_final, a[:, d_sum, 0] / n_final
        final_heading = to_deg(np.arctan2(final_sin, final_cos))
        reversed_ = np.abs(final_heading) > pt.REVERSED_DEG
        bounded = a[:, peak, 0] < np.maximum(pt.STABLE_BOUND, 2.0 * np.abs(first))
        calm, undecided = _calm(a, n_w, s_t, s_tt, tc, center, e_sum, te_sum, e_max, e_min,
                                pt.SETTLE_BAND)
        if n_w >= 3:
            pinned = ((a[:, pinned_at[0], 0] / n_w >= STABLE_PINNED_FRACTION)
                      & (a[:, pinned_at[1], 0] / n_w >= STABLE_PINNED_FRACTION))
        else:
            pinned = np.zeros(acc.shape[0], dtype=bool)
        stable = bounded & calm & ~pinned & ~reversed_
        needs_log = undecided | ~np.isfinite(a[:, finite, 0]).all(axis=1)
        figures = pt.path_tracking_figures(
            settle_time_min=settle, overshoot_nm=overshoot, max_after=max_after,
            rms_after=rms_after, final_y=final_y, final_heading_deg=final_heading,
            final_delta=final_d, rudder_rms=rudder_rms, saturation=saturation,
            stable=stable.astype(float), reversed_=reversed_.astype(float),
            final_abs=None if abs_sum is None else a[:, abs_sum, 0] / n_final)
        return {**figures, NEEDS_LOG: needs_log}

    return plan.build(finish)


def _calm(a, n, s_t, s_tt, tc, center, e_sum, te_sum, e_max, e_min, tolerance, blocks=None):
    """Whether each ship's residual half-range over the final window is within ``tolerance``
    (see the module: decided where its bounds clear it by :data:`MARGIN`, in the error's unit),
    and where undecided. A window of fewer than 3 samples has none (A = 0), as in
    ``stable_arrays``.

    ``e_max``, ``e_min`` (``ARGMAX`` of ±e) may be sequences, one per block of the window whose
    centred times span ``blocks`` [(τ₀, τ₁), ...] (default: one block, the window): on a block
    e − b·tc ≤ max e − min(b τ₀, b τ₁) and ≥ min e − max(b τ₀, b τ₁), which bounds ρ's range
    from above more tightly the shorter the blocks; each block's extreme samples bound it from
    below."""
    ships = a.shape[0]
    if n < 3:
        return np.ones(ships, dtype=bool), np.zeros(ships, dtype=bool)
    det = n * s_tt - s_t * s_t
    with np.errstate(invalid="ignore", divide="ignore"):
        slope = (n * a[:, te_sum, 0] - s_t * a[:, e_sum, 0]) / det if det > 0 else np.zeros(ships)
    maxima, minima = np.atleast_1d(e_max), np.atleast_1d(e_min)
    tau = np.array(blocks if blocks is not None else [(tc[0], tc[-1])], dtype=float)
    b = slope[:, None]
    high, t_high = a[:, maxima, 0], a[:, maxima, 1] - center
    low, t_low = -a[:, minima, 0], a[:, minima, 1] - center
    upper = 0.5 * (np.max(high - np.minimum(b * tau[:, 0], b * tau[:, 1]), axis=1)
                   - np.min(low - np.maximum(b * tau[:, 0], b * tau[:, 1]), axis=1))
    lower = 0.5 * (np.max(high - b * t_high, axis=1) - np.min(low - b * t_low, axis=1))
    calm = upper <= tolerance - MARGIN
    restless = lower > tolerance + MARGIN
    return calm, ~(calm | restless)


def course_quality(scenario, setup, signals, t: np.ndarray, dt: float) -> Accumulators:
    """The accumulators of ``course-quality``
    (:func:`shipgnc.analysis.metrics.course_quality_arrays`, notes 003-3.1 and 003-3.8) for a run
    sampled at ``t`` (steps of ``dt``): over the run Σ e_ψ², Σ δ², min u, the last e_ψ, max |δ|,
    max |e_ψ|, the rudder's steps (Σ (Δδ/Δt)², Σ |Δδ|, the steps at the rate limit) and, with a
    reference model, Σ wrap(ψ_z − ψ)²; over the last ``settle_window`` max |e_ψ|. ``stable``
    (:func:`shipgnc.analysis.metrics.stable_arrays`) looks at the final 20 % of each course step:
    the steps are foreseen from the schedule at the control samples, and checked in the loop
    (ψ_d's largest and smallest value in each are the foreseen ones, else every ship is scored
    from its log); in each step's final window the residual half-range is bounded as for
    ``path-tracking`` (:func:`_calm`) and the rudder's samples at ±δ_max counted."""
    from shipgnc.analysis import metrics as M

    plan = _Plan(signals)
    e, rudder = "psi_error", "delta"
    lam, delta_max = float(scenario.quality.lam), float(setup.model.params.delta_max)
    rate = M.rudder_rate_limit(setup.actuator)
    e_sq, d_sq = plan.add(e, SUM_SQUARES), plan.add(rudder, SUM_SQUARES)
    u_min, e_last = plan.add("u", MAX, arg=-1.0), plan.add(e, LAST)
    d_abs, e_abs = plan.add(rudder, MAX_ABS), plan.add(e, MAX_ABS)
    rate_sq, travel = plan.add(rudder, DIFF, level=0.0), plan.add(rudder, DIFF, level=1.0)
    at_rate = (plan.add(rudder, DIFF, arg=rate * (1.0 - 1e-6), level=2.0)
               if rate is not None and np.isfinite(rate) else None)
    late = plan.add(e, MAX_ABS, *_edges(t, t >= t[-1] - M.COURSE_SETTLE_WINDOW_S))
    has_ref = "psi_z" in plan.columns
    # ψ's column is its state index: the log's first columns are the states
    ref_sq = plan.add("psi_z", WRAP_DIFF_SQUARES, level=plan.columns["psi"]) if has_ref else None
    psi_d = foreseen_course(setup, t.size, dt)  # the course steps: segments of constant ψ_d
    labels = M._segments_of(psi_d)
    k = np.arange(t.size)
    starts = np.flatnonzero(np.r_[True, labels[1:] != labels[:-1]])
    limit = delta_max * (1.0 - 1e-6)
    steps = []
    for i0, i1 in zip(starts, np.r_[starts[1:], t.size], strict=True):
        inside = (k >= i0) & (k < i1)
        foreseen = (plan.add("psi_d", MAX, *_edges(t, inside)),
                    plan.add("psi_d", MAX, *_edges(t, inside), arg=-1.0),
                    psi_d[i0:i1].max(), psi_d[i0:i1].min())
        t_first, t_last = t[i0], t[i1 - 1]
        window_from = t_last - M.STABLE_FINAL_FRACTION * (t_last - t_first) - 1e-9
        window = inside & (t >= window_from)
        center = 0.5 * (t_first + t_last)
        lo, hi = _edges(t, window)
        tc = t[window] - center
        blocks = [idx for idx in np.array_split(np.flatnonzero(window), min(BLOCKS, tc.size))]
        peaks = [[plan.add(e, ARGMAX, *_edges(t, np.isin(k, idx)), arg=sign) for idx in blocks]
                 for sign in (1.0, -1.0)]
        sums = (plan.add(e, SUM, lo, hi), plan.add(e, SUM_TC, lo, hi, level=center), *peaks)
        pinned = [plan.add(rudder, COUNT, lo, hi, arg=sign, level=limit) for sign in (1.0, -1.0)]
        spans = [(t[idx[0]] - center, t[idx[-1]] - center) for idx in blocks]
        steps.append((foreseen, (float(tc.size), float(tc.sum()), float((tc * tc).sum()), tc,
                                 center), sums, pinned, spans))
    reached = t[-1] >= scenario.simulation.t_end - 1e-9
    n_steps = t.size - 1
    tolerance = math.radians(M.COURSE_OSCILLATION_DEG)

    def finish(acc: np.ndarray) -> dict:
        a = acc.reshape(acc.shape[0], -1, 3)
        ships = acc.shape[0]
        psi_E, delta_E = a[:, e_sq, 0], lam * a[:, d_sq, 0]
        with np.errstate(invalid="ignore", divide="ignore"):
            rate_rms = np.sqrt(a[:, rate_sq, 0] / n_steps) if n_steps else np.full(ships, np.nan)
            fraction = (a[:, at_rate, 0] / n_steps if at_rate is not None and n_steps
                        else np.full(ships, np.nan))
        foreseen_ok = np.ones(ships, dtype=bool)
        calm, restless, pinned = (np.ones(ships, dtype=bool), np.zeros(ships, dtype=bool),
                                  np.zeros(ships, dtype=bool))
        undecided = np.zeros(ships, dtype=bool)
        for (up, down, high, low), (n, s_t, s_tt, tc, center), sums, (at_high, at_low), spans \
                in steps:
            foreseen_ok &= (a[:, up, 0] == high) & (-a[:, down, 0] == low)
            calm_j, undecided_j = _calm(a, n, s_t, s_tt, tc, center, *sums, tolerance, spans)
            calm &= calm_j
            restless |= ~(calm_j | undecided_j)
            undecided |= undecided_j
            if n >= 3:
                pinned |= ((a[:, at_high, 0] / n >= M.STABLE_PINNED_FRACTION)
                           & (a[:, at_low, 0] / n >= M.STABLE_PINNED_FRACTION))
        bounded = a[:, e_abs, 0] < math.radians(M.COURSE_BOUND_DEG)
        stable = reached & bounded & calm & ~pinned
        # the verdict is open only where a step's oscillation is, and nothing else decides it
        open_ = reached & bounded & ~pinned & ~restless & undecided
        finite = np.isfinite(a[:, [e_abs, d_abs, u_min], 0]).all(axis=1)
        if has_ref:
            with np.errstate(invalid="ignore"):
                psi_E_ref = np.where(a[:, ref_sq, 1] > 0, a[:, ref_sq, 0], np.nan)
        else:
            psi_E_ref = np.full(ships, np.nan)
        return {
            "psi_E": psi_E,
            "delta_E": delta_E,
            "J": psi_E + delta_E,
            "min_surge_mps": -a[:, u_min, 0],
            "final_heading_error_deg": to_deg(-a[:, e_last, 0]),
            "max_rudder_deg": to_deg(a[:, d_abs, 0]),
            "rudder_rate_rms_deg_s": to_deg(rate_rms),
            "rudder_rate_limit_fraction": fraction,
            "rudder_travel_deg": to_deg(a[:, travel, 0]),
            "stable": stable.astype(float),
            "settled": (to_deg(a[:, late, 0]) <= M.COURSE_SETTLE_BAND_DEG).astype(float),
            "psi_E_ref": psi_E_ref,
            NEEDS_LOG: open_ | ~foreseen_ok | ~finite,
        }

    return plan.build(finish)


def foreseen_course(setup, n_samples: int, dt: float) -> np.ndarray:
    """ψ_d [rad] at each of ``n_samples`` samples k·``dt`` as the loop holds it: the course
    schedule (:class:`~shipgnc.guidance.schedule.CourseSchedule`) read at the last control sample
    (the guidance runs there), with the row rule of :func:`shipgnc.kernels.schedule_row`."""
    from shipgnc.sim.simulator import samples_per_period

    hold = samples_per_period(getattr(setup.controller, "Ts", None) or dt, dt)
    k = np.arange(n_samples)
    t_control = (k - k % hold) * dt
    schedule = setup.guidance.schedule
    rows = np.searchsorted(schedule.times, t_control + 1e-9 * np.maximum(1.0, np.abs(t_control)),
                           side="right") - 1
    return np.asarray(schedule.values, dtype=float)[rows, 0]


def _edges(t: np.ndarray, inside: np.ndarray) -> tuple[float, float]:
    """A window ``[start, end)`` holding exactly the samples ``inside`` (a contiguous run of
    ``t``, the log's rounded times) for the loop's unrounded times k·dt: its edges half a step
    from the first sample inside and the last (open at the run's ends)."""
    idx = np.flatnonzero(inside)
    i0, i1 = int(idx[0]), int(idx[-1])
    start = 0.5 * (t[i0 - 1] + t[i0]) if i0 > 0 else -math.inf
    end = 0.5 * (t[i1] + t[i1 + 1]) if i1 + 1 < t.size else math.inf
    return start, end
