"""Worker processes die with the process that started them.

A forked worker (the figure process, a pool's) outlives its parent when the parent is killed
(``kill -9``, SIGTERM, the out-of-memory killer): nothing is left to stop it, and it holds its
memory until it ends by itself, if ever. Two guards, set up first thing in the worker:

* Linux's parent-death signal, ``prctl(PR_SET_PDEATHSIG, SIGKILL)`` (prctl(2)): the kernel kills
  the worker the moment the thread that forked it exits;
* a watchdog thread that polls ``os.getppid()`` (the worker is re-parented when its parent dies)
  and ends the worker, where prctl is unavailable or refused.

Ctrl-C: a terminal sends SIGINT to the whole process group. The worker ignores it (its parent
answers Ctrl-C and stops the worker), so that it prints no traceback of its own. SIGINT stays
blocked in the parent while it forks (:func:`forking`): one that arrives meanwhile is delivered to
the parent after the fork, never to a worker that has not yet set its handler.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import signal
import sys
import threading
import time
from collections.abc import Iterator

#: prctl(2) option: the signal sent to this process when its parent thread exits
PR_SET_PDEATHSIG = 1
#: seconds between the watchdog's looks at the parent
POLL_S = 0.25


def die_with_parent(parent_pid: int, *, ignore_sigint: bool = True) -> None:
    """In a worker just forked from ``parent_pid``: end it when that parent is gone (see the
    module docstring); with ``ignore_sigint`` also ignore a terminal's Ctrl-C, and unblock it."""
    if ignore_sigint and threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    with contextlib.suppress(AttributeError, OSError, ValueError):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    if sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
    if os.getppid() != parent_pid:  # the parent died before the guard was set
        os._exit(1)
    threading.Thread(target=_watch, args=(parent_pid,), name="shipgnc-lifeline", daemon=True).start()


def _watch(parent_pid: int) -> None:
    while os.getppid() == parent_pid:
        time.sleep(POLL_S)
    os._exit(1)


@contextlib.contextmanager
def forking() -> Iterator[None]:
    """Block SIGINT in this (main) thread while a worker is forked; a Ctrl-C meanwhile is
    delivered here when the block ends."""
    try:
        previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    except (AttributeError, OSError, ValueError):
        yield
        return
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)
