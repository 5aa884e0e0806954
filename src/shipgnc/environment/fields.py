"""Current fields v(x, t) in NED, SI (note 002-2.9.1).

One protocol serves the router and the simulation loop:

* ``velocity(t, north, east) -> (..., 2)``: the water's velocity over ground (v_N, v_E) [m/s];
* ``jacobian(t, north, east) -> (..., 2, 2)``: J[i, j] = ∂v_i/∂x_j [1/s], used by the costate
  equation (2.3) and the heading rate (2.5);
* ``__call__(t, x)`` with ``x[..., 0]`` north and ``x[..., 1]`` east, plus ``per_stage = True`` and
  ``reset``: the disturbance protocol of :mod:`shipgnc.environment.disturbance`, so the same object is a
  ship's current, evaluated at every RK stage.

``north`` and ``east`` broadcast against each other (leading batch axes); ``t`` is a scalar or broadcasts
too. Positive ω and Γ turn clockwise on a north-up chart (positive about NED's down axis).

**One source.** Each field's equations are written once, as a term of the scalar kernel
:func:`field_state` (velocity and Jacobian of one point); ``velocity`` and ``jacobian`` of every field
that has a compiled form are the batch over points of that kernel (:func:`field_point`,
:func:`shipgnc.derive.per_ship`), and ``current_kernel(t0=0.0)`` → ``(field_velocity, params)`` hands the
same kernel to the composed loop (:mod:`shipgnc.kernels`) and the router's extremals. Uniform, affine
(shear), rigid-rotation, Lamb–Oseen and Rankine fields, the double gyre, bilinear gridded data, their
sums and a :class:`Modulated` factor over them have it; a factor over a factor and bicubic gridded data
have not (they are evaluated in numpy: the factor times the field, scipy's spline). ``current_kernel``
raises :class:`~shipgnc.kernels.NotCompiled` for gridded data unless asked for with ``grids=True`` (the
router, which watches the domain itself; a ship's current off its grid must raise, so a ship's gridded
current stays in the numpy loop, whose ``velocity`` checks the domain before the batch).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from shipgnc.errors import ConfigError, require
from shipgnc.kernels import JIT_OPTIONS, NotCompiled, flat, kernel_function
from shipgnc.units import KNOT

__all__ = [
    "AffineCurrent",
    "CurrentField",
    "DoubleGyre",
    "FieldDomainError",
    "GriddedCurrent",
    "LambOseenVortex",
    "Modulated",
    "NumpyReference",
    "RankineVortex",
    "RigidRotation",
    "SumField",
    "UniformCurrent",
    "sample_field",
    "shear",
]


class FieldDomainError(ConfigError):
    """A gridded field was queried outside its grid (note 002-F9); the message names point and extent."""


def _finite(value, field: str) -> float:
    require(isinstance(value, (int, float, np.floating, np.integer)) and math.isfinite(float(value)),
            field, value, "must be a finite number")
    return float(value)


def _shape(t, north, east):
    return np.broadcast_shapes(np.shape(t), np.shape(north), np.shape(east))


class CurrentField:
    """Base class: a steady or time-varying current field (see the module docstring)."""

    per_stage = True
    steady = True
    #: ((north_min, north_max), (east_min, east_max)) for gridded data, else None
    bounds: tuple[tuple[float, float], tuple[float, float]] | None = None

    def velocity(self, t, north, east) -> np.ndarray:
        """(v_N, v_E) (..., 2) [m/s]: the batch of :func:`field_point` over the points."""
        return self._batch(t, north, east)[..., :2]

    def jacobian(self, t, north, east) -> np.ndarray:
        """J[i, j] = ∂v_i/∂x_j (..., 2, 2) [1/s]: the batch of :func:`field_point`."""
        out = self._batch(t, north, east)
        return out[..., 2:].reshape(*out.shape[:-1], 2, 2)

    def describe(self) -> str:
        return type(self).__name__

    # --- unchecked evaluation (used inside integrators that handle the domain themselves) ---
    def _velocity(self, t, north, east) -> np.ndarray:
        return self.velocity(t, north, east)

    def _jacobian(self, t, north, east) -> np.ndarray:
        return self.jacobian(t, north, east)

    def compiled(self) -> bool:
        """Whether this field has a compiled form (its ``velocity`` is the kernel's batch)."""
        return self._params() is not None

    def _params(self):
        """This field's terms for :func:`field_state` (gridded data included), made once; None
        without a compiled form."""
        params = self.__dict__.get("_compiled_params", ())
        if isinstance(params, tuple):
            try:
                params = self.current_kernel(grids=True)[1]
            except NotCompiled:
                params = None
            object.__setattr__(self, "_compiled_params", params)  # frozen dataclasses too
        return params

    def _batch(self, t, north, east) -> np.ndarray:
        """(v_N, v_E, J₀₀, J₀₁, J₁₀, J₁₁) (..., 6) at every point: the batch of
        :func:`field_point` (gridded data clamped to the grid, as ``_velocity``)."""
        from shipgnc.derive import per_ship

        params = self._params()
        if params is None:
            raise NotCompiled(f"current {type(self).__name__} has no compiled form")
        shape = _shape(t, north, east)
        t, north, east = (np.asarray(a, dtype=float)[..., None] for a in (t, north, east))
        return per_ship(field_point, "i i i p o")(t, north, east, params, 6).reshape(*shape, 6)

    # --- disturbance protocol (shipgnc.environment.disturbance) ---
    def reset(self, batch_shape=(), rng=None) -> None:
        """Nothing to reset: a field is a pure function of (t, x)."""

    def __call__(self, t, x) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        return self.velocity(t, x[..., 0], x[..., 1])

    def __add__(self, other: CurrentField) -> SumField:
        return SumField([self, other])

    # --- compiled form (module docstring) ---
    def _terms(self, grids: bool = False) -> list[tuple]:
        """``[(code, numbers[, data])]``: this field as terms of :func:`field_state` (one here); a gridded
        term carries its grid as ``data`` (only with ``grids``, see :meth:`current_kernel`)."""
        raise NotCompiled(f"current {type(self).__name__} has no kernel (no compiled form)")

    def current_kernel(self, t0: float = 0.0, grids: bool = False):
        """``(field_velocity, params)``: :func:`field_velocity` (and :func:`field_state`, which adds the
        Jacobian) evaluates this field at ``t0 + t`` from ``params``; raises
        :class:`~shipgnc.kernels.NotCompiled` for a field without a compiled form.

        ``grids=True`` compiles gridded data too, clamped at the grid's edge like the unchecked
        ``_velocity``: for integrators that watch the domain themselves (the router's). A ship's
        current leaves it off, so a query off the grid raises :class:`FieldDomainError` (numpy loop)."""
        terms, tails, raw = [], [], self._terms(grids)
        offset = 2 + _TERM * len(raw)  # where the first term's data starts, counted from o
        for code, numbers, *data in raw:
            numbers = tuple(float(v) for v in numbers)
            if data:
                numbers = (*numbers[:3], float(offset), *numbers[4:])
                tails.append(data[0])
                offset += data[0].size
            terms.append(flat(code, numbers, np.zeros(_TERM - 1 - len(numbers))))
        return field_velocity, flat(float(t0), len(terms), *terms, *tails)

    def rate_bound(self) -> float:
        """An upper bound [1/s] of the Jacobian's Frobenius norm ‖∂v/∂x‖ over space and time: the
        rate at which the current turns an extremal's heading and costate (2.3, 2.5); it sets the
        router's fixed integration step (:mod:`shipgnc.routing.extremal_kernels`)."""
        raise NotCompiled(f"current {type(self).__name__} has no rate bound")

    def grid_cell(self) -> float:
        """The smallest grid spacing [m] of gridded data in this field (``inf`` for analytic fields)."""
        return math.inf

    def max_speed(self, bounds, t=0.0, n: int = 81) -> float:
        """Largest |v| [m/s] sampled on an n×n grid over ``bounds`` (a CFL and scale estimate)."""
        (n0, n1), (e0, e1) = bounds
        nn, ee = np.meshgrid(np.linspace(n0, n1, n), np.linspace(e0, e1, n), indexing="ij")
        with np.errstate(over="ignore", invalid="ignore"):  # an absurd field: inf, said by the caller
            return float(np.max(np.linalg.norm(self._velocity(t, nn, ee), axis=-1)))


@dataclass(frozen=True)
class UniformCurrent(CurrentField):
    """A uniform current c₀ = (north, east) [m/s] (notes 002-2.9.1, 002-2.10)."""

    north: float = 0.0
    east: float = 0.0

    def __post_init__(self):
        _finite(self.north, "current.north")
        _finite(self.east, "current.east")

    def describe(self):
        return f"uniform current ({self.north:.6g}, {self.east:.6g}) m/s"

    def _terms(self, grids=False):
        return [(_UNIFORM, (self.north, self.east))]

    def rate_bound(self):
        return 0.0


@dataclass(frozen=True)
class AffineCurrent(CurrentField):
    """v = v₀ + G (x − x_ref) (note 002-2.9.1); the document's shear is G = [[0, 0], [k, 0]] (note
    002-2.5)."""

    v0: tuple[float, float] = (0.0, 0.0)
    gradient: tuple[tuple[float, float], tuple[float, float]] = ((0.0, 0.0), (0.0, 0.0))
    ref: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self):
        for name, value in (("v0", self.v0), ("gradient", self.gradient), ("ref", self.ref)):
            arr = np.asarray(value, dtype=float)
            require(bool(np.all(np.isfinite(arr))), f"current.{name}", value, "must be finite")

    def describe(self):
        g = np.asarray(self.gradient)
        if np.allclose([g[0, 0], g[0, 1], g[1, 1], *self.v0], 0.0):
            return f"shear v_E = k·(x_N − {self.ref[0]:g} m), k = {g[1, 0]:.6g} 1/s"
        return f"affine current v0 = {tuple(self.v0)} m/s, G = {g.tolist()} 1/s"

    def rate_bound(self):
        return math.hypot(*np.asarray(self.gradient, float).ravel())  # Frobenius, free of overflow

    def _terms(self, grids=False):
        g = np.asarray(self.gradient, dtype=float)
        return [(_AFFINE, (self.v0[0], self.v0[1], g[0, 0], g[0, 1], g[1, 0], g[1, 1], self.ref[0],
                           self.ref[1]))]


