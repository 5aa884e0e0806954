"""Document 003's wave loads (:class:`~shipgnc.environment.waves.FroudeKrylovWaveLoads`) written
once: :func:`froude_krylov_sample`, the per-ship kernel. The composed loop calls it in every RK
stage; the numpy loop and every other caller call its batch over ships
(:func:`shipgnc.derive.per_ship`), so there is no second form to keep equal.

**Cost.** Per component and stage the loads need three sin/cos pairs — of the phase θᵢ and of
the hull-shape arguments uᵢ, vᵢ — evaluated by :func:`fast_sincos` in one vectorised loop over
the components (a two-part reduction and five-term polynomials, within 5.0e-15 of libm; no libm
call); whether every argument lies within its fast reduction (:data:`SINCOS_LIMIT`) is one bound
per ship and stage (|θᵢ| ≤ ω_max|t| + k_max(|n| + |e|) + |φ|_max), not a test per component.
sinc and j₁ need 1/uᵢ and 1/vᵢ: a long-crested sea takes them from the row 1/(½kᵢL) of
:data:`ROWS` (1/uᵢ = (1/(½kᵢL))/cos β, 1/vᵢ = (1/(½kᵢL))·L/(B sin β), two divisions per call), a
short-crested one from one division per component (1/(uᵢvᵢ)). Those sin/cos are the cost
(benchmarks/bench_waves.py). Measured on one 4.1 GHz AVX-512 core, 200 components, long-crested,
with the earlier sin/cos of libm's last bit (three-part reduction, fdlibm's six-term kernels) and a division
per argument: ≈ 2.7 ns (≈ 11 cycles) per component and stage, 2.1–2.2 CPU µs per ship-step,
eight components per 512-bit vector; one sin/cos pair alone in such a loop takes ≈ 2.2 cycles
per argument, so the three pairs are ≈ 7 of the 11 cycles. With :func:`fast_sincos` and the
reciprocal row the kernel takes ≈ 430 instead of ≈ 540 ns per call and cybership-waves' composed
loop runs ≈ 25 % more ship-steps per CPU second (alternating pairs). It is not memory bound: a
ship's state (14 rows of n numbers, 22 KB at n = 200) stays in the L1 cache while the composed
loop runs that ship through its steps, and one ship takes the same CPU time per ship-step as 500
or 1 000.

The price is the last bits: the loads stay within 3e-14 of the direct libm sum's scale over a
run (tests/test_waves.py), but the course-changing runs of cybership-waves amplify any last-bit
change — as much as an initial heading changed by 10⁻¹³° does (the rate-limited rudder flips on
the sign of command − rudder; the sliding-mode runs chatter) — to per-cent changes of their
quality indices, so those are one realisation's figures (document 003's page gives the band).

Tried and not kept: rearrangements with the same results to the bit (the three pairs in separate
loops, the hull-shape factors in a loop before the phases) were slower. A rotation recurrence of
the phase (e^{iθᵢ} advanced by e^{iωᵢΔt} from stage to stage) does not remove a sin/cos:
θᵢ = ωᵢt − kᵢ·r + φᵢ moves with the ship's position r, and e^{−ikᵢ·Δr} differs per component
and stage, so it needs a sin/cos (or a polynomial of the same length) of its own. The hull-shape
arguments move with ψ only, but ½kᵢL reaches ≈ 70 rad in cybership-waves' sea, so rotating
e^{iuᵢ} from a reference heading by a short series (|Δuᵢ| ≤ 1/8) holds for 0.1–0.2° of heading
change only; applied at every call it was ≈ 13 % faster than that earlier sin/cos, but ≈ 3 % slower
than :func:`fast_sincos`.
"""

from __future__ import annotations

import math

import numba
from llvmlite import ir
from numba.core import cgutils, types
from numba.core.extending import intrinsic

from shipgnc.kernels import JIT_OPTIONS, kernel_function

#: rows of a ship's per-component block in the kernel's state (each ``n_components`` long):
#: the sea (ωᵢ, φᵢ, kᵢcos χᵢ, kᵢsin χᵢ, ½kᵢL, ½kᵢB, χᵢ), the weights −2g_X ρgDᵢaᵢ, −2g_Y ρgDᵢaᵢ,
#: g_N ρgDᵢaᵢ, and 1/(½kᵢL) (so a long-crested sea needs no division per component for sinc, j₁)
ROWS = ("omega", "phase", "k_north", "k_east", "half_kL", "half_kB", "chi", "wX", "wY", "wN",
        "inv_half_kL")
