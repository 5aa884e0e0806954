"""Mariner-class cargo ship: the nonlinear manoeuvring model of Chislett & Strøm-Tejsen (1965).

Source: M. S. Chislett and J. Strøm-Tejsen (1965), *Planar Motion Mechanism Tests and Full-Scale
Steering and Manoeuvring Predictions for a Mariner Class Vessel*, International Shipbuilding Progress
12(129), 201–224 (also Report Hy-6, Hydro- and Aerodynamics Laboratory, Lyngby, Denmark; MSS cites it as
"Report Hy-5", the number of Abkowitz's 1964 lectures); as given in T. I. Fossen (2021), *Handbook of Marine
Craft Hydrodynamics and Motion Control*, 2nd ed., Wiley (Mariner-class vessel, §7.2 / Appendix),
and his MSS toolbox function ``mariner.m`` (the coefficient table below is that function's, checked
against it). Distinct from document 000's de Wit–Oppe ``mariner`` (:mod:`shipgnc.models.mariner`).

L = 160.93 m, design speed U₀ = 15 kn = 7.7175 m/s. Surge is a perturbation Δu = u − U₀ of the
design speed inside the model (there is no propeller: the thrust that holds U₀ is implied), but
the state ``u`` is the TOTAL surge speed. With U = √(u² + v²) the nondimensional (prime) states are
u' = Δu/U, v' = v/U, r' = r L/U, and δ_h = −δ (the model's rudder sign: δ_h > 0 turns to port; the
catalogue's δ > 0 turns the bow to starboard, as MSS's ``delta_c = −ui``)::

    X' = X_u u' + X_uu u'² + X_uuu u'³ + X_vv v'² + X_rr r'² + X_rv r'v' + X_δδ δ_h²
         + X_uδδ u'δ_h² + X_vδ v'δ_h + X_uvδ u'v'δ_h
    Y' = Y_v v' + Y_r r' + Y_vvv v'³ + Y_vvr v'²r' + Y_vu v'u' + Y_ru r'u' + Y_δ δ_h + Y_δδδ δ_h³
         + Y_uδ u'δ_h + Y_uuδ u'²δ_h + Y_vδδ v'δ_h² + Y_vvδ v'²δ_h + (Y₀ + Y₀u u' + Y₀uu u'²)
    N' = (the same terms with N coefficients)

    u̇ = X' (U²/L) / (m' − X'_u̇)
    v̇ = ( m'₃₃ Y' − m'₂₃ N') (U²/L) / det,    ṙ = (−m'₃₂ Y' + m'₂₂ N') (U²/L²) / det
    m'₂₂ = m' − Y'_v̇, m'₂₃ = m'x'_G − Y'_ṙ, m'₃₂ = m'x'_G − N'_v̇, m'₃₃ = I'_z − N'_ṙ,
    det = m'₂₂ m'₃₃ − m'₂₃ m'₃₂

Nondimensional coefficients (×10⁻⁵ unless noted): m' = 798, I'_z = 39.2, x'_G = −0.023 (plain);
X_u̇ −42, X_u −184, X_uu −110, X_uuu −215, X_vv −899, X_rr 18, X_δδ −95, X_uδδ −190, X_rv 798,
X_vδ 93, X_uvδ 93; Y_v̇ −748, Y_ṙ −9.354, Y_v −1160, Y_r −499, Y_vvv −8078, Y_vvr 15356,
Y_vu −1160, Y_ru −499, Y_δ 278, Y_δδδ −90, Y_uδ 556, Y_uuδ 278, Y_vδδ −4, Y_vvδ 1190, Y₀ −4,
Y₀u −8, Y₀uu −4; N_v̇ 4.646, N_ṙ −43.8, N_v −264, N_r −166, N_vvv 1636, N_vvr −5483, N_vu −264,
N_ru −166, N_δ −139, N_δδδ 45, N_uδ −278, N_uuδ −139, N_vδδ 13, N_vvδ −489, N₀ 3, N₀u 6,
N₀uu 3.

Steering machine: |δ| ≤ 40° (Fossen raised it from 30° so that a 35° execute is possible),
|δ̇| ≤ 5°/s, T_δ = 1 s (MSS: δ̇ = δ_c − δ, rate-limited). No propeller: ``can_reverse`` False.

The constant terms Y₀, N₀ (propeller asymmetry) make δ = 0 slightly off straight: at U₀ with
δ = 0, v = r = 0 the ship has v̇ = −8.8·10⁻⁴ m/s² and ṙ = 8.2·10⁻⁵ rad/s² (as much as ≈ 1.1° of
rudder). :meth:`MarinerCST.straight_state` returns the trimmed steady straight run (δ₀, v₀, Δu₀
with u̇ = v̇ = ṙ = 0); the trials execute from that δ₀ (docs/trials.md).

The speed U₀ is a parameter (as in MSS, ``mariner(x, ui, U0)``); the coefficients were measured at
15 kn, and the catalogue accepts 10–20 kn (Froude-number effects neglected).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from shipgnc.errors import require
from shipgnc.kernels import Kernel, flat
from shipgnc.units import KNOT
from shipgnc.vessels.base import CatalogueModel

L_MARINER = 160.93  #: length between perpendiculars [m]
U0_MARINER = 7.7175  #: design speed [m/s] (15 kn as MSS writes it)

_E5 = 1e-5
#: the coefficients of the module docstring (MSS ``mariner.m``), plain numbers
COEFFICIENTS = {
    "m": 798 * _E5, "Iz": 39.2 * _E5, "xG": -0.023,
    "Xudot": -42 * _E5, "Xu": -184 * _E5, "Xuu": -110 * _E5, "Xuuu": -215 * _E5,
    "Xvv": -899 * _E5, "Xrr": 18 * _E5, "Xdd": -95 * _E5, "Xudd": -190 * _E5, "Xrv": 798 * _E5,
    "Xvd": 93 * _E5, "Xuvd": 93 * _E5,
    "Yvdot": -748 * _E5, "Yrdot": -9.354 * _E5, "Yv": -1160 * _E5, "Yr": -499 * _E5,
    "Yvvv": -8078 * _E5, "Yvvr": 15356 * _E5, "Yvu": -1160 * _E5, "Yru": -499 * _E5,
    "Yd": 278 * _E5, "Yddd": -90 * _E5, "Yud": 556 * _E5, "Yuud": 278 * _E5, "Yvdd": -4 * _E5,
    "Yvvd": 1190 * _E5, "Y0": -4 * _E5, "Y0u": -8 * _E5, "Y0uu": -4 * _E5,
    "Nvdot": 4.646 * _E5, "Nrdot": -43.8 * _E5, "Nv": -264 * _E5, "Nr": -166 * _E5,
    "Nvvv": 1636 * _E5, "Nvvr": -5483 * _E5, "Nvu": -264 * _E5, "Nru": -166 * _E5,
    "Nd": -139 * _E5, "Nddd": 45 * _E5, "Nud": -278 * _E5, "Nuud": -139 * _E5, "Nvdd": 13 * _E5,
    "Nvvd": -489 * _E5, "N0": 3 * _E5, "N0u": 6 * _E5, "N0uu": 3 * _E5,
}

#: the order of the coefficients in the kernel's parameter array
KERNEL_ORDER = tuple(COEFFICIENTS)


@dataclass(frozen=True)
class MarinerCST(CatalogueModel):
    """Chislett & Strøm-Tejsen's Mariner (module docstring) at design speed ``U0`` [m/s]."""

    U0: float = U0_MARINER
    L: float = L_MARINER
    delta_max: float = field(default=math.radians(40.0), kw_only=True)
    delta_rate: float = field(default=math.radians(5.0), kw_only=True)
    T_delta: float = field(default=1.0, kw_only=True)

    def __post_init__(self) -> None:
        require(isinstance(self.U0, (int, float)) and math.isfinite(self.U0) and self.U0 > 0,
                "vessel.speed_mps", self.U0, "design speed must be > 0 m/s")
        self._check_steering()

    @property
    def speed(self) -> float:
        return self.U0

    def kernel(self) -> Kernel:
        """:meth:`derivatives` for the composed loop (:func:`~shipgnc.vessels.kernels.mariner_cst_rhs`)."""
        from shipgnc.vessels.kernels import mariner_cst_rhs

        return Kernel(mariner_cst_rhs, flat(self.U0, self.L, self.delta_max, self.delta_rate,
                                            self.T_delta, [COEFFICIENTS[k] for k in KERNEL_ORDER]))

    def straight_state(self, speed_mps: float | None = None) -> np.ndarray:
        """Steady straight running: r = 0 and (Δu, v, δ) with u̇ = v̇ = ṙ = 0 (Newton's method
        on the three accelerations), the trim rudder δ₀ in ``delta``. ``speed_mps`` must be the
        model's U₀ (the model is built about its design speed)."""
        if speed_mps is not None:
            require(abs(speed_mps - self.U0) <= 1e-9 * self.U0, "speed_mps", speed_mps,
                    f"this model is built about U0 = {self.U0:g} m/s; build it at the speed "
                    f"wanted (get_vessel('mariner-cst').build(speed_mps=...))")
        z = np.zeros(3)  # Δu, v, δ
        scale = np.array([1.0, 1.0, 1.0 / self.L])

        def f(z):  # (u̇, v̇, ṙ) of the kernel at (U₀ + Δu, v, r = 0, δ)
            x = self.state(u=self.U0 + z[0], v=z[1], delta=z[2])
            return self.derivatives(x, np.array([z[2]]))[3:6] / scale

        for _ in range(30):
            fz = f(z)
            J = np.empty((3, 3))
            for j in range(3):
                dz = np.zeros(3)
                dz[j] = 1e-7
                J[:, j] = (f(z + dz) - fz) / 1e-7
            step = np.linalg.solve(J, -fz)
            z = z + step
            if np.max(np.abs(step)) < 1e-13:
                break
        return self.state(u=self.U0 + z[0], v=z[1], delta=z[2])


#: the catalogue's speed range: 10–20 kn about the 15 kn of the tests
SPEED_RANGE = (10 * KNOT, 20 * KNOT)
