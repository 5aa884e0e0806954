"""Simple steering models at a constant speed: Nomoto (first order) and Norrbin (note 000-0.3).

Equations (document 000 eq. (3)–(6)), SI units (s, m, rad)::

    Nomoto   T ψ̈ + ψ̇ = K δ                   ṙ = (K δ − r)/T
    Norrbin  T ṙ + H_N(r) = K δ,  H_N(r) = a₃r³ + a₂r² + a₁r + a₀
    both     ẋ = U cos ψ + c_N,   ẏ = U sin ψ + c_E,   ψ̇ = r

State ``[north, east, psi, r]`` (NED, ψ clockwise from north), input ``[delta]`` [rad],
disturbance ``[b_r, current_north, current_east]`` as for the Mariner
(:mod:`shipgnc.models.mariner`): a yaw acceleration [rad/s²] added to ṙ and a current [m/s]
added to the kinematics. The ship sails at the constant speed ``U`` [m/s] without sway, so the
CG moves along the heading. With K > 0, δ > 0 turns the bow to starboard.

Norrbin with a₁ = 1 (a₀ = a₂ = a₃ = 0) is Nomoto; a₁ = −1 is a course-unstable ship, a₀ ≠ 0 a
single screw, a₂ = 0 a symmetric hull (eq. (6)). In SI a₁ is dimensionless, a₀ in rad/s, a₂ in
s/rad and a₃ in s²/rad². The Mariner's yaw equation is Norrbin with T = 60 s, K = 60 c,
a₁ = 60 a, a₃ = 60 b (note 000-0.3: T = 1 min, K = c, H_N = a r + b r³, in minutes).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

import numpy as np

from shipgnc.errors import require
from shipgnc.frames import body_to_ned
from shipgnc.models.base import Signal
from shipgnc.params import Params

STATES = (
    Signal("north", "m", "north position (NED x)"),
    Signal("east", "m", "east position (NED y)"),
    Signal("psi", "rad", "heading, clockwise from north (unwrapped)", angle=True),
    Signal("r", "rad/s", "yaw rate (bow to starboard)"),
)
INPUTS = (Signal("delta", "rad", "rudder angle, positive turns the bow to starboard (K > 0)",
                 angle=True),)
DISTURBANCES = (
    Signal("b_r", "rad/s^2", "yaw acceleration disturbance (added to r_dot)"),
    Signal("current_north", "m/s", "current velocity, north component"),
    Signal("current_east", "m/s", "current velocity, east component"),
)


class _SteeringModel(Params):
    """Shared pieces of the constant-speed steering models (validation, kinematics, limits)."""

    states = STATES
    inputs = INPUTS
    disturbances = DISTURBANCES
    state_limits = (1e8, 1e8, 1e5, 10.0)

    @property
    def params(self):
        """The model is its own frozen parameter set (``model.params.K`` etc.)."""
        return self

    def _check_numbers(self) -> None:
        for fl in fields(self):
            value = getattr(self, fl.name)
            require(isinstance(value, (int, float)) and not isinstance(value, bool),
                    f"vessel.params.{fl.name}", value, "must be a number")
            require(math.isfinite(value), f"vessel.params.{fl.name}", value, "must be finite")
        require(self.U >= 0, "vessel.params.U", self.U, "speed must be >= 0 m/s")
        require(0 < self.delta_max <= math.pi / 2, "vessel.params.delta_max", self.delta_max,
                "need 0 < delta_max <= pi/2 rad (90°)")

    def input_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper bounds of ``[delta]`` (±delta_max)."""
        return np.array([-self.delta_max]), np.array([self.delta_max])

    def yaw_acceleration(self, r, delta):
        raise NotImplementedError

    def derivatives(self, x, u, d=None):
        """ẋ for ``x`` (..., 4) = [north, east, ψ, r], ``u`` (..., 1) = [δ], ``d`` (..., 3) or None."""
        psi, sr = x[..., 2], x[..., 3]
        north_dot, east_dot = body_to_ned(psi, self.U, 0.0)
        r_dot = self.yaw_acceleration(sr, u[..., 0])
        if d is not None:
            r_dot = r_dot + d[..., 0]
            north_dot = north_dot + d[..., 1]
            east_dot = east_dot + d[..., 2]
        return np.stack([north_dot, east_dot, sr, r_dot], axis=-1)


@dataclass(frozen=True)
class NomotoModel(_SteeringModel):
    """First-order Nomoto model T ṙ + r = K δ (eq. (3)) at constant speed ``U`` [m/s].

    ``K`` [1/s] is the yaw-rate gain, ``T`` [s] the time constant (T < 0 with K < 0 is the
    first-order model of a course-unstable ship). Step response from rest:
    r(t) = K δ (1 − e^{−t/T}).
    """

    K: float
    T: float
    U: float = field(kw_only=True)
    delta_max: float = field(default=math.radians(35.0), kw_only=True)

    def __post_init__(self) -> None:
        self._check_numbers()
        require(self.T != 0, "vessel.params.T", self.T, "time constant must be nonzero s")

    def yaw_acceleration(self, r, delta):
        """ṙ = (K δ − r)/T [rad/s²]."""
        return (self.K * delta - r) / self.T


@dataclass(frozen=True)
class NorrbinModel(_SteeringModel):
    """Norrbin model T ṙ + H_N(r) = K δ, H_N = a₃r³ + a₂r² + a₁r + a₀ (eq. (4)–(6)), speed ``U``.

    ``K`` [1/s], ``T`` [s] > 0; a course-stable ship has a₁ = 1, a course-unstable one a₁ = −1
    (then a₃ > 0 is needed to bound the yaw rate). Steady turns solve H_N(r) = K δ.
    """

    K: float
    T: float
    a1: float
    a3: float
    a0: float = 0.0
    a2: float = 0.0
    U: float = field(kw_only=True)
    delta_max: float = field(default=math.radians(35.0), kw_only=True)

    def __post_init__(self) -> None:
        self._check_numbers()
        require(self.T > 0, "vessel.params.T", self.T, "time constant must be > 0 s")
        require(self.a3 >= 0, "vessel.params.a3", self.a3, "cubic yaw damping must be >= 0 s²")
        require(self.a1 > 0 or self.a3 > 0, "vessel.params.a1", self.a1,
                "a course-unstable ship (a1 <= 0) needs a3 > 0")

    def manoeuvring(self, r):
        """H_N(r) = a₃r³ + a₂r² + a₁r + a₀ [rad/s] (eq. (5))."""
        return ((self.a3 * r + self.a2) * r + self.a1) * r + self.a0

    def yaw_acceleration(self, r, delta):
        """ṙ = (K δ − H_N(r))/T [rad/s²]."""
        return (self.K * delta - self.manoeuvring(r)) / self.T
