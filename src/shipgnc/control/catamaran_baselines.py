"""Classical baselines for document 004's catamaran on the same plant (note 004-4.11.3).

* :class:`YawRatePI` — a fixed-gain PI yaw-rate controller with the bandwidth of law (20):
  law (20) with cos δ frozen at 1, i.e. δ̇ = K_i (ω* − ω) − K_p ṙ with K_i = J/(T_u h L T_v),
  K_p = J/(T_u L T_v) (``si``: K_i = 2.223, K_p = 5.558 s); in position form
  δ = K_i ∫(ω* − ω) dt − K_p ω. ṙ is the model's Φ₃ at the measured state, as in law (20).
* :class:`HeadingLQR` — a heading autopilot designed with ``control.lqr`` on the linearisation
  about straight running (4.42 m/s), state [v, r, ψ − ψ_r, δ], input δ̇. Since δ integrates δ̇,
  the law δ̇ = −K x is a PID on the heading error (I on e_ψ, P through r, D through ṙ ~ δ) with
  sway feedback. The heading reference is the ramp of the capture profile (17).

Both are kept as named reproductions (the note 004-4.11.3 baselines): the "PI" is law (20) with
cos δ frozen, and the LQR's dominant poles (−0.043 ± 0.006j s⁻¹) are ten times slower than the
FSM. The comparison's baselines of record are designed for the FSM's bandwidth:

* :class:`PolePlacementRate` — state feedback on the linearised sway–yaw model about straight
  running, augmented with the yaw-rate error integral ξ = ∫(r − ω*) dt (= ψ − ψ_ref), the
  closed-loop poles placed with ``control.acker`` at the FSM's time constants −1/T_u, −1/h and a
  non-dominant sway pole at −2/min(T_u, h) (:func:`place_rate_gain`). In rate form
  δ̇ = −k_v v̇ − k_r ṙ − k_ξ (r − ω*) (stateless; its integral is the physical δ), so it runs the
  yaw-rate cases (S3, S4) and, with the capture's ω*(t) of (17), the heading case S7.
* :class:`DesignedPI` — a PI on the first-order (Nomoto) yaw-rate model T ṙ + r = K δ fitted to the
  same linearisation (:func:`nomoto_model`), its two closed-loop poles placed at −1/T_u, −1/h
  (:func:`designed_pi_gains`), in I-P velocity form δ̇ = K_i (ω* − r) − K_p ṙ with anti-windup
  at the thruster-angle limit δ_max (the integrator — δ itself — stops when |δ| ≥ δ_max and the
  command pushes further).

All are stateless continuous laws (their integral is the physical δ), like the FSM laws, so the
comparison runs them in the same ``continuous`` mode. Each is written once, as a scalar kernel
(:func:`yaw_rate_pi_step`, :func:`pole_placement_step`, :func:`designed_pi_step`,
:func:`heading_lqr_step`; ω* and the heading capture's latch by
:func:`~shipgnc.control.finite_state.rate_value`, as the FSM laws): the composed loop calls it, and
the numpy ``law`` is its batch (:func:`~shipgnc.control.finite_state.rate_law`).
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.control.finite_state import (
    N_RATE_STATE,
    HeadingCapture,
    as_rate_reference,
    law_columns,
    law_params,
    per_ship_value,
    rate_law,
    rate_value,
    source_reason,
)
from shipgnc.errors import require
from shipgnc.kernels import Kernel, NotCompiled, clip, kernel_function, sign, wrap
from shipgnc.models.base import Signal
from shipgnc.models.catamaran import (
    DELTA,
    N_KERNEL_PARAMS,
    PSI,
    Catamaran,
    R,
    U,
    V,
    _hull_forces,
    catamaran_yaw_acceleration,
    kernel_params_reason,
    linearize,
    straight_running_state,
)


def pi_gains(params, T_u: float, h: float) -> tuple[float, float]:
    """(K_i [1/s... rad/(rad/s)/s], K_p [s]) = (J/(T_u h L T_v), J/(T_u L T_v)) of the equal-bandwidth PI."""
    k = params.J / (params.L * params.T_v)
    return k / (T_u * h), k / T_u

def rate_source_kernel(controller, function, batch_shape, *, signal: str = "omega_ref") -> Kernel:
    """The :class:`Kernel` of a law fed by a reference source (``controller.rate_source()``):
    parameters ``controller.law_pieces(model, source block)``, per-ship state ``[calls, last
    reference, source state]``; its ``restore`` hands the last reference (logged as ``signal``) and
    the source's state back to the numpy objects."""
    source = controller.rate_source()
    batch_shape = tuple(batch_shape)
    block, block_state = source.rate_block(batch_shape)
    columns = law_columns(controller)
    params = law_params(*controller.law_pieces(columns, block), lead=columns.shape[:-1])

    def restore(z: np.ndarray) -> None:
        z = z.reshape(-1, 2 + N_RATE_STATE)
        if z.shape[0] and np.any(z[:, 0] > 0):
            controller._last = {signal: z[:, 1].reshape(batch_shape).copy()}
        source.restore_block(z[:, 2:], batch_shape)

    return Kernel(function, params, controller.law_state(batch_shape, block_state), restore=restore,
                  continuous=controller.continuous)


