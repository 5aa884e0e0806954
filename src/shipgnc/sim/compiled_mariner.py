"""Compiled (numba) twin of :func:`shipgnc.sim.simulator.run_numpy` for document 000's Mariner.

Covers :class:`~shipgnc.models.mariner.MarinerWitOppe` (eq. (25), sway algebraic) steered by

* no controller (constant ``u0``), :class:`~shipgnc.control.lqr.PathLQR` (with or without
  anti-windup), :class:`~shipgnc.control.feedback_linearization.OutputFL` (any look-ahead,
  ``fl_paper`` and ``fl_lookahead``) or :class:`~shipgnc.control.feedback_linearization.LOSFL`,
  sampled every ``Ts`` with the command held, each with its own leg tracking (A6) and the signals
  it logs; no guidance object (the path controllers do their own geometry);
* a one-channel :class:`~shipgnc.actuators.Actuator` without lag: saturation and an optional rate
  limit, ``rate_mode`` ``"ramp"`` or ``"hold"``;
* no disturbance, a :class:`~shipgnc.environment.disturbance.ConstantDisturbance`, or a
  :class:`~shipgnc.models.mariner.MarinerDisturbance`: constant b_r, an optional
  :class:`~shipgnc.environment.current.CrossCurrent` (``"path"``: across the leg its own tracker
  finds at each step's start; ``"global"``: along east) and optional
  :class:`~shipgnc.environment.filtered_noise.SecondOrderNoise` waves;
* fixed-step RK4, no observer.

:func:`unsupported_reason` names what is not covered; ``simulate`` then uses the numpy loop.
:func:`run` returns the same ``Log`` as ``run_numpy``, through the driver shared with the boat's
twin (:mod:`shipgnc.sim.compiled`: chunked calls for progress, divergence replay, status and
divergence errors).

**Wave noise** does not depend on the state: the ``SecondOrderNoise`` object itself computes it
in numpy, chunk by chunk before each kernel call (``waves(t)`` at every step time, after the
disturbance's ``reset(batch, rng)``), so it draws from the simulator's generator exactly as the
numpy loop does: same seed, same sea, and the generator ends in the same state. After a
divergence the numpy loop stops drawing at the bad step, this loop at the end of the chunk
(≤ 2²¹ ship-steps); only a caller reusing a Generator passed as ``seed`` can tell.

**End state of the components**, as the numpy loop leaves them: the controller's active leg,
PathLQR's e_I and the logged signal values, the path current's active leg, the wave filter's state.

Kernel layout as the boat's (ships in ``numba.prange``, time inside, one ship's state in local
scalars); the arithmetic follows the numpy code operation for operation, with these shortcuts,
which change results only at round-off level (the closed loops are stable except ``fl_paper``,
whose zero dynamics amplify any round-off by e^{t/9 s}):

* sin ψ, cos ψ of the RK4 stages from one libm call per step (angle addition,
  :func:`~shipgnc.sim.compiled._sin_cos_shifted`);
* r³ = r·r·r (numpy's ``r**3`` calls ``pow``: within an ulp);
* the legs' cos, sin (path frame, current) are computed once per run by numpy, not per sample;
* LLVM may fuse multiply-adds and turn x/c into x·(1/c) (``fastmath={"contract", "arcp"}``);
  a fused product does not overflow by itself, so where numpy forms inf − inf = NaN from two
  overflowing products the kernel may get ±inf instead (only with absurd gains).
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.errors import ConfigError
from shipgnc.sim.compiled import (
    _clip,
    _numba_error,
    _owned,
    _sin_cos_shifted,
    _wrap,
    drive,
    jit,
    log_layout,
    log_length,
    make_log,
)

#: slots of the per-ship carried state ``S`` (N, N_SLOTS): states, command, applied input at the
#: step's end, the controller's four logged signals, e_I, the controller's and the current's leg
X0, CMD, APPLIED, SIG, E_I, LEG, LEG_D = 0, 5, 6, 7, 11, 12, 13
N_SLOTS = 14
#: controller modes of the kernel
CTRL_NONE, CTRL_LQR, CTRL_FL, CTRL_LOS = 0, 1, 2, 3
#: columns of a path's leg table (:func:`_legs`)
LEG_NORTH, LEG_EAST, LEG_COS, LEG_SIN, LEG_LENGTH, LEG_ANGLE = range(6)
#: most wave-noise values (ships × steps) computed ahead of one kernel call (16 MB)
WAVE_CHUNK = 2**21

# ``prange`` is bound to ``numba.prange`` by _load() before the kernel is compiled; until then the
# functions below are plain Python (readable, and usable to debug the kernel without numba).
prange = range

_KERNEL = None


# ----------------------------------------------------------------------------------------------
# scalar twins of LegTracker.update, MarinerWitOppe.derivatives and the controllers' step
# ----------------------------------------------------------------------------------------------

def _sign(value):
    """``np.sign`` for one float (NaN passes through)."""
    if value > 0.0:
        return 1.0
    if value < 0.0:
        return -1.0
    if value == 0.0:
        return 0.0
    return value


def _track(north, east, leg, legs):
    """:meth:`LegTracker.update` for one ship: ``(leg, x_r, y_r)`` after any due switches (A6).

    ``legs`` is a path's leg table (:func:`_legs`); the path frame is :func:`frames.path_frame`.
    """
    last = legs.shape[0] - 1
    while True:
        dn = north - legs[leg, LEG_NORTH]
        de = east - legs[leg, LEG_EAST]
        c = legs[leg, LEG_COS]
        s = legs[leg, LEG_SIN]
        x_r = dn * c + de * s
        y_r = -dn * s + de * c
        if leg < last and x_r >= legs[leg, LEG_LENGTH]:
            leg += 1
        else:
            return leg, x_r, y_r


def _mariner_rhs(c, s, su, sr, delta, yaw, current_n, current_e, a, b, k_c, r1, r2, f, W, thrust):
    """ẋ of eq. (25) for one ship; c, s = cos ψ, sin ψ; the disturbance [b_r, c_N, c_E] is held
    over the step. Twin of :meth:`MarinerWitOppe.derivatives` (same operation order)."""
    r3 = sr * sr * sr
    v = r1 * sr + r2 * r3
    north_dot = c * su - s * v + current_n
    east_dot = s * su + c * v + current_e
    r_dot = -a * sr - b * r3 + k_c * delta + yaw
    u_dot = -f * su - W * sr * sr + thrust
    return north_dot, east_dot, sr, u_dot, r_dot


def _path_lqr(y_r, psi_r, r, e_I, cp):
    """:meth:`PathLQR.step` for one ship: ``(δ, e_I after the update)`` (cp: :func:`_controller`)."""
    delta_max, k_y, k_psi, k_r, k_e, Ts, anti_windup = cp[0], cp[1], cp[2], cp[3], cp[4], cp[5], cp[6]
    raw = -(y_r * k_y + psi_r * k_psi + r * k_r + e_I * k_e)
    delta = _clip(raw, -delta_max, delta_max)
    integrate = True
    if anti_windup != 0.0:  # hold e_I when integrating would deepen the saturation
        deepens = _sign(-k_e * y_r) == _sign(raw)
        integrate = abs(raw) <= delta_max or not deepens
    if integrate:
        e_I = e_I + Ts * y_r
    return delta, e_I


def _path_kinematics(psi_r, u, r, cos_leg, cp):
    """Shared part of :meth:`_PathFL.kinematics`: (v, d_cross, ẏ_r, sin ψ_r, cos ψ_r)."""
    r1, r2, d_y, frame_global = cp[4], cp[5], cp[7], cp[8]
    v = r1 * r + r2 * (r * r * r)
    d_cross = d_y * cos_leg if frame_global != 0.0 else d_y
    s = math.sin(psi_r)
    c = math.cos(psi_r)
    return v, d_cross, u * s + v * c + d_cross, s, c


def _output_fl(y_r, psi_r, u, r, cos_leg, cp):
    """:meth:`OutputFL.step` for one ship: ``(δ, z)`` (cp: :func:`_controller`)."""
    delta_max, a, b, k_c, b_r = cp[0], cp[1], cp[2], cp[3], cp[6]
    r1, l, k1, k2, tiny, r2_3 = cp[4], cp[9], cp[10], cp[11], cp[12], cp[13]
    v, _, y_dot, s, c = _path_kinematics(psi_r, u, r, cos_leg, cp)
    lateral = v + l * r
    z = y_r + l * s
    z_dot = y_dot + l * r * c
    m = r1 + l + r2_3 * (r * r)
    f = (u * c - lateral * s) * r + m * c * (b_r - (a * r + b * (r * r * r)))
    g = m * k_c * c
    nu = -k1 * z - k2 * z_dot
    if abs(g) < tiny:  # the g_safe guard of OutputFL.step (NaN passes through)
        g = -tiny if g < 0.0 else tiny
    return _clip((nu - f) / g, -delta_max, delta_max), z


def _los_fl(y_r, psi_r, u, r, cos_leg, cp):
    """:meth:`LOSFL.step` for one ship: ``(δ, ψ_d,r)`` (cp: :func:`_controller`)."""
    delta_max, a, b, k_c, b_r = cp[0], cp[1], cp[2], cp[3], cp[6]
    D, kp, kd, D2 = cp[9], cp[10], cp[11], cp[12]
    _, d_cross, y_dot, _, _ = _path_kinematics(psi_r, u, r, cos_leg, cp)
    u_safe = u if (u > 1e-6 or u != u) else 1e-6  # np.maximum(u, 1e-6), NaN kept
    crab = math.asin(_clip(d_cross / u_safe, -1.0, 1.0))
    psi_d = -math.atan(y_r / D) - crab
    psi_d_dot = -D * y_dot / (D2 + y_r * y_r)
    e = _wrap(psi_r - psi_d)
    nu = -kp * e - kd * (r - psi_d_dot)
    raw = (nu + (a * r + b * (r * r * r)) - b_r) / k_c
    return _clip(raw, -delta_max, delta_max), psi_d


# ----------------------------------------------------------------------------------------------
# the kernel
# ----------------------------------------------------------------------------------------------

def _run_ship(i, k0, k1, n_steps, hold, log_every, dt, S, div_event, out, ctrl_mode, cp, legs,
              dist, current_mode, current_legs, current_table, has_waves, waves, mp, act, limits):
    """Steps ``k0 <= k < k1`` of ship ``i``: the body of ``run_numpy``'s loop for one ship."""
    a, b, k_c, r1, r2, f, W, thrust = mp[0], mp[1], mp[2], mp[3], mp[4], mp[5], mp[6], mp[7]
    lower, upper, rate_h = act[0], act[1], act[2]
    has_rate, ramp = act[3] != 0.0, act[4] != 0.0
    lim0, lim1, lim2, lim3, lim4 = limits[0], limits[1], limits[2], limits[3], limits[4]
    yaw0, current_n, current_e = dist[i, 0], dist[i, 1], dist[i, 2]
    x0, x1, x2, x3, x4 = S[i, 0], S[i, 1], S[i, 2], S[i, 3], S[i, 4]
    cmd, applied = S[i, CMD], S[i, APPLIED]
    sig_y, sig_psi, sig_leg, sig_extra = S[i, SIG], S[i, SIG + 1], S[i, SIG + 2], S[i, SIG + 3]
    e_I = S[i, E_I]
    leg, leg_d = int(S[i, LEG]), int(S[i, LEG_D])
    half_h = 0.5 * dt
    sixth_h = dt / 6.0

    ic = k0 % hold  # position in the control period
    il = k0 % log_every  # position in the logging period
    s = (k0 + log_every - 1) // log_every  # next log sample
    for k in range(k0, k1):
        if ic == 0 and ctrl_mode != CTRL_NONE:
            leg, _, y_r = _track(x0, x1, leg, legs)
            psi_r = _wrap(x2 - legs[leg, LEG_ANGLE])
            if ctrl_mode == CTRL_LQR:
                sig_extra = e_I  # logged before the update
                cmd, e_I = _path_lqr(y_r, psi_r, x4, e_I, cp)
            elif ctrl_mode == CTRL_FL:
                cmd, sig_extra = _output_fl(y_r, psi_r, x3, x4, legs[leg, LEG_COS], cp)
            else:
                cmd, sig_extra = _los_fl(y_r, psi_r, x3, x4, legs[leg, LEG_COS], cp)
            sig_y, sig_psi, sig_leg = y_r, psi_r, float(leg)
            if not math.isfinite(cmd):
                div_event[i] = 2 * k  # bad command, caught at its sample before it is logged
                break
        # Actuator.begin_step: the applied input moves from `start` to `end` within the step
        target = _clip(cmd, lower, upper)
        if has_rate:
            end = applied + _clip(target - applied, -rate_h, rate_h)
            start = applied if ramp else end
        else:
            start = target
            end = target
        # the disturbance, sampled with the state at the step's start and held over the step
        yaw = yaw0 + waves[i, k - k0] if has_waves else yaw0
        if current_mode != 0:
            leg_d, _, _ = _track(x0, x1, leg_d, current_legs)
            current_n = current_table[leg_d, 0]
            current_e = current_table[leg_d, 1]
        if il == 0 or k == n_steps:
            out[0, s, i] = x0
            out[1, s, i] = x1
            out[2, s, i] = x2
            out[3, s, i] = x3
            out[4, s, i] = x4
            out[5, s, i] = cmd
            out[6, s, i] = start  # Actuator.input_at(plan, 0)
            if ctrl_mode != CTRL_NONE:
                out[7, s, i] = sig_y
                out[8, s, i] = sig_psi
                out[9, s, i] = sig_leg
                out[10, s, i] = sig_extra
            s += 1
        if k == n_steps:
            break

        # Actuator.input_at at the RK4 stages, θ = (t_stage − t)/dt as the numpy loop forms it
        u1 = u2 = u4 = end
        if has_rate and ramp:
            t = k * dt
            u1 = start
            u2 = start + ((t + half_h) - t) / dt * (end - start)
            theta4 = ((t + dt) - t) / dt
            if theta4 != 1.0:
                u4 = start + theta4 * (end - start)
        # classic RK4 (sim.integrators.rk4_step) with the stages written out
        s1 = math.sin(x2)
        c1 = math.cos(x2)
        a0, a1, a2, a3, a4 = _mariner_rhs(c1, s1, x3, x4, u1, yaw, current_n, current_e,
                                          a, b, k_c, r1, r2, f, W, thrust)
        s2, c2 = _sin_cos_shifted(s1, c1, x2, half_h * a2)
        b0, b1, b2, b3, b4 = _mariner_rhs(c2, s2, x3 + half_h * a3, x4 + half_h * a4, u2, yaw,
                                          current_n, current_e, a, b, k_c, r1, r2, f, W, thrust)
        s3, c3 = _sin_cos_shifted(s1, c1, x2, half_h * b2)
        g0, g1, g2, g3, g4 = _mariner_rhs(c3, s3, x3 + half_h * b3, x4 + half_h * b4, u2, yaw,
                                          current_n, current_e, a, b, k_c, r1, r2, f, W, thrust)
        s4, c4 = _sin_cos_shifted(s1, c1, x2, dt * g2)
        h0, h1, h2, h3, h4 = _mariner_rhs(c4, s4, x3 + dt * g3, x4 + dt * g4, u4, yaw,
                                          current_n, current_e, a, b, k_c, r1, r2, f, W, thrust)
        x0 = x0 + sixth_h * (a0 + 2.0 * b0 + 2.0 * g0 + h0)
        x1 = x1 + sixth_h * (a1 + 2.0 * b1 + 2.0 * g1 + h1)
        x2 = x2 + sixth_h * (a2 + 2.0 * b2 + 2.0 * g2 + h2)
        x3 = x3 + sixth_h * (a3 + 2.0 * b3 + 2.0 * g3 + h3)
        x4 = x4 + sixth_h * (a4 + 2.0 * b4 + 2.0 * g4 + h4)
        applied = end

        # divergence guard (simulator.check_divergence): non-finite or runaway state after the step
        if not (abs(x0) <= lim0 and abs(x1) <= lim1 and abs(x2) <= lim2 and abs(x3) <= lim3
                and abs(x4) <= lim4):
            div_event[i] = 2 * k + 1
            break
        ic += 1
        if ic == hold:
            ic = 0
        il += 1
        if il == log_every:
            il = 0

    S[i, 0], S[i, 1], S[i, 2], S[i, 3], S[i, 4] = x0, x1, x2, x3, x4
    S[i, CMD], S[i, APPLIED] = cmd, applied
    S[i, SIG], S[i, SIG + 1], S[i, SIG + 2], S[i, SIG + 3] = sig_y, sig_psi, sig_leg, sig_extra
    S[i, E_I] = e_I
    S[i, LEG], S[i, LEG_D] = float(leg), float(leg_d)


