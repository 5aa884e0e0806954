"""Constant-speed steering models of the catalogue: Nomoto (first and second order), Norrbin.

The yaw dynamics of the first-order Nomoto and Norrbin models are those of
:mod:`shipgnc.models.nomoto` (reused: :class:`~shipgnc.models.nomoto.NomotoModel` and
:class:`~shipgnc.models.nomoto.NorrbinModel` hold and validate K, T, a₁…a₃); here they get the
catalogue's state layout (:mod:`shipgnc.vessels.base`) and its steering machine. The ship sails
at the constant speed U without sway (u = U and v = 0 stay constant), so the CG moves along the
heading.

Second-order Nomoto (Nomoto et al. 1957; Fossen 2021 eq. 7.50)::

    T₁T₂ ψ⃛ + (T₁ + T₂) ψ̈ + ψ̇ = K (δ + T₃ δ̇)

realised in observer canonical form with an auxiliary state w [rad]::

    ẇ = K δ − r,     ṙ = (w − (T₁ + T₂) r + K T₃ δ) / (T₁T₂)

(differentiate the second line and substitute the first: the transfer function r/δ =
K(1 + T₃s)/((1 + T₁s)(1 + T₂s)) without δ̇ in the state equations). Steady turn: r = Kδ.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from shipgnc.errors import require
from shipgnc.kernels import Kernel, flat
from shipgnc.models.base import Signal
from shipgnc.models.nomoto import NomotoModel, NorrbinModel
from shipgnc.vessels.base import SOLAS_RUDDER_RATE, CatalogueModel


@dataclass(frozen=True)
class NomotoVessel(CatalogueModel):
    """First-order Nomoto T ṙ + r = K δ (or Norrbin T ṙ + H_N(r) = K δ) at constant speed.

    ``steering`` is a :class:`~shipgnc.models.nomoto.NomotoModel` or
    :class:`~shipgnc.models.nomoto.NorrbinModel` (its ``U`` is the speed; K, T, a₀…a₃), ṙ with δ
    the actual rudder (the state ``delta``): :func:`~shipgnc.vessels.kernels.norrbin_rhs`.
    """

    steering: NomotoModel | NorrbinModel
    delta_max: float = math.radians(35.0)
    delta_rate: float = SOLAS_RUDDER_RATE
    T_delta: float = 1.0

    def __post_init__(self) -> None:
        self._check_steering()

    @property
    def speed(self) -> float:
        return self.steering.U

    def kernel(self) -> Kernel:
        """:meth:`derivatives` for the composed loop (:func:`~shipgnc.vessels.kernels.norrbin_rhs`;
        Nomoto as Norrbin with a₁ = 1)."""
        from shipgnc.vessels.kernels import norrbin_rhs

        st = self.steering
        a = [getattr(st, n, 0.0) for n in ("a0", "a1", "a2", "a3")]
        if not hasattr(st, "a1"):
            a[1] = 1.0
        return Kernel(norrbin_rhs, flat(st.K, st.T, a, self.delta_max, self.delta_rate,
                                        self.T_delta))

    def straight_state(self, speed_mps: float | None = None) -> np.ndarray:
        """x0 of straight running at the model's (constant) speed; with a Norrbin bias a₀ ≠ 0 the
        trim rudder δ₀ = a₀/K is in the state's ``delta``."""
        delta0 = getattr(self.steering, "a0", 0.0) / self.steering.K if self.steering.K else 0.0
        return self.state(u=self.speed, delta=delta0)


AUX = Signal("w", "rad", "second-order Nomoto auxiliary state (observer canonical form)")


@dataclass(frozen=True)
class Nomoto2Vessel(CatalogueModel):
    """Second-order Nomoto K(1 + T₃s)/((1 + T₁s)(1 + T₂s)) at constant speed ``U`` (module
    docstring). ``K`` [1/s], ``T1``, ``T2``, ``T3`` [s]; T₁T₂ ≠ 0."""

    K: float
    T1: float
    T2: float
    T3: float
    U: float = field(kw_only=True)
    delta_max: float = field(default=math.radians(35.0), kw_only=True)
    delta_rate: float = field(default=SOLAS_RUDDER_RATE, kw_only=True)
    T_delta: float = field(default=1.0, kw_only=True)

    extra_states = (AUX,)
    extra_limits = (1e5,)

    def __post_init__(self) -> None:
        for name in ("K", "T1", "T2", "T3", "U"):
            value = getattr(self, name)
            require(isinstance(value, (int, float)) and not isinstance(value, bool)
                    and math.isfinite(value), f"vessel.{name}", value, "must be a finite number")
        require(self.T1 * self.T2 != 0, "vessel.T1", self.T1, "T1 and T2 must be nonzero s")
        require(self.U >= 0, "vessel.speed_mps", self.U, "speed must be >= 0 m/s")
        self._check_steering()

    @property
    def speed(self) -> float:
        return self.U

    def kernel(self) -> Kernel:
        """:meth:`derivatives` for the composed loop (:func:`~shipgnc.vessels.kernels.nomoto2_rhs`)."""
        from shipgnc.vessels.kernels import nomoto2_rhs

        return Kernel(nomoto2_rhs, flat(self.K, self.T1, self.T2, self.T3, self.delta_max,
                                        self.delta_rate, self.T_delta))

    def straight_state(self, speed_mps: float | None = None) -> np.ndarray:
        return self.state(u=self.U, extra=(0.0,))