class _RateSourceLaw:
    """What the yaw-rate laws fed by a ω* source share: the source, the sampling (``Ts`` None:
    continuous, evaluated in every RK stage), the logged ω*, no events of their own; the numpy
    ``law`` is the batch of the kernel (:func:`~shipgnc.control.finite_state.rate_law`)."""

    #: the law reads the plant's parameters (``model``) in its kernel
    uses_model = True

    def _init_rate_source(self, omega_ref, Ts) -> None:
        self.omega_ref = as_rate_reference(omega_ref)
        self.Ts, self.continuous = Ts, Ts is None
        self.signals = (Signal("omega_ref", "rad/s", "yaw-rate reference"),)
        self.events: list[dict] = []
        self._last: dict = {}

    def reset(self, batch_shape) -> None:
        self.rate_source().reset(batch_shape)
        self.events = []

    def law(self, t, x, reference):
        command, signals, _ = rate_law(self, t, x, reference)
        self._last = {self.signals[0].name: signals[..., 0]}
        return command

    def step(self, t, x, reference):
        return self.law(t, x, reference)

    def signal_values(self):
        return dict(self._last)

    def rate_source(self):
        return self.omega_ref

    def law_state(self, lead, source_state) -> np.ndarray:
        """The kernel's initial per-ship state ``[calls, last reference, source state]``."""
        state = np.zeros((*lead, 2 + N_RATE_STATE))
        state[..., 2:] = source_state
        return state


