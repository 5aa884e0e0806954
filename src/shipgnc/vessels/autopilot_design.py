"""A heading autopilot designed for the vessel in hand, from its linearised yaw response.

**Design model.** The vessel's equations are linearised about its straight run at its speed
(central differences of ``model.derivatives``; the actual rudder angle as input, yaw rate as
output), reduced to a transfer function r/δ by python-control (``minreal`` removes the modes the
rudder does not reach, e.g. a decoupled surge). The first-order Nomoto model used for the design,

    ψ/δ = K / (s (1 + T s)),   i.e.  ṙ = −r/T + b δ,  b = K/T,

keeps r/δ's **dominant pole** p (the rightmost one; T = −1/p, negative for a course-unstable
ship) and its **high-frequency gain** b = lim s·r/δ (the rudder's yaw acceleration per radian).
Nomoto's low-frequency reduction T = T₁ + T₂ − T₃
(:func:`~shipgnc.models.nomoto_reduction.first_order_reduction`) is printed beside it: it is the
textbook design model, but it matches r/δ at s → 0, not near the crossover; for a small beamy
hull (L 12 m, B 4 m, T 1.2 m, C_b 0.5, 5.14 m/s) it gives b 4 × too small (0.36 against
1.41 1/s²), and Fossen's rule on it (with a 20°/s rudder, T_δ = 0.2 s) lands at crossovers
3–6 × the chosen bandwidth, with phase margins of 3–28° over the allowed bandwidths.

**Steering machine.** The catalogue's servo (:mod:`shipgnc.vessels.base`) is a first-order lag T_δ
with a rate limit δ̇_max. A sinusoid of amplitude δ_a is followed without rate limiting up to
ω = δ̇_max/δ_a; the servo's bandwidth for rudder motions of δ_a = 10° (the 10°/10° zig-zag's
rudder, IMO MSC.137(76)) is therefore taken as ω_δ = min(1/T_δ, δ̇_max/δ_a), and the loop is
checked with the servo as the lag 1/(1 + s/ω_δ).

**Rule** (Fossen 2021, *Handbook of Marine Craft Hydrodynamics and Motion Control*, 2nd ed.,
§15.3, PID pole placement on the Nomoto model): choose the closed-loop bandwidth ω_b with
1/|T| < ω_b < ω_δ (above the ship's own yaw dynamics, below the steering machine's); the
natural frequency follows from ω_b = ω_n √(1 − 2ζ² + √(4ζ⁴ − 4ζ² + 2)) and

    K_P = T ω_n² / K = ω_n² / b,    K_D = (2ζω_n T − 1) / K,    K_I = ω_n K_P / 10

(K_I only with ``integral``). The formulas hold for T < 0 (b > 0 still), where the −1/K term of
K_D stabilises the unstable pole. Default: ζ = 0.8 and ω_b the geometric mean √(ω_δ/|T|), an
equal factor from both limits. The gains are those of
:class:`~shipgnc.vessels.autopilot.HeadingAutopilot` (δ = δ₀ − K_P e − K_D r − K_I ∫e).

**Check.** The loop L(s) = (K_P + K_D s + K_I/s) · (r/δ)(s)/s · 1/(1 + s/ω_δ) on the full
linearised r/δ: closed-loop poles (stable?), gain and phase margins (``control.stability_margins``;
for a course-unstable ship the open loop is unstable and the gain margin is the factor by which a
*reduction* of the gain destabilises, < 1). A design whose loop is unstable or has a phase margin
below :data:`MIN_PHASE_MARGIN_DEG` is refused: the steering machine is too slow for the ship.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import control
import numpy as np

from shipgnc.errors import ConfigError, require

#: rudder amplitude at which the steering machine's rate limit sets its bandwidth [rad]
RUDDER_AMPLITUDE = math.radians(10.0)
#: the design rule's least phase margin [deg] (a design below it is refused, a hand-set gain noted)
MIN_PHASE_MARGIN_DEG = 30.0
DEFAULT_ZETA = 0.8


def _bandwidth_factor(zeta: float) -> float:
    """ω_b/ω_n of the second-order closed loop (Fossen 2021 §15.3)."""
    return math.sqrt(1 - 2 * zeta**2 + math.sqrt(4 * zeta**4 - 4 * zeta**2 + 2))


def yaw_response(model) -> control.TransferFunction:
    """r/δ of ``model`` linearised about its straight run (δ: the actual rudder angle)."""
    from shipgnc.vessels.scenario import straight_inputs

    x0 = np.asarray(model.straight_state(), dtype=float)
    u0 = straight_inputs(model)
    dyn = [3, 4, 5, *range(7, x0.size)]  # u, v, r and the extra states; δ (6) is the input

    def f(x):
        return np.asarray(model.derivatives(x, u0), dtype=float)[dyn]

    cols = []
    for j in [*dyn, 6]:
        h = 1e-6 * max(1.0, abs(x0[j]))
        xp, xm = x0.copy(), x0.copy()
        xp[j] += h
        xm[j] -= h
        cols.append((f(xp) - f(xm)) / (2 * h))
    A = np.column_stack(cols[:-1])
    B = cols[-1].reshape(-1, 1)
    C = np.zeros((1, len(dyn)))
    C[0, 2] = 1.0
    return control.minreal(control.tf(control.ss(A, B, C, 0.0)), verbose=False)


@dataclass(frozen=True)
class DesignModel:
    """ṙ = −r/T + bδ of the module docstring, with Nomoto's low-frequency reduction beside it."""

    K: float
    T: float
    b: float
    K_nomoto: float
    T_nomoto: float
    omega_delta: float
    r_over_delta: control.TransferFunction

    @property
    def course_stable(self) -> bool:
        return self.T > 0


