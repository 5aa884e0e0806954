"""Mariner-class cargo ship: the de Wit–Oppe simulation model (25) of document 000.

Equations (note 000-0.3, eq. (25); signs restored, A3)::

    ẋ = u cos ψ − v sin ψ + c_N          ẏ = u sin ψ + v cos ψ + c_E
    ψ̇ = r                                ṙ = −a r − b r³ + c δ + b_r
    u̇ = −f u − W r² + S                  v = r₁ r + r₂ r³   (algebraic)

State ``[north, east, psi, u, r]`` (NED, ψ clockwise from north; the document's x, y are the
toolkit's ``north``, ``east``), input ``[delta]`` [rad], disturbance ``[b_r, current_north,
current_east]``: a yaw acceleration [rad/s²] added to ṙ (A9) and an earth-fixed current
(c_N, c_E) [m/s] added to the kinematics. The document's cross current d_y acts along the active
leg's Y_r axis (A10); the scenario turns it into NED with the leg's angle ψ_r0, e.g.
``body_to_ned(psi_r0, 0.0, d_y)``.

**Current as relative velocity** (Fossen 2021 §10.3, ν_r = ν − ν_c). u is the *total* surge speed
(not a perturbation: u̇ = −f u − W r² + S settles at U = S/f), and u, the algebraic v and r are the
velocity **through the water** ν_r = [u_r, v_r, r]: every hull term of eq. (25) sees relative
velocity — the surge damping −f u, the speed loss in turns −W r² and the thrust S, the sway
v = r₁ r + r₂ r³, and the yaw terms −a r − b r³ + c δ (a current has no yaw component, so r is the
same through the water and over ground). Only the kinematics see the current::

    [ẋ, ẏ] = R(ψ)[u_r, v_r]ᵀ + [c_N, c_E]ᵀ,    ν̇_r = f(ν_r, δ)   (the hull equations above)

This is the boat's and the catamaran's formulation (:mod:`shipgnc.models.fossen3dof`: ν over
ground as their state, ν̇ = ν̇_r + (r v_c, −r u_c, 0), ν_c = R(ψ)ᵀ[c_N, c_E]) written in ν_r: for a
current constant in NED the two are the same equations, so the motion through the water is the
still-water motion and the track over ground is the still-water track moved by c·t. For a current
that changes in time or along the track this form lets the water's acceleration carry the ship
(ν̇_r does not see it) where the boat's form neglects R(ψ)ᵀ ċ; the two agree to first order in
the current's rate of change. The scenario's ``current`` section (uniform, Gauss–Markov, gridded:
:mod:`shipgnc.environment.current_field`) fills (c_N, c_E) with the same field objects as the other
vessels (:class:`MarinerYawDisturbance` is then the yaw channel beside it); document 000's d_y
(:class:`~shipgnc.environment.current.CrossCurrent`) fills the same channels, and its path-frame
form changes direction at each waypoint, where the ship's ground velocity jumps with it.

**Sway is algebraic.** v is not a state: ``sway(r)`` = r₁ r + r₂ r³ is evaluated from the yaw rate
wherever it is needed. With r₁ < 0 a starboard turn (r > 0) gives v < 0 at the centre of gravity;
the pivot point, where the hull's lateral velocity v + x r vanishes, lies −r₁ = 69.45 m ahead of
the CG (for r₂ = 0).

**Rudder sign:** c > 0, so δ > 0 gives ṙ > 0: the bow turns to **starboard** (the opposite of
CyberShip II, document 003). The steering machine (±35°, 3.8°/s) is an actuator, :func:`rudder`.

The document works in minutes, nautical miles and radians (A1); :class:`MarinerParams` holds SI
values and converts at this boundary (:meth:`MarinerParams.from_paper_units`,
:meth:`MarinerParams.to_paper_units`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from functools import cached_property
from types import MappingProxyType

import numpy as np

from shipgnc.actuators import Actuator
from shipgnc.derive import per_ship
from shipgnc.environment.fields import field_velocity
from shipgnc.errors import ConfigError, require
from shipgnc.kernels import Kernel, NotCompiled, flat, kernel_function
from shipgnc.models.base import Signal, kernel_derivatives, kernel_jacobian
from shipgnc.params import Params
from shipgnc.paths import leg_table, track_leg
from shipgnc.units import MINUTE, NAUTICAL_MILE

#: per parameter: (the document's unit, SI value of one document unit). Angles are rad in both.
PAPER_UNITS: Mapping[str, tuple[str, float]] = MappingProxyType({
    "a": ("1/min", 1.0 / MINUTE),
    "b": ("min", MINUTE),
    "c": ("1/min^2", 1.0 / MINUTE**2),
    "r1": ("nm/rad", NAUTICAL_MILE),
    "r2": ("nm min^2/rad^3", NAUTICAL_MILE * MINUTE**2),
    "f": ("1/min", 1.0 / MINUTE),
    "W": ("nm/rad^2", NAUTICAL_MILE),
    "S": ("nm/min^2", NAUTICAL_MILE / MINUTE**2),
    "delta_max": ("rad", 1.0),
    "delta_rate": ("rad/min", 1.0 / MINUTE),
})

#: the document's values in its own units (note 000-0.1); δ̇_max = 3.8°/s = 228°/min
PAPER_VALUES: Mapping[str, float] = MappingProxyType({
    "a": 1.084, "b": 0.62, "c": 3.553, "r1": -0.0375, "r2": 0.0, "f": 0.86, "W": 0.067, "S": 0.215,
    "delta_max": math.radians(35.0), "delta_rate": math.radians(228.0),
})

#: the document's yaw disturbance b_r = 0.1 rad/min² in SI [rad/s²] (A9)
DOC_B_R = 0.1 / MINUTE**2
#: the document's cross current d_y = 0.04 nm/min in SI [m/s] (2.4 kn, A10)
DOC_D_Y = 0.04 * NAUTICAL_MILE / MINUTE


def _si(name: str) -> float:
    return PAPER_VALUES[name] * PAPER_UNITS[name][1]


@dataclass(frozen=True)
class MarinerParams(Params):
    """Parameters of the de Wit–Oppe model (defaults: the document's Mariner; SI throughout).

    ==========  ==================  ==================  =================  =======================
    field       paper value         paper unit          SI value           SI unit
    ==========  ==================  ==================  =================  =======================
    a           1.084               1/min               0.018067           1/s
    b           0.62                min                 37.2               s  (multiplies r³)
    c           3.553               1/min² (A2)         9.869e-4           1/s²  (δ in rad)
    r1          −0.0375             nm/rad              −69.45             m/rad
    r2          0                   nm·min²/rad³        0                  m·s²/rad³
    f           0.86                1/min               0.014333           1/s
    W           0.067               nm/rad²             124.08             m/rad²
    S           0.215               nm/min²             0.11061            m/s²
    delta_max   35° = 0.6109        rad                 0.6109             rad
    delta_rate  228°/min (3.8°/s)   rad/min             0.06632            rad/s
    ==========  ==================  ==================  =================  =======================

    Straight-running speed U = S/f = 0.25 nm/min = 7.7167 m/s (15 kn). The rudder limits feed
    :func:`rudder` and :meth:`MarinerWitOppe.input_limits`; the model itself does not clip δ.
    """

    a: float = _si("a")
    b: float = _si("b")
    c: float = _si("c")
    r1: float = _si("r1")
    r2: float = _si("r2")
    f: float = _si("f")
    W: float = _si("W")
    S: float = _si("S")
    delta_max: float = _si("delta_max")
    delta_rate: float = _si("delta_rate")

    def __post_init__(self) -> None:
        for fl in fields(self):
            value = getattr(self, fl.name)
            require(isinstance(value, (int, float)) and not isinstance(value, bool),
                    f"vessel.params.{fl.name}", value, "must be a number")
            require(math.isfinite(value), f"vessel.params.{fl.name}", value, "must be finite")
        require(self.b >= 0, "vessel.params.b", self.b, "cubic yaw damping must be >= 0 s")
        require(self.a > 0 or self.b > 0, "vessel.params.a", self.a,
                "a course-unstable ship (a <= 0) needs cubic yaw damping b > 0")
        require(self.c > 0, "vessel.params.c", self.c,
                "rudder gain must be > 0 1/s² (δ > 0 turns to starboard)")
        require(self.f > 0, "vessel.params.f", self.f, "surge damping must be > 0 1/s")
        require(self.S > 0, "vessel.params.S", self.S, "surge thrust must be > 0 m/s² (U = S/f > 0)")
        require(self.W >= 0, "vessel.params.W", self.W, "speed loss in turns must be >= 0 m/rad²")
        require(0 < self.delta_max <= math.pi / 2, "vessel.params.delta_max", self.delta_max,
                "need 0 < delta_max <= pi/2 rad (90°)")
        require(self.delta_rate > 0, "vessel.params.delta_rate", self.delta_rate,
                "rudder rate limit must be > 0 rad/s")

    @classmethod
    def from_paper_units(cls, **values: float) -> MarinerParams:
        """Parameters from the document's minute / nautical-mile / rad values (see the table).

        Omitted names take the document's values; e.g. ``from_paper_units(r1=+0.0375)`` is the
        sign-flipped sway coupling of note 000-0.5.
        """
        for key in values:
            if key not in PAPER_UNITS:
                raise ConfigError(f"vessel.params.{key}: unknown parameter; allowed: "
                                  f"{', '.join(PAPER_UNITS)}")
        merged = {**PAPER_VALUES, **values}
        return cls(**{name: merged[name] * factor for name, (_, factor) in PAPER_UNITS.items()})

    def to_paper_units(self) -> dict[str, float]:
        """The parameters in the document's units (inverse of :meth:`from_paper_units`)."""
        return {name: getattr(self, name) / factor for name, (_, factor) in PAPER_UNITS.items()}

    @property
    def U(self) -> float:
        """Straight-running speed S/f [m/s] (δ = 0, r = 0): 7.7167 m/s for the Mariner."""
        return self.S / self.f

    def sway(self, r):
        """Sway velocity v = r₁ r + r₂ r³ [m/s] at the CG for yaw rate ``r`` [rad/s] (arrays broadcast)."""
        return self.r1 * r + self.r2 * r**3



STATES = (
    Signal("north", "m", "north position (NED x)"),
    Signal("east", "m", "east position (NED y)"),
    Signal("psi", "rad", "heading, clockwise from north (unwrapped)", angle=True),
    Signal("u", "m/s", "surge velocity"),
    Signal("r", "rad/s", "yaw rate (bow to starboard)"),
)
INPUTS = (Signal("delta", "rad", "rudder angle, positive turns the bow to starboard", angle=True),)
DISTURBANCES = (
    Signal("b_r", "rad/s^2", "yaw acceleration disturbance (added to r_dot)"),
    Signal("current_north", "m/s", "current velocity, north component"),
    Signal("current_east", "m/s", "current velocity, east component"),
)


@dataclass(frozen=True)
class MarinerWitOppe:
    """De Wit–Oppe model (25) of the Mariner (see module docstring); sway v is algebraic."""

    params: MarinerParams = field(default_factory=MarinerParams)
    length: float = 160.93  #: drawing outline only [m] (Mariner class, L_pp)
    beam: float = 23.17  #: drawing outline only [m]

    states = STATES
    inputs = INPUTS
    disturbances = DISTURBANCES
    state_limits = (1e8, 1e8, 1e5, 100.0, 10.0)

    @classmethod
    def from_paper_units(cls, **values: float) -> MarinerWitOppe:
        """The model with :meth:`MarinerParams.from_paper_units` parameters."""
        return cls(params=MarinerParams.from_paper_units(**values))

    def input_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper bounds of ``[delta]`` (±delta_max)."""
        d = self.params.delta_max
        return np.array([-d]), np.array([d])

    def sway(self, r):
        """Sway velocity v = r₁ r + r₂ r³ [m/s] at the CG (v is not a state of this model)."""
        return self.params.sway(r)

    def derivatives(self, x, u, d=None):
        """ẋ of eq. (25) for ``x`` (..., 5), ``u`` (..., 1) = [δ], ``d`` (..., 3) or None: the batch
        of :func:`mariner_rhs`."""
        return kernel_derivatives(self, mariner_rhs, self._kernel_params, x, u, d)

    def state_jacobian(self, x, u, d=None):
        """A = ∂f/∂x of :meth:`derivatives` at (x, u, d), analytic: (..., 5, 5), A[..., i, j] =
        ∂ẋ_i/∂x_j (the batch of :func:`mariner_rhs_jacobian`); used by the EKF
        (:class:`~shipgnc.navigation.ekf.ExtendedKalmanFilter`) in place of central differences."""
        return kernel_jacobian(self, mariner_rhs_jacobian, self._kernel_params, x, u, d)

    @cached_property
    def _kernel_params(self) -> np.ndarray:
        """[a, b, c, r₁, r₂, f, W, S], the kernels' parameter array."""
        p = self.params
        return flat(p.a, p.b, p.c, p.r1, p.r2, p.f, p.W, p.S)

    def kernel(self) -> Kernel:
        """:meth:`derivatives` for the composed loop (:func:`mariner_rhs`)."""
        return Kernel(mariner_rhs, self._kernel_params)


@kernel_function
def mariner_rhs(x, u, d, p, xdot):
    """ẋ of eq. (25) for one ship (the one source of :meth:`MarinerWitOppe.derivatives`)::

        ẋ = u cos ψ − v sin ψ + c_N,   ẏ = u sin ψ + v cos ψ + c_E,   ψ̇ = r
        u̇ = −f u − W r² + S,   ṙ = −a r − b r³ + c δ + b_r,   v = r₁ r + r₂ r³

    (note 000-0.3, signs restored A3): the hull terms on u, v, r through the water, the current
    ``d[1:3]`` = (c_N, c_E) added to the kinematics only, ``d[0]`` = b_r (module docstring; a zero
    ``d`` adds nothing). r³ = r·r·r; ``p`` = [a, b, c, r₁, r₂, f, W, S]."""
    a, b, c_rudder, r1, r2, f, W, S = p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]
    psi, su, sr = x[2], x[3], x[4]
    r3 = sr * sr * sr  # a libm pow call per stage cost ≈ 40 % of the Mariner's step
    v = r1 * sr + r2 * r3
    c, s = math.cos(psi), math.sin(psi)
    xdot[0] = c * su - s * v + d[1]
    xdot[1] = s * su + c * v + d[2]
    xdot[2] = sr
    xdot[3] = -f * su - W * sr * sr + S
    xdot[4] = -a * sr - b * r3 + c_rudder * u[0] + d[0]