def _ship_loop(k0, k1, n_steps, hold, log_every, dt, S, div_event, out, ctrl_mode, cp, legs, dist,
               current_mode, current_legs, current_table, has_waves, waves, mp, act, limits):
    """The kernel: ships in parallel (outer), time inside (:func:`_run_ship`)."""
    for i in prange(S.shape[0]):
        _run_ship(i, k0, k1, n_steps, hold, log_every, dt, S, div_event, out, ctrl_mode, cp, legs,
                  dist, current_mode, current_legs, current_table, has_waves, waves, mp, act, limits)


def _load():
    """Import numba and wrap the kernel (compiled, or loaded from the cache, on first call)."""
    global _KERNEL, prange, _wrap, _clip, _sin_cos_shifted, _sign, _track, _mariner_rhs
    global _path_lqr, _path_kinematics, _output_fl, _los_fl, _run_ship
    if _KERNEL is None:
        import numba

        # the kernel finds its helpers as module globals: rebind them to their compiled versions
        prange = numba.prange
        _wrap, _clip, _sin_cos_shifted = jit(_wrap), jit(_clip), jit(_sin_cos_shifted)
        _sign, _track, _mariner_rhs = jit(_sign), jit(_track), jit(_mariner_rhs)
        _path_lqr, _path_kinematics = jit(_path_lqr), jit(_path_kinematics)
        _output_fl, _los_fl = jit(_output_fl), jit(_los_fl)
        _run_ship = jit(_run_ship)
        _KERNEL = jit(_ship_loop, parallel=True)
    return _KERNEL


