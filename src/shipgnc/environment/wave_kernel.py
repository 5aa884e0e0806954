"""Compiled (numba) forms of document 003's wave loads (:class:`FroudeKrylovWaveLoads`).

The numpy form in :mod:`shipgnc.environment.waves` (``loads_numpy``) is the reference. Two
compiled forms repeat it:

* :func:`loads` — the twin the numpy loop calls (``__call__``, recorded as ``+wave_kernel``): one
  (ship, component) pair at a time, so a batch does not allocate a dozen (ships × components)
  temporaries per RK stage (about 3× faster; one thread: a parallel region's spinning workers
  would slow the numpy loop around it);
* :func:`froude_krylov_sample` — the disturbance kernel of the composed loop
  (:mod:`shipgnc.kernels`), one ship per call, its sea in the ship's kernel state.

Tests hold both equal to the reference to round-off.
"""

from __future__ import annotations

import math

import numpy as np

_KERNEL = None


def _sin_sinc_j1(u):
    """Scalar twin of ``waves._sin_sinc_j1``: sin u, sin u/u, j₁(u) (series near 0)."""
    su = math.sin(u)
    if abs(u) < 1e-3:
        u2 = u * u
        return su, 1.0 - u2 / 6.0, u * (1.0 / 3.0 - u2 / 30.0)
    sinc = su / u
    return su, sinc, (sinc - math.cos(u)) / u


def _loads(t, north, east, psi, omega, k_north, k_east, phase, half_kL, half_kB, chi,
           wX, wY, wN, length, beam, long_crested, out):
    """X, Y, N of every ship (rows of the (ships, components) arrays) into ``out`` (ships, 3)."""
    for i in range(omega.shape[0]):
        X = 0.0
        Y = 0.0
        N = 0.0
        cos_b = math.cos(chi[i, 0] - psi[i])  # long-crested: one direction for all components
        sin_b = math.sin(chi[i, 0] - psi[i])
        for j in range(omega.shape[1]):
            theta = omega[i, j] * t - (k_north[i, j] * north[i] + k_east[i, j] * east[i]) + phase[i, j]
            if not long_crested:
                cos_b = math.cos(chi[i, j] - psi[i])
                sin_b = math.sin(chi[i, j] - psi[i])
            s_u, sinc_u, j1_u = _sin_sinc_j1(half_kL[i, j] * cos_b)
            s_w, sinc_w, j1_w = _sin_sinc_j1(half_kB[i, j] * sin_b)
            s = math.sin(theta)
            X += wX[i, j] * (beam * s_u * sinc_w) * s
            Y += wY[i, j] * (length * s_w * sinc_u) * s
            N += wN[i, j] * (length * length * s_w * j1_u - beam * beam * s_u * j1_w) * math.cos(theta)
        out[i, 0] = X
        out[i, 1] = Y
        out[i, 2] = N


def available() -> bool:
    try:
        import numba  # noqa: F401
    except Exception:
        return False
    return True


def loads(t: float, north, east, psi, arrays: dict, length: float, beam: float,
          long_crested: bool) -> np.ndarray:
    """Evaluate the loads for flattened ships; ``arrays`` hold (ships, components) float arrays."""
    global _KERNEL, _sin_sinc_j1
    if _KERNEL is None:
        import numba

        _sin_sinc_j1 = numba.njit(cache=True)(_sin_sinc_j1)
        _KERNEL = numba.njit(cache=True)(_loads)
    out = np.empty((north.shape[0], 3))
    _KERNEL(float(t), north, east, psi, arrays["omega"], arrays["k_north"], arrays["k_east"],
            arrays["phase"], arrays["half_kL"], arrays["half_kB"], arrays["chi"], arrays["wX"],
            arrays["wY"], arrays["wN"], float(length), float(beam), bool(long_crested), out)
    return out


# ----------------------------------------------------------------------------------------------
# the disturbance kernel of the composed loop (shipgnc.kernels): one ship, every RK stage
# ----------------------------------------------------------------------------------------------

import numba  # noqa: E402
from llvmlite import ir  # noqa: E402
from numba.core import cgutils, types  # noqa: E402
from numba.core.extending import intrinsic  # noqa: E402

