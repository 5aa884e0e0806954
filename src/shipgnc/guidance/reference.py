"""Second-order reference models (smooth set-point filters)."""

from __future__ import annotations

import numpy as np

from shipgnc.errors import require
from shipgnc.frames import wrap_angle


class HeadingReferenceModel:
    """Critically damped heading filter ψ̈_r + 2ω ψ̇_r + ω² ψ_r = ω² ψ_d (spec 001 §1.10).

    Driven by wrap(ψ_d − ψ_r), so it turns the shortest way round; initialised at the measured
    heading with ψ̇_r = 0; advanced by explicit Euler at the controller's sample time.
    Batched: the state arrays take the batch shape.
    """

    def __init__(self, omega: float):
        require(np.isfinite(omega) and omega > 0, "controller.omega_ref", omega,
                "reference-model bandwidth must be > 0 rad/s")
        self.omega = float(omega)
        self.psi = None
        self.rate = None

    def reset(self) -> None:
        self.psi = None
        self.rate = None

    def acceleration(self, psi_d):
        """ψ̈_r = ω² wrap(ψ_d − ψ_r) − 2ω ψ̇_r."""
        w = self.omega
        return w * w * wrap_angle(psi_d - self.psi) - 2.0 * w * self.rate

    def start(self, psi_measured) -> None:
        if self.psi is None:
            self.psi = np.array(psi_measured, dtype=float, copy=True)
            self.rate = np.zeros_like(self.psi)

    def advance(self, acceleration, Ts: float) -> None:
        self.psi = self.psi + Ts * self.rate
        self.rate = self.rate + Ts * acceleration
