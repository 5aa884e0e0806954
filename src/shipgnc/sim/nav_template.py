"""The navigation step of the composed loop, as source: :mod:`shipgnc.sim.compose` writes it into
the generated module of a combination before the loop body (:mod:`shipgnc.sim.loop_template`), so
the estimators call the vessel model's kernel ``model_fn`` by name (a numba function passed as an
argument would make the loop uncacheable). Free names: ``model_fn``, ``nx``, ``nu``, ``nd``,
``est_slot`` (the estimator's step, one of the slots below, bound after them), ``ne`` (the EKF's
state dimension: ``nx`` plus its augmented states), ``CACHE``; ``jac_fn`` (the model's analytic
state Jacobian, :func:`shipgnc.navigation.kernels.jacobian_kernel`) is found from ``model_fn``.

This is :meth:`shipgnc.navigation.Navigation.observe` for one ship at one control sample: the
sensors' and the estimators' arithmetic is the kernels of :mod:`shipgnc.navigation.kernels` (the
numpy classes call the same kernels), and here is only what calls the model: the observer's RK4
over its right-hand side, the EKF's Jacobian and its RK4 prediction of the mean. Every block is
read through the named offsets of the kernels' layouts.
"""
# ruff: noqa: F821

import math

import numba

from shipgnc.kernels import JIT_OPTIONS
from shipgnc.navigation.kernels import (
    E_ROWS,
    E_SUBSTEPS,
    E_TS,
    EKF_ROW_SIZE,
    ER_FRESH,
    ER_HELD,
    ESTIMATOR_AT,
    ESTIMATOR_SIGNALS_AT,
    ESTIMATOR_STATE_AT,
    ETA,
    FIRST,
    KF_ROW_SIZE,
    KF_ROWS,
    KR_FRESH,
    KR_HELD,
    MAP_AT,
    NU,
    OB_ETA,
    OB_HELD,
    OB_MODEL,
    OB_NU,
    OB_SUBSTEPS,
    OB_TS,
    OB_VALID,
    OBS_S,
    OBSERVER_STATE_SIZE,
    TAU,
    ekf_rates,
    ekf_rows_at,
    ekf_update,
    ekf_work_size,
    gaussian_outputs,
    jacobian_kernel,
    kf_rows_at,
    kf_step,
    no_jacobian,
    observer_force,
    observer_outputs,
    observer_rhs,
    output_work_size,
    read_channels,
    sensors_observe,
    stack_empty,
)

#: the model's analytic state Jacobian kernel (``<model kernel>_jacobian`` beside it), if any:
#: the EKF's A then costs one call instead of 2n model calls
jac_fn = jacobian_kernel(model_fn)
has_jac = jac_fn is not None
if jac_fn is None:
    jac_fn = no_jacobian
#: scratch numbers per ship the loop hands to the navigation step (the slots' ``wk``; the
#: built-in slots keep their arrays on the stack)
nav_work = 1
#: the stack arrays' sizes (constants of this module)
ekf_work = ekf_work_size(ne)
output_work = output_work_size(nx)
nxx = nx * nx


def nav_observe(t, x, u, zn, pn, w, seen, nsg, pm, wk):
    """The state the guidance and the controller see (``seen``) and the logged navigation signals
    (``nsg``) at control sample ``t`` from the true state ``x`` and the input ``u`` applied over
    the last sample; ``zn`` the ship's navigation state, ``w`` its table row of this sample."""
    sensors_observe(t, x, zn, pn, w, seen, nsg)
    est_slot(x, u, zn, pn, pm, wk, seen, nsg)
    zn[FIRST] = 0.0


# the estimators' slots: ``(x, u, zn, pn, pm, wk, seen, nsg)``, an estimator's update and its
# outputs (its kernel_block names its slot; the generated module binds it to ``est_slot``)
def no_estimator(x, u, zn, pn, pm, wk, seen, nsg):
    pass


