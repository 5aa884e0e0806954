"""Named slots of the navigation kernels' flat arrays: every block a sensor, an estimator or the
navigation system hands to the compiled loop is declared here by field name and size, and every
offset is computed from the declaration (no number is written by hand where a field is read).

A :class:`Layout` lists the fixed fields of a block in order; its :meth:`Layout.at` gives their
offsets as module constants the kernels read (numba freezes module integers as constants), and
:meth:`Layout.pack` writes a block from named values, refusing a missing, unknown or mis-sized
field. The variable parts that follow a fixed head (a sensor's state indices, a filter's
matrices) are described by the layout's ``tail`` text and carved in order by their sizes.
"""

from __future__ import annotations

import numpy as np


class Layout:
    """Fields ``(name, size)`` of a flat float64 block, in order; offsets from the sizes."""

    def __init__(self, name: str, *fields: tuple[str, int], tail: str = ""):
        self.name = name
        self.fields = tuple(fields)
        self.tail = tail
        self.offsets: dict[str, int] = {}
        at = 0
        for field, size in self.fields:
            if field in self.offsets or size < 1:
                raise ValueError(f"layout {name}: field {field!r} repeated or of size {size}")
            self.offsets[field] = at
            at += size
        #: the numbers of the fixed head; the variable tail starts here
        self.size = at

    def __getitem__(self, field: str) -> int:
        return self.offsets[field]

    def at(self, *names: str) -> tuple[int, ...]:
        """The offsets of ``names``, in that order (to bind as module constants)."""
        return tuple(self.offsets[n] for n in names)

    def pack(self, **values) -> list[float]:
        """The fixed head from one value (or sequence of ``size`` values) per field."""
        unknown = sorted(set(values) - set(self.offsets))
        missing = [f for f, _ in self.fields if f not in values]
        if unknown or missing:
            raise ValueError(f"layout {self.name}: unknown {unknown}, missing {missing}")
        out: list[float] = []
        for field, size in self.fields:
            v = np.ravel(np.asarray(values[field], dtype=float))
            if v.size != size:
                raise ValueError(f"layout {self.name}.{field}: {v.size} numbers, not {size}")
            out += [float(e) for e in v]
        return out

    def describe(self) -> str:
        """``name: field (size), ...; then <tail>`` for docstrings and errors."""
        head = ", ".join(f"{f}" if s == 1 else f"{f} × {s}" for f, s in self.fields)
        return f"{self.name}: [{head}]" + (f", then {self.tail}" if self.tail else "")

