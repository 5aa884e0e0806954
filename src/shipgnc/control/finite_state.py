"""The finite-state method (FSM) of document 004, general and for the catamaran's yaw rate.

**General form** (note 004-4.5, eq. (12)–(15)). For an affine system ż = Φ(t, z) + B u and a
smooth criterion J(z) with target J*, predict the free motion over a horizon h,

    z̄ ≈ z + h Φ(t, z),   W ≈ I + h ∂Φ/∂z(t, z)                              (15)

and require dJ/dt = (J* − J(z̄))/T_u along the controlled motion:

    G u = f_J,   G = (∂J/∂z̄)ᵀ W B,   u = G⁺ f_J,   f_J = (J* − J(z̄))/T_u       (13)

(G⁺ the Moore–Penrose pseudo-inverse: the minimum-norm control for several inputs).
:func:`fsm_control` evaluates this on batched states with a central-difference (or supplied)
Jacobian; :class:`FiniteStateController` wraps it as a controller for any model.

**Yaw rate** (eq. (16)–(21)). With J = z̄₃ = ω̄ and δ a state driven by u = δ̇,

    W₃₇ = h L T_v cos δ / J                                                  (19)
    law (20):  u = (ω* − ω̄)/(T_u W₃₇),  ω̄ = ω + h Φ₃(z)
    law (21):  u = (ω* − ω)/(T_u W₃₇)   (no velocity measurement needed)

:class:`YawRateFSM` implements both with the guards of note 004-4.11.1: the feasibility check
|ω*| ≤ ω_max, an optional clamp |δ| ≤ δ_max, an optional frozen 1/cos δ gain near 90°, and events
(``omega_ref_above_max``, ``delta_clamped``, ``delta_reached_90``) recorded on the controller
(``controller.events``) rather than a silent failure.

**Actuator** (eq. (22)–(23)): with a thruster lag δ̇ = (−δ + k v_a)/T the command
v_a = (δ + T u)/k (:func:`actuator_inverse`) makes δ̇ = u when T and k are right.

**References** for the yaw rate: :class:`ConstantRate`, :class:`SineRate` and the heading
capture (17) :class:`HeadingCapture`. Each is also a guidance object (reference ``r_ref``,
tracking ``r``), so the simulator logs ω* and r − ω*; handed to the controller as ``omega_ref``
it is evaluated at the time of every RK stage (needed for an exact switch at t*).

The laws are stateless functions of (t, measured state, reference) — their "integral" is the
physical δ — so they run in ``continuous`` mode (evaluated inside every RK stage, as the document
does) or sampled every ``Ts`` with a hold.

**Written once** (:mod:`shipgnc.kernels`): each law is one scalar kernel (:func:`yaw_rate_fsm_step`,
and the ω* of the three sources :func:`rate_value`, also the references' kernel as guidance,
:func:`rate_reference`); :meth:`YawRateFSM.kernel` hands it to the composed loop and the numpy
``law`` — which the numpy loop, design and figures call — is its batch over ships
(:func:`rate_law`, :func:`shipgnc.derive.per_ship`). The per-ship kernel state holds what the
numpy objects keep: the heading capture's latch K(t₀), the last ω* and u (``signal_values``) and,
per event kind, the index of the first law call (samples and RK stages counted alike), its time
and the ship's |ω*| or |δ| there, from which ``events`` are written with the batch-wide values.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from shipgnc.derive import per_ship
from shipgnc.errors import ConfigError, require
from shipgnc.frames import wrap_angle
from shipgnc.kernels import Kernel, NotCompiled, clip, flat, kernel_function, sign, wrap
from shipgnc.models.base import Signal
from shipgnc.models.catamaran import (
    DELTA,
    N_KERNEL_PARAMS,
    PSI,
    Catamaran,
    R,
    U,
    V,
    _kernel_columns,
    kernel_params,
    kernel_params_reason,
    yaw_acceleration_of,
)

EVENT_KINDS = ("omega_ref_above_max", "delta_clamped", "delta_reached_90")


# --- the general method ------------------------------------------------------------------------
def numerical_jacobian(fun: Callable[[np.ndarray], np.ndarray], z: np.ndarray,
                       rel_step: float = 1e-6) -> np.ndarray:
    """Central-difference ∂fun/∂z for batched ``z`` (..., n) → (..., m, n)."""
    z = np.asarray(z, dtype=float)
    n = z.shape[-1]
    step = rel_step * np.maximum(1.0, np.abs(z))  # (..., n)
    eye = np.eye(n)
    dz = eye * step[..., None, :]  # (..., n(pert), n)
    plus = fun(z[..., None, :] + dz)  # (..., n(pert), m)
    minus = fun(z[..., None, :] - dz)
    return np.swapaxes((plus - minus) / (2.0 * step[..., :, None]), -1, -2)


def fsm_control(phi: Callable, z: np.ndarray, B: np.ndarray, criterion: Callable, target, T_u: float,
                h: float, *, jacobian: Callable | None = None,
                criterion_gradient: Callable | None = None) -> np.ndarray:
    """u = G⁺ (J* − J(z̄))/T_u of eq. (13) with the first-order prediction (15).

    ``phi(z)`` is the free motion Φ (batched, (..., n)); ``B`` the input matrix (n, m) or
    (..., n, m); ``criterion(z̄)`` returns (..., r); ``target`` broadcasts to (..., r);
    ``jacobian(z)`` → (..., n, n) and ``criterion_gradient(z̄)`` → (..., r, n) default to central
    differences. Returns u (..., m).
    """
    require(T_u > 0 and math.isfinite(T_u), "controller.T_u", T_u, "criterion time constant must be > 0 s")
    require(h > 0 and math.isfinite(h), "controller.h", h, "prediction horizon must be > 0 s")
    z = np.asarray(z, dtype=float)
    n = z.shape[-1]
    A = jacobian(z) if jacobian is not None else numerical_jacobian(phi, z)
    z_bar = z + h * phi(z)
    W = np.eye(n) + h * A
    crit = np.asarray(criterion(z_bar), dtype=float)
    grad = (criterion_gradient(z_bar) if criterion_gradient is not None
            else numerical_jacobian(criterion, z_bar))
    G = grad @ W @ B  # (..., r, m)
    f_J = (np.asarray(target, dtype=float) - crit) / T_u
    return (np.linalg.pinv(G) @ f_J[..., None])[..., 0]


class FiniteStateController:
    """The general FSM (13) + (15) for a model with an affine input, as a controller.

    ``criterion(z̄)`` → (..., r); the target J* is the guidance reference (first r channels) or
    ``target(t, x)``. Φ is the model's right-hand side at zero input; B = ∂f/∂u by differences
    (the model must be affine in u). Continuous mode by default (``Ts=None``).
    """

    def __init__(self, model, criterion: Callable, *, T_u: float, h: float, target: Callable | None = None,
                 jacobian: Callable | None = None, criterion_gradient: Callable | None = None,
                 Ts: float | None = None):
        require(isinstance(T_u, (int, float)) and T_u > 0, "controller.T_u", T_u, "must be > 0 s")
        require(isinstance(h, (int, float)) and h > 0, "controller.h", h, "prediction horizon must be > 0 s")
        self.model, self.criterion, self.T_u, self.h = model, criterion, float(T_u), float(h)
        self.target, self.jacobian, self.criterion_gradient = target, jacobian, criterion_gradient
        self.Ts = Ts
        self.continuous = Ts is None
        self.signals: tuple[Signal, ...] = ()
        n_in = len(model.inputs)
        n = len(model.states)
        x0 = np.zeros(n)
        u0 = np.zeros(n_in)
        B = np.empty((n, n_in))
        for j in range(n_in):
            e = np.zeros(n_in)
            e[j] = 1.0
            B[:, j] = (model.derivatives(x0, u0 + e) - model.derivatives(x0, u0 - e)) / 2.0
        self.B = B
        self._zero_input = u0

    def reset(self, batch_shape) -> None:
        pass

    def phi(self, z):
        return self.model.derivatives(z, np.broadcast_to(self._zero_input, (*z.shape[:-1], self.B.shape[1])))

    def law(self, t: float, x: np.ndarray, reference: np.ndarray) -> np.ndarray:
        target = self.target(t, x) if self.target is not None else reference
        return fsm_control(self.phi, x, self.B, self.criterion, target, self.T_u, self.h,
                           jacobian=self.jacobian, criterion_gradient=self.criterion_gradient)

    def step(self, t, x, reference):
        return self.law(t, x, reference)

    def signal_values(self) -> dict[str, np.ndarray]:
        return {}


# --- actuator (22)–(23) -------------------------------------------------------------------------
def actuator_inverse(delta, u, T: float, k: float):
    """v_a = (δ + T u)/k (eq. (23)): the lag command that gives δ̇ = u for a lag (T, k)."""
    return (np.asarray(delta) + T * np.asarray(u)) / k


def thruster_lag_rate(delta, v_a, T: float, k: float):
    """δ̇ = (−δ + k v_a)/T (eq. (22))."""
    return (-np.asarray(delta) + k * np.asarray(v_a)) / T


# --- yaw-rate references --------------------------------------------------------------------------
#: ω* sources of :func:`rate_value` (``RATE_GUIDANCE``: the guidance's first reference)
RATE_CONSTANT, RATE_SINE, RATE_CAPTURE, RATE_GUIDANCE = 0.0, 1.0, 2.0, 3.0
#: lengths of a source's parameter block and per-ship state block in a kernel
N_RATE_PARAMS, N_RATE_STATE = 6, 3


class _RateReference:
    """Base of the ω* sources: a guidance object with one reference ``r_ref`` (tracks ``r``)."""

    references = (Signal("r_ref", "rad/s", "yaw-rate reference omega*", tracks="r"),)
    outputs = ()

    def __init__(self) -> None:
        self._batch_shape: tuple[int, ...] = ()

    def reset(self, batch_shape, model=None) -> None:
        self._batch_shape = tuple(batch_shape)

    # --- the composed compiled loop ------------------------------------------------------------
    def rate_block(self, batch_shape) -> tuple[np.ndarray, np.ndarray]:
        """``(params, state)`` of :func:`rate_value`: the source's parameter block
        ``[kind, …]`` (:data:`N_RATE_PARAMS`) and its per-ship state ``[ω, latched, K(t₀)]``
        (``batch_shape + (N_RATE_STATE,)``), from the object's current state."""
        raise NotCompiled(f"{type(self).__name__} has no kernel")

    def restore_block(self, z: np.ndarray, batch_shape) -> None:
        """Leave the object as the numpy loop would, from the final per-ship state block."""

    def kernel_reason(self) -> str | None:
        """Why the reference, as guidance, has no kernel (None when it has one)."""
        return source_reason(self) and f"{type(self).__name__} has no kernel"

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`reference` for the composed loop (:func:`rate_reference`)."""
        params, state = self.rate_block(batch_shape)

        def restore(z: np.ndarray) -> None:
            self.restore_block(z, batch_shape)

        return Kernel(rate_reference, params, state, restore=restore)

    def value(self, t: float, x: np.ndarray) -> np.ndarray:
        """ω*(t) for a batch of ships (..., 7): the batch of :func:`rate_reference` on the source's
        :meth:`rate_block`, its per-ship state handed back by :meth:`restore_block` (a user's
        source written in numpy overrides this method instead)."""
        x = np.asarray(x, dtype=float)
        lead = np.broadcast_shapes(x.shape[:-1], self._value_shape())
        params, state = self.rate_block(lead)
        z = np.array(np.broadcast_to(state, (*lead, N_RATE_STATE)).reshape(-1, N_RATE_STATE))
        ref = per_ship(rate_reference, "t i z p o o -> r")(t, _to_batch(x, lead), z, params, 1, 0)[0]
        self.restore_block(z, lead)
        return ref[..., 0]

    def _value_shape(self) -> tuple[int, ...]:
        """The batch shape the source's own values have (one ω* or K(t₀) per ship)."""
        return ()

    def reference(self, t: float, x: np.ndarray) -> np.ndarray:
        return np.broadcast_to(self.value(t, x), x.shape[:-1])[..., None].copy()

    def output_values(self) -> dict[str, np.ndarray]:
        return {}

    def finished(self):
        return None


