"""The navigation step of the composed loop, as source: :mod:`shipgnc.sim.compose` writes it into
the generated module of a combination before the loop body (:mod:`shipgnc.sim.loop_template`), so
the estimators call the vessel model's kernel ``model_fn`` by name (a numba function passed as an
argument would make the loop uncacheable). Free names: ``model_fn``, ``nx``, ``nu``, ``nd``,
``est_kind``, ``CACHE``; ``jac_fn`` (the model's analytic state Jacobian,
:func:`shipgnc.navigation.kernels.jacobian_kernel`) is found from ``model_fn``. The
arithmetic is :mod:`shipgnc.navigation.kernels`; this is
:meth:`shipgnc.navigation.Navigation.observe` for one ship at one control sample.
"""
# ruff: noqa: F821

import math

import numba
import numpy as np

from shipgnc.kernels import JIT_OPTIONS, wrap
from shipgnc.navigation.kernels import (
    correct_row,
    jacobian_kernel,
    kf_step,
    nees,
    no_jacobian,
    observer_outputs,
    observer_rhs,
    sensors_observe,
)

#: the model's analytic state Jacobian kernel (``<model kernel>_jacobian`` beside it), if any:
#: the EKF's A then costs one call instead of 2n model calls
jac_fn = jacobian_kernel(model_fn)
has_jac = jac_fn is not None
if jac_fn is None:
    jac_fn = no_jacobian


def nav_observe(t, x, u, zn, pn, w, seen, nsg, pm, wk):
    """The state the guidance and the controller see (``seen``) and the logged navigation signals
    (``nsg``) at control sample ``t`` from the true state ``x`` and the input ``u`` applied over
    the last sample; ``zn`` the ship's navigation state, ``w`` its table row of this sample,
    ``wk`` scratch space (:data:`nav_work`)."""
    sensors_observe(t, x, zn, pn, w, seen, nsg)
    if est_kind == 1:
        observer_step(u, zn, pn, pm, wk)
        observer_outputs(zn, pn, seen, nsg)
    elif est_kind == 2:
        ekf_step(u, zn, pn, pm, wk)
        gaussian_outputs(x, zn, pn, seen, nsg, wk)
    elif est_kind == 3:
        kf_step(u, zn, pn)
        gaussian_outputs(x, zn, pn, seen, nsg, wk)
    zn[0] = 0.0


#: scratch numbers per ship of the navigation step (views into it: no allocation per sample)
nav_work = 7 * nx * nx + 10 * nx + nd + nu + 96


def observer_step(u, zn, pn, pm, wk):
    """:meth:`PassiveObserver.update`: RK4 over the control period, ``substeps`` steps, y, u and
    ψ_y held (layout: :mod:`shipgnc.navigation.kernels`)."""
    e = int(pn[3])
    ez = int(pn[5])
    y = wk[0:3]
    val = wk[3:6]
    fnu = wk[6:9]
    s = wk[9:24]
    ss = wk[24:39]
    kq = wk[39:54]
    acc = wk[54:69]
    xt = wk[69:69 + nx]
    fx = wk[69 + nx:69 + 2 * nx]
    f0 = wk[69 + 2 * nx:69 + 3 * nx]
    d0 = wk[69 + 3 * nx:69 + 3 * nx + nd]
    u0 = wk[69 + 3 * nx + nd:69 + 3 * nx + nd + nu]
    for q in range(3):
        ok = zn[int(pn[e + 12 + q])] != 0.0
        val[q] = 1.0 if ok else 0.0
        y[q] = zn[int(pn[e + 9 + q])] if ok else 0.0
    psi_y = y[2] if val[2] != 0.0 else zn[ez + 8]
    if zn[0] != 0.0:  # the first sample starts the observer (at the true initial state)
        return
    cpsi = math.cos(psi_y)
    spsi = math.sin(psi_y)
    model = pn[e] != 0.0
    substeps = int(pn[e + 1])
    Ts = pn[e + 2]
    for j in range(nx):
        xt[j] = zn[ez + 18 + j]
    for j in range(nd):
        d0[j] = 0.0
    tau = zn[ez + 15:ez + 18]
    if not model:  # τ = M [ν̇(x̂, u) − ν̇(x̂, 0)], held over the sample
        for j in range(nu):
            u0[j] = 0.0
        for q in range(3):
            xt[int(pn[e + 3 + q])] = zn[ez + 6 + q]
            xt[int(pn[e + 6 + q])] = zn[ez + 12 + q]
        model_fn(xt, u, d0, pm, fx)
        model_fn(xt, u0, d0, pm, f0)
        M = e + 15 + 18 + 36
        g0 = fx[int(pn[e + 6])] - f0[int(pn[e + 6])]
        g1 = fx[int(pn[e + 7])] - f0[int(pn[e + 7])]
        g2 = fx[int(pn[e + 8])] - f0[int(pn[e + 8])]
        for q in range(3):
            tau[q] = g0 * pn[M + 3 * q] + g1 * pn[M + 3 * q + 1] + g2 * pn[M + 3 * q + 2]
    for j in range(15):
        s[j] = zn[ez + j]
    h = Ts / substeps
    for _ in range(substeps):
        for stage in range(4):
            if stage == 0:
                for j in range(15):
                    ss[j] = s[j]
            else:
                c = h if stage == 3 else h / 2
                for j in range(15):
                    ss[j] = s[j] + c * kq[j]
            if model:
                for q in range(3):
                    xt[int(pn[e + 3 + q])] = ss[6 + q]
                    xt[int(pn[e + 6 + q])] = ss[12 + q]
                model_fn(xt, u, d0, pm, fx)
                for q in range(3):
                    fnu[q] = fx[int(pn[e + 6 + q])]
            observer_rhs(ss, y, val, cpsi, spsi, fnu, tau, pn, e, kq)
            if stage == 0:
                for j in range(15):
                    acc[j] = kq[j]
            elif stage < 3:
                for j in range(15):
                    acc[j] = acc[j] + 2 * kq[j]
            else:
                for j in range(15):
                    acc[j] = acc[j] + kq[j]
        for j in range(15):
            s[j] = s[j] + (h / 6) * acc[j]
    for j in range(15):
        zn[ez + j] = s[j]


