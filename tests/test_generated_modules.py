"""The code shipgnc generates (composed loops, derived batches) is written where a user can read
it, and is keyed by the sources it is compiled from (shipgnc.jit_cache)."""

from __future__ import annotations

import shutil

import numpy as np

from shipgnc import jit_cache
from shipgnc.control.open_loop import OpenLoopSchedule
from shipgnc.derive import per_ship
from shipgnc.kernels import Kernel, kernel_function
from shipgnc.models.fossen3dof import VectoredThrustBoat
from shipgnc.sim import compose
from shipgnc.sim.simulator import _validate

BOAT = VectoredThrustBoat()


def setup_of(model=BOAT, **kw):
    base = dict(t_end=1.0, dt=0.05, controller=None, actuator=None, guidance=None,
                disturbance=None, u0=None, integrator="rk4", method="RK45", rtol=1e-3, atol=1e-6,
                seed=None, on_divergence="raise", observer=None, progress=None, log_every=1)
    return _validate(model, np.zeros((2, 6)), **{**base, **kw})


def test_a_composed_loop_leaves_the_source_that_runs_beside_its_cache_entry(tmp_path, monkeypatch):
    """Building the loop writes its module (compiling waits for the first call): the
    combination's constants, its kernels by name, the small functions of the step."""
    monkeypatch.setenv("SHIPGNC_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(compose, "_LOOPS", {})
    comp = compose.Composition(setup_of(controller=OpenLoopSchedule([0], [[50, 0.1]])))
    path = comp.source_path
    assert path is not None and path.parent == tmp_path / "loops"
    assert path.name.startswith("shipgnc_loop_")
    text = path.read_text()
    for line in ("has_ctrl = True", "has_dist = False", "has_nav = False", "def run_ship(",
                 "def log_sample(", "from shipgnc.models.fossen3dof import"):
        assert line in text
    assert "pn[" not in text.split("def loop(")[1]  # no hand-written parameter offsets


def _drift_rhs(x, u, d, p, xdot):
    for j in range(6):
        xdot[j] = 0.0
    xdot[0] = p[0]


#: compiled under another name than its function's: not found again by module and name (as a
#: kernel typed into a notebook)
_DRIFT = kernel_function(_drift_rhs)


class _DriftingBoat(VectoredThrustBoat):
    def kernel(self):
        return Kernel(_DRIFT, np.array([1.0]))


def test_a_loop_compiled_in_memory_leaves_its_source_too(tmp_path, monkeypatch):
    monkeypatch.setenv("SHIPGNC_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(compose, "_LOOPS", {})
    comp = compose.Composition(setup_of(model=_DriftingBoat()))
    path = comp.source_path
    assert path is not None and path.name.startswith("shipgnc_memory_")
    text = path.read_text()
    assert "# model_fn = " in text and "_drift_rhs" in text and "def run_ship(" in text
    assert "CACHE = False" in text


def test_a_batch_compiled_in_memory_leaves_its_source(tmp_path, monkeypatch):
    monkeypatch.setenv("SHIPGNC_CACHE_DIR", str(tmp_path))

    def double(x, out):
        out[0] = 2.0 * x[0]

    batch = per_ship(kernel_function(double), "i o")
    np.testing.assert_array_equal(batch(np.array([[1.0], [3.0]]), 1), [[2.0], [6.0]])
    assert batch.source_path is not None and batch.source_path.name.startswith("shipgnc_memory_")
    assert "def serial(" in batch.source_path.read_text()


def test_the_key_follows_the_kernels_sources_not_the_whole_package(tmp_path, monkeypatch):
    """A generated module's key hashes the package files it imports, transitively: editing an
    unrelated module keeps it; editing a helper module of a kernel's module changes it. (On a
    copy of the package.)"""
    copy = tmp_path / "shipgnc"
    shutil.copytree(jit_cache.PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(jit_cache, "PACKAGE", copy)
    monkeypatch.setattr(jit_cache, "_FILE_IMPORTS", {})
    source = "from shipgnc.models.fossen3dof import boat_rhs as kernel\n"
    files = {p.relative_to(copy).as_posix() for p in jit_cache.source_files(source)}
    assert {"models/fossen3dof.py", "models/base.py", "kernels.py"} <= files
    assert "cli.py" not in files and "routing/graph.py" not in files
    key = jit_cache.module_key(source, ())

    def edited(relative):
        monkeypatch.setattr(jit_cache, "_FILE_IMPORTS", {})
        with open(copy / relative, "a") as f:
            f.write("\n# an edit\n")
        return jit_cache.module_key(source, ())

    assert edited("cli.py") == key
    assert edited("routing/graph.py") == key
    helper = next(f for f in ("kernels.py", "frames.py") if f in files)
    assert edited(helper) != key
