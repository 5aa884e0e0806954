"""Earth-fixed currents for every 3-DOF vessel: the router's current fields, a Gauss–Markov current,
and the one composition of a force disturbance with a current.

**Where the current goes.** The boat, CyberShip II and the catamaran take the disturbance vector
``[X_env, Y_env, N_env, current_north, current_east]``: forces in body axes and the earth-fixed
current [m/s] over ground. Each model turns the current into body axes, ν_c = R(ψ)ᵀ[V_N, V_E, 0]ᵀ,
and applies its hull forces to the velocity through the water ν_r = ν − ν_c (Fossen 2021 §10.3,
Property 10.1; :mod:`shipgnc.models.fossen3dof`). The Mariner of document 000 keeps its own
disturbance ``[b_r, current_north, current_east]`` (:class:`~shipgnc.models.mariner.MarinerDisturbance`),
which takes the same field objects.

**The current objects** are those of the router (:mod:`shipgnc.environment.fields`: uniform, affine /
shear, rotation, vortices, sums, tidal :class:`~shipgnc.environment.fields.Modulated`, gridded) and
:class:`GaussMarkovCurrent`, a slowly varying current whose speed and direction are first-order
Gauss–Markov processes with a saturating element (Fossen 2011 §8.3, 2021 §10.3):

    V̇_c = −(V_c − V₀)/T_V + w_V,   β̇_c = −(β_c − β₀)/T_β + w_β,
    V_min ≤ V_c ≤ V_max,   β_min ≤ β_c ≤ β_max,   [V_N, V_E] = V_c [cos β_c, sin β_c]

(β_c: the direction the water flows to, clockwise from north), sampled exactly on its own knots
t_j = j·h (stationary standard deviations σ_V, σ_β: x_{j+1} = x₀ + e^{−h/T}(x_j − x₀) +
σ√(1 − e^{−2h/T}) n, then clipped) and linear between knots. Its value is a function of time alone
for a given seed — it does not depend on the simulation's step — and it starts at (V₀, β₀).

**The composition** (:class:`CurrentDisturbance`): a force disturbance of
:mod:`shipgnc.environment.disturbance` (constant, gaussian, waves — or none) writes the forces,
the current the two channels after them. In the numpy loop it is one disturbance; in the composed
compiled loop (:mod:`shipgnc.sim.compose`) the force part is the disturbance's kernel and the
current part (:meth:`CurrentDisturbance.kernel_current`, :func:`current_sample`) is called right
after it, at the same points. It is evaluated at every RK stage (a current field of position and
time) unless the force part is a noise held over each step (``gaussian``): the current is then
evaluated at each step's start and held with it — exact for a uniform current, first order in
dt·U·|∇v| for a field that varies along the track.

Spec strings (:func:`parse_current`): the router's FIELD strings in SI (``uniform:north=0,east=0.5``,
``shear:k=..``, ``rotation:..``, ``lamb-oseen:..``, ``rankine:..``, a NetCDF file) and
``gauss-markov:speed=..,direction=..[,speed_std=..,speed_tau=..,direction_std=..,direction_tau=..,
speed_min=..,speed_max=..,direction_min=..,direction_max=..,step=..]`` (speeds m/s, directions
degrees, time constants and the knot step s), joined with ``+``.
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.environment.fields import CurrentField, SumField, field_velocity
from shipgnc.errors import require
from shipgnc.kernels import Kernel, NotCompiled, flat, kernel_function
from shipgnc.models.base import state_index as index_of
from shipgnc.streams import MemberStreams


def _finite(value, field: str) -> float:
    require(isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
            and math.isfinite(float(value)), field, value, "must be a finite number")
    return float(value)


class GaussMarkovCurrent(CurrentField):
    """A uniform current whose speed and direction are bounded first-order Gauss–Markov processes
    (module docstring; Fossen 2011 §8.3, 2021 §10.3). SI: ``speed`` V₀ [m/s], ``direction`` β₀
    [rad] (the direction the water flows to, clockwise from north), ``speed_std`` σ_V [m/s],
    ``speed_tau`` T_V [s], ``direction_std`` σ_β [rad], ``direction_tau`` T_β [s], bounds
    ``speed_range`` (default V₀ ± 3σ_V, not below 0) and ``direction_range`` (default β₀ ± 3σ_β),
    ``step`` h [s], the spacing of its knots (default T/20 of the faster process, at most 10 s).

    One realisation per ship, drawn after :meth:`reset` from a stream of its own (a child of the
    run's generator, drawn at reset), so it does not shift the draws of a force noise beside it.
    """

    steady = False

    def __init__(self, speed: float, direction: float, *, speed_std: float = 0.0,
                 speed_tau: float = 600.0, direction_std: float = 0.0, direction_tau: float = 600.0,
                 speed_range: tuple[float, float] | None = None,
                 direction_range: tuple[float, float] | None = None, step: float | None = None):
        self.speed = _finite(speed, "current.speed")
        require(self.speed >= 0, "current.speed", speed, "must be >= 0 m/s")
        self.direction = _finite(direction, "current.direction")
        self.speed_std = _finite(speed_std, "current.speed_std")
        self.direction_std = _finite(direction_std, "current.direction_std")
        for name, value in (("speed_std", self.speed_std), ("direction_std", self.direction_std)):
            require(value >= 0, f"current.{name}", value, "must be >= 0")
        self.speed_tau = _finite(speed_tau, "current.speed_tau")
        self.direction_tau = _finite(direction_tau, "current.direction_tau")
        for name, value in (("speed_tau", self.speed_tau), ("direction_tau", self.direction_tau)):
            require(value > 0, f"current.{name}", value, "time constant must be > 0 s")
        if speed_range is None:
            speed_range = (max(0.0, self.speed - 3 * self.speed_std), self.speed + 3 * self.speed_std)
        if direction_range is None:
            direction_range = (self.direction - 3 * self.direction_std,
                               self.direction + 3 * self.direction_std)
        self.speed_range = tuple(_finite(v, "current.speed_range") for v in speed_range)
        self.direction_range = tuple(_finite(v, "current.direction_range") for v in direction_range)
        require(0 <= self.speed_range[0] <= self.speed <= self.speed_range[1], "current.speed_range",
                self.speed_range, f"need 0 <= speed_min <= speed ({self.speed:g}) <= speed_max")
        require(self.direction_range[0] <= self.direction <= self.direction_range[1],
                "current.direction_range", self.direction_range,
                "need direction_min <= direction <= direction_max")
        if step is None:
            step = min(10.0, min(self.speed_tau, self.direction_tau) / 20.0)
        self.step = _finite(step, "current.step")
        require(self.step > 0, "current.step", step, "knot spacing must be > 0 s")
        self._rng = None
        self._knots: list[np.ndarray] = []  # knot j0 + i: (*batch, 2) [speed, direction]
        self._j0 = 0
        self._shape: tuple[int, ...] = ()

    def describe(self) -> str:
        return (f"Gauss-Markov current {self.speed:.6g} m/s towards {math.degrees(self.direction):.6g}° "
                f"(σ {self.speed_std:.3g} m/s, T {self.speed_tau:.4g} s; σ "
                f"{math.degrees(self.direction_std):.3g}°, T {self.direction_tau:.4g} s)")

    # --- the realisation ---------------------------------------------------------------------
    def reset(self, batch_shape=(), rng=None) -> None:
        """Start every ship's realisation at (V₀, β₀), drawing from a child stream of ``rng``."""
        require(rng is not None, "current", "GaussMarkovCurrent", "reset needs the run's generator")
        self._shape = tuple(batch_shape)
        if isinstance(rng, MemberStreams):  # one child per member (chunking-invariant studies)
            seeds = rng.random(self._shape)
            self._rng = MemberStreams([int(v * 2**53) for v in np.ravel(seeds)])
        else:
            self._rng = np.random.default_rng(int(rng.random() * 2**53))
        start = np.empty((*self._shape, 2))
        start[..., 0], start[..., 1] = self.speed, self.direction
        self._knots, self._j0 = [start], 0

    def _knot(self, j: int) -> np.ndarray:
        require(self._rng is not None, "current", "GaussMarkovCurrent",
                "call reset(batch_shape, rng) before evaluating it")
        require(j >= self._j0, "current time", j * self.step,
                "a Gauss-Markov current is evaluated forward in time only")
        a_v = math.exp(-self.step / self.speed_tau)
        a_b = math.exp(-self.step / self.direction_tau)
        mean = np.array([self.speed, self.direction])
        a = np.array([a_v, a_b])
        s = np.array([self.speed_std * math.sqrt(1 - a_v * a_v),
                      self.direction_std * math.sqrt(1 - a_b * a_b)])
        low = np.array([self.speed_range[0], self.direction_range[0]])
        high = np.array([self.speed_range[1], self.direction_range[1]])
        while self._j0 + len(self._knots) <= j:
            last = self._knots[-1]
            n = self._rng.standard_normal((*self._shape, 2))
            self._knots.append(np.clip(mean + a * (last - mean) + s * n, low, high))
        return self._knots[j - self._j0]

    def state(self, t: float) -> np.ndarray:
        """(speed [m/s], direction [rad]) of every ship at time ``t`` [s], shape (*batch, 2)."""
        x = float(t) / self.step
        j = max(0, math.floor(x))
        f = min(max(x - j, 0.0), 1.0)
        # keep the knots from the previous one on (stage times of a step go back at most dt)
        drop = j - 2 - self._j0
        if drop > 0:
            del self._knots[:drop]
            self._j0 += drop
        k0, k1 = self._knot(j), self._knot(j + 1)
        return k0 + f * (k1 - k0)

    def velocity(self, t, north, east) -> np.ndarray:
        s = self.state(float(np.max(t)) if np.ndim(t) else float(t))
        v = np.stack([s[..., 0] * np.cos(s[..., 1]), s[..., 0] * np.sin(s[..., 1])], axis=-1)
        shape = np.broadcast_shapes(np.shape(north), np.shape(east), v.shape[:-1])
        return np.broadcast_to(v, (*shape, 2)).copy()

    def jacobian(self, t, north, east) -> np.ndarray:
        return np.zeros((*np.broadcast_shapes(np.shape(north), np.shape(east)), 2, 2))


def split_current(current) -> tuple[CurrentField | None, list[GaussMarkovCurrent]]:
    """(the deterministic field part or None, the Gauss–Markov parts) of a current."""
    parts = list(current.fields) if isinstance(current, SumField) else [current]
    markov = [f for f in parts if isinstance(f, GaussMarkovCurrent)]
    fields = [f for f in parts if not isinstance(f, GaussMarkovCurrent)]
    field = None if not fields else (fields[0] if len(fields) == 1 else SumField(fields))
    return field, markov


class CurrentDisturbance:
    """A force disturbance (or None) and an earth-fixed current in one disturbance vector
    ``[forces..., current_north, current_east]`` (module docstring).

    ``current``: a :class:`~shipgnc.environment.fields.CurrentField` (including
    :class:`GaussMarkovCurrent` and sums of both); ``force``: a disturbance of
    :mod:`shipgnc.environment.disturbance` or :mod:`shipgnc.environment.waves` writing ``n_force``
    channels (3: X, Y, N); ``position_index``: where the model's state holds north and east; by
    default found by name in the simulated model's states (:meth:`bind_model`; (0, 1) before a run).
    """

    def __init__(self, current, force=None, *, n_force: int = 3,
                 position_index: tuple[int, int] | None = None):
        require(isinstance(current, CurrentField), "current", type(current).__name__,
                "must be a current field (shipgnc.environment.fields) or a GaussMarkovCurrent")
        self.current, self.force = current, force
        self.n_force = int(n_force)
        self._given_index = None if position_index is None else tuple(int(i) for i in position_index)
        self.position_index = self._given_index or (0, 1)
        self._field, self._markov = split_current(current)

    def bind_model(self, model) -> None:
        """Read north and east where ``model`` keeps them (found by name in its states; the
        simulator calls this at the start of every run), unless ``position_index`` was given; the
        force part is bound too."""
        if self._given_index is None:
            self.position_index = (index_of(model, "north"), index_of(model, "east"))
        bind = getattr(self.force, "bind_model", None)
        if callable(bind):
            bind(model)

    @property
    def per_stage(self) -> bool:
        """At every RK stage, unless the force part is a noise held over each step (then both are
        sampled at the step's start and held; a constant force is the same at every stage)."""
        from shipgnc.environment.disturbance import ConstantDisturbance

        f = self.force
        return f is None or bool(getattr(f, "per_stage", False)) or isinstance(f, ConstantDisturbance)

    def reset(self, batch_shape, rng) -> None:
        if self.force is not None:
            self.force.reset(batch_shape, rng)
        self._shape = tuple(batch_shape)
        for f in self._markov:
            f.reset(batch_shape, rng)

    def current_velocity(self, t: float, x: np.ndarray) -> np.ndarray:
        """[V_N, V_E] (..., 2) at time ``t`` and the states ``x``: the field, then the Gauss–Markov
        parts added (the order :func:`current_sample` adds them)."""
        i_n, i_e = self.position_index
        north, east = x[..., i_n], x[..., i_e]
        v = None
        if self._field is not None:
            v = self._field.velocity(t, north, east)
        for f in self._markov:
            w = f.velocity(t, north, east)
            v = w if v is None else v + w
        return v

    def __call__(self, t: float, x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        if self.force is None:
            forces = np.zeros((*x.shape[:-1], self.n_force))
        else:
            forces = np.broadcast_to(self.force(t, x), (*x.shape[:-1], self.n_force))
        return np.concatenate([forces, self.current_velocity(t, x)], axis=-1)

    # --- the composed loop --------------------------------------------------------------------
    def kernel_reason(self) -> str | None:
        """None when the composed loop covers both parts, else why not."""
        if self.force is not None:
            if not callable(getattr(self.force, "kernel", None)):
                return f"force {type(self.force).__name__} has no kernel"
            why = getattr(self.force, "kernel_reason", None)
            reason = why() if callable(why) else None
            if reason:
                return f"force {type(self.force).__name__}: {reason}"
        if self._field is not None:
            try:
                self._field.current_kernel()
            except NotCompiled as exc:
                return str(exc)
        return None

    def kernel(self, batch_shape, dt: float | None = None) -> Kernel:
        """The force part's kernel (or :func:`no_force`); the current is :meth:`kernel_current`."""
        if self.force is None:
            return Kernel(no_force)
        return self.force.kernel(batch_shape, dt=dt)

    def kernel_current(self, batch_shape, dt: float | None = None) -> Kernel:
        """:func:`current_sample` for the composed loop: called right after the force kernel with
        the same arguments (every RK stage or the step's start, as :attr:`per_stage`). The field's
        terms are its ``current_kernel()`` parameters; the Gauss–Markov parts are tabulated in
        numpy per step, at t_k, t_k + dt/2 and t_k + dt (the RK stage times), from the same
        realisation the numpy loop evaluates."""
        if dt is None:
            raise NotCompiled("a current needs the run's step dt")
        terms = np.zeros(2)
        if self._field is not None:
            _, terms = self._field.current_kernel()  # raises NotCompiled (a gridded field)
        markov = self._markov
        n_table = 7 if markov else 0
        params = flat(self.n_force, *self.position_index, float(self._field is not None),
                      float(bool(markov)), dt, terms)
        table = None
        if markov:
            n_ships = math.prod(tuple(batch_shape))

            def table(k0: int, k1: int) -> np.ndarray:
                out = np.empty((k1 - k0, n_ships, 7))
                for i, k in enumerate(range(k0, k1)):
                    t = k * dt
                    out[i, :, 0] = t
                    for j, ts in enumerate((t, t + 0.5 * dt, t + 1.0 * dt)):
                        v = None
                        for f in markov:
                            w = f.velocity(ts, 0.0, 0.0)  # uniform: any point
                            v = w if v is None else v + w
                        out[i, :, 1 + 2 * j:3 + 2 * j] = np.broadcast_to(
                            v, (*tuple(batch_shape), 2)).reshape(n_ships, 2)
                return out

        return Kernel(current_sample, params, table=table, n_table=n_table)


@kernel_function
def no_force(t, x, z, p, w, d):
    """No force: the model's force channels stay at zero."""


#: where :func:`current_sample` finds the field's terms
_TERMS = 6


@kernel_function
def current_sample(t, x, z, p, w, d):
    """:meth:`CurrentDisturbance.current_velocity` for one ship: d[i], d[i + 1] = [V_N, V_E] at
    (t, north, east), the field's terms (:func:`~shipgnc.environment.fields.field_velocity`) plus the
    tabulated Gauss–Markov value of the RK stage at ``t`` (w = [t_k, v(t_k), v(t_k + dt/2),
    v(t_k + dt)]). ``p`` = [i, north index, east index, has field, has table, dt, terms...]."""
    vn = 0.0
    ve = 0.0
    if p[3] != 0.0:
        vn, ve = field_velocity(t, x[int(p[1])], x[int(p[2])], p, _TERMS)
    if p[4] != 0.0:
        j = math.floor(2.0 * (t - w[0]) / p[5] + 0.5)
        if j < 0:
            j = 0
        elif j > 2:
            j = 2
        if p[3] != 0.0:
            vn = vn + w[1 + 2 * j]
            ve = ve + w[2 + 2 * j]
        else:
            vn = w[1 + 2 * j]
            ve = w[2 + 2 * j]
    i = int(p[0])
    d[i] = vn
    d[i + 1] = ve


# ----------------------------------------------------------------------------------------------
# spec strings
# ----------------------------------------------------------------------------------------------

#: gauss-markov parameters: name -> (constructor argument, factor to SI)
_GM = {"speed": ("speed", 1.0), "direction": ("direction", math.pi / 180),
       "speed_std": ("speed_std", 1.0), "speed_tau": ("speed_tau", 1.0),
       "direction_std": ("direction_std", math.pi / 180), "direction_tau": ("direction_tau", 1.0),
       "speed_min": ("speed_min", 1.0), "speed_max": ("speed_max", 1.0),
       "direction_min": ("direction_min", math.pi / 180),
       "direction_max": ("direction_max", math.pi / 180), "step": ("step", 1.0)}


def _gauss_markov(text: str) -> GaussMarkovCurrent:
    _, _, args = text.partition(":")
    from shipgnc.environment.field_spec import key_values

    values = {key: number * _GM[key][1]
              for key, number in key_values(args, _GM, "current gauss-markov").items()}
    missing = [k for k in ("speed", "direction") if k not in values]
    require(not missing, "current gauss-markov", text, f"missing {', '.join(missing)}")
    kw = {k: values[k] for k in ("speed_std", "speed_tau", "direction_std", "direction_tau", "step")
          if k in values}
    speed, direction = values["speed"], values["direction"]
    s3, d3 = 3 * values.get("speed_std", 0.0), 3 * values.get("direction_std", 0.0)
    if "speed_min" in values or "speed_max" in values:
        kw["speed_range"] = (values.get("speed_min", max(0.0, speed - s3)),
                             values.get("speed_max", speed + s3))
    if "direction_min" in values or "direction_max" in values:
        kw["direction_range"] = (values.get("direction_min", direction - d3),
                                 values.get("direction_max", direction + d3))
    return GaussMarkovCurrent(speed, direction, **kw)


def parse_current(text: str) -> CurrentField:
    """A current from a spec string (module docstring): the router's FIELD terms in SI and
    ``gauss-markov:...`` terms, joined with '+'."""
    from shipgnc.environment.field_spec import parse_field

    require(isinstance(text, str) and text.strip() != "", "current", text, "must name a current")
    terms = []
    for term in text.split("+"):
        if term.strip().lower().startswith("gauss-markov"):
            terms.append(_gauss_markov(term))
        else:
            terms.append(parse_field(term, "si"))
    return terms[0] if len(terms) == 1 else SumField(terms)
