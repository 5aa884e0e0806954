"""Draw figures in a worker process that starts while the simulation runs.

Importing matplotlib and rendering the PNGs of a small scenario take about as long as importing
xarray and simulating it. A worker forked first, while the command line has imported little more
than typer (no numpy threads yet), imports matplotlib on the second core meanwhile, so
a command-line run costs the longer of the two, not their sum. Linux only (``fork``); elsewhere,
and on any failure of the worker, the figures are drawn in this process. The worker dies with
this process and ignores Ctrl-C, which this process answers (:mod:`shipgnc.lifeline`).
"""

from __future__ import annotations

import concurrent.futures
import multiprocessing
import os
import sys
from collections.abc import Callable


def _preload(parent_pid: int) -> None:
    from shipgnc.lifeline import die_with_parent

    die_with_parent(parent_pid)  # killed with the command, and deaf to the terminal's Ctrl-C
    import matplotlib

    matplotlib.use("Agg")
    import shipgnc.viz.dashboard  # noqa: F401  (the import is the point: it runs meanwhile)


def _ready() -> bool:
    return True


class FigureProcess:
    """A one-worker process pool, warmed up at construction. Use as a context manager.

    ``SHIPGNC_FIGURE_PROCESS=0`` disables it (figures are then drawn in the calling process).
    """

    def __init__(self) -> None:
        self._pool = None
        if os.environ.get("SHIPGNC_FIGURE_PROCESS", "1") == "0" or not sys.platform.startswith("linux"):
            return
        from shipgnc.lifeline import forking

        try:
            ctx = multiprocessing.get_context("fork")
            self._pool = concurrent.futures.ProcessPoolExecutor(
                max_workers=1, mp_context=ctx, initializer=_preload, initargs=(os.getpid(),))
            with forking():
                self._pool.submit(_ready)  # start the worker (and its imports) now
        except (OSError, RuntimeError, ValueError):
            self._pool = None

    def submit(self, fn: Callable, *args) -> _Pending:
        """Start ``fn(*args)`` in the worker; ``.result()`` waits for it. If the worker is
        unavailable or breaks, ``result()`` runs ``fn`` in this process instead."""
        future = None
        if self._pool is not None:
            try:
                future = self._pool.submit(fn, *args)
            except (concurrent.futures.process.BrokenProcessPool, RuntimeError, OSError):
                self.close()
        return _Pending(future, fn, args, self)

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None

    def terminate(self) -> None:
        """Stop the worker now (Ctrl-C, a failed run): a figure half-drawn is abandoned and
        nothing more is written; the command does not wait for the drawing to end."""
        if self._pool is None:
            return
        processes = list(getattr(self._pool, "_processes", {}).values())
        for process in processes:
            process.terminate()
        for process in processes:  # dead within milliseconds of SIGTERM; else SIGKILL
            process.join(timeout=2.0)
            if process.is_alive():
                process.kill()
                process.join(timeout=2.0)
        # join the pool's manager thread too: left running (shutdown(wait=False)), the interpreter's
        # exit handler wakes it through a pipe the broken pool has closed, and prints "Exception
        # ignored ... Bad file descriptor" after the command's one line
        self._pool.shutdown(wait=True, cancel_futures=True)
        self._pool = None

    def __enter__(self) -> FigureProcess:
        return self

    def __exit__(self, exc_type, *exc) -> None:
        if exc_type is not None and issubclass(exc_type, BaseException) and not issubclass(
                exc_type, Exception):  # KeyboardInterrupt, SystemExit: do not wait for figures
            self.terminate()
        else:
            self.close()


class _Pending:
    def __init__(self, future, fn: Callable, args: tuple, owner: FigureProcess | None = None):
        self._future, self._fn, self._args, self._owner = future, fn, args, owner

    def cancel(self, timeout: float = 10.0) -> None:
        """Give up on the result: cancel the job, or stop the worker running it (so that it no
        longer writes where the caller is about to clean up); its outcome is ignored. Without
        a worker to stop, wait up to ``timeout`` s for the running job to end."""
        if self._future is None or self._future.cancel():
            return
        if self._owner is not None and self._owner._pool is not None:
            self._owner.terminate()
            return
        try:
            concurrent.futures.wait([self._future], timeout=timeout)
        except BaseException:  # a second Ctrl-C: stop waiting
            pass

    def result(self):
        if self._future is not None:
            try:
                return self._future.result()
            except (concurrent.futures.process.BrokenProcessPool, OSError, EOFError):
                pass
        return self._fn(*self._args)
