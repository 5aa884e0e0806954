"""Twin-azimuth-thruster research catamaran of document 004 (22.3 m, 155 t), in NED form.

Equations (note 004-4.3; document 004 eq. (1)–(11), reconstructed from its MathCAD listing)::

    m_x u̇ = 2T_v cos δ − R(V) cos β + m_y v r
    m_y v̇ = −2T_v sin δ − R(V) sin β + σ m_x u r          σ = +1 printed, −1 sign-consistent
    J ṙ   = L T_v sin δ − x_p(β) R(V) sin β − c_D V r + (m_x − m_y) u v
    Ṅ = u cos ψ − v sin ψ,  Ė = u sin ψ + v cos ψ,  ψ̇ = r
    δ̇ = u_δ                       (``delta_row="rate"``, eq. (2): the thruster turning rate is the input)
    δ̇ = (−δ + k_t v_a)/T_t        (``delta_row="lag"``, eq. (22): the thruster's own first-order lag)

with V = √(u² + v²), β = atan2(v, u) (= −β of the document), R(V) = 2000 R_K(V) [N] acting along
−(u, v)/V, R_K = 8.1 − 8.436 V + 2.536 V² [kN] (one hull), x_p = 0.4 L (0.5 − |β|/π) and
c_D = C_d (ρ/2) A_Ls L². The two thrusters are always at the same angle δ with equal thrust T_v;
δ > 0 turns the bow to starboard (an azimuth angle from +x toward starboard α = −δ).

State ``[north, east, psi, u, v, r, delta]`` (every vessel's layout; the document's order
[V_x, V_y, ω, x₁, x₂, K, δ] is :func:`to_document`), input ``[delta_rate]`` [rad/s] or
``[v_a]`` [rad], disturbance ``[X_env, Y_env, N_env]`` (body-axis force [N] and moment [N m]).

**δ is a state**, not the output of the foundation's actuator lag: the finite-state laws need δ in
the state they are evaluated on, and the document's eq. (22) carries a gain k that the foundation's
lag lacks. So the lag of (22) is the model's ``delta_row="lag"`` option (note 004-4.8) with the
true plant's T_t, k_t; a slew limit is the foundation's saturation on u_δ (``slew_actuator``).

**Presets** (note 004-4.4): ``si`` (default, consistent units) and ``paper`` (the listing's mixed
units: ρ = 1.025 in M_D and J in t·m² used as kg·m², which reproduces the document's figures).
Both keep the printed sway Coriolis sign; ``coriolis="consistent"`` flips it (the hull is then
directionally unstable, note 004-C3). The document-frame form (x forward, y to port, ω and K
clockwise) is :func:`document_derivatives`, with :func:`to_document`/:func:`from_document`.

**One source** (:mod:`shipgnc.kernels`, :mod:`shipgnc.derive`): the equations are written once,
for one ship, in :func:`catamaran_rhs` (every option above); :meth:`Catamaran.derivatives`,
:meth:`Catamaran.hull_forces` and :meth:`Catamaran.yaw_acceleration` are the batches of the
kernels, and the composed loop calls them itself (:func:`catamaran_yaw_acceleration` and, on
scalars, :func:`yaw_acceleration_of` are Φ₃ for the laws' kernels). The kernels pass scalars,
not arrays, to their helpers and make no arrays: numba then keeps no reference counts (atomic
operations on every array argument) in the loop's RK stages. Per-ship plant factors (arrays of
``m_x_factor``, ``m_y_factor``, ``J_factor``, the Monte Carlo of S10) are one parameter row per
ship; factors along more than one batch axis have no composed loop (the run stays in the numpy
loop, :meth:`Catamaran.kernel_reason`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

import numpy as np

from shipgnc.actuators import Actuator
from shipgnc.derive import per_ship
from shipgnc.errors import ConfigError, require
from shipgnc.kernels import Kernel, NotCompiled, kernel_function
from shipgnc.models.base import Signal, kernel_derivatives
from shipgnc.models.fossen3dof import CURRENT
from shipgnc.params import Params

#: resistance fit R_K(V) = a0 + a1 V + a2 V² [kN, one hull] of eq. (8)
RK_COEFFS = (8.1, -8.436, 2.536)
#: speed of the fit's minimum [m/s]; below it the continued resistance is used (note 004-4.3 [A])
V_MIN_FIT = -RK_COEFFS[1] / (2.0 * RK_COEFFS[2])

CORIOLIS = {"printed": 1.0, "consistent": -1.0}
LOW_SPEED = ("continued", "literal")
DELTA_ROWS = ("rate", "lag")


def _is_number_or_array(value) -> bool:
    if isinstance(value, bool):
        return False
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return False
    return bool(arr.size) and bool(np.all(np.isfinite(arr)))


@dataclass(frozen=True, eq=False)
class CatamaranParams(Params):
    """Parameters of document 004's catamaran (defaults: preset ``si``; SI unless noted).

    ============  ==============  ======================================================
    field         default (si)    meaning
    ============  ==============  ======================================================
    Delta         155 000 kg      displacement mass Δ
    k11/k22/k66   0.05/0.7/0.6    added-mass coefficients (surge, sway, yaw)
    L             22.3 m          length
    T_m           1.55 m          draught
    C_B           0.697           block coefficient (the listing's "δ")
    rho_MD        1025            density used in the yaw damping M_D (paper: 1.025)
    J_zz          3.95035e6       rigid yaw inertia [kg m²] (paper: 3950.35, t·m² used as kg·m²)
    T_v           20 400 N        thrust of each of the two thrusters
    coriolis      "printed"       sway Coriolis sign σ: printed (+1) or consistent (−1)
    low_speed     "continued"     R below V_m: quadratic continuation, or the literal fit
    delta_row     "rate"          δ̇ = u_δ (rate) or the lag (22) with T_t, k_t
    T_t, k_t      2 s, 1          true thruster lag time constant and gain (``lag`` row)
    Y_vV          0 kg/m          hull lift in sway, Y += Y_vV V v (preset ``si-consistent``)
    Y_rV          0 kg            hull lift in yaw, Y += Y_rV V r (preset ``si-consistent``)
    Y_vv          0 kg/m          cross-flow drag, Y += Y_vv |v| v (preset ``si-consistent``)
    m_x_factor…   1               plant-uncertainty multipliers of m_x, m_y, J (floats or
                                  per-ship arrays broadcasting against the batch)
    ============  ==============  ======================================================
    """

    Delta: float = 155_000.0
    k11: float = 0.05
    k22: float = 0.7
    k66: float = 0.6
    L: float = 22.3
    T_m: float = 1.55
    C_B: float = 0.697
    rho_MD: float = 1025.0
    J_zz: float = 0.05 * 1025.0 * 155_000.0 * 22.3**2 / 1000.0
    T_v: float = 20_400.0
    coriolis: str = "printed"
    low_speed: str = "continued"
    delta_row: str = "rate"
    T_t: float = 2.0
    k_t: float = 1.0
    Y_vV: float = 0.0
    Y_rV: float = 0.0
    Y_vv: float = 0.0
    m_x_factor: float | np.ndarray = 1.0
    m_y_factor: float | np.ndarray = 1.0
    J_factor: float | np.ndarray = 1.0

    def __post_init__(self) -> None:
        require(self.coriolis in CORIOLIS, "vessel.params.coriolis", self.coriolis,
                f"allowed: {', '.join(CORIOLIS)}")
        require(self.low_speed in LOW_SPEED, "vessel.params.low_speed", self.low_speed,
                f"allowed: {', '.join(LOW_SPEED)}")
        require(self.delta_row in DELTA_ROWS, "vessel.params.delta_row", self.delta_row,
                f"allowed: {', '.join(DELTA_ROWS)}")
        for f in fields(self):
            if f.name in ("coriolis", "low_speed", "delta_row"):
                continue
            value = getattr(self, f.name)
            require(_is_number_or_array(value), f"vessel.params.{f.name}", value,
                    "must be a finite number")
        for name in ("Delta", "L", "T_m", "C_B", "rho_MD", "J_zz", "T_v", "T_t",
                     "m_x_factor", "m_y_factor", "J_factor"):
            value = getattr(self, name)
            require(bool(np.all(np.asarray(value) > 0)), f"vessel.params.{name}", value, "must be > 0")
        for name in ("k11", "k22", "k66"):
            require(getattr(self, name) >= 0, f"vessel.params.{name}", getattr(self, name),
                    "added-mass coefficients must be >= 0")
        require(self.k_t != 0, "vessel.params.k_t", self.k_t, "thruster gain must be non-zero")

    # --- derived quantities (eq. (6)–(11)) ---------------------------------------------------
    @property
    def inactive(self) -> tuple[str, ...]:
        """Parameters that do not enter the equations as set: the lag (22)'s T_t, k_t without
        ``delta_row="lag"`` (a study refuses to perturb them rather than draw values that change
        nothing)."""
        return () if self.delta_row == "lag" else ("T_t", "k_t")

    @property
    def m_x(self):
        """Surge mass (1 + k₁₁)Δ [kg] (times ``m_x_factor``)."""
        return (1.0 + self.k11) * self.Delta * self.m_x_factor

    @property
    def m_y(self):
        """Sway mass (1 + k₂₂)Δ [kg] (times ``m_y_factor``)."""
        return (1.0 + self.k22) * self.Delta * self.m_y_factor

    @property
    def J(self):
        """Yaw inertia with added inertia (1 + k₆₆) J_zz [kg m²] (times ``J_factor``)."""
        return (1.0 + self.k66) * self.J_zz * self.J_factor

    @property
    def sigma(self) -> float:
        """Sway Coriolis sign σ (+1 printed, −1 consistent)."""
        return CORIOLIS[self.coriolis]

    @property
    def A_Ls(self) -> float:
        """Lateral area C_B L T_m [m²]."""
        return self.C_B * self.L * self.T_m

    @property
    def C_d(self) -> float:
        """Yaw-damping coefficient (0.739 + 8.7 T_m/L)(1.611 C_B² − 2.873 C_B + 1.33)."""
        return (0.739 + 8.7 * self.T_m / self.L) * (1.611 * self.C_B**2 - 2.873 * self.C_B + 1.33)

    @property
    def c_D(self) -> float:
        """M_D = −c_D V r with c_D = C_d (ρ/2) A_Ls L² [N m s]."""
        return self.C_d * 0.5 * self.rho_MD * self.A_Ls * self.L**2

    def resistance(self, V):
        """Hull resistance R(V) = 2000 R_K(V) [N], both hulls (continued below V_m unless literal)."""
        V = np.asarray(V, dtype=float)
        a0, a1, a2 = RK_COEFFS
        fit = 2000.0 * (a0 + a1 * V + a2 * V * V)
        if self.low_speed == "literal":
            return fit
        rk_min = a0 + a1 * V_MIN_FIT + a2 * V_MIN_FIT**2
        return np.where(V >= V_MIN_FIT, fit, 2000.0 * rk_min * (V / V_MIN_FIT) ** 2)

    def resistance_over_speed(self, V):
        """R(V)/V [N s/m], finite at V = 0 (0 for the continued fit; R's direction is −(u, v)/V)."""
        V = np.asarray(V, dtype=float)
        a0, a1, a2 = RK_COEFFS
        with np.errstate(divide="ignore", invalid="ignore"):
            fit = 2000.0 * (a0 / V + a1 + a2 * V)
        if self.low_speed == "literal":
            return np.where(V > 0, fit, 0.0)
        rk_min = a0 + a1 * V_MIN_FIT + a2 * V_MIN_FIT**2
        return np.where(V >= V_MIN_FIT, fit, (2000.0 * rk_min / V_MIN_FIT**2) * V)

    def top_speed(self) -> float:
        """Straight-running speed: 2 T_v = R(V), i.e. 2.536 V² − 8.436 V + (8.1 − T_v/1000) = 0."""
        a0, a1, a2 = RK_COEFFS
        c = a0 - 2.0 * self.T_v / 2000.0
        return (-a1 + math.sqrt(a1 * a1 - 4.0 * a2 * c)) / (2.0 * a2)



#: density of sea water for the lateral-lift terms of ``si-consistent`` [kg/m³]
RHO_SEA = 1025.0
#: demihull beam assumed for Clarke's regression [m] [A] (the document gives the overall beam only)
DEMIHULL_BEAM = 2.5
#: cross-flow drag coefficient of a demihull section [A]
CROSS_FLOW_CD = 0.8


def clarke_lateral(L: float = 22.3, T_m: float = 1.55, C_B: float = 0.697, B: float = DEMIHULL_BEAM,
                   hulls: int = 2, rho: float = RHO_SEA, C_Dy: float = CROSS_FLOW_CD) -> dict[str, float]:
    """Lateral hull lift and cross-flow drag of the physically consistent preset (note 004-4.11.7) [A].

    Linear sway derivatives per demihull from Clarke, Gedling & Hine (1983),
    Y'_v = −π(T/L)²(1 + 0.40 C_B B/T), Y'_r = −π(T/L)²(−1/2 + 2.2 B/L − 0.080 B/T), made dimensional
    (Y_v = ½ρL²U Y'_v, Y_r = ½ρL³U Y'_r) and summed over the ``hulls``; cross-flow drag
    Y = −½ρ C_Dy (hulls·L T_m)|v|v. The yaw derivatives are left to the document's own M_K, Munk
    moment and M_D, which already have Clarke's size (N'_v, N'_r; note 004-4.4). Returns the
    :class:`CatamaranParams` fields ``Y_vV`` [kg/m], ``Y_rV`` [kg], ``Y_vv`` [kg/m].
    """
    t2 = math.pi * (T_m / L) ** 2
    Yv = -t2 * (1.0 + 0.40 * C_B * B / T_m)
    Yr = -t2 * (-0.5 + 2.2 * B / L - 0.080 * B / T_m)
    return {"Y_vV": hulls * 0.5 * rho * L**2 * Yv, "Y_rV": hulls * 0.5 * rho * L**3 * Yr,
            "Y_vv": -0.5 * rho * C_Dy * hulls * L * T_m}


#: named parameter sets (note 004-4.4). ``si-consistent`` (the scenarios' default) is the
#: physically consistent hull: SI units, the sway Coriolis sign of the rigid-body equations
#: (σ = −1) and a lateral hull force (:func:`clarke_lateral`, [A]) so that it is directionally
#: stable with the drift of a real turn (bow into the circle). ``si`` (units fixed, printed sign)
#: and ``paper`` (the listing's mixed units, printed sign) are reproductions of the document.
PRESETS: dict[str, dict] = {
    "si-consistent": {"coriolis": "consistent", **clarke_lateral()},
    "si": {},
    "paper": {"rho_MD": 1.025, "J_zz": 0.05 * 1.025 * 155_000.0 * 22.3**2 / 1000.0},
}
#: the preset of every scenario unless one is named
DEFAULT_PRESET = "si-consistent"
#: what each preset is, for figure titles and the metrics' ``model_note``
PRESET_NOTES: dict[str, str] = {
    "si-consistent": "physically consistent (SI units, sway Coriolis sign corrected, hull lift [A])",
    "si": "printed Coriolis sign (reproduction)",
    "paper": "paper units (unit-inconsistent), printed Coriolis sign (reproduction)",
}
#: the document's finite-state gains per preset: (T_u [s], h [s]) (note 004-4.4)
FSM_GAINS: dict[str, tuple[float, float]] = {"paper": (0.1, 0.0625), "si": (2.5, 2.5),
                                             "si-consistent": (2.5, 2.5)}


def model_note(params: CatamaranParams, preset_name: str | None = None) -> tuple[str, bool]:
    """(note, reproduction?) describing the hull ``params`` (of preset ``preset_name``): whether it
    is a reproduction of the document (printed Coriolis sign, paper units) or physically consistent."""
    paper = preset_name == "paper" or float(np.max(np.asarray(params.J_zz))) < 1e5
    parts = []
    if paper:
        parts.append("paper units (unit-inconsistent)")
    if params.coriolis == "printed":
        parts.append("printed Coriolis sign (reproduction)")
    elif params.Y_vV == 0.0 and params.Y_vv == 0.0:
        parts.append("consistent Coriolis sign without hull lift (directionally unstable)")
    if parts:
        return ", ".join(parts), True
    return PRESET_NOTES["si-consistent"], False


def preset(name: str = DEFAULT_PRESET, **overrides) -> CatamaranParams:
    """Parameters of preset ``si-consistent`` (default), ``si`` or ``paper`` with optional
    overrides (e.g. ``coriolis=...``)."""
    if name not in PRESETS:
        raise ConfigError(f"vessel.preset = {name!r}: unknown preset; allowed: {', '.join(PRESETS)}")
    return CatamaranParams().with_(**{**PRESETS[name], **overrides})


STATES = (  # the layout of every vessel: pose, body velocity, then states of its own
    Signal("north", "m", "north position (NED x)"),
    Signal("east", "m", "east position (NED y)"),
    Signal("psi", "rad", "heading, clockwise from north (unwrapped)", angle=True),
    Signal("u", "m/s", "surge velocity"),
    Signal("v", "m/s", "sway velocity (to starboard)"),
    Signal("r", "rad/s", "yaw rate (bow to starboard)"),
    Signal("delta", "rad", "thruster angle, positive turns the bow to starboard", angle=True),
)
RATE_INPUTS = (Signal("delta_rate", "rad/s", "thruster turning rate"),)
LAG_INPUTS = (Signal("v_a", "rad", "thruster angle command of the lag (22)", angle=True),)
DISTURBANCES = (
    Signal("X_env", "N", "environmental surge force"),
    Signal("Y_env", "N", "environmental sway force (to starboard)"),
    Signal("N_env", "N m", "environmental yaw moment"),
)
NORTH, EAST, PSI, U, V, R, DELTA = range(7)


@dataclass(frozen=True, eq=False)
class Catamaran:
    """Document 004's twin-azimuth catamaran in NED form (see the module docstring)."""

    params: CatamaranParams = field(default_factory=CatamaranParams)
    preset_name: str = DEFAULT_PRESET
    length: float = 22.3  #: drawing outline only [m]
    beam: float = 9.0  #: drawing outline only [m] (thrusters at ±3 m)

    states = STATES
    disturbances = (*DISTURBANCES, *CURRENT)
    state_limits = (1e8, 1e8, 1e6, 50.0, 50.0, 50.0, 1e4)

    @classmethod
    def from_preset(cls, name: str = DEFAULT_PRESET, **overrides) -> Catamaran:
        return cls(params=preset(name, **overrides), preset_name=name)

    @property
    def inputs(self) -> tuple[Signal, ...]:
        return RATE_INPUTS if self.params.delta_row == "rate" else LAG_INPUTS

    def input_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """No hardware limit on the input by default (a slew limit: :func:`slew_actuator`)."""
        return np.array([-np.inf]), np.array([np.inf])

    def hull_forces(self, x):
        """(X, Y, N) of the hull alone (resistance, yaw damping, Coriolis, Munk) in NED body axes:
        the batch of :func:`catamaran_hull_forces`."""
        params, x = self._batch(np.asarray(x, dtype=float))
        out = per_ship(catamaran_hull_forces, "i p o")(x, params, 3)
        return out[..., 0], out[..., 1], out[..., 2]

    def derivatives(self, x, u, d=None):
        """ẋ for ``x`` (..., 7), ``u`` (..., 1) = [δ̇] or [v_a], ``d`` (..., 3) (forces), (..., 5)
        (forces and an earth-fixed current [m/s]) or None: the batch of :func:`catamaran_rhs`."""
        params, x = self._batch(np.asarray(x, dtype=float), u, d)
        return kernel_derivatives(self, catamaran_rhs, params, x, u, d)

    def yaw_acceleration(self, x, d=None):
        """Φ₃ = ṙ at state ``x`` (it does not depend on the input; a current in ``d`` acts on ν_r)."""
        x = np.asarray(x, dtype=float)
        return self.derivatives(x, np.zeros((*x.shape[:-1], 1)), d)[..., R]

    def _batch(self, x, *others) -> tuple[np.ndarray, np.ndarray]:
        """(the kernels' parameters, ``x``) for the batch: one flat array, or with per-ship factors
        one row per ship of the broadcast batch (``x`` broadcast to it; numpy's broadcasting of
        the factors against the states)."""
        columns = _kernel_columns(self.params)
        if columns.ndim == 1:
            return columns, x
        lead = np.broadcast_shapes(x.shape[:-1], columns.shape[:-1],
                                   *(np.shape(a)[:-1] for a in others if a is not None))
        rows = np.broadcast_to(columns, (*lead, N_KERNEL_PARAMS)).reshape(-1, N_KERNEL_PARAMS)
        return np.ascontiguousarray(rows), np.broadcast_to(x, (*lead, x.shape[-1]))

    # --- the composed compiled loop (shipgnc.kernels) ----------------------------------------
    def kernel_reason(self) -> str | None:
        """Why :meth:`kernel` cannot compile this model (None when it can)."""
        return kernel_params_reason(self.params)

    def kernel(self) -> Kernel:
        """:meth:`derivatives` for the composed loop (:func:`catamaran_rhs`); parameters of
        :func:`kernel_params`."""
        return Kernel(catamaran_rhs, kernel_params(self.params))


#: fields that may hold one value per ship (a Monte Carlo over the plant, check 16 / S10)
FACTORS = ("m_x_factor", "m_y_factor", "J_factor")
#: length of :func:`kernel_params`
N_KERNEL_PARAMS = 18


def kernel_params_reason(params: CatamaranParams) -> str | None:
    """None when :func:`kernel_params` covers ``params`` (scalar factors, or one per ship along a
    single batch axis), else why not."""
    shapes = {np.shape(getattr(params, name)) for name in FACTORS} - {()}
    if any(len(shape) > 1 for shape in shapes) or len({s[0] for s in shapes}) > 1:
        return (f"per-ship factors ({', '.join(FACTORS)}) of shapes {sorted(shapes)}: the compiled "
                "loop takes one value per ship along one batch axis")
    return None


def kernel_params(params: CatamaranParams) -> np.ndarray:
    """The parameters of :func:`catamaran_rhs` and :func:`catamaran_yaw_acceleration`:
    ``[m_x, m_y, J, σ m_x, m_x − m_y, c_D, 0.4 L, 2 T_v, L T_v, literal, V_m, 2000 R_K(V_m)/V_m²,
    lag row, k_t, T_t, Y_vV, Y_rV, Y_vv]``: a flat array, or one row per ship when the mass
    factors vary from ship to ship."""
    reason = kernel_params_reason(params)
    if reason:
        raise NotCompiled(reason)
    return _kernel_columns(params)


def _kernel_columns(params: CatamaranParams) -> np.ndarray:
    """The columns of :func:`kernel_params` broadcast over the factors' shape (..., 18)."""
    p = params
    m_x, m_y, J = (np.asarray(v, dtype=float) for v in (p.m_x, p.m_y, p.J))
    a0, a1, a2 = RK_COEFFS
    rk_min = a0 + a1 * V_MIN_FIT + a2 * V_MIN_FIT**2
    columns = np.broadcast_arrays(
        m_x, m_y, J, p.sigma * m_x, m_x - m_y, p.c_D, 0.4 * p.L, 2.0 * p.T_v, p.L * p.T_v,
        float(p.low_speed == "literal"), V_MIN_FIT, 2000.0 * rk_min / V_MIN_FIT**2,
        float(p.delta_row == "lag"), p.k_t, p.T_t, p.Y_vV, p.Y_rV, p.Y_vv)
    out = np.ascontiguousarray(np.stack(columns, axis=-1), dtype=np.float64)
    assert out.shape[-1] == N_KERNEL_PARAMS
    return out


@kernel_function
def _hull_forces(su, sv, sr, p, o):
    """(X, Y, N) of the hull alone for one ship at (u, v, r) = (``su``, ``sv``, ``sr``) (note
    004-4.3, eq. (1)–(3), (8))::

        X = −R(V)/V · u + m_y v r
        Y = −R(V)/V · v + σ m_x u r + Y_vV V v + Y_rV V r + Y_vv |v| v
        N = −x_p(β) R(V)/V · v − c_D V r + (m_x − m_y) u v,   x_p = 0.4 L (0.5 − |β|/π)

    resistance R(V) = 2000 R_K(V), R_K = 8.1 − 8.436 V + 2.536 V² [kN] (continued below V_m as
    R_K(V_m) V²/V_m² unless ``low_speed="literal"``), Coriolis with sign σ, yaw damping c_D V r and
    the Munk moment. V = √(u² + v²) (|u|, |v| ≤ 50 m/s by the state limits: no overflow), |β| =
    |atan2(v, u)| = atan(|v|/u) for u > 0 (atan2(|v|, u) otherwise), about half the cost.
    ``p[o:]`` holds :func:`kernel_params` (an offset, not a slice: no array view per call).
    Scalars in, scalars out: no array is made or passed, so the callers keep no reference counts
    in their hot path."""
    m_y, sig_m_x, munk, c_D, x_p0 = p[o + 1], p[o + 3], p[o + 4], p[o + 5], p[o + 6]
    speed = math.sqrt(su * su + sv * sv)
    a0, a1, a2 = RK_COEFFS
    if p[o + 9] != 0.0:  # literal fit, 0 at V = 0
        r_over_v = 2000.0 * (a0 / speed + a1 + a2 * speed) if speed > 0 else 0.0
    elif speed >= p[o + 10]:
        r_over_v = 2000.0 * (a0 / speed + a1 + a2 * speed)
    else:
        r_over_v = p[o + 11] * speed
    abs_v = abs(sv)
    abs_beta = math.atan(abs_v / su) if su > 0.0 else math.atan2(abs_v, su)
    x_p = x_p0 * (0.5 - abs_beta / math.pi)
    X = -r_over_v * su + m_y * sv * sr
    Y = -r_over_v * sv + sig_m_x * su * sr
    Y = Y + (p[o + 15] * speed * sv + p[o + 16] * speed * sr + p[o + 17] * abs_v * sv)
    N = -x_p * r_over_v * sv - c_D * speed * sr + munk * su * sv
    return X, Y, N


@kernel_function
def catamaran_rhs(x, u, d, p, xdot):
    """ẋ of document 004 eq. (1)–(3) with δ̇ of eq. (2) (rate row) or of the lag (22) for one
    ship (the one source of :meth:`Catamaran.derivatives`; ``p``: :func:`kernel_params`; forces
    ``d[0:3]``; a zero ``d`` is ``d=None``).

    An earth-fixed current ``d[3:5]`` [m/s] acts as relative velocity (Fossen 2021 §10.3): the
    hull's forces of :func:`_hull_forces` — resistance R(V_r) along −ν_r/V_r, its moment at
    x_p(β_r), the yaw damping c_D V_r r, the Coriolis and Munk terms with the total masses m_x, m_y
    (rigid plus added: Δ and k₁₁Δ, k₂₂Δ) and the lateral lift — are evaluated at ν_r = ν − ν_c,
    ν_c = R(ψ)ᵀ[V_N, V_E], and ν̇ = ν̇_r + (r v_c, −r u_c, 0). With the consistent Coriolis sign
    the Coriolis terms are C(ν)ν of M = diag(m_x, m_y, J) with x_g = 0, so Property 10.1 makes
    this Fossen's M_RB ν̇ + C_RB(ν)ν + M_A ν̇_r + C_A(ν_r)ν_r + D(ν_r)ν_r = τ exactly for a
    constant current; with the printed sign (not a rigid-body Coriolis term) the same
    substitution is applied as a reproduction. The thrust does not depend on speed."""
    m_x, m_y, J, two_T_v, L_T_v = p[0], p[1], p[2], p[7], p[8]
    delta = x[DELTA]
    c, s = math.cos(x[PSI]), math.sin(x[PSI])
    in_current = d.shape[0] > 4 and (d[3] != 0.0 or d[4] != 0.0)
    uc = 0.0
    vc = 0.0
    su, sv = x[U], x[V]
    if in_current:  # the hull sees ν_r = ν − R(ψ)ᵀ[V_N, V_E]
        uc = c * d[3] + s * d[4]
        vc = -s * d[3] + c * d[4]
        su = x[U] - uc
        sv = x[V] - vc
    X, Y, N = _hull_forces(su, sv, x[R], p, 0)
    cd, sd = math.cos(delta), math.sin(delta)
    X = X + two_T_v * cd + d[0]
    Y = Y - two_T_v * sd + d[1]
    N = N + L_T_v * sd + d[2]
    # ν̇_c = (r v_c, −r u_c, 0), zero in still water (u_c = v_c = 0); every element written once,
    # unconditionally (a write in one branch keeps numba's reference counting in the RK stages)
    xdot[NORTH] = c * x[U] - s * x[V]
    xdot[EAST] = s * x[U] + c * x[V]
    xdot[PSI] = x[R]
    xdot[U] = X / m_x + x[R] * vc
    xdot[V] = Y / m_y - x[R] * uc
    xdot[R] = N / J
    if p[12] != 0.0:
        xdot[DELTA] = (-delta + p[13] * u[0]) / p[14]
    else:
        xdot[DELTA] = u[0]


@kernel_function
def catamaran_hull_forces(x, p, out):
    """(X, Y, N) of :func:`_hull_forces` at one ship's state ``x`` into ``out``."""
    X, Y, N = _hull_forces(x[U], x[V], x[R], p, 0)
    out[0] = X
    out[1] = Y
    out[2] = N


@kernel_function
def yaw_acceleration_of(su, sv, sr, delta, p, o):
    """Φ₃ = ṙ of eq. (3) without disturbance at (u, v, r, δ) = (``su``, ``sv``, ``sr``, ``delta``):
    ṙ of :func:`catamaran_rhs` on scalars (``p[o:]``: :func:`kernel_params`), for laws that
    read the state once and keep it out of conditional calls."""
    N = _hull_forces(su, sv, sr, p, o)[2]
    N = N + p[o + 8] * math.sin(delta)
    return N / p[o + 2]


@kernel_function
def catamaran_yaw_acceleration(x, p, o):
    """Φ₃ = ṙ of eq. (3) at one ship's state without disturbance (``p[o:]``: :func:`kernel_params`)."""
    return yaw_acceleration_of(x[U], x[V], x[R], x[DELTA], p, o)


def slew_actuator(model: Catamaran, rate_deg_s: float) -> Actuator:
    """Thruster slew limit |δ̇| ≤ ``rate_deg_s`` as the foundation's saturation on u_δ (note 004-4.11.2)."""
    require(model.params.delta_row == "rate", "vessel.params.delta_row", model.params.delta_row,
            "a slew limit on the input needs the rate row (input delta_rate)")
    require(math.isfinite(rate_deg_s) and rate_deg_s > 0, "actuator.slew_deg_s", rate_deg_s, "must be > 0")
    rate = math.radians(rate_deg_s)
    return Actuator(np.array([-rate]), np.array([rate]), names=("delta_rate",))


# --- document frame (x forward, y to port, ω and K clockwise), note 004-4.2 ------------------
#: where the document's z = [V_x, V_y, ω, x₁, x₂, K, δ] sits in the NED state
DOCUMENT_ORDER = (U, V, R, NORTH, EAST, PSI, DELTA)


def to_document(x):
    """NED state [N, E, ψ, u, v, r, δ] → the document's z = [V_x, V_y, ω, x₁, x₂, K, δ]
    = [u, −v, r, N, E, ψ, δ] (its y to port)."""
    z = np.array(x, dtype=float)[..., DOCUMENT_ORDER]
    z[..., 1] = -z[..., 1]
    return z


def from_document(z):
    """The document's z = [V_x, V_y, ω, x₁, x₂, K, δ] → NED state (inverse of :func:`to_document`)."""
    z = np.asarray(z, dtype=float)
    x = np.empty_like(z)
    x[..., DOCUMENT_ORDER] = z
    x[..., V] = -x[..., V]
    return x


def document_derivatives(params: CatamaranParams, z, u_delta):
    """ż = Φ(z) + B u of eq. (1)–(3) written in the document's own frame (for the frame test)."""
    p = params
    Vx, Vy, w, K, delta = z[..., 0], z[..., 1], z[..., 2], z[..., 5], z[..., 6]
    speed = np.sqrt(Vx**2 + Vy**2)
    beta = np.arctan2(Vy, Vx)
    R = p.resistance_over_speed(speed) * speed
    Rx, Ry = R * np.cos(beta), R * np.sin(beta)
    M_K = 0.4 * p.L * (0.5 - np.abs(beta) / np.pi) * Ry
    M_D = -p.C_d * (p.rho_MD / 2.0) * p.A_Ls * p.L**2 * speed * w
    s = p.sigma
    phi = [
        (2 * p.T_v * np.cos(delta) - Rx - p.m_y * w * Vy) / p.m_x,
        (2 * p.T_v * np.sin(delta) - Ry - s * p.m_x * w * Vx
         + p.Y_vV * speed * Vy - p.Y_rV * speed * w + p.Y_vv * np.abs(Vy) * Vy) / p.m_y,
        (p.L * p.T_v * np.sin(delta) + M_K + M_D - (p.m_x - p.m_y) * Vx * Vy) / p.J,
        speed * np.cos(K - beta),
        speed * np.sin(K - beta),
        w,
        np.asarray(u_delta, dtype=float) + 0.0 * delta,
    ]
    return np.stack(phi, axis=-1)


def straight_running_state(params: CatamaranParams, speed: float | None = None) -> np.ndarray:
    """State at straight running (δ = 0) with surge ``speed`` (default: the top speed)."""
    x = np.zeros(7)
    x[U] = params.top_speed() if speed is None else speed
    return x


def linearize(model: Catamaran, x0, *, step: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """Central-difference Jacobians (A = ∂f/∂x, B = ∂f/∂u) of ``model`` at ``x0`` (input 0)."""
    x0 = np.asarray(x0, dtype=float)
    n = x0.size
    eye = np.eye(n) * step
    u0 = np.zeros(1)
    A = (model.derivatives(x0 + eye, u0) - model.derivatives(x0 - eye, u0)).T / (2 * step)
    B = ((model.derivatives(x0, u0 + step) - model.derivatives(x0, u0 - step)) / (2 * step))[:, None]
    return A, B


def straight_running_eigenvalues(model: Catamaran, speed: float | None = None) -> np.ndarray:
    """Eigenvalues of the (u, v, r) subsystem at straight running (note 004-4.12 check 15), sorted."""
    A, _ = linearize(model, straight_running_state(model.params, speed))
    nu = [U, V, R]
    eig = np.linalg.eigvals(A[np.ix_(nu, nu)])
    return eig[np.lexsort((eig.imag, eig.real))]
