"""The composed compiled loop: any model × actuator × controller × guidance × disturbance whose
components have kernels (:mod:`shipgnc.kernels`), run as one numba loop.

:func:`loop_for` is the loop generator: a factory whose inner jitted loop calls the components'
jitted functions, compiled on the first use of a combination and memoised for the process (numba's
disk cache does not cover closures; each component's own kernel is cached on disk). The loop is
:func:`shipgnc.sim.simulator.run_numpy` step for step, for one ship at a time:

1. every ``Ts``: the guidance's references and outputs, then the controller's command and
   signals (a non-finite command is a divergence at that sample);
2. the actuator's plan of the step (:mod:`shipgnc.actuators`: saturation, rate limit ``ramp`` or
   ``hold``, first-order lag integrated with the plant) and the applied input at its start;
3. a held disturbance sample;
4. the log (every ``log_every``-th sample, the last one, and the sample where every ship's
   guidance has finished);
5. classic RK4 of ``[x, lag]`` (a continuous controller's law and a ``per_stage`` disturbance in
   every stage), the applied input at the step's end, the divergence guard.

Ships are the outer loop (``numba.prange``), time the inner one. A run is one kernel call or
several (progress, bounded log chunks) that carry each ship's state in its row of ``S`` and give
bit-identical results (:func:`shipgnc.sim.compiled.drive`). :func:`unsupported_reason` names the
first component without a kernel; ``simulate`` then runs the numpy loop.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from shipgnc.errors import ConfigError
from shipgnc.kernels import JIT_OPTIONS, Kernel, NotCompiled, clip, kernel_function, wrap

_LOOPS: dict = {}


@kernel_function
def _no_model(x, u, d, p, xdot):  # pragma: no cover - placeholder, never called
    pass


@kernel_function
def _no_controller(t, x, ref, z, p, cmd, sig):
    pass


@kernel_function
def _no_guidance(t, x, z, p, ref, out):
    return False


@kernel_function
def _no_disturbance(t, x, z, p, w, d):
    pass


# ----------------------------------------------------------------------------------------------
# the actuator (shipgnc.actuators.Actuator), per ship; p = [lower, upper, rate, tau] (n each)
# ----------------------------------------------------------------------------------------------

@kernel_function
def _plan(applied, cmd, pa, h, rate_limited, hold_mode, start, end):
    """:meth:`Actuator.begin_step` for one ship: the step's input runs from ``start`` to ``end``."""
    n = cmd.shape[0]
    for j in range(n):
        target = clip(cmd[j], pa[j], pa[n + j])
        if not rate_limited:
            start[j] = target
            end[j] = target
            continue
        rate = pa[2 * n + j]
        e = applied[j] + clip(target - applied[j], -rate * h, rate * h)
        end[j] = e
        start[j] = e if (hold_mode or not math.isfinite(rate)) else applied[j]


@kernel_function
def _input_at(start, end, theta, lag, pa, has_lag, rate_limited, u):
    """:meth:`Actuator.input_at`: the applied input at fraction ``theta`` of the step."""
    n = u.shape[0]
    for j in range(n):
        if has_lag and pa[3 * n + j] > 0:
            u[j] = lag[j]
        elif theta == 1.0 or not rate_limited:
            u[j] = end[j]
        else:
            u[j] = start[j] + theta * (end[j] - start[j])


@kernel_function
def _lag_rate(cmd, lag, pa, out):
    """:meth:`Actuator.lag_derivative`: ȧ = clip((sat(cmd) − a)/τ, −rate, rate) on lag channels."""
    n = cmd.shape[0]
    for j in range(n):
        tau = pa[3 * n + j]
        if tau > 0:
            target = clip(cmd[j], pa[j], pa[n + j])
            rate = pa[2 * n + j]
            out[j] = clip((target - lag[j]) / tau, -rate, rate)
        else:
            out[j] = 0.0


def loop_for(model_fn, ctrl_fn, guid_fn, dist_fn, *, nx: int, nu: int, nd: int, nref: int,
             nout: int, nsig: int, nerr: int, nzc: int, nzg: int, nzd: int, has_ctrl: bool,
             continuous: bool, has_guid: bool, has_dist: bool, per_stage: bool, has_lag: bool,
             rate_limited: bool, hold_mode: bool):
    """The composed loop of one combination (compiled on first use, memoised per process)."""
    key = (model_fn, ctrl_fn, guid_fn, dist_fn, nx, nu, nd, nref, nout, nsig, nerr, nzc, nzg, nzd,
           has_ctrl, continuous, has_guid, has_dist, per_stage, has_lag, rate_limited, hold_mode)
    if key not in _LOOPS:
        _LOOPS[key] = _generate(*key)
    return _LOOPS[key]


