"""``shipgnc``'s entry point ends a finished command without the interpreter's teardown
(:func:`shipgnc.__main__.exit_finished`): the exit handlers still run, the standard streams are
flushed, the exit code is the command's, and a thread Python would wait for is waited for."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

SRC = str(Path(__file__).resolve().parents[1] / "src")

#: a command run through the entry point, with an exit handler and an object whose finaliser
#: runs only when the interpreter tears its modules down
PROBE = textwrap.dedent("""
    import atexit, sys, threading, time
    OUT = sys.argv.pop(1)

    class Teardown:
        def __del__(self):
            sys.stderr.write("torn down\\n")

    keep = Teardown()
    atexit.register(lambda: open(OUT, "a").write("handler ran\\n"))
    if sys.argv[1] == "--thread":
        sys.argv.pop(1)
        def late():
            time.sleep(0.3)
            open(OUT, "a").write("thread done\\n")
        threading.Thread(target=late).start()
    sys.argv[0] = "shipgnc"
    from shipgnc.__main__ import main
    main()
""")


def _run(tmp_path, *args, quick="1"):
    out = tmp_path / "marks.txt"
    env = {**os.environ, "PYTHONPATH": SRC + os.pathsep + os.environ.get("PYTHONPATH", ""),
           "SHIPGNC_QUICK_EXIT": quick}
    done = subprocess.run([sys.executable, "-c", PROBE, str(out), *args], capture_output=True,
                          text=True, env=env, timeout=120)
    return done, (out.read_text() if out.exists() else "")


def test_a_finished_command_skips_the_teardown_and_keeps_its_output_and_handlers(tmp_path):
    done, marks = _run(tmp_path, "list")
    assert done.returncode == 0, done.stderr
    assert "cybership-waves" in done.stdout and done.stdout.endswith("\n")  # flushed whole
    assert marks == "handler ran\n"
    assert "torn down" not in done.stderr  # the interpreter's teardown did not run


def test_the_ordinary_exit_when_turned_off(tmp_path):
    done, marks = _run(tmp_path, "list", quick="0")
    assert done.returncode == 0 and marks == "handler ran\n"
    assert "torn down" in done.stderr


def test_a_usage_error_keeps_its_exit_code(tmp_path):
    done, marks = _run(tmp_path, "run", "--no-such-flag")
    assert done.returncode == 2
    assert "error" in done.stderr and "torn down" not in done.stderr
    assert marks == "handler ran\n"


def test_a_running_thread_is_waited_for(tmp_path):
    done, marks = _run(tmp_path, "--thread", "list")
    assert done.returncode == 0, done.stderr
    assert marks.splitlines() == ["thread done", "handler ran"]  # as Python orders them