from shipgnc.kernels import JIT_OPTIONS, kernel_function  # noqa: E402

#: rows of a ship's per-component block in the kernel's state (each ``n_components`` long)
ROWS = ("omega", "phase", "k_north", "k_east", "half_kL", "half_kB", "chi", "wX", "wY", "wN")
#: scratch rows after them: the per-component terms of X, Y and N, summed as numpy sums them
N_SCRATCH = 3


@kernel_function
def pairwise_sum(a, lo, n):
    """Σ a[lo:lo + n] in the order of numpy's ``np.sum`` along a contiguous axis (its pairwise
    summation: eight interleaved partial sums in blocks of at most 128, halves above that), so the
    kernel adds the components exactly as :meth:`FroudeKrylovWaveLoads.loads_numpy` does."""
    if n < 8:
        res = 0.0
        for i in range(n):
            res += a[lo + i]
        return res
    if n <= 128:
        r0, r1, r2, r3 = a[lo], a[lo + 1], a[lo + 2], a[lo + 3]
        r4, r5, r6, r7 = a[lo + 4], a[lo + 5], a[lo + 6], a[lo + 7]
        i = 8
        end = n - n % 8
        while i < end:
            j = lo + i
            r0 += a[j]
            r1 += a[j + 1]
            r2 += a[j + 2]
            r3 += a[j + 3]
            r4 += a[j + 4]
            r5 += a[j + 5]
            r6 += a[j + 6]
            r7 += a[j + 7]
            i += 8
        res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
        while i < n:
            res += a[lo + i]
            i += 1
        return res
    n2 = n // 2
    n2 -= n2 % 8
    return pairwise_sum(a, lo, n2) + pairwise_sum(a, lo + n2, n - n2)


@intrinsic
def _lane_sums3(typingctx, a, lo, m, stride):
    """Three 8-lane partial-sum blocks at once: for each row k = 0, 1, 2 (starting at
    lo + k·stride) lane l adds a[lo + k·stride + 8i + l] for i = 0 … m − 1 in that order, and the
    lanes are combined as ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7)) — numpy's block
    (:func:`pairwise_sum`) written as one 8-wide vector add per step (plain IEEE adds, no
    reassociation: the same sum to the bit). numba does not SLP-vectorise the scalar form."""
    if not (isinstance(a, types.Array) and a.ndim == 1 and a.dtype == types.float64
            and a.layout == "C"):
        return None
    sig = types.UniTuple(types.float64, 3)(a, types.intp, types.intp, types.intp)

    def codegen(context, builder, signature, args):
        data = context.make_array(signature.args[0])(context, builder, args[0]).data
        lo_, m_, stride_ = args[1], args[2], args[3]
        f64 = ir.DoubleType()
        vec = ir.VectorType(f64, 8)
        rows = [builder.gep(data, [builder.add(lo_, builder.mul(stride_, ir.Constant(lo_.type, k)))],
                            source_etype=f64) for k in range(3)]
        accs = [cgutils.alloca_once_value(builder, builder.load(r, typ=vec, align=8)) for r in rows]
        one = ir.Constant(lo_.type, 1)
        with cgutils.for_range_slice(builder, one, m_, one, inc=True) as (i, _):
            offset = builder.mul(i, ir.Constant(i.type, 8))
            for row, acc in zip(rows, accs, strict=True):
                block = builder.load(builder.gep(row, [offset], source_etype=f64), typ=vec, align=8)
                builder.store(builder.fadd(builder.load(acc), block), acc)
        sums = []
        for acc in accs:
            r = builder.load(acc)
            e = [builder.extract_element(r, ir.Constant(ir.IntType(32), k)) for k in range(8)]
            sums.append(builder.fadd(builder.fadd(builder.fadd(e[0], e[1]), builder.fadd(e[2], e[3])),
                                     builder.fadd(builder.fadd(e[4], e[5]), builder.fadd(e[6], e[7]))))
        return context.make_tuple(builder, signature.return_type, sums)

    return sig, codegen