class YawRatePI(_RateSourceLaw):
    """Fixed-gain PI yaw-rate controller (law (20) without the 1/cos δ scheduling)."""

    def __init__(self, model: Catamaran, *, T_u: float, h: float, omega_ref, Ts: float | None = None):
        require(T_u > 0 and h > 0, "controller.T_u/h", (T_u, h), "must be > 0 s")
        self.model = model
        self.K_i, self.K_p = pi_gains(model.params, T_u, h)
        self._init_rate_source(omega_ref, Ts)

    def kernel_reason(self) -> str | None:
        """Why :meth:`kernel` cannot compile this controller (None when it can)."""
        return kernel_params_reason(self.model.params) or source_reason(self.omega_ref)

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`law` for the composed loop (:func:`yaw_rate_pi_step`): parameters ``[K_i, K_p,
        model, ω* source]``, per-ship state ``[calls, ω*, source state]``."""
        reason = self.kernel_reason()
        if reason:
            raise NotCompiled(reason)
        return rate_source_kernel(self, yaw_rate_pi_step, batch_shape)

    law_kernel = property(lambda self: yaw_rate_pi_step)

    def law_pieces(self, columns, block) -> list:
        return [per_ship_value(self.K_i), per_ship_value(self.K_p), columns, block]


#: offset of the ω* source's parameters in :meth:`YawRatePI.kernel`
PI_SOURCE = 2 + N_KERNEL_PARAMS


@kernel_function
def yaw_rate_pi_step(t, x, ref, z, p, cmd, sig):
    """One :meth:`YawRatePI.law` for one ship: δ̇ = K_i (ω* − ω) − K_p Φ₃ (law (20) with
    cos δ = 1, note 004-4.11.3); the numpy law is its batch."""
    z[0] += 1.0
    w = rate_value(t, x, ref, p, PI_SOURCE, z, 2)
    u = p[0] * (w - x[R]) - p[1] * catamaran_yaw_acceleration(x, p, 2)
    z[1] = w
    sig[0] = w
    cmd[0] = u


def heading_lqr_gain(model: Catamaran, q=(0.0, 1.0e3, 1.0, 0.0), r: float = 1.0e3) -> np.ndarray:
    """LQR gain K (1×4) on [v, r, ψ, δ] with input δ̇ about straight running (python-control)."""
    import control

    A, B = linearize(model, straight_running_state(model.params))
    keep = [V, R, PSI, DELTA]
    K, _, _ = control.lqr(A[np.ix_(keep, keep)], B[keep], np.diag(q), np.array([[r]]))
    return np.asarray(K)[0]


class HeadingLQR:
    """Heading autopilot δ̇ = −K [v, r − r_r, wrap(ψ − ψ_r), δ] with the ramp reference of (17)."""

    def __init__(self, model: Catamaran, psi_target: float, omega_c: float = 0.0022, *, gain=None,
                 Ts: float | None = None):
        self.model = model
        self.K = heading_lqr_gain(model) if gain is None else np.asarray(gain, dtype=float)
        self.capture = HeadingCapture(psi_target, omega_c)
        self.Ts, self.continuous = Ts, Ts is None
        self.signals = (Signal("psi_ref", "rad", "heading reference (ramp)", angle=True),)
        self.events: list[dict] = []
        self._last: dict = {}

    def reset(self, batch_shape) -> None:
        self.capture.reset(batch_shape)
        self.events = []

    def law(self, t, x, reference):
        command, signals, _ = rate_law(self, t, x, reference)
        self._last = {"psi_ref": signals[..., 0]}
        return command

    step = law

    def signal_values(self):
        return dict(self._last)

    def kernel_reason(self) -> str | None:
        """Why :meth:`kernel` cannot compile this controller (None when it can)."""
        if np.size(self.K) != 4:
            return f"gain of {np.size(self.K)} values (need 4)"
        return None

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`law` for the composed loop (:func:`heading_lqr_step`): parameters ``[K (4),
        capture]``, per-ship state ``[calls, ψ_r, capture state]`` (K(t₀) latched there)."""
        reason = self.kernel_reason()
        if reason:
            raise NotCompiled(reason)
        return rate_source_kernel(self, heading_lqr_step, batch_shape, signal="psi_ref")

    # --- what the kernel and its batch share (:func:`~shipgnc.control.finite_state.rate_law`) ---
    uses_model = False
    law_kernel = property(lambda self: heading_lqr_step)
    law_state = _RateSourceLaw.law_state

    def rate_source(self):
        return self.capture

    def law_pieces(self, columns, block) -> list:
        require(np.size(self.K) == 4, "controller.gain", np.ravel(self.K).tolist(),
                "need 4 values (v, r, heading error, delta)")
        return [np.ravel(self.K), block]