def _generate(model_fn, ctrl_fn, guid_fn, dist_fn, nx, nu, nd, nref, nout, nsig, nerr, nzc, nzg,
              nzd, has_ctrl, continuous, has_guid, has_dist, per_stage, has_lag, rate_limited,
              hold_mode):
    nl = nu if has_lag else 0
    nz = nx + nl
    lay = row_layout(nx, nl, nu, nref, nout, nsig, nd, nzc, nzg, nzd)
    o_x, o_lag, o_app, o_cmd, o_ref = lay["x"], lay["lag"], lay["applied"], lay["cmd"], lay["ref"]
    o_out, o_sig, o_d, o_done = lay["out"], lay["sig"], lay["d"], lay["done"]
    o_zc, o_zg, o_zd = lay["zc"], lay["zg"], lay["zd"]
    # columns of the log (the order of simulator.log_signals)
    c_cmd, c_app, c_ref = nx, nx + nu, nx + 2 * nu
    c_err = c_ref + nref
    c_out = c_err + nerr
    c_sig = c_out + nout

    def loop(k0, k1, k_last, hold, every, dt, S, W, pm, pa, pc, pg, pd, limits, err,
             out, event, done_at):
        n_ships = S.shape[0]
        for i in numba.prange(n_ships):
            row = S[i]
            x = row[o_x:o_x + nx]
            lag = row[o_lag:o_lag + nl]
            applied = row[o_app:o_app + nu]
            cmd = row[o_cmd:o_cmd + nu]
            ref = row[o_ref:o_ref + nref]
            gout = row[o_out:o_out + nout]
            sig = row[o_sig:o_sig + nsig]
            d = row[o_d:o_d + nd]
            zci = row[o_zc:o_zc + nzc]
            zgi = row[o_zg:o_zg + nzg]
            zdi = row[o_zd:o_zd + nzd]
            start = np.empty(nu)
            end = np.empty(nu)
            u = np.empty(nu)
            cs = np.empty(nu)
            sig_s = np.empty(nsig)
            zs = np.empty(nz)
            zn = np.empty(nz)
            ks = np.empty(nz)
            acc = np.empty(nz)
            xdot = np.empty(nx)
            ic = k0 % hold
            il = k0 % every
            s = (k0 + every - 1) // every
            for k in range(k0, k1):
                t = k * dt
                if ic == 0:
                    if has_guid:
                        if guid_fn(t, x, zgi, pg, ref, gout):
                            row[o_done] = 1.0
                    if has_ctrl:
                        ctrl_fn(t, x, ref, zci, pc, cmd, sig)
                        bad = False
                        for j in range(nu):
                            if not math.isfinite(cmd[j]):
                                bad = True
                        if bad:
                            event[i] = 2 * k
                            break
                _plan(applied, cmd, pa, dt, rate_limited, hold_mode, start, end)
                _input_at(start, end, 0.0, lag, pa, has_lag, rate_limited, u)
                if has_dist and not per_stage:
                    dist_fn(t, x, zdi, pd, W[k - k0, i], d)
                if row[o_done] != 0.0 and done_at[i] < 0:
                    done_at[i] = k
                if il == 0 or k == k_last:
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
                    s += 1
                if k == k_last:
                    break
                # classic RK4 (sim.integrators.rk4_step) of z = [x, lag]
                for stage in range(4):
                    if stage == 0:
                        theta = 0.0
                        for j in range(nz):
                            zs[j] = x[j] if j < nx else lag[j - nx]
                    else:
                        theta = 1.0 if stage == 3 else 0.5
                        step = dt if stage == 3 else 0.5 * dt
                        for j in range(nz):
                            zs[j] = (x[j] if j < nx else lag[j - nx]) + step * ks[j]
                    ts = t + theta * dt
                    xs = zs[:nx]
                    lag_s = zs[nx:]
                    if continuous:
                        ctrl_fn(ts, xs, ref, zci, pc, cs, sig_s)
                        for j in range(nu):
                            if has_lag and pa[3 * nu + j] > 0:
                                u[j] = lag_s[j]
                            else:
                                u[j] = clip(cs[j], pa[j], pa[nu + j])
                    else:
                        _input_at(start, end, theta, lag_s, pa, has_lag, rate_limited, u)
                    if has_dist and per_stage:
                        dist_fn(ts, xs, zdi, pd, W[k - k0, i], d)
                    model_fn(xs, u, d, pm, xdot)
                    for j in range(nx):
                        ks[j] = xdot[j]
                    if has_lag:
                        _lag_rate(cs if continuous else cmd, lag_s, pa, ks[nx:])
                    if stage == 0:
                        for j in range(nz):
                            acc[j] = ks[j]
                    elif stage < 3:
                        for j in range(nz):
                            acc[j] = acc[j] + 2.0 * ks[j]
                    else:
                        for j in range(nz):
                            acc[j] = acc[j] + ks[j]
                sixth = dt / 6.0
                for j in range(nz):
                    zn[j] = (x[j] if j < nx else lag[j - nx]) + sixth * acc[j]
                for j in range(nx):
                    x[j] = zn[j]
                for j in range(nl):
                    lag[j] = zn[nx + j]
                _input_at(start, end, 1.0, lag, pa, has_lag, rate_limited, applied)
                ok = True
                for j in range(nx):
                    if not abs(x[j]) <= limits[j]:
                        ok = False
                if not ok:
                    event[i] = 2 * k + 1
                    break
                ic += 1
                if ic == hold:
                    ic = 0
                il += 1
                if il == every:
                    il = 0

    return numba.njit(parallel=True, **{**JIT_OPTIONS, "cache": False})(loop)


