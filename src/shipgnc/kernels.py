"""Compiled components: the record a component hands to the composed loop, and the scalar helpers
every component kernel shares.

A component (vessel model, controller, guidance law, disturbance) writes its per-ship arithmetic
once, as a small numba function over a flat float64 parameter array and a slice of per-ship state,
and hands it over in a :class:`Kernel`. The composed loop (:mod:`shipgnc.sim.compose`) calls these
functions inside one compiled loop over ships and time; the component's numpy methods, which the
numpy loop, linearisation and design call, are the batch :func:`shipgnc.derive.per_ship` derives
from the same function (its plain-Python ``py_func`` is the debugging form). A component written
only in numpy still runs, in the numpy loop: a component without a kernel (or whose ``kernel``
raises :class:`NotCompiled`) makes the run fall back to numpy, and the reason names the component.

Signatures, by kind (``x`` the ship's state, ``p`` the parameters, ``z`` the component's own
per-ship state, mutated in place; every array is a 1-D float64 slice of one ship):

* model       ``rhs(x, u, d, p, xdot)`` — writes ẋ; ``d`` is zeros when the run has no
  disturbance, so a model's kernel treats zero ``d`` exactly as ``d=None``;
* controller  ``step(t, x, ref, z, p, cmd, sig)`` — sampled every Ts; writes the command and the
  logged signals ``sig``; a ``continuous`` controller's kernel has the same signature and is
  called at the samples (``sig`` logged) and in every RK4 stage (``sig`` a scratch array there);
* guidance    ``reference(t, x, z, p, ref, out) -> finished`` — writes the references and the
  logged outputs, returns True once the ship's task is complete;
* disturbance ``sample(t, x, z, p, w, d)`` — writes ``d``; ``w`` is the step's row of a table the
  component fills in numpy before each kernel call (its random draws, at t_k = k·dt: a
  disturbance's ``kernel(batch_shape, dt)`` is told the step), so a seed gives the same sea as the
  numpy loop; ``per_stage`` disturbances are called in every RK4 stage.

Methods, called after the component's ``reset``: ``model.kernel()``,
``controller.kernel(batch_shape)``, ``guidance.kernel(batch_shape)``,
``disturbance.kernel(batch_shape, dt)``; optionally ``kernel_reason()`` → None or why a setting of
the component has no kernel (checked before the run, so the fallback to numpy costs nothing).

All kernels use :data:`JIT_OPTIONS`: cached on disk, fused multiply-add and x/c → x·(1/c) only,
so NaN and inf keep their meaning for the divergence guard; results move at round-off level.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field

import numba
import numpy as np

#: numba options of every component kernel and of the composed loop
JIT_OPTIONS = {"cache": True, "error_model": "numpy", "fastmath": {"contract", "arcp"}}
TWO_PI = 2.0 * math.pi


class NotCompiled(Exception):
    """A component (or one of its settings) has no kernel; the message says which and why."""


def kernel_function(function):
    """Compile ``function`` as a component kernel or scalar helper (lazily, on first call; cached
    on disk when it is defined in a file; a kernel typed into a notebook or ``exec``-ed compiles
    once per process). Kernels are called, not inlined, by the composed loop: numba's IR-level
    inlining (``inline="always"``) ran the boat ≈ 25 % faster but tripled the loop's first compile
    and defeated its disk cache (a disturbance's kernels excepted: :mod:`shipgnc.sim.loop_template`).

    Developers: numba's cache of a kernel is keyed to its own file only, so after editing a helper
    that kernels in *other* files call (``wrap``, ``paths.track_leg``), delete the
    ``__pycache__/*.nbi`` files (the composed loops are keyed to every file of the package and
    regenerate by themselves). Without the per-kernel cache every new combination would compile
    twice as long; an installed package never meets the case."""
    in_a_file = os.path.isfile(function.__code__.co_filename)
    return numba.njit(**{**JIT_OPTIONS, "cache": in_a_file})(function)


@dataclass(frozen=True, eq=False)
class Kernel:
    """A component's per-ship arithmetic for the composed loop (see the module docstring).

    ``function`` is the numba dispatcher (its identity keys the memoised composed loops);
    ``params`` the flat parameter array, or one row per ship ``(n_ships, n_p)`` (parameters that
    differ from ship to ship, e.g. a Monte Carlo over the plant; the kernel gets its ship's row);
    ``state`` the initial per-ship state ``(n_ships, n_z)`` (after the component's ``reset``);
    ``table(k0, k1)`` the per-step inputs of steps ``k0 <= k < k1``, shape
    ``(k1 - k0, n_ships, n_table)``; ``restore(z)`` leaves the component as the numpy loop would,
    from the final per-ship state.
    """

    function: Callable
    params: np.ndarray = field(default_factory=lambda: np.zeros(1))
    state: np.ndarray | None = None
    table: Callable | None = None
    n_table: int = 0
    restore: Callable | None = None
    per_stage: bool = False
    continuous: bool = False

    def state_for(self, n_ships: int) -> np.ndarray:
        """The initial per-ship state as a fresh C-ordered ``(n_ships, n_z)`` array."""
        if self.state is None:
            return np.zeros((n_ships, 0))
        z = np.asarray(self.state, dtype=float)
        return np.array(np.broadcast_to(z.reshape(-1, z.shape[-1]) if z.ndim > 1 else z,
                                        (n_ships, z.shape[-1])), dtype=np.float64, order="C")


def flat(*parts) -> np.ndarray:
    """Concatenate numbers and arrays into one flat, owned float64 parameter array."""
    pieces = [np.atleast_1d(np.asarray(part, dtype=float)).ravel() for part in parts]
    return np.ascontiguousarray(np.concatenate(pieces) if pieces else np.zeros(1), dtype=np.float64)


# ----------------------------------------------------------------------------------------------
# scalar helpers shared by the kernels (one place for each: the numpy forms live in frames.py and
# timeseries.py, and these follow them operation for operation)
# ----------------------------------------------------------------------------------------------

@kernel_function
def wrap(angle):
    """:func:`shipgnc.frames.wrap_angle` for one float: (−π, π], numpy's ``remainder`` convention."""
    a = angle + math.pi
    # remainder(a, 2π) = fmod(a, 2π) moved into [0, 2π); fmod is exact: a itself for |a| < 2π,
    # a ∓ 2π for |a| < 4π (Sterbenz); only larger angles pay for the general float modulo
    if abs(a) < TWO_PI:
        m = a
    elif abs(a) < 2.0 * TWO_PI:
        m = a - TWO_PI if a > 0.0 else a + TWO_PI
    else:
        m = a % TWO_PI
    if m < 0.0:
        m += TWO_PI
    elif m == 0.0:
        m = 0.0
    w = m - math.pi
    if w == -math.pi:
        return math.pi
    return w


@kernel_function
def clip(value, lower, upper):
    """``np.clip`` for one float (NaN passes through, for the divergence guard)."""
    if value < lower:
        value = lower
    if value > upper:
        value = upper
    return value


@kernel_function
def sign(value):
    """``np.sign`` for one float (NaN passes through)."""
    if value > 0.0:
        return 1.0
    if value < 0.0:
        return -1.0
    if value == 0.0:
        return 0.0
    return value


@kernel_function
def schedule_row(times, t):
    """Row of a :class:`~shipgnc.timeseries.PiecewiseConstant` holding at ``t`` (same rule:
    ``searchsorted(times, t + 1e-9·max(1, |t|), "right") − 1``)."""
    return np.searchsorted(times, t + 1e-9 * max(1.0, abs(t)), side="right") - 1


def schedule_params(schedule) -> np.ndarray:
    """``[n, times (n), values (n × m, row-major)]`` of a PiecewiseConstant, for :func:`schedule_row`."""
    return flat(len(schedule.times), schedule.times, schedule.values)