class ConstantRate(_RateReference):
    """ω*(t) = ``omega`` [rad/s] (from ``t_start``, 0 before); an array gives one value per ship."""

    def __init__(self, omega: float, t_start: float = 0.0):
        super().__init__()
        value = np.asarray(omega, dtype=float) if not isinstance(omega, (str, bool)) else np.nan
        require(bool(np.all(np.isfinite(value))) and np.ndim(value) <= 1, "omega_ref", omega,
                "must be a finite yaw rate [rad/s] (or one per ship)")
        self.omega = float(value) if np.ndim(value) == 0 else value
        self.t_start = float(t_start)

    def _value_shape(self):
        return np.shape(self.omega)

    def rate_block(self, batch_shape):
        state = np.zeros((*batch_shape, N_RATE_STATE))
        state[..., 0] = np.broadcast_to(self.omega, tuple(batch_shape))
        return _block(RATE_CONSTANT, self.t_start), state


class SineRate(_RateReference):
    """ω*(t) = A sin(2π t / period) (S6: A = 0.0072 rad/s, period t_f/4 = 375 s, reading C11)."""

    def __init__(self, amplitude: float, period: float):
        super().__init__()
        require(math.isfinite(amplitude), "omega_ref.amplitude", amplitude, "must be finite")
        require(math.isfinite(period) and period > 0, "omega_ref.period", period, "must be > 0 s")
        self.amplitude, self.period = float(amplitude), float(period)

    @classmethod
    def document(cls, reading: str = "pi", t_f: float = 1500.0, amplitude: float = 0.0072) -> SineRate:
        """Fig. 7's 0.0072 sin(8πt/t_f) (``reading="pi"``) or sin(8t/t_f) (``"literal"``)."""
        require(reading in ("pi", "literal"), "omega_ref.reading", reading, "allowed: pi, literal")
        return cls(amplitude, t_f / 4.0 if reading == "pi" else 2.0 * math.pi * t_f / 8.0)

    def rate_block(self, batch_shape):
        return _block(RATE_SINE, self.amplitude, self.period), np.zeros((*batch_shape, N_RATE_STATE))


