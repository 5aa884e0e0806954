"""
Your vessel, your autopilot
===========================

From a ship's main dimensions to a tuned heading autopilot checked in waves and in a Monte Carlo,
in one script (it runs at every build of this site, so every number and figure below is what the
code gives today). The steps:

1. a linear manoeuvring model from the main dimensions (Clarke, Gedling & Hine 1983);
2. the model as a shipgnc vessel, its rudder-step and turning response;
3. a heading autopilot designed for the ship from its linearised yaw response, to a stated
   bandwidth and damping, its margins checked with python-control;
4. the autopilot on the simulated ship, with its steering machine;
5. the same in irregular waves;
6. a Monte Carlo: thirty ships, each in its own sea and with its own initial heading;
7. the same path with the command line: a vessel file, its IMO trials, a scenario with the
   designed autopilot and a Monte Carlo study, each a command to copy.

Download the script at the bottom of the page and change the dimensions to your ship's. A small
beamy hull is a different animal: Clarke's regressions, extrapolated to a 12 m workboat
(L 12 m, B 4 m, T 1.2 m, C_b 0.5, 10 kn; L/B = 3, T/L = 0.1), give a course-unstable ship with a
yaw pole at +0.83 rad/s, 1.9 in units of U/L (the 300 m tanker of step 7 has 0.19), once the
rigid body's centripetal terms are in the equations (Fossen's MSS ``clarke83`` leaves them out
and calls the same hull course-stable). Such a ship needs a steering machine faster than its
pole: with the large-ship rudder (2.32°/s, T_δ = 1 s) the design refuses it in one line naming
both numbers; with a small craft's (``rudder_rate_deg_s: 20``, ``rudder_time_constant_s: 0.2``)
and the autopilot sampled at 10 Hz, it designs the gains with the steering machine in the loop
(step 3, and step 7's workboat).
"""

# %%
# 1. A model from the main dimensions
# -----------------------------------
# A slender 60 m vessel at 12 knots. :func:`~shipgnc.models.linear3dof.clarke83` returns the inertia
# matrix M and the damping matrix N(U) of M ν̇ + N ν = τ over (surge, sway, yaw), from Clarke et
# al.'s regressions; :func:`~shipgnc.models.linear3dof.rudder_input` gives the rudder's force and
# moment per radian, B.

import math
from dataclasses import dataclass

import control
import matplotlib.pyplot as plt
import numpy as np

from shipgnc import simulate
from shipgnc.guidance.schedule import CourseSchedule
from shipgnc.models.base import Signal
from shipgnc.models.linear3dof import clarke83, rudder_input

L, B, T, Cb = 60.0, 8.0, 3.5, 0.45           # length, beam, draft [m], block coefficient
U = 12 * 1852 / 3600                          # speed [m/s]
M, N = clarke83(U, L, B, T, Cb, R66=0.25 * L, xg=0.0, T_surge=L)
b = rudder_input(U, L, T)                     # (3, 1): [X, Y, N] per rad of rudder
print("M =\n", M.round(0), "\nN =\n", N.round(0), "\nb =", b.ravel().round(0))

# %%
# The sway–yaw part is a two-state linear system with the rudder as input; python-control gives
# its transfer function r/δ, a second-order Nomoto model K(1 + T₃s)/((1 + T₁s)(1 + T₂s)) (here
# with two real poles, one slow: a slender hull, course-stable; a beamier, fuller one, e.g.
# B = 11 m, C_b = 0.6, is course-unstable once the rigid body's centripetal terms are in N), and
# its first-order reduction K/(1 + Ts) with T = T₁ + T₂ − T₃.

