"""Compiled (numba) twins of :func:`shipgnc.sim.simulator.run_numpy`: the shared driver, and the
twin of the built-in boat.

The numpy loop stays the readable reference; a twin repeats it step for step as scalar code for
one vessel model. This module holds what every twin shares — the scalar building blocks
(:func:`_wrap`, :func:`_clip`, :func:`_sin_cos_shifted`), the numba plumbing (lazy import,
:func:`jit`, :func:`_numba_error`) and the driver (:func:`drive`: thread count, chunked kernel
calls for progress, divergence replay; :func:`make_log`: status, divergence errors, the ``Log``)
— and the twin of the boat. :mod:`shipgnc.sim.compiled_mariner` is the twin of document 000's
Mariner.

**The boat twin** covers :class:`~shipgnc.models.fossen3dof.VectoredThrustBoat` (spec 001
eq. (1)–(5), (9)–(11')) with a static (saturating) actuator; no controller, an
:class:`~shipgnc.control.open_loop.OpenLoopSchedule` or the
:class:`~shipgnc.control.heading_speed.HeadingSpeedAutopilot` (spec 001 §1.10); no guidance or a
:class:`~shipgnc.guidance.schedule.ReferenceSchedule`; an optional
:class:`~shipgnc.environment.disturbance.ConstantDisturbance`; fixed-step RK4.
:func:`unsupported_reason` says in words why a setup is not covered; ``simulate`` then falls back
to the numpy loop (or refuses, for ``backend="compiled"``). :func:`run` returns the same ``Log``
as ``run_numpy``: names, sample times, ``log_every`` thinning, status and divergence errors.

Kernel layout (spec 001 §1.12, §1.16 item 13): ships are the outer loop (``numba.prange``), time
the inner one, and one ship's state lives in local scalars. The arithmetic follows the numpy code
operation for operation, with these shortcuts, which change results only at round-off level
(≤ 1e-12 relative over the spec 001 scenarios, far inside the 1e-9 promised):

* sin ψ, cos ψ come from one libm call per step; the other RK4 stages add their small angle
  increment by angle addition (:func:`_sin_cos_shifted`);
* the held thruster force τ of eq. (5) is computed once per control period; when the autopilot's
  command is within the actuator limits it is the allocated force itself (T cos α = τ_u,
  T sin α = τ_v, since the allocation is the exact inverse of eq. (5));
* T = √(τ_u² + τ_v²) instead of ``hypot`` (within one ulp; ``hypot`` near over/underflow);
* LLVM may fuse multiply-adds and turn x/c into x·(1/c) (``fastmath={"contract", "arcp"}``);
  no other fast-math flag, so NaN and inf keep their meaning for the divergence guard.

numba is imported on first use, so importing this module stays cheap; the kernels are cached on
disk (``cache=True``). A run is one kernel call, or several that carry each ship's state from one
to the next (bit-identical results): about twenty with a progress callback, and short ones for a
batch logging many samples (:func:`drive`).
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.errors import ConfigError

#: slots of the boat's per-ship carried state ``S`` (N, N_SLOTS): everything a chunk hands to the next
X0, CMD, REF, ERR, SIG, Z, ZU, PSI_R, R_R, FORCE, APPLIED = 0, 6, 8, 10, 12, 14, 15, 16, 17, 18, 21
N_SLOTS = 23
#: controller modes of the boat kernel
CTRL_NONE, CTRL_TABLE, CTRL_AUTOPILOT = 0, 1, 2
#: number of kernel calls when a progress callback is given
PROGRESS_CHUNKS = 20
#: ship-steps worth a thread of their own (≈ 10 ms)
MIN_THREAD_WORK = 100_000
#: most logged samples per ship of one kernel call in a batch: the log is (variable, sample, ship),
#: so neighbouring ships share its cache lines, and short calls keep them cached from one ship to
#: the next (a 1 000-ship log of every step is written ≈ 2× faster)
LOG_SAMPLES_PER_CALL = 256
#: numba options of every kernel and helper: cached on disk; fused multiply-add and x/c → x·(1/c)
#: only, so NaN and inf keep their meaning (divergence guard); results move at round-off level,
#: ≈20 % faster
JIT_OPTIONS = {"cache": True, "error_model": "numpy", "fastmath": {"contract", "arcp"}}

TWO_PI = 2.0 * math.pi

# ``prange`` is bound to ``numba.prange`` by _load() before the kernel is compiled; until then the
# functions below are plain Python (readable, and usable to debug the kernel without numba).
prange = range

_KERNEL = None
_JITTED: dict = {}
_NUMBA_ERROR: str | None = None
_NUMBA_CHECKED = False


# ----------------------------------------------------------------------------------------------
# scalar building blocks shared by the twins (frames.wrap_angle, np.clip, sin/cos of RK4 stages)
# ----------------------------------------------------------------------------------------------

def _wrap(angle):
    """:func:`shipgnc.frames.wrap_angle` for one float: (−π, π], numpy's ``remainder`` convention."""
    a = angle + math.pi
    # remainder(a, 2π) = fmod(a, 2π), moved into [0, 2π) (Python's and numpy's convention).
    # fmod is exact: a itself for |a| < 2π, a ∓ 2π for |a| < 4π (exact by Sterbenz' lemma);
    # only larger angles pay for the general (slow) float modulo.
    if abs(a) < TWO_PI:
        m = a
    elif abs(a) < 2.0 * TWO_PI:
        m = a - TWO_PI if a > 0.0 else a + TWO_PI
    else:
        m = a % TWO_PI
    if m < 0.0:
        m += TWO_PI
    elif m == 0.0:
        m = 0.0
    w = m - math.pi
    if w == -math.pi:
        return math.pi
    return w


