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
MAX, MAX_ABS, SUM_SQUARES, LAST, FIRST, BAND_EXIT = range(6)
#: accumulator kinds that start from −∞ (the others from 0)
_FROM_MINUS_INF = (MAX, MAX_ABS)
#: a window's edges as the series formulas draw them (a sample at t_k − 1e-9 or later)
EDGE = 1e-9
#: metric sets scored inside the loop
IN_LOOP_SETS = ("heading-steps",)


@dataclass(frozen=True)
class Accumulators:
    """The accumulators of a metric set (see :class:`shipgnc.sim.compose.ScoreArrays`): ``ops``
    (m, 2), ``span`` (m, 4), ``init`` (3 m,) and ``finish(acc)`` → the metric arrays (ships,)."""

    ops: np.ndarray
    span: np.ndarray
    init: np.ndarray
    finish: Callable[[np.ndarray], dict]


class _Plan:
    """Accumulators added one by one, by log signal name."""

    def __init__(self, signals) -> None:
        self.columns = {name: i for i, name in enumerate(signals)}
        self.rows: list[tuple[int, int, float, float, float, float]] = []

    def add(self, name: str, kind: int, start=-math.inf, end=math.inf, arg=1.0, level=0.0) -> int:
        """Index of a new accumulator of signal ``name``."""
        self.rows.append((self.columns[name], kind, start, end, arg, level))
        return len(self.rows) - 1

    def build(self, finish) -> Accumulators:
        ops = np.array([r[:2] for r in self.rows], dtype=np.int64).reshape(-1, 2)
        span = np.array([r[2:] for r in self.rows], dtype=np.float64).reshape(-1, 4)
        init = np.zeros(3 * len(self.rows))
        for m, kind in enumerate(ops[:, 1]):
            if kind in _FROM_MINUS_INF:
                init[3 * m] = -math.inf
        return Accumulators(ops, span, init, finish)


def plan_for(scenario, setup, signals, n_steps: int, dt: float) -> Accumulators | None:
    """The accumulators of ``scenario.metrics`` for a run of ``n_steps`` steps of ``dt`` whose log
    has ``signals`` (in column order), or None when the set is scored from the series (also: a
    run with navigation, whose estimate errors are scored from the series)."""
    if scenario.metrics not in IN_LOOP_SETS or setup.navigation is not None:
        return None
    t = time_coordinate(np.arange(n_steps + 1) * dt)  # the sample times of a log of every step
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
