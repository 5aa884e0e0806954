"""Document 000's path frame as guidance: the active leg of a waypoint path and the ship's errors
in its frame (notes 000-A4, 000-A6), the references of the path-tracking laws
(:class:`~shipgnc.control.lqr.PathLQR`, :class:`~shipgnc.control.feedback_linearization.OutputFL`,
:class:`~shipgnc.control.feedback_linearization.LOSFL`).

For the active leg i from P_i with course π_p (clockwise from north), eq. (2) of document 000::

    y_r = −(n − n_i) sin π_p + (e − e_i) cos π_p      (cross-track error, positive to starboard)
    ψ_r = wrap(ψ − π_p)                              (path-relative heading)

Leg i + 1 becomes active once the along-track distance x_r on leg i reaches its length (A6,
:class:`~shipgnc.paths.LegTracker`); the last leg is a half-line, so the task never finishes.

Waypoint paths and the leg tracker themselves live in :mod:`shipgnc.paths` (core geometry, like
:mod:`shipgnc.frames`: vessel models and currents use them too); this module keeps their old
import path working.
"""

from __future__ import annotations

import numpy as np

from shipgnc.errors import require
from shipgnc.guidance.base import kernel_reference
from shipgnc.kernels import Kernel, flat, kernel_function, wrap
from shipgnc.models.base import Signal, state_index
from shipgnc.paths import LEG_ANGLE, LegTracker, WaypointPath, leg_table, leg_value, track_leg

__all__ = ["LegTracker", "PathGuidance", "WaypointPath", "leg_table", "leg_value", "path_reference",
           "track_leg"]

#: the references of :class:`PathGuidance`, in order (a path law names them in its
#: ``reference_names`` and finds each by name)
PATH_REFERENCES = (
    Signal("cross_track_error", "m", "cross-track error y_r of the active leg, positive to starboard"),
    Signal("heading_error", "rad", "path-relative heading psi_r = psi - leg course", angle=True),
    Signal("path_course", "rad", "course pi_p of the active leg, clockwise from north", angle=True),
)


class PathGuidance:
    """The path frame of a :class:`~shipgnc.paths.WaypointPath` (module docstring): references
    ``[cross_track_error y_r, heading_error ψ_r, path_course π_p]`` and the output ``leg``.

    Works with any model that has ``north``, ``east`` and ``psi`` states (found by name at
    ``reset``). Batched: each ship has its own active leg."""

    references = PATH_REFERENCES
    outputs = (Signal("leg", "1", "active leg index (0-based)"),)

    def __init__(self, path: WaypointPath):
        require(isinstance(path, WaypointPath), "guidance.path", type(path).__name__,
                "must be a WaypointPath")
        self.path = path
        self.tracker = LegTracker(path)
        self._index = (0, 1, 2)
        self._outputs: dict[str, np.ndarray] = {}

    def reset(self, batch_shape, model) -> None:
        self._index = tuple(state_index(model, name) for name in ("north", "east", "psi"))
        self.tracker.reset(batch_shape)
        self._outputs = {}

    def reference(self, t: float, x: np.ndarray) -> np.ndarray:
        """``[y_r, ψ_r, π_p]`` for every ship: the batch of :func:`path_reference`."""
        references, self._outputs = kernel_reference(self, t, x)
        return references

    def output_values(self) -> dict[str, np.ndarray]:
        return self._outputs

    def finished(self) -> None:
        """None: the last leg is a half-line, the task has no end."""
        return None

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`reference` for the composed loop (:func:`path_reference`), after ``reset``;
        per-ship state ``[leg]``."""
        shape = tuple(batch_shape)
        params = flat(*self._index, leg_table(self.path))
        leg = np.broadcast_to(np.asarray(self.tracker.leg, dtype=float), shape)

        def restore(z: np.ndarray) -> None:
            self.tracker.leg = z[:, 0].astype(int).reshape(shape)
            self._outputs = {"leg": self.tracker.leg.astype(float)}

        return Kernel(path_reference, params, leg[..., None], restore=restore)


#: where :func:`path_reference` finds the leg table in its parameters
_LEGS = 3


@kernel_function
def path_reference(t, x, z, p, ref, out):
    """The path frame of document 000 for one ship: the active leg (A6, :func:`track_leg`), then
    eq. (2) y_r = −(n − n_i) sin π_p + (e − e_i) cos π_p, ψ_r = wrap(ψ − π_p), and π_p.
    ``p`` = [north, east, psi indices, leg table]; ``z`` = [leg]."""
    leg, _, y_r = track_leg(x[int(p[0])], x[int(p[1])], int(z[0]), p, _LEGS)
    angle = leg_value(p, _LEGS, LEG_ANGLE, leg)
    z[0] = leg
    ref[0] = y_r
    ref[1] = wrap(x[int(p[2])] - angle)
    ref[2] = angle
    out[0] = float(leg)
    return False