def _clip(value, lower, upper):
    """``np.clip`` for one float (NaN passes through, for the divergence guard)."""
    if value < lower:
        value = lower
    if value > upper:
        value = upper
    return value


def _sin_cos_shifted(s, c, angle, delta):
    """sin and cos of ``angle + delta`` from s = sin(angle), c = cos(angle).

    Angle addition with the Taylor series of sin δ and cos δ − 1 (truncation < 3e-18 relative for
    |δ| ≤ 0.1): the RK4 stages of one step share one libm ``sincos`` call. Larger δ use libm.
    """
    if abs(delta) <= 0.1:
        d2 = delta * delta
        sd = delta + delta * d2 * (-1.0 / 6.0 + d2 * (1.0 / 120.0 + d2 * (-1.0 / 5040.0
                                                                          + d2 * (1.0 / 362880.0))))
        cm1 = d2 * (-0.5 + d2 * (1.0 / 24.0 + d2 * (-1.0 / 720.0 + d2 * (1.0 / 40320.0
                                                                        - d2 * (1.0 / 3628800.0)))))
        return s + (s * cm1 + c * sd), c + (c * cm1 - s * sd)
    return math.sin(angle + delta), math.cos(angle + delta)


# ----------------------------------------------------------------------------------------------
# numba plumbing
# ----------------------------------------------------------------------------------------------

def jit(function, *, parallel: bool = False):
    """The numba dispatcher of a kernel function or scalar helper (one per function, shared by the
    twins; :data:`JIT_OPTIONS`). Scalar helpers are inlined by LLVM into the kernels calling them.

    A kernel finds its helpers as module globals, so each twin's ``_load`` rebinds its names to
    the dispatchers before its kernel compiles. numba's disk cache is keyed to the source file of
    the cached function only: after editing a helper of this module, delete the twins'
    ``__pycache__/*.nbi`` files so that no kernel inlining the old helper is loaded.
    """
    import numba

    py = _py(function)
    key = (py, parallel)
    if key not in _JITTED:
        _JITTED[key] = numba.njit(parallel=parallel, **JIT_OPTIONS)(py)
    return _JITTED[key]


def _py(function):
    """The plain Python function behind a (possibly already wrapped) numba dispatcher."""
    return getattr(function, "py_func", function)


def _numba_error() -> str | None:
    """None if numba imports, else the reason (checked once per process)."""
    global _NUMBA_CHECKED, _NUMBA_ERROR
    if not _NUMBA_CHECKED:
        _NUMBA_CHECKED = True
        try:
            import numba  # noqa: F401
        except Exception as exc:  # ImportError, or a broken install (llvmlite mismatch, ...)
            _NUMBA_ERROR = f"numba cannot be imported ({type(exc).__name__}: {exc})"
    return _NUMBA_ERROR


def _owned(values) -> np.ndarray:
    """A fresh, writeable, C-ordered float64 copy: one kernel signature whatever the caller passes
    (numba compiles read-only or strided arrays as other types)."""
    return np.array(values, dtype=np.float64, order="C", copy=True)


# ----------------------------------------------------------------------------------------------
# the shared driver: chunked kernel calls, progress, divergence replay, the Log
# ----------------------------------------------------------------------------------------------