A_sy = -np.linalg.solve(M[1:, 1:], N[1:, 1:])
B_sy = np.linalg.solve(M[1:, 1:], b[1:])
yaw = control.ss(A_sy, B_sy, [[0.0, 1.0]], [[0.0]])     # δ [rad] → r [rad/s]
G_r = control.tf(yaw)
K = float(control.dcgain(G_r))
T1_plus_T2 = float(np.real(-np.sum(1.0 / control.poles(G_r))))   # Σ −1/pᵢ, real or complex pair
T3 = float(-1.0 / np.real(control.zeros(G_r))[0])
T_nomoto = T1_plus_T2 - T3
stable = bool(all(np.real(control.poles(G_r)) < 0))
print(f"poles {np.round(control.poles(G_r), 4)}: course-{'stable' if stable else 'UNSTABLE'}")
print(f"Nomoto: K = {K:.4f} 1/s, T1 + T2 = {T1_plus_T2:.2f} s, T3 = {T3:.2f} s, T = {T_nomoto:.2f} s")

# %%
# 2. The model as a shipgnc vessel
# --------------------------------
# A vessel is a small class with named states, inputs and disturbances and a vectorised
# ``derivatives`` (:doc:`/extending`). Here the state is the catalogue vessels' layout
# (north, east, ψ, u, v, r, δ), the input the commanded rudder, the steering machine a first-order
# lag with a rate limit, and the disturbance a body-frame force [X, Y, N] that waves will fill.

@dataclass(frozen=True, eq=False)
class MyShip:
    M: np.ndarray
    N: np.ndarray
    b: np.ndarray
    U: float
    delta_max: float = math.radians(35.0)
    delta_rate: float = math.radians(2.32)    # IMO: 35° to the other side's 30° in 28 s
    T_delta: float = 1.0
    states = (Signal("north", "m"), Signal("east", "m"), Signal("psi", "rad", angle=True),
              Signal("u", "m/s"), Signal("v", "m/s"), Signal("r", "rad/s"),
              Signal("delta", "rad", "rudder angle", angle=True))
    inputs = (Signal("delta_c", "rad", "commanded rudder angle", angle=True),)
    disturbances = (Signal("X_env", "N"), Signal("Y_env", "N"), Signal("N_env", "N*m"))
    state_limits = (1e8, 1e8, 1e4, 50.0, 50.0, 5.0, 2.0)

    @property
    def params(self):
        return self

    def input_limits(self):
        return np.array([-self.delta_max]), np.array([self.delta_max])

    def derivatives(self, x, u, d=None):
        psi, delta = x[..., 2], x[..., 6]
        nu = np.stack([x[..., 3] - self.U, x[..., 4], x[..., 5]], axis=-1)   # surge about U
        tau = delta[..., None] * self.b[:, 0]
        if d is not None:
            tau = tau + d
        nu_dot = np.linalg.solve(self.M, (tau - nu @ self.N.T)[..., None])[..., 0]
        c, s = np.cos(psi), np.sin(psi)
        delta_dot = np.clip((u[..., 0] - delta) / self.T_delta, -self.delta_rate, self.delta_rate)
        return np.stack([x[..., 3] * c - x[..., 4] * s, x[..., 3] * s + x[..., 4] * c, x[..., 5],
                         nu_dot[..., 0], nu_dot[..., 1], nu_dot[..., 2], delta_dot], axis=-1)


ship = MyShip(M, N, b, U)
straight = np.array([0.0, 0.0, 0.0, U, 0.0, 0.0, 0.0])

# %%
# **Rudder step and turning circle.** Ten degrees of rudder, held: the yaw rate settles at the
# steady turn N ν = B δ, and the track is a circle of radius U/r. The simulated ship includes the
# steering machine, which the transfer function does not; the steady states agree.

delta = math.radians(10.0)
turn = simulate(ship, straight, t_end=400.0, dt=0.1, u0=np.array([delta]))
r_ss = np.linalg.solve(N, b[:, 0] * delta)[2]
print(f"steady yaw rate: simulated {float(turn.r[-1]):.5f}, N ν = B δ gives {r_ss:.5f} rad/s; "
      f"radius {U / r_ss:.0f} m")
assert abs(float(turn.r[-1]) - r_ss) < 1e-3 * abs(r_ss)