class HeadingCapture(_RateReference):
    """Heading capture (17): ω* = ±ω_c until t* = t₀ + |wrap(K* − K(t₀))|/ω_c, then 0.

    The sign of ω* is that of the wrapped difference K* − K(t₀) ∈ (−π, π] (C12); K(t₀) is latched
    per ship at the first evaluation at t ≥ t₀ (or given as ``psi0``). ``ramp_s`` > 0 replaces the
    jump at t* by a linear ramp over [t* − ramp/2, t* + ramp/2] (same area, so the same heading).
    """

    def __init__(self, psi_target: float, omega_c: float = 0.0022, *, t0: float = 0.0, psi0=None,
                 ramp_s: float = 0.0):
        super().__init__()
        require(isinstance(psi_target, (int, float)) and math.isfinite(psi_target), "heading_target",
                psi_target, "must be a finite heading [rad]")
        require(isinstance(omega_c, (int, float)) and math.isfinite(omega_c) and omega_c > 0,
                "omega_c", omega_c, "capture rate must be > 0 rad/s")
        require(math.isfinite(t0) and t0 >= 0, "t0", t0, "must be >= 0 s")
        require(math.isfinite(ramp_s) and ramp_s >= 0, "ramp_s", ramp_s, "must be >= 0 s")
        self.psi_target, self.omega_c, self.t0, self.ramp_s = float(psi_target), float(omega_c), t0, ramp_s
        self._psi0_given = None if psi0 is None else np.asarray(psi0, dtype=float)
        self.psi0 = self._psi0_given

    def reset(self, batch_shape, model=None) -> None:
        super().reset(batch_shape)
        self.psi0 = self._psi0_given

    def switch_time(self):
        """t* per ship (needs K(t₀): after the first evaluation or with ``psi0``)."""
        if self.psi0 is None:
            raise ConfigError("heading capture: K(t0) unknown before the first evaluation")
        diff = wrap_angle(self.psi_target - self.psi0)
        return self.t0 + np.abs(diff) / self.omega_c

    def _value_shape(self):
        return np.shape(self.psi0) if self.psi0 is not None else ()

    def rate_block(self, batch_shape):
        state = np.zeros((*batch_shape, N_RATE_STATE))
        if self.psi0 is not None:
            state[..., 1], state[..., 2] = 1.0, np.broadcast_to(self.psi0, tuple(batch_shape))
        return _block(RATE_CAPTURE, self.psi_target, self.omega_c, self.t0, self.ramp_s), state

    def restore_block(self, z, batch_shape) -> None:
        z = np.asarray(z).reshape(*batch_shape, N_RATE_STATE)
        if self._psi0_given is None and z.size and bool(np.all(z[..., 1] > 0)):
            self.psi0 = z[..., 2].copy()

    def kernel_reason(self) -> str | None:
        """As guidance, K(t₀) latched after t = 0 is refused: numpy latches it in the object the
        guidance shares with a continuous law, possibly in an RK stage between two samples, and
        the guidance's kernel only sees the samples."""
        if self._psi0_given is None and self.t0 > 0:
            return ("as guidance, a heading capture with t0 > 0 latches K(t0) in the object it "
                    "shares with the controller (possibly in an RK stage); give psi0 or t0 = 0")
        return None