def log_layout(setup, names: list[str]):
    """``log_signals(setup)``, after checking that a kernel's log columns ``names`` match it."""
    from shipgnc.sim.simulator import log_signals

    signals = log_signals(setup)
    if list(names) != list(signals):  # the kernel's column layout must match the numpy loop's log
        raise RuntimeError(f"compiled loop: log layout {list(names)} differs from {list(signals)}")
    return signals


def log_length(setup) -> int:
    """Number of logged samples of a full run: every ``log_every``-th step and the last one."""
    n_steps, every = int(setup.n_steps), int(setup.log_every)
    return n_steps // every + 1 + (1 if n_steps % every else 0)


def drive(setup, call, S: np.ndarray, div_event: np.ndarray, *, n_chunks: int = 1,
          prepare=None) -> int | None:
    """Run a kernel over steps 0 … n_steps; returns the first divergence event or None.

    ``call(k0, k1)`` runs steps ``k0 <= k < k1`` of every ship, carrying each ship's state in its
    row of ``S`` and writing ``div_event[i]`` = 2k (bad command at sample k) or 2k + 1 (bad state
    after step k) when ship i diverges. The steps are cut into ``n_chunks`` calls, or more: at
    least :data:`PROGRESS_CHUNKS` with a progress callback (reported after each call), and for a
    batch at most :data:`LOG_SAMPLES_PER_CALL` logged samples per call. ``prepare(k0, k1)`` runs
    before each call (e.g. to fill the chunk's input tables). On a divergence the chunk is
    replayed up to the event, as the numpy loop stops the whole batch at the first bad sample:
    ``S`` then holds every ship's command of that sample or state after that step. The chunks
    give bit-identical results.
    """
    import numba

    n_ships, n_steps = S.shape[0], int(setup.n_steps)
    # small runs on one thread: a parallel region waits for every worker thread, which costs a
    # scheduler tick when the other cores are busy
    threads = max(1, min(numba.get_num_threads(), n_ships, n_ships * n_steps // MIN_THREAD_WORK))

    def limited(k0: int, k1: int) -> None:
        previous = numba.get_num_threads()
        numba.set_num_threads(threads)  # local to the calling thread
        try:
            call(k0, k1)
        finally:
            numba.set_num_threads(previous)

    if setup.progress is not None:
        n_chunks = max(n_chunks, PROGRESS_CHUNKS)
    if n_ships > 1:
        n_chunks = max(n_chunks, math.ceil(log_length(setup) / LOG_SAMPLES_PER_CALL))
    bounds = np.linspace(0, n_steps + 1, min(n_chunks, n_steps + 1) + 1).round().astype(int)
    if setup.progress is not None:
        setup.progress(0, n_steps)
    for k0, k1 in zip(bounds[:-1].tolist(), bounds[1:].tolist(), strict=True):
        if prepare is not None:
            prepare(k0, k1)
        start = S.copy()
        limited(k0, k1)
        if (div_event >= 0).any():
            event = int(div_event[div_event >= 0].min())
            S[:] = start
            div_event[:] = -1
            limited(k0, event // 2 + 1)
            return event
        if setup.progress is not None:
            setup.progress(k1 - 1, n_steps)
    return None


def make_log(setup, signals, out: np.ndarray, S: np.ndarray, event: int | None, *, state_slot: int,
             cmd_slot: int):
    """The run's ``Log`` from the kernel's ``out`` (variable, sample, ship) and the first divergence
    ``event`` (see :func:`drive`): the numpy loop's sample times, status and divergence error
    (``S[:, state_slot:]`` holds the states, ``S[:, cmd_slot:]`` the commands). Raises the error
    for ``on_divergence="raise"``."""
    from shipgnc.sim.simulator import Log, check_divergence

    batch = setup.batch_shape
    n_steps, every, dt = int(setup.n_steps), int(setup.log_every), float(setup.dt)
    n_states, n_inputs = len(setup.model.states), int(setup.actuator.n)
    log_steps = np.arange(0, n_steps + 1, every)
    if n_steps % every:
        log_steps = np.append(log_steps, n_steps)
    status: dict = {"diverged": 0, "stopped_early": 0, "message": ""}
    n_logged = log_steps.size
    if event is not None:
        k = event // 2
        if event % 2 == 0:  # the command of sample k: samples before k are logged
            n_logged = (k - 1) // every + 1
            command = S[:, cmd_slot:cmd_slot + n_inputs].reshape(*batch, n_inputs)
            error = check_divergence(setup, k * dt, command=command)
        else:  # the state after step k: samples up to k are logged
            n_logged = k // every + 1
            t = k * dt
            error = check_divergence(setup, t + dt,
                                     S[:, state_slot:state_slot + n_states].reshape(*batch, n_states))
        if error is None:
            raise RuntimeError(f"compiled loop: divergence event {event} not confirmed by "
                               "check_divergence")
        if setup.on_divergence == "raise":
            raise error
        status.update(diverged=1, message=str(error))
    data = {name: out[col, :n_logged].reshape(n_logged, *batch) for col, name in enumerate(signals)}
    return Log(time=log_steps[:n_logged] * dt, data=data, signals=signals, status=status)


# ----------------------------------------------------------------------------------------------
# the boat: scalar twins of fossen3dof.derivatives and autopilot.step, and its kernel
# ----------------------------------------------------------------------------------------------

def _thruster(T_cmd, alpha_cmd, lower, upper, L_m):
    """Applied input sat(cmd) of the static actuator and its force, eq. (5): (T, α, τ_u, τ_v, τ_r)."""
    T = _clip(T_cmd, lower[0], upper[0])
    alpha = _clip(alpha_cmd, lower[1], upper[1])
    lateral = T * math.sin(alpha)
    return T, alpha, T * math.cos(alpha), lateral, -L_m * lateral


def _boat_rhs(c, s, su, sv, sr, tau_u, tau_v, tau_r, M11, M22, M33, X_u, Y_v, N_r, N_rr, k_munk):
    """ẋ of spec 001 eq. (1)–(3), (9)–(11') for one ship; c, s = cos ψ, sin ψ; τ (eq. (5) + τ_env)
    is held over the step.

    Twin of :meth:`VectoredThrustBoat.derivatives` (same operation order).
    """
    north_dot = c * su - s * sv
    east_dot = s * su + c * sv
    u_dot = (tau_u + M22 * sv * sr + X_u * su) / M11
    v_dot = (tau_v - M11 * su * sr + Y_v * sv) / M22
    r_dot = (tau_r + k_munk * su * sv + N_r * sr + N_rr * abs(sr) * sr) / M33
    return north_dot, east_dot, sr, u_dot, v_dot, r_dot


def _autopilot(psi, su, sr, psi_d, u_d, z, z_u, psi_r, r_r, cp):
    """One :meth:`HeadingSpeedAutopilot.step` for one ship (spec 001 §1.10; same operation order).

    Returns ``(T_cmd, alpha_cmd, tau_u, tau_v, z, z_u, psi_r, r_r)``: the command, the surge and
    sway force it allocates, the integrators and the reference model (ψ_r, ψ̇_r) advanced by Ts.
    """
    M33, N_r, N_rr, X_u, L_m = cp[0], cp[1], cp[2], cp[3], cp[4]
    alpha_max, T_min, T_max = cp[5], cp[6], cp[7]
    Kp, Kd, Ki, Kpu, Kiu = cp[8], cp[9], cp[10], cp[11], cp[12]
    w, Ts, yaw_ff = cp[13], cp[14], cp[15]
    acc = w * w * _wrap(psi_d - psi_r) - 2.0 * w * r_r
    e = _wrap(psi - psi_r)
    damping_ff = -N_r * r_r
    if yaw_ff != 0.0:
        damping_ff = damping_ff - N_rr * abs(r_r) * r_r
    tau_r = M33 * acc + damping_ff - Kp * e - Kd * (sr - r_r) - Ki * z
    speed_error = u_d - su
    tau_u = -X_u * u_d + Kpu * speed_error + Kiu * z_u
    if not (tau_u > 0.0 or tau_u != tau_u):  # np.maximum(0.0, tau_u), NaN kept
        tau_u = 0.0
    # allocation, the exact inverse of eq. (5); √(a² + b²) instead of hypot (within 1 ulp, faster)
    # unless the squares would overflow or underflow
    lateral = -tau_r / L_m
    square = tau_u * tau_u + lateral * lateral
    if square < 1e300 and (square > 1e-300 or square == 0.0):
        thrust = math.sqrt(square)
    else:
        thrust = math.hypot(tau_u, lateral)
    alpha = math.atan2(lateral, tau_u)
    if abs(alpha) <= alpha_max:
        z = z + Ts * e
    if thrust >= T_min and thrust <= T_max:
        z_u = z_u + Ts * speed_error
    return thrust, alpha, tau_u, lateral, z, z_u, psi_r + Ts * r_r, r_r + Ts * acc


def _run_ship(i, k0, k1, n_steps, hold, log_every, dt, S, div_event, out, ctrl_mode, cmd_table,
              has_ref, ref_table, has_d, dist, mp, cp, lower, upper, act_lim, limits):
    """Steps ``k0 <= k < k1`` of ship ``i``: the body of ``run_numpy``'s loop for one ship."""
    M11, M22, M33, X_u, Y_v = mp[0], mp[1], mp[2], mp[3], mp[4]
    N_r, N_rr, k_munk, L_m = mp[5], mp[6], mp[7], mp[8]
    lim0, lim1, lim2, lim3, lim4, lim5 = (limits[0], limits[1], limits[2], limits[3], limits[4],
                                          limits[5])
    d0 = d1 = d2 = 0.0
    if has_d:
        d0, d1, d2 = dist[i, 0], dist[i, 1], dist[i, 2]
    x0, x1, x2, x3, x4, x5 = S[i, 0], S[i, 1], S[i, 2], S[i, 3], S[i, 4], S[i, 5]
    c_T, c_a = S[i, CMD], S[i, CMD + 1]
    psi_d, u_d = S[i, REF], S[i, REF + 1]
    e_psi, e_u = S[i, ERR], S[i, ERR + 1]
    sig_psi_r, sig_r_r = S[i, SIG], S[i, SIG + 1]
    z, z_u, psi_r, r_r = S[i, Z], S[i, ZU], S[i, PSI_R], S[i, R_R]
    # applied input (static actuator: sat(cmd), held over the step) and its force τ, eq. (5) + τ_env
    tau_u, tau_v, tau_r = S[i, FORCE], S[i, FORCE + 1], S[i, FORCE + 2]
    T_app, a_app = S[i, APPLIED], S[i, APPLIED + 1]
    half_h = 0.5 * dt
    sixth_h = dt / 6.0
    col_sig = 10 + 4 * has_ref

    ic = k0 % hold  # position in the control period
    j = (k0 + hold - 1) // hold  # next control sample
    il = k0 % log_every  # position in the logging period
    s = (k0 + log_every - 1) // log_every  # next log sample
    for k in range(k0, k1):
        if ic == 0:
            if has_ref:
                psi_d = ref_table[j, 0]
                u_d = ref_table[j, 1]
            if ctrl_mode == CTRL_TABLE:
                c_T = cmd_table[j, 0]
                c_a = cmd_table[j, 1]
                T_app, a_app, tau_u, tau_v, tau_r = _thruster(c_T, c_a, lower, upper, L_m)
            elif ctrl_mode == CTRL_AUTOPILOT:
                if k == 0:  # the reference model starts at the measured heading, ψ̇_r = 0
                    psi_r = x2
                    r_r = 0.0
                sig_psi_r = psi_r
                sig_r_r = r_r
                c_T, c_a, f_u, f_v, z, z_u, psi_r, r_r = _autopilot(x2, x3, x5, psi_d, u_d, z, z_u,
                                                                    psi_r, r_r, cp)
                # inside the actuator's limits T cos α, T sin α of eq. (5) are the allocated
                # forces themselves; the test on the forces keeps sqrt and atan2 off the critical
                # path (at the limits both branches give the same force, to round-off)
                square = f_u * f_u + f_v * f_v
                if (act_lim[0] <= square <= act_lim[1]
                        and act_lim[2] * f_u <= f_v <= act_lim[3] * f_u):
                    T_app = _clip(c_T, lower[0], upper[0])  # logged: within limits, always
                    a_app = _clip(c_a, lower[1], upper[1])
                    tau_u, tau_v, tau_r = f_u, f_v, -L_m * f_v
                else:
                    T_app, a_app, tau_u, tau_v, tau_r = _thruster(c_T, c_a, lower, upper, L_m)
            elif k == 0:  # constant command u0
                T_app, a_app, tau_u, tau_v, tau_r = _thruster(c_T, c_a, lower, upper, L_m)
            if has_d and (ctrl_mode != CTRL_NONE or k == 0):
                tau_u, tau_v, tau_r = tau_u + d0, tau_v + d1, tau_r + d2
            j += 1
            if ctrl_mode != CTRL_NONE and not (math.isfinite(c_T) and math.isfinite(c_a)):
                div_event[i] = 2 * k  # bad command, caught at its sample before it is logged
                break
        if il == 0 or k == n_steps:
            out[0, s, i] = x0
            out[1, s, i] = x1
            out[2, s, i] = x2
            out[3, s, i] = x3
            out[4, s, i] = x4
            out[5, s, i] = x5
            out[6, s, i] = c_T
            out[7, s, i] = c_a
            out[8, s, i] = T_app
            out[9, s, i] = a_app
            if has_ref:  # errors of the current state against the held reference
                e_psi = _wrap(x2 - psi_d)
                e_u = x3 - u_d
                out[10, s, i] = psi_d
                out[11, s, i] = u_d
                out[12, s, i] = e_psi
                out[13, s, i] = e_u
            if ctrl_mode == CTRL_AUTOPILOT:
                out[col_sig, s, i] = sig_psi_r
                out[col_sig + 1, s, i] = sig_r_r
            s += 1
        if k == n_steps:
            break

        # classic RK4 (sim.integrators.rk4_step) with the stages written out; τ is held over the
        # step, and the stages' sin ψ, cos ψ come from one libm call (_sin_cos_shifted)
        s1 = math.sin(x2)
        c1 = math.cos(x2)
        a0, a1, a2, a3, a4, a5 = _boat_rhs(c1, s1, x3, x4, x5, tau_u, tau_v, tau_r,
                                           M11, M22, M33, X_u, Y_v, N_r, N_rr, k_munk)
        s2, c2 = _sin_cos_shifted(s1, c1, x2, half_h * a2)
        b0, b1, b2, b3, b4, b5 = _boat_rhs(c2, s2, x3 + half_h * a3, x4 + half_h * a4,
                                           x5 + half_h * a5, tau_u, tau_v, tau_r,
                                           M11, M22, M33, X_u, Y_v, N_r, N_rr, k_munk)
        s3, c3 = _sin_cos_shifted(s1, c1, x2, half_h * b2)
        g0, g1, g2, g3, g4, g5 = _boat_rhs(c3, s3, x3 + half_h * b3, x4 + half_h * b4,
                                           x5 + half_h * b5, tau_u, tau_v, tau_r,
                                           M11, M22, M33, X_u, Y_v, N_r, N_rr, k_munk)
        s4, c4 = _sin_cos_shifted(s1, c1, x2, dt * g2)
        h0, h1, h2, h3, h4, h5 = _boat_rhs(c4, s4, x3 + dt * g3, x4 + dt * g4, x5 + dt * g5,
                                           tau_u, tau_v, tau_r,
                                           M11, M22, M33, X_u, Y_v, N_r, N_rr, k_munk)
        x0 = x0 + sixth_h * (a0 + 2.0 * b0 + 2.0 * g0 + h0)
        x1 = x1 + sixth_h * (a1 + 2.0 * b1 + 2.0 * g1 + h1)
        x2 = x2 + sixth_h * (a2 + 2.0 * b2 + 2.0 * g2 + h2)
        x3 = x3 + sixth_h * (a3 + 2.0 * b3 + 2.0 * g3 + h3)
        x4 = x4 + sixth_h * (a4 + 2.0 * b4 + 2.0 * g4 + h4)
        x5 = x5 + sixth_h * (a5 + 2.0 * b5 + 2.0 * g5 + h5)

        # divergence guard (simulator.check_divergence): non-finite or runaway state after the step
        if not (abs(x0) <= lim0 and abs(x1) <= lim1 and abs(x2) <= lim2 and abs(x3) <= lim3
                and abs(x4) <= lim4 and abs(x5) <= lim5):
            div_event[i] = 2 * k + 1
            break
        ic += 1
        if ic == hold:
            ic = 0
        il += 1
        if il == log_every:
            il = 0

    S[i, 0], S[i, 1], S[i, 2], S[i, 3], S[i, 4], S[i, 5] = x0, x1, x2, x3, x4, x5
    S[i, CMD], S[i, CMD + 1] = c_T, c_a
    S[i, REF], S[i, REF + 1] = psi_d, u_d
    S[i, ERR], S[i, ERR + 1] = e_psi, e_u
    S[i, SIG], S[i, SIG + 1] = sig_psi_r, sig_r_r
    S[i, Z], S[i, ZU], S[i, PSI_R], S[i, R_R] = z, z_u, psi_r, r_r
    S[i, FORCE], S[i, FORCE + 1], S[i, FORCE + 2] = tau_u, tau_v, tau_r
    S[i, APPLIED], S[i, APPLIED + 1] = T_app, a_app


def _ship_loop(k0, k1, n_steps, hold, log_every, dt, S, div_event, out, ctrl_mode, cmd_table,
               has_ref, ref_table, has_d, dist, mp, cp, lower, upper, act_lim, limits):
    """The kernel: ships in parallel (outer), time inside (:func:`_run_ship`)."""
    for i in prange(S.shape[0]):
        _run_ship(i, k0, k1, n_steps, hold, log_every, dt, S, div_event, out, ctrl_mode, cmd_table,
                  has_ref, ref_table, has_d, dist, mp, cp, lower, upper, act_lim, limits)


# ----------------------------------------------------------------------------------------------
# the boat twin's entry points
# ----------------------------------------------------------------------------------------------

def _load():
    """Import numba and wrap the boat kernel (compiled, or loaded from the cache, on first call)."""
    global _KERNEL, prange, _wrap, _clip, _thruster, _sin_cos_shifted, _boat_rhs, _autopilot
    global _run_ship
    if _KERNEL is None:
        import numba

        # the kernel finds its helpers as module globals: rebind them to their compiled versions
        prange = numba.prange
        _wrap, _clip, _thruster = jit(_wrap), jit(_clip), jit(_thruster)
        _sin_cos_shifted, _boat_rhs, _autopilot = jit(_sin_cos_shifted), jit(_boat_rhs), jit(_autopilot)
        _run_ship = jit(_run_ship)
        _KERNEL = jit(_ship_loop, parallel=True)
    return _KERNEL


def unsupported_reason(setup) -> str | None:
    """None when the boat's compiled loop covers ``setup``, else a short reason in words."""
    from shipgnc.control.heading_speed import HeadingSpeedAutopilot
    from shipgnc.control.open_loop import OpenLoopSchedule
    from shipgnc.environment.disturbance import ConstantDisturbance
    from shipgnc.guidance.schedule import ReferenceSchedule
    from shipgnc.models.fossen3dof import VectoredThrustBoat

    model, ctrl, gd, dist, act = (setup.model, setup.controller, setup.guidance,
                                  setup.disturbance, setup.actuator)
    if type(model) is not VectoredThrustBoat:
        return f"model {type(model).__name__} is not compiled (only VectoredThrustBoat)"
    if ctrl is not None and type(ctrl) not in (OpenLoopSchedule, HeadingSpeedAutopilot):
        return f"controller {type(ctrl).__name__} is not compiled"
    if type(ctrl) is OpenLoopSchedule and ctrl.schedule.values.shape[1:] != (2,):
        return "the open-loop schedule does not hold 2 channels (T, alpha)"
    if gd is not None and type(gd) is not ReferenceSchedule:
        return f"guidance {type(gd).__name__} is not compiled"
    if gd is not None and gd.schedule.values.shape[1:] != (2,):
        return "the reference schedule does not hold 2 channels (psi_d, u_d)"
    if type(ctrl) is HeadingSpeedAutopilot and gd is None:
        return "HeadingSpeedAutopilot without guidance has no reference"
    if type(ctrl) is HeadingSpeedAutopilot and ctrl.reference_model.zeta != 1.0:
        return "a reference model with zeta != 1 is not compiled"
    if act.has_lag:
        return "actuator lag (tau > 0) is not compiled"
    if act.has_rate_limit:
        return "actuator rate limit is not compiled"
    if dist is not None:
        if type(dist) is not ConstantDisturbance:
            return f"disturbance {type(dist).__name__} is not compiled"
        try:
            np.broadcast_to(dist.values, (*setup.batch_shape, 3))
        except ValueError:
            return f"disturbance values of shape {dist.values.shape} do not fit the batch"
    if setup.integrator != "rk4":
        return f"integrator {setup.integrator!r} is not compiled (only 'rk4')"
    if setup.observer is not None:
        return "an observer callback needs the Python loop"
    return _numba_error()


def run(setup):
    """Run ``setup`` in the boat's compiled loop; returns the same ``Log`` as ``run_numpy(setup)``."""
    from shipgnc.control.heading_speed import HeadingSpeedAutopilot
    from shipgnc.control.open_loop import OpenLoopSchedule

    reason = unsupported_reason(setup)
    if reason:
        raise ConfigError(f"compiled loop: {reason}")
    kernel = _load()

    model, ctrl, gd, dist, act = (setup.model, setup.controller, setup.guidance,
                                  setup.disturbance, setup.actuator)
    batch = setup.batch_shape
    n_ships = math.prod(batch)
    n_steps, hold, every, dt = (int(setup.n_steps), int(setup.hold), int(setup.log_every),
                                float(setup.dt))
    # the same side effects on the components as the numpy loop
    if ctrl is not None:
        ctrl.reset(batch)
    if gd is not None:
        gd.reset(batch, model)
    if dist is not None:
        dist.reset(batch, setup.rng)

    S = np.zeros((n_ships, N_SLOTS))
    S[:, X0:X0 + 6] = setup.x0.reshape(n_ships, 6)
    S[:, CMD:CMD + 2] = np.broadcast_to(setup.u0, (*batch, act.n)).reshape(n_ships, 2)
    control_times = np.arange(0, n_steps + 1, hold) * dt  # t_k = k·dt of each control sample
    no_table = np.zeros((1, 2))
    ctrl_mode, cmd_table, cp = CTRL_NONE, no_table, np.zeros(16)
    if type(ctrl) is OpenLoopSchedule:
        ctrl_mode, cmd_table = CTRL_TABLE, _lookup(ctrl.schedule, control_times)
    elif type(ctrl) is HeadingSpeedAutopilot:
        p, g = ctrl.params, ctrl.gains
        ctrl_mode = CTRL_AUTOPILOT
        cp = np.array([p.M33, p.N_r, p.N_rr, p.X_u, p.L_m, p.alpha_max, p.T_min, p.T_max,
                       g.Kp, g.Kd, g.Ki, g.Kpu, g.Kiu, ctrl.reference_model.omega, ctrl.Ts,
                       float(ctrl.yaw_feedforward)])
    has_ref, ref_table = (1, _lookup(gd.schedule, control_times)) if gd is not None else (0, no_table)
    has_d, d = 0, np.zeros((1, 3))
    if dist is not None:
        has_d = 1
        d = _owned(np.broadcast_to(dist(0.0, setup.x0), (*batch, 3))).reshape(n_ships, 3)
    p = model.params
    mp = np.array([p.M11, p.M22, p.M33, p.X_u, p.Y_v, p.N_r, p.N_rr, p.munk_coefficient, p.L_m])
    lower, upper = _owned(act.lower), _owned(act.upper)
    limits = _owned(model.state_limits)
    act_lim = _inside_limits(lower, upper)

    names = [s.name for s in model.states]
    names += [f"{s.name}_cmd" for s in model.inputs] + [s.name for s in model.inputs]
    if gd is not None:
        names += ["psi_d", "u_d", "psi_error", "u_error"]
    if ctrl_mode == CTRL_AUTOPILOT:
        names += ["psi_r", "r_r"]
    signals = log_layout(setup, names)
    out = np.empty((len(names), log_length(setup), n_ships))  # written in place: no copy afterwards
    div_event = np.full(n_ships, -1, dtype=np.int64)

    def call(k0: int, k1: int) -> None:
        kernel(k0, k1, n_steps, hold, every, dt, S, div_event, out, ctrl_mode, cmd_table,
               has_ref, ref_table, has_d, d, mp, cp, lower, upper, act_lim, limits)

    event = drive(setup, call, S, div_event)
    if ctrl_mode == CTRL_AUTOPILOT:  # leave the controller as the numpy loop would
        ctrl.z = S[:, Z].reshape(batch).copy()
        ctrl.z_u = S[:, ZU].reshape(batch).copy()
        ctrl.reference_model.psi = S[:, PSI_R].reshape(batch).copy()
        ctrl.reference_model.rate = S[:, R_R].reshape(batch).copy()
        ctrl._logged = {"psi_r": S[:, SIG].reshape(batch).copy(),
                        "r_r": S[:, SIG + 1].reshape(batch).copy()}
    return make_log(setup, signals, out, S, event, state_slot=X0, cmd_slot=CMD)


def _lookup(schedule, t: np.ndarray) -> np.ndarray:
    """``schedule(t)`` for many times at once: the rule of :meth:`PiecewiseConstant.index`."""
    idx = np.searchsorted(schedule.times, t + 1e-9 * np.maximum(1.0, np.abs(t)), side="right") - 1
    return _owned(schedule.values[idx])


def _inside_limits(lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """Bounds ``[T_lo², T_hi², tan α_lo, tan α_hi]`` of an unsaturated force (τ_u ≥ 0, τ_v).

    T ∈ [T_lo, T_hi] ⟺ T_lo² ≤ τ_u² + τ_v² ≤ T_hi², and α ∈ [α_lo, α_hi] ⟺ tan α_lo·τ_u ≤ τ_v ≤
    tan α_hi·τ_u. Bounds the test cannot express (T_lo ≤ 0, |α| ≥ π/2) are replaced by ones that
    always pass or always fail, the latter sending the kernel to its exact (slower) branch.
    """
    T_lo, T_hi, a_lo, a_hi = float(lower[0]), float(upper[0]), float(lower[1]), float(upper[1])
    square_lo = T_lo * T_lo if T_lo > 0 else -1.0
    square_hi = T_hi * T_hi if T_hi >= 0 else -2.0
    tan_lo = math.tan(a_lo) if a_lo > -math.pi / 2 else -math.inf
    tan_hi = math.tan(a_hi) if a_hi < math.pi / 2 else math.inf
    return np.array([square_lo, square_hi, tan_lo, tan_hi])
