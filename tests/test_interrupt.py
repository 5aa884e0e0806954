"""Ctrl-C during a run or a sweep: one line, exit 130, no traceback; ``--keep-partial`` writes the
samples computed so far, marked ``interrupted``."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from shipgnc import HeadingSpeedAutopilot, ReferenceSchedule, VectoredThrustBoat, simulate
from shipgnc.errors import Interrupted

BOAT = VectoredThrustBoat()


def components():
    return {"controller": HeadingSpeedAutopilot(BOAT.params),
            "guidance": ReferenceSchedule([0, 10], np.radians([0, 45]), [1.5, 1.5])}


def test_numpy_loop_keeps_the_samples_before_the_interrupt():
    def observer(t, x, command, applied):
        if t >= 2.0:
            raise KeyboardInterrupt

    full = simulate(BOAT, np.zeros(6), t_end=5.0, dt=0.05, backend="numpy", **components())
    with pytest.raises(Interrupted, match=r"interrupted at t = 2 s") as info:
        simulate(BOAT, np.zeros(6), t_end=5.0, dt=0.05, observer=observer, **components())
    partial = info.value.partial
    assert partial.attrs["interrupted"] == 1 and info.value.time == pytest.approx(2.0)
    n = partial.sizes["time"]
    np.testing.assert_array_equal(partial.psi.values, full.psi.values[:n])


def test_compiled_loop_keeps_the_chunks_completed():
    calls = []

    def progress(k, n):
        calls.append(k)
        if len(calls) == 6:
            raise KeyboardInterrupt

    x0 = np.zeros((3, 6))
    full = simulate(BOAT, x0, t_end=30.0, dt=0.05, backend="compiled", **components())
    with pytest.raises(Interrupted) as info:
        simulate(BOAT, x0, t_end=30.0, dt=0.05, backend="compiled", progress=progress,
                 **components())
    partial = info.value.partial
    n = partial.sizes["time"]
    assert 0 < n < full.sizes["time"] and partial.attrs["backend"] == "compiled"
    assert info.value.time == pytest.approx(float(partial.time[-1]))
    for name in full.data_vars:
        np.testing.assert_array_equal(partial[name].values, full[name].values[:n], err_msg=name)


def ctrl_c(args, wait_s: float, tmp_path):
    """Start ``shipgnc ARGS`` in its own process group, send SIGINT to the group after
    ``wait_s`` seconds (as a terminal's Ctrl-C does), return (exit code, stderr)."""
    command = [sys.executable, "-m", "shipgnc.cli", *args]
    env = {**os.environ, "MPLBACKEND": "Agg"}
    proc = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=tmp_path,
                            env=env, start_new_session=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    time.sleep(wait_s)
    assert proc.poll() is None, "the run ended before the interrupt: make it longer"
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    return proc.returncode, err.decode()


#: a run on the Python loop, measured here (CPU s of the command): starting 0–1, simulating 1–9
#: (3000 s at ~390 simulated s per CPU second), writing to ~10
LONG_RUN = ["run", "boat-stern-kick", "--set", "simulation.t_end=3000", "--set",
            "simulation.backend=numpy", "--no-figures"]


def _while_simulating(code: int, err: str) -> int:
    """Where a Ctrl-C landed: -1 before the simulation, 0 in it, 1 after the run ended."""
    if code == 0:
        return 1
    assert code == 130 and "Traceback" not in err, err[-1500:]
    if any(late in err for late in ("after the run finished", "while scoring", "while writing")):
        return 1  # the run had ended: its line names what the Ctrl-C cut short after it
    return 0 if "interrupted at t = " in err and "interrupted at t = 0 s" not in err else -1


def _ctrl_c_while_simulating(args, tmp_path):
    """Ctrl-C at 3 s of the command's CPU (its moment whatever the machine's load), moved earlier
    or later until it lands while simulating (a machine three times as fast ends the run after
    ~3.3 s; one twice as slow starts simulating at ~2 s)."""
    from test_faults import _ctrl_c_in_phase

    code, err, _, _ = _ctrl_c_in_phase(args, 3.0, tmp_path, _while_simulating, out="out")
    assert _while_simulating(code, err) == 0, err[-1500:]
    return code, err


def test_cli_run_interrupted_is_one_line_and_exit_130(tmp_path):
    code, err = _ctrl_c_while_simulating([*LONG_RUN, "--out", "out"], tmp_path)
    assert code == 130
    assert err.strip().startswith("interrupted at t = ") and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out" / "result.nc").exists()


def test_cli_run_keep_partial_writes_what_was_computed(tmp_path):
    code, err = _ctrl_c_while_simulating([*LONG_RUN, "--out", "out", "--keep-partial"], tmp_path)
    assert code == 130 and "interrupted at t = " in err and "Traceback" not in err
    metrics = json.loads((tmp_path / "out" / "metrics.json").read_text())
    assert metrics["interrupted"] is True
    import xarray as xr

    with xr.open_dataset(tmp_path / "out" / "result.nc", engine="h5netcdf") as ds:
        assert ds.attrs["interrupted"] == 1 and 0 < float(ds.time[-1]) < 3000


def test_cli_sweep_on_a_local_cluster_interrupted_without_worker_tracebacks(tmp_path):
    # 40 000 boats for 700 s: ~90 s of the workers' CPU here (~15 s on two cores three times as
    # fast), so the sweep still runs at 8 s; each chunk is scored in the loop (no log kept)
    code, err = ctrl_c(["sweep", "boat-autopilot", "--mc", "40000", "--chunk-size", "500",
                        "--set", "simulation.t_end=700", "--workers", "dask", "--no-figures",
                        "--out", "sw"], 8.0, tmp_path)
    assert code == 130
    assert err.strip().startswith("interrupted after ") and "Traceback" not in err