def source_reason(source) -> str | None:
    """Why the ω* source ``source`` (None: the guidance's reference) has no kernel in a law."""
    if source is not None and type(source).rate_block is _RateReference.rate_block:
        return f"omega_ref: {type(source).__name__} has no kernel"
    return None


def _block(kind: float, *values: float) -> np.ndarray:
    out = np.zeros(N_RATE_PARAMS)
    out[0] = kind
    out[1:1 + len(values)] = values
    return out


# --- a law's numpy form: the batch derived from its kernel ------------------------------------------
def law_params(*pieces, lead: tuple[int, ...] = ()) -> np.ndarray:
    """A law kernel's parameters from ``pieces`` in order: numbers and flat blocks (shared by every
    ship) and per-ship blocks (..., k) (arrays of two or more dimensions, e.g. a plant's
    :func:`~shipgnc.models.catamaran.kernel_params` columns with per-ship mass factors). One flat
    array when every piece is shared, else one row per ship of the batch ``lead`` (C order)."""
    arrays = [np.asarray(piece, dtype=float) for piece in pieces]
    if all(a.ndim <= 1 for a in arrays):
        return flat(*arrays)
    blocks = [np.broadcast_to(a.reshape(-1) if a.ndim <= 1 else a, (*lead, a.shape[-1] if a.ndim else 1))
              for a in arrays]
    rows = np.concatenate(blocks, axis=-1)
    return np.ascontiguousarray(rows.reshape(-1, rows.shape[-1]))


def _to_batch(x: np.ndarray, lead: tuple[int, ...]) -> np.ndarray:
    """States ``x`` (..., k) over the batch ``lead``: as given when they cover it, else a copy."""
    return x if x.shape[:-1] == lead else np.array(np.broadcast_to(x, (*lead, x.shape[-1])))


def per_ship_value(value) -> np.ndarray:
    """A number shared by every ship as is; one per ship (an array (...,)) as a block (..., 1)."""
    a = np.asarray(value, dtype=float)
    return a[..., None] if a.ndim else a


