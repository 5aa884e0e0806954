"""Run a study's chunks here or on a dask cluster, and put them together into one Dataset.

Three ways, one result to the bit: ``workers="local"`` runs the chunks one after another in this
process; ``workers="dask"`` starts a :class:`dask.distributed.LocalCluster` (one single-threaded
worker process per core); ``scheduler="tcp://HOST:PORT"`` sends them to a running dask cluster.
dask reschedules the chunks of a worker that dies, and a chunk is a pure function of the study, so
a lost worker costs time, not members.
"""

from __future__ import annotations

import logging
import os
import signal
import threading
import warnings
from collections.abc import Callable
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from shipgnc.errors import ConfigError, Interrupted, ShipGNCWarning
from shipgnc.interrupts import note
from shipgnc.memory import available_memory
from shipgnc.study.chunk import (
    Chunk,
    check_perturbable,
    check_sweepable,
    chunk_setup,
    in_loop_plan,
    plan_chunks,
    run_chunk,
)
from shipgnc.study.spec import Study

WORKERS = ("local", "dask")
#: members per chunk by default: large enough that a task is thousands of ship-runs, small enough
#: that its time series (≈ 15 signals × samples × 8 bytes per member) stay in memory
DEFAULT_CHUNK_SIZE = 1000
#: seconds to wait for a dask scheduler before calling it unreachable
CONNECT_TIMEOUT_S = 5


@dataclass
class StudyRun:
    """A finished study: the Dataset and how it ran (kept out of the Dataset, which depends on
    the study alone)."""

    dataset: object  # xarray.Dataset
    chunks: int
    workers: str
    seconds: float
    interrupted: str | None = None  #: Ctrl-C's one line when the study kept its finished chunks


def variants_of(study: Study) -> list[str] | None:
    """The controller variants (a ``controller`` dimension) of a comparison scenario or of a
    catamaran scenario with several runs, else None; every grid point is loaded here, so a bad
    grid key or value, an unsweepable scenario or a ``--perturb`` field the vessel does not have
    fails before any work starts."""
    from shipgnc.scenarios.runner import variant_names

    variants = None
    for point in study.points:
        scenario = study.scenario_at(point)
        check_sweepable(scenario)
        g = scenario.guidance
        if study.members > 1 and getattr(g, "awareness", None) == "ais":  # one draw for the batch
            raise ConfigError(f"--mc {study.members} with guidance.awareness = ais: the AIS reports "
                              "are drawn once from guidance.ais.seed, so every member would see the "
                              "same ones; sweep guidance.ais.seed with --grid instead, or use "
                              "shipgnc encounters --mc N --awareness ais")
        plant = [str(p) for p in study.perturb if p.param is not None]
        if scenario.route is not None and plant:
            raise ConfigError(f"--perturb {plant[0]}: a route scenario's ship is sail.vessel at its "
                              "preset, not a vessel section; perturb its initial state (north, east, "
                              "psi_deg, u, v, r_deg_s) or sweep sail settings with --grid")
        try:
            model, x0, _ = _vessel_of(scenario, study.seed)
        except ConfigError as exc:  # e.g. a route that a grid point makes unreachable
            where = ", ".join(f"{k}={v}" for (k, _), v in zip(study.grid, point, strict=True))
            raise ConfigError(f"{exc} (at grid point {where})" if where else str(exc)) from None
        check_perturbable(study.perturb, model, x0)
        names = variant_names(scenario)
        if names is not None:
            if variants is not None and names != variants:
                raise ConfigError(f"--grid: the controllers change across the grid ({variants} vs {names})")
            variants = names
    return variants


def _vessel_of(scenario, seed: int):
    """(model, x0, SimulationConfig) of a scenario's first run: a route's first sailed run (its
    route solved), else the scenario's vessel, initial state and simulation section."""
    from shipgnc.scenarios.runner import build, initial_states, simulation_of, vessel_parts

    if scenario.route is not None:
        setup = build(scenario, seed=seed)
        return setup.model, setup.x0, simulation_of(scenario, setup)
    return vessel_parts(scenario)[0], initial_states(scenario, seed), scenario.simulation