# ----------------------------------------------------------------------------------------------
# public entry points
# ----------------------------------------------------------------------------------------------

def unsupported_reason(setup) -> str | None:
    """None when the Mariner's compiled loop covers ``setup``, else a short reason in words."""
    from shipgnc.models.mariner import MarinerWitOppe

    model, ctrl, gd, dist, act = (setup.model, setup.controller, setup.guidance,
                                  setup.disturbance, setup.actuator)
    if type(model) is not MarinerWitOppe:
        return f"model {type(model).__name__} is not compiled (only MarinerWitOppe)"
    if ctrl is not None:
        from shipgnc.control.feedback_linearization import LOSFL, OutputFL
        from shipgnc.control.lqr import PathLQR

        if type(ctrl) not in (PathLQR, OutputFL, LOSFL):
            return f"controller {type(ctrl).__name__} is not compiled (only PathLQR, OutputFL, LOSFL)"
    if gd is not None:
        return f"guidance {type(gd).__name__} is not compiled (the path controllers need none)"
    if act.has_lag:
        return "actuator lag (tau > 0) is not compiled"
    if dist is not None:
        reason = _disturbance_reason(dist, setup.batch_shape)
        if reason:
            return reason
    if setup.integrator != "rk4":
        return f"integrator {setup.integrator!r} is not compiled (only 'rk4')"
    if setup.observer is not None:
        return "an observer callback needs the Python loop"
    return _numba_error()


