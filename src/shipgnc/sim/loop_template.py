"""The composed loop's body, as source: :mod:`shipgnc.sim.compose` writes it under a header that
binds the free names below (the components' kernels ``model_fn``, ``ctrl_fn``, ``guid_fn``,
``dist_fn`` and a disturbance's current part ``cur_fn``; the navigation step ``nav_observe`` of
:mod:`shipgnc.sim.nav_template`, written before this body; the sizes ``nx``, ``nu``, ...; the row
offsets ``o_*`` and log columns ``c_*`` that :func:`~shipgnc.sim.compose.row_layout` and
:func:`~shipgnc.sim.compose.log_columns` compute by name; the flags ``has_*``) as constants of one
combination, and compiles it (so this module is never imported as itself). It is
:func:`shipgnc.sim.simulator.run_numpy` step for step, for one ship at a time (see
:mod:`shipgnc.sim.compose`).

The flags are module constants, so numba and LLVM compile the branches of absent components away
(a loop without a disturbance has no call of ``dist_fn``). :func:`loop` runs the ships in
parallel, :func:`run_ship` one ship over the call's steps; the parts of a step are small
functions — :func:`guide` and :func:`command` (a control sample), :func:`plan_input` (the
actuator), :func:`disturb`, :func:`log_sample`, the RK4 stage's :func:`stage_state`,
:func:`stage_input` and :func:`accumulate`, :func:`rk4_finish`, :func:`state_ok` — inlined, with
:func:`run_ship`, into the parallel loop's body by numba (``inline="always"``): one function as
before, the same arithmetic in the same order, on local arrays that LLVM knows do not alias (a
ship's function called from the loop, not inlined, ran ≈ 4× slower). They take arrays, not tuples of
them: numba reference-counts an array read from a tuple at each use (≈ 20× slower).
"""
# ruff: noqa: F821

import math

import numba
import numpy as np

from shipgnc.actuators import input_at_kernel, lag_rate_kernel, plan_kernel
from shipgnc.kernels import JIT_OPTIONS, clip, wrap
from shipgnc.sim.stack import stack_empty

inline = numba.njit(inline="always", **{**JIT_OPTIONS, "cache": False})
# the disturbance's kernels inlined into the loop (numba's IR level): called as functions they
# cost more than their arithmetic at every step (the Mariner's path current and yaw bias: a third
# of its loop, 0.24 → 0.16 s for 2 000 ships × 1 000 steps, outputs identical) for ≈ 0.6 s more
# first compile; the other components' kernels stay calls (inlining them gained nothing measurable
# and every one lengthens the compile: shipgnc.kernels.kernel_function)
dist_fn = inline(getattr(dist_fn, "py_func", dist_fn))
cur_fn = inline(getattr(cur_fn, "py_func", cur_fn))


def loop(steps, S, out, event, done_at, params, tables, limits, err, score):
    """Steps ``steps.k0 <= k < steps.k1`` of every ship whose ``event`` is unset (the arguments:
    :class:`shipgnc.sim.compose.Composition.call`)."""
    ops, span, acc = score.ops, score.span, score.acc  # the scoring step's (see score_step)
    for i in numba.prange(S.shape[0]):
        if event[i] >= 0:  # stopped by its divergence (on_divergence="mask"): skipped
            continue
        run_ship(np.int64(i), steps, S[i], out, event, done_at, params, tables, limits, err, ops,
                 span, acc[i])


@inline
def pick(rows, ship):
    """A component's parameter row of ``ship`` (1 row for every ship, or n rows), copied."""
    return rows[min(ship, rows.shape[0] - 1)].copy()