def law_columns(law, columns=None) -> np.ndarray:
    """The plant's :func:`~shipgnc.models.catamaran.kernel_params` columns of a law that reads its
    model (``law.model``; zeros when it reads none: ``law.uses_model`` False). ``columns`` the
    function forming them (default :func:`~shipgnc.models.catamaran.kernel_params`: refused
    along more than one batch axis, as the composed loop needs)."""
    if not getattr(law, "uses_model", True):
        return np.zeros(N_KERNEL_PARAMS)
    return (columns or kernel_params)(law.model.params)


def rate_law(law, t: float, x, reference) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Evaluate the yaw-rate law ``law`` on a batch of ships by the batch
    :func:`~shipgnc.derive.per_ship` derives from its kernel (``law.law_kernel``, signature
    ``step(t, x, ref, z, p, cmd, sig)``): the numpy loop, design and figures run the kernel's
    arithmetic, written once. Returns ``(command (..., 1), signals (..., n), kernel state (n_ships,
    k))`` after handing the ω* source's state back to its object (the heading capture's latch).

    ``law`` provides ``model`` (or None), ``rate_source()`` (the ω* source or None: the guidance's
    first reference), ``law_state(lead, source_state)`` (the kernel's per-ship state) and
    ``law_pieces(columns, block)`` (its parameters, :func:`law_params`). Every setting runs: the
    plant's per-ship factors along any number of batch axes (the batch is the broadcast of the
    factors and the states, one row per ship), and a user's ω* source written only in numpy (no
    ``rate_block``): its ``value(t, x)`` is fed to the kernel as the guidance's reference."""
    x = np.asarray(x, dtype=float)
    reference = np.asarray(reference, dtype=float)
    columns = law_columns(law, _kernel_columns)
    lead = np.broadcast_shapes(x.shape[:-1], columns.shape[:-1], reference.shape[:-1])
    x = _to_batch(x, lead)
    source = law.rate_source()
    if source is not None and source_reason(source) is None:
        block, source_state = source.rate_block(lead)
    else:
        block, source_state = _block(RATE_GUIDANCE), np.zeros((*lead, N_RATE_STATE))
        if source is not None:  # a source written in numpy: its ω* as the guidance's reference
            reference = np.broadcast_to(np.asarray(source.value(t, x), dtype=float), lead)[..., None]
        elif reference.shape[-1] < 1:
            raise ConfigError(f"guidance: none; {type(law).__name__} without omega_ref needs a "
                              "yaw-rate reference from the guidance")
    z = np.array(law.law_state(lead, source_state).reshape(math.prod(lead), -1))
    params = law_params(*law.law_pieces(columns, block), lead=lead)
    command, signals = per_ship(law.law_kernel, "t i i z p o o")(t, x, reference, z, params, 1,
                                                                 len(law.signals))
    if source is not None and source_reason(source) is None:
        source.restore_block(z[:, -N_RATE_STATE:], lead)
    return command, signals, z


@kernel_function
def rate_value(t, x, ref, p, o, z, oz):
    """ω*(t) of one ship, the one source of the sources' ``value`` (their batch): ``p[o:]`` a
    parameter block of :meth:`_RateReference.rate_block`, ``z[oz:]`` its per-ship state (the
    heading capture (17) latches K(t₀) there at the first call with t ≥ t₀, as
    :class:`HeadingCapture` does); ``ref`` the held guidance references (source
    ``RATE_GUIDANCE``: ``ref[0]``). Offsets, not slices: no array view per call."""
    # every array element read once, up front, and the latch written back unconditionally: an
    # array whose last use sits inside a conditional keeps numba's reference counting (atomic
    # increments and decrements of every array argument) in the caller's hot path
    kind = p[o]
    p1, p2, p3, p4 = p[o + 1], p[o + 2], p[o + 3], p[o + 4]
    omega, latched, psi0 = z[oz], z[oz + 1], z[oz + 2]
    psi = x[PSI]
    if kind == RATE_CONSTANT:
        return omega if t >= p1 else 0.0 * omega
    if kind == RATE_SINE:
        return p1 * math.sin(2.0 * math.pi * t / p2)
    if kind == RATE_CAPTURE:
        psi_target, omega_c, t0, ramp = p1, p2, p3, p4
        if latched == 0.0 and t >= t0:
            latched, psi0 = 1.0, psi
        z[oz + 1], z[oz + 2] = latched, psi0
        if latched == 0.0:
            return 0.0
        diff = wrap(psi_target - psi0)
        t_star = t0 + abs(diff) / omega_c
        if ramp > 0:
            frac = clip((t_star + ramp / 2 - t) / ramp, 0.0, 1.0)
        else:
            frac = 1.0 if t < t_star else 0.0
        return sign(diff) * omega_c * frac
    return ref[0]


@kernel_function
def rate_reference(t, x, z, p, ref, out):
    """:meth:`_RateReference.reference` for one ship: ``r_ref`` = ω*(t); never finished."""
    ref[0] = rate_value(t, x, ref, p, 0, z, 0)
    return False