def connect(scheduler: str | None, workers: str):
    """A dask ``Client``: to ``scheduler`` if given, else to a new LocalCluster sized to the machine."""
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise ConfigError("dask is not installed: pip install 'shipgnc[dist]' to run on dask") from None
    if scheduler is not None:
        try:
            return Client(scheduler, timeout=f"{CONNECT_TIMEOUT_S}s")
        except (OSError, TimeoutError, ValueError) as exc:
            reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise ConfigError(f"--scheduler {scheduler!r}: cannot reach a dask scheduler within "
                              f"{CONNECT_TIMEOUT_S} s ({reason})") from None
    # the workers start with Ctrl-C ignored (an ignored signal stays ignored in a child process):
    # Ctrl-C reaches the whole terminal's process group, and this process alone answers it
    with _sigint_ignored():
        # worker logs at CRITICAL only: a failing task reaches us as its exception, and the
        # workers' shutdown chatter ("failed to communicate with scheduler during heartbeat",
        # logged at ERROR when a loaded machine closes the scheduler first) is not an error of ours
        cluster = LocalCluster(n_workers=os.cpu_count() or 1, threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=logging.CRITICAL)
    return Client(cluster)


@contextmanager
def _sigint_ignored():
    """SIGINT ignored inside the block (main thread only; elsewhere a no-op)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def run_chunks(study: Study, chunks: list[Chunk], *, client=None,
               on_chunk: Callable[[int, int], None] | None = None) -> list:
    """The chunks' Datasets in chunk order; ``on_chunk(done, total)`` after each finished chunk.

    Ctrl-C raises :class:`~shipgnc.errors.Interrupted` whose ``partial`` is the list of the chunks'
    Datasets, None for each chunk that had not finished."""
    total = len(chunks)
    results: list = [None] * total
    finished = [0]

    def counted(done: int, total: int) -> None:
        finished[0] = done
        if on_chunk is not None:
            on_chunk(done, total)

    try:
        if client is None:
            for i, chunk in enumerate(chunks):
                results[i] = run_chunk(study, chunk)
                counted(i + 1, total)
        else:
            _run_on_dask(study, chunks, client, counted, results)
        return results
    except KeyboardInterrupt:  # Ctrl-C: one line, whatever was running
        message = f"interrupted after {finished[0]} of {total} chunks"
        note(message)  # said at once if closing the cluster would keep the command waiting
        raise Interrupted(message=message, partial=results) from None


def _run_on_dask(study: Study, chunks: list[Chunk], client, on_chunk, results: list) -> None:
    """The chunks on the dask cluster, each Dataset stored in ``results`` (chunk order) as it ends."""
    total = len(chunks)
    from dask.distributed import as_completed

    # retries: one more try for a chunk that raised (e.g. a race on numba's cache); bad input
    # is returned, not raised, so it is not retried
    futures = [client.submit(chunk_task, study, chunk, pure=False, retries=1) for chunk in chunks]
    index = {f.key: i for i, f in enumerate(futures)}
    for done, future in enumerate(as_completed(futures), start=1):
        part = future.result()
        if isinstance(part, ConfigError):
            client.cancel(futures)
            raise part
        results[index[future.key]] = part
        if on_chunk is not None:
            on_chunk(done, total)


def unfinished_filled(chunks: list[Chunk], parts: list) -> list:
    """``parts`` with each chunk that did not finish (None) replaced by its members with every
    variable NaN, so that an interrupted study assembles like a whole one; a variable ``finished``
    (1 for a member computed, 0 for one left out) tells them apart."""
    template = next(part for part in parts if part is not None)
    filled = []
    for chunk, part in zip(chunks, parts, strict=True):
        if part is None:
            part = (template.isel(member=[0] * chunk.size).astype(float) * np.nan).assign_coords(
                member=np.arange(chunk.start, chunk.stop))
            part["finished"] = ("member", np.zeros(chunk.size))
        else:
            part = part.assign(finished=("member", np.ones(part.sizes["member"])))
        filled.append(part)
    return filled


def chunk_task(study: Study, chunk: Chunk):
    """A chunk on a dask worker: its Dataset, or the ConfigError it met *returned*, so that bad
    input ends the study with its one-line message instead of a worker traceback and a retry
    (a worker that dies is another matter: dask reschedules its chunks)."""
    try:
        return run_chunk(study, chunk)
    except ConfigError as exc:
        return exc


def assemble(study: Study, chunks: list[Chunk], parts: list, variants: list[str] | None):
    """One Dataset: dimensions (*grid keys, [controller], member), coordinates labelled."""
    import xarray as xr

    by_cell: dict[tuple, list] = {}
    for chunk, part in zip(chunks, parts, strict=True):
        by_cell.setdefault((chunk.point, chunk.variant), []).append(part)
    cells = {key: xr.concat(ps, dim="member", join="outer") for key, ps in by_cell.items()}
    backends = sorted({b for part in parts for b in part.attrs.get("backend", "").split(", ") if b})
    if len(backends) > 1:
        warnings.warn(f"the study's chunks ran on different loops ({', '.join(backends)}; a worker "
                      "without numba runs the numpy loop): members agree to round-off, not to the "
                      "bit; install shipgnc's numba on every worker", ShipGNCWarning, stacklevel=2)
    points = []
    for p in range(len(study.points)):
        if variants is None:
            points.append(cells[(p, None)])
        else:
            points.append(xr.concat([cells[(p, v)] for v in variants], dim="controller", join="outer")
                          .assign_coords(controller=variants))
    if study.grid:
        nested = np.empty(study.shape, dtype=object)
        for i, ds in enumerate(points):
            nested[np.unravel_index(i, study.shape)] = ds
        ds = xr.combine_nested(nested.tolist(), concat_dim=list(study.dims), join="outer",
                               combine_attrs="drop")
        ds = ds.assign_coords({key: list(values) for key, values in study.grid})
        ds = ds.transpose(*study.dims, ...)
    else:
        ds = points[0]
    ds.attrs = {"scenario": study.scenario, "seed": int(study.seed), "members": int(study.members),
                "grid": "; ".join(f"{k}={','.join(map(str, v))}" for k, v in study.grid),
                "perturb": "; ".join(str(p) for p in study.perturb),
                "overrides": "; ".join(study.overrides), "backend": ", ".join(backends),
                "streams": "member i: SeedSequence(seed).spawn(members)[i] (offsets, disturbances, "
                            "plant parameters)"}
    return ds


#: numbers kept per member and cell besides the series: its metrics, parameters and offsets
#: (a generous bound: the richest metric set holds about forty)
NUMBERS_PER_MEMBER = 64


def estimate_memory(study: Study, variants: list[str] | None, chunk_size: int) -> dict[str, int]:
    """Bytes a study holds at its peak, estimated before any work: ``result`` (every member's
    metrics, with ``--series`` every member's thinned series) and ``chunk`` (what one chunk holds
    while it runs, :func:`chunk_numbers`). The measure of a series is
    :func:`shipgnc.sim.simulator.logged_numbers`."""
    cells = len(study.points) * len(variants or [None])
    per_member = NUMBERS_PER_MEMBER
    if study.series:  # the longest series of any grid point (a grid may set t_end, dt, log_every)
        per_member += max(_series_numbers(study, point) for point in range(len(study.points)))
    size = min(chunk_size, study.members)
    # the largest chunk of any grid point and controller (each point may decide otherwise)
    chunk = max(chunk_numbers(study, variant, size, point) for variant in variants or [None]
                for point in range(len(study.points)))
    return {"result": 8 * cells * study.members * per_member, "chunk": 8 * chunk}


def _series_numbers(study: Study, point: int) -> int:
    """Numbers of one member's series at grid point ``point`` (logged at its ``log_every``)."""
    from shipgnc.sim.simulator import logged_numbers

    model, _, sim = _vessel_of(study.scenario_at(study.points[point]), study.seed)
    return logged_numbers(model, (1,), round(sim.t_end / sim.dt), sim.log_every)