def shear(k: float, s: float = 0.0) -> AffineCurrent:
    """The document's linear shear v = (0, k (x_N − s)) [k in 1/s, s in m] (note 002-2.5)."""
    _finite(k, "shear.k")
    return AffineCurrent((0.0, 0.0), ((0.0, 0.0), (float(k), 0.0)), (float(s), 0.0))


@dataclass(frozen=True)
class RigidRotation(CurrentField):
    """Rigid rotation ω [rad/s] about ``centre`` (north, east) [m]: v = ω (−r_E, r_N), clockwise for ω > 0."""

    omega: float
    centre: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self):
        _finite(self.omega, "rotation.omega")

    def describe(self):
        return f"rigid rotation ω = {self.omega:.6g} rad/s about {tuple(self.centre)} m"

    def _terms(self, grids=False):
        return [(_ROTATION, (self.omega, self.centre[0], self.centre[1]))]

    def rate_bound(self):
        return math.sqrt(2.0) * abs(self.omega)


class _Vortex(CurrentField):
    """Axisymmetric vortex v = f(q)·(−r_E, r_N), q = r², with tangential speed v_t = r f(q)."""

    gamma: float
    rc: float
    centre: tuple[float, float]

    def _check(self, name):
        _finite(self.gamma, f"{name}.gamma")
        require(_finite(self.rc, f"{name}.rc") > 0, f"{name}.rc", self.rc, "core radius must be > 0 m")
        for k, value in enumerate(self.drift):
            _finite(value, f"{name}.drift[{k}]")

    def _where(self) -> str:
        moving = "" if self.steady else f", drifting at {tuple(self.drift)} m/s"
        return f"at {tuple(self.centre)} m{moving}"

    @property
    def steady(self) -> bool:
        return self.drift[0] == 0.0 and self.drift[1] == 0.0

    def centre_at(self, t):
        """The centre at time t [s]: ``centre + drift·t`` (north, east) [m], each broadcast with t."""
        t = np.asarray(t, float)
        return self.centre[0] + self.drift[0] * t, self.centre[1] + self.drift[1] * t

    def tangential_speed(self, r):
        """v_t(r) [m/s] at radii ``r`` [m] from the centre (at t = 0): the velocity's east
        component on the ray due north."""
        r = np.asarray(r, dtype=float)
        return self.velocity(0.0, self.centre[0] + r, self.centre[1])[..., 1]

    def rate_bound(self):
        # ‖J‖ depends on r alone and decays as 1/r² outside the core: its peak lies within a few r_c
        # (at r = 0 for Lamb–Oseen, anywhere in the core for Rankine); sampled 4 000 radii to 20 r_c
        r = np.linspace(0.0, 20.0 * self.rc, 4001)
        j = self.jacobian(0.0, self.centre[0] + r, self.centre[1])  # on the ray due north
        return float(np.max(np.sqrt(np.sum(j * j, axis=(-2, -1)))))