# ----------------------------------------------------------------------------------------------
# entry points: which setups the composed loop covers, and running one
# ----------------------------------------------------------------------------------------------

def _roles(setup):
    return (("model", setup.model), ("controller", setup.controller),
            ("guidance", setup.guidance), ("disturbance", setup.disturbance))


def unsupported_reason(setup) -> str | None:
    """None when every component of ``setup`` has a kernel, else which one has none and why."""
    if setup.integrator != "rk4":
        return f"integrator {setup.integrator!r} is not compiled (only 'rk4')"
    if setup.observer is not None:
        return "an observer callback needs the Python loop"
    for role, component in _roles(setup):
        if component is None:
            continue
        if not callable(getattr(component, "kernel", None)):
            return f"{role} {type(component).__name__} has no kernel"
        why = getattr(component, "kernel_reason", None)
        reason = why() if callable(why) else None
        if reason:
            return f"{role} {type(component).__name__}: {reason}"
    if getattr(setup.controller, "continuous", False) and getattr(setup.controller, "signals", ()):
        return f"controller {type(setup.controller).__name__}: a continuous law's signals are not compiled"
    return None


def run(setup):
    """Run ``setup`` in its composed loop; returns the same ``Log`` as ``run_numpy(setup)``."""
    from shipgnc.sim.compiled import drive, log_length, make_log
    from shipgnc.sim.simulator import log_signals

    reason = unsupported_reason(setup)
    if reason:
        raise ConfigError(f"compiled loop: {reason}")
    model, act, ctrl, gd, dist = (setup.model, setup.actuator, setup.controller, setup.guidance,
                                  setup.disturbance)
    batch = setup.batch_shape
    n = math.prod(batch)
    # the same side effects on the components as the numpy loop, then their kernels
    if ctrl is not None:
        ctrl.reset(batch)
    if gd is not None:
        gd.reset(batch, model)
    if dist is not None:
        dist.reset(batch, setup.rng)
    try:
        km = model.kernel()
        kc = ctrl.kernel(batch) if ctrl is not None else None
        kg = gd.kernel(batch) if gd is not None else None
        kd = dist.kernel(batch) if dist is not None else None
    except NotCompiled as exc:  # a setting only known after reset: the caller falls back
        raise ConfigError(f"compiled loop: {exc}") from None
    empty = Kernel(_no_controller)
    kc_, kg_, kd_ = kc or empty, kg or empty, kd or empty

    nx, nu = len(model.states), act.n
    nd = len(model.disturbances)
    refs = tuple(gd.references) if gd is not None else ()
    nout = len(gd.outputs) if gd is not None else 0
    nsig = len(getattr(ctrl, "signals", ())) if ctrl is not None else 0
    state_names = [s.name for s in model.states]
    err = np.array([(state_names.index(s.tracks), j, int(s.angle)) for j, s in enumerate(refs)
                    if s.tracks], dtype=np.int64).reshape(-1, 3)
    zc0, zg0, zd0 = kc_.state_for(n), kg_.state_for(n), kd_.state_for(n)
    continuous = bool(getattr(ctrl, "continuous", False))
    loop = loop_for(km.function, kc.function if kc else _no_controller,
                    kg.function if kg else _no_guidance, kd.function if kd else _no_disturbance,
                    nx=nx, nu=nu, nd=nd, nref=len(refs), nout=nout, nsig=nsig, nerr=err.shape[0],
                    nzc=zc0.shape[1], nzg=zg0.shape[1], nzd=zd0.shape[1], has_ctrl=ctrl is not None,
                    continuous=continuous, has_guid=gd is not None, has_dist=dist is not None,
                    per_stage=bool(getattr(dist, "per_stage", False)), has_lag=act.has_lag,
                    rate_limited=act.has_rate_limit, hold_mode=act.rate_mode == "hold")
    lay = row_layout(nx, nu if act.has_lag else 0, nu, len(refs), nout, nsig, nd, zc0.shape[1],
                     zg0.shape[1], zd0.shape[1])

    S = np.zeros((n, lay["row"]))
    S[:, :nx] = setup.x0.reshape(n, nx)
    command = np.broadcast_to(setup.u0, (*batch, nu)).reshape(n, nu)
    applied = act.initial(command)
    if act.has_lag:
        S[:, lay["lag"]:lay["lag"] + nu] = applied
    S[:, lay["applied"]:lay["applied"] + nu] = applied
    S[:, lay["cmd"]:lay["cmd"] + nu] = command
    S[:, lay["zc"]:lay["zc"] + zc0.shape[1]] = zc0
    S[:, lay["zg"]:lay["zg"] + zg0.shape[1]] = zg0
    S[:, lay["zd"]:lay["zd"] + zd0.shape[1]] = zd0

    signals = log_signals(setup)
    n_columns = nx + 2 * nu + len(refs) + err.shape[0] + nout + nsig
    if n_columns != len(signals):  # the loop's column layout must match the numpy loop's log
        raise RuntimeError(f"compiled loop: {n_columns} log columns for {list(signals)}")
    out = np.empty((n_columns, log_length(setup), n))
    event_at = np.full(n, -1, dtype=np.int64)
    done_at = np.full(n, -1, dtype=np.int64) if gd is not None else None
    params = [np.ascontiguousarray(k.params, dtype=np.float64) for k in (km, kc_, kg_, kd_)]
    pa = np.concatenate([act.lower, act.upper, act.rate, act.tau]).astype(np.float64)
    limits = np.asarray(model.state_limits, dtype=np.float64)
    table = {"W": np.zeros((1, n, 0))}

    def prepare(k0: int, k1: int) -> None:
        if kd is not None and kd.table is not None:
            table["W"] = np.ascontiguousarray(kd.table(k0, k1), dtype=np.float64)
        else:
            table["W"] = np.zeros((k1 - k0, n, 0))

    def call(k0: int, k1: int, k_last: int) -> None:
        loop(k0, k1, k_last, int(setup.hold), int(setup.log_every), float(setup.dt), S, table["W"],
             params[0], pa, params[1], params[2], params[3], limits, err, out, event_at,
             done_at if done_at is not None else np.zeros(n, dtype=np.int64))

    event, k_end = drive(setup, call, S, event_at, prepare=prepare, done_at=done_at)
    for k, key, width in ((kc, "zc", zc0.shape[1]), (kg, "zg", zg0.shape[1]), (kd, "zd", zd0.shape[1])):
        if k is not None and k.restore is not None:
            k.restore(S[:, lay[key]:lay[key] + width].copy())
    return make_log(setup, signals, out, S, event, state_slot=0, cmd_slot=lay["cmd"], k_end=k_end)


def row_layout(nx, nl, nu, nref, nout, nsig, nd, nzc, nzg, nzd) -> dict[str, int]:
    """Offsets of a ship's row of ``S``: state, lag, applied input, command, references, guidance
    outputs, controller signals, held disturbance, finished flag, the components' own states."""
    lay = {"x": 0, "lag": nx, "applied": nx + nl, "cmd": nx + nl + nu}
    lay["ref"] = lay["cmd"] + nu
    lay["out"] = lay["ref"] + nref
    lay["sig"] = lay["out"] + nout
    lay["d"] = lay["sig"] + nsig
    lay["done"] = lay["d"] + nd
    lay["zc"] = lay["done"] + 1
    lay["zg"] = lay["zc"] + nzc
    lay["zd"] = lay["zg"] + nzg
    lay["row"] = lay["zd"] + nzd
    return lay
