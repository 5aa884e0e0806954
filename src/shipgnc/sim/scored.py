"""A batch run scored inside the composed loop: each ship's accumulators
(:mod:`shipgnc.sim.score_template`) updated at every step, and no log beyond the first and the last
sample, so that a study member keeps only the numbers it is scored on.

:func:`run_scored` is :func:`shipgnc.sim.compose.run` with
:meth:`~shipgnc.sim.compose.Composition.score_in_loop` and a log period of the whole run; it
returns None when the compiled loop does not cover the setup (the caller then logs every step and
scores the series). With ``logged=True`` it keeps the run's log at the setup's own ``log_every``
too (a Monte Carlo section's written result) and the per-step input tables the batch drew (the
wave noise of every ship), so that :func:`run_with_tables` can run some of its ships again alone
on exactly the inputs they had in the batch (one generator draws for the whole batch, so a ship's
noise depends on the batch it was drawn in).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np


class Scored(NamedTuple):
    """Each ship's accumulators ``acc`` (ships, 3 m) and divergence ``event`` (−1: none; see
    :class:`shipgnc.sim.compose.Composition`); with ``logged``: the run's ``log``
    (:class:`~shipgnc.sim.simulator.Log` at the setup's ``log_every``; ``status["interrupted"]``
    after Ctrl-C) and its per-step input ``tables`` by name (steps + 1, ships, ·)."""

    acc: np.ndarray
    event: np.ndarray
    log: object | None = None
    tables: dict | None = None


def run_scored(setup, ops: np.ndarray, span: np.ndarray, init: np.ndarray, *,
               logged: bool = False, tables: dict | None = None,
               unrolled: bool = False) -> Scored | None:
    """Run ``setup`` (a validated :class:`~shipgnc.sim.simulator.SimSetup`; its ``log_every`` is
    best the run's length, unless ``logged``) in its composed loop with the accumulators ``ops``,
    ``span`` (see :class:`~shipgnc.sim.compose.ScoreArrays`) starting from ``init`` (3 m,) for
    every ship. None when no compiled loop covers ``setup``. Ctrl-C raises KeyboardInterrupt,
    except with ``logged`` (the log then holds the samples up to it). ``tables``: the per-step
    input tables (:attr:`Scored.tables` of a run whose components draw the same ones) used
    instead of drawing them again (and returned as :attr:`Scored.tables`). ``unrolled``: in the
    loop of this plan's own scoring step (:func:`score_step_source`: faster per step, a compile
    per plan), else in the combination's scored loop, whose step reads the plan at run time."""
    from shipgnc.sim.compiled import drive, make_log
    from shipgnc.sim.compose import Composition, unsupported_reason
    from shipgnc.sim.simulator import reset_components

    if unsupported_reason(setup):
        return None
    reset_components(setup)
    comp = Composition(setup, scored=True)
    n = comp.S.shape[0]
    acc = np.empty((n, len(init)))
    acc[:] = np.asarray(init, dtype=np.float64)
    comp.score_in_loop(ops, span, acc, unrolled)
    if tables is not None and table_widths(comp) == _widths(tables, n):
        prepare = _replaying(comp, tables)
    else:  # no tables, or not the ones this loop's kernels draw: draw them
        prepare, tables = (_recording(comp, setup.n_steps + 1) if logged else (comp.prepare, None))
    stop = drive(setup, comp.call, comp.S, comp.event, prepare=prepare, done_at=comp.done_at)
    if stop.interrupted and not logged:
        raise KeyboardInterrupt
    comp.restore()
    if not logged:
        return Scored(acc, comp.event.copy())
    log = make_log(setup, comp.signals, comp.out, comp.S, stop.event, state_slot=0,
                   cmd_slot=comp.layout["cmd"], k_end=stop.k_end, interrupted=stop.interrupted,
                   events=comp.event)
    return Scored(acc, comp.event.copy(), log, tables)