def _disturbance_reason(dist, batch_shape) -> str | None:
    from shipgnc.environment.disturbance import ConstantDisturbance
    from shipgnc.models.mariner import MarinerDisturbance

    if type(dist) is ConstantDisturbance:
        try:
            np.broadcast_to(dist.values, (*batch_shape, 3))
        except ValueError:
            return f"disturbance values of shape {dist.values.shape} do not fit the batch"
        return None
    if type(dist) is not MarinerDisturbance:
        return f"disturbance {type(dist).__name__} is not compiled"
    if dist.per_stage:
        return "a disturbance evaluated at every RK4 stage is not compiled"
    if dist.current is not None:
        from shipgnc.environment.current import CrossCurrent

        if type(dist.current) is not CrossCurrent:
            return f"current {type(dist.current).__name__} is not compiled (only CrossCurrent)"
        # the position indices are private to CrossCurrent; the kernel reads north, east = x[0], x[1]
        if tuple(getattr(dist.current, "_i", (0, 1))) != (0, 1):
            return "a cross current reading the position elsewhere than [north, east] is not compiled"
    if dist.waves is not None:
        from shipgnc.environment.filtered_noise import SecondOrderNoise

        if type(dist.waves) is not SecondOrderNoise:
            return f"waves {type(dist.waves).__name__} are not compiled (only SecondOrderNoise)"
    return None