def chunk_numbers(study: Study, variant: str | None, size: int, point: int = 0) -> int:
    """Numbers a chunk of ``size`` members of grid point ``point`` holds while it runs,
    as :func:`~shipgnc.study.chunk.run_chunk` will run it (the decision is
    :func:`~shipgnc.study.chunk.in_loop_plan`'s, taken on the chunk's first member). Scored in
    the loop: each member's accumulators and its first and last sample, plus one member's
    every-step record (a diverged member is run again alone with its log). Else the chunk's
    every-step record, about twice (the arrays derived from it)."""
    from shipgnc.sim.simulator import logged_numbers

    scenario, setup, sim, x0, seeds, _ = chunk_setup(study, Chunk(point, 0, 1, variant))
    n_steps = round(sim.t_end / sim.dt)
    planned = in_loop_plan(scenario, setup, sim, x0, seeds, "compiled-or-numpy", study.series)
    if planned is None:
        return 2 * logged_numbers(setup.model, (size,), n_steps)
    _, plan = planned
    return (size * (len(plan.init) + NUMBERS_PER_MEMBER)
            + logged_numbers(setup.model, (size,), n_steps, max(1, n_steps))
            + 2 * logged_numbers(setup.model, (1,), n_steps))


def check_memory(study: Study, variants: list[str] | None, chunk_size: int,
                 max_memory: float | None = None) -> None:
    """A ConfigError naming the estimate and what to change when a study would need more than
    ``max_memory`` bytes (default: the memory available now)."""
    need = estimate_memory(study, variants, chunk_size)
    limit = available_memory() if max_memory is None else max_memory
    what = "the memory available" if max_memory is None else "--max-memory"
    gib = 2.0 ** 30
    if need["chunk"] > limit:
        raise ConfigError(f"--chunk-size {chunk_size}: one chunk's record needs about "
                          f"{need['chunk'] / gib:.1f} GiB, more than {what} "
                          f"({limit / gib:.1f} GiB); use a smaller --chunk-size")
    if need["result"] + need["chunk"] > limit:
        hint = "drop --series or use fewer members (--mc)" if study.series else \
            "use fewer members (--mc) or grid points, or split the study by --seed"
        raise ConfigError(f"the study needs about {(need['result'] + need['chunk']) / gib:,.1f} GiB "
                          f"({study.members:,} members x {len(study.points)} grid points"
                          f"{' x ' + str(len(variants)) + ' controllers' if variants else ''}), "
                          f"more than {what} ({limit / gib:.1f} GiB): {hint}")