@kernel_function
def mariner_rhs_jacobian(x, u, d, p, A):
    """∂ẋ/∂x of :func:`mariner_rhs` for one ship into ``A`` (5 × 5, row-major flat); ``p`` as
    :func:`mariner_rhs`. Eq. (25) differentiated (δ and d enter additively); with
    v = r₁ r + r₂ r³, v' = r₁ + 3 r₂ r²::

        ∂(ẋ, ẏ)/∂ψ = (−u sin ψ − v cos ψ, u cos ψ − v sin ψ)
        ∂(ẋ, ẏ)/∂u = (cos ψ, sin ψ),   ∂(ẋ, ẏ)/∂r = (−v' sin ψ, v' cos ψ)
        ∂ψ̇/∂r = 1,   ∂u̇/∂(u, r) = (−f, −2 W r),   ∂ṙ/∂r = −a − 3 b r²

    Found by the composed loop's EKF by its name (:func:`shipgnc.navigation.kernels.jacobian_kernel`)."""
    a, b, r1, r2, f, W = p[0], p[1], p[3], p[4], p[5], p[6]
    psi, su, sr = x[2], x[3], x[4]
    v = r1 * sr + r2 * sr * sr * sr
    dv = r1 + 3.0 * r2 * sr * sr
    c, s = math.cos(psi), math.sin(psi)
    for i in range(25):
        A[i] = 0.0
    A[2] = -s * su - c * v
    A[3] = c
    A[4] = -s * dv
    A[5 + 2] = c * su - s * v
    A[5 + 3] = s
    A[5 + 4] = c * dv
    A[10 + 4] = 1.0
    A[15 + 3] = -f
    A[15 + 4] = -2.0 * W * sr
    A[20 + 4] = -a - 3.0 * b * sr * sr


