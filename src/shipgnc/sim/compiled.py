"""The driver of the compiled loop: chunked kernel calls, progress, divergence and completion
replay, the ``Log``.

:mod:`shipgnc.sim.compose` composes any combination of components with kernels into one loop and
runs it through :func:`drive` and :func:`make_log`. A run is several kernel calls that carry
each ship's state from one to the next (bit-identical results): each about :data:`CALL_S` long
(Ctrl-C is seen between calls), at least twenty with a progress callback, and short ones for a
batch logging many samples.
"""

from __future__ import annotations

import itertools
import math
from typing import NamedTuple

import numpy as np

#: number of kernel calls when a progress callback is given
PROGRESS_CHUNKS = 20
#: ship-steps worth a thread of their own (≈ 10 ms)
MIN_THREAD_WORK = 100_000
#: most ship-steps of one kernel call (≈ 0.5 s): Ctrl-C is seen between calls
MAX_CALL_WORK = 5_000_000
#: most logged samples per ship of one kernel call in a batch: the log is (variable, sample, ship),
#: so neighbouring ships share its cache lines, and short calls keep them cached from one ship to
#: the next (a 1 000-ship log of every step is written ≈ 2× faster) ...
LOG_SAMPLES_PER_CALL = 256
#: ... unless the call would then hold fewer ship-steps than this: a call costs ≈ 0.5 µs per ship
#: (its carried state unpacked into local arrays) and ≈ 0.1–3 ms of Python (its input tables), so
#: a few ships logging every step are not cut into hundreds of calls of a millisecond's work
MIN_LOGGED_CALL_WORK = 500_000
#: seconds a kernel call should last at most: Ctrl-C is answered between calls (a signal waits
#: for compiled code to return), so each run is cut into calls about this long, measured as it goes
#: (wall time: a loaded machine makes calls shorter, so the fixed cost per call must stay small
#: beside this: 2 000 ships × 1 000 steps in 100 calls took 27–45 % more CPU than in one)
CALL_S = 0.25
#: ship-steps of the first call (before the rate is known), and the growth of a call over the last
FIRST_CALL_WORK = 20_000
CALL_GROWTH = 4
#: kernel calls of a run whose guidance can finish: the kernel steps a finished ship on to the end
#: of its call (only the driver sees that every ship has finished) and the call that holds the
#: last finish is replayed up to it, so both costs are one call's share of the run, not the run
FINISH_CHUNKS = 32


# ----------------------------------------------------------------------------------------------
# the shared driver: chunked kernel calls, progress, divergence replay, the Log
# ----------------------------------------------------------------------------------------------

def log_length(setup) -> int:
    """Number of logged samples of a full run: every ``log_every``-th step and the last one."""
    n_steps, every = int(setup.n_steps), int(setup.log_every)
    return n_steps // every + 1 + (1 if n_steps % every else 0)


