"""Deterministic derived results kept on disk, keyed by everything they are computed from.

Some numbers a run needs are computed from fixed inputs by code that costs far more than the
numbers (a root found with scipy's ``brentq`` costs the import of ``scipy.optimize``; a Nomoto
model identified from a simulated zig-zag, a simulation and a least-squares fit). :func:`stored`
computes such a result once and keeps it as JSON beside the generated loops
(``<cache>/derived``, in :func:`shipgnc.jit_cache.cache_root`); a later process reads it back.

* **Bit-identical.** Values are finite or non-finite floats, ints, strings, bools and lists or
  dicts of them; a float is written as Python's shortest repr, which reads back to the same
  double, so a stored result is exactly the computed one.
* **Keyed by its inputs and its code.** The file's name is a SHA-256 of the result's kind, its
  inputs (floats by repr), the package's source files the computing modules import, transitively
  (:func:`shipgnc.jit_cache.source_files`, as a generated loop is keyed), the versions of
  Python, numpy, scipy and numba, whether numba compiles (``NUMBA_DISABLE_JIT``) and the CPU it
  compiles for: a changed input, an edited module on the path, an upgraded library or another
  compiler computes it again (compiled and plain-Python kernels round differently in the last
  bit). Inside :func:`shipgnc.derive.plain_python` nothing is read or kept.
* **Never in the way.** A cache that cannot be found or written, a key that cannot be computed
  (no home folder, an unreadable source file), or a file that does not read back as a
  result of the kind, is ignored: the result is computed. ``SHIPGNC_DERIVED_CACHE=0`` turns it off.
* **Bounded.** A study that varies an input (a sweep over gains) writes one small file per value:
  beyond :data:`MAX_FILES` files the least recently used quarter is deleted.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import sys
from collections.abc import Callable
from pathlib import Path

#: bump when the stored form changes
FORMAT = 1
#: files kept in the folder; when a write passes it, the least recently used quarter goes
MAX_FILES = 2048


def stored(kind: str, inputs: dict, modules: tuple[str, ...], compute: Callable[[], dict], *,
           shape: dict) -> dict:
    """``compute()`` (a dict of JSON values), or the same dict kept from an earlier call with the
    same ``kind``, ``inputs`` and code (``modules``: the package's modules the computation runs;
    the files they import within the package count too). ``shape``: the result's form, a dict of
    its keys to ``float``, ``int``, ``str``, ``bool``, a list of those (``[float] * 2``: that
    length) or a dict of the same kind; a kept file whose inputs or result differ from it (a
    damaged or foreign file) is computed again and replaced."""
    if os.environ.get("SHIPGNC_DERIVED_CACHE", "1") == "0" or _plain_python():
        return compute()
    try:
        path = cache_path(kind, inputs, modules)
        expected = json.loads(json.dumps(_plain(inputs), sort_keys=True))
    except Exception:  # no home folder, a source file unreadable: computed, not kept
        return compute()
    try:
        with open(path, encoding="utf-8") as f:
            kept = json.load(f)
        if isinstance(kept, dict) and kept.get("kind") == kind and kept.get("inputs") == expected \
                and _fits(kept.get("result"), shape):
            with contextlib.suppress(OSError):
                os.utime(path)  # used: the last to be pruned
            return kept["result"]
    except (OSError, ValueError, RecursionError):
        pass
    text = json.dumps({"kind": kind, "inputs": _plain(inputs), "result": compute()}, sort_keys=True)
    _write(path, text)
    return json.loads(text)["result"]  # as a later process reads it: the same values and types


def _fits(value, shape) -> bool:
    """True when ``value`` (read from JSON) has the form ``shape`` (:func:`stored`): the same keys,
    list lengths and types (a float is a float, not an int or a string; a bool is not an int)."""
    if isinstance(shape, dict):
        return isinstance(value, dict) and value.keys() == shape.keys() and all(
            _fits(value[k], s) for k, s in shape.items())
    if isinstance(shape, list):
        return isinstance(value, list) and len(value) == len(shape) and all(
            _fits(v, s) for v, s in zip(value, shape, strict=True))
    return type(value) is shape


def cache_path(kind: str, inputs: dict, modules: tuple[str, ...]) -> Path:
    """The file of a result: ``<cache>/derived/<kind>-<16 hex digits of its key>.json``."""
    from shipgnc.jit_cache import cache_root

    digest = hashlib.sha256(f"{FORMAT} {kind}\n".encode())
    digest.update(json.dumps(_plain(inputs), sort_keys=True).encode())
    digest.update(_code(tuple(modules)))
    digest.update(_compiler().encode())
    return cache_root() / "derived" / f"{kind}-{digest.hexdigest()[:16]}.json"


def _code(modules: tuple[str, ...]) -> bytes:
    """SHA-256 of the package files ``modules`` import (transitively; each read again when it
    changes: a module edited and reloaded) and of the library versions."""
    from shipgnc.jit_cache import hash_files, source_files

    digest = hashlib.sha256()
    hash_files(digest, sorted(source_files("", modules)))
    digest.update(_versions().encode())
    return digest.digest()


def _plain_python() -> bool:
    """Inside :func:`shipgnc.derive.plain_python` the kernels' plain-Python forms run, whose
    rounding may differ from the compiled ones: a result is computed there, not read."""
    from shipgnc.derive import in_plain_python

    return in_plain_python()


def _compiler() -> str:
    """What the compiled kernels' rounding depends on: numba's version, whether it compiles at all
    (``NUMBA_DISABLE_JIT``) and the CPU name and features it compiles for (fused multiply-adds,
    vector widths). A surge root or a zig-zag run through a compiled batch differs from the
    plain-Python one in the last bit."""
    import llvmlite.binding as ll
    import numba

    name = numba.config.CPU_NAME or ll.get_host_cpu_name()
    features = numba.config.CPU_FEATURES or ll.get_host_cpu_features().flatten()
    return f"numba {numba.__version__}; jit {not numba.config.DISABLE_JIT}; cpu {name} {features}"


def _versions() -> str:
    from importlib.metadata import PackageNotFoundError, version

    found = []
    for name in ("numpy", "scipy"):
        try:
            found.append(f"{name} {version(name)}")
        except PackageNotFoundError:
            found.append(f"{name} -")
    return f"python {sys.version}; " + "; ".join(found)


def _plain(value):
    """``value`` as JSON-ready data: floats (numpy's too) by repr, so -0.0, inf and nan keep."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, (bool, str, int)) or value is None:
        return value
    if hasattr(value, "tolist"):  # numpy scalars and arrays
        return _plain(value.tolist())
    number = float(value)
    return number if math.isfinite(number) else repr(number)


def _write(path: Path, text: str) -> None:
    from shipgnc.jit_cache import write_atomic

    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(path, text + "\n")
        _prune(path.parent)
    except OSError:  # a read-only cache: computed each time
        pass


def _prune(folder: Path) -> None:
    """Beyond :data:`MAX_FILES` results, delete the least recently used quarter."""
    files = list(folder.glob("*.json"))
    if len(files) <= MAX_FILES:
        return
    used = []
    for f in files:
        with contextlib.suppress(OSError):  # another process pruned it first
            used.append((f.stat().st_mtime, f))
    for _, f in sorted(used)[: len(used) - 3 * MAX_FILES // 4]:
        with contextlib.suppress(OSError):
            f.unlink()
