"""The ``shipgnc`` command (also ``python -m shipgnc``).

A light entry point: Ctrl-C while the command-line modules are still importing (about a second
on a cold start) is answered like Ctrl-C later — one line, exit 130 — instead of a traceback.
"""

from __future__ import annotations

import sys

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
    cli_main()


if __name__ == "__main__":
    main()
