"""The composed loop's body, as source: :mod:`shipgnc.sim.compose` writes it under a header that
binds the free names below (the components' kernels ``model_fn``, ``ctrl_fn``, ``guid_fn``,
``dist_fn``; the sizes ``nx``, ``nu``, ...; the row offsets ``o_*`` and log columns ``c_*`` of
:func:`~shipgnc.sim.compose.row_layout`; the flags ``has_*``) as constants of one combination,
and compiles it (so this module is never imported as itself). It is
:func:`shipgnc.sim.simulator.run_numpy` step for step, for one ship at a time (see
:mod:`shipgnc.sim.compose`).
"""
# ruff: noqa: F821

import math

import numba
import numpy as np

from shipgnc.actuators import input_at_kernel, lag_rate_kernel, plan_kernel
from shipgnc.kernels import JIT_OPTIONS, clip, wrap  # noqa: F401  (JIT_OPTIONS: the generated tail)


def loop(k0, k1, k_last, hold, every, dt, S, W, pm_rows, pa, pc_rows, pg_rows, pd_rows, limits,
         err, out, event, done_at):
    n_ships = S.shape[0]
    for i in numba.prange(n_ships):
        row = S[i]
        # a component's parameters: one row for every ship, or a row per ship (1 or n rows)
        ship = np.int64(i)  # the prange index may be unsigned: int64 keeps min() an integer
        pm = pm_rows[min(ship, pm_rows.shape[0] - 1)]
        pc = pc_rows[min(ship, pc_rows.shape[0] - 1)]
        pg = pg_rows[min(ship, pg_rows.shape[0] - 1)]
        pd = pd_rows[min(ship, pd_rows.shape[0] - 1)]
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
            plan_kernel(applied, cmd, pa, dt, rate_limited, hold_mode, start, end)
            input_at_kernel(start, end, 0.0, lag, pa, has_lag, rate_limited, u)
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
                    input_at_kernel(start, end, theta, lag_s, pa, has_lag, rate_limited, u)
                if has_dist and per_stage:
                    dist_fn(ts, xs, zdi, pd, W[k - k0, i], d)
                model_fn(xs, u, d, pm, xdot)
                for j in range(nx):
                    ks[j] = xdot[j]
                if has_lag:
                    lag_rate_kernel(cs if continuous else cmd, lag_s, pa, ks[nx:])
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
            input_at_kernel(start, end, 1.0, lag, pa, has_lag, rate_limited, applied)
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
