"""Uniform currents as disturbances: fixed in NED, or across the active leg of a path.

Document 000's cross current d_y acts "along OY_r", perpendicular to the active leg (note 000-A10): in NED
it is R(ψ_r0)·[0, d_y]ᵀ = d_y·[−sin ψ_r0, cos ψ_r0] with ψ_r0 the active leg's
angle (eq. (2)); the ``global`` option fixes it along global y (east). The active leg follows the
switching rule of note 000-A6 (:class:`~shipgnc.paths.LegTracker`), tracked from the
ship's position at each step's start; the current is held over the step.
"""

from __future__ import annotations

import numpy as np

from shipgnc.errors import require
from shipgnc.paths import LegTracker, WaypointPath

CURRENT_FRAMES = ("path", "global")


class CrossCurrent:
    """Current of speed ``d_y`` [m/s] across the active leg (``frame="path"``) or along east
    (``frame="global"``); returns [current_north, current_east] (..., 2) [m/s].

    ``north_index``, ``east_index``: where the model's state holds the position.
    """

    per_stage = False

    def __init__(self, d_y: float, path: WaypointPath, *, frame: str = "path",
                 north_index: int = 0, east_index: int = 1):
        require(isinstance(d_y, (int, float)) and np.isfinite(d_y), "disturbance.d_y", d_y,
                "must be a finite speed in m/s")
        require(frame in CURRENT_FRAMES, "disturbance.current_frame", frame,
                f"allowed: {', '.join(CURRENT_FRAMES)}")
        self.d_y, self.frame = float(d_y), frame
        self.tracker = LegTracker(path)
        self._i = (north_index, east_index)

    def reset(self, batch_shape, rng=None) -> None:
        self.tracker.reset(batch_shape)

    def __call__(self, t: float, x: np.ndarray) -> np.ndarray:
        if self.frame == "global":
            zeros = np.zeros(x.shape[:-1])
            return np.stack([zeros, zeros + self.d_y], axis=-1)
        _, _, angle = self.tracker.update(x[..., self._i[0]], x[..., self._i[1]])
        return np.stack([-self.d_y * np.sin(angle), self.d_y * np.cos(angle)], axis=-1)
