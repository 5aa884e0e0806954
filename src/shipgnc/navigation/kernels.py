"""The per-ship arithmetic of the sensors and the estimators, written once as scalar kernels
(:mod:`shipgnc.kernels`): the numpy classes of :mod:`shipgnc.navigation` call their batch over
ships (:func:`shipgnc.derive.per_ship`), and the composed loop's navigation step
(:mod:`shipgnc.sim.nav_template`) calls them for one ship at each control sample.

What stays outside the kernels is what calls the vessel model: the EKF's prediction of the mean
(RK4 on the model) and its Jacobian, and the passive observer's RK4 over its right-hand side.
The numpy classes evaluate the model through its batch (``model.derivatives``), the composed loop
through the model's kernel by name (a numba function passed as an argument would make the loop
uncacheable); both then call the same kernels here.

Every flat array is declared by name in a :class:`~shipgnc.navigation.layout.Layout` below; the
kernels read fields through the offsets the layouts compute (module constants, and ``<LAYOUT>_SIZE``
for a layout's fixed head: numba freezes module integers, not the layout objects).

:meth:`shipgnc.navigation.Navigation.kernel` packs a navigation system into one parameter array
(:data:`NAV` then one :data:`PLACE` per sensor, the sensors' blocks, the channels, the
estimator's block and a Gaussian filter's :data:`MAP`), one per-ship state row (:data:`NAV_STATE`,
the sensors' states, the estimator's) and a random table (the sensors' draws, taken from the same
child streams and in the same order as the numpy sensors take them, so a seed gives the same
measurements in both loops). Offsets stored in the arrays are floats (``int()`` in the kernels).
"""

from __future__ import annotations

import math

import numpy as np
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

from shipgnc.kernels import kernel_function, wrap
from shipgnc.navigation.layout import Layout


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


# ----------------------------------------------------------------------------------------------
# layouts
# ----------------------------------------------------------------------------------------------

#: the navigation system's parameter head (the field order is public: a third-party estimator's
#: slot reads ``estimator_at``, ``estimator_signals_at``, ``estimator_state_at``)
NAV = Layout("navigation", ("n_sensors", 1), ("n_channels", 1), ("channels_at", 1),
             ("estimator_at", 1), ("estimator_signals_at", 1), ("estimator_state_at", 1),
             ("map_at", 1), tail="one PLACE per sensor")
NAV_SIZE = NAV.size
(N_SENSORS, N_CHANNELS, CHANNELS_AT, ESTIMATOR_AT, ESTIMATOR_SIGNALS_AT, ESTIMATOR_STATE_AT,
 MAP_AT) = NAV.at("n_sensors", "n_channels", "channels_at", "estimator_at",
                  "estimator_signals_at", "estimator_state_at", "map_at")
#: where one sensor's blocks are: its parameters, its state, its draws, its logged signals
PLACE = Layout("sensor placement", ("params_at", 1), ("state_at", 1), ("draws_at", 1),
               ("signals_at", 1))
PLACE_SIZE = PLACE.size
PARAMS_AT, STATE_AT, DRAWS_AT, SIGNALS_AT = PLACE.at("params_at", "state_at", "draws_at",
                                                     "signals_at")
#: one measured state: its index in the model's state and where its sensor's state holds it
CHANNEL = Layout("channel", ("state", 1), ("held_at", 1), ("valid_at", 1), ("fresh_at", 1),
                 ("variance", 1))
#: the navigation system's per-ship state head, then the sensors' states and the estimator's
NAV_STATE = Layout("navigation state", ("first", 1), tail="the sensors' states, the estimator's")
FIRST, = NAV_STATE.at("first")

#: a sensor's parameters (:meth:`Sensor.kernel_params`)
SENSOR = Layout("sensor", ("k", 1), ("every", 1), ("latency", 1), ("n_dropouts", 1),
                ("noise_std", 1), ("a", 1), ("b_scale", 1),
                tail="state index × k, (t0, t1) × n_dropouts")
SENSOR_SIZE = SENSOR.size
S_K, S_EVERY, S_LATENCY, S_DROPOUTS, S_NOISE, S_A, S_B_SCALE = SENSOR.at(
    "k", "every", "latency", "n_dropouts", "noise_std", "a", "b_scale")
#: a sensor's state (:meth:`Sensor.kernel_state`)
SENSOR_STATE = Layout("sensor state", ("valid", 1), ("fresh", 1), ("count", 1), ("first", 1),
                      tail="held × k, bias × k, pipe: latency + 1 entries of PIPE then value × k")
SENSOR_STATE_SIZE = SENSOR_STATE.size
Z_VALID, Z_FRESH, Z_COUNT, Z_FIRST = SENSOR_STATE.at("valid", "fresh", "count", "first")
#: an entry of a sensor's latency pipe
PIPE = Layout("pipe entry", ("due", 1), ("lost", 1), tail="value × k")
PIPE_SIZE = PIPE.size
P_DUE, P_LOST = PIPE.at("due", "lost")


def sensor_state_size(k: int, latency: int) -> int:
    """Numbers of a sensor's state measuring ``k`` states with ``latency`` samples of delay."""
    return SENSOR_STATE_SIZE + 2 * k + (latency + 1) * (PIPE_SIZE + k)


# ----------------------------------------------------------------------------------------------
# the sensors (sensors.Sensor)
# ----------------------------------------------------------------------------------------------