@kernel_function
def heading_lqr_step(t, x, ref, z, p, cmd, sig):
    """:meth:`HeadingLQR.law` for one ship (the numpy law is its batch): the ramp ψ_r = K(t₀) +
    sign(ΔK) ω_c clip(t − t₀, 0, t* − t₀) and ω* of the capture (17), then
    δ̇ = −K [v, r − ω*, wrap(ψ − ψ_r), δ] summed left to right (:func:`~shipgnc.batchmath.row_dot`)."""
    z[0] += 1.0
    r_ref = rate_value(t, x, ref, p, 4, z, 2)  # the capture's block at p[4:], its state at z[2:]
    psi_target, omega_c, t0 = p[5], p[6], p[7]
    psi0 = z[4] if z[3] != 0.0 else math.nan  # numpy: K(t0) unknown is an error (t0 = 0 here)
    diff = wrap(psi_target - psi0)
    t_star = t0 + abs(diff) / omega_c
    psi_ref = psi0 + sign(diff) * omega_c * clip(t - t0, 0.0, t_star - t0)
    total = x[V] * p[0]
    total = total + (x[R] - r_ref) * p[1]
    total = total + wrap(x[PSI] - psi_ref) * p[2]
    total = total + x[DELTA] * p[3]
    z[1] = psi_ref
    sig[0] = psi_ref
    cmd[0] = -total


# --- equal-bandwidth baselines --------------------------------------------------------------------
#: default thruster-angle limit of :class:`DesignedPI`'s anti-windup [rad] (85°, note 004-4.11.1 [A])
DELTA_LIMIT = math.radians(85.0)


def sway_yaw_linearisation(model: Catamaran) -> tuple[np.ndarray, np.ndarray]:
    """(A, B) of [v, r] with the thruster angle δ as the input, linearised about straight running
    at the top speed (δ = 0): A = ∂(v̇, ṙ)/∂(v, r), B = ∂(v̇, ṙ)/∂δ (:func:`linearize`)."""
    A, _ = linearize(model, straight_running_state(model.params))
    keep = [V, R]
    return A[np.ix_(keep, keep)], A[keep, DELTA][:, None]


def fsm_poles(T_u: float, h: float) -> tuple[float, float]:
    """The FSM's closed-loop poles: the criterion's −1/T_u and the prediction's −1/h [1/s]
    (law (20): the predicted rate ω̄ = ω + h ω̇ approaches ω* with time constant T_u, so
    ω/ω* ≈ 1/((1 + T_u s)(1 + h s)); notes 004-4.5–004-4.6)."""
    return -1.0 / T_u, -1.0 / h


def place_rate_gain(model: Catamaran, T_u: float, h: float, sway_pole: float | None = None) -> np.ndarray:
    """Gain K = [k_v, k_r, k_ξ] of δ = −K [v, r, ξ], ξ̇ = r − ω*, placing the poles of the augmented
    linear model at −1/T_u, −1/h and ``sway_pole`` (default −2/min(T_u, h)) with ``control.acker``."""
    import control

    A2, B2 = sway_yaw_linearisation(model)
    Aa = np.zeros((3, 3))
    Aa[:2, :2] = A2
    Aa[2, 1] = 1.0
    Ba = np.vstack([B2, [[0.0]]])
    poles = [*fsm_poles(T_u, h), -2.0 / min(T_u, h) if sway_pole is None else sway_pole]
    return np.asarray(control.acker(Aa, Ba, poles), dtype=float).ravel()


def place_rate_closed_loop(model: Catamaran, gain) -> np.ndarray:
    """Eigenvalues of the augmented linear model [v, r, ξ] under δ = −K [v, r, ξ] (sorted)."""
    A2, B2 = sway_yaw_linearisation(model)
    Aa = np.zeros((3, 3))
    Aa[:2, :2] = A2
    Aa[2, 1] = 1.0
    Ba = np.vstack([B2, [[0.0]]])
    eig = np.linalg.eigvals(Aa - Ba @ np.asarray(gain, dtype=float)[None, :])
    return eig[np.lexsort((eig.imag, eig.real))]


