"""Heading reference models (smooth set-point filters): second order, and third order with
rate and acceleration saturation."""

from __future__ import annotations

import math

import numpy as np

from shipgnc.errors import require
from shipgnc.frames import wrap_angle


class HeadingReferenceModel:
    """Second-order heading filter ψ̈_r + 2ζω ψ̇_r + ω² ψ_r = ω² ψ_d.

    ζ = 1 (critically damped) is note 001-1.10's autopilot; document 003 eq. (15) uses ω_n = 0.1,
    ζ = 0.85. Driven by wrap(ψ_d − ψ_r), ψ̈_r = ω² wrap(ψ_d − ψ_r) − 2ζω ψ̇_r, so it turns the
    shortest way round; initialised at the measured heading with ψ̇_r = 0; advanced by explicit
    Euler at the controller's sample time. The controllers that use it step it inside their
    kernels (:func:`~shipgnc.control.heading_speed.heading_speed_step`,
    :func:`~shipgnc.control.course.sliding_mode_step`); this object keeps its parameters and, per
    ship, the state ``psi``, ``rate`` (None before the first sample).
    """

    def __init__(self, omega: float, zeta: float = 1.0):
        require(np.isfinite(omega) and omega > 0, "controller.omega_ref", omega,
                "reference-model bandwidth must be > 0 rad/s")
        require(np.isfinite(zeta) and zeta > 0, "controller.zeta", zeta,
                "reference-model damping ratio must be > 0")
        self.omega = float(omega)
        self.zeta = float(zeta)
        self.psi = None
        self.rate = None

    def reset(self) -> None:
        self.psi = None
        self.rate = None