@kernel_function
def sensor_sample(t, x, z, p, w, sig):
    """One control sample of one sensor (:meth:`shipgnc.navigation.sensors.Sensor.sample`):
    at a due sample (every ``every``-th) the measurement

        y = x + b + σ w_noise,      b ← a b + b_scale w_bias   (from the sensor's second sample on)

    is taken into the latency pipe (lost inside a dropout interval [t0, t1]; the bias advances
    through a dropout too); the entry taken ``latency`` samples ago is delivered (``fresh``,
    ``valid``) or, lost, clears ``valid``; the held value stays between deliveries. The bias is
    the GNSS receiver's Gauss–Markov process sampled exactly at its period h (a = e^{−h/T_b},
    b_scale = σ_b √(1 − a²); Farrell, *Aided Navigation*, 2008, §4.9), the gyro's random walk
    (a = 1, b_scale = σ_rw √h), the compass's constant (b_scale = 0), the log's none.

    ``x`` the true state, ``z`` the sensor's state (:data:`SENSOR_STATE`), ``p`` its parameters
    (:data:`SENSOR`), ``w`` its draws ``[bias × k, noise × k]`` (zeros when not due), ``sig`` its
    logged signals ``[<state>_meas × k (NaN while not valid), <sensor>_valid]``."""
    k = int(p[S_K])
    every = int(p[S_EVERY])
    lat = int(p[S_LATENCY])
    ndrop = int(p[S_DROPOUTS])
    noise = p[S_NOISE]
    a = p[S_A]
    bscale = p[S_B_SCALE]
    index = SENSOR_SIZE              # state indices, then the dropout intervals
    drops = index + k
    held = SENSOR_STATE_SIZE         # held values, then the bias, then the pipe
    bias = held + k
    pipe = bias + k
    entry = PIPE_SIZE + k
    jj = int(z[Z_COUNT])
    slot = pipe + (jj % (lat + 1)) * entry
    if jj % every == 0:  # due: the error states advance through a dropout too
        if bscale > 0.0:
            if z[Z_FIRST] == 0.0:
                for c in range(k):
                    if a == 1.0:  # a random walk (no product a·b for the compiler to fuse)
                        z[bias + c] = z[bias + c] + bscale * w[c]
                    else:
                        z[bias + c] = a * z[bias + c] + bscale * w[c]
            z[Z_FIRST] = 0.0
        for c in range(k):
            nz = noise * w[k + c] if noise > 0.0 else 0.0
            z[slot + PIPE_SIZE + c] = x[int(p[index + c])] + z[bias + c] + nz
        lost = False
        for q in range(ndrop):
            if p[drops + 2 * q] <= t <= p[drops + 2 * q + 1]:
                lost = True
        z[slot + P_DUE] = 1.0
        z[slot + P_LOST] = 1.0 if lost else 0.0
    else:
        z[slot + P_DUE] = 0.0
        z[slot + P_LOST] = 0.0
    z[Z_COUNT] = jj + 1.0
    z[Z_FRESH] = 0.0
    if jj >= lat:                    # deliver the entry taken lat samples ago
        old = pipe + ((jj - lat) % (lat + 1)) * entry
        if z[old + P_DUE] != 0.0:
            if z[old + P_LOST] != 0.0:
                z[Z_VALID] = 0.0
            else:
                for c in range(k):
                    z[held + c] = z[old + PIPE_SIZE + c]
                z[Z_VALID] = 1.0
                z[Z_FRESH] = 1.0
    valid = z[Z_VALID] != 0.0
    for c in range(k):
        sig[c] = z[held + c] if valid else np.nan
    sig[k] = 1.0 if valid else 0.0


@kernel_function
def sensors_observe(t, x, z, p, w, seen, sig):
    """Every sensor's :func:`sensor_sample` at control sample ``t``, then the state the
    controller sees before the estimator (:meth:`Navigation.observe`: a measured state replaced
    by its held value while valid); ``z``, ``p``: the navigation system's (:data:`NAV`)."""
    for j in range(x.shape[0]):
        seen[j] = x[j]
    for s in range(int(p[N_SENSORS])):
        o = NAV_SIZE + PLACE_SIZE * s
        ps = int(p[o + PARAMS_AT])
        zs = int(p[o + STATE_AT])
        sensor_sample(t, x, z[zs:], p[ps:], w[int(p[o + DRAWS_AT]):], sig[int(p[o + SIGNALS_AT]):])
        if z[zs + Z_VALID] != 0.0:
            for c in range(int(p[ps + S_K])):
                seen[int(p[ps + SENSOR_SIZE + c])] = z[zs + SENSOR_STATE_SIZE + c]


@kernel_function
def read_channels(zn, p, rows_at, n_rows, row_size, held_field, fresh_field, y, fresh):
    """An estimator's measurement rows from the sensors' states ``zn``: row r's held value and
    fresh flag at the offsets its block stores (``rows_at + r·row_size`` + the field offsets)."""
    for r in range(n_rows):
        o = rows_at + r * row_size
        y[r] = zn[int(p[o + held_field])]
        fresh[r] = zn[int(p[o + fresh_field])]


# ----------------------------------------------------------------------------------------------
# the passive observer (passive_observer.PassiveObserver)
# ----------------------------------------------------------------------------------------------

#: the observer's parameters (:meth:`PassiveObserver.kernel_block`); vectors per DOF (surge,
#: sway, yaw), matrices 3 × 3 row-major
OBSERVER = Layout("passive observer", ("velocity_model", 1), ("substeps", 1), ("Ts", 1),
                  ("eta_index", 3), ("nu_index", 3), ("held_at", 3), ("valid_at", 3),
                  ("minus_w0_sq", 3), ("two_zeta_w0", 3), ("K1a", 3), ("K1b", 3), ("K2", 3),
                  ("T_b", 3), ("K3", 9), ("K4", 9), ("D", 9), ("Minv", 9), ("M", 9))