# the vessel catalogue builds the same model from the same dimensions (shipgnc vessels lists it)
from shipgnc.vessels import get_vessel  # noqa: E402

catalogue = get_vessel("linear-3dof").build(U, L=L, B=B, T=T, Cb=Cb)
print("catalogue's linear-3dof steady turn:", catalogue.steady_turn(delta).round(5))

t_lin, r_lin = control.step_response(G_r * delta, T=np.linspace(0, 150, 301))
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
ax1.plot(turn.time, np.degrees(turn.r), label="simulated (with the steering machine)")
ax1.plot(t_lin, np.degrees(r_lin), "--", label="transfer function r/δ")
ax1.set(xlim=(0, 150), xlabel="time [s]", ylabel="yaw rate [deg/s]", title="10° rudder step")
ax1.legend()
ax2.plot(turn.east, turn.north)
ax2.set(xlabel="east [m]", ylabel="north [m]", aspect="equal", title="turning circle, 10° rudder")
fig.tight_layout()

# %%
# 3. Designing the autopilot
# --------------------------
# A PD (or PID) on the heading error, δ = −K_P e − K_D r − K_I ∫e (the catalogue's
# :class:`~shipgnc.vessels.autopilot.HeadingAutopilot`), designed by
# :func:`~shipgnc.vessels.autopilot_design.design_autopilot` (the same as
# ``shipgnc design autopilot`` and a scenario's ``controller: {type: course, design: auto}``):
# the vessel is linearised at its speed and reduced to ψ/δ = K/(s(1 + Ts)) keeping the dominant
# pole and the rudder's yaw acceleration; Fossen's pole placement (Handbook 2021, §15.3) gives
# K_P = Tω_n²/K, K_D = (2ζω_nT − 1)/K, K_I = ω_n K_P/10, for a bandwidth between :math:`1/|T|` (the
# ship's own yaw dynamics) and the steering machine's (its time constant, and its rate limit over
# 10° of rudder). The loop is then checked on the full linearised model with the steering machine
# as a lag: its closed-loop poles and margins. For a ship whose unstable yaw pole is near the
# steering machine's bandwidth (the small beamy hull above), Fossen's rule, which leaves the servo
# out, fails that check; the design then searches the PD gains with the servo (and the
# autopilot's sampling) in the loop, the stiffest whose sensitivity peak is at most 1.93 (a phase
# margin of at least 30°), and refuses the ship, in one line, only when the steering machine is
# too slow for it.

from shipgnc.vessels.autopilot import HeadingAutopilot  # noqa: E402
from shipgnc.vessels.autopilot_design import design_autopilot  # noqa: E402

design = design_autopilot(catalogue)   # integral=True adds K_I = ω_n K_P/10
print("\n".join(design.lines()))
assert design.check.stable and design.check.phase_margin_deg >= 30.0

# %%
# **Damping.** The same bandwidth at three damping ratios: the linearised loop's heading steps
# (the derivative acts on the yaw rate, not on the error, as in the autopilot).

fig, ax = plt.subplots(figsize=(7, 3.8))
for zeta in (0.7, 0.8, 1.0):
    d = design_autopilot(catalogue, bandwidth=design.bandwidth, zeta=zeta)
    t, y = control.step_response(d.heading_loop(), T=np.linspace(0, 4 * design.settling_time(), 601))
    ax.plot(t, np.ravel(y), label=f"ζ = {zeta:g}: phase margin {d.check.phase_margin_deg:.0f}°")
ax.set(xlabel="time [s]", ylabel="heading / heading command",
       title=f"closed-loop step, linearised, ω_b = {design.bandwidth:.3g} rad/s")
ax.legend()
fig.tight_layout()
kp, kd, ki = design.Kp, design.Kd, design.Ki


def autopilot():
    return HeadingAutopilot(kp, kd, ki, Ts=0.5, delta_max=ship.delta_max)


# %%
# 4. On the simulated ship
# ------------------------
# Course changes of +20° and −30°, with the rudder's saturation and rate limit in the loop.