def observer_slot(x, u, zn, pn, pm, wk, seen, nsg):
    e = int(pn[ESTIMATOR_AT])
    ez = int(pn[ESTIMATOR_STATE_AT])
    observer_step(u, zn, pn[e:], zn[ez:], pm, zn[FIRST] != 0.0)
    observer_outputs(zn[ez:], pn[e:], seen, nsg[int(pn[ESTIMATOR_SIGNALS_AT]):])


def ekf_slot(x, u, zn, pn, pm, wk, seen, nsg):
    e = int(pn[ESTIMATOR_AT])
    ez = int(pn[ESTIMATOR_STATE_AT])
    ekf_step(u, zn, pn[e:], zn[ez:], pm, zn[FIRST])
    filter_outputs(x, zn[ez:], pn, seen, nsg)


def kf_slot(x, u, zn, pn, pm, wk, seen, nsg):
    p = pn[int(pn[ESTIMATOR_AT]):]
    y = stack_empty(nx)             # a row per measured state: at most nx
    fresh = stack_empty(nx)
    nrows = int(p[KF_ROWS])
    read_channels(zn, p, kf_rows_at(p), nrows, KF_ROW_SIZE, KR_HELD, KR_FRESH, y, fresh)
    kf_step(zn[FIRST], u, y, fresh, zn[int(pn[ESTIMATOR_STATE_AT]):], p)
    filter_outputs(x, zn[int(pn[ESTIMATOR_STATE_AT]):], pn, seen, nsg)


def filter_outputs(x, z, pn, seen, nsg):
    """A Gaussian filter's estimates and logged signals (its map at ``map_at``)."""
    work = stack_empty(output_work)
    gaussian_outputs(x, z, pn[int(pn[MAP_AT]):], seen, nsg[int(pn[ESTIMATOR_SIGNALS_AT]):], work)


def observer_step(u, zn, p, z, pm, first):
    """:meth:`PassiveObserver.update` for one ship: RK4 over the control period, ``substeps``
    steps, y, u and ψ_y held, of :func:`~shipgnc.navigation.kernels.observer_rhs` (``p`` its
    block, ``z`` its state)."""
    y = stack_empty(3)
    val = stack_empty(3)
    for q in range(3):
        ok = zn[int(p[OB_VALID + q])] != 0.0
        val[q] = 1.0 if ok else 0.0
        y[q] = zn[int(p[OB_HELD + q])] if ok else 0.0
    psi_y = y[2] if val[2] != 0.0 else z[ETA + 2]
    if first:  # the first sample starts the observer (at the true initial state)
        return
    rot = stack_empty(2)
    rot[0] = math.cos(psi_y)
    rot[1] = math.sin(psi_y)
    fnu = stack_empty(3)
    s = stack_empty(OBS_S)
    ss = stack_empty(OBS_S)
    kq = stack_empty(OBS_S)
    acc = stack_empty(OBS_S)
    fx = stack_empty(nx)
    f0 = stack_empty(nx)
    d0 = stack_empty(nd)
    u0 = stack_empty(nu)
    model = p[OB_MODEL] != 0.0
    substeps = int(p[OB_SUBSTEPS])
    xt = stack_empty(nx)             # the model's other states: the initial truth
    for j in range(nx):
        xt[j] = z[OBSERVER_STATE_SIZE + j]
    for j in range(nd):
        d0[j] = 0.0
    tau = z[TAU:TAU + 3]
    if not model:  # τ = M [ν̇(x̂, u) − ν̇(x̂, 0)], held over the sample
        for j in range(nu):
            u0[j] = 0.0
        for q in range(3):
            xt[int(p[OB_ETA + q])] = z[ETA + q]
            xt[int(p[OB_NU + q])] = z[NU + q]
        model_fn(xt, u, d0, pm, fx)
        model_fn(xt, u0, d0, pm, f0)
        observer_force(fx, f0, p, tau)
    for j in range(OBS_S):
        s[j] = z[j]
    h = p[OB_TS] / substeps
    for _ in range(substeps):
        for stage in range(4):
            if stage == 0:
                for j in range(OBS_S):
                    ss[j] = s[j]
            else:
                c = h if stage == 3 else h / 2
                for j in range(OBS_S):
                    ss[j] = s[j] + c * kq[j]
            if model:
                for q in range(3):
                    xt[int(p[OB_ETA + q])] = ss[ETA + q]
                    xt[int(p[OB_NU + q])] = ss[NU + q]
                model_fn(xt, u, d0, pm, fx)
                for q in range(3):
                    fnu[q] = fx[int(p[OB_NU + q])]
            observer_rhs(ss, y, val, rot, fnu, tau, p, kq)
            if stage == 0:
                for j in range(OBS_S):
                    acc[j] = kq[j]
            elif stage < 3:
                for j in range(OBS_S):
                    acc[j] = acc[j] + 2 * kq[j]
            else:
                for j in range(OBS_S):
                    acc[j] = acc[j] + kq[j]
        for j in range(OBS_S):
            s[j] = s[j] + (h / 6) * acc[j]
    for j in range(OBS_S):
        z[j] = s[j]