def nomoto_model(model: Catamaran) -> tuple[float, float]:
    """First-order (Nomoto) fit (K [1/s], T [s]) of δ → r of :func:`sway_yaw_linearisation`:
    K the DC gain, T the time at which the linear step response reaches 1 − e⁻¹ of K (a fit that
    holds for the consistent hull's real poles and the printed-sign hulls' complex pair alike)."""
    A2, B2 = sway_yaw_linearisation(model)
    K = float(-(np.array([[0.0, 1.0]]) @ np.linalg.solve(A2, B2))[0, 0])
    require(K > 0, "nomoto_model", K, "the yaw-rate DC gain must be > 0 (a directionally stable hull)")
    slowest = float(np.min(np.abs(np.linalg.eigvals(A2).real)))
    t = np.linspace(0.0, 12.0 / slowest, 24001)
    # r(t) of the unit step: r = C A⁻¹ (e^{At} − I) B, by eigendecomposition
    lam, W = np.linalg.eig(A2)
    c = np.linalg.solve(W, np.linalg.solve(A2, B2))[:, 0]
    r = np.real((W[1, :] * c) @ (np.exp(np.outer(lam, t)) - 1.0))
    k = int(np.argmax(r >= (1.0 - math.exp(-1.0)) * K))
    T = float(np.interp((1.0 - math.exp(-1.0)) * K, r[k - 1:k + 1], t[k - 1:k + 1]))
    return K, T


def designed_pi_gains(model: Catamaran, T_u: float, h: float) -> tuple[float, float]:
    """(K_i [1/s], K_p [s]) of the PI on the Nomoto model T ṙ + r = K δ whose closed
    loop T s² + (1 + K K_p) s + K K_i has its poles at −1/T_u and −1/h:
    K_p = (T (1/T_u + 1/h) − 1)/K, K_i = T/(K T_u h)."""
    K, T = nomoto_model(model)
    return T / (K * T_u * h), (T * (1.0 / T_u + 1.0 / h) - 1.0) / K