@dataclass(frozen=True)
class LambOseenVortex(_Vortex):
    """Lamb–Oseen vortex v_t = Γ/(2πr)·(1 − exp(−r²/r_c²)) [Γ in m²/s, r_c in m] (note 002-2.9.1)."""

    gamma: float
    rc: float
    centre: tuple[float, float] = (0.0, 0.0)
    drift: tuple[float, float] = (0.0, 0.0)  #: velocity of the centre [m/s] (a moving vortex)

    def __post_init__(self):
        self._check("lamb-oseen")

    def describe(self):
        return f"Lamb–Oseen vortex Γ = {self.gamma:.6g} m²/s, r_c = {self.rc:.6g} m {self._where()}"

    def _terms(self, grids=False):  # a = Γ/2π and c = r_c² as _f forms them
        return [(_LAMB_OSEEN, (self.gamma / (2 * math.pi), self.rc**2, *self.centre, *self.drift))]


@dataclass(frozen=True)
class RankineVortex(_Vortex):
    """Rankine vortex: v_t = Γr/(2πr_c²) inside r_c, Γ/(2πr) outside; its Jacobian jumps at r_c."""

    gamma: float
    rc: float
    centre: tuple[float, float] = (0.0, 0.0)
    drift: tuple[float, float] = (0.0, 0.0)  #: velocity of the centre [m/s] (a moving vortex)

    def __post_init__(self):
        self._check("rankine")

    def describe(self):
        return f"Rankine vortex Γ = {self.gamma:.6g} m²/s, r_c = {self.rc:.6g} m {self._where()}"

    def _terms(self, grids=False):
        return [(_RANKINE, (self.gamma / (2 * math.pi), self.rc**2, *self.centre, *self.drift))]


@dataclass(frozen=True)
class DoubleGyre(CurrentField):
    """The steady double gyre, a classic test of routing in a current (e.g. Lolla et al. 2014):

        v_N = −U sin(π e′/L) cos(π n′/L),  v_E = U cos(π e′/L) sin(π n′/L),
        n′ = north − centre_N,  e′ = east − centre_E,

    cells of size L [m] turning alternately, speed up to U [m/s], divergence-free."""

    speed: float
    length: float
    centre: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self):
        _finite(self.speed, "gyre.speed")
        require(_finite(self.length, "gyre.length") > 0, "gyre.length", self.length, "must be > 0 m")

    def rate_bound(self):
        return math.sqrt(2.0) * abs(self.speed) * math.pi / self.length

    def describe(self):
        return f"double gyre U = {self.speed:.6g} m/s, L = {self.length:.6g} m about {tuple(self.centre)} m"

    def _terms(self, grids=False):
        return [(_GYRE, (self.speed, math.pi / self.length, *self.centre))]