def run(setup):
    """Run ``setup`` in the compiled loop; returns the same :class:`Log` as ``run_numpy(setup)``."""
    reason = unsupported_reason(setup)
    if reason:
        raise ConfigError(f"compiled loop: {reason}")
    kernel = _load()

    model, ctrl, dist, act = setup.model, setup.controller, setup.disturbance, setup.actuator
    batch = setup.batch_shape
    n_ships = math.prod(batch)
    n_steps, hold, every, dt = (int(setup.n_steps), int(setup.hold), int(setup.log_every),
                                float(setup.dt))
    # the same side effects on the components as the numpy loop
    if ctrl is not None:
        ctrl.reset(batch)
    if dist is not None:
        dist.reset(batch, setup.rng)

    S = np.zeros((n_ships, N_SLOTS))
    S[:, X0:X0 + 5] = setup.x0.reshape(n_ships, 5)
    command = np.broadcast_to(setup.u0, (*batch, 1)).reshape(n_ships, 1)
    S[:, CMD] = command[:, 0]
    S[:, APPLIED] = act.initial(command)[:, 0]
    ctrl_mode, cp, legs = _controller(ctrl)
    base, current_mode, current_legs, current_table, noise = _disturbance(dist, batch, n_ships)
    p = model.params
    mp = np.array([p.a, p.b, p.c, p.r1, p.r2, p.f, p.W, p.S])
    rate = float(act.rate[0])
    act_p = np.array([act.lower[0], act.upper[0], rate * dt, float(act.has_rate_limit),
                      float(act.rate_mode == "ramp")])
    limits = _owned(model.state_limits)

    names = [s.name for s in model.states]
    names += [f"{s.name}_cmd" for s in model.inputs] + [s.name for s in model.inputs]
    if ctrl is not None:
        names += [s.name for s in ctrl.signals]
    signals = log_layout(setup, names)
    out = np.empty((len(names), log_length(setup), n_ships))  # written in place: no copy afterwards
    div_event = np.full(n_ships, -1, dtype=np.int64)
    waves = np.zeros((n_ships, 1))  # this chunk's wave noise (ship, step − k0)

    def prepare(k0: int, k1: int) -> None:
        nonlocal waves
        if noise is not None:  # the numpy loop's draws: one call per step at t_k = k·dt
            values = np.stack([noise(k * dt) for k in range(k0, k1)]).reshape(k1 - k0, n_ships)
            waves = _owned(values.T)

    def call(k0: int, k1: int, k_last: int) -> None:  # the Mariner's path controllers never finish
        kernel(k0, k1, n_steps, hold, every, dt, S, div_event, out, ctrl_mode, cp, legs, base,
               current_mode, current_legs, current_table, int(noise is not None), waves, mp,
               act_p, limits)

    n_chunks = 1 if noise is None else max(1, math.ceil(n_ships * (n_steps + 1) / WAVE_CHUNK))
    event, _ = drive(setup, call, S, div_event, n_chunks=n_chunks, prepare=prepare)

    # leave the components as the numpy loop would
    if ctrl is not None:
        ctrl.tracker.leg = S[:, LEG].astype(int).reshape(batch)
        if ctrl_mode == CTRL_LQR:
            ctrl.e_I = S[:, E_I].reshape(batch).copy()
        ctrl._logged = {sig.name: S[:, SIG + j].reshape(batch).copy()
                        for j, sig in enumerate(ctrl.signals)}
    if current_mode != 0:
        dist.current.tracker.leg = S[:, LEG_D].astype(int).reshape(batch)
    return make_log(setup, signals, out, S, event, state_slot=X0, cmd_slot=CMD)


