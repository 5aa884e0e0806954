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

**Check.** The loop L(s) = (K_P + K_D s + K_I/s) · (r/δ)(s)/s · 1/(1 + s/ω_δ) · H(s) on the full
linearised r/δ, H the hold of an autopilot sampled every T_s (a delay T_s/2, its second-order Padé
approximant; H = 1 for a continuous design, the default of ``shipgnc design autopilot``; a
scenario's autopilot is checked at its ``Ts``): closed-loop poles (stable?), gain and phase
margins and the sensitivity peak M_s = max |1/(1 + L(jω))| (``control.stability_margins``; for a
course-unstable ship the open loop is unstable and the gain margin is the factor by which a
*reduction* of the gain destabilises, < 1). The settling time printed is the linearised loop's
with the servo as its own lag 1/(1 + T_δ s) (rudder motions too small for the rate limit). A
design whose loop is unstable or has a phase margin below :data:`MIN_PHASE_MARGIN_DEG` is refused.

**A ship that is course-unstable on the steering machine's time scale.** Fossen's rule leaves the
servo out of the design model; when the ship's unstable pole p = −1/T is near ω_δ (a small beamy
hull: the 12 m workboat above has p = 0.83 rad/s), no bandwidth of the rule passes the check. The
design then includes the servo and the full r/δ: among the PD gains whose closed loop is stable and
whose sensitivity peak is at most :data:`MAX_SENSITIVITY` = 1/(2 sin(30°/2)) = 1.93 (so that the
phase margin is ≥ 2 arcsin(1/(2 M_s)) = 30°, and the gain may change by a factor in
[1/(1 + 1/M_s), 1/(1 − 1/M_s)] = [0.66, 2.1]: the stability margin s_m = 1/M_s of Åström &
Murray, *Feedback Systems*, 2nd ed., 2021), it takes the one with the largest K_P (the stiffest
heading; Åström & Hägglund's MIGO idea of maximising the low-frequency gain under an M_s bound).
The gains are searched on a logarithmic grid (refined three times) around the servo's scales
K_P ~ ω_δ²/b, K_D ~ ω_δ/b, M_s on a logarithmic frequency grid, stability by the roots of the
closed loop's characteristic polynomial.
With ``integral`` K_I = ω_c K_P/10 (ω_c the loop's crossover) is added and the loop re-checked.
The ship is refused — in one line naming the numbers — when the steering machine is too slow: on
the design model ṙ = −r/T + bδ with the servo lag, a PD needs ω_δ > p (Routh: the closed loop
s(s − p)(1 + s/ω_δ) + b(K_P + K_D s) = (s³ + (ω_δ − p)s² + …)/ω_δ; with K_I the same two leading
terms), and otherwise when no PD reaches M_s ≤ 1.93.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import control
import numpy as np

from shipgnc.errors import ConfigError, require

#: rudder amplitude at which the steering machine's rate limit sets its bandwidth [rad]
RUDDER_AMPLITUDE = math.radians(10.0)
#: the design rule's least phase margin [deg] (a design below it is refused, a hand-set gain noted)
MIN_PHASE_MARGIN_DEG = 30.0
#: the largest sensitivity peak of the servo-aware design: M_s with 2 arcsin(1/(2 M_s)) = 30°
MAX_SENSITIVITY = 1.0 / (2.0 * math.sin(math.radians(MIN_PHASE_MARGIN_DEG) / 2.0))
DEFAULT_ZETA = 0.8
#: the servo-aware search: grid points per gain, refinements, frequency points
_GRID, _REFINE, _FREQS = 60, 3, 800


def _bandwidth_factor(zeta: float) -> float:
    """ω_b/ω_n of the second-order closed loop (Fossen 2021 §15.3)."""
    return math.sqrt(1 - 2 * zeta**2 + math.sqrt(4 * zeta**4 - 4 * zeta**2 + 2))


def yaw_response(model) -> control.TransferFunction:
    """r/δ of ``model`` linearised about its straight run (δ: the actual rudder angle)."""
    from shipgnc.vessels.scenario import straight_inputs

    x0 = np.asarray(model.straight_state(), dtype=float)
    u0 = straight_inputs(model)
    dyn = [3, 4, 5, *range(7, x0.size)]  # u, v, r and the extra states; δ (6) is the input

    from shipgnc.control.finite_state import numerical_jacobian

    J = numerical_jacobian(lambda x: np.asarray(model.derivatives(x, u0), dtype=float)[..., dyn], x0)
    A, B = J[:, dyn], J[:, 6:7]
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
    #: the autopilot's sampling period [s] (0: continuous); its hold is a delay Ts/2
    sample_time: float = 0.0
    #: the servo's own bandwidth 1/T_δ [rad/s]: its lag for rudder motions the rate limit leaves alone
    omega_servo: float = math.inf

    @property
    def course_stable(self) -> bool:
        return self.T > 0

    def actuator(self, small: bool = False) -> control.TransferFunction:
        """δ/δ_c: the servo lag 1/(1 + s/ω_δ) (``small``: 1/(1 + s/ω_servo), the lag of rudder
        motions too small for the rate limit) and the sample-and-hold's delay Ts/2 (second-order
        Padé approximant, ``control.pade``)."""
        s = control.tf("s")
        omega = self.omega_servo if small else self.omega_delta
        lag = 1 / (1 + s / omega) if math.isfinite(omega) else control.tf(1, 1)
        if self.sample_time <= 0:
            return lag
        return lag * control.tf(*control.pade(self.sample_time / 2, 2))

    def plant(self, small: bool = False) -> control.TransferFunction:
        """ψ/δ_c = (r/δ)/s · δ/δ_c (:meth:`actuator`)."""
        return self.r_over_delta / control.tf("s") * self.actuator(small)


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
                       omega_servo=1.0 / model.T_delta if model.T_delta > 0 else math.inf,
                       r_over_delta=G)


@dataclass(frozen=True)
class LoopCheck:
    """Closed-loop stability and margins of gains on the linearised loop (module docstring)."""

    stable: bool
    gain_margin: float
    phase_margin_deg: float
    crossover: float
    sensitivity_peak: float = math.nan  #: M_s = max |1/(1 + L(jω))|

    @property
    def poor(self) -> bool:
        return not self.stable or not self.phase_margin_deg >= MIN_PHASE_MARGIN_DEG

    def describe(self) -> str:
        gm = "inf" if not math.isfinite(self.gain_margin) else f"{self.gain_margin:.3g}"
        return (f"closed loop {'stable' if self.stable else 'UNSTABLE'}, phase margin "
                f"{self.phase_margin_deg:.1f}° at {self.crossover:.3g} rad/s, gain margin {gm}")


def check_loop(dm: DesignModel, Kp: float, Kd: float, Ki: float = 0.0) -> LoopCheck:
    """Stability and margins of δ = −K_P e − K_D r − K_I ∫e on ``dm``'s full r/δ with the servo
    (and the hold, :meth:`DesignModel.actuator`)."""
    s = control.tf("s")
    L = (Kp + Kd * s + Ki / s) * dm.plant()
    gm, pm, sm, _, wgc, _ = control.stability_margins(L)
    closed = control.feedback(L, 1)
    stable = bool(np.all(np.real(control.poles(closed)) < 0))
    return LoopCheck(stable, float(gm), float(pm), float(wgc),
                     1.0 / float(sm) if sm > 0 else math.inf)


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
    #: "pole placement" (Fossen's rule) or "servo-aware" (largest K_P at M_s <= 1.93)
    rule: str = "pole placement"

    def heading_loop(self, small: bool = False) -> control.TransferFunction:
        """ψ/ψ_d of the linearised loop: the derivative acts on r, not on the error (as
        :class:`~shipgnc.vessels.autopilot.HeadingAutopilot`), ψ/ψ_d = K_P P/(1 + (K_P + K_D s)P),
        P = ψ/δ_c (:meth:`DesignModel.plant`, ``small`` as there; K_I left out)."""
        s = control.tf("s")
        P = self.model.plant(small)
        return control.feedback(self.Kp * P, 1 + (self.Kd / self.Kp) * s)

    def settling_time(self, threshold: float = 0.02) -> float:
        """Time [s] for the linearised loop's heading-step response to stay within ``threshold``
        of the step (python-control's ``step_info``): no saturation, no rate limit (the servo as
        its own lag 1/(1 + T_δ s))."""
        return float(control.step_info(self.heading_loop(small=True),
                                       SettlingTimeThreshold=threshold)["SettlingTime"])

    def lines(self) -> list[str]:
        m, c = self.model, self.check
        kind = "course-stable" if m.course_stable else "course-UNSTABLE"
        if self.rule == "pole placement":
            rule = (f"rule: pole placement (Fossen 2021 §15.3), bandwidth ω_b = {self.bandwidth:.4g} "
                    f"rad/s, ζ = {self.zeta:g}, ω_n = {self.omega_n:.4g} rad/s")
        else:
            rule = (f"rule: servo-aware, the largest Kp with a stable loop and M_s <= "
                    f"{MAX_SENSITIVITY:.3g} (Fossen's rule, servo left out, fails the check); "
                    f"closed-loop bandwidth {self.bandwidth:.4g} rad/s")
        gm = "inf" if not math.isfinite(c.gain_margin) else f"{c.gain_margin:.3g}"
        gm_note = (" (open loop unstable: the factor of a gain REDUCTION that destabilises)"
                   if not m.course_stable else "")
        return [
            f"design model: r/δ ≈ K/(1 + T s), K = {m.K:.4g} 1/s, T = {m.T:.4g} s ({kind}), "
            f"b = K/T = {m.b:.4g} 1/s²  (Nomoto's T1+T2-T3 reduction: K = {m.K_nomoto:.4g} 1/s, "
            f"T = {m.T_nomoto:.4g} s)",
            f"steering machine bandwidth ω_δ = {m.omega_delta:.4g} rad/s"
            + (f"; allowed ω_b in ({1 / abs(m.T):.4g}, {m.omega_delta:.4g}) rad/s"
               if self.rule == "pole placement" else ""),
            rule,
            f"gains: Kp = {self.Kp:.4g} rad/rad, Kd = {self.Kd:.4g} s, Ki = {self.Ki:.4g} 1/s",
            "margins (linearised loop, steering machine as a lag 1/(1 + s/ω_δ)"
            + (f", sampled every {m.sample_time:g} s):" if m.sample_time > 0 else ", continuous):"),
            f"  closed loop       {'stable' if c.stable else 'UNSTABLE'}",
            f"  phase margin      {c.phase_margin_deg:.1f}° at {c.crossover:.3g} rad/s "
            f"(required >= {MIN_PHASE_MARGIN_DEG:g}°)",
            f"  gain margin       {gm}{gm_note}",
            f"  sensitivity peak  M_s = {c.sensitivity_peak:.3g}",
            f"  heading step      settles within 2 % in {self.settling_time():.3g} s "
            "(no rudder saturation or rate limit)",
        ]


def _servo_aware(dm: DesignModel) -> tuple[tuple[float, float, float] | None, float]:
    """((K_P, K_D, M_s) of the servo-aware rule (module docstring) or None, the least M_s of a
    stabilising PD on the first grid: what the steering machine allows)."""
    P = dm.plant()  # ψ/δ_c
    num = np.ravel(P.num[0][0]).astype(float)
    open_den = np.ravel(P.den[0][0]).astype(float)
    wd = dm.omega_delta
    scales = np.abs(np.roots(open_den))
    scales = scales[scales > 1e-12]
    w = np.logspace(math.log10(0.01 * min(scales.min(initial=wd), wd)),
                    math.log10(100 * max(scales.max(initial=wd), wd)), _FREQS)
    s = 1j * w
    plant = np.polyval(num, s) / np.polyval(open_den, s)

    def stable(kp: float, kd: float) -> bool:
        return bool(np.all(np.real(np.roots(np.polyadd(open_den, np.polymul(num, [kd, kp])))) < 0))

    def grid(low, high):
        kp, kd = np.meshgrid(np.exp(np.linspace(low[0], high[0], _GRID)),
                             np.exp(np.linspace(low[1], high[1], _GRID)), indexing="ij")
        ms = 1.0 / np.min(np.abs(1 + (kp[..., None] + kd[..., None] * s) * plant), axis=-1)
        return kp.ravel(), kd.ravel(), ms.ravel()

    centre = np.log([wd**2 / dm.b, wd / dm.b])
    low, high = centre - np.log([1e4, 1e3]), centre + np.log([1e2, 1e2])
    best = None
    for refinement in range(_REFINE + 1):
        kp, kd, ms = grid(low, high)
        ok = [i for i in np.argsort(-kp, kind="stable") if ms[i] <= MAX_SENSITIVITY]
        found = next((i for i in ok if stable(kp[i], kd[i])), None)
        if found is None:
            if refinement == 0:
                least = next((ms[i] for i in np.argsort(ms) if stable(kp[i], kd[i])), math.inf)
                return None, float(least)
            break
        best = (float(kp[found]), float(kd[found]), float(ms[found]))
        step = 2 * (high - low) / (_GRID - 1)
        low, high = np.log(best[:2]) - step, np.log(best[:2]) + step
    return best, best[2]


def design_autopilot(model, *, bandwidth: float | None = None, zeta: float = DEFAULT_ZETA,
                     integral: bool = False, sample_time: float = 0.0) -> AutopilotDesign:
    """The heading autopilot of ``model`` by the rule of the module docstring, for an autopilot
    sampled every ``sample_time`` seconds (0: continuous; the hold checked as a delay of half a
    period); a one-line :class:`ConfigError` for a bandwidth the rudder cannot deliver or a loop
    it cannot hold."""
    require(isinstance(zeta, (int, float)) and math.isfinite(zeta) and 0.3 <= zeta <= 2.0,
            "controller.zeta", zeta, "damping ratio must be in [0.3, 2]")
    require(isinstance(sample_time, (int, float)) and math.isfinite(sample_time)
            and sample_time >= 0, "controller.Ts", sample_time, "must be a period >= 0 s")
    dm = dataclasses.replace(design_model(model), sample_time=float(sample_time))
    low, high = 1.0 / abs(dm.T), dm.omega_delta
    if bandwidth is None and not dm.course_stable:
        if low < high:
            design = _pole_placement(dm, math.sqrt(low * high), zeta, integral)
            if not design.check.poor:
                return design
        return _servo_aware_design(dm, model, integral)
    if bandwidth is None:
        if low >= high:
            raise ConfigError(
                f"autopilot design: the ship's yaw dynamics (1/|T| = {low:.3g} rad/s, T = "
                f"{dm.T:.3g} s) are faster than the steering machine (ω_δ = {high:.3g} rad/s: "
                f"{_servo_text(model)}); no bandwidth fits (rudder_rate_deg_s, "
                "rudder_time_constant_s)")
        bandwidth = math.sqrt(low * high)
    require(isinstance(bandwidth, (int, float)) and math.isfinite(bandwidth) and low < bandwidth < high,
            "bandwidth", bandwidth,
            f"the rudder can deliver {low:.3g} < ω_b < {high:.3g} rad/s (above 1/|T|, below the "
            "steering machine's bandwidth)")
    design = _pole_placement(dm, bandwidth, zeta, integral)
    require(design.Kd >= 0, "zeta", zeta, f"gives a negative derivative gain ({design.Kd:.3g} s) "
            f"at ω_b = {bandwidth:.3g} rad/s; raise zeta or the bandwidth")
    if design.check.poor:
        raise ConfigError(
            f"autopilot design: ω_b = {bandwidth:.3g} rad/s leaves {design.check.describe()} (need "
            f"a stable loop and >= {MIN_PHASE_MARGIN_DEG:g}°): the steering machine (ω_δ = "
            f"{high:.3g} rad/s) is too slow for this ship (T = {dm.T:.3g} s)")
    return design


def _servo_text(model) -> str:
    return (f"rate {math.degrees(model.delta_rate):.3g}°/s over {math.degrees(RUDDER_AMPLITUDE):g}°, "
            f"T_δ = {model.T_delta:.3g} s")


def _pole_placement(dm: DesignModel, bandwidth: float, zeta: float, integral: bool) -> AutopilotDesign:
    """Fossen's rule (module docstring) at ``bandwidth``, checked."""
    omega_n = bandwidth / _bandwidth_factor(zeta)
    Kp = omega_n**2 / dm.b
    Kd = (2 * zeta * omega_n * dm.T - 1) / dm.K
    Ki = omega_n * Kp / 10 if integral else 0.0
    return AutopilotDesign(dm, float(bandwidth), float(zeta), omega_n, Kp, Kd, Ki,
                           check_loop(dm, Kp, Kd, Ki))


def _servo_aware_design(dm: DesignModel, model, integral: bool) -> AutopilotDesign:
    """The servo-aware rule (module docstring) for a course-unstable ship, or its refusal."""
    p = -1.0 / dm.T
    servo = f"the steering machine (ω_δ = {dm.omega_delta:.3g} rad/s: {_servo_text(model)})"
    if dm.sample_time > 0:
        servo += f" with the autopilot sampled every {dm.sample_time:.3g} s"
    fix = "a faster steering machine (rudder_rate_deg_s, rudder_time_constant_s)"
    if dm.sample_time > 0:
        fix += " or a faster autopilot (controller.Ts, simulation.dt)"
    if dm.omega_delta <= p:
        raise ConfigError(
            f"autopilot design: the ship's unstable yaw pole (p = {p:.3g} rad/s, T = {dm.T:.3g} s) "
            f"is faster than {servo}: no PD or PID holds it with ω_δ <= p; give it {fix}")
    found, least = _servo_aware(dm)
    if found is None:
        reach = f"the best PD reaches M_s = {least:.3g}" if math.isfinite(least) else \
            "no PD of the search stabilises it"
        raise ConfigError(
            f"autopilot design: {servo} is too slow for the ship's unstable yaw pole (p = {p:.3g} "
            f"rad/s): {reach}, the design needs M_s <= {MAX_SENSITIVITY:.3g} (phase margin >= "
            f"{MIN_PHASE_MARGIN_DEG:g}°); give it {fix}")
    Kp, Kd, _ = found
    Ki = 0.0
    if integral:
        Ki = check_loop(dm, Kp, Kd).crossover * Kp / 10
    check = check_loop(dm, Kp, Kd, Ki)
    if check.poor:
        raise ConfigError(f"autopilot design: the integral gain Ki = {Ki:.3g} 1/s leaves "
                          f"{check.describe()}; design without integral action")
    design = AutopilotDesign(dm, math.nan, math.nan, math.nan, Kp, Kd, Ki, check, "servo-aware")
    return dataclasses.replace(design, bandwidth=float(control.bandwidth(design.heading_loop())))
