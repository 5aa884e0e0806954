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

A Python signal handler runs only when the main thread returns to the interpreter: compiled code
(a numba kernel, LLVM compiling one, HDF5 writing, a C extension importing) delays it, and so can
a slow exit (a worker to stop, threads to join). The command line therefore arms an exit
deadline (:func:`arm_exit_deadline`): the C-level handler wakes a watchdog thread through
``signal.set_wakeup_fd``, and if the process is still there :data:`EXIT_DEADLINE_S` after the
Ctrl-C, the watchdog says the one line (unless it was said), runs the registered clean-ups
(:func:`on_hard_exit`: temporary output directories) and ends the process with exit 130. While a
partial result is being kept (:func:`keeping`) the first Ctrl-C waits for it; a second one ends
the process at once.
"""

from __future__ import annotations

import os
import select
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

_latched = False
_previous_hook = sys.__unraisablehook__


_holding = False  # a complete result is being kept (hold()): the first Ctrl-C is held, not raised
_held = False


def _handler(signum, frame) -> None:
    global _latched
    _latched = True
    if not held_now():
        raise KeyboardInterrupt


def held_now() -> bool:
    """A Ctrl-C arrives (or was deferred): True when it is held (:func:`hold`), so not to be raised."""
    global _held
    if _holding and not _held:
        _held = True
        return True
    return False


def hold(on: bool = True) -> None:
    """From now until the command ends (or ``hold(False)``: the next run starts), a first Ctrl-C is
    held (latched, :func:`held` says so) instead of raised: a run kept with --keep-partial has
    finished, and its complete result is written before the command ends as interrupted; a second
    Ctrl-C still raises."""
    global _holding
    _holding = on


def held() -> bool:
    """Whether a Ctrl-C was held since :func:`hold`."""
    return _held


def _unraisable(info) -> None:
    """A latched Ctrl-C that a callback could not raise is not printed (it is acted on later),
    nor, once a Ctrl-C is latched, a finaliser's error: an object the KeyboardInterrupt cut short
    while it was built fails in its ``__del__`` (llvmlite's ``PassBuilder`` interrupted in a
    compile: "AttributeError: _as_parameter_"), a consequence of the Ctrl-C, not a fault to
    report in place of its one line. Anything else goes to Python's own hook."""
    if not _latched:
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
    global _latched, _said_flag, _noted, _holding, _held
    previous = signal.getsignal(signal.SIGINT) if _main_thread() else None
    hook = sys.unraisablehook
    install()
    if previous is not _handler:  # a command of its own: its one line is still to be said
        _said_flag = False
        _holding = _held = False
        note("interrupted")
    caught = False
    try:
        yield
    except Exception:
        if _latched:  # an error that follows a Ctrl-C is its consequence (a compile it cut short)
            raise KeyboardInterrupt from None
        raise
    finally:
        caught = _latched
        if previous is not None and previous is not _handler:  # this block installed the latch
            signal.signal(signal.SIGINT, previous)
            sys.unraisablehook = hook
            _latched = _holding = _held = False  # a later command, or library call, starts clear
    if caught:
        raise KeyboardInterrupt


#: seconds from Ctrl-C to the end of the process, at most (the requirement is 0.5 s)
EXIT_DEADLINE_S = 0.2
#: the exit code of an interrupted command (128 + SIGINT, as a shell reports it)
EXIT_INTERRUPTED = 130

_said = threading.Lock()
_said_flag = False
_noted = "interrupted"
_keeping = False
_cleanups: dict[int, Callable[[], None]] = {}
_armed = False


def say_once(line: str) -> bool:
    """Write the command's one line about the interrupt on stderr, unless it was written; True
    when this call wrote it."""
    global _said_flag
    with _said:
        if _said_flag:
            return False
        _said_flag = True
        try:
            sys.stderr.write(line.rstrip("\n") + "\n")
            sys.stderr.flush()
        except (OSError, ValueError):
            pass
        return True


def note(line: str) -> None:
    """What the interrupt cut short, in the one line the watchdog says if the command has not
    said its own by the deadline (e.g. "interrupted after 3 of 8 chunks")."""
    global _noted
    _noted = " ".join(str(line).split()) or "interrupted"


def noted() -> str:
    """The line :func:`note` last set: what a Ctrl-C now cuts short."""
    return _noted


def on_hard_exit(key: int, cleanup: Callable[[], None] | None) -> None:
    """Register (or, with None, drop) a clean-up the watchdog runs before it ends the process."""
    if cleanup is None:
        _cleanups.pop(key, None)
    else:
        _cleanups[key] = cleanup


@contextmanager
def keeping() -> Iterator[None]:
    """Inside the block the first Ctrl-C does not end the process at the deadline (a partial
    result is being kept, as asked); a second one still does."""
    global _keeping
    previous, _keeping = _keeping, True
    try:
        yield
    finally:
        _keeping = previous


def arm_exit_deadline() -> None:
    """From now on (main thread, once per process) a Ctrl-C ends the process within
    :data:`EXIT_DEADLINE_S` s (see the module docstring)."""
    global _armed
    if _armed or not _main_thread():
        return
    try:
        read, write = os.pipe()
        os.set_blocking(write, False)
        signal.set_wakeup_fd(write, warn_on_full_buffer=False)
    except (OSError, ValueError, AttributeError):
        return
    _armed = True
    threading.Thread(target=_watchdog, args=(read,), name="shipgnc-ctrl-c", daemon=True).start()


def _watchdog(read: int) -> None:
    deadline = None
    count = 0
    while True:
        timeout = None if deadline is None else max(0.0, deadline - time.monotonic())
        ready, _, _ = select.select([read], [], [], timeout)
        if ready:
            data = os.read(read, 64)
            hits = data.count(bytes([signal.SIGINT]))
            if not hits:
                continue
            count += hits
            deadline = min(deadline or float("inf"),
                           time.monotonic() + (0.0 if count >= 2 else EXIT_DEADLINE_S))
            continue
        if deadline is not None and time.monotonic() >= deadline:
            if _keeping and count < 2:  # a partial result is being kept: wait for it
                deadline = time.monotonic() + EXIT_DEADLINE_S
                continue
            _hard_exit()


def _hard_exit() -> None:
    say_once(_noted)
    for cleanup in list(_cleanups.values()):
        try:
            cleanup()
        except Exception:  # the process ends now, whatever a clean-up met
            pass
    os._exit(EXIT_INTERRUPTED)


def exit_now(code: int = EXIT_INTERRUPTED) -> None:
    """End an interrupted command at once, its line said: the standard streams flushed, and no
    interpreter shutdown (collecting a large run's memory, joining threads), which can take
    seconds and would let the Ctrl-C wait."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass
    os._exit(code)
