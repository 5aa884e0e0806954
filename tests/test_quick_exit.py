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


def _plain_env(quick="1"):
    """The environment of a command whose standard output is block-buffered, as a user's is
    (``PYTHONUNBUFFERED`` would write each line at once, and no error would wait for the exit)."""
    env = {**os.environ, "PYTHONPATH": SRC + os.pathsep + os.environ.get("PYTHONPATH", ""),
           "SHIPGNC_QUICK_EXIT": quick}
    env.pop("PYTHONUNBUFFERED", None)
    return env


def test_standard_output_that_cannot_be_written_is_an_error_not_success():
    # /dev/full: every write fails with ENOSPC (Linux); Python's own exit ends 120, quick exit 1
    with open("/dev/full", "w") as full:
        done = subprocess.run([sys.executable, "-m", "shipgnc", "show", "cybership-waves"],
                              stdout=full, stderr=subprocess.PIPE, text=True, env=_plain_env(),
                              timeout=120)
    assert done.returncode == 1
    assert done.stderr.strip().splitlines() == [
        "error: could not write standard output: No space left on device"]


def test_a_reader_that_left_is_exit_141_without_a_message():
    read, write = os.pipe()
    os.close(read)  # the reader left before the command wrote: each write is EPIPE
    try:
        # ``show`` prints with ``print``: the text waits in the buffer for the exit's flush
        done = subprocess.run([sys.executable, "-m", "shipgnc", "show", "cybership-waves"],
                              stdout=write,
                              stderr=subprocess.PIPE, text=True, env=_plain_env(), timeout=120)
    finally:
        os.close(write)
    assert done.returncode == 141 and done.stderr == ""


def test_a_script_that_runs_the_package_goes_on_after_it(tmp_path):
    script = tmp_path / "wrapper.py"
    script.write_text(textwrap.dedent("""
        import runpy, sys
        sys.argv = ["shipgnc", "vessels"]
        try:
            runpy.run_module("shipgnc", run_name="__main__")
        except SystemExit as done:
            print("after", done.code)
    """))
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                          env=_plain_env(), timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines()[-1] == "after 0"


def test_a_profiled_command_writes_its_profile(tmp_path):
    profile = tmp_path / "p.out"
    done = subprocess.run([sys.executable, "-m", "cProfile", "-o", str(profile), "-m", "shipgnc",
                           "vessels"], capture_output=True, text=True, env=_plain_env(),
                          cwd=tmp_path, timeout=120)
    assert done.returncode == 0, done.stderr
    import pstats

    assert pstats.Stats(str(profile)).total_calls > 0