class SumField(CurrentField):
    """The sum of several fields (note 002-2.9.1)."""

    def __init__(self, fields):
        flat = []
        for f in fields:
            require(isinstance(f, CurrentField), "field", f, "must be a CurrentField")
            flat.extend(f.fields if isinstance(f, SumField) else [f])
        require(len(flat) > 0, "field", fields, "a sum needs at least one field")
        self.fields = tuple(flat)
        self.steady = all(f.steady for f in flat)
        boxes = [f.bounds for f in flat if f.bounds is not None]
        if boxes:
            self.bounds = ((max(b[0][0] for b in boxes), min(b[0][1] for b in boxes)),
                           (max(b[1][0] for b in boxes), min(b[1][1] for b in boxes)))

    # the batch of the terms' kernel when every term has one and none is gridded (whose
    # velocity checks its domain first); else the sum of the fields' own evaluations
    def velocity(self, t, north, east):
        if self.bounds is None and self.compiled():
            return super().velocity(t, north, east)
        return sum(f.velocity(t, north, east) for f in self.fields)

    def jacobian(self, t, north, east):
        if self.bounds is None and self.compiled():
            return super().jacobian(t, north, east)
        return sum(f.jacobian(t, north, east) for f in self.fields)

    def _velocity(self, t, north, east):
        if self.compiled():
            return super().velocity(t, north, east)
        return sum(f._velocity(t, north, east) for f in self.fields)

    def _jacobian(self, t, north, east):
        if self.compiled():
            return super().jacobian(t, north, east)
        return sum(f._jacobian(t, north, east) for f in self.fields)

    def describe(self):
        return " + ".join(f.describe() for f in self.fields)

    def _terms(self, grids=False):
        return [term for f in self.fields for term in f._terms(grids)]

    def rate_bound(self):
        return sum(f.rate_bound() for f in self.fields)

    def grid_cell(self):
        return min(f.grid_cell() for f in self.fields)


class NumpyReference(CurrentField):
    """``field`` without its compiled form: the router integrates it on the numpy reference path (the
    numpy family and the ``solve_ivp`` polish of :mod:`~shipgnc.routing.pmp`) — to hold the compiled
    integrations equal to it, or to time the two side by side. The sweep's seed refinement and the
    polish's coarse first phase belong to the compiled path only, so two sweeps may polish different
    seeds and find different local extremals (the optimum agrees)."""

    def __init__(self, field: CurrentField):
        require(isinstance(field, CurrentField), "field", field, "must be a CurrentField")
        self.field, self.steady, self.bounds = field, field.steady, field.bounds

    def velocity(self, t, north, east):
        return self.field.velocity(t, north, east)

    def jacobian(self, t, north, east):
        return self.field.jacobian(t, north, east)

    def _velocity(self, t, north, east):
        return self.field._velocity(t, north, east)

    def _jacobian(self, t, north, east):
        return self.field._jacobian(t, north, east)

    def describe(self):
        return f"{self.field.describe()} (numpy reference path)"


class Modulated(CurrentField):
    """A field scaled in time: v(x, t) = m(t)·w(x), m(t) = mean + amplitude·cos(2πt/period + phase).

    The tidal uniform current of note 002-2.9.5 is ``Modulated(UniformCurrent(0, c), 0, 1, T, φ)``; its
    tidally modulated shear k(t) = k(1 + 0.5 sin(2πt/T)) is ``Modulated(shear(k), 1, 0.5, T, −π/2)``.
    """

    steady = False

    def __init__(self, field: CurrentField, mean: float = 1.0, amplitude: float = 0.0,
                 period: float = 12.42 * 3600.0, phase: float = 0.0):
        require(isinstance(field, CurrentField), "field", field, "must be a CurrentField")
        self.field = field
        self.mean, self.amplitude = _finite(mean, "tide.mean"), _finite(amplitude, "tide.amplitude")
        require(_finite(period, "tide.period") > 0, "tide.period", period, "must be > 0 s")
        self.period, self.phase = float(period), _finite(phase, "tide.phase")
        self.bounds = field.bounds

    def factor(self, t):
        w = 2 * np.pi / self.period
        return self.mean + self.amplitude * np.cos(w * np.asarray(t, float) + self.phase)

    def factor_integral(self, t0, t1):
        """∫_{t0}^{t1} m(t) dt [s] (closed form)."""
        w = 2 * np.pi / self.period
        return (self.mean * (t1 - t0)
                + self.amplitude / w * (np.sin(w * t1 + self.phase) - np.sin(w * t0 + self.phase)))

    # the batch of the kernel (the factor is part of each term) when the field has one and is not
    # gridded (whose velocity checks its domain first); else the factor times the field's own
    # evaluation (a factor over a factor)
    def velocity(self, t, north, east):
        if self.bounds is None and self.compiled():
            return super().velocity(t, north, east)
        return np.asarray(self.factor(t))[..., None] * self.field.velocity(t, north, east)

    def jacobian(self, t, north, east):
        if self.bounds is None and self.compiled():
            return super().jacobian(t, north, east)
        return np.asarray(self.factor(t))[..., None, None] * self.field.jacobian(t, north, east)

    def _velocity(self, t, north, east):
        if self.compiled():
            return super().velocity(t, north, east)
        return np.asarray(self.factor(t))[..., None] * self.field._velocity(t, north, east)

    def _jacobian(self, t, north, east):
        if self.compiled():
            return super().jacobian(t, north, east)
        return np.asarray(self.factor(t))[..., None, None] * self.field._jacobian(t, north, east)

    def describe(self):
        return (f"({self.field.describe()}) × ({self.mean:g} + {self.amplitude:g}·cos(2πt/"
                f"{self.period:g} s + {self.phase:g}))")

    def _terms(self, grids=False):
        # m(t)·(w₁ + w₂ + …) as m(t)·w₁ + m(t)·w₂ + … (the same up to round-off)
        terms = []
        for code, numbers, *data in self.field._terms(grids):
            if code >= _MODULATED:
                raise NotCompiled("a tidal factor over a tidal factor has no compiled form")
            terms.append((code + _MODULATED, (*numbers, *[0.0] * (_FACTOR - len(numbers)),
                                              self.mean, self.amplitude, 2 * np.pi / self.period,
                                              self.phase), *data))
        return terms

    def rate_bound(self):
        return (abs(self.mean) + abs(self.amplitude)) * self.field.rate_bound()

    def grid_cell(self):
        return self.field.grid_cell()