def run_study(study: Study, *, workers: str = "local", scheduler: str | None = None,
              chunk_size: int = DEFAULT_CHUNK_SIZE, client=None,
              on_chunk: Callable[[int, int], None] | None = None,
              max_memory: float | None = None, keep_interrupted: bool = False) -> StudyRun:
    """Run ``study`` and return its Dataset (see :func:`assemble`).

    ``workers``: ``"local"`` or ``"dask"`` (a new LocalCluster); ``scheduler``: an existing dask
    cluster's address (implies dask); ``client``: an existing ``dask.distributed.Client`` (tests).
    ``max_memory``: bytes the study may hold (default: the memory available); checked with
    :func:`check_memory` before any work. ``keep_interrupted``: a Ctrl-C returns the chunks that
    had finished (the others' members NaN, ``finished`` 0; ``attrs["interrupted"] = 1``) instead
    of raising, when at least one had.
    """
    import time

    if workers not in WORKERS:
        raise ConfigError(f"--workers {workers!r}: allowed: {', '.join(WORKERS)}")
    variants = variants_of(study)
    check_memory(study, variants, chunk_size, max_memory)
    chunks = plan_chunks(study, variants, chunk_size)
    start = time.perf_counter()
    owned = None
    if client is None and (workers == "dask" or scheduler is not None):
        client = owned = connect(scheduler, workers)
    interrupted = None
    try:
        parts = run_chunks(study, chunks, client=client, on_chunk=on_chunk)
    except Interrupted as exc:  # --keep-partial: the finished chunks, when there are any
        if not keep_interrupted or not any(part is not None for part in exc.partial):
            raise
        parts, interrupted = unfinished_filled(chunks, exc.partial), str(exc)
    finally:
        if owned is not None:
            cluster = getattr(owned, "cluster", None)
            owned.close()
            if cluster is not None and scheduler is None:
                cluster.close()
    ds = assemble(study, chunks, parts, variants)
    if interrupted is not None:
        ds.attrs["interrupted"] = 1
        ds.attrs["members_finished"] = int(ds["finished"].sum())
    how = "local" if client is None else ("scheduler " + scheduler if scheduler else "dask")
    return StudyRun(ds, len(chunks), how, time.perf_counter() - start, interrupted)