def design_model(model) -> DesignModel:
    """The design model of ``model`` (module docstring)."""
    G = yaw_response(model)
    num = np.atleast_1d(np.ravel(G.num[0][0])).astype(float)
    den = np.atleast_1d(np.ravel(G.den[0][0])).astype(float)
    if den.size - num.size != 1:
        raise ConfigError(f"vessel: r/δ has relative degree {den.size - num.size}; the design needs "
                          "a rudder that acts on the yaw acceleration directly (degree 1)")
    b = float(num[0] / den[0])
    poles = np.asarray(control.poles(G))
    p = float(np.real(poles[np.argmax(np.real(poles))]))
    require(abs(p) > 1e-12 and b > 0, "vessel", f"pole {p:.3g}, b {b:.3g}",
            "the yaw response needs a non-zero dominant pole and positive rudder gain")
    T = -1.0 / p
    if abs(den[-1]) > 1e-14 and abs(num[-1]) > 1e-14:
        K_n = float(num[-1] / den[-1])
        T_n = float(den[-2] / den[-1] - (num[-2] / num[-1] if num.size > 1 else 0.0))
    else:
        K_n = T_n = math.nan
    omega_delta = min(1.0 / model.T_delta, model.delta_rate / RUDDER_AMPLITUDE)
    return DesignModel(K=b * T, T=T, b=b, K_nomoto=K_n, T_nomoto=T_n, omega_delta=omega_delta,
                       r_over_delta=G)


@dataclass(frozen=True)
class LoopCheck:
    """Closed-loop stability and margins of gains on the linearised loop (module docstring)."""

    stable: bool
    gain_margin: float
    phase_margin_deg: float
    crossover: float

    @property
    def poor(self) -> bool:
        return not self.stable or not self.phase_margin_deg >= MIN_PHASE_MARGIN_DEG

    def describe(self) -> str:
        gm = "inf" if not math.isfinite(self.gain_margin) else f"{self.gain_margin:.3g}"
        return (f"closed loop {'stable' if self.stable else 'UNSTABLE'}, phase margin "
                f"{self.phase_margin_deg:.1f}° at {self.crossover:.3g} rad/s, gain margin {gm}")


def check_loop(dm: DesignModel, Kp: float, Kd: float, Ki: float = 0.0) -> LoopCheck:
    """Stability and margins of δ = −K_P e − K_D r − K_I ∫e on ``dm``'s full r/δ with the servo."""
    s = control.tf("s")
    L = (Kp + Kd * s + Ki / s) * dm.r_over_delta / s / (1 + s / dm.omega_delta)
    gm, pm, _, _, wgc, _ = control.stability_margins(L)
    closed = control.feedback(L, 1)
    stable = bool(np.all(np.real(control.poles(closed)) < 0))
    return LoopCheck(stable, float(gm), float(pm), float(wgc))