def rudder(params: MarinerParams, *, rate_limit: bool = True, rate_mode: str = "ramp") -> Actuator:
    """The Mariner's steering machine: δ within ±delta_max slewing at most delta_rate (35°, 3.8°/s).

    ``rate_limit=False`` keeps only the saturation; ``rate_mode`` as in :class:`Actuator`.
    """
    p = params
    return Actuator(np.array([-p.delta_max]), np.array([p.delta_max]),
                    rate=[p.delta_rate if rate_limit else math.inf],
                    names=tuple(s.name for s in INPUTS), rate_mode=rate_mode)


def tracking_model(a: float, c: float, U: float) -> tuple[np.ndarray, np.ndarray]:
    """(A, B) of the design model (8)/(9), state [y_r, ψ_r, r, e_I], in the units of a, c, U
    (the LQR of :mod:`shipgnc.control.lqr` is designed on it)."""
    for name, value in (("a", a), ("c", c), ("U", U)):
        require(isinstance(value, (int, float, np.floating)) and np.isfinite(value),
                f"controller.{name}", value, "must be a finite number")
    require(c != 0, "controller.c", c, "the rudder must act on the yaw rate (c != 0)")
    A = np.array([[0.0, U, 0.0, 0.0],
                  [0.0, 0.0, 1.0, 0.0],
                  [0.0, 0.0, -a, 0.0],
                  [1.0, 0.0, 0.0, 0.0]])
    B = np.array([[0.0], [0.0], [c], [0.0]])
    return A, B


