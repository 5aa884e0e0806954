"""The ``shipgnc`` command (also ``python -m shipgnc``): ``[project.scripts]`` points here.

A light entry point: Ctrl-C while the command-line modules are still importing (about a second
on a cold start) is answered like Ctrl-C later — one line, exit 130 — instead of a traceback. A
finished command ends without the interpreter's teardown (:func:`exit_finished`; the exit
handlers run, standard output is flushed and its errors reported) when the command is the program
itself (:func:`is_program`: not under a profiler, a tracer or a script running the package through
:mod:`runpy`); ``SHIPGNC_QUICK_EXIT=0`` keeps Python's ordinary exit.
"""

from __future__ import annotations

import atexit
import contextlib
import os
import sys
import threading

EXIT_INTERRUPTED = 130


def main() -> None:
    from shipgnc.interrupts import arm_exit_deadline, install

    install()  # from the first moment: a Ctrl-C swallowed while importing still ends the command
    arm_exit_deadline()  # and the command ends within half a second of it, whatever it is doing
    try:
        from shipgnc.cli import main as cli_main
    except KeyboardInterrupt:
        sys.stderr.write("interrupted while starting\n")
        raise SystemExit(EXIT_INTERRUPTED) from None
    try:
        try:
            cli_main()
        except SystemExit as done:  # finished: end without tearing the interpreter down
            if is_program(sys._getframe(1)):
                exit_finished(done.code)
            raise
    except KeyboardInterrupt:  # outside the command (its exit handlers): the one line, no traceback
        from shipgnc.interrupts import noted, say_once

        say_once(noted())
        raise SystemExit(EXIT_INTERRUPTED) from None


def exit_finished(code: object) -> None:
    """End a command that finished (``code``: its ``SystemExit`` code) without the interpreter's
    teardown, and return only when that is not safe.

    The command's files are written and closed when it returns; what Python does after that is
    tear down the tens of thousands of objects that numpy, scipy, numba, xarray and matplotlib
    created at import (0.5–0.8 s of a ``shipgnc run`` on the reference machine, for nothing).
    Here the exit handlers run as Python runs them (:mod:`atexit`: temporary directories,
    multiprocessing's workers, logging), the standard streams are flushed, and the process ends
    with ``code``. It returns, leaving the ordinary exit to Python, when a thread that Python
    would wait for is still running, or when ``code`` is not an exit status (a message Python
    prints). ``SHIPGNC_QUICK_EXIT=0`` turns it off."""
    if os.environ.get("SHIPGNC_QUICK_EXIT", "1") == "0":
        return
    if code is None:
        code = 0
    if not isinstance(code, int) or isinstance(code, bool) or not 0 <= code <= 255:
        return
    first = threading.main_thread()
    if any(t is not first and not t.daemon and t.is_alive() for t in threading.enumerate()):
        return
    atexit._run_exitfuncs()
    code = flush_output(code)
    os._exit(code)


def flush_output(code: int) -> int:
    """Flush standard output and error, and the exit code as Python's own exit would make it when
    standard output cannot be written (a full disk, ``> /dev/full``, a reader that left): only a
    command that succeeded (``code`` 0) changes its code. A reader that left (``shipgnc … | head``)
    is 141, as SIGPIPE would end the command (the command line's convention); any other error is
    one line on standard error and exit 1."""
    try:
        sys.stdout.flush()
    except BrokenPipeError:
        code = code or 141
    except OSError as exc:
        if code == 0:
            with contextlib.suppress(OSError, ValueError):
                sys.stderr.write(f"error: could not write standard output: {exc.strerror or exc}\n")
            code = 1
    except (ValueError, AttributeError):  # closed, or replaced by None
        pass
    with contextlib.suppress(OSError, ValueError, AttributeError):
        sys.stderr.flush()
    return code


#: the frames of ``python -m`` running the package: runpy's functions between the interpreter and
#: the module
_RUNPY = {"_run_module_as_main", "_run_code"}


def is_program(caller) -> bool:
    """True when :func:`main`, called from the frame ``caller``, is the program itself: called
    from the top level of the ``__main__`` module (the installed ``shipgnc`` script, or
    ``python -m shipgnc`` through runpy's ``_run_module_as_main``), with no profiler or tracer
    (``cProfile``, ``coverage``, a debugger) watching. Otherwise something runs after it (a script
    that runs the package with :func:`runpy.run_module` and catches ``SystemExit``, a profiler that
    writes its file at exit), and the ordinary exit is kept."""
    if sys.getprofile() is not None or sys.gettrace() is not None:
        return False
    monitoring = getattr(sys, "monitoring", None)  # Python 3.12+: profilers and coverage use it
    if monitoring is not None and any(monitoring.get_tool(i) is not None for i in range(6)):
        return False
    top = sys.modules.get("__main__")
    if caller is None or caller.f_code.co_name != "<module>" or top is None \
            or caller.f_globals is not vars(top):
        return False
    frame = caller.f_back
    while frame is not None:  # only runpy's own frames of ``python -m`` above it
        if frame.f_code.co_name not in _RUNPY or frame.f_globals.get("__name__") != "runpy":
            return False
        frame = frame.f_back
    return True


if __name__ == "__main__":
    main()