def _legs(path) -> np.ndarray:
    """Leg table (n_legs, 6) of a :class:`WaypointPath`: start north, east, cos, sin of the leg
    angle, length, angle (the quantities of :meth:`WaypointPath.project` and the leg switching)."""
    angles = path.leg_angles
    return _owned(np.column_stack([path.waypoints[:-1, 0], path.waypoints[:-1, 1], np.cos(angles),
                                   np.sin(angles), path.leg_lengths, angles]))


def _controller(ctrl) -> tuple[int, np.ndarray, np.ndarray]:
    """Kernel mode, parameters ``cp`` and leg table of the controller (see the scalar twins)."""
    cp = np.zeros(16)
    if ctrl is None:
        return CTRL_NONE, cp, np.zeros((1, 6))
    from shipgnc.control.feedback_linearization import OutputFL
    from shipgnc.control.lqr import PathLQR
    from shipgnc.units import NAUTICAL_MILE

    if type(ctrl) is PathLQR:
        cp[:7] = [ctrl.delta_max, *ctrl.K, ctrl.Ts, float(ctrl.anti_windup)]
        return CTRL_LQR, cp, _legs(ctrl.path)
    cp[:9] = [ctrl.delta_max, ctrl.a, ctrl.b, ctrl.c, ctrl.r1, ctrl.r2, ctrl.b_r, ctrl.d_y,
              float(ctrl.current_frame == "global")]
    if type(ctrl) is OutputFL:
        # the g_safe threshold of OutputFL.step
        tiny = 1e-12 * abs(ctrl.c) * (abs(ctrl.r1) + ctrl.lookahead + NAUTICAL_MILE)
        cp[9:14] = [ctrl.lookahead, ctrl.k1, ctrl.k2, tiny, 3.0 * ctrl.r2]
        return CTRL_FL, cp, _legs(ctrl.path)
    cp[9:13] = [ctrl.delta_los, ctrl.kp, ctrl.kd, ctrl.delta_los**2]
    return CTRL_LOS, cp, _legs(ctrl.path)


