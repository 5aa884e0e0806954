"""A scenario's ``montecarlo`` section scored inside the compiled loop (``shipgnc run
mariner-montecarlo``: one batch of ships per controller, summarised by
:func:`shipgnc.analysis.path_tracking.montecarlo_summary`).

The summary needs every step of every ship; the written result and the figures need only the
samples of ``simulation.log_every``. So the batch runs once in its composed loop with the
``path-tracking`` accumulators (:func:`shipgnc.analysis.accumulated.path_tracking`) updated at
every step and the log kept at ``log_every`` (:func:`shipgnc.sim.scored.run_scored` with
``logged``): the result is the one the run logged at every step and thinned, to the bit, and
the figures the ones scored from the full log. A ship whose ``stable`` verdict the accumulators
leave undecided (:data:`~shipgnc.analysis.accumulated.NEEDS_LOG`) is run again with the ships
like it, on the wave noise the batch drew for it (:func:`shipgnc.sim.scored.run_with_tables`),
logged at every step and scored from its log. A batch in which a ship diverged, or one the
compiled loop does not cover, returns None: the caller runs it as before (logged at every step,
scored from the log). A batch cut short by Ctrl-C keeps the samples it logged (every
``log_every`` steps), and its metrics, flagged ``interrupted``, are scored from those.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from shipgnc.errors import Interrupted


@dataclass
class ScoredBatch:
    """A Monte Carlo batch's ``result`` (logged at ``simulation.log_every``), its ``metrics``
    (the summary) and each ship's ``figures`` ((ship,) arrays, as
    :func:`~shipgnc.analysis.path_tracking.path_tracking_arrays` gives them)."""

    result: object
    metrics: dict
    figures: dict


def scored_in_loop(scenario, observer=None) -> bool:
    """Whether a run of ``scenario`` is a Monte Carlo section scored in the loop (its
    ``path-tracking`` summary, the ``rk4`` compiled loop, no observer callback)."""
    sim = scenario.simulation
    return (scenario.montecarlo is not None and scenario.metrics == "path-tracking"
            and observer is None and sim.integrator == "rk4" and sim.backend != "numpy")


def run(scenario, setup, rebuild: Callable, *, seed: int, progress=None,
        attrs: dict | None = None, seas: dict | None = None,
        scoring: Callable[[], None] | None = None) -> ScoredBatch | None:
    """The batch of ``setup`` (built from ``scenario``; ``rebuild()`` builds it again, fresh
    components for the ships run again) scored in the loop, or None (see the module). Ctrl-C
    raises :class:`~shipgnc.errors.Interrupted` with the samples logged up to it.

    ``seas``: the per-step input tables of the batches run so far (a dict this call reads and
    fills), by :func:`sea_key`. The controllers of a comparison sail one sea: the same
    disturbance section, vessel, simulation, seed and batch give the same tables (a table is
    drawn from the run's generator before the steps it feeds, so it cannot depend on the
    controller or the ships' states), drawn by the first controller and read by the others.

    ``scoring()`` is called once the batch has run to its end, before the ships left undecided
    are run again (those runs are its scoring: the runner holds a Ctrl-C from then on with
    --keep-partial, and the complete batch is kept as for any run scored after it finished)."""
    from shipgnc.analysis import accumulated
    from shipgnc.analysis.path_tracking import montecarlo_figures
    from shipgnc.scenarios.runner import design_figures
    from shipgnc.sim.result import build_dataset, time_coordinate
    from shipgnc.sim.scored import run_scored
    from shipgnc.sim.simulator import log_signals, result_attrs, wants_compiled

    delta_max = float(setup.model.params.delta_max)
    if delta_max <= 0 or setup.navigation is not None:
        return None
    sim = scenario.simulation
    batch = _sim_setup(setup, sim, seed, sim.log_every, progress)
    if not wants_compiled(sim.backend, batch.x0.shape[0], batch.n_steps):
        return None  # a run simulate leaves to the numpy loop
    t = time_coordinate(np.arange(batch.n_steps + 1) * batch.dt)  # every step's sample time
    plan = accumulated.path_tracking(list(log_signals(batch)), t, delta_max, final_abs=True)
    key = sea_key(scenario, seed, batch.x0.shape)
    scored = run_scored(batch, plan.ops, plan.span, plan.init, logged=True,
                        tables=None if seas is None else seas.get(key))
    if scored is None:
        return None
    run_attrs = result_attrs(batch, "compiled", attrs)
    log = scored.log
    if log.status.get("interrupted"):
        last = float(log.time[-1]) if log.time.size else 0.0
        raise Interrupted(last, partial=(lambda: build_dataset(log, batch.batch_shape, None,
                                                               run_attrs))
                          if log.time.size else None)
    if seas is not None:
        seas[key] = scored.tables
    if (scored.event >= 0).any():
        return None
    if scoring is not None:
        scoring()
    figures = plan.finish(scored.acc)
    again = np.flatnonzero(figures.pop(accumulated.NEEDS_LOG))
    for block in np.array_split(again, -(-again.size // SHIPS_PER_RERUN)) if again.size else ():
        rows = _scored_from_log(rebuild(), sim, seed, batch.x0[block],
                                {k: v[:, block] for k, v in scored.tables.items()}, delta_max)
        if rows is None:
            return None
        for name, values in figures.items():
            values[block] = rows[name]
    metrics = {**montecarlo_figures(figures), **design_figures(setup), "diverged": False}
    return ScoredBatch(build_dataset(log, batch.batch_shape, None, run_attrs), metrics, figures)


def sea_key(scenario, seed: int, shape) -> str:
    """What a batch's per-step input tables (its wave noise, a Gauss–Markov current's draws)
    depend on: the scenario's sections that build the drawing components (disturbance, current,
    vessel, sensors, estimator) and simulation, the seed and the batch's shape. (A table whose
    name or width is not what the loop's kernels draw is not replayed either:
    :func:`shipgnc.sim.scored.run_scored` draws afresh.)"""
    return repr((scenario.disturbance, scenario.current, scenario.vessel, scenario.sensors,
                 scenario.estimator, scenario.simulation, seed, tuple(shape)))


def table_numbers(scenario, setup, seed: int, seas: dict) -> int:
    """The float64 numbers of per-step input tables alive while the batch of ``setup`` runs
    (:func:`run` records them, ``seas`` keeps them for the comparison): those already in
    ``seas`` and, unless its sea is among them, the batch's own, (steps + 1) × ships × the
    columns its drawing kernels declare (``Kernel.n_table``). For
    :func:`~shipgnc.sim.simulator.check_run_memory` before the run; ``setup`` is a fresh build
    (its disturbance is reset here, on a generator of its own, to ask for its kernels)."""
    from shipgnc.kernels import NotCompiled
    from shipgnc.sim.simulator import reset_disturbance

    held = sum(t.size for tables in seas.values() for t in tables.values())
    sim, batch, dist = scenario.simulation, setup.x0.shape[:-1], setup.disturbance
    steps = sim.t_end / sim.dt
    if dist is None or sea_key(scenario, seed, setup.x0.shape) in seas or not math.isfinite(steps):
        return held  # nothing drawn, drawn already, or a run simulate's own check refuses
    reset_disturbance(dist, setup.model, batch, np.random.default_rng(0))
    columns = 0
    for make in (getattr(dist, "kernel", None), getattr(dist, "kernel_current", None)):
        if not callable(make):
            continue
        try:
            kernel = make(batch, dt=sim.dt)
        except NotCompiled:  # no compiled loop: the run is not scored in it (no tables)
            continue
        if kernel is not None and kernel.table is not None:
            columns += int(kernel.n_table)
    return held + (round(steps) + 1) * math.prod(batch) * columns


#: ships of a batch run again together with their log of every step (a block's log stays small)
SHIPS_PER_RERUN = 64


def _sim_setup(setup, sim, seed, log_every: int, progress=None):
    """The validated run of ``setup`` as ``sim`` steps it (ships that diverge stop alone)."""
    from shipgnc.sim.simulator import _validate

    return _validate(setup.model, setup.x0, t_end=sim.t_end, dt=sim.dt,
                     controller=setup.controller, actuator=setup.actuator,
                     guidance=setup.guidance, disturbance=setup.disturbance, u0=setup.u0,
                     integrator=sim.integrator, method=sim.method, rtol=sim.rtol, atol=sim.atol,
                     seed=seed, on_divergence="mask", observer=None, progress=progress,
                     log_every=log_every, navigation=setup.navigation)


def _scored_from_log(fresh, sim, seed, x0, tables: dict, delta_max: float) -> dict | None:
    """The path-tracking figures of ships ``x0`` of a batch, run again with their per-step
    ``tables`` from it and scored from their log of every step (None: no compiled loop)."""
    from dataclasses import replace

    from shipgnc.analysis.path_tracking import path_tracking_arrays
    from shipgnc.sim.result import time_coordinate
    from shipgnc.sim.scored import run_with_tables

    alone = _sim_setup(replace(fresh, x0=x0), sim, seed, 1)
    log = run_with_tables(alone, tables)
    if log is None or (log.diverged_at is not None and np.isfinite(log.diverged_at).any()):
        return None
    d = log.data
    return path_tracking_arrays(time_coordinate(log.time), d["cross_track_error"],
                                d["heading_error"], d["leg"], d["delta"], delta_max=delta_max,
                                reached_end=True)
