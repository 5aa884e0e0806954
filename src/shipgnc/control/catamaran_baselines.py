"""Classical baselines for document 004's catamaran on the same plant (spec 004 §4.11.3).

* :class:`YawRatePI` — a fixed-gain PI yaw-rate controller with the bandwidth of law (20):
  law (20) with cos δ frozen at 1, i.e. δ̇ = K_i (ω* − ω) − K_p ṙ with K_i = J/(T_u h L T_v),
  K_p = J/(T_u L T_v) (``si``: K_i = 2.223, K_p = 5.558 s); in position form
  δ = K_i ∫(ω* − ω) dt − K_p ω. ṙ is the model's Φ₃ at the measured state, as in law (20).
* :class:`HeadingLQR` — a heading autopilot designed with ``control.lqr`` on the linearisation
  about straight running (4.42 m/s), state [v, r, ψ − ψ_r, δ], input δ̇. Since δ integrates δ̇,
  the law δ̇ = −K x is a PID on the heading error (I on e_ψ, P through r, D through ṙ ~ δ) with
  sway feedback. The heading reference is the ramp of the capture profile (17).

Both are stateless continuous laws (their integral is the physical δ), like the FSM laws, so the
comparison runs them in the same ``continuous`` mode. Each has a kernel for the composed compiled
loop (:func:`yaw_rate_pi_step`, :func:`heading_lqr_step`; ω* and the heading capture's latch by
:func:`~shipgnc.control.finite_state.rate_value`, as the FSM laws).
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.batchmath import row_dot
from shipgnc.control.finite_state import (
    N_RATE_STATE,
    HeadingCapture,
    as_rate_reference,
    rate_value,
    source_reason,
)
from shipgnc.errors import require
from shipgnc.frames import wrap_angle
from shipgnc.kernels import Kernel, NotCompiled, clip, flat, kernel_function, sign, wrap
from shipgnc.models.base import Signal
from shipgnc.models.catamaran import (
    DELTA,
    N_KERNEL_PARAMS,
    PSI,
    Catamaran,
    R,
    V,
    catamaran_yaw_acceleration,
    kernel_params,
    kernel_params_reason,
    linearize,
    straight_running_state,
)


def pi_gains(params, T_u: float, h: float) -> tuple[float, float]:
    """(K_i [1/s... rad/(rad/s)/s], K_p [s]) = (J/(T_u h L T_v), J/(T_u L T_v)) of the equal-bandwidth PI."""
    k = params.J / (params.L * params.T_v)
    return k / (T_u * h), k / T_u


class YawRatePI:
    """Fixed-gain PI yaw-rate controller (law (20) without the 1/cos δ scheduling)."""

    def __init__(self, model: Catamaran, *, T_u: float, h: float, omega_ref, Ts: float | None = None):
        require(T_u > 0 and h > 0, "controller.T_u/h", (T_u, h), "must be > 0 s")
        self.model = model
        self.K_i, self.K_p = pi_gains(model.params, T_u, h)
        self.omega_ref = as_rate_reference(omega_ref)
        self.Ts, self.continuous = Ts, Ts is None
        self.signals = (Signal("omega_ref", "rad/s", "yaw-rate reference"),)
        self.events: list[dict] = []
        self._last: dict = {}

    def reset(self, batch_shape) -> None:
        self.omega_ref.reset(batch_shape)
        self.events = []

    def law(self, t, x, reference):
        w = self.omega_ref.value(t, x)
        u = self.K_i * (w - x[..., R]) - self.K_p * self.model.yaw_acceleration(x)
        self._last = {"omega_ref": w}
        return u[..., None]

    step = law

    def signal_values(self):
        return dict(self._last)

    def kernel_reason(self) -> str | None:
        """Why :meth:`kernel` cannot compile this controller (None when it can)."""
        return kernel_params_reason(self.model.params) or source_reason(self.omega_ref)

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`law` for the composed loop (:func:`yaw_rate_pi_step`): parameters ``[K_i, K_p,
        model, ω* source]``, per-ship state ``[calls, ω*, source state]``."""
        reason = self.kernel_reason()
        if reason:
            raise NotCompiled(reason)
        batch_shape = tuple(batch_shape)
        block, block_state = self.omega_ref.rate_block(batch_shape)
        state = np.zeros((*batch_shape, 2 + N_RATE_STATE))
        state[..., 2:] = block_state

        def restore(z: np.ndarray) -> None:
            z = z.reshape(-1, 2 + N_RATE_STATE)
            if z.shape[0] and np.any(z[:, 0] > 0):
                self._last = {"omega_ref": z[:, 1].reshape(batch_shape).copy()}
            self.omega_ref.restore_block(z[:, 2:], batch_shape)

        return Kernel(yaw_rate_pi_step, flat(self.K_i, self.K_p, kernel_params(self.model.params),
                                             block), state, restore=restore,
                      continuous=self.continuous)


#: offset of the ω* source's parameters in :meth:`YawRatePI.kernel`
PI_SOURCE = 2 + N_KERNEL_PARAMS


@kernel_function
def yaw_rate_pi_step(t, x, ref, z, p, cmd, sig):
    """One :meth:`YawRatePI.law` for one ship: δ̇ = K_i (ω* − ω) − K_p Φ₃ (law (20) with
    cos δ = 1, spec 004 §4.11.3), operation for operation."""
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

    def heading_reference(self, t, x):
        r_ref = self.capture.value(t, x)
        cap = self.capture
        diff = wrap_angle(cap.psi_target - cap.psi0)
        t_star = cap.switch_time()
        psi_ref = cap.psi0 + np.sign(diff) * cap.omega_c * np.clip(t - cap.t0, 0.0, t_star - cap.t0)
        return psi_ref, r_ref

    def law(self, t, x, reference):
        psi_ref, r_ref = self.heading_reference(t, x)
        err = np.stack([x[..., V], x[..., R] - r_ref, wrap_angle(x[..., PSI] - psi_ref), x[..., DELTA]], -1)
        self._last = {"psi_ref": psi_ref}
        return -row_dot(err, self.K)[..., None]

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
        batch_shape = tuple(batch_shape)
        block, block_state = self.capture.rate_block(batch_shape)
        state = np.zeros((*batch_shape, 2 + N_RATE_STATE))
        state[..., 2:] = block_state

        def restore(z: np.ndarray) -> None:
            z = z.reshape(-1, 2 + N_RATE_STATE)
            if z.shape[0] and np.any(z[:, 0] > 0):
                self._last = {"psi_ref": z[:, 1].reshape(batch_shape).copy()}
            self.capture.restore_block(z[:, 2:], batch_shape)

        return Kernel(heading_lqr_step, flat(np.ravel(self.K), block), state, restore=restore,
                      continuous=self.continuous)


@kernel_function
def heading_lqr_step(t, x, ref, z, p, cmd, sig):
    """One :meth:`HeadingLQR.law` for one ship, operation for operation: the ramp ψ_r = K(t₀) +
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