def as_rate_reference(omega_ref) -> _RateReference | None:
    """``None`` (use the guidance), a number (constant) or a reference object."""
    if omega_ref is None or isinstance(omega_ref, _RateReference):
        return omega_ref
    if isinstance(omega_ref, (int, float, np.ndarray, list, tuple)) and not isinstance(omega_ref, bool):
        return ConstantRate(float(omega_ref))
    raise ConfigError(f"omega_ref = {omega_ref!r}: need a number [rad/s], ConstantRate, SineRate or "
                      "HeadingCapture")


# --- the yaw-rate laws -------------------------------------------------------------------------------
def law20(model: Catamaran, x, omega_ref, T_u: float, h: float):
    """u = (ω* − ω − h Φ₃)/(T_u W₃₇), W₃₇ = h L T_v cos δ / J, eq. (19)–(20), for a batch of states
    ``x`` (..., 7) and references ``omega_ref`` (broadcast): :func:`yaw_rate_fsm_step`'s batch."""
    return _bare_law(model, 20, x, omega_ref, T_u, h)


def law21(model: Catamaran, x, omega_ref, T_u: float, h: float):
    """u = (ω* − ω)/(T_u W₃₇), eq. (21): needs only L, J, T_v, ω and δ (:func:`law20`)."""
    return _bare_law(model, 21, x, omega_ref, T_u, h)


def _bare_law(model: Catamaran, law: int, x, omega_ref, T_u: float, h: float):
    """The law without guards, actuator or ω* source: ω* handed over as the guidance's reference."""
    controller = YawRateFSM(model, law, T_u=T_u, h=h, check_feasibility=False)
    x = np.asarray(x, dtype=float)
    lead = np.broadcast_shapes(x.shape[:-1], np.shape(omega_ref))
    reference = np.broadcast_to(np.asarray(omega_ref, dtype=float), lead)[..., None]
    return rate_law(controller, 0.0, x, reference)[0][..., 0]


