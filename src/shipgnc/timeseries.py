"""Piecewise-constant schedules: the one lookup used by open-loop commands and references."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from shipgnc.errors import require


@dataclass(frozen=True, eq=False)
class PiecewiseConstant:
    """Value ``values[i]`` holds for ``times[i] <= t < times[i+1]`` (the last one forever).

    A small tolerance (1e-9 relative) makes a switch at 5 s fire at the sample t = 100·0.05 s
    even when floating point lands a hair below it (note 001-A8).
    """

    times: np.ndarray
    values: np.ndarray
    field: str = "schedule"

    def __post_init__(self) -> None:
        times = np.asarray(self.times, dtype=float)
        values = np.asarray(self.values, dtype=float)
        require(times.ndim == 1 and times.size >= 1, self.field, times.tolist(),
                "need at least one entry")
        require(bool(np.all(np.isfinite(times))), f"{self.field}.t", times.tolist(),
                "times must be finite")
        require(times[0] == 0.0, f"{self.field}[0].t", float(times[0]),
                "the first entry must start at t = 0")
        require(bool(np.all(np.diff(times) > 0)), f"{self.field}.t", times.tolist(),
                "times must be strictly increasing")
        require(values.shape[0] == times.size, self.field, values.shape,
                "one value row per time")
        require(bool(np.all(np.isfinite(values))), self.field, values.tolist(),
                "values must be finite")
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "values", values)

    def index(self, t: float) -> int:
        return int(np.searchsorted(self.times, t + 1e-9 * max(1.0, abs(t)), side="right")) - 1

    def __call__(self, t: float) -> np.ndarray:
        return self.values[self.index(t)]