(OB_MODEL, OB_SUBSTEPS, OB_TS, OB_ETA, OB_NU, OB_HELD, OB_VALID, OB_W0SQ, OB_2ZW0, OB_K1A,
 OB_K1B, OB_K2, OB_TB, OB_K3, OB_K4, OB_D, OB_MINV, OB_M) = OBSERVER.at(
    "velocity_model", "substeps", "Ts", "eta_index", "nu_index", "held_at", "valid_at",
    "minus_w0_sq", "two_zeta_w0", "K1a", "K1b", "K2", "T_b", "K3", "K4", "D", "Minv", "M")
#: the observer's state; the first ``OBS_S`` numbers are integrated
OBSERVER_STATE = Layout("passive observer state", ("xi1", 3), ("xi2", 3), ("eta", 3), ("b", 3),
                        ("nu", 3), ("tau", 3), tail="the model's state (the true initial one)")
OBSERVER_STATE_SIZE = OBSERVER_STATE.size
XI1, XI2, ETA, BIAS, NU, TAU = OBSERVER_STATE.at("xi1", "xi2", "eta", "b", "nu", "tau")
OBS_S = TAU
#: the observer's logged signals (:meth:`PassiveObserver.signals`, in this order)
OBSERVER_SIGNALS = Layout("passive observer signals", ("eta_hat", 3), ("nu_hat", 3),
                          ("w_hat", 3), ("b_hat", 3))
OS_ETA, OS_NU, OS_WAVE, OS_BIAS = OBSERVER_SIGNALS.at("eta_hat", "nu_hat", "w_hat", "b_hat")


@kernel_function
def _row3(p, m, q, a0, a1, a2):
    """Row ``q`` of the row-major 3 × 3 matrix at ``p[m]`` times (a0, a1, a2)."""
    return a0 * p[m + 3 * q] + a1 * p[m + 3 * q + 1] + a2 * p[m + 3 * q + 2]


@kernel_function
def observer_rhs(s, y, val, rot, fnu, tau, p, ds):
    """The right-hand side of Fossen & Strand's (1999) passive observer for one ship
    (:mod:`shipgnc.navigation.passive_observer`; Fossen 2021 §13.4), per DOF i::

        ỹ = y − η̂ − ξ̂₂                     (ψ wrapped; 0 on a channel not valid)
        ξ̂̇₁ = ξ̂₂ + K₁ₐ ỹ,   ξ̂̇₂ = −ω₀² ξ̂₁ − 2ζω₀ ξ̂₂ + K₁ᵦ ỹ
        η̂̇ = R(ψ_y) ν̂ + K₂ ỹ
        b̂̇ = −b̂/T_b + K₃ ỹ
        ν̂̇ = M⁻¹(τ − D ν̂ + R(ψ_y)ᵀ(b̂ + K₄ ỹ))          (velocity_model "linear")
        ν̂̇ = ν̇_model(x̂, u) + M⁻¹ R(ψ_y)ᵀ(b̂ + K₄ ỹ)    ("model": ``fnu``)

    ``s`` = [ξ₁, ξ₂, η̂, b̂, ν̂] (``OBS_S`` numbers), ``y``/``val`` the measured (north, east, ψ)
    and their valid flags, ``rot`` = (cos ψ_y, sin ψ_y), ``tau`` the held τ, ``p`` the
    observer's :data:`OBSERVER` block; writes ``ds``."""
    yt0 = y[0] - s[ETA] - s[XI2]
    yt1 = y[1] - s[ETA + 1] - s[XI2 + 1]
    yt2 = wrap(y[2] - s[ETA + 2] - s[XI2 + 2])
    yt0 = yt0 if val[0] != 0.0 else 0.0
    yt1 = yt1 if val[1] != 0.0 else 0.0
    yt2 = yt2 if val[2] != 0.0 else 0.0
    cpsi, spsi = rot[0], rot[1]
    for q in range(3):
        ytq = yt0 if q == 0 else (yt1 if q == 1 else yt2)
        ds[XI1 + q] = s[XI2 + q] + p[OB_K1A + q] * ytq
        ds[XI2 + q] = p[OB_W0SQ + q] * s[XI1 + q] - p[OB_2ZW0 + q] * s[XI2 + q] + p[OB_K1B + q] * ytq
    un, vn, rn = s[NU], s[NU + 1], s[NU + 2]
    ds[ETA] = cpsi * un - spsi * vn + p[OB_K2] * yt0
    ds[ETA + 1] = spsi * un + cpsi * vn + p[OB_K2 + 1] * yt1
    ds[ETA + 2] = rn + p[OB_K2 + 2] * yt2
    i0 = s[BIAS] + _row3(p, OB_K4, 0, yt0, yt1, yt2)       # earth-fixed force, to body: Rᵀ
    i1 = s[BIAS + 1] + _row3(p, OB_K4, 1, yt0, yt1, yt2)
    i2 = s[BIAS + 2] + _row3(p, OB_K4, 2, yt0, yt1, yt2)
    for q in range(3):
        ds[BIAS + q] = -s[BIAS + q] / p[OB_TB + q] + _row3(p, OB_K3, q, yt0, yt1, yt2)
    b0 = cpsi * i0 + spsi * i1
    b1 = -spsi * i0 + cpsi * i1
    b2 = i2
    if p[OB_MODEL] != 0.0:  # the vessel's own ν̇ + M⁻¹ body
        for q in range(3):
            ds[NU + q] = fnu[q] + _row3(p, OB_MINV, q, b0, b1, b2)
    else:  # (τ − D ν̂ + body) M⁻ᵀ
        f0 = tau[0] - _row3(p, OB_D, 0, un, vn, rn) + b0
        f1 = tau[1] - _row3(p, OB_D, 1, un, vn, rn) + b1
        f2 = tau[2] - _row3(p, OB_D, 2, un, vn, rn) + b2
        for q in range(3):
            ds[NU + q] = _row3(p, OB_MINV, q, f0, f1, f2)


