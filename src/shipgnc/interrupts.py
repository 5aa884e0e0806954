"""Ctrl-C is never lost.

Python delivers SIGINT as a KeyboardInterrupt wherever the main thread happens to be. Raised
inside a weakref or ``__del__`` callback (an import's module lock, one of h5py's object IDs) it
is printed as "Exception ignored" and the program runs on: a command interrupted at such a
moment finished and exited 0. The handler here raises the KeyboardInterrupt as Python's own does
and also *latches* it (and such a swallowed one is not printed), so that

* a command that reaches its end after a swallowed Ctrl-C ends as interrupted (exit 130,
  :func:`latching` raises it again there), and
* a complete run's files are not moved into place (:func:`shipgnc.outputs.atomic_dir` asks
  :func:`latched` before it moves them).
"""

from __future__ import annotations

import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager

_latched = False
_previous_hook = sys.__unraisablehook__


def _handler(signum, frame) -> None:
    global _latched
    _latched = True
    raise KeyboardInterrupt


def _unraisable(info) -> None:
    """A latched Ctrl-C that a callback could not raise is not printed (it is acted on later);
    anything else goes to Python's own hook."""
    if not (_latched and isinstance(info.exc_value, KeyboardInterrupt)):
        _previous_hook(info)


def _main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


def install() -> None:
    """Latch Ctrl-C from now on (main thread only, and only in place of Python's default
    handler); installed afresh, the latch starts clear."""
    global _latched, _previous_hook
    if not _main_thread():
        return
    current = signal.getsignal(signal.SIGINT)
    if current is signal.default_int_handler:
        _latched = False
        signal.signal(signal.SIGINT, _handler)
        if sys.unraisablehook is not _unraisable:
            _previous_hook = sys.unraisablehook
        sys.unraisablehook = _unraisable


def latched() -> bool:
    """Whether a Ctrl-C arrived since :func:`install` (delivered, or swallowed by a callback)."""
    return _latched


@contextmanager
def latching() -> Iterator[None]:
    """Ctrl-C latched inside the block, the previous handler restored after it; a block that ends
    normally after a Ctrl-C that something swallowed raises KeyboardInterrupt."""
    global _latched
    previous = signal.getsignal(signal.SIGINT) if _main_thread() else None
    hook = sys.unraisablehook
    install()
    caught = False
    try:
        yield
    finally:
        caught = _latched
        if previous is not None and previous is not _handler:  # this block installed the latch
            signal.signal(signal.SIGINT, previous)
            sys.unraisablehook = hook
            _latched = False  # a later command, or library call, starts clear
    if caught:
        raise KeyboardInterrupt