course = CourseSchedule([0.0, 100.0], np.radians([20.0, -10.0]))
calm = simulate(ship, straight, t_end=300.0, dt=0.1, controller=autopilot(), guidance=course)
fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 5), sharex=True)
ax1.plot(calm.time, np.degrees(calm.psi), label="ψ")
ax1.step([0, 100, 300], [20, -10, -10], where="post", color="k", ls=":", label="ψ_d")
ax1.set(ylabel="heading [deg]", title="course changes in calm water")
ax1.legend()
ax2.plot(calm.time, np.degrees(calm.delta), label="rudder")
ax2.plot(calm.time, np.degrees(calm.delta_c), lw=0.8, label="command")
ax2.set(xlabel="time [s]", ylabel="rudder [deg]")
ax2.legend()
fig.tight_layout()
final_error = float(np.degrees(abs(calm.psi_error.sel(time=slice(250, None)))).max())
print(f"heading error over the last 50 s: {final_error:.3f}°")
assert final_error < 1.0

# %%
# What overshoot there is comes from the rudder's rate limit, which the linear design leaves out.
# A PD leaves a steady error under a constant yaw moment (wind, a current's drift does not
# turn the ship); ``integral=True`` adds a slow integrator that takes it back.

# %%
# 5. In waves
# -----------
# Irregular bow-quartering seas of significant height 2 m and modal period 8 s (a modified
# Pierson–Moskowitz spectrum) act on the hull through their Froude–Krylov loads
# (:class:`~shipgnc.environment.waves.FroudeKrylovWaveLoads`, a box of the ship's main dimensions;
# ``backend="numpy"`` skips compiling its kernel for this short run). The autopilot cannot and
# should not cancel the wave-frequency yaw; what matters is that the course is held and the rudder
# does not chase every wave.

from shipgnc.environment.waves import FroudeKrylovWaveLoads, WaveSpectrum  # noqa: E402

sea = WaveSpectrum.modified_pierson_moskowitz(2.0, 8.0)


def waves():
    return FroudeKrylovWaveLoads(sea, direction=math.radians(200.0), n_components=60, length=L,
                                 beam=B, draft=T, rho=1025.0, backend="numpy")


rough = simulate(ship, straight, t_end=300.0, dt=0.1, controller=autopilot(), guidance=course,
                 disturbance=waves(), seed=3)
fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 5), sharex=True)
for res, name in ((calm, "calm"), (rough, "waves, Hs 2 m")):
    ax1.plot(res.time, np.degrees(res.psi), label=name)
    ax2.plot(res.time, np.degrees(res.delta), label=name)
ax1.set(ylabel="heading [deg]", title="the same autopilot in waves")
ax2.set(xlabel="time [s]", ylabel="rudder [deg]")
ax1.legend()
fig.tight_layout()
steady = rough.sel(time=slice(200, None))
rms = {name: float(np.degrees(np.sqrt((steady[name] ** 2).mean()))) for name in ("psi_error", "delta")}
print(f"in waves, last 100 s: heading error RMS {rms['psi_error']:.2f}°, rudder RMS {rms['delta']:.2f}°")

# %%
# 6. A Monte Carlo
# ----------------
# Thirty ships in one batched run: each starts with its own heading error (uniform ±20°) and meets
# its own realisation of the same sea (``seed`` fixes them all). The batch axis comes first in
# every array; the result has dimensions (time, ship).

rng = np.random.default_rng(0)
x0 = np.tile(straight, (30, 1))
x0[:, 2] = np.radians(rng.uniform(-20.0, 20.0, 30))
fleet = simulate(ship, x0, t_end=180.0, dt=0.1, controller=autopilot(),
                 guidance=CourseSchedule([0.0], [0.0]), disturbance=waves(), seed=11)