@kernel_function
def observer_force(f, f0, p, tau):
    """The actuator force the linear observer holds over a control period,
    τ = M [ν̇(x̂, u) − ν̇(x̂, 0)] (``f``, ``f0``: the model's ẋ with and without the input; exact
    for inputs entering as forces; :mod:`shipgnc.navigation.passive_observer`)."""
    g0 = f[int(p[OB_NU])] - f0[int(p[OB_NU])]
    g1 = f[int(p[OB_NU + 1])] - f0[int(p[OB_NU + 1])]
    g2 = f[int(p[OB_NU + 2])] - f0[int(p[OB_NU + 2])]
    for q in range(3):
        tau[q] = _row3(p, OB_M, q, g0, g1, g2)


@kernel_function
def observer_outputs(z, p, seen, sig):
    """The observer's estimates into ``seen`` (η̂, ν̂ at the model's indices) and its logged
    signals ``[<s>_hat (η, ν), <s>_w_hat (ξ₂), b_<s>_hat]``; ``z`` its state, ``p`` its block."""
    for q in range(3):
        seen[int(p[OB_ETA + q])] = z[ETA + q]
        seen[int(p[OB_NU + q])] = z[NU + q]
        sig[OS_ETA + q] = z[ETA + q]
        sig[OS_NU + q] = z[NU + q]
        sig[OS_WAVE + q] = z[XI2 + q]
        sig[OS_BIAS + q] = z[BIAS + q]


# ----------------------------------------------------------------------------------------------
# the Kalman filters (estimator.GaussianFilter, kalman.KalmanFilter, ekf.ExtendedKalmanFilter)
# ----------------------------------------------------------------------------------------------

#: a Gaussian filter's state after ẑ (n) and P (n × n, row-major)
FILTER_TAIL = Layout("Gaussian filter state after ẑ, P", ("nis", 1), ("nis_dim", 1))
F_NIS, F_NIS_DIM = FILTER_TAIL.at("nis", "nis_dim")
#: a Gaussian filter's logged signals after <s>_hat × n and <s>_std × n (GaussianFilter.signals)
FILTER_SIGNALS = Layout("Gaussian filter signals after the estimates and their std",
                        ("nees", 1), ("nis", 1), ("nis_dim", 1))
FS_NEES, FS_NIS, FS_NIS_DIM = FILTER_SIGNALS.at("nees", "nis", "nis_dim")
#: a Gaussian filter's map of its states to the model's (:meth:`GaussianFilter.kernel_map`)
MAP = Layout("filter map", ("n", 1), ("n_mapped", 1), tail="MAP_ENTRY × n_mapped")
MAP_SIZE = MAP.size
M_N, M_MAPPED = MAP.at("n", "n_mapped")
MAP_ENTRY = Layout("mapped state", ("filter_index", 1), ("model_index", 1), ("angle", 1))
MAP_ENTRY_SIZE = MAP_ENTRY.size
ME_FILTER, ME_MODEL, ME_ANGLE = MAP_ENTRY.at("filter_index", "model_index", "angle")

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
def _upper_update(zh, P, Pc, S, innov):
    """x̂ += Pc/S·innov, P −= Pc Pcᵀ/S on the upper triangle of P, mirrored (the symmetrised
    update ½(P + Pᵀ) up to round-off)."""
    n = zh.shape[0]
    for a in range(n):
        zh[a] = zh[a] + Pc[a] / S * innov
    for a in range(n):
        Ka = Pc[a] / S
        for b in range(a, n):
            P[a * n + b] = P[a * n + b] - Ka * Pc[b]
            P[b * n + a] = P[a * n + b]


@kernel_function
def correct_c(zh, P, c, y, var, angle, Pc):
    """The scalar Kalman update with the measurement y = c·x + v, v ~ N(0, var) (Simon 2006
    §5.1; sequential scalar updates of independent measurements equal the joint update)::

        Pc = P cᵀ,  S = c P cᵀ + var,  ν = y − c x̂  (wrapped for a heading),
        x̂ ← x̂ + Pc ν/S,   P ← P − Pc Pcᵀ/S

    Returns the row's NIS ν²/S, −1 when S ≤ 0 (no update); ``Pc`` scratch of n."""
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
    for a in range(n):
        zh[a] = zh[a] + Pc[a] / S * innov
    for a in range(n):
        Ka = Pc[a] / S
        for b in range(n):
            P[a * n + b] = P[a * n + b] - Ka * Pc[b]
    for a in range(n):  # ½(P + Pᵀ)
        for b in range(a + 1, n):
            m = 0.5 * (P[a * n + b] + P[b * n + a])
            P[a * n + b] = m
            P[b * n + a] = m
    return innov * innov / S


@kernel_function
def nees(err, P, n, idx, m, work):
    """(x − x̂)ᵀ P_sub⁻¹ (x − x̂) over the ``m`` filter states ``idx`` (Gaussian elimination with
    partial pivoting, NaN for a singular block); ``work`` holds at least m² + 2m numbers."""
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


def output_work_size(nx: int) -> int:
    """Scratch numbers of :func:`filter_nees` for a filter mapping at most ``nx`` model states."""
    return nx * nx + 4 * nx + 1


@kernel_function
def filter_nees(x, z, pmap, work):
    """The normalised estimation error squared of a Gaussian filter for one ship,
    (x − x̂)ᵀ P⁻¹ (x − x̂) over the filter states that are model states (their marginal
    covariance; heading errors wrapped): χ²-distributed with that many degrees of freedom for a
    consistent filter (Bar-Shalom, Li & Kirubarajan 2001, §5.4.2). ``x`` the true state, ``z``
    the filter's state ``[ẑ, P, ...]``, ``pmap`` its :data:`MAP`; NaN when it maps none."""
    n = int(pmap[M_N])
    m = int(pmap[M_MAPPED])
    if m == 0:
        return np.nan
    err = work[0:m]
    idx = work[m:2 * m]
    for a in range(m):
        o = MAP_SIZE + MAP_ENTRY_SIZE * a
        i = int(pmap[o + ME_FILTER])
        e = x[int(pmap[o + ME_MODEL])] - z[i]
        err[a] = wrap(e) if pmap[o + ME_ANGLE] != 0.0 else e
        idx[a] = i
    return nees(err, z[n:n + n * n], n, idx, m, work[2 * m:])


