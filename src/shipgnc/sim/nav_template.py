"""The navigation step of the composed loop, as source: :mod:`shipgnc.sim.compose` writes it into
the generated module of a combination before the loop body (:mod:`shipgnc.sim.loop_template`), so
the estimators call the vessel model's kernel ``model_fn`` by name (a numba function passed as an
argument would make the loop uncacheable). Free names: ``model_fn``, ``nx``, ``nu``, ``nd``,
``est_slot`` (the estimator's step, one of the slots below, bound after them), ``ne`` (the EKF's
state dimension: ``nx`` plus its augmented states), ``CACHE``;
``jac_fn`` (the model's analytic state Jacobian,
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
    jacobian_kernel,
    kf_step,
    nees,
    no_jacobian,
    observer_outputs,
    observer_rhs,
    sensors_observe,
    stack_empty,
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
    est_slot(x, u, zn, pn, pm, wk, seen, nsg)
    zn[0] = 0.0


# the estimators' slots: ``(x, u, zn, pn, pm, wk, seen, nsg)``, an estimator's update and its
# outputs (its kernel_block names its slot; the generated module binds it to ``est_slot``)
def no_estimator(x, u, zn, pn, pm, wk, seen, nsg):
    pass


def observer_slot(x, u, zn, pn, pm, wk, seen, nsg):
    observer_step(u, zn, pn, pm, wk)
    observer_outputs(zn, pn, seen, nsg)


def ekf_slot(x, u, zn, pn, pm, wk, seen, nsg):
    ekf_step(u, zn, pn, pm, wk)
    gaussian_outputs(x, zn, pn, seen, nsg, wk)


def kf_slot(x, u, zn, pn, pm, wk, seen, nsg):
    kf_step(u, zn, pn)
    gaussian_outputs(x, zn, pn, seen, nsg, wk)


#: scratch numbers per ship of the navigation step (views into it: no allocation per sample)
nav_work = nx * nx + 5 * nx + nd + nu + 96
#: the size of the EKF's matrices (a constant: :func:`ekf_step`'s arrays live on the stack)
nn = nx * nx
nne = ne * ne
#: fields of an EKF measurement row in its parameter block (ExtendedKalmanFilter.kernel_block)
ROW = 10


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


def ekf_faug(z, u, d0, pm, pn, a0, out):
    """The EKF's augmented derivative (:meth:`ExtendedKalmanFilter._f_aug`): the model's ẋ plus
    each bias d on the state it drives, −λ b for the others; ``a0`` the augmented block of ``pn``:
    (driven state or −1, λ) per augmented state."""
    model_fn(z[:nx], u, d0, pm, out[:nx])
    for a in range(ne - nx):
        tgt = int(pn[a0 + 2 * a])
        b = z[nx + a]
        if tgt >= 0:
            out[tgt] = out[tgt] + b
        out[nx + a] = -b * pn[a0 + 2 * a + 1]


def ekf_step(u, zn, pn, pm, wk):
    """:meth:`ExtendedKalmanFilter.update`: predict (RK4 on the model, its analytic Jacobian
    ``jac_fn`` when it has one, else central differences, F by the 4th-order series, Q_d) unless
    first, then one scalar correction per state whose sensor delivered now (:func:`ekf_correct`).
    Small loops of known length (n = ``ne``: the model's states and the augmented ones) on
    arrays on the stack (no BLAS call, no allocation, nothing the compiler must assume aliases
    ``zn``: at n = 5 or 6 these cost less than a call).

    The numpy form's arithmetic with fewer operations (equal to it up to round-off):

    * F − I = E = At + At²/2 + At² (At/6 + At²/24), At = A Ts: two matrix products where the
      series term by term takes three (Paterson & Stockmeyer 1973, SIAM J. Comput. 2(1));
    * P⁻ = F P Fᵀ + Q_d as T = F P = P + E P, then P⁻ = T + T Eᵀ + Q_d on the upper triangle only
      and mirrored (P⁻ is symmetric: what the numpy form's symmetrisation returns); Q_d's
      products on the upper triangle too.

    At n = 6 that is about 900 multiply-adds per prediction instead of 1 500 (the series 3 × 216,
    F P Fᵀ 2 × 216, A Q_c Aᵀ 216)."""
    e = int(pn[3])
    ez = int(pn[5])
    n = ne
    zh = zn[ez:ez + n]
    P = zn[ez + n:ez + n + nne]
    substeps = int(pn[e])
    Ts = pn[e + 1]
    held = pn[e + 2] != 0.0
    nrows = int(pn[e + 3])
    nslt = int(pn[e + 5])           # pending delayed samples (Larsen et al. 1998)
    q0 = e + 6 + ROW * nrows        # Q_c diagonal
    a0 = q0 + n                     # augmented states: (driven state, λ) each
    kc = ez + n + nne + 2           # the sample count, then the slots
    sb = kc + 1
    ssz = 4 + n + nslt
    nis = 0.0
    nisd = 0.0
    if zn[0] != 0.0:
        zn[kc] = 0.0
    else:
        zn[kc] += 1.0
        d0 = stack_empty(nd)
        for j in range(nd):
            d0[j] = 0.0
        A = stack_empty(nne)
        Ax = stack_empty(nn)
        At = stack_empty(nne)
        B2 = stack_empty(nne)       # At², then T = F P
        C = stack_empty(nne)        # At/6 + At²/24, then Γ
        E = stack_empty(nne)        # F − I
        Qd = stack_empty(nne)       # Q_d, then P⁻ (upper triangles)
        q = stack_empty(ne)
        Pl = stack_empty(nne)
        xp = stack_empty(ne)
        k1 = stack_empty(ne)
        k2 = stack_empty(ne)
        k3 = stack_empty(ne)
        k4 = stack_empty(ne)
        for j in range(n):
            q[j] = pn[q0 + j]
        if has_jac:  # the model's analytic ∂f/∂x
            jac_fn(zh[:nx], u, d0, pm, Ax)
        else:  # central differences
            for j in range(nx):
                hj = 1e-6 * max(1.0, abs(zh[j]))
                for i in range(nx):
                    xp[i] = zh[i]
                xp[j] = zh[j] + hj
                model_fn(xp[:nx], u, d0, pm, k1[:nx])
                xp[j] = zh[j] - hj
                model_fn(xp[:nx], u, d0, pm, k2[:nx])
                for i in range(nx):
                    Ax[i * nx + j] = (k1[i] - k2[i]) / (2.0 * hj)
        for i in range(n):
            for j in range(n):
                A[i * n + j] = Ax[i * nx + j] if (i < nx and j < nx) else 0.0
        for a in range(n - nx):     # [[A, Dᵀ], [0, −diag λ]]
            tgt = int(pn[a0 + 2 * a])
            if tgt >= 0:
                A[tgt * n + nx + a] = 1.0
            A[(nx + a) * n + nx + a] = -pn[a0 + 2 * a + 1]
        for i in range(nne):
            At[i] = A[i] * Ts
        for i in range(n):   # At², At/6 + At²/24
            for j in range(n):
                acc = 0.0
                for m in range(n):
                    acc += At[i * n + m] * At[m * n + j]
                B2[i * n + j] = acc
                C[i * n + j] = At[i * n + j] / 6 + acc / 24
        for i in range(n):   # E = F − I = At + At²/2 + At² (At/6 + At²/24)
            for j in range(n):
                acc = 0.0
                for m in range(n):
                    acc += B2[i * n + m] * C[m * n + j]
                E[i * n + j] = At[i * n + j] + B2[i * n + j] / 2 + acc
        if held:  # Γ (Q_c/Ts) Γᵀ, Γ = Ts (I + At/2 + At²/6)
            for i in range(n):
                for j in range(n):
                    C[i * n + j] = Ts * ((1.0 if i == j else 0.0) + At[i * n + j] / 2
                                         + B2[i * n + j] / 6)
            for i in range(n):
                for j in range(i, n):
                    acc = 0.0
                    for m in range(n):
                        acc += C[i * n + m] * q[m] * C[j * n + m]
                    Qd[i * n + j] = acc / Ts
        else:  # Q_c Ts + (A Q_c + Q_c Aᵀ) Ts²/2 + A Q_c Aᵀ Ts³/3
            Ts2 = Ts**2
            Ts3 = Ts**3
            for i in range(n):
                for j in range(i, n):
                    acc = 0.0
                    for m in range(n):
                        acc += A[i * n + m] * q[m] * A[j * n + m]
                    x_ = ((A[i * n + j] * q[j] + A[j * n + i] * q[i]) * Ts2) / 2
                    qc = q[i] if i == j else 0.0
                    Qd[i * n + j] = qc * Ts + x_ + (acc * Ts3) / 3
        # x̂⁻ = Φ(x̂, u): RK4, substeps per Ts
        h = Ts / substeps
        for _ in range(substeps):
            ekf_faug(zh, u, d0, pm, pn, a0, k1)
            for i in range(n):
                xp[i] = zh[i] + 0.5 * h * k1[i]
            ekf_faug(xp, u, d0, pm, pn, a0, k2)
            for i in range(n):
                xp[i] = zh[i] + 0.5 * h * k2[i]
            ekf_faug(xp, u, d0, pm, pn, a0, k3)
            for i in range(n):
                xp[i] = zh[i] + h * k3[i]
            ekf_faug(xp, u, d0, pm, pn, a0, k4)
            for i in range(n):
                zh[i] = zh[i] + (h / 6.0) * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i])
        # P⁻ = F P Fᵀ + Q_d: T = P + E P, then the upper triangle of T + T Eᵀ + Q_d, mirrored
        for i in range(nne):
            Pl[i] = P[i]
        for i in range(n):
            for j in range(n):
                acc = Pl[i * n + j]
                for m in range(n):
                    acc += E[i * n + m] * Pl[m * n + j]
                B2[i * n + j] = acc
        for i in range(n):
            for j in range(i, n):
                acc = B2[i * n + j]
                for m in range(n):
                    acc += B2[i * n + m] * E[j * n + m]
                Qd[i * n + j] = acc + Qd[i * n + j]
                P[i * n + j] = Qd[i * n + j]
                P[j * n + i] = Qd[i * n + j]
        for sl in range(nslt):      # Larsen's M*: g ← F g = g + E g
            g0 = sb + sl * ssz + 4
            if zn[sb + sl * ssz] != 0.0:
                for i in range(n):
                    acc = zn[g0 + i]
                    for m in range(n):
                        acc += E[i * n + m] * zn[g0 + m]
                    xp[i] = acc
                for i in range(n):
                    zn[g0 + i] = xp[i]
    for r in range(nrows):
        o = e + 6 + ROW * r
        if pn[o + 6] == 0.0 and zn[int(pn[o + 2])] != 0.0:  # no latency, fresh
            v = ekf_correct(zh, P, int(pn[o]), int(pn[o + 5]), zn[int(pn[o + 1])], pn[o + 3],
                            pn[o + 4] != 0.0, zn, sb, nslt)
            if v >= 0.0:
                nis += v
                nisd += 1.0
    if nslt > 0:
        nis, nisd = ekf_delayed(zh, P, zn, pn, e, nrows, sb, nslt, int(zn[kc]), nis, nisd)
    zn[ez + n + nne] = nis
    zn[ez + n + nne + 1] = nisd


def ekf_delayed(zh, P, zn, pn, e, nrows, sb, nslt, k, nis, nisd):
    """:meth:`ExtendedKalmanFilter._delayed` for one ship (Larsen et al. 1998): apply the delayed
    samples delivered now, then record the ones the delayed rows take now, in slots
    ``[active, taken at, h, S, g, Cov(ν, ν_other) per slot]``; returns the updated NIS and its
    dimension."""
    n = ne
    ssz = 4 + n + nslt
    for r in range(nrows):
        o = e + 6 + ROW * r
        lat = int(pn[o + 6])
        if lat == 0:
            continue
        for sl in range(int(pn[o + 8]), int(pn[o + 8]) + int(pn[o + 9])):
            b = sb + sl * ssz
            if zn[b] == 0.0 or zn[b + 1] > k - lat:
                continue
            zn[b] = 0.0
            if zn[b + 1] != k - lat or zn[int(pn[o + 2])] == 0.0 or not zn[b + 3] > 0.0:
                continue
            S = zn[b + 3]
            innov = zn[int(pn[o + 1])] - zn[b + 2]
            if pn[o + 4] != 0.0:
                innov = wrap(innov)
            nis += innov * innov / S
            nisd += 1.0
            g = zn[b + 4:b + 4 + n]
            for a in range(n):
                zh[a] = zh[a] + g[a] * (innov / S)
            for a in range(n):
                for c in range(a, n):
                    P[a * n + c] = P[a * n + c] - g[a] * g[c] / S
                    P[c * n + a] = P[a * n + c]
            for ot in range(nslt):
                bo = sb + ot * ssz
                if ot != sl and zn[bo] != 0.0:
                    rho = zn[bo + 4 + n + sl]
                    for a in range(n):
                        zn[bo + 4 + a] = zn[bo + 4 + a] - g[a] * (rho / S)
    for r in range(nrows):
        o = e + 6 + ROW * r
        lat = int(pn[o + 6])
        if lat == 0 or k % int(pn[o + 7]) != 0:
            continue
        j = int(pn[o])
        jb = int(pn[o + 5])
        for sl in range(int(pn[o + 8]), int(pn[o + 8]) + int(pn[o + 9])):
            b = sb + sl * ssz
            if zn[b] != 0.0:
                continue
            zn[b] = 1.0
            zn[b + 1] = float(k)
            zn[b + 2] = zh[j] + zh[jb] if jb >= 0 else zh[j]
            for a in range(n):
                zn[b + 4 + a] = P[a * n + j] + P[a * n + jb] if jb >= 0 else P[a * n + j]
            zn[b + 3] = (zn[b + 4 + j] + zn[b + 4 + jb] if jb >= 0 else zn[b + 4 + j]) + pn[o + 3]
            for ot in range(nslt):   # Cov(ν_new, ν_other) = c g_other
                bo = sb + ot * ssz
                if ot != sl and zn[bo] != 0.0:
                    rho = zn[bo + 4 + j] + zn[bo + 4 + jb] if jb >= 0 else zn[bo + 4 + j]
                    zn[b + 4 + n + ot] = rho
                    zn[bo + 4 + n + sl] = rho
            break
    return nis, nisd


def ekf_correct(zh, P, j, jb, y, var, angle, zn, sb, nslt):
    """:meth:`GaussianFilter.correct_row` for one ship and a row c = e_j (a measured state), or
    c = e_j + e_jb (a measured state and the sensor's bias state jb ≥ 0), at the filter's size
    ``ne`` (loops of known length): x̂ += Pc/S·innov, P −= Pc Pcᵀ/S with Pc = P cᵀ,
    S = c P cᵀ + var (Simon 2006 §5.1), on the upper triangle of P, mirrored (the symmetrised
    update up to round-off); the pending delayed samples' g ← g − K c g (slots at ``sb``).
    Returns innov²/S (the row's NIS), −1 when S ≤ 0 (no update)."""
    n = ne
    Pc = stack_empty(ne)
    for a in range(n):
        Pc[a] = P[a * n + j] + P[a * n + jb] if jb >= 0 else P[a * n + j]
    S = (Pc[j] + Pc[jb] if jb >= 0 else Pc[j]) + var
    if not S > 0.0:
        return -1.0
    innov = y - (zh[j] + zh[jb] if jb >= 0 else zh[j])
    if angle:
        innov = wrap(innov)
    ssz = 4 + n + nslt
    for sl in range(nslt):
        g0 = sb + sl * ssz + 4
        if zn[sb + sl * ssz] != 0.0:
            cg = zn[g0 + j] + zn[g0 + jb] if jb >= 0 else zn[g0 + j]
            for a in range(n):
                zn[g0 + a] = zn[g0 + a] - Pc[a] / S * cg
    for a in range(n):
        zh[a] = zh[a] + Pc[a] / S * innov
    for a in range(n):
        Ka = Pc[a] / S
        for b in range(a, n):
            P[a * n + b] = P[a * n + b] - Ka * Pc[b]
            P[b * n + a] = P[a * n + b]
    return innov * innov / S


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
    nsg[so + 2 * n + 1] = zn[ez + n + n * n]
    nsg[so + 2 * n + 2] = zn[ez + n + n * n + 1]


_OPTIONS = {**JIT_OPTIONS, "cache": CACHE}
observer_step = numba.njit(**_OPTIONS)(observer_step)
ekf_correct = numba.njit(**_OPTIONS)(ekf_correct)
ekf_faug = numba.njit(**_OPTIONS)(ekf_faug)
ekf_delayed = numba.njit(**_OPTIONS)(ekf_delayed)
ekf_step = numba.njit(**_OPTIONS)(ekf_step)
gaussian_outputs = numba.njit(**_OPTIONS)(gaussian_outputs)
no_estimator = numba.njit(**_OPTIONS)(no_estimator)
observer_slot = numba.njit(**_OPTIONS)(observer_slot)
ekf_slot = numba.njit(**_OPTIONS)(ekf_slot)
kf_slot = numba.njit(**_OPTIONS)(kf_slot)
nav_observe = numba.njit(**_OPTIONS)(nav_observe)