@kernel_function
def pairwise_sum3(a, lo, n, stride):
    """(Σ a[lo:lo + n], Σ a[lo + s:lo + s + n], Σ a[lo + 2s:lo + 2s + n]) with s = ``stride``,
    each exactly as :func:`pairwise_sum` (numpy's order); the three rows' blocks are added side by
    side, eight lanes per vector add (:func:`_lane_sums3`)."""
    if n < 8:
        sx = sy = sz = 0.0
        for i in range(n):
            sx += a[lo + i]
            sy += a[lo + stride + i]
            sz += a[lo + 2 * stride + i]
        return sx, sy, sz
    if n <= 128:
        m = n // 8
        sx, sy, sz = _lane_sums3(a, lo, m, stride)
        for i in range(lo + 8 * m, lo + n):
            sx += a[i]
            sy += a[i + stride]
            sz += a[i + 2 * stride]
        return sx, sy, sz
    n2 = n // 2
    n2 -= n2 % 8
    ax, ay, az = pairwise_sum3(a, lo, n2, stride)
    bx, by, bz = pairwise_sum3(a, lo + n2, n - n2, stride)
    return ax + bx, ay + by, az + bz


# sin and cos of many arguments in one vectorisable loop (no libm call per element): Cody–Waite
# reduction by π/2 in three parts (exact products for |x| < 2²⁰·π/2) and fdlibm's kernels
# __kernel_sin / __kernel_cos on |r| ≤ π/4 (error < 1 ulp; libm's own reduction and kernels)
_PIO2_1 = 1.57079632673412561417e+00
_PIO2_2 = 6.07710050630396597660e-11
_PIO2_3 = 2.02226624871116645580e-21
_INV_PIO2 = 6.36619772367581382433e-01
#: 1.5·2⁵²: (y + _ROUND) − _ROUND rounds |y| < 2⁵¹ to the nearest integer
_ROUND = 6755399441055744.0
#: beyond this |x| the three-part reduction loses bits: those arguments go to libm
SINCOS_LIMIT = 1.0e6
_S1, _S2, _S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04
_S4, _S5, _S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10
_C1, _C2, _C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05
_C4, _C5, _C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11


@numba.njit(inline="always", **JIT_OPTIONS)
def sincos(x):
    """(sin x, cos x) within 1 ulp of libm for |x| ≤ :data:`SINCOS_LIMIT`, branch-free (so a loop
    of it vectorises); NaN stays NaN. q = nearest integer to 2x/π by the 1.5·2⁵² rounding trick
    (no floor, one float → int conversion for the quadrant: the cheapest form found)."""
    q = (x * _INV_PIO2 + _ROUND) - _ROUND
    r = x - q * _PIO2_1
    r = r - q * _PIO2_2
    r = r - q * _PIO2_3
    z = r * r
    s = r + r * z * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))))
    rc = z * (_C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * _C6)))))
    hz = 0.5 * z
    w = 1.0 - hz
    c = w + (((1.0 - w) - hz) + z * rc)
    m = int(q)  # quadrant: bit 0 swaps sin and cos, bit 1 (of m, m + 1) flips their signs
    a = c if m & 1 else s
    b = s if m & 1 else c
    return (-a if m & 2 else a), (-b if (m + 1) & 2 else b)


@numba.njit(inline="always", **JIT_OPTIONS)
def _sinc_j1(s, c, u):
    """sinc u and j₁(u) from s = sin u, c = cos u, as ``waves._sin_sinc_j1`` (series for
    |u| < 1e-3), without branches."""
    small = abs(u) < 1e-3
    us = 1.0 if small else u
    u2 = u * u
    inv = 1.0 / us  # one division for both (x/u → x·(1/u): round-off only, as arcp allows)
    sinc = 1.0 - u2 * (1.0 / 6.0) if small else s * inv
    j1 = u * (1.0 / 3.0 - u2 * (1.0 / 30.0)) if small else (sinc - c) * inv
    return sinc, j1


@numba.njit(inline="always", **JIT_OPTIONS)
def _terms(z, j, n, o_t, length, beam, L2, B2, s, c, s_u, c_u, s_v, c_v, u, v):
    """Component j's terms of X, Y, N (:meth:`FroudeKrylovWaveLoads.loads_numpy`'s products)."""
    sinc_u, j1_u = _sinc_j1(s_u, c_u, u)
    sinc_v, j1_v = _sinc_j1(s_v, c_v, v)
    z[o_t + j] = z[7 * n + j] * (beam * s_u * sinc_v) * s
    z[o_t + n + j] = z[8 * n + j] * (length * s_v * sinc_u) * s
    z[o_t + 2 * n + j] = z[9 * n + j] * (L2 * s_v * j1_u - B2 * s_u * j1_v) * c