@kernel_function
def gaussian_outputs(x, z, pmap, seen, sig, work):
    """A Gaussian filter's estimates of the model states into ``seen`` and its logged signals
    ``[<s>_hat × n, <s>_std × n (√ of P's diagonal), nees, nis, nis_dim]``."""
    n = int(pmap[M_N])
    for a in range(int(pmap[M_MAPPED])):
        o = MAP_SIZE + MAP_ENTRY_SIZE * a
        seen[int(pmap[o + ME_MODEL])] = z[int(pmap[o + ME_FILTER])]
    for i in range(n):
        sig[i] = z[i]
        sig[n + i] = math.sqrt(max(z[n + i * n + i], 0.0))
    tail = 2 * n                     # after <s>_hat × n, <s>_std × n
    sig[tail + FS_NEES] = filter_nees(x, z, pmap, work)
    sig[tail + FS_NIS] = z[n + n * n + F_NIS]
    sig[tail + FS_NIS_DIM] = z[n + n * n + F_NIS_DIM]


#: the linear Kalman filter's parameters (:meth:`KalmanFilter.kernel_block`)
KF = Layout("Kalman filter", ("n", 1), ("n_inputs", 1), ("n_rows", 1),
            tail="A (n × n), B (n × n_inputs), input index × n_inputs, Q (n × n), "
                 "KF_ROW × n_rows, C (n_rows × n)")
KF_SIZE = KF.size
KF_N, KF_INPUTS, KF_ROWS = KF.at("n", "n_inputs", "n_rows")
KF_ROW = Layout("Kalman filter row", ("held_at", 1), ("fresh_at", 1), ("R", 1), ("angle", 1))
KF_ROW_SIZE = KF_ROW.size
KR_HELD, KR_FRESH, KR_R, KR_ANGLE = KF_ROW.at("held_at", "fresh_at", "R", "angle")


@kernel_function
def kf_rows_at(p):
    """Where the linear filter's rows start in its block (after A, B, the input indices, Q)."""
    n = int(p[KF_N])
    ni = int(p[KF_INPUTS])
    return KF_SIZE + 2 * n * n + n * ni + ni


@kernel_function
def kf_step(first, u, y, fresh, z, p):
    """One control sample of the discrete Kalman filter (:mod:`shipgnc.navigation.kalman`) for
    one ship: unless ``first``, the prediction with the input applied over the last sample,

        ẑ⁻ = A ẑ + B u,      P⁻ = A P Aᵀ + Q,

    then :func:`correct_c` with every row whose sensor delivered now (``fresh``; ``y`` the rows'
    held values). ``z`` the filter's state ``[ẑ, P, FILTER_TAIL]``, ``p`` its :data:`KF` block."""
    n = int(p[KF_N])
    ni = int(p[KF_INPUTS])
    nrows = int(p[KF_ROWS])
    oA = KF_SIZE
    oB = oA + n * n
    oI = oB + n * ni
    oQ = oI + ni
    oR = oQ + n * n
    oC = oR + KF_ROW_SIZE * nrows
    zh = z[0:n].copy()
    P = z[n:n + n * n].copy()
    if first == 0.0:
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
        o = oR + KF_ROW_SIZE * r
        if fresh[r] != 0.0:
            for j in range(n):
                c[j] = p[oC + r * n + j]
            v = correct_c(zh, P, c, y[r], p[o + KR_R], p[o + KR_ANGLE] != 0.0, Pc)
            if v >= 0.0:
                nis += v
                nisd += 1.0
    for i in range(n):
        z[i] = zh[i]
    for i in range(n * n):
        z[n + i] = P[i]
    z[n + n * n + F_NIS] = nis
    z[n + n * n + F_NIS_DIM] = nisd


#: the EKF's parameters (:meth:`ExtendedKalmanFilter.kernel_block`)
EKF = Layout("extended Kalman filter", ("n", 1), ("nx", 1), ("substeps", 1), ("Ts", 1),
             ("held", 1), ("n_rows", 1), ("n_aug", 1), ("n_slots", 1),
             tail="EKF_ROW × n_rows, Q_c diagonal × n, AUGMENTED × n_aug")
EKF_SIZE = EKF.size
E_N, E_NX, E_SUBSTEPS, E_TS, E_HELD, E_ROWS, E_AUG, E_SLOTS = EKF.at(
    "n", "nx", "substeps", "Ts", "held", "n_rows", "n_aug", "n_slots")
#: a measurement row: c = e_state (+ e_bias_state when ≥ 0), its sensor's latency and period,
#: and its slots for pending delayed samples
EKF_ROW = Layout("EKF row", ("state", 1), ("held_at", 1), ("fresh_at", 1), ("R", 1),
                 ("angle", 1), ("bias_state", 1), ("latency", 1), ("every", 1),
                 ("first_slot", 1), ("slots", 1))
EKF_ROW_SIZE = EKF_ROW.size
(ER_STATE, ER_HELD, ER_FRESH, ER_R, ER_ANGLE, ER_BIAS, ER_LATENCY, ER_EVERY, ER_FIRST_SLOT,
 ER_SLOTS) = EKF_ROW.at("state", "held_at", "fresh_at", "R", "angle", "bias_state", "latency",
                        "every", "first_slot", "slots")
