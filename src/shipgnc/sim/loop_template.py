"""The composed loop's body, as source: :mod:`shipgnc.sim.compose` writes it under a header that
binds the free names below (the components' kernels ``model_fn``, ``ctrl_fn``, ``guid_fn``,
``dist_fn`` and a disturbance's current part ``cur_fn``; the navigation step ``nav_observe`` of
:mod:`shipgnc.sim.nav_template`, written before this body; the sizes ``nx``, ``nu``, ...; the row
offsets ``o_*`` and log columns ``c_*`` of
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
         err, out, event, done_at, Wu, pu_rows, Wn, pn_rows, s_base):
    n_ships = S.shape[0]
    for i in numba.prange(n_ships):
        if event[i] >= 0:  # stopped by its divergence (on_divergence="mask"): skipped
            continue
        row = S[i]
        # a component's parameters: one row for every ship, or a row per ship (1 or n rows)
        ship = np.int64(i)  # the prange index may be unsigned: int64 keeps min() an integer
        pm = pm_rows[min(ship, pm_rows.shape[0] - 1)].copy()
        pc = pc_rows[min(ship, pc_rows.shape[0] - 1)].copy()
        pg = pg_rows[min(ship, pg_rows.shape[0] - 1)].copy()
        pd = pd_rows[min(ship, pd_rows.shape[0] - 1)].copy()
        pu = pu_rows[min(ship, pu_rows.shape[0] - 1)].copy()
        pn = pn_rows[min(ship, pn_rows.shape[0] - 1)].copy()
        zui = np.empty(0)  # the current part keeps no state
        # the ship's carried state as fresh local arrays (written back after its last step):
        # arrays that cannot alias each other let LLVM keep values in registers across the
        # components' calls (views into S, or a parameter row picked by index, run ≈ 2× slower)
        x = row[o_x:o_x + nx].copy()
        lag = row[o_lag:o_lag + nl].copy()
        applied = row[o_app:o_app + nu].copy()
        cmd = row[o_cmd:o_cmd + nu].copy()
        ref = row[o_ref:o_ref + nref].copy()
        gout = row[o_out:o_out + nout].copy()
        sig = row[o_sig:o_sig + nsig].copy()
        d = row[o_d:o_d + nd].copy()
        zci = row[o_zc:o_zc + nzc].copy()
        zgi = row[o_zg:o_zg + nzg].copy()
        zdi = row[o_zd:o_zd + nzd].copy()
        zni = row[o_zn:o_zn + nzn].copy()   # navigation: its state and held logged signals
        nsg = row[o_nsg:o_nsg + nnsig].copy()
        seen = np.empty(nx if has_nav else 0)  # the state guidance and controller see
        nwk = np.empty(nav_work if has_nav else 0)  # the navigation step's scratch space
        j0 = (k0 + hold - 1) // hold  # the chunk's first control sample (row 0 of Wn)
        done = row[o_done]
        start = np.empty(nu)
        end = np.empty(nu)
        u = np.empty(nu)
        cs = np.empty(nu)
        sig_s = np.empty(nsig)
        xs = np.empty(nx)  # stage state, derivative and RK4 sum of the plant ...
        kx = np.empty(nx)
        ax = np.empty(nx)
        ls = np.empty(nl)  # ... and of the actuator lag
        kl = np.empty(nl)
        al = np.empty(nl)
        ic = k0 % hold
        il = k0 % every
        s = (k0 + every - 1) // every - s_base  # the log's sample (``out`` from sample s_base)
        for k in range(k0, k1):
            t = k * dt
            if ic == 0:
                if has_nav:  # Navigation.observe: the estimate (or measurements) from the truth
                    nav_observe(t, x, applied, zni, pn, Wn[k // hold - j0, i], seen, nsg, pm,
                                nwk)
                # the constant flags pick each call at compile time (an array chosen by a
                # conditional expression would keep numba's reference counting in the loop)
                if has_guid:
                    if has_nav:
                        finished = guid_fn(t, seen, zgi, pg, ref, gout)
                    else:
                        finished = guid_fn(t, x, zgi, pg, ref, gout)
                    if finished:
                        done = 1.0
                if has_ctrl:  # a continuous controller's law reads the truth (as run_numpy)
                    if has_nav and not continuous:
                        ctrl_fn(t, seen, ref, zci, pc, cmd, sig)
                    else:
                        ctrl_fn(t, x, ref, zci, pc, cmd, sig)
                    bad = False
                    for j in range(nu):
                        if not math.isfinite(cmd[j]):
                            bad = True
                    if bad:
                        event[i] = 2 * k
                        break
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
            if has_dist and not per_stage:
                dist_fn(t, x, zdi, pd, W[k - k0, i], d)
                if has_cur:
                    cur_fn(t, x, zui, pu, Wu[k - k0, i], d)
            if done != 0.0 and done_at[i] < 0:
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
                for j in range(nnsig):
                    out[c_nav + j, s, i] = nsg[j]
                s += 1
            if k == k_last:
                break
            # classic RK4 (sim.integrators.rk4_step) of z = [x, lag]; stage states in their own
            # arrays (no views in the hot loop); a static actuator's input is the step's constant
            for stage in range(4):
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
                ts = t + theta * dt
                if continuous:
                    ctrl_fn(ts, xs, ref, zci, pc, cs, sig_s)
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
                if has_dist and per_stage:
                    dist_fn(ts, xs, zdi, pd, W[k - k0, i], d)
                    if has_cur:
                        cur_fn(ts, xs, zui, pu, Wu[k - k0, i], d)
                model_fn(xs, u, d, pm, kx)
                if has_lag:
                    lag_rate_kernel(cs if continuous else cmd, ls, pa, kl)
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
        row[o_x:o_x + nx] = x
        row[o_lag:o_lag + nl] = lag
        row[o_app:o_app + nu] = applied
        row[o_cmd:o_cmd + nu] = cmd
        row[o_ref:o_ref + nref] = ref
        row[o_out:o_out + nout] = gout
        row[o_sig:o_sig + nsig] = sig
        row[o_d:o_d + nd] = d
        row[o_zc:o_zc + nzc] = zci
        row[o_zg:o_zg + nzg] = zgi
        row[o_zd:o_zd + nzd] = zdi
        row[o_zn:o_zn + nzn] = zni
        row[o_nsg:o_nsg + nnsig] = nsg
        row[o_done] = done