@inline
def run_ship(i, steps, row, out, event, done_at, params, tables, limits, err, ops, span, scores):
    """Steps ``k0 … k1 − 1`` of ship ``i`` (its state carried in ``row``); sets ``event[i]`` (a
    bad command 2k, a bad state after step k 2k + 1) and ``done_at[i]``."""
    k0, k1, k_last, hold, every, dt = (steps.k0, steps.k1, steps.k_last, steps.hold, steps.every,
                                       steps.dt)
    pm, pa, pc = pick(params.model, i), params.actuator, pick(params.controller, i)
    pg, pd = pick(params.guidance, i), pick(params.disturbance, i)
    pu, pn = pick(params.current, i), pick(params.navigation, i)
    W, Wu, Wn = tables.disturbance, tables.current, tables.navigation  # read once (see above)
    # the ship's carried state as fresh local arrays (written back after its last step): arrays
    # that cannot alias each other let LLVM keep values in registers across the components'
    # calls (views into S, or a parameter row picked by index, run ≈ 2× slower)
    x = row[o_x:o_x + nx].copy()
    lag = row[o_lag:o_lag + nl].copy()
    applied = row[o_app:o_app + nu].copy()
    cmd = row[o_cmd:o_cmd + nu].copy()
    ref = row[o_ref:o_ref + nref].copy()
    gout = row[o_out:o_out + nout].copy()
    sig = row[o_sig:o_sig + nsig].copy()
    d = stack_empty(nd)  # on the stack: see below
    for j in range(nd):
        d[j] = row[o_d + j]
    zc = row[o_zc:o_zc + nzc].copy()
    zg = row[o_zg:o_zg + nzg].copy()
    zd = row[o_zd:o_zd + nzd].copy()
    zn = row[o_zn:o_zn + nzn].copy()  # navigation: its state and held logged signals
    nsg = row[o_nsg:o_nsg + nnsig].copy()
    zu = np.empty(0)  # the current part keeps no state
    seen = np.empty(nx if has_nav else 0)  # the state guidance and controller see
    nwk = np.empty(nav_work if has_nav else 0)  # the navigation step's scratch space
    # the actuator's plan of the step, the input, a continuous controller's stage command and
    # signals; the RK4 stage state, derivative and sum of the plant and of the actuator lag. On the
    # stack (shipgnc.sim.stack): LLVM then knows no other array's write changes them, so the
    # input and the held disturbance are loaded (and a model's sin and cos of an input angle
    # computed) once per step, not once per RK stage (boat-autopilot's loop 0.19 → 0.15 CPU s per
    # 1 000 ships × 1 400 steps), results to the bit as on the heap. The stage state xs stays on
    # the heap: with it in registers too, LLVM fuses other multiply-adds (fastmath "contract")
    # and the last bit changes
    start, end, u, cs = stack_empty(nu), stack_empty(nu), stack_empty(nu), stack_empty(nu)
    sig_s = stack_empty(nsig)
    xs, kx, ax = np.empty(nx), stack_empty(nx), stack_empty(nx)
    ls, kl, al = np.empty(nl), np.empty(nl), np.empty(nl)
    done = row[o_done]
    acc = scores.copy()  # the ship's accumulators of the scoring step (see score_step)
    j0 = (k0 + hold - 1) // hold  # the chunk's first control sample (row 0 of the navigation table)
    ic = k0 % hold
    il = k0 % every
    s = (k0 + every - 1) // every - steps.s_base  # the log's sample (``out`` from sample s_base)
    # ``done`` changes only at a control sample (the guidance's): its first step is noted there,
    # and here for a flag carried in (a call that starts between samples)
    if has_guid and ic != 0 and k0 < k1 and done != 0.0 and done_at[i] < 0:
        done_at[i] = k0
    for k in range(k0, k1):
        t = k * dt
        if ic == 0:
            if has_nav:  # Navigation.observe: the estimate (or measurements) from the truth
                nav_observe(t, x, applied, zn, pn, Wn[k // hold - j0, i], seen, nsg,
                            pm, nwk)
            if has_guid and guide(t, seen, x, zg, pg, ref, gout):
                done = 1.0
            if has_ctrl and not command(t, seen, x, ref, zc, pc, cmd, sig):
                event[i] = 2 * k
                break
            if has_guid and done != 0.0 and done_at[i] < 0:
                done_at[i] = k
        plan_input(dt, applied, cmd, lag, pa, start, end, u)
        if has_dist and not per_stage:
            disturb(t, x, zd, pd, zu, pu, W[k - k0, i], Wu[k - k0, i], d)
        if il == 0 or k == k_last:
            log_sample(out, s, i, x, cmd, u, ref, gout, sig, nsg, err)
            s += 1
        if has_score:  # a study's in-loop scoring: every step's sample into its accumulators
            score_step(t, x, cmd, u, ref, gout, sig, nsg, err, ops, span, acc)
        if k == k_last:
            break
        # classic RK4 (sim.integrators.rk4_step) of z = [x, lag]; stage states in their own
        # arrays (no views in the hot loop); a static actuator's input is the step's constant
        for stage in range(4):
            theta = stage_state(stage, dt, x, lag, kx, kl, xs, ls)
            ts = t + theta * dt
            stage_input(ts, theta, xs, ls, ref, zc, pc, pa, start, end, cs, sig_s, u)
            if has_dist and per_stage:
                disturb(ts, xs, zd, pd, zu, pu, W[k - k0, i], Wu[k - k0, i], d)
            model_fn(xs, u, d, pm, kx)
            if has_lag:
                lag_rate_kernel(cs if continuous else cmd, ls, pa, kl)
            accumulate(stage, kx, kl, ax, al)
        rk4_finish(dt, ax, al, start, end, pa, x, lag, applied)
        if not state_ok(x, limits):
            event[i] = 2 * k + 1
            break
        ic += 1
        if ic == hold:
            ic = 0
        il += 1
        if il == every:
            il = 0
    row[o_x:o_x + nx] = x
    row[o_lag:o_lag + nl] = lag
    row[o_app:o_app + nu] = applied
    row[o_cmd:o_cmd + nu] = cmd
    row[o_ref:o_ref + nref] = ref
    row[o_out:o_out + nout] = gout
    row[o_sig:o_sig + nsig] = sig
    row[o_d:o_d + nd] = d
    row[o_zc:o_zc + nzc] = zc
    row[o_zg:o_zg + nzg] = zg
    row[o_zd:o_zd + nzd] = zd
    row[o_zn:o_zn + nzn] = zn
    row[o_nsg:o_nsg + nnsig] = nsg
    row[o_done] = done
    scores[:] = acc


# the constant flags pick each call at compile time (an array chosen by a conditional expression
# would keep numba's reference counting in the loop)
@inline
def guide(t, seen, x, zg, pg, ref, gout):
    """The guidance's references and outputs from the state it sees; True once it has finished."""
    if has_nav:
        return guid_fn(t, seen, zg, pg, ref, gout)
    return guid_fn(t, x, zg, pg, ref, gout)


@inline
def command(t, seen, x, ref, zc, pc, cmd, sig):
    """The controller's command and signals; False when the command is not finite (a continuous
    controller's law reads the truth, as run_numpy)."""
    if has_nav and not continuous:
        ctrl_fn(t, seen, ref, zc, pc, cmd, sig)
    else:
        ctrl_fn(t, x, ref, zc, pc, cmd, sig)
    ok = True
    for j in range(nu):
        if not math.isfinite(cmd[j]):
            ok = False
    return ok


@inline
def plan_input(dt, applied, cmd, lag, pa, start, end, u):
    """The actuator's plan of the step (``start``, ``end``) and the input ``u`` at its start."""
    if has_lag:
        plan_kernel(applied, cmd, pa, dt, rate_limited, hold_mode, start, end)
        input_at_kernel(start, end, 0.0, lag, pa, has_lag, rate_limited, u)
    elif rate_limited:  # Actuator.input_at without lag: from start to end over the step
        plan_kernel(applied, cmd, pa, dt, rate_limited, hold_mode, start, end)
        for j in range(nu):
            u[j] = start[j]
    else:  # a static actuator (Actuator.saturate): the input is constant over the step
        for j in range(nu):
            u[j] = clip(cmd[j], pa[j], pa[nu + j])
            end[j] = u[j]


@inline
def disturb(t, x, zd, pd, zu, pu, w, wu, d):
    """The disturbance at ``(t, x)`` into ``d`` (held over the step, or one RK stage; ``w``, ``wu``
    its and a current part's table rows of the step), then the current part's channels."""
    dist_fn(t, x, zd, pd, w, d)
    if has_cur:
        cur_fn(t, x, zu, pu, wu, d)


@inline
def log_sample(out, s, i, x, cmd, u, ref, gout, sig, nsg, err):
    """Sample ``s`` of ship ``i`` in the log (the columns of simulator.log_signals)."""
    for j in range(nx):
        out[j, s, i] = x[j]
    for j in range(nu):
        out[c_cmd + j, s, i] = cmd[j]
        out[c_app + j, s, i] = u[j]
    for j in range(nref):
        out[c_ref + j, s, i] = ref[j]
    for j in range(nerr):
        e = x[err[j, 0]] - ref[err[j, 1]]
        out[c_err + j, s, i] = wrap(e) if err[j, 2] else e
    for j in range(nout):
        out[c_out + j, s, i] = gout[j]
    for j in range(nsig):
        out[c_sig + j, s, i] = sig[j]
    for j in range(nnsig):
        out[c_nav + j, s, i] = nsg[j]


@inline
def stage_state(stage, dt, x, lag, kx, kl, xs, ls):
    """The RK4 stage's state ``xs`` and lag ``ls``; returns its fraction θ of the step."""
    if stage == 0:
        theta = 0.0
        for j in range(nx):
            xs[j] = x[j]
        for j in range(nl):
            ls[j] = lag[j]
    else:
        theta = 1.0 if stage == 3 else 0.5
        step = dt if stage == 3 else 0.5 * dt
        for j in range(nx):
            xs[j] = x[j] + step * kx[j]
        for j in range(nl):
            ls[j] = lag[j] + step * kl[j]
    return theta


@inline
def stage_input(ts, theta, xs, ls, ref, zc, pc, pa, start, end, cs, sig_s, u):
    """The input ``u`` of a stage: a continuous controller's law through the actuator, the lagged
    or ramped input, or (a static actuator) the step's constant (left as it is)."""
    if continuous:
        ctrl_fn(ts, xs, ref, zc, pc, cs, sig_s)
        for j in range(nu):
            if has_lag and pa[3 * nu + j] > 0:
                u[j] = ls[j]
            else:
                u[j] = clip(cs[j], pa[j], pa[nu + j])
    elif has_lag:
        input_at_kernel(start, end, theta, ls, pa, has_lag, rate_limited, u)
    elif rate_limited:
        for j in range(nu):
            u[j] = end[j] if theta == 1.0 else start[j] + theta * (end[j] - start[j])


@inline
def accumulate(stage, kx, kl, ax, al):
    """The RK4 sum k1 + 2 k2 + 2 k3 + k4 of the plant (``ax``) and of the lag (``al``)."""
    if stage == 0:
        for j in range(nx):
            ax[j] = kx[j]
        for j in range(nl):
            al[j] = kl[j]
    elif stage < 3:
        for j in range(nx):
            ax[j] = ax[j] + 2.0 * kx[j]
        for j in range(nl):
            al[j] = al[j] + 2.0 * kl[j]
    else:
        for j in range(nx):
            ax[j] = ax[j] + kx[j]
        for j in range(nl):
            al[j] = al[j] + kl[j]


@inline
def rk4_finish(dt, ax, al, start, end, pa, x, lag, applied):
    """The step's end: ``x`` and ``lag`` advanced by dt/6 of the RK4 sums, the applied input."""
    sixth = dt / 6.0
    for j in range(nx):
        x[j] = x[j] + sixth * ax[j]
    for j in range(nl):
        lag[j] = lag[j] + sixth * al[j]
    if has_lag:
        input_at_kernel(start, end, 1.0, lag, pa, has_lag, rate_limited, applied)
    else:
        for j in range(nu):
            applied[j] = end[j]


@inline
def state_ok(x, limits):
    """The divergence guard: every state finite and within its limit."""
    ok = True
    for j in range(nx):
        if not abs(x[j]) <= limits[j]:
            ok = False
    return ok