#: an augmented state: the model state whose derivative it drives (−1: none), its decay rate λ
AUGMENTED = Layout("augmented state", ("driven", 1), ("decay", 1))
AUGMENTED_SIZE = AUGMENTED.size
AU_DRIVEN, AU_DECAY = AUGMENTED.at("driven", "decay")
#: the EKF's state after ẑ (n) and P (n × n), then ``n_slots`` SLOTs
EKF_TAIL = Layout("EKF state after ẑ, P", ("nis", 1), ("nis_dim", 1), ("count", 1),
                  tail="SLOT × n_slots")
EKF_TAIL_SIZE = EKF_TAIL.size
E_NIS, E_NIS_DIM, E_COUNT = EKF_TAIL.at("nis", "nis_dim", "count")
#: a pending delayed sample (Larsen et al. 1998): taken at ``taken_at``, its predicted
#: measurement h and innovation variance S, then g (n) and Cov(ν, ν_other) per slot
SLOT = Layout("pending sample", ("active", 1), ("taken_at", 1), ("h", 1), ("S", 1),
              tail="g × n, Cov(ν, ν_other) × n_slots")
SLOT_SIZE = SLOT.size
SL_ACTIVE, SL_TAKEN, SL_H, SL_S = SLOT.at("active", "taken_at", "h", "S")


def ekf_state_size(n: int, n_slots: int) -> int:
    """Numbers of the EKF's state with ``n`` filter states and ``n_slots`` pending slots."""
    return n + n * n + EKF_TAIL_SIZE + n_slots * (SLOT_SIZE + n + n_slots)


def ekf_work_size(n: int) -> int:
    """Scratch numbers of :func:`ekf_update` for a filter of ``n`` states."""
    return 7 * n * n + 2 * n


@kernel_function
def ekf_rows_at():
    """Where the EKF's rows start in its block."""
    return EKF_SIZE


@kernel_function
def ekf_rates(z, fx, p, out):
    """The augmented state's derivative (:mod:`shipgnc.navigation.ekf`): the model's ẋ = ``fx``
    plus each bias d on the derivative of the state it drives, ḃ = −λ b for every augmented
    state (λ = 0: a random walk; 1/T_b: a GNSS Gauss–Markov bias). ``out`` may be ``fx``."""
    n = int(p[E_N])
    nx = int(p[E_NX])
    a0 = EKF_SIZE + EKF_ROW_SIZE * int(p[E_ROWS]) + n
    for j in range(nx):
        out[j] = fx[j]
    for a in range(n - nx):
        o = a0 + AUGMENTED_SIZE * a
        tgt = int(p[o + AU_DRIVEN])
        b = z[nx + a]
        if tgt >= 0:
            out[tgt] = out[tgt] + b
        out[nx + a] = -b * p[o + AU_DECAY]


@kernel_function
def _carve(work, at, size):
    """The next ``size`` numbers of a scratch array from ``at``, and where the next start."""
    return work[at:at + size], at + size


@kernel_function
def ekf_update(first, Ax, xpred, y, fresh, z, p, work):
    """One control sample of the EKF (:mod:`shipgnc.navigation.ekf`) for one ship after the
    model's part: unless ``first``, the prediction from the model's Jacobian ``Ax`` (nx × nx at
    the last estimate) and the propagated mean ``xpred`` (RK4 on the augmented model),

        A  = [[Ax, Dᵀ], [0, −diag λ]]
        F  = I + A Ts + (A Ts)²/2 + (A Ts)³/6 + (A Ts)⁴/24             (RK4 on the linearisation)
        Q_d = Q_c Ts + (A Q_c + Q_c Aᵀ) Ts²/2 + A Q_c Aᵀ Ts³/3          (continuous noise), or
        Q_d = Γ (Q_c/Ts) Γᵀ,  Γ = Ts (I + A Ts/2 + (A Ts)²/6)           (noise held over Ts)
        P⁻ = F P Fᵀ + Q_d,   and every pending delayed sample's g ← F g  (Larsen's M*)

    (Fossen 2021 §13.3; Simon 2006 §13.2), then one scalar correction per row whose sensor
    delivered now without latency (:func:`ekf_correct`), then the delayed rows
    (:func:`ekf_delayed`). The arithmetic takes fewer operations than the formulas: F − I = E =
    At + At²/2 + At²(At/6 + At²/24), At = A Ts (two products instead of three; Paterson &
    Stockmeyer 1973, SIAM J. Comput. 2(1)); P⁻ = T + T Eᵀ + Q_d with T = P + E P, on the upper
    triangle only and mirrored. ``z`` the EKF's state (ẑ, P, :data:`EKF_TAIL`, slots), ``p`` its
    :data:`EKF` block, ``work`` :func:`ekf_work_size` numbers."""
    n = int(p[E_N])
    tail = n + n * n
    if first != 0.0:
        z[tail + E_COUNT] = 0.0
    else:
        z[tail + E_COUNT] += 1.0
        ekf_predict(Ax, xpred, z, p, work)
    zh = z[0:n]
    P = z[n:tail]
    nslt = int(p[E_SLOTS])
    slots = z[tail + EKF_TAIL_SIZE:]
    nis, nisd = _ekf_fresh_rows(zh, P, y, fresh, slots, p, work[0:n])
    if nslt > 0:
        nis, nisd = ekf_delayed(zh, P, y, fresh, slots, p, int(z[tail + E_COUNT]), nis, nisd)
    z[tail + E_NIS] = nis
    z[tail + E_NIS_DIM] = nisd