late = fleet.sel(time=slice(120, None))
err_rms = np.degrees(np.sqrt((late.psi_error**2).mean("time"))).values
rud_rms = np.degrees(np.sqrt((late.delta**2).mean("time"))).values
print(f"{fleet.sizes['ship']} ships: heading error RMS median {np.median(err_rms):.2f}°, "
      f"max {err_rms.max():.2f}°; rudder RMS median {np.median(rud_rms):.2f}°")
assert err_rms.max() < 5.0

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 3.8))
ax1.plot(fleet.time, np.degrees(fleet.psi_error), color="C0", lw=0.5, alpha=0.5)
ax1.set(xlabel="time [s]", ylabel="heading error [deg]", title="30 ships, each in its own sea")
ax2.scatter(err_rms, rud_rms)
ax2.set(xlabel="heading error RMS after 120 s [deg]", ylabel="rudder RMS [deg]",
        title="what the autopilot costs")
fig.tight_layout()


# %%
# 7. The same with the command line
# ---------------------------------
# The catalogue path: the vessel as a file, its standard trials with the IMO MSC.137(76) verdicts,
# the autopilot designed for it, a scenario that steers it with that autopilot, and a Monte Carlo
# over its block coefficient (±10 %, the plant only: the autopilot keeps its nominal design) and
# its initial heading. Save the two files and run the commands in a shell (with the virtual
# environment active); change the dimensions in both files to your ship's.

VESSEL_FILE = """\
# my-vessel.yaml: a 60 m vessel at 12 kn from its main dimensions (SI)
vessel: {model: linear-3dof, speed_mps: 6.173, L: 60, B: 8, T: 3.5, Cb: 0.45}
"""

SCENARIO_FILE = """\
# my-heading.yaml: a 20 deg course change with the autopilot designed for the vessel
name: my-heading
metrics: course-quality
vessel: {model: linear-3dof, speed_mps: 6.173, L: 60, B: 8, T: 3.5, Cb: 0.45}
simulation: {dt: 0.1, t_end: 300.0}
controller: {type: course, design: auto}   # or: bandwidth: 0.08 (rad/s), zeta: 1.0
guidance:
  type: course-schedule
  schedule:
    - {t: 0.0, psi_deg: 0.0}
    - {t: 20.0, psi_deg: 20.0}
"""

COMMANDS = """\
shipgnc trial all --vessel my-vessel.yaml --out runs/my-vessel-trials
shipgnc design autopilot --vessel my-vessel.yaml --sample-time 0.1
shipgnc run my-heading.yaml --out runs/my-heading
shipgnc sweep my-heading.yaml --mc 20 --perturb vessel.params.Cb=normal:10% \\
    --perturb psi_deg=uniform:-10,10 --out runs/my-heading-mc
"""
print(VESSEL_FILE, SCENARIO_FILE, COMMANDS, sep="\n")

# %%
# For the 12 m workboat, change the vessel line in both files to
#
# .. code-block:: yaml
#
#    vessel: {model: linear-3dof, speed_mps: 5.144, L: 12, B: 4, T: 1.2, Cb: 0.5,
#             rudder_rate_deg_s: 20, rudder_time_constant_s: 0.2}
#
# ``shipgnc design autopilot`` then prints the servo-aware rule's gains and its margins table
# (closed loop stable, phase margin ≥ 30°, sensitivity peak M_s ≤ 1.93, the linearised settling
# time); the run settles the 20° step in about half a minute. Its trials, and the 300 m tanker's,
# are refused in one line: a linear model of a course-unstable ship has no steady turn, and its
# turning circle and pull-out would grow without bound.
#
# ``shipgnc trial all`` prints every trial and the IMO table (yes/NO per criterion) and writes
# the figures; ``shipgnc design autopilot`` prints the design model, the allowed bandwidths, the
# gains, the margins and the predicted settling time; the run writes ``metrics.json`` (settling,
# overshoot, rudder use) and its figures; the sweep writes ``summary.md`` (median and 5–95 %
# band of every metric) and ``sweep.nc``, with each member's drawn ``Cb`` and initial heading.
