"""Second-order reference models (smooth set-point filters)."""

from __future__ import annotations

import numpy as np

from shipgnc.errors import require
from shipgnc.frames import wrap_angle


class HeadingReferenceModel:
    """Second-order heading filter ψ̈_r + 2ζω ψ̇_r + ω² ψ_r = ω² ψ_d.

    ζ = 1 (critically damped) is note 001-1.10's autopilot; document 003 eq. (15) uses ω_n = 0.1,
    ζ = 0.85. Driven by wrap(ψ_d − ψ_r), so it turns the shortest way round; initialised at the
    measured heading with ψ̇_r = 0; advanced by explicit Euler at the controller's sample time.
    Batched: the state arrays take the batch shape.
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

    def acceleration(self, psi_d):
        """ψ̈_r = ω² wrap(ψ_d − ψ_r) − 2ζω ψ̇_r."""
        w = self.omega
        return w * w * wrap_angle(psi_d - self.psi) - 2.0 * self.zeta * w * self.rate

    def start(self, psi_measured) -> None:
        if self.psi is None:
            self.psi = np.array(psi_measured, dtype=float, copy=True)
            self.rate = np.zeros_like(self.psi)

    def advance(self, acceleration, Ts: float) -> None:
        self.psi = self.psi + Ts * self.rate
        self.rate = self.rate + Ts * acceleration