def ekf_step(u, zn, pn, pm, wk):
    """:meth:`ExtendedKalmanFilter.update`: predict (RK4 on the model, its analytic Jacobian
    ``jac_fn`` when it has one, else central differences, F by the 4th-order series, Q_d) unless
    first, then one scalar correction per state whose sensor delivered now. Small dense loops on
    views of ``wk`` (no BLAS call, no allocation: at n = 5 or 6 these cost less than a call)."""
    e = int(pn[3])
    ez = int(pn[5])
    n = nx
    nn = n * n
    zh = zn[ez:ez + n]
    P = zn[ez + n:ez + n + nn]
    substeps = int(pn[e])
    Ts = pn[e + 1]
    held = pn[e + 2] != 0.0
    nrows = int(pn[e + 3])
    q0 = e + 4 + 5 * nrows          # Q_c diagonal
    A = wk[0:nn]
    At = wk[nn:2 * nn]
    F = wk[2 * nn:3 * nn]
    T1 = wk[3 * nn:4 * nn]
    T2 = wk[4 * nn:5 * nn]
    Qd = wk[5 * nn:6 * nn]
    G = wk[6 * nn:7 * nn]
    v = 7 * nn
    fp = wk[v:v + n]
    fm = wk[v + n:v + 2 * n]
    xp = wk[v + 2 * n:v + 3 * n]
    k1 = wk[v + 3 * n:v + 4 * n]
    k2 = wk[v + 4 * n:v + 5 * n]
    k3 = wk[v + 5 * n:v + 6 * n]
    k4 = wk[v + 6 * n:v + 7 * n]
    Pc = wk[v + 7 * n:v + 8 * n]
    d0 = wk[v + 8 * n:v + 8 * n + nd]
    for j in range(nd):
        d0[j] = 0.0
    if zn[0] == 0.0:
        if has_jac:  # the model's analytic ∂f/∂x
            jac_fn(zh, u, d0, pm, A)
        else:  # central differences
            for j in range(n):
                hj = 1e-6 * max(1.0, abs(zh[j]))
                for i in range(n):
                    xp[i] = zh[i]
                xp[j] = zh[j] + hj
                model_fn(xp, u, d0, pm, fp)
                xp[j] = zh[j] - hj
                model_fn(xp, u, d0, pm, fm)
                for i in range(n):
                    A[i * n + j] = (fp[i] - fm[i]) / (2.0 * hj)
        for i in range(nn):
            At[i] = A[i] * Ts
        for i in range(n):   # F = I + At + At²/2 + At³/6 + At⁴/24 (term = term·At / k)
            for j in range(n):
                F[i * n + j] = (1.0 if i == j else 0.0) + At[i * n + j]
        for i in range(nn):
            T1[i] = At[i]
        for k in range(2, 5):
            matmul(T1, At, T2, False)
            for i in range(nn):
                T1[i] = T2[i] / k
                F[i] = F[i] + T1[i]
        if held:  # Γ (Q_c/Ts) Γᵀ, Γ = Ts (I + At/2 + At²/6)
            matmul(At, At, T2, False)
            for i in range(n):
                for j in range(n):
                    G[i * n + j] = Ts * ((1.0 if i == j else 0.0) + At[i * n + j] / 2
                                         + T2[i * n + j] / 6)
            for i in range(n):
                for j in range(n):
                    T1[i * n + j] = G[i * n + j] * pn[q0 + j]
            matmul(T1, G, Qd, True)
            for i in range(nn):
                Qd[i] = Qd[i] / Ts
        else:  # Q_c Ts + (A Q_c + Q_c Aᵀ) Ts²/2 + A Q_c Aᵀ Ts³/3
            Ts2 = Ts**2
            Ts3 = Ts**3
            for i in range(n):
                for j in range(n):
                    T1[i * n + j] = A[i * n + j] * pn[q0 + j]
            matmul(T1, A, T2, True)
            for i in range(n):
                for j in range(n):
                    x_ = ((T1[i * n + j] + T1[j * n + i]) * Ts2) / 2
                    qc = pn[q0 + i] if i == j else 0.0
                    Qd[i * n + j] = qc * Ts + x_ + (T2[i * n + j] * Ts3) / 3
        # x̂⁻ = Φ(x̂, u): RK4, substeps per Ts
        h = Ts / substeps
        for _ in range(substeps):
            model_fn(zh, u, d0, pm, k1)
            for i in range(n):
                xp[i] = zh[i] + 0.5 * h * k1[i]
            model_fn(xp, u, d0, pm, k2)
            for i in range(n):
                xp[i] = zh[i] + 0.5 * h * k2[i]
            model_fn(xp, u, d0, pm, k3)
            for i in range(n):
                xp[i] = zh[i] + h * k3[i]
            model_fn(xp, u, d0, pm, k4)
            for i in range(n):
                zh[i] = zh[i] + (h / 6.0) * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i])
        matmul(F, P, T1, False)   # P⁻ = F P Fᵀ + Q_d, symmetrised
        matmul(T1, F, T2, True)
        for i in range(nn):
            T2[i] = T2[i] + Qd[i]
        for i in range(n):
            for j in range(n):
                P[i * n + j] = 0.5 * (T2[i * n + j] + T2[j * n + i])
    for r in range(nrows):
        o = e + 4 + 5 * r
        if zn[int(pn[o + 2])] != 0.0:  # fresh
            correct_row(zh, P, int(pn[o]), zn[int(pn[o + 1])], pn[o + 3], pn[o + 4] != 0.0, Pc)