def run_with_tables(setup, tables: dict):
    """The :class:`~shipgnc.sim.simulator.Log` of ``setup`` in its composed loop with the per-step
    input ``tables`` (by name, (steps + 1, ships, ·): :attr:`Scored.tables` of the ships ``setup``
    holds) instead of those its components draw: ships of a batch run again on the inputs they had
    there. None when no compiled loop covers ``setup``. The loop is the scored one with no
    accumulator (the loop :func:`run_scored` compiled for the batch: no second compile)."""
    from shipgnc.sim.compiled import drive, make_log
    from shipgnc.sim.compose import Composition, unsupported_reason
    from shipgnc.sim.simulator import reset_components

    if unsupported_reason(setup):
        return None
    reset_components(setup)
    comp = Composition(setup, scored=True)
    comp.score_in_loop(np.zeros((0, 3), dtype=np.int64), np.zeros((0, 4)),
                       np.zeros((comp.S.shape[0], 0)))
    if table_widths(comp) != _widths(tables, comp.S.shape[0]):
        raise ValueError(f"run_with_tables: the tables {_widths(tables, None)} are not the ones "
                         f"the loop's kernels draw {table_widths(comp)}")
    stop = drive(setup, comp.call, comp.S, comp.event, prepare=_replaying(comp, tables),
                 done_at=comp.done_at)
    if stop.interrupted:
        raise KeyboardInterrupt
    comp.restore()
    return make_log(setup, comp.signals, comp.out, comp.S, stop.event, state_slot=0,
                    cmd_slot=comp.layout["cmd"], k_end=stop.k_end, events=comp.event)


#: the update function of each accumulator kind in :mod:`shipgnc.sim.score_template`, by kind
KIND_FUNCTIONS = ("score_max", "score_max_abs", "score_sum_squares", "score_last", "score_first",
                  "score_band_exit", "score_sum", "score_count", "score_switch", "score_last_out",
                  "score_sum_tc", "score_argmax", "score_diff", "score_wrap_diff_squares")
#: the kinds whose ``span[m, 3]`` names a function (``SCORE_SUM``, ``SCORE_DIFF``) or a state
#: (``SCORE_WRAP_DIFF_SQUARES``), and how many there are (None: the model's states)
_NAMED = {KIND_FUNCTIONS.index("score_sum"): 4, KIND_FUNCTIONS.index("score_diff"): 3,
          KIND_FUNCTIONS.index("score_wrap_diff_squares"): None}


#: the most accumulators a plan's own step is written for (``course-quality`` takes 22 per course
#: step): a larger plan is scored by the generic step, whose compile does not grow with it
OWN_STEP_MAX_ACCUMULATORS = 64


def own_step(plan: tuple) -> bool:
    """Whether a loop of ``plan``'s own step (:func:`score_step_source`) is written for the
    signature ``plan`` (:func:`score_plan`): not for an empty one (nothing to score) nor for one
    of more than :data:`OWN_STEP_MAX_ACCUMULATORS` accumulators."""
    return 0 < len(plan) <= OWN_STEP_MAX_ACCUMULATORS


def score_plan(ops: np.ndarray, span: np.ndarray, n_states: int) -> tuple:
    """The signature of the accumulators ``ops`` (m, 3: log column, kind, gate), ``span``
    (m, 4): per accumulator its column, kind, gate, function (``span[m, 3]`` of the kinds that
    name one by it, else 0) and whether it has a window other than −∞ … ∞, the constants of a
    scoring step written for the plan (:func:`score_step_source`). A kind, a function or a gate
    the step cannot take is a ValueError."""
    keys = []
    for m, (column, kind, gate) in enumerate(np.asarray(ops, dtype=np.int64).tolist()):
        if not 0 <= kind < len(KIND_FUNCTIONS):
            raise ValueError(f"score_in_loop: accumulator {m} has kind {kind}, not one of "
                             f"0 … {len(KIND_FUNCTIONS) - 1}")
        f = 0
        if kind in _NAMED:
            level, count = float(span[m, 3]), _NAMED[kind] or n_states
            f = int(level) if math.isfinite(level) else -1
            if f != level or not 0 <= f < count:
                raise ValueError(f"score_in_loop: accumulator {m} of kind {kind} names span[m, 3] "
                                 f"= {float(span[m, 3]):g}, not an integer 0 … {count - 1}")
        if gate >= 0 and not gate // 2 < m:
            raise ValueError(f"score_in_loop: accumulator {m} has gate {gate}: its switch "
                             f"{gate // 2} must come before it")
        windowed = not (span[m, 0] == -math.inf and span[m, 1] == math.inf)
        keys.append((column, kind, gate, f, windowed))
    return tuple(keys)


