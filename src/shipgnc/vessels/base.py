"""What every catalogue vessel model shares: the state layout, the steering machine, kinematics.

State (SI, NED, ψ clockwise from north)::

    [north, east, psi, u, v, r, delta, ...extra]

``u`` is the TOTAL surge speed [m/s] (a model that works with a perturbation about its design
speed converts internally), ``v`` the sway speed [m/s] at the body origin, ``r`` the yaw rate
[rad/s], ``delta`` the actual rudder angle [rad] (positive turns the bow to starboard). Extra
states follow (e.g. ``n``, propeller revolutions [1/s]). Inputs: ``delta_c`` (rudder command
[rad]) first, then e.g. ``n_c``. Disturbance: an earth-fixed current ``[current_north,
current_east]`` [m/s] added to the position rates (kinematic drift; the hull forces see the water
as still).

Steering machine (as in Fossen's MSS ``mariner.m``/``frigate.m``, Fossen 2021 §9.5): the command
is clipped to ±``delta_max``, then

    δ̇ = sat( (δ_c − δ)/T_δ , ±δ̇_max )

a first-order servo of time constant T_δ (default 1 s) that slews at the rate limit δ̇_max for
any sizeable step (the rudder "moves at its rate limit" of the trials, docs/trials.md).
"""

from __future__ import annotations

import math
from functools import cached_property

import numpy as np

from shipgnc.errors import require
from shipgnc.models.base import Signal, kernel_derivatives

BASE_STATES = (
    Signal("north", "m", "north position (NED x)"),
    Signal("east", "m", "east position (NED y)"),
    Signal("psi", "rad", "heading, clockwise from north (unwrapped)", angle=True),
    Signal("u", "m/s", "surge speed (total)"),
    Signal("v", "m/s", "sway speed (starboard)"),
    Signal("r", "rad/s", "yaw rate (bow to starboard)"),
    Signal("delta", "rad", "rudder angle (actual), positive turns the bow to starboard",
           angle=True),
)
RUDDER_INPUT = Signal("delta_c", "rad", "rudder command, positive turns the bow to starboard",
                      angle=True)
DISTURBANCES = (
    Signal("current_north", "m/s", "current velocity, north component"),
    Signal("current_east", "m/s", "current velocity, east component"),
)
#: runaway guards of the base states (position, heading, speeds, yaw rate, rudder)
BASE_LIMITS = (1e8, 1e8, 1e5, 100.0, 100.0, 10.0, 10.0)

#: IMO/SOLAS steering gear: 35° one side to 30° the other in 28 s → 65°/28 s ≈ 2.32°/s
SOLAS_RUDDER_RATE = math.radians(65.0 / 28.0)


def check_number(name: str, value, rule: str = "must be a finite number", *, positive=False,
                 where: str = "vessel") -> float:
    """``value`` as float, or a one-line ConfigError ``vessel.<name> = value: rule``."""
    ok = isinstance(value, (int, float, np.floating, np.integer)) and not isinstance(value, bool)
    require(ok and math.isfinite(float(value)), f"{where}.{name}", value, "must be a finite number")
    if positive:
        require(float(value) > 0, f"{where}.{name}", value, rule)
    return float(value)


class CatalogueModel:
    """Mixin of the catalogue's frozen model dataclasses.

    A subclass defines fields ``delta_max`` [rad], ``delta_rate`` [rad/s], ``T_delta`` [s] and
    ``speed`` [m/s] (its speed of design or construction), ``extra_states``, ``inputs``,
    ``extra_limits`` and a ``kernel()`` whose function (:mod:`shipgnc.vessels.kernels`) is ẋ of
    one ship: its equations written once, :meth:`derivatives` their batch. A vessel written only
    in numpy defines :meth:`body_rates` instead (the numpy loop's slow path).
    """

    extra_states: tuple[Signal, ...] = ()
    extra_limits: tuple[float, ...] = ()
    inputs: tuple[Signal, ...] = (RUDDER_INPUT,)
    disturbances = DISTURBANCES
    can_reverse = False

    @property
    def states(self) -> tuple[Signal, ...]:
        return BASE_STATES + self.extra_states

    @property
    def state_limits(self) -> tuple[float, ...]:
        return BASE_LIMITS + self.extra_limits

    @property
    def params(self):
        """The model is its own frozen parameter set (``model.params.delta_max`` etc.)."""
        return self

    def _check_steering(self) -> None:
        require(0 < self.delta_max <= math.pi / 2, "vessel.rudder_max", self.delta_max,
                "need 0 < rudder limit <= pi/2 rad (90°)")
        require(self.delta_rate > 0, "vessel.rudder_rate", self.delta_rate,
                "rudder rate limit must be > 0 rad/s")
        require(self.T_delta > 0, "vessel.rudder_time_constant", self.T_delta,
                "steering-machine time constant must be > 0 s")

    def input_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """Bounds of the inputs: ±delta_max for ``delta_c`` (subclasses add theirs)."""
        return np.array([-self.delta_max]), np.array([self.delta_max])

    def rudder_rate(self, delta, delta_c):
        """δ̇ = sat((sat(δ_c, ±δ_max) − δ)/T_δ, ±δ̇_max) [rad/s] (steering machine,
        :func:`~shipgnc.vessels.kernels.steering_rate` elementwise)."""
        from shipgnc.vessels.kernels import steering_rate

        return np.vectorize(steering_rate, otypes=[float])(
            delta, delta_c, self.delta_max, self.delta_rate, self.T_delta)

    def body_rates(self, x, u):
        """(u̇, v̇, ṙ, *extra) for states ``x`` (..., n) and inputs ``u`` (..., m): a vessel written
        only in numpy defines this instead of a :meth:`kernel` (the slow path)."""
        raise NotImplementedError

    @cached_property
    def _kernel(self):
        kernel = getattr(self, "kernel", None)
        return kernel() if callable(kernel) else None

    def derivatives(self, x, u, d=None):
        """ẋ for ``x`` (..., n_states), ``u`` (..., n_inputs), ``d`` (..., 2) or None: the batch of
        the vessel's kernel (its ``kernel()``, :mod:`shipgnc.vessels.kernels`); a vessel without
        one gets the kinematics and the steering machine from
        :func:`~shipgnc.vessels.kernels.steering_rhs` and its body rates from :meth:`body_rates`."""
        kernel = self._kernel
        if kernel is not None:
            return kernel_derivatives(self, kernel.function, kernel.params, x, u, d)
        from shipgnc.vessels.kernels import steering_rhs

        x, u = np.asarray(x, dtype=float), np.asarray(u, dtype=float)
        xdot = kernel_derivatives(self, steering_rhs, [self.delta_max, self.delta_rate, self.T_delta],
                                  x, u, d)
        rates = self.body_rates(x, u)
        for i, rate in zip((3, 4, 5, *range(7, xdot.shape[-1])), rates, strict=True):
            xdot[..., i] = rate
        return xdot

    def state(self, *, u: float, v: float = 0.0, r: float = 0.0, delta: float = 0.0,
              extra: tuple[float, ...] = (), north: float = 0.0, east: float = 0.0,
              psi: float = 0.0) -> np.ndarray:
        """A state vector from named parts (SI)."""
        return np.array([north, east, psi, u, v, r, delta, *extra], dtype=float)

    def straight_state(self, speed_mps: float | None = None) -> np.ndarray:
        """x0 of steady straight running (δ = 0, r = 0, v = 0) at ``speed_mps`` (default: the
        model's speed). Models with constant side-force terms override it with their trim."""
        U = self.speed if speed_mps is None else float(speed_mps)
        return self.state(u=U)
