"""Navigation in the composed compiled loop: the per-ship arithmetic of the sensors and the
estimators as numba kernels (:mod:`shipgnc.kernels`), following the numpy forms of
:mod:`shipgnc.navigation` operation for operation.

:meth:`shipgnc.navigation.Navigation.kernel` packs a navigation system into one flat parameter
array ``p``, one per-ship state row ``z`` and a random table (the sensors' draws, taken from the
same child streams and in the same order as the numpy sensors take them, so a seed gives the same
measurements in both loops). The composed loop (:mod:`shipgnc.sim.compose`) calls, at each control
sample, the navigation step of :mod:`shipgnc.sim.nav_template`: :func:`sensors_observe` (sampling,
hold, latency, dropouts, the state the controller sees, the logged ``<state>_meas`` and
``<sensor>_valid``), then the estimator's update, whose model evaluations are made there (the
vessel model's kernel is a name of the generated loop module: a numba function passed as an
argument would make the loop uncacheable), and whose arithmetic is here: :func:`observer_rhs`
(Fossen & Strand 1999), :func:`correct_c` and :func:`nees` (the Kalman filters, Simon 2006 §5.1,
§13.2; the EKF's scalar correction, at the model's size, is the template's ``ekf_correct``).

Layouts (offsets are stored as floats in ``p``; ``int()`` in the kernels):

``p``: ``[n_sensors, n_channels, o_channels, o_estimator, sig_estimator, z_estimator, o_map,
sensor offsets ...]`` (``o_map``: a Kalman filter's map of its states to the model's, see
:func:`gaussian_outputs`); a sensor block: ``[0 (reserved), k, every, latency, n_dropouts,
noise_std, bias_std, a, b_scale, z_offset, w_offset, sig_offset, state index × k, (t0, t1) ×
n_dropouts]``. No sensor kind is compiled in: every sensor the kernel computes has the error
model y = x + b + σ w with the bias b_{j+1} = a b_j + b_scale w_j at its samples (from the
second on), started at its own value (``Sensor.kernel_errors``): the GNSS's Gauss–Markov bias
(``a`` = e^{−h/T_b}, ``b_scale`` = σ_b √(1 − a²)), the gyro's random walk (a = 1, σ_rw √h), the
compass's constant bias (b_scale = 0), the log's none (b = 0); a channel (one measured state):
``[state index, z offset of the held value, of the valid flag, of the fresh flag, variance]``.

``z``: ``[first, sensor blocks ..., estimator]`` (a Kalman filter's: ``[ẑ, P, NIS, NIS
dimension]``); a sensor block: ``[held × k, valid, fresh, j,
first, bias × k, pipe]`` with the pipe a ring of ``latency + 1`` entries ``[due, lost, value × k]``.

``w`` (the table row of one control sample): per sensor ``[bias draws × k, noise draws × k]``
(zeros where the sensor is not due or has no such error).
"""

from __future__ import annotations

import numpy as np
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

from shipgnc.kernels import kernel_function, wrap

#: header length of ``p`` before the sensor offsets
HEADER = 7
#: fields of a sensor's parameter block before its state indices
SENSOR_FIELDS = 12
#: fields of a channel
CHANNEL_FIELDS = 5


@intrinsic
def stack_empty(typingctx, size):
    """``stack_empty(N)``: an uninitialised float64 array of ``N`` numbers (a constant when
    compiled, e.g. a size of the generated loop module) on the stack of the compiled function
    that calls it: no allocation, and memory the compiler knows no argument aliases, so it keeps
    the entries of small matrices in registers. Valid while that function runs: never return it
    or store it beyond the call."""
    if not isinstance(size, types.IntegerLiteral):
        return None
    count = max(int(size.literal_value), 1)
    array = types.Array(types.float64, 1, "C")

    def codegen(context, builder, signature, args):
        out = context.make_array(array)(context, builder)
        data = cgutils.alloca_once(builder, context.get_data_type(types.float64), size=count)
        intp = context.get_value_type(types.intp)
        context.populate_array(out, data=data,
                               shape=cgutils.pack_array(builder, [intp(size.literal_value)]),
                               strides=cgutils.pack_array(builder, [intp(8)]),
                               itemsize=intp(8), meminfo=None)
        return out._getvalue()

    return array(size), codegen


