"""The batch over ships derived from a component's scalar kernel: each component's per-ship
arithmetic is written once.

A component's kernel (:mod:`shipgnc.kernels`) is the one source of its arithmetic for one ship. The
composed loop calls it inside its compiled loop over ships and time; everything else — the numpy
loop (:func:`shipgnc.sim.simulator.run_numpy`), linearisation, trim, design and figures — calls the
batch :func:`per_ship` derives from it: a loop over the ships that calls the kernel on each ship's
rows (``numba.prange`` from :data:`PARALLEL_FROM` ships on). There is no second, hand-written
numpy form to keep equal.

``spec`` names the kernel's arguments in order, one letter each (spaces ignored)::

    t   a number, the same for every ship (the time)
    i   an input: the ship's row of an array (..., k) (leading shapes broadcast; read only)
    z   a state the kernel updates in place: an (n, k) float64 C-array the caller owns
    p   parameters: one flat array for every ship, or one row per ship (n, k)
    o   an output the kernel writes: the caller gives its width, the batch returns (..., width)
    -> r   (suffix) the kernel returns a number per ship, returned as a float array (...,)

e.g. a model's right-hand side ``rhs(x, u, d, p, xdot)`` is ``"i i i p o"``, a controller's
``step(t, x, ref, z, p, cmd, sig)`` is ``"t i i z p o o"``, a guidance law's
``reference(t, x, z, p, ref, out) -> finished`` is ``"t i z p o o -> r"``.

The batch is generated as a small module written to the disk cache (:mod:`shipgnc.jit_cache`), so
that it is compiled once per release and read back by later processes, and a user can read exactly
what runs. Inside :func:`plain_python` every batch instead calls the kernel's plain-Python form
(``py_func``) ship by ship: slow, but steppable in a debugger, and the reference a test holds the
compiled batch to.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable

import numpy as np

from shipgnc.jit_cache import import_file, importable, module_file

#: from this many ships on, the batch runs the ships in parallel (numba.prange). A kernel call costs
#: ≈ 0.5 µs per ship; a parallel region costs tens of µs to wake its threads, and milliseconds when
#: the cores are busy (measured: 30 ms per call at 256 ships on a loaded 2-core machine against
#: 0.03 ms serial), so only batches where the work dwarfs that cost go parallel. The composed loop,
#: one parallel region per run, is the fast path for many ships.
PARALLEL_FROM = 50_000
_LETTERS = set("tizpo")
_BATCHES: dict = {}
_PLAIN: list[bool] = []


@contextlib.contextmanager
def plain_python():
    """Within this block every derived batch calls its kernel's plain-Python ``py_func``."""
    _PLAIN.append(True)
    try:
        yield
    finally:
        _PLAIN.pop()


def in_plain_python() -> bool:
    """True inside :func:`plain_python`."""
    return bool(_PLAIN)


def per_ship(function: Callable, spec: str) -> ShipBatch:
    """The batch over ships of the scalar kernel ``function`` (module docstring), memoised."""
    key = (function, spec)
    if key not in _BATCHES:
        _BATCHES[key] = ShipBatch(function, spec)
    return _BATCHES[key]