class PolePlacementRate(_RateSourceLaw):
    """Equal-bandwidth pole placement: δ̇ = −k_v v̇ − k_r ṙ − k_ξ (r − ω*) (see the module docstring);
    v̇ and ṙ are the model's at the measured state, as law (20) uses Φ₃."""

    def __init__(self, model: Catamaran, *, T_u: float, h: float, omega_ref, gain=None,
                 Ts: float | None = None):
        require(T_u > 0 and h > 0, "controller.T_u/h", (T_u, h), "must be > 0 s")
        self.model = model
        self.T_u, self.h = float(T_u), float(h)
        self.K = place_rate_gain(model, T_u, h) if gain is None else np.asarray(gain, dtype=float)
        self._init_rate_source(omega_ref, Ts)

    def kernel_reason(self) -> str | None:
        """Why :meth:`kernel` cannot compile this controller (None when it can)."""
        if self.model.params.delta_row != "rate":
            return "pole placement on a lag-row plant (its v̇ needs the rate row)"
        return kernel_params_reason(self.model.params) or source_reason(self.omega_ref)

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`law` for the composed loop (:func:`pole_placement_step`): parameters ``[K (3),
        model, ω* source]``, per-ship state ``[calls, ω*, source state]``."""
        reason = self.kernel_reason()
        if reason:
            raise NotCompiled(reason)
        return rate_source_kernel(self, pole_placement_step, batch_shape)

    law_kernel = property(lambda self: pole_placement_step)

    def law_pieces(self, columns, block) -> list:
        require(np.size(self.K) == 3, "controller.gain", np.ravel(self.K).tolist(),
                "need 3 values (k_v, k_r, k_xi)")
        return [np.ravel(self.K), columns, block]


#: offsets in :meth:`PolePlacementRate.kernel`'s parameters: the model's, the ω* source's
PLACE_MODEL = 3
PLACE_SOURCE = PLACE_MODEL + N_KERNEL_PARAMS


@kernel_function
def pole_placement_step(t, x, ref, z, p, cmd, sig):
    """:meth:`PolePlacementRate.law` for one ship (the numpy law is its batch):
    δ̇ = −k_v v̇ − k_r ṙ − k_ξ (r − ω*) with v̇, ṙ of :func:`~shipgnc.models.catamaran.catamaran_rhs`
    (no disturbance)."""
    z[0] += 1.0
    w = rate_value(t, x, ref, p, PLACE_SOURCE, z, 2)
    o = PLACE_MODEL
    _, Y, N = _hull_forces(x[U], x[V], x[R], p, o)
    sd = math.sin(x[DELTA])
    v_dot = (Y - p[o + 7] * sd + 0.0) / p[o + 1]
    r_dot = (N + p[o + 8] * sd + 0.0) / p[o + 2]
    u = -p[0] * v_dot - p[1] * r_dot - p[2] * (x[R] - w)
    z[1] = w
    sig[0] = w
    cmd[0] = u


class DesignedPI(_RateSourceLaw):
    """PI yaw-rate controller designed on the Nomoto model for the FSM's poles, with anti-windup
    (see the module docstring): δ̇ = K_i (ω* − r) − K_p ṙ, and δ̇ = 0 when |δ| ≥ δ_max and the
    command pushes |δ| further."""

    def __init__(self, model: Catamaran, *, T_u: float, h: float, omega_ref,
                 delta_max: float | None = DELTA_LIMIT, gains: tuple[float, float] | None = None,
                 Ts: float | None = None):
        require(T_u > 0 and h > 0, "controller.T_u/h", (T_u, h), "must be > 0 s")
        require(delta_max is None or 0 < delta_max <= math.pi / 2, "controller.delta_max", delta_max,
                "need 0 < delta_max <= pi/2 rad")
        self.model = model
        self.T_u, self.h = float(T_u), float(h)
        self.K_i, self.K_p = designed_pi_gains(model, T_u, h) if gains is None else gains
        self.delta_max = delta_max
        self._init_rate_source(omega_ref, Ts)

    def kernel_reason(self) -> str | None:
        """Why :meth:`kernel` cannot compile this controller (None when it can)."""
        return kernel_params_reason(self.model.params) or source_reason(self.omega_ref)

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`law` for the composed loop (:func:`designed_pi_step`): parameters ``[K_i, K_p,
        clamp?, δ_max, model, ω* source]``, per-ship state ``[calls, ω*, source state]``."""
        reason = self.kernel_reason()
        if reason:
            raise NotCompiled(reason)
        return rate_source_kernel(self, designed_pi_step, batch_shape)

    law_kernel = property(lambda self: designed_pi_step)

    def law_pieces(self, columns, block) -> list:
        return [per_ship_value(self.K_i), per_ship_value(self.K_p), float(self.delta_max is not None),
                self.delta_max or 0.0, columns, block]


#: offsets in :meth:`DesignedPI.kernel`'s parameters: the model's, the ω* source's
DPI_MODEL = 4
DPI_SOURCE = DPI_MODEL + N_KERNEL_PARAMS


@kernel_function
def designed_pi_step(t, x, ref, z, p, cmd, sig):
    """:meth:`DesignedPI.law` for one ship (the numpy law is its batch): δ̇ = K_i (ω* − r) − K_p Φ₃,
    set to 0 when |δ| ≥ δ_max and sign(δ̇) = sign(δ) (anti-windup)."""
    z[0] += 1.0
    w = rate_value(t, x, ref, p, DPI_SOURCE, z, 2)
    u = p[0] * (w - x[R]) - p[1] * catamaran_yaw_acceleration(x, p, DPI_MODEL)
    delta = x[DELTA]
    clamp, delta_max = p[2], p[3]  # read before the branch: no reference counting of p
    if clamp != 0.0 and abs(delta) >= delta_max and sign(u) == sign(delta):
        u = 0.0
    z[1] = w
    sig[0] = w
    cmd[0] = u