class YawRateFSM:
    """Yaw-rate control by the FSM laws (20) or (21) for document 004's catamaran.

    Parameters
    ----------
    model : the controller's model of the plant (nominal :class:`Catamaran`; only its parameters).
    law : 20 or 21.
    T_u, h : criterion time constant and prediction horizon [s] (``paper``: 0.1, 0.0625; ``si``:
        2.5, 2.5; :func:`default_gains`).
    omega_ref : a number, a reference object (:class:`ConstantRate`, :class:`SineRate`,
        :class:`HeadingCapture`; evaluated at every RK stage) or ``None`` to use the guidance's
        first reference channel (held over each step).
    Ts : ``None`` (default) = continuous mode; a number = sample-and-hold every ``Ts`` s.
    actuator : ``None`` (the input is δ̇) or ``(T_a, k_a)``: the command is v_a of (23) for a plant
        with the thruster lag (22) (``delta_row="lag"``).
    delta_max : optional clamp |δ| ≤ δ_max [rad] (no thruster rate pushing further out).
    gain_freeze : optional angle [rad] beyond which cos δ in W₃₇ is frozen at cos(gain_freeze).
    check_feasibility : compare |ω*| with ω_max of the controller's model (event, never an error).
    """

    reference_names = ()

    def __init__(self, model: Catamaran, law: int = 21, *, T_u: float, h: float, omega_ref=None,
                 Ts: float | None = None, actuator: tuple[float, float] | None = None,
                 delta_max: float | None = None, gain_freeze: float | None = None,
                 check_feasibility: bool = True):
        require(isinstance(model, Catamaran), "controller.model", type(model).__name__,
                "need a Catamaran (the controller's model of the plant)")
        require(law in (20, 21, "20", "21"), "controller.law", law, "allowed: 20, 21")
        for name, value in (("T_u", T_u), ("h", h)):
            require(isinstance(value, (int, float)) and math.isfinite(value) and value > 0,
                    f"controller.{name}", value, "must be a finite number > 0 s")
        if Ts is not None:
            require(isinstance(Ts, (int, float)) and math.isfinite(Ts) and Ts > 0, "controller.Ts", Ts,
                    "must be > 0 s (or None for continuous mode)")
        if actuator is not None:
            T_a, k_a = actuator
            require(math.isfinite(T_a) and T_a > 0, "controller.actuator.T", T_a, "must be > 0 s")
            require(math.isfinite(k_a) and k_a != 0, "controller.actuator.k", k_a, "must be non-zero")
        if delta_max is not None:
            require(0 < delta_max <= math.pi / 2, "controller.delta_max", delta_max,
                    "need 0 < delta_max <= pi/2 rad")
        if gain_freeze is not None:
            require(0 < gain_freeze < math.pi / 2, "controller.gain_freeze", gain_freeze,
                    "need 0 < gain_freeze < pi/2 rad")
        self.model = model if model.params.delta_row == "rate" else Catamaran(
            model.params.with_(delta_row="rate"), model.preset_name)
        self.law_number = int(law)
        self.T_u, self.h = float(T_u), float(h)
        self.omega_ref = as_rate_reference(omega_ref)
        self.Ts = Ts
        self.continuous = Ts is None
        self.actuator = actuator
        self.delta_max, self.gain_freeze = delta_max, gain_freeze
        self.omega_max = None
        if check_feasibility and model.params.coriolis == "printed":
            from shipgnc.models.steady_turn import omega_max

            self.omega_max = omega_max(self.model)
        self.signals = (Signal("omega_ref", "rad/s", "yaw-rate reference used by the law"),
                        Signal("fsm_u", "rad/s", "thruster rate asked by the law"))
        self.events: list[dict] = []
        self._last: dict[str, np.ndarray] = {}

    def reset(self, batch_shape) -> None:
        self.events = []
        self._last = {}
        if self.omega_ref is not None:
            self.omega_ref.reset(batch_shape)

    def _event(self, t: float, kind: str, message: str) -> None:
        if all(e["kind"] != kind for e in self.events):
            self.events.append({"time_s": float(t), "kind": kind, "message": message})

    def _message(self, kind: str, value: float) -> str:
        """The text of event ``kind``; ``value`` the batch's largest |ω*| or |δ| at the call."""
        if kind == "omega_ref_above_max":
            return (f"|omega*| = {value:.6g} rad/s exceeds omega_max = {self.omega_max:.6g} "
                    "rad/s: no steady turn with |delta| < 90°")
        if kind == "delta_reached_90":
            return (f"|delta| reached 90° ({math.degrees(value):.2f}°): the FSM gain 1/cos(delta) "
                    "is singular and the thruster keeps turning")
        return (f"thruster angle held at the clamp |delta| = {math.degrees(self.delta_max):.2f}°: "
                "the reference is not reached")

    def law(self, t: float, x: np.ndarray, reference: np.ndarray) -> np.ndarray:
        """The command for a batch of ships: :func:`yaw_rate_fsm_step`'s batch (:func:`rate_law`);
        the events of this call read from the kernel's per-ship records."""
        command, signals, z = rate_law(self, t, x, reference)
        if np.any(np.isnan(signals[..., 0])):
            raise ConfigError("omega_ref = nan: the yaw-rate reference must be finite")
        for j, kind in enumerate(FSM_EVENTS):  # in the order the law checks them
            fired = z[:, 1 + j] >= 0.0
            if np.any(fired):
                self._event(t, kind, self._message(kind, float(z[fired, 7 + j].max())))
        self._last = {"omega_ref": signals[..., 0], "fsm_u": signals[..., 1]}
        return command

    def step(self, t, x, reference):
        return self.law(t, x, reference)

    def signal_values(self) -> dict[str, np.ndarray]:
        return dict(self._last)

    # --- the composed compiled loop ------------------------------------------------------------
    def kernel_reason(self) -> str | None:
        """Why :meth:`kernel` cannot compile this controller (None when it can)."""
        return kernel_params_reason(self.model.params) or source_reason(self.omega_ref)

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`law` for the composed loop (:func:`yaw_rate_fsm_step`, sampled or continuous).

        Parameters ``[law 20?, T_u, h, h L T_v, J, ω_max?, ω_max, freeze?, δ_f, clamp?, δ_max,
        inverse?, T_a, k_a, 0, 0, model, ω* source]`` (``model``: the plant's parameters as
        :func:`~shipgnc.models.catamaran.kernel_params` orders them); per-ship state ``[calls,
        first call (3), time (3), value (3), ω*, u, source state (3)]`` (events in the order the law
        checks them: ω_max, 90°, clamp).
        """
        reason = self.kernel_reason()
        if reason:
            raise NotCompiled(reason)
        batch_shape = tuple(batch_shape)
        columns = law_columns(self)
        source = self.omega_ref
        if source is None:
            block, block_state = _block(RATE_GUIDANCE), np.zeros((*batch_shape, N_RATE_STATE))
        else:
            block, block_state = source.rate_block(batch_shape)
        params = law_params(*self.law_pieces(columns, block), lead=columns.shape[:-1])
        state = self.law_state(batch_shape, block_state)

        def restore(z: np.ndarray) -> None:
            self._restore(z.reshape(-1, FSM_STATE), batch_shape)

        return Kernel(yaw_rate_fsm_step, params, state, restore=restore, continuous=self.continuous)

    # --- what the kernel and its batch share (:func:`rate_law`) ----------------------------------
    @property
    def law_kernel(self):
        return yaw_rate_fsm_step

    def rate_source(self):
        return self.omega_ref

    def law_state(self, lead, source_state) -> np.ndarray:
        """The kernel's initial per-ship state: no call, no event yet, the source's state."""
        state = np.zeros((*lead, FSM_STATE))
        state[..., 1:4] = -1.0
        state[..., FSM_STATE - N_RATE_STATE:] = source_state
        return state

    def law_pieces(self, columns, block) -> list:
        """The kernel's parameters (:meth:`kernel`) from the plant's columns (..., 18)."""
        p = self.model.params
        T_a, k_a = self.actuator if self.actuator is not None else (1.0, 1.0)
        return [float(self.law_number == 20), self.T_u, self.h, self.h * p.L * p.T_v,
                columns[..., 2:3], self.omega_max is not None,
                self.omega_max if self.omega_max is not None else 0.0,
                self.gain_freeze is not None, self.gain_freeze or 0.0,
                self.delta_max is not None, self.delta_max or 0.0,
                self.actuator is not None, T_a, k_a, 0.0, 0.0, columns, block]

    def _restore(self, z: np.ndarray, batch_shape) -> None:
        """``events``, ``signal_values`` and the ω* source as the numpy loop leaves them."""
        if z.shape[0] == 0:
            return
        found = []
        for j, kind in enumerate(FSM_EVENTS):
            first = z[:, 1 + j]
            if not np.any(first >= 0):
                continue
            call = first[first >= 0].min()
            at = first == call  # the ships over the threshold in numpy's first such call
            found.append((call, j, kind, float(z[at, 4 + j][0]), float(z[at, 7 + j].max())))
        self.events = [{"time_s": t, "kind": kind, "message": self._message(kind, value)}
                       for _, _, kind, t, value in sorted(found)]
        if np.any(z[:, 0] > 0):
            self._last = {"omega_ref": z[:, 10].reshape(batch_shape).copy(),
                          "fsm_u": z[:, 11].reshape(batch_shape).copy()}
        if self.omega_ref is not None:
            self.omega_ref.restore_block(z[:, FSM_STATE - N_RATE_STATE:], batch_shape)


#: the events of :func:`yaw_rate_fsm_step`, in the order the law checks them
FSM_EVENTS = ("omega_ref_above_max", "delta_reached_90", "delta_clamped")
#: offsets of :meth:`YawRateFSM.kernel`'s parameters: the model's, the ω* source's
FSM_MODEL = 16
FSM_SOURCE = FSM_MODEL + N_KERNEL_PARAMS
#: length of :meth:`YawRateFSM.kernel`'s per-ship state
FSM_STATE = 12 + N_RATE_STATE


@kernel_function
def _first(z, j, t, value):
    """Record event ``j`` in the per-ship state at its first call (index, time, value)."""
    if z[1 + j] < 0.0:
        z[1 + j], z[4 + j], z[7 + j] = z[0], t, value


@kernel_function
def yaw_rate_fsm_step(t, x, ref, z, p, cmd, sig):
    """:meth:`YawRateFSM.law` for one ship (the one source; the numpy law is its batch): ω* of the source,
    law (20) u = (ω* − ω − h Φ₃)/(T_u W₃₇) or (21) u = (ω* − ω)/(T_u W₃₇) with W₃₇ = h L T_v
    cos δ / J (eq. (19)); cos δ frozen beyond δ_f; u = 0 pushing |δ| beyond δ_max; the command
    u or v_a = (δ + T_a u)/k_a (eq. (23)). Events recorded in ``z`` (see :meth:`YawRateFSM.kernel`)."""
    # the state and the parameters read once, up front, and each output written once: an array
    # whose last use sits inside a conditional (a call in one branch, a write in one branch)
    # keeps numba's reference counting of every array argument in the RK stages' hot path
    z[0] += 1.0
    w = rate_value(t, x, ref, p, FSM_SOURCE, z, FSM_STATE - N_RATE_STATE)
    su, sv, sr, delta = x[U], x[V], x[R], x[DELTA]
    law20, T_u, h, hLT_v, J, check_max, omega_max = p[0], p[1], p[2], p[3], p[4], p[5], p[6]
    if check_max != 0.0 and abs(w) > omega_max:
        _first(z, 0, t, abs(w))
    if abs(delta) >= math.pi / 2:
        _first(z, 1, t, abs(delta))
    cd = math.cos(delta)
    w37 = hLT_v * cd / J
    if law20 != 0.0:
        omega_bar = sr + h * yaw_acceleration_of(su, sv, sr, delta, p, FSM_MODEL)
        u = (w - omega_bar) / (T_u * w37)
    else:
        u = (w - sr) / (T_u * w37)
    freeze, delta_f, clamp, delta_max = p[7], p[8], p[9], p[10]
    inverse, T_a, k_a = p[11], p[12], p[13]
    if freeze != 0.0:
        frozen = clip(delta, -delta_f, delta_f)
        u = u * (cd / math.cos(frozen))
    if clamp != 0.0 and abs(delta) >= delta_max and sign(u) == sign(delta):
        _first(z, 2, t, 0.0)
        u = 0.0
    sig[0], sig[1] = w, u
    z[10], z[11] = w, u
    cmd[0] = (delta + T_a * u) / k_a if inverse != 0.0 else u


def default_gains(preset_name: str) -> tuple[float, float]:
    """(T_u, h) of the document (``paper``) or the consistent-unit tuning (``si``), note 004-4.4."""
    from shipgnc.models.catamaran import FSM_GAINS

    if preset_name not in FSM_GAINS:
        raise ConfigError(f"vessel.preset = {preset_name!r}: unknown preset; allowed: {', '.join(FSM_GAINS)}")
    return FSM_GAINS[preset_name]
