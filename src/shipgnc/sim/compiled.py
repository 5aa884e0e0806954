"""The driver of the compiled loops: chunked kernel calls, progress, divergence and completion
replay, the ``Log``; and the numba plumbing the loops share.

:mod:`shipgnc.sim.compose` composes any combination of components with kernels into one loop and
runs it through :func:`drive` and :func:`make_log`; :mod:`shipgnc.sim.compiled_mariner` is the
last whole-loop twin (document 000's Mariner and its path controllers), which uses the same
driver. A run is one kernel call, or several that carry each ship's state from one to the next
(bit-identical results): about twenty with a progress callback, and short ones for a batch
logging many samples.
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.kernels import JIT_OPTIONS
from shipgnc.kernels import clip as _clip  # noqa: F401  (the Mariner twin's scalar helpers)
from shipgnc.kernels import wrap as _wrap  # noqa: F401

#: number of kernel calls when a progress callback is given
PROGRESS_CHUNKS = 20
#: ship-steps worth a thread of their own (≈ 10 ms)
MIN_THREAD_WORK = 100_000
#: most logged samples per ship of one kernel call in a batch: the log is (variable, sample, ship),
#: so neighbouring ships share its cache lines, and short calls keep them cached from one ship to
#: the next (a 1 000-ship log of every step is written ≈ 2× faster)
LOG_SAMPLES_PER_CALL = 256

_JITTED: dict = {}
_NUMBA_ERROR: str | None = None
_NUMBA_CHECKED = False


# ----------------------------------------------------------------------------------------------
# sin/cos of RK4 stages (the Mariner twin)
# ----------------------------------------------------------------------------------------------

def _sin_cos_shifted(s, c, angle, delta):
    """sin and cos of ``angle + delta`` from s = sin(angle), c = cos(angle).

    Angle addition with the Taylor series of sin δ and cos δ − 1 (truncation < 3e-18 relative for
    |δ| ≤ 0.1): the RK4 stages of one step share one libm ``sincos`` call. Larger δ use libm.
    """
    if abs(delta) <= 0.1:
        d2 = delta * delta
        sd = delta + delta * d2 * (-1.0 / 6.0 + d2 * (1.0 / 120.0 + d2 * (-1.0 / 5040.0
                                                                          + d2 * (1.0 / 362880.0))))
        cm1 = d2 * (-0.5 + d2 * (1.0 / 24.0 + d2 * (-1.0 / 720.0 + d2 * (1.0 / 40320.0
                                                                        - d2 * (1.0 / 3628800.0)))))
        return s + (s * cm1 + c * sd), c + (c * cm1 - s * sd)
    return math.sin(angle + delta), math.cos(angle + delta)


# ----------------------------------------------------------------------------------------------
# numba plumbing
# ----------------------------------------------------------------------------------------------

def jit(function, *, parallel: bool = False):
    """The numba dispatcher of a kernel function or scalar helper (one per function, shared by the
    twins; :data:`JIT_OPTIONS`). Scalar helpers are inlined by LLVM into the kernels calling them.

    A kernel finds its helpers as module globals, so each twin's ``_load`` rebinds its names to
    the dispatchers before its kernel compiles. numba's disk cache is keyed to the source file of
    the cached function only: after editing a helper of this module, delete the twins'
    ``__pycache__/*.nbi`` files so that no kernel inlining the old helper is loaded.
    """
    import numba

    py = _py(function)
    key = (py, parallel)
    if key not in _JITTED:
        _JITTED[key] = numba.njit(parallel=parallel, **JIT_OPTIONS)(py)
    return _JITTED[key]


def _py(function):
    """The plain Python function behind a (possibly already wrapped) numba dispatcher."""
    return getattr(function, "py_func", function)


def _numba_error() -> str | None:
    """None if numba imports, else the reason (checked once per process)."""
    global _NUMBA_CHECKED, _NUMBA_ERROR
    if not _NUMBA_CHECKED:
        _NUMBA_CHECKED = True
        try:
            import numba  # noqa: F401
        except Exception as exc:  # ImportError, or a broken install (llvmlite mismatch, ...)
            _NUMBA_ERROR = f"numba cannot be imported ({type(exc).__name__}: {exc})"
    return _NUMBA_ERROR


def _owned(values) -> np.ndarray:
    """A fresh, writeable, C-ordered float64 copy: one kernel signature whatever the caller passes
    (numba compiles read-only or strided arrays as other types)."""
    return np.array(values, dtype=np.float64, order="C", copy=True)


# ----------------------------------------------------------------------------------------------
# the shared driver: chunked kernel calls, progress, divergence replay, the Log
# ----------------------------------------------------------------------------------------------

def log_layout(setup, names: list[str]):
    """``log_signals(setup)``, after checking that a kernel's log columns ``names`` match it."""
    from shipgnc.sim.simulator import log_signals

    signals = log_signals(setup)
    if list(names) != list(signals):  # the kernel's column layout must match the numpy loop's log
        raise RuntimeError(f"compiled loop: log layout {list(names)} differs from {list(signals)}")
    return signals


def log_length(setup) -> int:
    """Number of logged samples of a full run: every ``log_every``-th step and the last one."""
    n_steps, every = int(setup.n_steps), int(setup.log_every)
    return n_steps // every + 1 + (1 if n_steps % every else 0)


def drive(setup, call, S: np.ndarray, div_event: np.ndarray, *, n_chunks: int = 1,
          prepare=None, done_at: np.ndarray | None = None) -> tuple[int | None, int]:
    """Run a kernel over steps 0 … n_steps; returns the first divergence event (or None) and the
    last step run.

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
    step. The chunks give bit-identical results.
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
        n_chunks = max(n_chunks, math.ceil(log_length(setup) / LOG_SAMPLES_PER_CALL))
    bounds = np.linspace(0, n_steps + 1, min(n_chunks, n_steps + 1) + 1).round().astype(int)
    if setup.progress is not None:
        setup.progress(0, n_steps)
    for k0, k1 in zip(bounds[:-1].tolist(), bounds[1:].tolist(), strict=True):
        if prepare is not None:
            prepare(k0, k1)
        start = S.copy()
        done_start = None if done_at is None else done_at.copy()
        limited(k0, k1, n_steps)
        event = int(div_event[div_event >= 0].min()) if (div_event >= 0).any() else None
        k_done = None
        if done_at is not None and n_ships and bool(np.all(done_at >= 0)):
            k_done = int(done_at.max())  # every ship finished: the run ends at this sample ...
            if event is not None and event < 2 * k_done + 1:
                k_done = None  # ... unless a ship diverged before
        if event is None and k_done is None:
            if setup.progress is not None:
                setup.progress(k1 - 1, n_steps)
            continue
        S[:] = start
        div_event[:] = -1
        if done_start is not None:
            done_at[:] = done_start
        if k_done is not None:
            limited(k0, k_done + 1, k_done)
            if setup.progress is not None:
                setup.progress(n_steps, n_steps)
            return None, k_done
        limited(k0, event // 2 + 1, n_steps)
        return event, event // 2
    return None, n_steps


def make_log(setup, signals, out: np.ndarray, S: np.ndarray, event: int | None, *, state_slot: int,
             cmd_slot: int, k_end: int | None = None):
    """The run's ``Log`` from the kernel's ``out`` (variable, sample, ship), the first divergence
    ``event`` and the last step run ``k_end`` (see :func:`drive`): the numpy loop's sample times,
    status and divergence error (``S[:, state_slot:]`` holds the states, ``S[:, cmd_slot:]`` the
    commands). Raises the error for ``on_divergence="raise"``."""
    from shipgnc.sim.simulator import Log, check_divergence

    batch = setup.batch_shape
    n_steps, every, dt = int(setup.n_steps), int(setup.log_every), float(setup.dt)
    n_states, n_inputs = len(setup.model.states), int(setup.actuator.n)
    last = n_steps if (k_end is None or event is not None) else k_end
    log_steps = np.arange(0, last + 1, every)
    if last % every:
        log_steps = np.append(log_steps, last)
    status: dict = {"diverged": 0, "stopped_early": 0, "message": ""}
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
    return Log(time=log_steps[:n_logged] * dt, data=data, signals=signals, status=status)