#: velocity units of a current file [unit text, lower case, single spaces → factor to m/s]: the UDUNITS
#: spellings of m/s (CF's canonical "m s-1"), cm/s and knots
VELOCITY_UNITS = {"m/s": 1.0, "m s-1": 1.0, "m s^-1": 1.0, "m s**-1": 1.0, "m.s-1": 1.0,
                  "meter second-1": 1.0, "meters/second": 1.0, "meter/second": 1.0, "metre/second": 1.0,
                  "metres/second": 1.0, "meters per second": 1.0, "ms-1": 1.0, "m/sec": 1.0,
                  "cm/s": 0.01, "cm s-1": 0.01, "cm s^-1": 0.01, "cm s**-1": 0.01, "cm.s-1": 0.01,
                  "centimeter/second": 0.01, "centimeters/second": 0.01, "centimeter second-1": 0.01,
                  "kn": KNOT, "knot": KNOT, "knots": KNOT, "kt": KNOT, "kts": KNOT}


def velocity_factor(units, where: str) -> float:
    """The factor to m/s of a current variable's ``units`` attribute. CF requires ``units`` on every
    dimensional variable (CF conventions §3.1): a velocity without it is refused, not guessed as m/s, and
    so is a unit outside :data:`VELOCITY_UNITS`; ``where`` names the file and the variable."""
    text = "" if units is None else str(units).strip()
    if not text:
        raise ConfigError(f"{where} has no units attribute: CF requires one (e.g. units = 'm s-1'); "
                          "add it rather than let the current be guessed in m/s")
    key = " ".join(text.lower().split())
    if key not in VELOCITY_UNITS:
        raise ConfigError(f"{where} has units {text!r}; allowed: m/s, cm/s, knots (and CF spellings such "
                          "as 'm s-1')")
    return VELOCITY_UNITS[key]