def drive(setup, call, S: np.ndarray, div_event: np.ndarray, *, n_chunks: int = 1,
          prepare=None, done_at: np.ndarray | None = None) -> Stop:
    """Run a kernel over steps 0 … n_steps; returns how it ended (:class:`Stop`).

    ``call(k0, k1, k_last)`` runs steps ``k0 <= k < k1`` of every ship (``k_last``: the step that
    is logged whatever ``log_every`` and ends the run), carrying each ship's state in its row of
    ``S`` and writing ``div_event[i]`` = 2k (bad command at sample k) or 2k + 1 (bad state after
    step k) when ship i diverges, and ``done_at[i]`` = the first step at which ship i's guidance
    has finished (when ``done_at`` is given). The steps are cut into ``n_chunks`` calls, or more:
    at least :data:`PROGRESS_CHUNKS` with a progress callback (reported after each call), and for
    a batch at most :data:`LOG_SAMPLES_PER_CALL` logged samples per call. ``prepare(k0, k1)`` runs
    before each call (e.g. to fill the chunk's input tables). As the numpy loop stops the whole
    batch at the first bad sample, or once every ship has finished, the chunk holding that event
    is replayed up to it: ``S`` then holds every ship's command of that sample or state after that
    step. With ``on_divergence="mask"`` a diverged ship stops alone (the kernel skips a ship whose
    ``div_event`` is set) and, when the guidance can finish (``done_at`` given), counts as finished
    from its divergence on. The chunks give
    bit-identical results.
    """
    import numba

    n_ships, n_steps = S.shape[0], int(setup.n_steps)
    # small runs on one thread: a parallel region waits for every worker thread, which costs a
    # scheduler tick when the other cores are busy
    threads = max(1, min(numba.get_num_threads(), n_ships, n_ships * n_steps // MIN_THREAD_WORK))

    def limited(k0: int, k1: int, k_last: int) -> None:
        previous = numba.get_num_threads()
        numba.set_num_threads(threads)  # local to the calling thread
        try:
            call(k0, k1, k_last)
        finally:
            numba.set_num_threads(previous)

    if setup.progress is not None:
        n_chunks = max(n_chunks, PROGRESS_CHUNKS)
    if n_ships > 1:
        n_chunks = max(n_chunks, math.ceil(log_length(setup) / log_samples_per_call(setup, n_ships)))
    if done_at is not None:
        n_chunks = max(n_chunks, FINISH_CHUNKS)
    n_chunks = max(n_chunks, math.ceil(n_ships * (n_steps + 1) / MAX_CALL_WORK))
    bounds = np.linspace(0, n_steps + 1, min(n_chunks, n_steps + 1) + 1).round().astype(int)
    if setup.progress is not None:
        setup.progress(0, n_steps)
    done_through = -1  # the last step every ship has completed (Ctrl-C keeps the log up to it)
    masking = setup.on_divergence == "mask"
    try:
        for k0, k1 in _timed_calls(bounds.tolist(), n_ships):
            if prepare is not None:
                prepare(k0, k1)
            start = S.copy()
            done_start = None if done_at is None else done_at.copy()
            event_start = div_event.copy()
            limited(k0, k1, n_steps)
            event = None
            if not masking and (div_event >= 0).any():
                event = int(div_event[div_event >= 0].min())
            k_done = None
            if masking and done_at is not None and n_ships:
                ends = finish_steps(done_at, div_event)
                if bool(np.all(ends >= 0)):
                    k_done = int(ends.max())  # every ship finished or stopped
            elif done_at is not None and n_ships and bool(np.all(done_at >= 0)):
                k_done = int(done_at.max())  # every ship finished: the run ends at this sample ...
                if event is not None and event < 2 * k_done + 1:
                    k_done = None  # ... unless a ship diverged before
            if event is None and k_done is None:
                done_through = k1 - 1
                if setup.progress is not None:
                    setup.progress(k1 - 1, n_steps)
                continue
            S[:] = start
            div_event[:] = event_start
            if done_start is not None:
                done_at[:] = done_start
            if k_done is not None:
                limited(k0, k_done + 1, k_done)
                if setup.progress is not None:
                    setup.progress(n_steps, n_steps)
                return _complete(setup, Stop(None, k_done))
            limited(k0, event // 2 + 1, n_steps)
            return _complete(setup, Stop(event, event // 2))
        return _complete(setup, Stop(None, n_steps))
    except KeyboardInterrupt:  # Ctrl-C between (or within) kernel calls
        return Stop(None, done_through, interrupted=True)


def _complete(setup, stop: Stop) -> Stop:
    """``stop``, a run that ended without a Ctrl-C, after ``setup.on_complete()`` (if any): the
    caller learns the run is complete before its log is gathered."""
    on_complete = getattr(setup, "on_complete", None)
    if on_complete is not None:
        on_complete()
    return stop


def log_samples_per_call(setup, n_ships: int) -> int:
    """Most logged samples per ship of one kernel call of a batch: :data:`LOG_SAMPLES_PER_CALL`,
    or as many as make a call of :data:`MIN_LOGGED_CALL_WORK` ship-steps."""
    steps = math.ceil(MIN_LOGGED_CALL_WORK / max(n_ships, 1))
    return max(LOG_SAMPLES_PER_CALL, math.ceil(steps / int(setup.log_every)))


def _timed_calls(bounds: list[int], n_ships: int):
    """The calls ``(k0, k1)`` of a run: each interval of ``bounds`` cut into calls of about
    :data:`CALL_S` seconds, the steps per second measured on the calls before (the first two
    calls :data:`FIRST_CALL_WORK` ship-steps: the first may compile the kernel; each call at most
    :data:`CALL_GROWTH` times the last). How the steps are cut changes no result (the calls carry
    each ship's state exactly)."""
    import time

    size = max(1, FIRST_CALL_WORK // max(n_ships, 1))
    first = True
    for a, b in itertools.pairwise(bounds):
        k = a
        while k < b:
            k1 = min(b, k + size)
            start = time.perf_counter()
            yield k, k1
            elapsed = time.perf_counter() - start
            if not first:  # the first call's time is mostly compiling, not stepping
                rate = (k1 - k) / max(elapsed, 1e-6)
                size = max(1, min(int(rate * CALL_S), CALL_GROWTH * (k1 - k)))
            first = False
            k = k1


def finish_steps(done_at: np.ndarray, div_event: np.ndarray) -> np.ndarray:
    """``on_divergence="mask"``: the step from which each ship counts as done (its guidance
    finished, or it diverged: at its bad command's sample k, or at step k + 1 after its bad state
    of step k), −1 while it runs on (the numpy loop's ``finished | ~alive``)."""
    died = np.where(div_event >= 0, div_event // 2 + div_event % 2, -1)
    both = (done_at >= 0) & (died >= 0)
    return np.where(both, np.minimum(done_at, died), np.maximum(done_at, died))


class Stop(NamedTuple):
    """How a compiled run ended: the first divergence ``event`` (or None), the last step run
    ``k_end``, and whether Ctrl-C ended it (the log then holds the samples up to ``k_end``)."""

    event: int | None
    k_end: int
    interrupted: bool = False


def make_log(setup, signals, out: np.ndarray, S: np.ndarray, event: int | None, *, state_slot: int,
             cmd_slot: int, k_end: int | None = None, interrupted: bool = False,
             events: np.ndarray | None = None):
    """The run's ``Log`` from the kernel's ``out`` (variable, sample, ship), the first divergence
    ``event`` and the last step run ``k_end`` (see :func:`drive`): the numpy loop's sample times,
    status and divergence error (``S[:, state_slot:]`` holds the states, ``S[:, cmd_slot:]`` the
    commands). Raises the error for ``on_divergence="raise"``; with ``"mask"`` each ship's
    ``events`` entry (see :func:`drive`) ends its own record
    (:func:`~shipgnc.sim.simulator.mask_diverged`)."""
    from shipgnc.sim.simulator import Log, check_divergence

    batch = setup.batch_shape
    n_steps, every, dt = int(setup.n_steps), int(setup.log_every), float(setup.dt)
    n_states, n_inputs = len(setup.model.states), int(setup.actuator.n)
    last = n_steps if (k_end is None or event is not None) else k_end
    log_steps = np.arange(0, last + 1, every)
    if last % every and not interrupted:  # an interrupted run logged the grid only
        log_steps = np.append(log_steps, last)
    status: dict = {"diverged": 0, "stopped_early": 0, "message": ""}
    if interrupted:
        done = float(log_steps[-1] * dt) if log_steps.size else 0.0
        status.update(stopped_early=1, interrupted=1, message=f"interrupted at t = {done:.6g} s")
    n_logged = log_steps.size
    if event is not None:
        k = event // 2
        if event % 2 == 0:  # the command of sample k: samples before k are logged
            n_logged = (k - 1) // every + 1
            command = S[:, cmd_slot:cmd_slot + n_inputs].reshape(*batch, n_inputs)
            error = check_divergence(setup, k * dt, command=command)
        else:  # the state after step k: samples up to k are logged
            n_logged = k // every + 1
            t = k * dt
            error = check_divergence(setup, t + dt,
                                     S[:, state_slot:state_slot + n_states].reshape(*batch, n_states))
        if error is None:
            raise RuntimeError(f"compiled loop: divergence event {event} not confirmed by "
                               "check_divergence")
        if setup.on_divergence == "raise":
            raise error
        status.update(diverged=1, message=str(error))
    data = {name: out[col, :n_logged].reshape(n_logged, *batch) for col, name in enumerate(signals)}
    log = Log(time=log_steps[:n_logged] * dt, data=data, signals=signals, status=status)
    if setup.on_divergence != "mask" or events is None:
        return log
    from shipgnc.sim.simulator import mask_diverged

    k = events // 2
    diverged_at = np.where(events < 0, np.nan, np.where(events % 2 == 0, k * dt, k * dt + dt))
    first = None
    if (events >= 0).any():
        e = int(events[events >= 0].min())
        ships = (events == e)[:, None]
        if e % 2 == 0:
            command = np.where(ships, S[:, cmd_slot:cmd_slot + n_inputs], 0.0)
            first = check_divergence(setup, (e // 2) * dt, command=command.reshape(*batch, n_inputs))
        else:
            x = np.where(ships, S[:, state_slot:state_slot + n_states], 0.0)
            first = check_divergence(setup, (e // 2) * dt + dt, x.reshape(*batch, n_states))
    return mask_diverged(log, diverged_at.reshape(batch), first, dt)