def linear_tracking_model(params: MarinerParams, *,
                          paper_units: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """(A, B) of the linear design model (8) for the state [y_r, ψ_r, r, e_I] and input δ::

        A = [[0, U, 0, 0], [0, 0, 1, 0], [0, 0, −a, 0], [1, 0, 0, 0]],   B = [0, 0, c, 0]ᵀ

    with U = S/f, sway neglected (eq. (7)). SI by default (m, rad, rad/s, m·s; s); with
    ``paper_units=True`` in the document's nm, rad, rad/min, nm·min (min), the units the printed
    LQR gain refers to (note 000-0.4). B has shape (4, 1).
    """
    values = params.to_paper_units() if paper_units else params.as_dict()
    return tracking_model(values["a"], values["c"], values["S"] / values["f"])


class MarinerDisturbance:
    """The disturbance vector ``[b_r, current_north, current_east]`` of note 000-0.6 (A9–A11).

    ``b_r`` [rad/s²] constant yaw acceleration; ``current`` a
    :class:`~shipgnc.environment.current.CrossCurrent` (d_y across the active leg, or along east)
    or None; ``waves`` a :class:`~shipgnc.environment.filtered_noise.SecondOrderNoise` added to ṙ
    or None; or any current field with ``__call__(t, x) -> (..., 2)`` (e.g. a
    :mod:`shipgnc.environment.fields` field, evaluated per RK stage). In the composed loop a field
    current needs ``current_kernel()`` → ``(field_velocity, params)`` (its compiled form,
    :meth:`shipgnc.environment.fields.CurrentField.current_kernel`).
    """

    def __init__(self, b_r: float = 0.0, current=None, waves=None):
        require(isinstance(b_r, (int, float)) and math.isfinite(b_r), "disturbance.b_r", b_r,
                "must be a finite yaw acceleration in rad/s^2")
        self.b_r, self.current, self.waves = float(b_r), current, waves

    @property
    def per_stage(self) -> bool:
        """Evaluated at every RK stage when the current is a field of position and time (a route's
        current, document 002); else sampled at each step's start and held."""
        return bool(getattr(self.current, "per_stage", False)) and self.waves is None

    def reset(self, batch_shape, rng: np.random.Generator) -> None:
        self._shape = tuple(batch_shape)
        if self.current is not None:
            self.current.reset(batch_shape, rng)
        if self.waves is not None:
            self.waves.reset(batch_shape, rng)

    def __call__(self, t: float, x: np.ndarray) -> np.ndarray:
        """d (..., 3) for a batch of ships: the batch of :func:`mariner_disturbance` (the path
        current's leg tracker handed back to the current's object); the waves' value drawn in numpy
        as the kernel's table row. A current written only in numpy (no kernel) is its own call."""
        x = np.asarray(x, dtype=float)
        shape = x.shape[:-1]
        own = self.current is not None and self._current_reason() is not None
        params, leg = self._kernel_parts(shape, with_current=not own)
        z = np.array(leg, dtype=float).reshape(-1, 1)
        w = (np.asarray(self.waves(t, x), dtype=float)[..., None] if self.waves is not None
             else np.zeros(1))
        d = per_ship(mariner_disturbance, "t i z p i o")(t, x, z, params, w, 3)
        if own:
            d[..., 1:] = self.current(t, x)
        elif params[1] == 2.0:
            self.current.tracker.leg = z[:, 0].astype(int).reshape(shape)
        return d

    def _current_reason(self) -> str | None:
        """Why the current has no kernel (None when it has one, or there is none)."""
        from shipgnc.environment.current import CrossCurrent

        if self.current is not None and type(self.current) is not CrossCurrent:
            try:
                _field_kernel(self.current)
            except NotCompiled as exc:
                return str(exc)
        return None

    def kernel_reason(self) -> str | None:
        """None when :meth:`kernel` covers this disturbance, else why not (the run then uses numpy)."""
        from shipgnc.environment.filtered_noise import SecondOrderNoise

        reason = self._current_reason()
        if reason:
            return reason
        if self.waves is not None:
            if type(self.waves) is not SecondOrderNoise:
                return f"waves {type(self.waves).__name__} have no kernel (only SecondOrderNoise)"
        return None

    def kernel(self, batch_shape, dt: float | None = None) -> Kernel:
        """:meth:`__call__` for the composed loop (:func:`mariner_disturbance`), after ``reset``.

        Per-ship state ``[leg]``: the path current's own leg tracker (A6), from the ship's position
        at each step's start. A current field (document 002) is its ``current_kernel()`` parameters,
        evaluated by :func:`~shipgnc.environment.fields.field_velocity` at the position and time it is
        called with (every RK stage when the disturbance is ``per_stage``). The wave noise does not
        depend on the state: ``table(k0, k1)`` asks the
        :class:`~shipgnc.environment.filtered_noise.SecondOrderNoise` itself for its values at
        t_k = k·``dt`` (``at_times``: the numpy loop's calls at once, to the bit; needs the run's
        step ``dt``), so it draws from the run's generator exactly as the numpy loop does (same
        seed, same sea) and the filter ends in the same state.
        """
        current, waves = self.current, self.waves
        shape = tuple(batch_shape)
        params, leg = self._kernel_parts(shape)  # raises NotCompiled for a field without a kernel
        mode = params[1]
        table, restore = None, None
        if waves is not None:
            if dt is None:
                raise NotCompiled("SecondOrderNoise waves need the run's step dt")

            def table(k0: int, k1: int) -> np.ndarray:  # the numpy loop's calls, t_k = k·dt
                values = waves.at_times(np.arange(k0, k1) * dt)
                return values.reshape(k1 - k0, -1, 1)

        if mode == 2:
            def restore(z: np.ndarray) -> None:
                current.tracker.leg = z[:, 0].astype(int).reshape(shape)

        return Kernel(mariner_disturbance, params, np.asarray(leg)[..., None], table=table,
                      n_table=int(waves is not None), restore=restore)


    def _kernel_parts(self, shape, with_current: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """(parameters of :func:`mariner_disturbance`, per-ship leg of the path current) for the
        batch ``shape``; ``with_current`` False: the yaw channel alone (zeros for the current)."""
        from shipgnc.environment.current import CrossCurrent

        current = self.current if with_current else None
        leg = np.zeros(shape)
        mode, d_y, i_north, i_east, legs = 0, 0.0, 0, 0, np.zeros(0)
        if current is not None and type(current) is not CrossCurrent:
            mode, legs = 3, _field_kernel(current)  # raises NotCompiled
        elif current is not None:
            d_y, (i_north, i_east) = current.d_y, current._i
            if current.frame == "global":
                mode = 1
            else:  # d_y·[−sin ψ_r0, cos ψ_r0] of each leg, as CrossCurrent.__call__ forms it
                mode, path = 2, current.tracker.path
                legs = flat(leg_table(path), -current.d_y * np.sin(path.leg_angles),
                            current.d_y * np.cos(path.leg_angles))
                require(current.tracker.leg is not None, "disturbance", "MarinerDisturbance",
                        "call reset(batch_shape, rng) first")
                leg = np.broadcast_to(current.tracker.leg, shape).astype(float)
        return flat(self.b_r, mode, d_y, i_north, i_east, self.waves is not None, legs), leg


class MarinerYawDisturbance(MarinerDisturbance):
    """The yaw channel of :class:`MarinerDisturbance` alone: ``[b_r (+ waves)]`` (..., 1), the
    force part of :class:`~shipgnc.environment.current_field.CurrentDisturbance` with ``n_force=1``
    when the current is a scenario's ``current`` section (an earth-fixed field object: uniform,
    Gauss–Markov, gridded), so the Mariner's current is filled by the same component, numpy and
    compiled, as the other vessels'. Its kernel is :func:`mariner_disturbance` without a current
    (it writes d[0] and zeros d[1:3], which the current's kernel then fills).

    Evaluated at every RK stage unless there are waves (a constant b_r is the same at each stage;
    the wave noise is held over each step, and the current with it)."""

    def __init__(self, b_r: float = 0.0, waves=None):
        super().__init__(b_r, current=None, waves=waves)

    @property
    def per_stage(self) -> bool:
        return self.waves is None

    def __call__(self, t: float, x: np.ndarray) -> np.ndarray:
        return super().__call__(t, x)[..., :1]


def _field_kernel(current) -> np.ndarray:
    """The ``current_kernel()`` parameters of a field current (for :func:`field_velocity`), or
    :class:`~shipgnc.kernels.NotCompiled` saying why it has none."""
    make = getattr(current, "current_kernel", None)
    if not callable(make):
        raise NotCompiled(f"current {type(current).__name__} has no kernel (only CrossCurrent or a "
                          "field with current_kernel())")
    function, params = make()
    if function is not field_velocity:
        raise NotCompiled(f"current {type(current).__name__}: its current_kernel() is not "
                          "shipgnc.environment.fields.field_velocity")
    return params


#: where :func:`mariner_disturbance` finds the path current's leg table (or the field's terms)
_LEGS = 6


@kernel_function
def mariner_disturbance(t, x, z, p, w, d):
    """:meth:`MarinerDisturbance.__call__` for one ship: d = [b_r (+ w, the step's wave value),
    current_north, current_east] (notes 000-0.6, 000-A9–000-A11); the path current d_y·[−sin ψ_r0,
    cos ψ_r0] of the leg its tracker ``z[0]`` finds (A10, A6), or a current field (document 002) at
    (t, x[0], x[1]). ``p`` = [b_r, mode (0 none, 1 global, 2 path, 3 field), d_y, north index,
    east index, has waves, then the leg table, c_N, c_E per leg (mode 2) or the field's terms
    (mode 3)]."""
    yaw = p[0]
    if p[5] != 0.0:
        yaw = yaw + w[0]
    d[0] = yaw
    mode = p[1]
    if mode == 0.0:
        d[1] = 0.0
        d[2] = 0.0
    elif mode == 1.0:  # along east
        d[1] = 0.0
        d[2] = 0.0 + p[2]
    elif mode == 3.0:  # a routing field: velocity(t, north, east)
        vn, ve = field_velocity(t, x[0], x[1], p, _LEGS)
        d[1] = vn
        d[2] = ve
    else:
        leg, _, _ = track_leg(x[int(p[3])], x[int(p[4])], int(z[0]), p, _LEGS)
        z[0] = leg
        n = int(p[_LEGS])
        d[1] = p[_LEGS + 1 + 6 * n + leg]
        d[2] = p[_LEGS + 1 + 7 * n + leg]