class GriddedCurrent(CurrentField):
    """Gridded data (note 002-2.9.1): an ``xarray.Dataset`` with ``current_north`` and ``current_east``
    [m/s] on coordinates ``north`` and ``east`` [m], optionally ``time`` [s].

    ``method="linear"`` interpolates bilinearly (exact for affine fields), ``"cubic"`` with a bicubic spline
    (scipy's ``RectBivariateSpline``); the Jacobian is the derivative of the same interpolant. In time the
    data is interpolated linearly. A query outside the grid raises :class:`FieldDomainError`, never
    extrapolates (F9).
    """

    def __init__(self, dataset, method: str = "linear"):
        require(method in ("linear", "cubic"), "field.method", method, "allowed: linear, cubic")
        for name in ("current_north", "current_east"):
            require(name in dataset.data_vars, "field.dataset", sorted(dataset.data_vars),
                    f"needs a variable {name!r} [m/s]")
        for name in ("north", "east"):
            require(name in dataset.coords, "field.dataset", sorted(dataset.coords),
                    f"needs a coordinate {name!r} [m]")
        self.method = method
        has_time = "time" in dataset.dims
        order = (("time",) if has_time else ()) + ("north", "east")
        vn = dataset["current_north"].transpose(*order).values.astype(float)
        ve = dataset["current_east"].transpose(*order).values.astype(float)
        self.n = np.asarray(dataset["north"].values, float)
        self.e = np.asarray(dataset["east"].values, float)
        for name, axis in (("north", self.n), ("east", self.e)):
            require(axis.size >= (4 if method == "cubic" else 2) and bool(np.all(np.diff(axis) > 0)),
                    f"field.{name}", f"{axis.size} values",
                    "must increase strictly, at least 2 (4 for cubic)")
        require(bool(np.all(np.isfinite(vn)) and np.all(np.isfinite(ve))), "field.current", "NaN/inf",
                "gridded current values must be finite")
        if has_time:
            self.times = np.asarray(dataset["time"].values, float)
            require(bool(np.all(np.diff(self.times) > 0)), "field.time", self.times.size,
                    "must increase strictly")
            self.steady = self.times.size == 1
        else:
            self.times = np.zeros(1)
            vn, ve = vn[None], ve[None]
        self.data = np.stack([vn, ve], axis=-1)  # (time, north, east, 2)
        self.bounds = ((float(self.n[0]), float(self.n[-1])), (float(self.e[0]), float(self.e[-1])))
        self._splines = None
        if method == "cubic":
            from scipy.interpolate import RectBivariateSpline

            self._splines = [[RectBivariateSpline(self.n, self.e, self.data[k, :, :, c], kx=3, ky=3)
                              for c in range(2)] for k in range(self.times.size)]

    @classmethod
    def from_netcdf(cls, path, method: str = "linear") -> GriddedCurrent:
        import xarray as xr

        try:
            with xr.open_dataset(path) as ds:
                ds.load()
        except (OSError, ValueError) as exc:
            raise ConfigError(f"field = {str(path)!r}: cannot read as NetCDF ({exc})") from None
        for name in ("current_north", "current_east"):  # in m/s from the file's units (CF)
            if name in ds.data_vars:
                factor = velocity_factor(ds[name].attrs.get("units"), f"field = {str(path)!r}: {name}")
                ds[name] = ds[name] * factor
        return cls(ds, method)

    def describe(self):
        (n0, n1), (e0, e1) = self.bounds
        return (f"gridded current ({self.method}) on N [{n0:g}, {n1:g}] m × E [{e0:g}, {e1:g}] m, "
                f"{self.n.size}×{self.e.size} points")

    def contains(self, north, east):
        (n0, n1), (e0, e1) = self.bounds
        north, east = np.asarray(north), np.asarray(east)
        return (north >= n0) & (north <= n1) & (east >= e0) & (east <= e1)

    def _check_domain(self, north, east):
        inside = self.contains(north, east)
        if not np.all(inside):
            nn, ee = np.broadcast_arrays(np.asarray(north, float), np.asarray(east, float))
            k = np.flatnonzero(~np.broadcast_to(inside, nn.shape))[0]
            (n0, n1), (e0, e1) = self.bounds
            raise FieldDomainError(
                f"field query at (north, east) = ({nn.flat[k]:.6g}, {ee.flat[k]:.6g}) m: outside the gridded "
                f"field's extent N [{n0:g}, {n1:g}] m × E [{e0:g}, {e1:g}] m (no extrapolation)")

    def velocity(self, t, north, east):
        self._check_domain(north, east)
        return self._velocity(t, north, east)

    def jacobian(self, t, north, east):
        self._check_domain(north, east)
        return self._jacobian(t, north, east)

    def _velocity(self, t, north, east):
        if self._splines is None:
            return super().velocity(t, north, east)
        return self._eval(t, north, east, deriv=False)

    def _jacobian(self, t, north, east):
        if self._splines is None:
            return super().jacobian(t, north, east)
        return self._eval(t, north, east, deriv=True)

    def _eval(self, t, north, east, deriv):
        """The bicubic spline's value or gradient, linear in time between slices."""
        shape = _shape(t, north, east)
        (n0, n1), (e0, e1) = self.bounds
        nn = np.clip(np.broadcast_to(np.asarray(north, float), shape), n0, n1).ravel()
        ee = np.clip(np.broadcast_to(np.asarray(east, float), shape), e0, e1).ravel()
        tt = np.broadcast_to(np.asarray(t, float), shape).ravel()
        if self.times.size == 1:
            out = self._slice(0, nn, ee, deriv)
        else:
            k = np.clip(np.searchsorted(self.times, tt, side="right") - 1, 0, self.times.size - 2)
            w = np.clip((tt - self.times[k]) / (self.times[k + 1] - self.times[k]), 0.0, 1.0)
            out = np.empty((nn.size, 2, 2) if deriv else (nn.size, 2))
            for kk in np.unique(k):
                m = k == kk
                ww = w[m].reshape((-1,) + (1,) * (out.ndim - 1))
                out[m] = ((1 - ww) * self._slice(kk, nn[m], ee[m], deriv)
                          + ww * self._slice(kk + 1, nn[m], ee[m], deriv))
        return out.reshape((*shape, 2, 2) if deriv else (*shape, 2))

    def _terms(self, grids=False):
        if not grids:
            raise NotCompiled("current GriddedCurrent has no kernel for a ship (a query off its grid must "
                              "raise, so the simulation keeps it in numpy)")
        if self._splines is not None:
            raise NotCompiled("current GriddedCurrent (cubic) has no kernel: the bicubic spline")
        sizes = (self.times.size, self.n.size, self.e.size)
        data = np.concatenate([self.times, self.n, self.e, self.data.ravel()])
        return [(_GRIDDED, (*sizes, 0.0), data)]  # the 0 becomes the data's offset (current_kernel)

    def rate_bound(self):
        # the bilinear Jacobian is linear in each cell's coordinates: its entries peak at the cell edges
        dn = np.abs(np.diff(self.data, axis=1)) / np.diff(self.n)[None, :, None, None]
        de = np.abs(np.diff(self.data, axis=2)) / np.diff(self.e)[None, None, :, None]
        return float(math.sqrt(2.0 * (np.max(dn) ** 2 + np.max(de) ** 2)))

    def grid_cell(self):
        return float(min(np.min(np.diff(self.n)), np.min(np.diff(self.e))))

    def _slice(self, k, nn, ee, deriv):
        """Time slice ``k`` at the points (nn, ee) clamped to the grid: the bilinear kernel's batch
        at t = times[k] (its time weight is exactly 0 or 1 there), or the bicubic spline."""
        if self._splines is None:
            return (self._jacobian if deriv else self._velocity)(self.times[k], nn, ee)
        sp = self._splines[k]
        if not deriv:
            return np.stack([sp[c].ev(nn, ee) for c in range(2)], axis=-1)
        return np.stack([np.stack([sp[c].ev(nn, ee, dx=1), sp[c].ev(nn, ee, dy=1)], axis=-1)
                         for c in range(2)], axis=-2)


