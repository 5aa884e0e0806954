"""The navigation step of the composed loop, as source: :mod:`shipgnc.sim.compose` writes it into
the generated module of a combination before the loop body (:mod:`shipgnc.sim.loop_template`), so
the estimators call the vessel model's kernel ``model_fn`` by name (a numba function passed as an
argument would make the loop uncacheable). Free names: ``model_fn``, ``nx``, ``nu``, ``nd``,
``est_kind``, ``CACHE``. The arithmetic is :mod:`shipgnc.navigation.kernels`; this is
:meth:`shipgnc.navigation.Navigation.observe` for one ship at one control sample.
"""
# ruff: noqa: F821

import math

import numba
import numpy as np

from shipgnc.kernels import JIT_OPTIONS, wrap
from shipgnc.navigation.kernels import (
    correct_row,
    kf_step,
    nees,
    observer_outputs,
    observer_rhs,
    sensors_observe,
)


def nav_observe(t, x, u, zn, pn, w, seen, nsg, pm):
    """The state the guidance and the controller see (``seen``) and the logged navigation signals
    (``nsg``) at control sample ``t`` from the true state ``x`` and the input ``u`` applied over
    the last sample; ``zn`` the ship's navigation state, ``w`` its table row of this sample."""
    sensors_observe(t, x, zn, pn, w, seen, nsg)
    if est_kind == 1:
        observer_step(u, zn, pn, pm)
        observer_outputs(zn, pn, seen, nsg)
    elif est_kind == 2:
        ekf_step(u, zn, pn, pm)
        gaussian_outputs(x, zn, pn, seen, nsg)
    elif est_kind == 3:
        kf_step(u, zn, pn)
        gaussian_outputs(x, zn, pn, seen, nsg)
    zn[0] = 0.0


def observer_step(u, zn, pn, pm):
    """:meth:`PassiveObserver.update`: RK4 over the control period, ``substeps`` steps, y, u and
    ψ_y held (layout: :mod:`shipgnc.navigation.kernels`)."""
    e = int(pn[3])
    ez = int(pn[5])
    y = np.empty(3)
    val = np.empty(3)
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
    xt = zn[ez + 18:ez + 18 + nx].copy()
    fx = np.empty(nx)
    fnu = np.empty(3)
    tau = zn[ez + 15:ez + 18].copy()
    d0 = np.zeros(nd)
    if not model:  # τ = M [ν̇(x̂, u) − ν̇(x̂, 0)], held over the sample
        f0 = np.empty(nx)
        u0 = np.zeros(nu)
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
        for q in range(3):
            zn[ez + 15 + q] = tau[q]
    s = zn[ez:ez + 15].copy()
    ss = np.empty(15)
    kq = np.empty(15)
    acc = np.empty(15)
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


def ekf_step(u, zn, pn, pm):
    """:meth:`ExtendedKalmanFilter.update`: predict (RK4 on the model, the central-difference
    Jacobian, F by the 4th-order series, Q_d) unless first, then one scalar correction per state
    whose sensor delivered now."""
    e = int(pn[3])
    ez = int(pn[5])
    n = nx
    zh = zn[ez:ez + n].copy()
    P = zn[ez + n:ez + n + n * n].copy()
    substeps = int(pn[e])
    Ts = pn[e + 1]
    held = pn[e + 2] != 0.0
    nrows = int(pn[e + 3])
    q0 = e + 4 + 5 * nrows          # Q_c diagonal
    d0 = np.zeros(nd)
    if zn[0] == 0.0:
        fp = np.empty(n)
        fm = np.empty(n)
        xp = np.empty(n)
        A = np.empty((n, n))
        for j in range(n):
            hj = 1e-6 * max(1.0, abs(zh[j]))
            for i in range(n):
                xp[i] = zh[i]
            xp[j] = zh[j] + hj
            model_fn(xp, u, d0, pm, fp)
            xp[j] = zh[j] - hj
            model_fn(xp, u, d0, pm, fm)
            for i in range(n):
                A[i, j] = (fp[i] - fm[i]) / (2.0 * hj)
        At = A * Ts
        F = np.eye(n) + At
        term = At
        for k in range(2, 5):
            term = (term @ At) / k
            F = F + term
        Qd = np.zeros((n, n))
        if held:
            G = Ts * (np.eye(n) + At / 2 + (At @ At) / 6)
            GQ = np.empty((n, n))
            for i in range(n):
                for j in range(n):
                    GQ[i, j] = G[i, j] * pn[q0 + j]
            Qd = (GQ @ G.T) / Ts
        else:
            AQ = np.empty((n, n))
            for i in range(n):
                for j in range(n):
                    AQ[i, j] = A[i, j] * pn[q0 + j]
            X = ((AQ + AQ.T) * Ts**2) / 2
            Y = ((AQ @ A.T) * Ts**3) / 3
            for i in range(n):
                for j in range(n):
                    qc = pn[q0 + i] if i == j else 0.0
                    Qd[i, j] = qc * Ts + X[i, j] + Y[i, j]
        # x̂⁻ = Φ(x̂, u): RK4, substeps per Ts
        h = Ts / substeps
        k1 = np.empty(n)
        k2 = np.empty(n)
        k3 = np.empty(n)
        k4 = np.empty(n)
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
        Pm = P.reshape((n, n))
        Pn = (F @ Pm) @ F.T + Qd
        for i in range(n):
            for j in range(n):
                P[i * n + j] = 0.5 * (Pn[i, j] + Pn[j, i])
    Pc = np.empty(n)
    for r in range(nrows):
        o = e + 4 + 5 * r
        if zn[int(pn[o + 2])] != 0.0:  # fresh
            correct_row(zh, P, int(pn[o]), zn[int(pn[o + 1])], pn[o + 3], pn[o + 4] != 0.0, Pc)
    for i in range(n):
        zn[ez + i] = zh[i]
    for i in range(n * n):
        zn[ez + n + i] = P[i]


def gaussian_outputs(x, zn, pn, seen, nsg):
    """A Gaussian filter's estimates of the model states into ``seen`` and its logged signals
    ``<s>_hat``, ``<s>_std`` (√ of P's diagonal) and ``nees`` (:meth:`GaussianFilter.nees`);
    its map at ``pn[6]``: ``[n, n_mapped, (filter index, model index, angle) × n_mapped]``."""
    ez = int(pn[5])
    so = int(pn[4])
    g = int(pn[6])                   # the filter's map block
    n = int(pn[g])
    m = int(pn[g + 1])
    err = np.empty(m)
    idx = np.empty(m)
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
    nsg[so + 2 * n] = nees(err, zn[ez + n:ez + n + n * n], n, idx, m) if m > 0 else np.nan


_OPTIONS = {**JIT_OPTIONS, "cache": CACHE}
observer_step = numba.njit(**_OPTIONS)(observer_step)
ekf_step = numba.njit(**_OPTIONS)(ekf_step)
gaussian_outputs = numba.njit(**_OPTIONS)(gaussian_outputs)
nav_observe = numba.njit(**_OPTIONS)(nav_observe)