def score_step_source(plan: tuple | None) -> str:
    """The loop's scoring step ``score_step`` as source (written after
    :mod:`shipgnc.sim.score_template`): its generic step, or (``plan``: :func:`score_plan`'s
    signature) straight-line code for that plan, each column used read once per sample, then
    each accumulator in turn updated by its kind's function with its column, gate, function and
    index as constants (``boat-autopilot``'s 16 heading-step accumulators: ≈ 10 instead of
    ≈ 31 ns per ship-step; a loop, so a compile, per plan)."""
    if plan is None:
        return "score_step = score_step_generic\n"
    lines = ["@inline",
             "def score_step(t, x, cmd, u, ref, gout, sig, nsg, err, ops, span, acc):",
             '    """Update the ship\'s accumulators ``acc`` with the sample at time ``t``."""']
    for column in sorted({key[0] for key in plan}):
        lines.append(f"    v{column} = column_value({column}, x, cmd, u, ref, gout, sig, nsg, err)")
    for m, (column, kind, gate, f, windowed) in enumerate(plan):
        conditions = [f"t >= span[{m}, 0] and t < span[{m}, 1]"] if windowed else []
        if gate >= 0:  # before (2 j) or from (2 j + 1) switch j's first v > 0
            conditions.append(f"acc[{3 * (gate // 2)}] {'!=' if gate % 2 else '=='} 0.0")
        pad = "    "
        if conditions:
            lines.append(f"    if {' and '.join(f'({c})' for c in conditions)}:")
            pad = "        "
        lines.append(f"{pad}{KIND_FUNCTIONS[kind]}(acc, {3 * m}, v{column}, t, span[{m}, 2], "
                     f"span[{m}, 3], {f}, x)")
    if not plan:
        lines.append("    pass")
    return "\n".join(lines) + "\n"


def table_widths(comp) -> dict[str, int]:
    """The per-step tables ``comp``'s kernels draw: their columns by name (a kernel that draws
    none is left out)."""
    return {name: int(k.n_table) for name, k in comp._tabled
            if k is not None and k.table is not None and k.n_table > 0}


def _widths(tables: dict, ships: int | None) -> dict[str, int] | None:
    """The columns of each of ``tables`` by name, or None if one is not of ``ships`` ships."""
    if ships is not None and any(t.shape[1] != ships for t in tables.values()):
        return None
    return {name: int(t.shape[-1]) for name, t in tables.items()}


def _replaying(comp, tables: dict):
    """``comp.prepare`` with the per-step ``tables`` (by name, (steps + 1, ships, ·): those
    ``comp``'s kernels draw, :func:`table_widths`, checked by the caller), the other tables
    empty, nothing drawn."""
    widths = table_widths(comp)

    def prepare(k0: int, k1: int) -> None:
        for name, table in comp._table.items():
            comp._table[name] = (np.ascontiguousarray(tables[name][k0:k1]) if name in widths
                                 else np.zeros((k1 - k0, *table.shape[1:2], 0)))

    return prepare


def _recording(comp, n_rows: int):
    """``comp.prepare`` that also keeps each drawn per-step table (a table of no columns is not
    kept): the prepare function and the dict it fills, by name, (``n_rows``, ships, ·)."""
    tables: dict[str, np.ndarray] = {}

    def prepare(k0: int, k1: int) -> None:
        comp.prepare(k0, k1)
        for name, table in comp._table.items():
            if table.shape[-1] == 0:
                continue
            if name not in tables:
                tables[name] = np.full((n_rows, *table.shape[1:]), np.nan)
            tables[name][k0:k1] = table

    return prepare, tables
