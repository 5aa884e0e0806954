"""The ``shipgnc`` command (also ``python -m shipgnc``).

A light entry point: Ctrl-C while the command-line modules are still importing (about a second
on a cold start) is answered like Ctrl-C later — one line, exit 130 — instead of a traceback.
"""

from __future__ import annotations

import atexit
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
        cli_main()
    except SystemExit as done:  # finished: end without tearing the interpreter down
        exit_finished(done.code)
        raise


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
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass
    os._exit(code)


if __name__ == "__main__":
    main()