@kernel_function
def sensors_observe(t, x, z, p, w, seen, sig):
    """Every sensor's sample at control sample time ``t`` (:meth:`Sensor.sample` for one ship),
    then the state the controller sees before the estimator (:meth:`Navigation.observe`: a
    measured state replaced by its held value while valid) and the sensors' logged signals."""
    for j in range(x.shape[0]):
        seen[j] = x[j]
    ns = int(p[0])
    for s in range(ns):
        o = int(p[HEADER + s])
        k = int(p[o + 1])
        every = int(p[o + 2])
        lat = int(p[o + 3])
        ndrop = int(p[o + 4])
        noise = p[o + 5]
        a = p[o + 7]
        bscale = p[o + 8]
        zo = int(p[o + 9])
        wo = int(p[o + 10])
        so = int(p[o + 11])
        idx = o + SENSOR_FIELDS
        jj = int(z[zo + k + 2])
        zb = zo + k + 4              # bias
        zp = zb + k                  # pipe: lat + 1 entries of 2 + k
        slot = zp + (jj % (lat + 1)) * (2 + k)
        due = jj % every == 0
        if due:  # the error states advance through a dropout too
            if bscale > 0.0:  # the bias b ← a b + b_scale w, from the second sample on
                if z[zo + k + 3] == 0.0:
                    for c in range(k):
                        if a == 1.0:  # a random walk (no product a·b for the compiler to fuse)
                            z[zb + c] = z[zb + c] + bscale * w[wo + c]
                        else:
                            z[zb + c] = a * z[zb + c] + bscale * w[wo + c]
                z[zo + k + 3] = 0.0
            for c in range(k):
                xv = x[int(p[idx + c])]
                nz = noise * w[wo + k + c] if noise > 0.0 else 0.0
                z[slot + 2 + c] = xv + z[zb + c] + nz
            lost = False
            for q in range(ndrop):
                t0 = p[idx + k + 2 * q]
                t1 = p[idx + k + 2 * q + 1]
                if t0 <= t <= t1:
                    lost = True
            z[slot] = 1.0
            z[slot + 1] = 1.0 if lost else 0.0
        else:
            z[slot] = 0.0
            z[slot + 1] = 0.0
        z[zo + k + 2] = jj + 1.0
        z[zo + k + 1] = 0.0          # fresh
        if jj >= lat:                # deliver the entry taken lat samples ago
            old = zp + ((jj - lat) % (lat + 1)) * (2 + k)
            if z[old] != 0.0:
                if z[old + 1] != 0.0:
                    z[zo + k] = 0.0
                else:
                    for c in range(k):
                        z[zo + c] = z[old + 2 + c]
                    z[zo + k] = 1.0
                    z[zo + k + 1] = 1.0
        valid = z[zo + k] != 0.0
        for c in range(k):
            if valid:
                seen[int(p[idx + c])] = z[zo + c]
                sig[so + c] = z[zo + c]
            else:
                sig[so + c] = np.nan
        sig[so + k] = 1.0 if valid else 0.0


# ----------------------------------------------------------------------------------------------
# the passive observer (passive_observer.PassiveObserver)
# ----------------------------------------------------------------------------------------------

#: observer parameter block: [velocity model (1: the vessel's), substeps, Ts, ieta × 3, inu × 3,
#: held-value offsets × 3, valid offsets × 3] then 3-vectors −ω₀², 2ζω₀, K1a, K1b, K2, T_b and
#: 3 × 3 matrices (row-major) K3, K4, D, M⁻¹, M
OBS_VEC = 15
#: observer state: [xi1 × 3, xi2 × 3, eta × 3, b × 3, nu × 3, tau × 3, the true initial state]
OBS_STATE = 18