@kernel_function
def ekf_predict(Ax, xpred, z, p, work):
    """The prediction of :func:`ekf_update`: A from the model's Jacobian ``Ax`` and the augmented
    states, F − I = E, Q_d, then ẑ⁻ = ``xpred``, P⁻ = F P Fᵀ + Q_d and every pending delayed
    sample's g ← F g (the formulas of :func:`ekf_update`)."""
    n = int(p[E_N])
    nne = n * n
    Ts = p[E_TS]
    A, at = _carve(work, 0, nne)
    At, at = _carve(work, at, nne)
    B2, at = _carve(work, at, nne)       # At², then T = F P
    C, at = _carve(work, at, nne)        # At/6 + At²/24, then Γ
    E, at = _carve(work, at, nne)        # F − I
    Qd, at = _carve(work, at, nne)       # Q_d, then P⁻ (upper triangles)
    Pl, at = _carve(work, at, nne)
    q, at = _carve(work, at, n)
    xp, at = _carve(work, at, n)
    q0 = EKF_SIZE + EKF_ROW_SIZE * int(p[E_ROWS])   # Q_c diagonal
    for j in range(n):
        q[j] = p[q0 + j]
    _ekf_system(Ax, p, q0 + n, A)
    _ekf_transition(At, A, Ts, B2, C, E)
    if p[E_HELD] != 0.0:
        _ekf_noise_held(At, B2, q, Ts, C, Qd)
    else:
        _ekf_noise_continuous(A, q, Ts, Qd)
    for i in range(n):
        z[i] = xpred[i]
    _ekf_covariance(z[n:n + nne], E, Pl, B2, Qd)
    nslt = int(p[E_SLOTS])
    sb = n + nne + EKF_TAIL_SIZE
    ssz = SLOT_SIZE + n + nslt
    for sl in range(nslt):      # Larsen's M*: g ← F g = g + E g
        if z[sb + sl * ssz + SL_ACTIVE] != 0.0:
            _ekf_propagate_gain(z, sb + sl * ssz + SLOT_SIZE, E, xp)


@kernel_function
def _ekf_system(Ax, p, a0, A):
    """A = [[Ax, Dᵀ], [0, −diag λ]] (n × n, row-major) from the model's Jacobian ``Ax`` (nx × nx)
    and the augmented states' block at ``p[a0:]`` (:data:`AUGMENTED`)."""
    n = int(p[E_N])
    nx = int(p[E_NX])
    for i in range(n):
        for j in range(n):
            A[i * n + j] = Ax[i * nx + j] if (i < nx and j < nx) else 0.0
    for a in range(n - nx):
        o = a0 + AUGMENTED_SIZE * a
        tgt = int(p[o + AU_DRIVEN])
        if tgt >= 0:
            A[tgt * n + nx + a] = 1.0
        A[(nx + a) * n + nx + a] = -p[o + AU_DECAY]


@kernel_function
def _ekf_transition(At, A, Ts, B2, C, E):
    """At = A Ts, B2 = At², C = At/6 + At²/24 and E = F − I = At + At²/2 + At² C (Paterson &
    Stockmeyer: two products instead of three)."""
    n = int(math.sqrt(A.shape[0]) + 0.5)
    for i in range(n * n):
        At[i] = A[i] * Ts
    for i in range(n):
        for j in range(n):
            acc = 0.0
            for m in range(n):
                acc += At[i * n + m] * At[m * n + j]
            B2[i * n + j] = acc
            C[i * n + j] = At[i * n + j] / 6 + acc / 24
    for i in range(n):
        for j in range(n):
            acc = 0.0
            for m in range(n):
                acc += B2[i * n + m] * C[m * n + j]
            E[i * n + j] = At[i * n + j] + B2[i * n + j] / 2 + acc


@kernel_function
def _ekf_noise_held(At, B2, q, Ts, C, Qd):
    """Q_d = Γ (Q_c/Ts) Γᵀ, Γ = Ts (I + At/2 + At²/6) (noise held over Ts), upper triangle;
    Γ is formed in ``C``."""
    n = q.shape[0]
    for i in range(n):
        for j in range(n):
            C[i * n + j] = Ts * ((1.0 if i == j else 0.0) + At[i * n + j] / 2 + B2[i * n + j] / 6)
    for i in range(n):
        for j in range(i, n):
            acc = 0.0
            for m in range(n):
                acc += C[i * n + m] * q[m] * C[j * n + m]
            Qd[i * n + j] = acc / Ts


@kernel_function
def _ekf_noise_continuous(A, q, Ts, Qd):
    """Q_d = Q_c Ts + (A Q_c + Q_c Aᵀ) Ts²/2 + A Q_c Aᵀ Ts³/3 (continuous noise), upper triangle."""
    n = q.shape[0]
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


@kernel_function
def _ekf_covariance(P, E, Pl, B2, Qd):
    """P⁻ = F P Fᵀ + Q_d in place: T = P + E P (in ``B2``), then the upper triangle of
    T + T Eᵀ + Q_d (in ``Qd``), mirrored into ``P``."""
    n = int(math.sqrt(P.shape[0]) + 0.5)
    for i in range(n * n):
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


@kernel_function
def _ekf_propagate_gain(z, g0, E, xp):
    """A pending delayed sample's g (``z[g0:g0 + n]``) ← F g = g + E g (Larsen's M*)."""
    n = xp.shape[0]
    for i in range(n):
        acc = z[g0 + i]
        for m in range(n):
            acc += E[i * n + m] * z[g0 + m]
        xp[i] = acc
    for i in range(n):
        z[g0 + i] = xp[i]


@kernel_function
def _ekf_fresh_rows(zh, P, y, fresh, slots, p, Pc):
    """One scalar correction per row whose sensor delivered now without latency
    (:func:`ekf_correct`); returns the summed NIS and the number of rows it sums."""
    nis = 0.0
    nisd = 0.0
    nslt = int(p[E_SLOTS])
    for r in range(int(p[E_ROWS])):
        o = EKF_SIZE + EKF_ROW_SIZE * r
        if p[o + ER_LATENCY] == 0.0 and fresh[r] != 0.0:  # no latency, fresh
            v = ekf_correct(zh, P, int(p[o + ER_STATE]), int(p[o + ER_BIAS]), y[r], p[o + ER_R],
                            p[o + ER_ANGLE] != 0.0, slots, nslt, Pc)
            if v >= 0.0:
                nis += v
                nisd += 1.0
    return nis, nisd