@dataclass(frozen=True)
class AutopilotDesign:
    """Gains of the rule (module docstring), the model they were designed on and their check."""

    model: DesignModel
    bandwidth: float
    zeta: float
    omega_n: float
    Kp: float
    Kd: float
    Ki: float
    check: LoopCheck

    def heading_loop(self) -> control.TransferFunction:
        """ψ/ψ_d of the linearised loop: the derivative acts on r, not on the error (as
        :class:`~shipgnc.vessels.autopilot.HeadingAutopilot`), ψ/ψ_d = K_P P/(1 + (K_P + K_D s)P),
        P = (r/δ)/s · 1/(1 + s/ω_δ) (K_I left out)."""
        s = control.tf("s")
        P = self.model.r_over_delta / s / (1 + s / self.model.omega_delta)
        return control.feedback(self.Kp * P, 1 + (self.Kd / self.Kp) * s)

    def settling_time(self, threshold: float = 0.02) -> float:
        """Time [s] for the linearised loop's heading-step response to stay within ``threshold``
        of the step (python-control's ``step_info``); no saturation, no rate limit."""
        return float(control.step_info(self.heading_loop(),
                                       SettlingTimeThreshold=threshold)["SettlingTime"])

    def lines(self) -> list[str]:
        m = self.model
        kind = "course-stable" if m.course_stable else "course-UNSTABLE"
        return [
            f"design model: r/δ ≈ K/(1 + T s), K = {m.K:.4g} 1/s, T = {m.T:.4g} s ({kind}), "
            f"b = K/T = {m.b:.4g} 1/s²  (Nomoto's T1+T2-T3 reduction: K = {m.K_nomoto:.4g} 1/s, "
            f"T = {m.T_nomoto:.4g} s)",
            f"steering machine bandwidth ω_δ = {m.omega_delta:.4g} rad/s; allowed ω_b in "
            f"({1 / abs(m.T):.4g}, {m.omega_delta:.4g}) rad/s",
            f"bandwidth ω_b = {self.bandwidth:.4g} rad/s, ζ = {self.zeta:g}, ω_n = "
            f"{self.omega_n:.4g} rad/s",
            f"gains: Kp = {self.Kp:.4g} rad/rad, Kd = {self.Kd:.4g} s, Ki = {self.Ki:.4g} 1/s",
            f"check: {self.check.describe()}; a heading step settles within 2 % in "
            f"{self.settling_time():.3g} s (linearised, no rudder saturation or rate limit)",
        ]


def design_autopilot(model, *, bandwidth: float | None = None, zeta: float = DEFAULT_ZETA,
                     integral: bool = False) -> AutopilotDesign:
    """The heading autopilot of ``model`` by the rule of the module docstring; a one-line
    :class:`ConfigError` for a bandwidth the rudder cannot deliver or a loop it cannot hold."""
    require(isinstance(zeta, (int, float)) and math.isfinite(zeta) and 0.3 <= zeta <= 2.0,
            "controller.zeta", zeta, "damping ratio must be in [0.3, 2]")
    dm = design_model(model)
    low, high = 1.0 / abs(dm.T), dm.omega_delta
    if bandwidth is None:
        if low >= high:
            raise ConfigError(
                f"autopilot design: the ship's yaw dynamics (1/|T| = {low:.3g} rad/s, T = "
                f"{dm.T:.3g} s) are faster than the steering machine (ω_δ = {high:.3g} rad/s: "
                f"rate {math.degrees(model.delta_rate):.3g}°/s over {math.degrees(RUDDER_AMPLITUDE):g}°, "
                f"T_δ = {model.T_delta:.3g} s); no bandwidth fits (rudder_rate_deg_s, "
                "rudder_time_constant_s)")
        bandwidth = math.sqrt(low * high)
    require(isinstance(bandwidth, (int, float)) and math.isfinite(bandwidth) and low < bandwidth < high,
            "bandwidth", bandwidth,
            f"the rudder can deliver {low:.3g} < ω_b < {high:.3g} rad/s (above 1/|T|, below the "
            "steering machine's bandwidth)")
    omega_n = bandwidth / _bandwidth_factor(zeta)
    Kp = omega_n**2 / dm.b
    Kd = (2 * zeta * omega_n * dm.T - 1) / dm.K
    Ki = omega_n * Kp / 10 if integral else 0.0
    require(Kd >= 0, "zeta", zeta, f"gives a negative derivative gain ({Kd:.3g} s) at ω_b = "
            f"{bandwidth:.3g} rad/s; raise zeta or the bandwidth")
    check = check_loop(dm, Kp, Kd, Ki)
    if check.poor:
        raise ConfigError(
            f"autopilot design: ω_b = {bandwidth:.3g} rad/s leaves {check.describe()} (need a stable "
            f"loop and >= {MIN_PHASE_MARGIN_DEG:g}°): the steering machine (ω_δ = {high:.3g} rad/s) "
            f"is too slow for this ship (T = {dm.T:.3g} s)")
    return AutopilotDesign(dm, float(bandwidth), float(zeta), omega_n, Kp, Kd, Ki, check)