# ----------------------------------------------------------------------------------------------
# compiled form: one point of a field from its terms (CurrentField.current_kernel)
# ----------------------------------------------------------------------------------------------

#: term codes of :func:`field_state`; a :class:`Modulated` term adds ``_MODULATED`` to its code
_UNIFORM, _AFFINE, _ROTATION, _LAMB_OSEEN, _RANKINE, _GRIDDED, _GYRE, _MODULATED = 1, 2, 3, 4, 5, 6, 7, 8
#: numbers per term (code first), and where among a term's numbers a modulated term's factor
#: [mean, amplitude, ω = 2π/period, phase] starts
_TERM, _FACTOR = 13, 8


@kernel_function
def _cell(p, start, size, x):
    """``searchsorted(axis, x, side="right") − 1`` clipped to [0, size − 2] for the axis
    ``p[start:start + size]`` (increasing): the cell holding ``x``, by bisection."""
    lo = 0
    hi = size
    while lo < hi:
        mid = (lo + hi) // 2
        if p[start + mid] <= x:
            lo = mid + 1
        else:
            hi = mid
    return min(max(lo - 1, 0), size - 2)


@kernel_function
def _bilinear(p, base, k, nt, nn, ne, north, east):
    """One time slice ``k`` of gridded data at a point clamped to the grid, and its Jacobian, as
    :meth:`GriddedCurrent._slice` forms them: (v_N, v_E, ∂v_N/∂n, ∂v_N/∂e, ∂v_E/∂n, ∂v_E/∂e)."""
    sn = base + nt
    se = sn + nn
    x = min(max(north, p[sn]), p[sn + nn - 1])
    y = min(max(east, p[se]), p[se + ne - 1])
    i = _cell(p, sn, nn, x)
    j = _cell(p, se, ne, y)
    axn0, axn1, axe0, axe1 = p[sn + i], p[sn + i + 1], p[se + j], p[se + j + 1]
    hn = axn1 - axn0
    he = axe1 - axe0
    a = (x - axn0) / hn
    b = (y - axe0) / he
    d = base + nt + nn + ne + k * nn * ne * 2
    r0 = d + (i * ne + j) * 2  # f00 of v_N; f01 two further, f10 one row (ne·2) further
    r1 = r0 + ne * 2
    f00, f01, f10, f11 = p[r0], p[r0 + 2], p[r1], p[r1 + 2]
    g00, g01, g10, g11 = p[r0 + 1], p[r0 + 3], p[r1 + 1], p[r1 + 3]
    vn = (1 - a) * (1 - b) * f00 + (1 - a) * b * f01 + a * (1 - b) * f10 + a * b * f11
    ve = (1 - a) * (1 - b) * g00 + (1 - a) * b * g01 + a * (1 - b) * g10 + a * b * g11
    jnn = ((1 - b) * (f10 - f00) + b * (f11 - f01)) / hn
    jne = ((1 - a) * (f01 - f00) + a * (f11 - f10)) / he
    jen = ((1 - b) * (g10 - g00) + b * (g11 - g01)) / hn
    jee = ((1 - a) * (g01 - g00) + a * (g11 - g10)) / he
    return vn, ve, jnn, jne, jen, jee