@kernel_function
def ekf_correct(zh, P, j, jb, y, var, angle, slots, nslt, Pc):
    """:func:`correct_c` for a row c = e_j (a measured state), or c = e_j + e_jb (a measured
    state and its sensor's bias state jb ≥ 0), reading P's columns instead of multiplying; every
    pending delayed sample's g ← g − K c g (the correction carried into Larsen's M*). Returns
    the row's NIS, −1 when S ≤ 0 (no update)."""
    n = zh.shape[0]
    for a in range(n):
        Pc[a] = P[a * n + j] + P[a * n + jb] if jb >= 0 else P[a * n + j]
    S = (Pc[j] + Pc[jb] if jb >= 0 else Pc[j]) + var
    if not S > 0.0:
        return -1.0
    innov = y - (zh[j] + zh[jb] if jb >= 0 else zh[j])
    if angle:
        innov = wrap(innov)
    ssz = SLOT_SIZE + n + nslt
    for sl in range(nslt):
        g0 = sl * ssz + SLOT_SIZE
        if slots[sl * ssz + SL_ACTIVE] != 0.0:
            cg = slots[g0 + j] + slots[g0 + jb] if jb >= 0 else slots[g0 + j]
            for a in range(n):
                slots[g0 + a] = slots[g0 + a] - Pc[a] / S * cg
    _upper_update(zh, P, Pc, S, innov)
    return innov * innov / S


@kernel_function
def ekf_delayed(zh, P, y, fresh, slots, p, k, nis, nisd):
    """Delayed measurements by Larsen, Andersen, Ravn & Poulsen (1998, Proc. 37th IEEE CDC, the
    extrapolation method) for one ship at sample ``k``: apply the pending samples delivered now,

        x̂ ← x̂ + g ν_s/S_s,   P ← P − g gᵀ/S_s,   g_other ← g_other − g Cov(ν_s, ν_other)/S_s,

    then record the samples the delayed rows take now (h = c x̂, g = P cᵀ, S = c g + R,
    Cov(ν_new, ν_other) = c g_other) in free :data:`SLOT` s; returns the updated NIS and its
    dimension."""
    n = zh.shape[0]
    nslt = int(p[E_SLOTS])
    nrows = int(p[E_ROWS])
    ssz = SLOT_SIZE + n + nslt
    for r in range(nrows):
        o = EKF_SIZE + EKF_ROW_SIZE * r
        lat = int(p[o + ER_LATENCY])
        if lat == 0:
            continue
        first = int(p[o + ER_FIRST_SLOT])
        for sl in range(first, first + int(p[o + ER_SLOTS])):
            b = sl * ssz
            if slots[b + SL_ACTIVE] == 0.0 or slots[b + SL_TAKEN] > k - lat:
                continue
            slots[b + SL_ACTIVE] = 0.0
            if slots[b + SL_TAKEN] != k - lat or fresh[r] == 0.0 or not slots[b + SL_S] > 0.0:
                continue
            S = slots[b + SL_S]
            innov = y[r] - slots[b + SL_H]
            if p[o + ER_ANGLE] != 0.0:
                innov = wrap(innov)
            nis += innov * innov / S
            nisd += 1.0
            g = slots[b + SLOT_SIZE:b + SLOT_SIZE + n]
            for a in range(n):
                zh[a] = zh[a] + g[a] * (innov / S)
            for a in range(n):
                for c in range(a, n):
                    P[a * n + c] = P[a * n + c] - g[a] * g[c] / S
                    P[c * n + a] = P[a * n + c]
            for ot in range(nslt):
                bo = ot * ssz
                if ot != sl and slots[bo + SL_ACTIVE] != 0.0:
                    rho = slots[bo + SLOT_SIZE + n + sl]
                    for a in range(n):
                        slots[bo + SLOT_SIZE + a] = slots[bo + SLOT_SIZE + a] - g[a] * (rho / S)
    for r in range(nrows):
        o = EKF_SIZE + EKF_ROW_SIZE * r
        lat = int(p[o + ER_LATENCY])
        if lat == 0 or k % int(p[o + ER_EVERY]) != 0:
            continue
        j = int(p[o + ER_STATE])
        jb = int(p[o + ER_BIAS])
        first = int(p[o + ER_FIRST_SLOT])
        for sl in range(first, first + int(p[o + ER_SLOTS])):
            b = sl * ssz
            if slots[b + SL_ACTIVE] != 0.0:
                continue
            g0 = b + SLOT_SIZE
            slots[b + SL_ACTIVE] = 1.0
            slots[b + SL_TAKEN] = float(k)
            slots[b + SL_H] = zh[j] + zh[jb] if jb >= 0 else zh[j]
            for a in range(n):
                slots[g0 + a] = P[a * n + j] + P[a * n + jb] if jb >= 0 else P[a * n + j]
            slots[b + SL_S] = (slots[g0 + j] + slots[g0 + jb] if jb >= 0
                               else slots[g0 + j]) + p[o + ER_R]
            for ot in range(nslt):   # Cov(ν_new, ν_other) = c g_other
                bo = ot * ssz
                if ot != sl and slots[bo + SL_ACTIVE] != 0.0:
                    go = bo + SLOT_SIZE
                    rho = slots[go + j] + slots[go + jb] if jb >= 0 else slots[go + j]
                    slots[g0 + n + ot] = rho
                    slots[go + n + sl] = rho
            break
    return nis, nisd