@kernel_function
def observer_rhs(s, y, val, cpsi, spsi, fnu, tau, p, e, ds):
    """:meth:`PassiveObserver._rhs` for one ship: ``s`` = [ξ₁, ξ₂, η̂, b̂, ν̂] (15), ``fnu`` the
    vessel model's ν̇ at the stage state (``velocity_model="model"``), ``tau`` the held τ
    (``"linear"``); writes ``ds``."""
    v = e + OBS_VEC
    yt0 = y[0] - s[6] - s[3]
    yt1 = y[1] - s[7] - s[4]
    yt2 = wrap(y[2] - s[8] - s[5])
    yt0 = yt0 if val[0] != 0.0 else 0.0
    yt1 = yt1 if val[1] != 0.0 else 0.0
    yt2 = yt2 if val[2] != 0.0 else 0.0
    for q in range(3):
        ytq = yt0 if q == 0 else (yt1 if q == 1 else yt2)
        ds[q] = s[3 + q] + p[v + 6 + q] * ytq
        ds[3 + q] = p[v + q] * s[q] - p[v + 3 + q] * s[3 + q] + p[v + 9 + q] * ytq
    un, vn, rn = s[12], s[13], s[14]
    ds[6] = cpsi * un - spsi * vn + p[v + 12] * yt0
    ds[7] = spsi * un + cpsi * vn + p[v + 13] * yt1
    ds[8] = rn + p[v + 14] * yt2
    m = v + 18
    K3, K4, D, Minv = m, m + 9, m + 18, m + 27
    inj = np.empty(3)
    for q in range(3):
        ds[9 + q] = -s[9 + q] / p[v + 15 + q] + (yt0 * p[K3 + 3 * q] + yt1 * p[K3 + 3 * q + 1]
                                                  + yt2 * p[K3 + 3 * q + 2])
        inj[q] = s[9 + q] + (yt0 * p[K4 + 3 * q] + yt1 * p[K4 + 3 * q + 1]
                             + yt2 * p[K4 + 3 * q + 2])
    b0 = cpsi * inj[0] + spsi * inj[1]
    b1 = -spsi * inj[0] + cpsi * inj[1]
    b2 = inj[2]
    if p[e] != 0.0:  # the vessel's own ν̇ + M⁻¹ body
        for q in range(3):
            ds[12 + q] = fnu[q] + (b0 * p[Minv + 3 * q] + b1 * p[Minv + 3 * q + 1]
                                   + b2 * p[Minv + 3 * q + 2])
    else:  # (τ − D ν̂ + body) M⁻ᵀ
        f0 = tau[0] - (un * p[D] + vn * p[D + 1] + rn * p[D + 2]) + b0
        f1 = tau[1] - (un * p[D + 3] + vn * p[D + 4] + rn * p[D + 5]) + b1
        f2 = tau[2] - (un * p[D + 6] + vn * p[D + 7] + rn * p[D + 8]) + b2
        for q in range(3):
            ds[12 + q] = f0 * p[Minv + 3 * q] + f1 * p[Minv + 3 * q + 1] + f2 * p[Minv + 3 * q + 2]


@kernel_function
def observer_outputs(z, p, seen, sig):
    """The observer's estimates into ``seen`` (η̂, ν̂) and its logged signals: ``<s>_hat`` (η, ν),
    ``<s>_w_hat`` (ξ₂), ``b_<s>_hat``."""
    e = int(p[3])
    ez = int(p[5])
    so = int(p[4])
    for q in range(3):
        seen[int(p[e + 3 + q])] = z[ez + 6 + q]
        seen[int(p[e + 6 + q])] = z[ez + 12 + q]
        sig[so + q] = z[ez + 6 + q]
        sig[so + 3 + q] = z[ez + 12 + q]
        sig[so + 6 + q] = z[ez + 3 + q]
        sig[so + 9 + q] = z[ez + 9 + q]


# ----------------------------------------------------------------------------------------------
# the Kalman filters (estimator.GaussianFilter, ekf.ExtendedKalmanFilter, kalman.KalmanFilter)
# ----------------------------------------------------------------------------------------------

#: the name of a model kernel's analytic state Jacobian: ``<kernel name>_jacobian`` beside it
JACOBIAN_SUFFIX = "_jacobian"


def jacobian_kernel(model_fn):
    """The analytic state Jacobian kernel of the vessel model kernel ``model_fn``, or None: the
    function ``<name>_jacobian(x, u, d, p, A)`` of the kernel's own module (A = ∂ẋ/∂x into the
    flat row-major ``A``, n × n, with the kernel's parameters ``p``; e.g.
    :func:`shipgnc.models.mariner.mariner_rhs_jacobian`). The composed loop's EKF calls it in
    place of the central differences (:mod:`shipgnc.sim.nav_template`)."""
    import importlib

    py = getattr(model_fn, "py_func", model_fn)
    try:
        module = importlib.import_module(py.__module__)
        fn = getattr(module, py.__qualname__ + JACOBIAN_SUFFIX, None)
    except (ImportError, AttributeError, TypeError):
        return None
    return fn if fn is not None and hasattr(fn, "py_func") else None


@kernel_function
def no_jacobian(x, u, d, p, A):
    """Stand-in for a model without an analytic Jacobian (never called: the EKF then takes
    central differences)."""
    pass


@kernel_function
def apply_gain(zh, P, Pc, S, innov):
    """The scalar Kalman update of :func:`correct_c`: with Pc = P cᵀ and S = c P cᵀ + var,
    x̂ += Pc/S·innov, P −= Pc Pcᵀ/S (then symmetrised), P row-major flat n × n."""
    n = zh.shape[0]
    for a in range(n):
        zh[a] = zh[a] + Pc[a] / S * innov
    for a in range(n):
        Ka = Pc[a] / S
        for b in range(n):
            P[a * n + b] = P[a * n + b] - Ka * Pc[b]
    for a in range(n):
        for b in range(a + 1, n):
            m = 0.5 * (P[a * n + b] + P[b * n + a])
            P[a * n + b] = m
            P[b * n + a] = m