@numba.njit(**JIT_OPTIONS, inline="always")
def field_state(t, north, east, p, o):
    """``velocity`` and ``jacobian`` at ``(t0 + t, north, east)`` of one point, ``(v_N, v_E, J₀₀, J₀₁,
    J₁₀, J₁₁)`` with J[i, j] = ∂v_i/∂x_j, from the terms in ``p[o:]`` = [t0, n, n × (code, 12
    numbers), gridded data] (:meth:`CurrentField.current_kernel`), added in order (note 002-2.9.1):

    * uniform v = c₀; affine v = v₀ + G(x − x_ref), J = G (the shear G = [[0, 0], [k, 0]], 002-2.5);
    * rigid rotation v = ω(−r_E, r_N), r = x − centre;
    * vortex v = f(q)(−r_E, r_N), q = r², r from the centre + drift·t, J = f R + (−r_E, r_N) ⊗
      2f'(q)(r_N, r_E): Lamb–Oseen f = a(1 − e^{−q/c})/q (series for q < 10⁻⁶c), Rankine f = a/c
      inside q ≤ c, a/q outside (a = Γ/2π, c = r_c²);
    * double gyre v_N = −U sin(π e′/L) cos(π n′/L), v_E = U cos(π e′/L) sin(π n′/L);
    * gridded data: bilinear in the cell holding the point (clamped to the grid), its Jacobian the
      derivative of the same interpolant, linear in time between slices;
    * a tidal factor m(t) = mean + amplitude·cos(2πt/T + φ) multiplies a term and its Jacobian."""
    tt = p[o] + t
    n = int(p[o + 1])
    vn = 0.0
    ve = 0.0
    jnn = 0.0
    jne = 0.0
    jen = 0.0
    jee = 0.0
    for j in range(n):
        b = o + 2 + j * _TERM
        code = int(p[b])
        q = p[b + 1:b + _TERM]
        kind = code - _MODULATED if code > _MODULATED else code
        if kind == _UNIFORM:
            wn, we = q[0], q[1]
            gnn = gne = gen = gee = 0.0
        elif kind == _AFFINE:
            dn, de = north - q[6], east - q[7]
            wn = q[0] + q[2] * dn + q[3] * de
            we = q[1] + q[4] * dn + q[5] * de
            gnn, gne, gen, gee = q[2], q[3], q[4], q[5]
        elif kind == _ROTATION:
            wn = -q[0] * (east - q[2])
            we = q[0] * (north - q[1])
            gnn, gne, gen, gee = 0.0, -q[0], q[0], 0.0
        elif kind == _GYRE:
            wave = q[1]  # π/L
            ph_e, ph_n = wave * (east - q[3]), wave * (north - q[2])
            sa, ca, sb, cb = math.sin(ph_e), math.cos(ph_e), math.sin(ph_n), math.cos(ph_n)
            u = q[0] * wave
            wn, we = -q[0] * sa * cb, q[0] * ca * sb
            gnn, gne, gen, gee = u * sa * sb, -u * ca * cb, u * ca * cb, -u * sa * sb
        elif kind == _GRIDDED:
            nt, nn, ne = int(q[0]), int(q[1]), int(q[2])
            base = o + int(q[3])
            if nt == 1:
                wn, we, gnn, gne, gen, gee = _bilinear(p, base, 0, nt, nn, ne, north, east)
            else:
                k = _cell(p, base, nt, tt)
                w = min(max((tt - p[base + k]) / (p[base + k + 1] - p[base + k]), 0.0), 1.0)
                an, ae, ann, ane, aen, aee = _bilinear(p, base, k, nt, nn, ne, north, east)
                bn, be, bnn, bne, ben, bee = _bilinear(p, base, k + 1, nt, nn, ne, north, east)
                wn, we = (1 - w) * an + w * bn, (1 - w) * ae + w * be
                gnn, gne = (1 - w) * ann + w * bnn, (1 - w) * ane + w * bne
                gen, gee = (1 - w) * aen + w * ben, (1 - w) * aee + w * bee
        else:  # _Vortex: v = f(r²)·(−r_E, r_N), J = f R + (−r_E, r_N) ⊗ 2f'(r_N, r_E)
            a, c = q[0], q[1]
            rn, re = north - (q[2] + q[4] * tt), east - (q[3] + q[5] * tt)
            r2 = rn * rn + re * re
            if kind == _LAMB_OSEEN:
                if r2 < 1e-6 * c:
                    f = (1 - r2 / (2 * c) + r2 * r2 / (6 * c * c)) / c
                    df = -1 / (2 * c * c) + r2 / (3 * c ** 3)
                else:
                    f = -math.expm1(-r2 / c) / r2
                    df = math.exp(-r2 / c) / (c * r2) + math.expm1(-r2 / c) / (r2 * r2)
            elif r2 <= c:
                f, df = 1 / c, 0.0
            else:
                f, df = 1 / r2, -1 / (r2 * r2)
            f = a * f
            df = a * df
            wn = -f * re
            we = f * rn
            gnn = -re * 2 * df * rn
            gne = -f - re * 2 * df * re
            gen = f + rn * 2 * df * rn
            gee = rn * 2 * df * re
        if code > _MODULATED:
            m = q[_FACTOR] + q[_FACTOR + 1] * math.cos(q[_FACTOR + 2] * tt + q[_FACTOR + 3])
            wn, we = m * wn, m * we
            gnn, gne, gen, gee = m * gnn, m * gne, m * gen, m * gee
        vn = vn + wn
        ve = ve + we
        jnn = jnn + gnn
        jne = jne + gne
        jen = jen + gen
        jee = jee + gee
    return vn, ve, jnn, jne, jen, jee


@kernel_function
def field_velocity(t, north, east, p, o):
    """``velocity(t0 + t, north, east)`` of one point, ``(v_N, v_E)``: :func:`field_state` without
    its Jacobian (the ship's current in the composed loop)."""
    vn, ve, _, _, _, _ = field_state(t, north, east, p, o)
    return vn, ve


@kernel_function
def field_point(t, north, east, p, out):
    """``out`` = (v_N, v_E, J₀₀, J₀₁, J₁₀, J₁₁) at ``(t0 + t[0], north[0], east[0])``:
    :func:`field_state` for the batch over points (:meth:`CurrentField.velocity`)."""
    out[0], out[1], out[2], out[3], out[4], out[5] = field_state(t[0], north[0], east[0], p, 0)


def sample_field(field: CurrentField, north, east, times=None):
    """Sample a field on a grid as the ``xarray.Dataset`` that :class:`GriddedCurrent` reads."""
    import xarray as xr

    north, east = np.asarray(north, float), np.asarray(east, float)
    nn, ee = np.meshgrid(north, east, indexing="ij")
    attrs = {"units": "m/s"}
    if times is None:
        v = field.velocity(0.0, nn, ee)
        dims = ("north", "east")
        coords = {"north": ("north", north, {"units": "m"}), "east": ("east", east, {"units": "m"})}
        data = {"current_north": (dims, v[..., 0], attrs), "current_east": (dims, v[..., 1], attrs)}
    else:
        times = np.asarray(times, float)
        v = np.stack([field.velocity(t, nn, ee) for t in times])
        dims = ("time", "north", "east")
        coords = {"time": ("time", times, {"units": "s"}), "north": ("north", north, {"units": "m"}),
                  "east": ("east", east, {"units": "m"})}
        data = {"current_north": (dims, v[..., 0], attrs), "current_east": (dims, v[..., 1], attrs)}
    return xr.Dataset(data, coords=coords)