class ShipBatch:
    """Call with the kernel's arguments in order: numbers for ``t``, arrays for ``i``/``z``/``p``,
    the width (an int) for each ``o``. Returns the outputs (one array, or a tuple in order), then
    the per-ship return value when ``spec`` ends in ``-> r``."""

    def __init__(self, function: Callable, spec: str):
        letters, _, result = spec.replace(" ", "").partition("->")
        if not letters or set(letters) - _LETTERS or result not in ("", "r"):
            raise ValueError(f"spec {spec!r}: letters of {sorted(_LETTERS)}, optional '-> r'")
        self.function = function
        self.letters = letters
        self.returns = result == "r"
        self._compiled = None
        #: the file holding the batch's generated source once compiled (None: not writable)
        self.source_path = None

    # ---------------------------------------------------------------- arguments
    def _rows(self, args) -> tuple[tuple[int, ...], int, list]:
        if len(args) != len(self.letters):
            name = getattr(self.function, "__name__", self.function)
            raise TypeError(f"{name}: {len(self.letters)} arguments ({self.letters}), got {len(args)}")
        arrays = [np.asarray(a, dtype=np.float64) if letter in "iz" else a
                  for letter, a in zip(self.letters, args, strict=True)]
        leads = {a.shape[:-1] if a.ndim else () for letter, a in zip(self.letters, arrays, strict=True)
                 if letter == "i"}  # a state 'z' is (n, k) for the n ships of the inputs' shape
        lead = leads.pop() if len(leads) == 1 else np.broadcast_shapes(*leads) if leads else \
            next((a.shape[:1] for letter, a in zip(self.letters, arrays, strict=True) if letter == "z"), ())
        n = math.prod(lead)
        rows = []
        for letter, a in zip(self.letters, arrays, strict=True):
            if letter == "t":
                rows.append(float(a))
            elif letter == "i":
                width = a.shape[-1] if a.ndim else 1
                if a.shape[:-1] != lead or not a.flags.c_contiguous:
                    a = np.ascontiguousarray(np.broadcast_to(a.reshape(*a.shape[:-1], width),
                                                             (*lead, width)))
                rows.append(a.reshape(n, width))
            elif letter == "z":
                if not (a is args[len(rows)] and a.ndim == 2 and a.shape[0] == n
                        and a.flags.c_contiguous):
                    raise ValueError(f"a 'z' state must be a C-ordered float64 ({n}, k) array, got "
                                     f"{getattr(args[len(rows)], 'shape', type(args[len(rows)]))}")
                rows.append(a)
            elif letter == "p":
                a = a if type(a) is np.ndarray and a.dtype == np.float64 and a.flags.c_contiguous \
                    else np.ascontiguousarray(a, dtype=np.float64)
                rows.append(a.reshape(1, -1) if a.ndim <= 1 else a)
            else:  # "o": the width
                rows.append(np.zeros((n, int(a))))
        return lead, n, rows

    def __call__(self, *args):
        lead, n, rows = self._rows(args)
        result = np.zeros(n)
        if _PLAIN:
            self._plain(rows, result, n)
        else:
            serial, parallel = self._batch()
            (parallel if n >= PARALLEL_FROM else serial)(*rows, result)
        outs = [r.reshape(*lead, r.shape[-1]) for letter, r in zip(self.letters, rows, strict=True)
                if letter == "o"]
        if self.returns:
            outs.append(result.reshape(lead))
        return outs[0] if len(outs) == 1 else tuple(outs)

    def _plain(self, rows, result, n):
        py = getattr(self.function, "py_func", self.function)
        for i in range(n):
            value = py(*(self._row(letter, a, i) for letter, a in zip(self.letters, rows, strict=True)))
            if self.returns:
                result[i] = value

    @staticmethod
    def _row(letter, a, i):
        if letter == "t":
            return a
        if letter == "p":
            return a[i % a.shape[0]]
        return a[i]

    # ---------------------------------------------------------------- generated module
    def _batch(self):
        if self._compiled is None:
            source = self.source()
            path = module_file(source, [self.function], prefix="shipgnc_batch") \
                if importable(self.function) else None
            if path is not None:
                self.source_path = path
                module = import_file(path)
                self._compiled = (module.serial, module.parallel)
            else:  # a kernel typed into a notebook: compiled in memory, once per process, its
                # source written to the cache all the same (to read, never imported)
                body = source.replace("CACHE = True", "CACHE = False").split("# kernel\n")[1]
                path = module_file(source.replace("# kernel\n", "# kernel (bound in memory)\n"),
                                   [self.function], prefix="shipgnc_memory")
                self.source_path = path
                namespace = {"kernel": self.function}
                exec(compile("\n" * source.split("# kernel\n")[0].count("\n") + "\n" + body,
                             str(path) if path else "<shipgnc derived batch>", "exec"), namespace)
                self._compiled = (namespace["serial"], namespace["parallel"])
        return self._compiled

    def source(self) -> str:
        """The generated module: the kernel imported by name, a loop over ships calling it."""
        py = getattr(self.function, "py_func", self.function)
        names = [f"a{k}" for k in range(len(self.letters))]
        first = next((name for letter, name in zip(self.letters, names, strict=True)
                      if letter in "izo"), None)
        count = f"{first}.shape[0]" if first else "1"
        call_args = []
        for letter, name in zip(self.letters, names, strict=True):
            call_args.append({"t": name, "p": f"{name}[i % {name}.shape[0]]"}.get(
                letter, f"{name}[i]"))
        call = f"kernel({', '.join(call_args)})"
        body = f"result[i] = {call}" if self.returns else call
        signature = ", ".join([*names, "result"])
        lines = [
            f"# generated by shipgnc.derive: the batch over ships of {py.__module__}.{py.__qualname__}",
            f"# (spec {self.letters!r}{' -> r' if self.returns else ''}); exactly what runs",
            "import numba",
            "from shipgnc.kernels import JIT_OPTIONS",
            f"from {py.__module__} import {py.__qualname__} as kernel",
            "# kernel",
            "import numba",
            "from shipgnc.kernels import JIT_OPTIONS",
            "CACHE = True",
            "",
            f"def serial({signature}):",
            f"    for i in range({count}):",
            f"        {body}",
            "",
            f"def parallel({signature}):",
            f"    for i in numba.prange({count}):",
            f"        {body}",
            "",
            'serial = numba.njit(**{**JIT_OPTIONS, "cache": CACHE})(serial)',
            'parallel = numba.njit(parallel=True, **{**JIT_OPTIONS, "cache": CACHE})(parallel)',
            "",
        ]
        return "\n".join(lines)