#: scratch rows after them: the per-component terms of X, Y and N, summed by :func:`pairwise_sum3`
N_SCRATCH = 3
#: numbers after the scratch rows, bounds of the arguments: [ω_max, max |kᵢcos χᵢ|, |kᵢsin χᵢ|,
#: |φ|_max, max(½kᵢL, ½kᵢB, |χᵢ|)] (so |θᵢ|, |uᵢ|, |vᵢ|, |βᵢ| are bounded by one number per call)
N_BOUNDS = 4


def state_width(n_components: int) -> int:
    """Length of a ship's kernel state for ``n_components`` components."""
    return (len(ROWS) + N_SCRATCH) * n_components + N_BOUNDS


@intrinsic
def _lane_sums3(typingctx, a, lo, m, stride):
    """Three 8-lane partial-sum blocks at once: for each row k = 0, 1, 2 (starting at
    lo + k·stride) lane l adds a[lo + k·stride + 8i + l] for i = 0 … m − 1 in that order, and the
    lanes are combined as ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7)) — numpy's pairwise
    block written as one 8-wide vector add per step (plain IEEE adds, no reassociation). numba
    does not SLP-vectorise the scalar form."""
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
    each in the order of numpy's ``np.sum`` along a contiguous axis (its pairwise summation: eight
    interleaved partial sums in blocks of at most 128, halves above that; a deterministic order,
    and accurate to O(log n) roundings); the three rows' blocks are added side by side, eight
    lanes per vector add (:func:`_lane_sums3`)."""
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
# reduction by π/2 in two parts (p₁ + p₂ ≈ π/2; p₁ has 33 significant bits, so q·p₁ is exact for
# |q| < 2²⁰) and polynomials on |r| ≤ π/4 (:func:`fast_sincos`)
_PIO2_1 = 1.57079632673412561417e+00
_PIO2_2 = 6.07710050630396597660e-11
_INV_PIO2 = 6.36619772367581382433e-01
#: 1.5·2⁵²: (y + _ROUND) − _ROUND rounds |y| < 2⁵¹ to the nearest integer
_ROUND = 6755399441055744.0
#: beyond this |x| the reduction loses bits: those arguments go to libm
SINCOS_LIMIT = 1.0e6


@intrinsic
def _bits(typingctx, x):
    """The IEEE-754 bits of a float64 as an int64 (a bit cast, no conversion)."""
    if x != types.float64:
        return None

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.IntType(64))

    return types.int64(types.float64), codegen


@intrinsic
def _from_bits(typingctx, i):
    """The float64 whose IEEE-754 bits are the int64 ``i``."""
    if i != types.int64:
        return None

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.DoubleType())

    return types.float64(types.int64), codegen


#: the sign bit of a float64's bits
_SIGN_BIT = -(2 ** 63)


_F1, _F2, _F3 = -0.16666666666634747, 0.008333333325725155, -0.0001984126403207385
_F4, _F5 = 2.75553964597516e-06, -2.4764148998579136e-08
_G1, _G2, _G3 = 0.041666666666602785, -0.0013888888878344516, 2.4801581000292875e-05
_G4, _G5 = -2.755557190499262e-07, 2.0648019412154456e-09


@numba.njit(inline="always", **JIT_OPTIONS)
def fast_sincos(x):
    """(sin x, cos x) for |x| ≤ :data:`SINCOS_LIMIT`, branch-free: the wave loads' sin/cos.
    q = nearest integer to 2x/π by the 1.5·2⁵² rounding trick; the quadrant is read from the low
    bits of the rounded sum x·2/π + 1.5·2⁵² itself (its last mantissa bit is worth 1 and 1.5·2⁵²
    has none below 2⁵¹, so they are q's two's-complement bits: no float → int conversion; bit 0
    swaps sin and cos, bit 1 of m and of m + 1 flips their signs, set by flipping the sign bit);
    a two-part Cody–Waite reduction r = (x − q·p₁) − q·p₂ (p₁ + p₂ ≈ π/2) and
    five-term polynomials on |r| ≤ π/4:

        sin r ≈ r + r·z·(F₁ + F₂z + … + F₅z⁴),   cos r ≈ 1 − z/2 + z²·(G₁ + G₂z + … + G₅z⁴),
        z = r²,

    whose coefficients F₁…F₅, G₁…G₅ were fitted by least squares on |r| ≤ π/4 (near the
    Taylor coefficients (−1)ᵏ/(2k+1)!, (−1)^{k+1}/(2k+2)!; the fifth differs by ≈ 1 %, which
    spreads the truncation error over the interval). Measured max |Δ| against libm (math.sin,
    math.cos) on 4·10⁶ uniform arguments per range and on the multiples of π/4 and their
    neighbours: 4.0e-15 for |x| ≤ 10⁴, 5.0e-15 for |x| ≤ 10⁶ (the dropped third part of the
    reduction grows with |x|); tests/test_compose_cybership.py checks 1e-14. The loads move in their last
    bits only (≈ 3e-14 of their scale over a run)."""
    qb = x * _INV_PIO2 + _ROUND
    q = qb - _ROUND
    r = x - q * _PIO2_1
    r = r - q * _PIO2_2
    z = r * r
    s = r + r * z * (_F1 + z * (_F2 + z * (_F3 + z * (_F4 + z * _F5))))
    c = 1.0 - 0.5 * z + z * z * (_G1 + z * (_G2 + z * (_G3 + z * (_G4 + z * _G5))))
    m = _bits(qb)
    a = c if m & 1 else s
    b = s if m & 1 else c
    return (_from_bits(_bits(a) ^ ((m << 62) & _SIGN_BIT)),
            _from_bits(_bits(b) ^ (((m + 1) << 62) & _SIGN_BIT)))


@numba.njit(inline="always", **JIT_OPTIONS)
def _sinc_j1(s, c, u, inv):
    """sinc u = sin u/u and j₁(u) = (sin u − u cos u)/u² from s = sin u, c = cos u and inv = 1/u
    (x/u → x·(1/u): round-off only, as arcp allows), without divisions or branches; the series
    1 − u²/6, u(1/3 − u²/30) for |u| < 1e-3 (inv is then not read and may be anything)."""
    small = abs(u) < 1e-3
    u2 = u * u
    sinc = 1.0 - u2 * (1.0 / 6.0) if small else s * inv
    j1 = u * (1.0 / 3.0 - u2 * (1.0 / 30.0)) if small else (sinc - c) * inv
    return sinc, j1


@numba.njit(inline="always", **JIT_OPTIONS)
def _away_from_zero(u):
    """u, or 1 for |u| < 1e-3 (where :func:`_sinc_j1` takes its series): a safe divisor."""
    return 1.0 if abs(u) < 1e-3 else u


@numba.njit(inline="always", **JIT_OPTIONS)
def _terms(z, j, n, o_t, length, beam, L2, B2, s, c, s_u, c_u, s_v, c_v, u, v, inv_u, inv_v):
    """Component j's terms of X, Y and N into the scratch rows at ``o_t``, from the sin/cos of
    θ, u and v and the reciprocals inv_u = 1/u, inv_v = 1/v."""
    sinc_u, j1_u = _sinc_j1(s_u, c_u, u, inv_u)
    sinc_v, j1_v = _sinc_j1(s_v, c_v, v, inv_v)
    z[o_t + j] = z[7 * n + j] * (beam * s_u * sinc_v) * s
    z[o_t + n + j] = z[8 * n + j] * (length * s_v * sinc_u) * s
    z[o_t + 2 * n + j] = z[9 * n + j] * (L2 * s_v * j1_u - B2 * s_u * j1_v) * c


@kernel_function
def froude_krylov_sample(t, x, z, p, w, d):
    """[X_env, Y_env, N_env] of one ship at time ``t`` and stage state ``x``: document 003's
    seeded first-order Froude–Krylov loads on a box-shaped hull L × B × T (note 003-3.6; the
    closed-form integrals of :func:`~shipgnc.environment.waves.box_froude_krylov_transfer` per
    component, summed):

        θᵢ = ωᵢ t − (kᵢ cos χᵢ · n + kᵢ sin χᵢ · e) + φᵢ,   βᵢ = χᵢ − ψ,
        uᵢ = ½kᵢL cos βᵢ,   vᵢ = ½kᵢB sin βᵢ,
        X = Σ w_X,ᵢ B sin uᵢ sinc vᵢ sin θᵢ,   Y = Σ w_Y,ᵢ L sin vᵢ sinc uᵢ sin θᵢ,
        N = Σ w_N,ᵢ (L² sin vᵢ j₁(uᵢ) − B² sin uᵢ j₁(vᵢ)) cos θᵢ,

    with w_X,ᵢ = −2g_X ρgDᵢaᵢ, w_Y,ᵢ = −2g_Y ρgDᵢaᵢ, w_N,ᵢ = g_N ρgDᵢaᵢ, Dᵢ = (1 − e^{−kᵢT})/kᵢ,
    sinc u = sin u/u, j₁(u) = (sin u − u cos u)/u² (series for |u| < 1e-3), deep water
    kᵢ = ωᵢ²/g; a long-crested sea has one χ. The sums are taken in numpy's pairwise order
    (:func:`pairwise_sum3`). Cost and the exact reformulations: the module docstring.

    ``z`` holds the ship's sea (:data:`ROWS`), the scratch rows of the terms and the bounds of
    the arguments (:data:`N_BOUNDS`); ``p`` = [n_components, L, B, long-crested, i_north, i_east,
    i_psi]; ``w`` is not read."""
    n = int(p[0])
    length, beam = p[1], p[2]
    north, east, psi = x[int(p[4])], x[int(p[5])], x[int(p[6])]
    L2, B2 = length ** 2, beam ** 2
    o_t = len(ROWS) * n
    o_b = o_t + N_SCRATCH * n
    # every argument within the fast reduction (|β| too: ψ of a runaway heading)? one bound
    bound = max(z[o_b] * abs(t) + z[o_b + 1] * (abs(north) + abs(east)) + z[o_b + 2],
                z[o_b + 3] + abs(psi))
    long_crested = p[3] != 0.0
    if bound <= SINCOS_LIMIT and long_crested:  # one direction: β per ship
        beta = z[6 * n] - psi
        cos_b, sin_b = math.cos(beta), math.sin(beta)
        # 1/uᵢ = (1/(½kᵢL))/cos β, 1/vᵢ = (1/(½kᵢL))·L/(B sin β): two divisions per call
        ru = 1.0 / cos_b
        rv = length / (beam * sin_b)
        for j in range(n):
            theta = z[j] * t - (z[2 * n + j] * north + z[3 * n + j] * east) + z[n + j]
            u = z[4 * n + j] * cos_b
            v = z[5 * n + j] * sin_b
            s, c = fast_sincos(theta)
            s_u, c_u = fast_sincos(u)
            s_v, c_v = fast_sincos(v)
            _terms(z, j, n, o_t, length, beam, L2, B2, s, c, s_u, c_u, s_v, c_v, u, v,
                   z[10 * n + j] * ru, z[10 * n + j] * rv)
    elif bound <= SINCOS_LIMIT:
        for j in range(n):
            theta = z[j] * t - (z[2 * n + j] * north + z[3 * n + j] * east) + z[n + j]
            sin_b, cos_b = fast_sincos(z[6 * n + j] - psi)
            u = z[4 * n + j] * cos_b
            v = z[5 * n + j] * sin_b
            s, c = fast_sincos(theta)
            s_u, c_u = fast_sincos(u)
            s_v, c_v = fast_sincos(v)
            us, vs = _away_from_zero(u), _away_from_zero(v)
            inv = 1.0 / (us * vs)  # one division for 1/u and 1/v
            _terms(z, j, n, o_t, length, beam, L2, B2, s, c, s_u, c_u, s_v, c_v, u, v,
                   vs * inv, us * inv)
    else:  # arguments beyond the fast reduction (a run of hours, a runaway heading): libm
        for j in range(n):
            theta = z[j] * t - (z[2 * n + j] * north + z[3 * n + j] * east) + z[n + j]
            beta = (z[6 * n] if long_crested else z[6 * n + j]) - psi
            u = z[4 * n + j] * math.cos(beta)
            v = z[5 * n + j] * math.sin(beta)
            _terms(z, j, n, o_t, length, beam, L2, B2, math.sin(theta), math.cos(theta),
                   math.sin(u), math.cos(u), math.sin(v), math.cos(v), u, v,
                   1.0 / _away_from_zero(u), 1.0 / _away_from_zero(v))
    d[0], d[1], d[2] = pairwise_sum3(z, o_t, n, n)