def ekf_faug(zh, u, d0, pm, p, out):
    """The EKF's augmented derivative: the model's ẋ (its kernel), then
    :func:`~shipgnc.navigation.kernels.ekf_rates`."""
    model_fn(zh[:nx], u, d0, pm, out[:nx])
    ekf_rates(zh, out, p, out)


def ekf_step(u, zn, p, z, pm, first):
    """:meth:`ExtendedKalmanFilter.update` for one ship: unless first, the model's Jacobian
    (``jac_fn`` when it has one, else central differences, step 1e-6·max(1, |x_j|)) and the mean
    propagated by RK4 (``substeps`` per Ts), then
    :func:`~shipgnc.navigation.kernels.ekf_update` with the rows' measurements. Arrays on the
    stack of known length (n = ``ne``)."""
    zh = z[0:ne]
    Ax = stack_empty(nxx)
    xn = stack_empty(ne)
    work = stack_empty(ekf_work)
    nrows = int(p[E_ROWS])
    y = stack_empty(nx)             # a row per measured state: at most nx
    fresh = stack_empty(nx)
    read_channels(zn, p, ekf_rows_at(), nrows, EKF_ROW_SIZE, ER_HELD, ER_FRESH, y, fresh)
    if first == 0.0:
        d0 = stack_empty(nd)
        for j in range(nd):
            d0[j] = 0.0
        xp = stack_empty(ne)
        k1 = stack_empty(ne)
        k2 = stack_empty(ne)
        k3 = stack_empty(ne)
        k4 = stack_empty(ne)
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
        # x̂⁻ = Φ(x̂, u): RK4, substeps per Ts
        for i in range(ne):
            xn[i] = zh[i]
        h = p[E_TS] / int(p[E_SUBSTEPS])
        for _ in range(int(p[E_SUBSTEPS])):
            ekf_faug(xn, u, d0, pm, p, k1)
            for i in range(ne):
                xp[i] = xn[i] + 0.5 * h * k1[i]
            ekf_faug(xp, u, d0, pm, p, k2)
            for i in range(ne):
                xp[i] = xn[i] + 0.5 * h * k2[i]
            ekf_faug(xp, u, d0, pm, p, k3)
            for i in range(ne):
                xp[i] = xn[i] + h * k3[i]
            ekf_faug(xp, u, d0, pm, p, k4)
            for i in range(ne):
                xn[i] = xn[i] + (h / 6.0) * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i])
    ekf_update(first, Ax, xn, y, fresh, z, p, work)


_OPTIONS = {**JIT_OPTIONS, "cache": CACHE}
observer_step = numba.njit(**_OPTIONS)(observer_step)
ekf_faug = numba.njit(**_OPTIONS)(ekf_faug)
ekf_step = numba.njit(**_OPTIONS)(ekf_step)
filter_outputs = numba.njit(**_OPTIONS)(filter_outputs)
no_estimator = numba.njit(**_OPTIONS)(no_estimator)
observer_slot = numba.njit(**_OPTIONS)(observer_slot)
ekf_slot = numba.njit(**_OPTIONS)(ekf_slot)
kf_slot = numba.njit(**_OPTIONS)(kf_slot)
nav_observe = numba.njit(**_OPTIONS)(nav_observe)