@kernel_function
def correct_c(zh, P, c, y, var, angle, Pc):
    """:meth:`GaussianFilter.correct_row` for one ship and a general row ``c`` (the linear KF);
    returns the row's NIS innov²/S, −1 when S ≤ 0 (no update)."""
    n = zh.shape[0]
    S = var
    yc = 0.0
    for a in range(n):
        acc = 0.0
        for b in range(n):
            acc += P[a * n + b] * c[b]
        Pc[a] = acc
    for a in range(n):
        S += Pc[a] * c[a]
        yc += zh[a] * c[a]
    if not S > 0.0:
        return -1.0
    innov = y - yc
    if angle:
        innov = wrap(innov)
    apply_gain(zh, P, Pc, S, innov)
    return innov * innov / S


@kernel_function
def nees(err, P, n, idx, m, work):
    """(x − x̂)ᵀ P_sub⁻¹ (x − x̂) over the ``m`` filter states ``idx`` (:meth:`GaussianFilter.nees`;
    Gaussian elimination with partial pivoting, NaN for a singular block); ``work`` holds at
    least m² + 3m numbers."""
    A = work[:m * m].reshape((m, m))
    b = work[m * m:m * m + m]
    sol = work[m * m + m:m * m + 2 * m]
    for a in range(m):
        b[a] = err[a]
        for c in range(m):
            A[a, c] = P[int(idx[a]) * n + int(idx[c])]
    for col in range(m):
        piv = col
        best = abs(A[col, col])
        for r in range(col + 1, m):
            if abs(A[r, col]) > best:
                best = abs(A[r, col])
                piv = r
        if not best > 0.0:
            return np.nan
        if piv != col:
            for c in range(m):
                A[col, c], A[piv, c] = A[piv, c], A[col, c]
            b[col], b[piv] = b[piv], b[col]
        for r in range(col + 1, m):
            f = A[r, col] / A[col, col]
            for c in range(col, m):
                A[r, c] -= f * A[col, c]
            b[r] -= f * b[col]
    for r in range(m - 1, -1, -1):
        acc = b[r]
        for c in range(r + 1, m):
            acc -= A[r, c] * sol[c]
        sol[r] = acc / A[r, r]
    out = 0.0
    for a in range(m):
        out += err[a] * sol[a]
    return out


#: linear KF parameter block: [n, n_inputs, n_rows, A (n × n), B (n × n_inputs), input indices,
#: Q (n × n), rows (held offset, fresh offset, R, angle) × n_rows, C (n_rows × n)]


@kernel_function
def kf_step(u, z, p):
    """:meth:`KalmanFilter.update` for one ship: predict (unless first), then the rows delivered
    now."""
    e = int(p[3])
    ez = int(p[5])
    n = int(p[e])
    ni = int(p[e + 1])
    nrows = int(p[e + 2])
    oA = e + 3
    oB = oA + n * n
    oI = oB + n * ni
    oQ = oI + ni
    oR = oQ + n * n
    oC = oR + 4 * nrows
    zh = z[ez:ez + n].copy()
    P = z[ez + n:ez + n + n * n].copy()
    if z[0] == 0.0:
        zn = np.empty(n)
        for i in range(n):
            acc = 0.0
            for j in range(n):
                acc += zh[j] * p[oA + i * n + j]
            accu = 0.0
            for j in range(ni):
                accu += u[int(p[oI + j])] * p[oB + i * ni + j]
            zn[i] = acc + accu
        AP = np.empty((n, n))
        for i in range(n):
            for j in range(n):
                acc = 0.0
                for k in range(n):
                    acc += p[oA + i * n + k] * P[k * n + j]
                AP[i, j] = acc
        for i in range(n):
            for j in range(n):
                acc = 0.0
                for k in range(n):
                    acc += AP[i, k] * p[oA + j * n + k]
                P[i * n + j] = acc + p[oQ + i * n + j]
        for i in range(n):
            zh[i] = zn[i]
    Pc = np.empty(n)
    c = np.empty(n)
    nis = 0.0
    nisd = 0.0
    for r in range(nrows):
        o = oR + 4 * r
        if z[int(p[o + 1])] != 0.0:
            for j in range(n):
                c[j] = p[oC + r * n + j]
            v = correct_c(zh, P, c, z[int(p[o])], p[o + 2], p[o + 3] != 0.0, Pc)
            if v >= 0.0:
                nis += v
                nisd += 1.0
    for i in range(n):
        z[ez + i] = zh[i]
    for i in range(n * n):
        z[ez + n + i] = P[i]
    z[ez + n + n * n] = nis
    z[ez + n + n * n + 1] = nisd