def matmul(X, Y, out, transposed):
    """``out`` = X Y (or X Yᵀ) of n × n row-major matrices, each entry summed over m in order (as
    a dot product) but with the n entries of a row accumulated side by side: independent sums
    that the processor overlaps (a sum at a time waits on each add)."""
    n = nx
    for i in range(n):
        for j in range(n):
            out[i * n + j] = 0.0
        for m in range(n):
            a = X[i * n + m]
            if transposed:
                for j in range(n):
                    out[i * n + j] += a * Y[j * n + m]
            else:
                for j in range(n):
                    out[i * n + j] += a * Y[m * n + j]


def gaussian_outputs(x, zn, pn, seen, nsg, wk):
    """A Gaussian filter's estimates of the model states into ``seen`` and its logged signals
    ``<s>_hat``, ``<s>_std`` (√ of P's diagonal) and ``nees`` (:meth:`GaussianFilter.nees`);
    its map at ``pn[6]``: ``[n, n_mapped, (filter index, model index, angle) × n_mapped]``."""
    ez = int(pn[5])
    so = int(pn[4])
    g = int(pn[6])                   # the filter's map block
    n = int(pn[g])
    m = int(pn[g + 1])
    need = m * m + 5 * m
    work = wk[:need] if need <= wk.shape[0] else np.empty(need)
    err = work[0:m]
    idx = work[m:2 * m]
    for a in range(m):
        i = int(pn[g + 2 + 3 * a])
        j = int(pn[g + 3 + 3 * a])
        seen[j] = zn[ez + i]
        e = x[j] - zn[ez + i]
        err[a] = wrap(e) if pn[g + 4 + 3 * a] != 0.0 else e
        idx[a] = i
    for i in range(n):
        nsg[so + i] = zn[ez + i]
        nsg[so + n + i] = math.sqrt(max(zn[ez + n + i * n + i], 0.0))
    nsg[so + 2 * n] = (nees(err, zn[ez + n:ez + n + n * n], n, idx, m, work[2 * m:]) if m > 0
                       else np.nan)


_OPTIONS = {**JIT_OPTIONS, "cache": CACHE}
matmul = numba.njit(**_OPTIONS)(matmul)
observer_step = numba.njit(**_OPTIONS)(observer_step)
ekf_step = numba.njit(**_OPTIONS)(ekf_step)
gaussian_outputs = numba.njit(**_OPTIONS)(gaussian_outputs)
nav_observe = numba.njit(**_OPTIONS)(nav_observe)
