"""KVLCC2 tanker: the MMG standard manoeuvring model of Yasukawa & Yoshimura (2015).

Source: H. Yasukawa and Y. Yoshimura (2015), "Introduction of MMG standard method for ship
maneuvering predictions", J. Mar. Sci. Technol. 20:37–52 (principal particulars and the
hydrodynamic force coefficients of KVLCC2, model L7 at scale 1/45.7 and full scale). Equations
(their eq. 4–17), midship origin (the state's ``v`` is the sway speed at midship), x_G the CG
ahead of midship::

    (m + m_x) u̇ − (m + m_y) v r − x_G m r² = X_H + X_R + X_P
    (m + m_y) v̇ + x_G m ṙ + (m + m_x) u r = Y_H + Y_R
    (I_zG + x_G² m + J_z) ṙ + x_G m (v̇ + u r) = N_H + N_R

    hull:  X_H = ½ρ L d U² (−R'₀ + X'_vv v'² + X'_vr v'r' + X'_rr r'² + X'_vvvv v'⁴)
           Y_H = ½ρ L d U² (Y'_v v' + Y'_r r' + Y'_vvv v'³ + Y'_vvr v'²r' + Y'_vrr v'r'² + Y'_rrr r'³)
           N_H = ½ρ L² d U² (N'_v v' + N'_r r' + N'_vvv v'³ + N'_vvr v'²r' + N'_vrr v'r'² + N'_rrr r'³)
           v' = v/U, r' = r L/U, β = atan2(−v, u)
    prop:  X_P = (1 − t_P) ρ n² D⁴ K_T(J),  K_T = k₀ + k₁J + k₂J²,  J = u(1 − w_P)/(n D)
           w_P = 1 − (1 − w_P0)(1 + (1 − e^{−C₁|β_P|})(C₂ − 1)),  β_P = β − x'_P r'
    rudder: F_N = ½ρ A_R U_R² f_α sin α_R,   α_R = δ − atan(v_R/u_R)
           X_R = −(1 − t_R) F_N sin δ,  Y_R = −(1 + a_H) F_N cos δ,  N_R = −(x_R + a_H x_H) F_N cos δ
           u_R = ε u (1 − w_P) √(η {1 + κ(√(1 + 8K_T/(πJ²)) − 1)}² + 1 − η),   η = D/H_R
           v_R = U γ_R β_R,  β_R = β − l'_R r'  (γ_R for β_R < 0 and > 0)

Coefficients (Yasukawa & Yoshimura 2015, tables of KVLCC2): m'_x 0.022, m'_y 0.223, J'_z 0.011
(on ½ρL²d and ½ρL⁴d), R'₀ 0.022, X'_vv −0.040, X'_vr 0.002, X'_rr 0.011, X'_vvvv 0.771, Y'_v
−0.315, Y'_r 0.083, Y'_vvv −1.607, Y'_vvr 0.379, Y'_vrr −0.391, Y'_rrr 0.008, N'_v −0.137, N'_r
−0.049, N'_vvv −0.030, N'_vvr −0.294, N'_vrr 0.055, N'_rrr −0.013; t_P 0.220, w_P0 0.40, k₀
0.2931, k₁ −0.2753, k₂ −0.1385, C₁ 2.0, C₂ 1.6 (β_P > 0) / 1.1 (β_P < 0), x'_P −0.48; t_R 0.387,
a_H 0.312, x'_H −0.464, x'_R −0.5, γ_R 0.395 (β_R < 0) / 0.640 (β_R > 0), l'_R −0.710, ε 1.09,
κ 0.50, f_α 2.747. Particulars (full scale / model L7): L_pp 320 / 7.00 m, B 58.0 / 1.27 m, d 20.8
/ 0.46 m, ∇ 312 600 / 3.27 m³, x_G 11.2 / 0.25 m, D_P 9.86 / 0.216 m, H_R 15.80 / 0.345 m, A_R
112.5 / 0.0539 m²; k_zz = 0.25 L (I_zG = m (0.25 L)²), ρ = 1025 kg/m³. The full-scale ship uses
the same nondimensional coefficients (Froude scaling, as the paper's full-scale example; no
Reynolds correction of R'₀). Design condition: 15.5 kn full scale, 1.179 m/s for L7 (Fn 0.142).

Rudder: |δ| ≤ 35°, |δ̇| ≤ 2.34°/s full scale (15.8°/s for L7, the free-running tests' rate; both
the IMO 2.32°/s Froude-scaled), T_δ = 1 s (0.15 s for L7). Propeller: the state ``n`` [rps]
follows the command ``n_c`` with a first-order engine lag T_n (10 s full scale, 1.5 s for L7 —
our assumption, not the paper's); n_c ∈ [0, 1.5 n_design].

**Astern is outside the model** (``can_reverse`` False): the MMG thrust K_T(J) is the open-water
polynomial of the first quadrant (ahead revs, ahead speed) and the hull/rudder terms are fitted for
forward motion; a crash stop needs four-quadrant propeller data that the paper does not give.
Inventing them would give stopping figures without meaning, so the catalogue refuses the stopping
trial for this vessel instead.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from shipgnc.errors import require
from shipgnc.kernels import Kernel, flat
from shipgnc.models.base import Signal
from shipgnc.units import KNOT
from shipgnc.vessels.base import RUDDER_INPUT, CatalogueModel

RHO = 1025.0

#: nondimensional coefficients (module docstring)
COEFFICIENTS = {
    "m_x": 0.022, "m_y": 0.223, "J_z": 0.011,
    "R0": 0.022, "Xvv": -0.040, "Xvr": 0.002, "Xrr": 0.011, "Xvvvv": 0.771,
    "Yv": -0.315, "Yr": 0.083, "Yvvv": -1.607, "Yvvr": 0.379, "Yvrr": -0.391, "Yrrr": 0.008,
    "Nv": -0.137, "Nr": -0.049, "Nvvv": -0.030, "Nvvr": -0.294, "Nvrr": 0.055, "Nrrr": -0.013,
    "t_P": 0.220, "w_P0": 0.40, "k0": 0.2931, "k1": -0.2753, "k2": -0.1385,
    "C1": 2.0, "C2_plus": 1.6, "C2_minus": 1.1, "x_P": -0.48,
    "t_R": 0.387, "a_H": 0.312, "x_H": -0.464, "x_R": -0.5,
    "gamma_minus": 0.395, "gamma_plus": 0.640, "l_R": -0.710,
    "eps": 1.09, "kappa": 0.50, "f_alpha": 2.747,
}

#: principal particulars at full scale and of the paper's model L7 (scale 1/45.7)
PARTICULARS = {
    "full": {"L": 320.0, "B": 58.0, "d": 20.8, "volume": 312600.0, "x_G": 11.2, "D_P": 9.86,
             "H_R": 15.80, "A_R": 112.5, "U0": 15.5 * KNOT, "rudder_rate_deg_s": 2.34,
             "T_delta": 1.0, "T_n": 10.0},
    "model": {"L": 7.00, "B": 1.27, "d": 0.46, "volume": 3.27, "x_G": 0.25, "D_P": 0.216,
              "H_R": 0.345, "A_R": 0.0539, "U0": 1.179, "rudder_rate_deg_s": 15.8,
              "T_delta": 0.15, "T_n": 1.5},
}

PROPELLER_STATE = Signal("n", "1/s", "propeller revolutions (rps)")
PROPELLER_INPUT = Signal("n_c", "1/s", "propeller revolutions command (rps)")


@dataclass(frozen=True)
class KVLCC2(CatalogueModel):
    """The MMG model of the KVLCC2 (module docstring) at ``scale`` ``full`` or ``model`` (L7).

    ``U0`` [m/s] is the approach speed (the self-propelled straight run of
    :meth:`straight_state` and the design revolutions :attr:`n_design`)."""

    scale: str = "full"
    U0: float | None = None
    delta_max: float = field(default=math.radians(35.0), kw_only=True)
    delta_rate: float | None = field(default=None, kw_only=True)
    T_delta: float | None = field(default=None, kw_only=True)
    T_n: float | None = field(default=None, kw_only=True)

    extra_states = (PROPELLER_STATE,)
    extra_limits = (100.0,)
    inputs = (RUDDER_INPUT, PROPELLER_INPUT)
    can_reverse = False

    def __post_init__(self) -> None:
        require(self.scale in PARTICULARS, "vessel.scale", self.scale, "allowed: full, model")
        p = PARTICULARS[self.scale]
        if self.U0 is None:
            object.__setattr__(self, "U0", p["U0"])
        if self.delta_rate is None:
            object.__setattr__(self, "delta_rate", math.radians(p["rudder_rate_deg_s"]))
        if self.T_delta is None:
            object.__setattr__(self, "T_delta", p["T_delta"])
        if self.T_n is None:
            object.__setattr__(self, "T_n", p["T_n"])
        require(math.isfinite(self.U0) and self.U0 > 0, "vessel.speed_mps", self.U0,
                "approach speed must be > 0 m/s")
        require(self.T_n > 0, "vessel.T_n", self.T_n, "engine time constant must be > 0 s")
        self._check_steering()
        c = COEFFICIENTS
        L, d = p["L"], p["d"]
        m = RHO * p["volume"]
        m_x = c["m_x"] * 0.5 * RHO * L**2 * d
        m_y = c["m_y"] * 0.5 * RHO * L**2 * d
        J_z = c["J_z"] * 0.5 * RHO * L**4 * d
        I_zG = m * (0.25 * L) ** 2
        x_G = p["x_G"]
        # sway-yaw mass matrix and its inverse
        M = np.array([[m + m_y, x_G * m], [x_G * m, I_zG + x_G**2 * m + J_z]])
        object.__setattr__(self, "_k", {
            "L": L, "d": d, "m": m, "m_x": m_x, "m_y": m_y, "x_G": x_G, "D": p["D_P"],
            "eta": p["D_P"] / p["H_R"], "A_R": p["A_R"], "Minv": np.linalg.inv(M),
        })
        object.__setattr__(self, "n_design", self.self_propulsion_rps(self.U0))

    @property
    def speed(self) -> float:
        return self.U0

    @property
    def length(self) -> float:
        return PARTICULARS[self.scale]["L"]

    def input_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """δ_c within ±delta_max; n_c within [0, 1.5 n_design] (ahead only: see module doc)."""
        return (np.array([-self.delta_max, 0.0]),
                np.array([self.delta_max, 1.5 * self.n_design]))

    def derivatives(self, x, u, d=None):
        """ẋ of the MMG equations (:func:`~shipgnc.vessels.kernels.kvlcc2_rhs`); an input of the
        rudder alone ``[delta_c]`` holds the design revolutions n_c = n_design."""
        u = np.asarray(u, dtype=float)
        if u.shape[-1] == 1:
            u = np.concatenate([u, np.full_like(u, self.n_design)], axis=-1)
        return super().derivatives(x, u, d)

    def kernel(self) -> Kernel:
        """:meth:`derivatives` for the composed loop (:func:`~shipgnc.vessels.kernels.kvlcc2_rhs`)."""
        from shipgnc.vessels.kernels import kvlcc2_rhs

        c, k = COEFFICIENTS, self._k
        names = ("R0", "Xvv", "Xvr", "Xrr", "Xvvvv", "Yv", "Yr", "Yvvv", "Yvvr", "Yvrr", "Yrrr",
                 "Nv", "Nr", "Nvvv", "Nvvr", "Nvrr", "Nrrr", "t_P", "w_P0", "k0", "k1", "k2",
                 "C1", "C2_plus", "C2_minus", "x_P", "t_R", "a_H", "x_H", "x_R", "gamma_minus",
                 "gamma_plus", "l_R", "eps", "kappa", "f_alpha")
        return Kernel(kvlcc2_rhs, flat(
            [c[n] for n in names], RHO, k["L"], k["d"], k["m"], k["m_x"], k["m_y"], k["x_G"],
            k["D"], k["eta"], k["A_R"], k["Minv"].ravel(), self.delta_max, self.delta_rate,
            self.T_delta, self.T_n, 1.5 * self.n_design))

    # ----------------------------------------------------------------- trim

    def self_propulsion_rps(self, speed_mps: float) -> float:
        """The revolutions n [rps] at which X = 0 in straight running at ``speed_mps`` with δ = 0
        (thrust (1 − t_P)T balances R'₀ ½ρLdU²): the positive root of the quadratic in n."""
        c, k = COEFFICIENTS, self._k
        U = float(speed_mps)
        R = c["R0"] * 0.5 * RHO * k["L"] * k["d"] * U**2
        u_P = U * (1 - c["w_P0"])  # β = r = 0: w_P = w_P0
        D = k["D"]
        a = (1 - c["t_P"]) * RHO * D**4 * c["k0"]
        b = (1 - c["t_P"]) * RHO * D**3 * c["k1"] * u_P
        cc = (1 - c["t_P"]) * RHO * D**2 * c["k2"] * u_P**2 - R
        return float((-b + math.sqrt(b * b - 4 * a * cc)) / (2 * a))

    def straight_state(self, speed_mps: float | None = None) -> np.ndarray:
        """Self-propelled straight running at ``speed_mps`` (default U0): δ = 0, v = r = 0 and n
        from :meth:`self_propulsion_rps` (the hull is symmetric: no trim rudder); command
        ``n_c`` = the state's ``n`` to hold it."""
        U = self.U0 if speed_mps is None else float(speed_mps)
        return self.state(u=U, extra=(self.self_propulsion_rps(U),))
