"""Linear 3-DOF manoeuvring model M ν̇ + N ν = B δ (Fossen 2021, §7.2, eq. 7.14–7.15).

ν = [u − U, v, r]: the surge equation works on the perturbation of the surge speed about the
model's speed U (a thrust balancing N₁₁U is implied), so the state's ``u`` stays the TOTAL surge
speed and settles back to U. Sway and yaw are the classical linear model whose N includes the
linearised Coriolis terms at U. Kinematics as every catalogue vessel (:mod:`shipgnc.vessels.base`).

Steady turn for a constant rudder δ: N ν_ss = B δ (for a course-stable ship), the closed form the
checks compare against (:meth:`Linear3DOFVessel.steady_turn`).

Built from given matrices (``M``, ``N``, ``B``: SI, 3×3, 3×3, 3×1 with the rudder in rad), or from
main dimensions with :func:`shipgnc.models.linear3dof.clarke83` and
:func:`~shipgnc.models.linear3dof.rudder_input` (:func:`from_dimensions`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from shipgnc.errors import ConfigError, require
from shipgnc.kernels import Kernel, flat
from shipgnc.vessels.base import SOLAS_RUDDER_RATE, CatalogueModel


def _matrix(name: str, value, shape: tuple[int, int]) -> np.ndarray:
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise ConfigError(f"vessel.{name}: not a numeric matrix ({value!r})") from None
    if shape[1] == 1 and arr.shape == (shape[0],):
        arr = arr.reshape(shape)
    require(arr.shape == shape, f"vessel.{name} shape", arr.shape,
            f"must be {shape[0]}x{shape[1]} over (surge, sway, yaw)")
    require(bool(np.all(np.isfinite(arr))), f"vessel.{name}", arr.tolist(),
            "entries must be finite")
    return arr


@dataclass(frozen=True, eq=False)
class Linear3DOFVessel(CatalogueModel):
    """M ν̇ + N ν = B δ at speed ``U`` (module docstring); M must be invertible."""

    M: np.ndarray
    N: np.ndarray
    B: np.ndarray
    U: float = field(kw_only=True)
    delta_max: float = field(default=math.radians(35.0), kw_only=True)
    delta_rate: float = field(default=SOLAS_RUDDER_RATE, kw_only=True)
    T_delta: float = field(default=1.0, kw_only=True)
    length: float | None = field(default=None, kw_only=True)

    def __post_init__(self) -> None:
        object.__setattr__(self, "M", _matrix("M", self.M, (3, 3)))
        object.__setattr__(self, "N", _matrix("N", self.N, (3, 3)))
        object.__setattr__(self, "B", _matrix("B", self.B, (3, 1)))
        require(isinstance(self.U, (int, float)) and math.isfinite(self.U) and self.U >= 0,
                "vessel.speed_mps", self.U, "speed must be a finite number >= 0 m/s")
        cond = np.linalg.cond(self.M)
        require(bool(np.isfinite(cond) and cond < 1e12), "vessel.M", self.M.tolist(),
                "must be invertible (condition number < 1e12)")
        self._check_steering()
        Minv = np.linalg.inv(self.M)
        object.__setattr__(self, "_A", -Minv @ self.N)
        object.__setattr__(self, "_Bu", (Minv @ self.B)[:, 0])

    @property
    def speed(self) -> float:
        return self.U

    def kernel(self) -> Kernel:
        """:meth:`derivatives` for the composed loop (:func:`~shipgnc.vessels.kernels.linear3dof_rhs`)."""
        from shipgnc.vessels.kernels import linear3dof_rhs

        return Kernel(linear3dof_rhs, flat(self.U, self._A, self._Bu, self.delta_max,
                                           self.delta_rate, self.T_delta))

    def steady_turn(self, delta: float) -> np.ndarray:
        """[u − U, v, r] of the steady turn at rudder ``delta`` [rad]: the solve of N ν = B δ."""
        return np.linalg.solve(self.N, self.B[:, 0] * float(delta))

    def straight_state(self, speed_mps: float | None = None) -> np.ndarray:
        return self.state(u=self.U)

    def sway_yaw_pole(self) -> float:
        """The largest real part [1/s] of the eigenvalues of −M⁻¹N (the surge pole −1/T_surge
        decoupled from dimensions, the sway–yaw pair's rightmost): > 0 for a
        course-unstable ship, whose linear model has no steady turn (N ν = B δ gives the unstable
        equilibrium) and whose large-rudder manoeuvres grow without bound."""
        return float(np.max(np.linalg.eigvals(self._A).real))


def from_dimensions(*, speed_mps: float, L: float, B: float, T: float, Cb: float,
                    R66: float | None = None, xg: float = 0.0, T_surge: float | None = None,
                    **steering) -> Linear3DOFVessel:
    """The linear model of a ship of length ``L``, beam ``B``, draft ``T`` [m] and block coefficient
    ``Cb`` at ``speed_mps``: (M, N) by :func:`~shipgnc.models.linear3dof.clarke83` and the rudder
    B by :func:`~shipgnc.models.linear3dof.rudder_input`. Defaults as Fossen's ``shipClarke83``:
    R66 = 0.27 L for L > 100 m else 0.25 L, T_surge = L [s] (numerically), x_g = 0."""
    from shipgnc.models.linear3dof import clarke83, rudder_input

    for name, value in (("L", L), ("B", B), ("T", T)):
        require(isinstance(value, (int, float)) and not isinstance(value, bool)
                and math.isfinite(value) and value > 0, f"vessel.{name}", value,
                "main dimension must be a number > 0 m")
    if R66 is None:
        R66 = (0.27 if L > 100 else 0.25) * L
    if T_surge is None:
        T_surge = float(L)
    M, N = clarke83(speed_mps, L, B, T, Cb, R66, xg, T_surge)
    return Linear3DOFVessel(M, N, rudder_input(speed_mps, L, T), U=float(speed_mps), length=L,
                            **steering)
