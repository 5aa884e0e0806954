"""A batch run scored inside the composed loop: each ship's accumulators
(:mod:`shipgnc.sim.score_template`) updated at every step, and no log beyond the first and the last
sample, so that a study member keeps only the numbers it is scored on.

:func:`run_scored` is :func:`shipgnc.sim.compose.run` with
:meth:`~shipgnc.sim.compose.Composition.score_in_loop` and a log period of the whole run; it
returns None when the compiled loop does not cover the setup (the caller then logs every step and
scores the series).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class Scored(NamedTuple):
    """Each ship's accumulators ``acc`` (ships, 3 m) and divergence ``event`` (−1: none; see
    :class:`shipgnc.sim.compose.Composition`)."""

    acc: np.ndarray
    event: np.ndarray


def run_scored(setup, ops: np.ndarray, span: np.ndarray, init: np.ndarray) -> Scored | None:
    """Run ``setup`` (a validated :class:`~shipgnc.sim.simulator.SimSetup`; its ``log_every`` is
    best the run's length) in its composed loop with the accumulators ``ops``, ``span`` (see
    :class:`~shipgnc.sim.compose.ScoreArrays`) starting from ``init`` (3 m,) for every ship.
    None when no compiled loop covers ``setup``. Ctrl-C raises KeyboardInterrupt."""
    from shipgnc.sim.compiled import drive
    from shipgnc.sim.compose import Composition, unsupported_reason
    from shipgnc.sim.simulator import reset_components

    if unsupported_reason(setup):
        return None
    reset_components(setup)
    comp = Composition(setup, scored=True)
    n = comp.S.shape[0]
    acc = np.empty((n, len(init)))
    acc[:] = np.asarray(init, dtype=np.float64)
    comp.score_in_loop(ops, span, acc)
    stop = drive(setup, comp.call, comp.S, comp.event, prepare=comp.prepare, done_at=comp.done_at)
    if stop.interrupted:
        raise KeyboardInterrupt
    comp.restore()
    return Scored(acc, comp.event.copy())