@kernel_function
def froude_krylov_sample(t, x, z, p, w, d):
    """[X_env, Y_env, N_env] of one ship at time ``t`` and stage state ``x``: document 003's
    seeded Froude–Krylov loads (note 003-3.6; :class:`~shipgnc.environment.waves.FroudeKrylovWaveLoads`),

        θᵢ = ωᵢ t − (k_n,ᵢ n + k_e,ᵢ e) + φᵢ,   βᵢ = χᵢ − ψ,   uᵢ = ½kᵢL cos βᵢ,  vᵢ = ½kᵢB sin βᵢ,
        X = Σ w_X,ᵢ B sin uᵢ sinc vᵢ sin θᵢ,   Y = Σ w_Y,ᵢ L sin vᵢ sinc uᵢ sin θᵢ,
        N = Σ w_N,ᵢ (L² sin vᵢ j₁(uᵢ) − B² sin uᵢ j₁(vᵢ)) cos θᵢ,

    operation for operation as :meth:`~FroudeKrylovWaveLoads.loads_numpy`, the sums in numpy's
    order (:func:`pairwise_sum3`). The cost is three sin/cos pairs per component and stage: they
    are evaluated by :func:`sincos` in one vectorised loop over the components (libm for any
    argument beyond :data:`SINCOS_LIMIT`). ``z`` holds the ship's sea (:data:`ROWS`) and the
    scratch rows of the terms; ``p`` = [n_components, L, B, long-crested, i_north, i_east, i_psi]."""
    n = int(p[0])
    length, beam = p[1], p[2]
    north, east, psi = x[int(p[4])], x[int(p[5])], x[int(p[6])]
    L2, B2 = length ** 2, beam ** 2
    o_t = 10 * n
    n_big = 0
    if p[3] != 0.0:  # long-crested: one direction, so β is the ship's
        beta = z[6 * n] - psi
        cos_b, sin_b = math.cos(beta), math.sin(beta)
        for j in range(n):
            theta = z[j] * t - (z[2 * n + j] * north + z[3 * n + j] * east) + z[n + j]
            u = z[4 * n + j] * cos_b
            v = z[5 * n + j] * sin_b
            n_big += max(abs(theta), abs(u), abs(v)) > SINCOS_LIMIT
            s, c = sincos(theta)
            s_u, c_u = sincos(u)
            s_v, c_v = sincos(v)
            _terms(z, j, n, o_t, length, beam, L2, B2, s, c, s_u, c_u, s_v, c_v, u, v)
    else:
        for j in range(n):
            theta = z[j] * t - (z[2 * n + j] * north + z[3 * n + j] * east) + z[n + j]
            beta = z[6 * n + j] - psi
            n_big += max(abs(theta), abs(beta)) > SINCOS_LIMIT
            sin_b, cos_b = sincos(beta)
            u = z[4 * n + j] * cos_b
            v = z[5 * n + j] * sin_b
            s, c = sincos(theta)
            s_u, c_u = sincos(u)
            s_v, c_v = sincos(v)
            _terms(z, j, n, o_t, length, beam, L2, B2, s, c, s_u, c_u, s_v, c_v, u, v)
    if n_big:  # arguments beyond the fast reduction (a run of hours, a runaway heading): libm
        for j in range(n):
            theta = z[j] * t - (z[2 * n + j] * north + z[3 * n + j] * east) + z[n + j]
            beta = (z[6 * n] if p[3] != 0.0 else z[6 * n + j]) - psi
            u = z[4 * n + j] * math.cos(beta)
            v = z[5 * n + j] * math.sin(beta)
            _terms(z, j, n, o_t, length, beam, L2, B2, math.sin(theta), math.cos(theta),
                   math.sin(u), math.cos(u), math.sin(v), math.cos(v), u, v)
    d[0], d[1], d[2] = pairwise_sum3(z, o_t, n, n)