def _disturbance(dist, batch, n_ships):
    """Per-ship constant part [b_r, c_N, c_E] (n_ships, 3), path-current mode, leg table and
    per-leg current (n_legs, 2), and the wave noise object (or None)."""
    from shipgnc.environment.disturbance import ConstantDisturbance

    no_legs, no_table = np.zeros((1, 6)), np.zeros((1, 2))
    if dist is None:
        return np.zeros((n_ships, 3)), 0, no_legs, no_table, None
    if type(dist) is ConstantDisturbance:
        base = _owned(np.broadcast_to(dist.values, (*batch, 3))).reshape(n_ships, 3)
        return base, 0, no_legs, no_table, None
    base = np.zeros((n_ships, 3))
    base[:, 0] = dist.b_r
    current = dist.current
    if current is None:
        return base, 0, no_legs, no_table, dist.waves
    if current.frame == "global":
        base[:, 2] = 0.0 + current.d_y
        return base, 0, no_legs, no_table, dist.waves
    angles = current.tracker.path.leg_angles  # d_y·[−sin ψ_r0, cos ψ_r0] of each leg
    table = _owned(np.column_stack([-current.d_y * np.sin(angles), current.d_y * np.cos(angles)]))
    return base, 1, _legs(current.tracker.path), table, dist.waves
