"""Derived results kept on disk (:mod:`shipgnc.derived_cache`) and the three results kept with it:
CyberShip II's surge equilibrium, its identified Nomoto model and the sliding-mode pole placement.
A kept result is the computed one to the bit, and a changed input or code computes it again."""

from __future__ import annotations

import math
import os
import struct
import threading

import numpy as np
import pytest

from shipgnc import derived_cache, jit_cache
from shipgnc.derived_cache import cache_path, stored


@pytest.fixture(autouse=True)
def _own_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("SHIPGNC_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.delenv("SHIPGNC_DERIVED_CACHE", raising=False)
    monkeypatch.setattr(jit_cache, "_SWEPT", set())  # each test a fresh process's first write


def _bits(values):
    return [struct.pack("<d", v) for v in values]


class Counted:
    def __init__(self, result):
        self.result, self.calls = result, 0

    def __call__(self):
        self.calls += 1
        return self.result


X = {"x": float}  # the form of most results below
HARD = [0.1 + 0.2, -0.0, 1e-310, 2.0**-1074, 1.7976931348623157e308, math.pi, -1.0 / 3.0]


def test_a_kept_result_is_the_computed_one_to_the_bit():
    compute = Counted({"x": HARD, "nan": float("nan"), "inf": -math.inf, "label": "a", "n": 3})
    shape = {"x": [float] * len(HARD), "nan": float, "inf": float, "label": str, "n": int}
    first = stored("probe", {"a": 1.5}, ("shipgnc.errors",), compute, shape=shape)
    again = stored("probe", {"a": 1.5}, ("shipgnc.errors",), compute, shape=shape)
    assert compute.calls == 1
    for got in (first, again):
        assert _bits(got["x"]) == _bits(HARD)
        assert math.isnan(got["nan"]) and got["inf"] == -math.inf
        assert got["label"] == "a" and got["n"] == 3


def test_a_changed_input_computes_again():
    compute = Counted({"x": 1.0})
    stored("probe", {"a": 0.1, "v": np.array([1.0, 2.0])}, ("shipgnc.errors",), compute, shape=X)
    stored("probe", {"a": 0.1, "v": np.array([1.0, 2.0])}, ("shipgnc.errors",), compute, shape=X)
    assert compute.calls == 1
    stored("probe", {"a": np.nextafter(0.1, 1.0), "v": np.array([1.0, 2.0])}, ("shipgnc.errors",),
           compute, shape=X)  # one ulp
    stored("probe", {"a": 0.1, "v": np.array([1.0, -2.0])}, ("shipgnc.errors",), compute, shape=X)
    stored("other", {"a": 0.1, "v": np.array([1.0, 2.0])}, ("shipgnc.errors",), compute, shape=X)
    assert compute.calls == 4


def test_edited_code_computes_again_in_the_same_process(tmp_path, monkeypatch):
    # a module edited and reloaded in a running session (a notebook) is its new code
    code = tmp_path / "kernel.py"
    code.write_text("def f(): return 1\n")
    monkeypatch.setattr(jit_cache, "source_files", lambda source, modules=(): {code})
    compute = Counted({"x": 1.0})
    stored("probe", {}, ("whatever",), compute, shape=X)
    stored("probe", {}, ("whatever",), compute, shape=X)
    assert compute.calls == 1
    code.write_text("def f(): return 2\n")
    os.utime(code, ns=(1, 1))  # the same size: known changed by its modification time
    stored("probe", {}, ("whatever",), compute, shape=X)
    assert compute.calls == 2


def test_the_key_covers_the_imported_modules_transitively(monkeypatch):
    seen = []
    real = jit_cache.source_files
    monkeypatch.setattr(jit_cache, "source_files", lambda s, m=(): seen.append(m) or real(s, m))
    cache_path("probe", {}, ("shipgnc.models.cybership2",))
    files = {p.name for p in real("", ("shipgnc.models.cybership2",))}
    assert {"cybership2.py", "actuators.py", "kernels.py"} <= files  # what it imports counts too


def test_a_damaged_file_is_computed_again_and_replaced():
    compute = Counted({"x": 2.5})
    path = cache_path("probe", {"a": 1}, ("shipgnc.errors",))
    path.parent.mkdir(parents=True)
    path.write_text("{not json")
    assert stored("probe", {"a": 1}, ("shipgnc.errors",), compute, shape=X) == {"x": 2.5}
    assert stored("probe", {"a": 1}, ("shipgnc.errors",), compute, shape=X) == {"x": 2.5}
    assert compute.calls == 1


def test_an_unwritable_cache_and_the_switch_compute_each_time(tmp_path, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setenv("SHIPGNC_CACHE_DIR", str(blocker))  # a file: no folder can be made in it
    compute = Counted({"x": 1.0})
    assert stored("probe", {}, ("shipgnc.errors",), compute, shape=X) == {"x": 1.0}
    assert stored("probe", {}, ("shipgnc.errors",), compute, shape=X) == {"x": 1.0}
    assert compute.calls == 2
    monkeypatch.setenv("SHIPGNC_CACHE_DIR", str(tmp_path / "ok"))
    monkeypatch.setenv("SHIPGNC_DERIVED_CACHE", "0")
    stored("probe", {}, ("shipgnc.errors",), compute, shape=X)
    stored("probe", {}, ("shipgnc.errors",), compute, shape=X)
    assert compute.calls == 4 and not (tmp_path / "ok").exists()


def test_the_folder_is_bounded_and_keeps_what_was_used_last(monkeypatch):
    monkeypatch.setattr(derived_cache, "MAX_FILES", 8)
    for i in range(8):
        stored("probe", {"i": i}, ("shipgnc.errors",), lambda i=i: {"x": float(i)}, shape=X)
        os.utime(cache_path("probe", {"i": i}, ("shipgnc.errors",)), (1e9 + i, 1e9 + i))
    stored("probe", {"i": 0}, ("shipgnc.errors",), lambda: {"x": -1.0}, shape=X)  # read: used now
    stored("probe", {"i": 8}, ("shipgnc.errors",), lambda: {"x": 8}, shape=X)  # the ninth file
    left = {p.name for p in cache_path("probe", {}, ()).parent.glob("*.json")}
    assert len(left) == 6
    kept = {i for i in range(9) if cache_path("probe", {"i": i}, ("shipgnc.errors",)).name in left}
    assert kept == {0, 4, 5, 6, 7, 8}  # the three least recently used went


# --- the results kept ---------------------------------------------------------------------------

def _cardano_surge(p, n: float) -> float:
    """The positive root of −X_uuu u³ − X_|u|u u² + (2T_nu n − X_u) u − 2T_nn n² = 0 (the surge
    balance 2T(n, u) = d₁₁(u)u of CyberShip II at δ = 0, T > 0) by Cardano's formula."""
    a, b, c, d = -p.X_uuu, -p.X_absu_u, 2.0 * p.T_nu * n - p.X_u, -2.0 * p.T_nn * n * n
    pp = (3 * a * c - b * b) / (3 * a * a)
    qq = (2 * b**3 - 9 * a * b * c + 27 * a * a * d) / (27 * a**3)
    disc = (qq / 2) ** 2 + (pp / 3) ** 3
    assert disc > 0  # one real root (Descartes: exactly one positive one)
    t = np.cbrt(-qq / 2 + math.sqrt(disc)) + np.cbrt(-qq / 2 - math.sqrt(disc))
    return float(t - b / (3 * a))


@pytest.mark.parametrize("n", [8.13, 4.0, 12.5])
def test_the_surge_equilibrium_kept_is_brentqs_and_the_cubics_root(n):
    from shipgnc.models.cybership2 import CyberShip2Params, _surge_root, surge_equilibrium

    p = CyberShip2Params()
    computed = _surge_root(p, n)
    assert _bits([surge_equilibrium(p, n), surge_equilibrium(p, n)]) == _bits([computed] * 2)
    assert computed == pytest.approx(_cardano_surge(p, n), rel=1e-13)
    assert surge_equilibrium(p, 0.0) == 0.0
    changed = p.with_(X_uuu=2.0 * p.X_uuu)  # another hull: its own root, not the kept one
    assert surge_equilibrium(changed, n) == _surge_root(changed, n) != computed


def test_the_identified_model_kept_is_the_computed_one():
    from shipgnc.analysis import identification as idn
    from shipgnc.models.cybership2 import CRUISE_RPS, CyberShip2Params

    p = CyberShip2Params()
    computed = idn._identify(p, 20.0, 20.0, CRUISE_RPS, 120.0, 0.1)
    idn._identify_cached.cache_clear()
    first = idn.identify_cybership2(p)
    idn._identify_cached.cache_clear()  # a new process: read from disk
    kept = idn.identify_cybership2(p)
    for fit in (first, kept):
        assert _bits([fit.K, fit.T, fit.residual_rms, fit.r_rms, fit.fit, fit.cost]) == _bits(
            [computed["fit"][k] for k in ("K", "T", "residual_rms", "r_rms", "fit", "cost")])
        assert fit.extra == computed["extra"]
        assert fit.label == "CyberShip II zig-zag 20/20, 120 s"
    idn._identify_cached.cache_clear()


@pytest.mark.parametrize("a22, b2, lam1, lam2", [(-0.115, -0.0303, -0.0005, -1.0),
                                                 (0.1057, -0.0040, -0.0005, -7.8128)])
def test_the_pole_placement_kept_is_scipys_and_the_closed_form(a22, b2, lam1, lam2):
    from scipy.signal import place_poles

    from shipgnc.control.course import design_smc

    A = np.array([[0.0, 1.0], [0.0, a22]])
    B = np.array([[0.0], [b2]])
    direct = place_poles(A, B, np.array([lam1, lam2]), method="YT").gain_matrix.ravel()
    first, kept = design_smc(a22, b2, lam1, lam2), design_smc(a22, b2, lam1, lam2)
    assert _bits(first.K) == _bits(kept.K) == _bits(direct)
    # A − BK = [[0, 1], [−b₂k₁, a₂₂ − b₂k₂]]: s² − (λ₁ + λ₂)s + λ₁λ₂ gives k₁ = λ₁λ₂/b₂,
    # k₂ = (a₂₂ − λ₁ − λ₂)/b₂
    assert kept.K == pytest.approx([lam1 * lam2 / b2, (a22 - lam1 - lam2) / b2], rel=1e-12)
    assert len(list(derived_cache.cache_path("x", {}, ()).parent.glob("place-poles-yt-*.json"))) >= 1


def test_plain_python_computes_and_the_compiler_is_in_the_key(monkeypatch):
    # compiled and plain-Python kernels differ in the last bit: neither is to stand for the other
    import numba

    from shipgnc.derive import plain_python

    stored("probe", {}, ("shipgnc.errors",), lambda: {"x": 1.0}, shape=X)
    with plain_python():
        assert stored("probe", {}, ("shipgnc.errors",), lambda: {"x": 2.0}, shape=X) == {"x": 2.0}
    assert stored("probe", {}, ("shipgnc.errors",), lambda: {"x": 3.0}, shape=X) == {"x": 1.0}
    compiled = cache_path("probe", {}, ("shipgnc.errors",))
    monkeypatch.setattr(numba.config, "DISABLE_JIT", not numba.config.DISABLE_JIT)
    assert cache_path("probe", {}, ("shipgnc.errors",)) != compiled
    monkeypatch.setattr(numba.config, "DISABLE_JIT", not numba.config.DISABLE_JIT)  # back
    monkeypatch.setattr(numba.config, "CPU_NAME", "generic")
    assert cache_path("probe", {}, ("shipgnc.errors",)) != compiled


@pytest.mark.parametrize("result", [{}, {"u": None}, {"u": "0.3"}, {"u": 1}, {"u": [0.3]},
                                    {"u": 0.3, "v": 0.1}, None, []])
def test_a_valid_json_file_of_another_form_is_computed_again_and_replaced(result):
    import json

    from shipgnc.models.cybership2 import CyberShip2Params, _surge_root, surge_equilibrium

    p = CyberShip2Params()
    surge_equilibrium(p, 8.13)  # written
    [path] = cache_path("x", {}, ()).parent.glob("surge-equilibrium-*.json")
    kept = json.loads(path.read_text())
    path.write_text(json.dumps({**kept, "result": result}))
    assert surge_equilibrium(p, 8.13) == _surge_root(p, 8.13)
    assert json.loads(path.read_text()) == kept  # replaced by the computed one


def test_a_file_whose_inputs_differ_is_not_taken():
    import json

    path = cache_path("probe", {"a": 1.0}, ("shipgnc.errors",))
    path.parent.mkdir(parents=True)
    path.write_text(json.dumps({"kind": "probe", "inputs": {"a": 2.0}, "result": {"x": 7.0}}))
    assert stored("probe", {"a": 1.0}, ("shipgnc.errors",), lambda: {"x": 1.0}, shape=X) == {"x": 1.0}


def test_a_key_that_cannot_be_computed_computes_the_result(monkeypatch):
    from pathlib import Path

    def no_home():
        raise RuntimeError("Could not determine home directory.")

    monkeypatch.delenv("SHIPGNC_CACHE_DIR")
    monkeypatch.delenv("XDG_CACHE_HOME", raising=False)
    monkeypatch.setattr(Path, "home", staticmethod(no_home))
    assert stored("probe", {}, ("shipgnc.errors",), lambda: {"x": 1.0}, shape=X) == {"x": 1.0}


def test_an_unreadable_source_computes_the_result(monkeypatch):
    def unreadable(source, modules=()):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(jit_cache, "source_files", unreadable)
    assert stored("probe", {}, ("shipgnc.errors",), lambda: {"x": 2.0}, shape=X) == {"x": 2.0}


def test_writers_do_not_clash_and_a_killed_writers_file_is_deleted():
    folder = cache_path("probe", {}, ()).parent
    folder.mkdir(parents=True)
    old, fresh = folder / "probe-0.json.1.tmp", folder / "probe-1.json.2.tmp"
    for f in (old, fresh):
        f.write_text("{")
    os.utime(old, (0.0, 0.0))  # a writer killed long ago; the fresh one may still be writing

    def write(i):
        stored("probe", {"i": i % 2}, ("shipgnc.errors",), lambda: {"x": float(i % 2)}, shape=X)

    threads = [threading.Thread(target=write, args=(i,)) for i in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert sorted(p.name for p in folder.glob("*.tmp")) == [fresh.name]
    for i in (0, 1):
        assert stored("probe", {"i": i}, ("shipgnc.errors",), lambda: {"x": -1.0}, shape=X) == {
            "x": float(i)}