class ThirdOrderReferenceModel:
    """Third-order heading reference model with rate (and optional acceleration) saturation,
    Fossen (2021) §12.1.1 eq. (12.10): ψ_r/ψ_d = ω³ / ((s + ω)(s² + 2ζωs + ω²)), i.e.

        ψ_r⃛ = ω³ wrap(ψ_d − ψ_r) − (2ζ + 1)ω² r_r − (2ζ + 1)ω a_r,   ψ̇_r = r_r,  ṙ_r = a_r

    with the saturating elements of Fossen's reference models: |r_r| ≤ r_max and, optionally,
    |a_r| ≤ a_max. A saturated channel is held at its limit for as long as the model pushes it
    outward (conditional integration), and the acceleration that would push the rate past r_max is
    zero: while the rate is saturated ψ_r is a ramp of slope ±r_max with r_r = ±r_max, a_r = 0, so
    a large step becomes a ramp and ψ_r, r_r, a_r stay consistent feed-forward signals for a
    heading autopilot. The linear part leaves the limit when the jerk turns inward, i.e. once
    |wrap(ψ_d − ψ_r)| ≤ (2ζ + 1) r_max / ω (with a_r = 0).

    Driven by wrap(ψ_d − ψ_r): it turns the shortest way round; ψ_r itself is not wrapped.

    **Discretisation** (``step(psi_d, Ts)``, ψ_d held over the sample, zero-order hold): away from
    the limits the linear model is advanced by its exact transition matrix Φ = exp(A·Ts) (scipy's
    ``expm``), so the unsaturated response equals the continuous one at the samples to round-off
    for any Ts; on a limit the held channel is integrated exactly (ramp, or constant acceleration
    up to the rate limit). A step that crosses a limit inside the sample is clipped at its end:
    the only discretisation error, first order in Ts in a_r and smaller in ψ_r.
    Batched: the state arrays take the batch shape.
    """

    def __init__(self, omega_n: float, zeta: float = 1.0, r_max: float = math.inf,
                 a_max: float | None = None):
        require(_is_number(omega_n) and math.isfinite(omega_n) and omega_n > 0,
                "reference_model.omega_n", omega_n, "natural frequency must be a finite number > 0 rad/s")
        require(_is_number(zeta) and math.isfinite(zeta) and zeta > 0, "reference_model.zeta",
                zeta, "relative damping ratio must be a finite number > 0")
        require(_is_number(r_max) and r_max > 0, "reference_model.r_max", r_max,
                "rate limit must be > 0 rad/s (math.inf: no rate saturation)")
        require(a_max is None or (_is_number(a_max) and a_max > 0), "reference_model.a_max", a_max,
                "acceleration limit must be > 0 rad/s² (None: no acceleration saturation)")
        self.omega_n = float(omega_n)
        self.zeta = float(zeta)
        self.r_max = float(r_max)
        self.a_max = math.inf if a_max is None else float(a_max)
        w, k = self.omega_n, 2.0 * self.zeta + 1.0
        #: companion matrix of the error state [ψ_r − ψ_d, r_r, a_r]
        self.A = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [-w**3, -k * w * w, -k * w]])
        self._phi: dict[float, np.ndarray] = {}
        self.psi = None
        self.rate = None
        self.acc = None

    def reset(self) -> None:
        self.psi = self.rate = self.acc = None

    def start(self, psi_measured, rate=0.0, acc=0.0) -> None:
        """Initialise at the measured heading (rate and acceleration 0 unless given); a no-op once
        started."""
        if self.psi is None:
            self.psi = np.array(psi_measured, dtype=float, copy=True)
            self.rate = np.broadcast_to(np.asarray(rate, dtype=float), self.psi.shape).copy()
            self.acc = np.broadcast_to(np.asarray(acc, dtype=float), self.psi.shape).copy()

    def transition(self, Ts: float) -> np.ndarray:
        """Φ = exp(A·Ts) of the linear model (cached per Ts)."""
        require(_is_number(Ts) and math.isfinite(Ts) and Ts > 0, "reference_model.Ts", Ts,
                "sample time must be > 0 s")
        phi = self._phi.get(float(Ts))
        if phi is None:
            from scipy import linalg

            phi = self._phi[float(Ts)] = linalg.expm(self.A * float(Ts))
        return phi

    def jerk(self, e, rate, acc):
        """ψ_r⃛ = ω³ e − (2ζ + 1)ω² r_r − (2ζ + 1)ω a_r for the wrapped error e = wrap(ψ_d − ψ_r)."""
        return -(self.A[2, 0] * e) + self.A[2, 1] * rate + self.A[2, 2] * acc

    def step(self, psi_d, Ts: float):
        """Advance one sample with ψ_d held; return the new (ψ_r, r_r, a_r)."""
        require(self.psi is not None, "reference_model", "ThirdOrderReferenceModel",
                "call start(psi_measured) first")
        phi = self.transition(Ts)
        r_max, a_max = self.r_max, self.a_max
        psi, rate, acc = self.psi, self.rate, self.acc
        e = wrap_angle(np.asarray(psi_d, dtype=float) - psi)
        # on the rate limit the acceleration may only turn the rate back
        s_r = np.sign(rate)
        on_r = np.abs(rate) >= r_max
        acc = np.where(on_r & (acc * s_r > 0), 0.0, acc)
        hold_r = on_r & (acc == 0) & (self.jerk(e, rate, acc) * s_r >= 0)
        s_a = np.sign(acc)
        hold_a = ~hold_r & (np.abs(acc) >= a_max) & (self.jerk(e, rate, acc) * s_a >= 0)
        # linear: exact transition of the error state x̃ = [ψ_r − ψ_d, r_r, a_r]
        x = -e
        lin_psi = psi + e + phi[0, 0] * x + phi[0, 1] * rate + phi[0, 2] * acc
        lin_rate = phi[1, 0] * x + phi[1, 1] * rate + phi[1, 2] * acc
        lin_acc = phi[2, 0] * x + phi[2, 1] * rate + phi[2, 2] * acc
        # acceleration held at ±a_max: exact, up to the rate limit if it is reached in the sample
        a = np.where(hold_a, acc, 0.0)
        free_rate = rate + a * Ts
        with np.errstate(divide="ignore", invalid="ignore"):
            tau = np.where(np.abs(free_rate) > r_max, (np.sign(a) * r_max - rate) / a, Ts)
        tau = np.clip(np.nan_to_num(tau, nan=Ts), 0.0, Ts)
        acc_psi = psi + rate * tau + 0.5 * a * tau * tau + (rate + a * tau) * (Ts - tau)
        acc_rate = rate + a * tau
        new_psi = np.where(hold_r, psi + rate * Ts, np.where(hold_a, acc_psi, lin_psi))
        new_rate = np.where(hold_r, rate, np.where(hold_a, acc_rate, lin_rate))
        new_acc = np.where(hold_r, 0.0, np.where(hold_a, acc, lin_acc))
        new_acc = np.clip(new_acc, -a_max, a_max)
        over = np.abs(new_rate) >= r_max
        s = np.sign(new_rate)
        new_rate = np.where(over, s * r_max, new_rate)
        new_acc = np.where(over & (new_acc * s > 0), 0.0, new_acc)
        self.psi, self.rate, self.acc = new_psi, new_rate, new_acc
        return new_psi, new_rate, new_acc

    def response(self, psi_d, Ts: float, psi0=0.0):
        """Run from ψ_r = ``psi0`` (rate and acceleration 0) through the set-points ``psi_d``
        (shape (n, *batch), ψ_d[k] held over [k·Ts, (k+1)·Ts)); return ψ_r, r_r, a_r at the
        n + 1 samples, each of shape (n + 1, *batch). Leaves the model at the last sample."""
        psi_d = np.asarray(psi_d, dtype=float)
        self.reset()
        self.start(np.broadcast_to(np.asarray(psi0, dtype=float), psi_d.shape[1:]))
        out = [(self.psi, self.rate, self.acc)]
        for target in psi_d:
            out.append(self.step(target, Ts))
        return tuple(np.stack(series) for series in zip(*out, strict=True))


def _is_number(value) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool) \
        and not math.isnan(float(value))
