"""Closed forms and exact checks of document 002: the linear shear (note 002-2.5), uniform and tidal
currents (2.10, F1, F1b, 2.9.5), a rigid rotation (a Rankine vortex's core) and the straight course
(F6). SI throughout: m, s, m/s, rad, k in 1/s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from shipgnc.errors import require

TWO_PI = 2.0 * math.pi


# --------------------------------------------------------------------------- linear shear (2.6)–(2.8)
def shear_heading(u_f, k, tau):
    """u(t) = atan2(sin u_f, cos u_f + k τ sin u_f), τ = t_f − t (2.6); in [0, 2π)."""
    s = np.sin(u_f)
    return np.mod(np.arctan2(s, np.cos(u_f) + k * np.asarray(tau, float) * s), TWO_PI)


def shear_time(u0, u_f, k):
    """t_f = (cot u₀ − cot u_f)/k (2.7) [s]."""
    return (1.0 / math.tan(u0) - 1.0 / math.tan(u_f)) / k


def _F(u, u_f):
    cot = 1 / np.tan(u)
    return 0.5 * np.log(np.abs(np.tan(u / 2))) - cot / math.sin(u_f) + cot / (2 * np.sin(u))


def shear_path(u, u_f, speed, k, target, s=0.0):
    """Position (north, east) on the extremal with final heading u_f, parameterised by the heading u (2.8)."""
    u = np.asarray(u, float)
    b1, b2 = target
    x1 = b1 + speed / k * (1 / math.sin(u_f) - 1 / np.sin(u))
    x2 = (b2 + speed / k * (_F(u, u_f) - _F(np.asarray(u_f), u_f))
          - (b1 - s) * (1 / np.tan(u) - 1 / math.tan(u_f)))
    return np.stack([x1, x2], axis=-1)


@dataclass(frozen=True)
class ShearSolution:
    duration: float  #: t_f [s]
    heading_start: float  #: u₀ [rad]
    heading_end: float  #: u_f [rad]; the document's α = u_f − π (Z3)


def shear_closed_form(speed, k, start, target, s=0.0, n_scan=7200) -> list[ShearSolution]:
    """All solutions of (2.7)–(2.8) through ``start`` (fastest first) for the shear v = (0, k (x_N − s)).

    From the first equation of (2.8): 1/sin u₀ = 1/sin u_f − k (A₁ − B₁)/V; u₀ lies in the half-plane of
    u_f with t_f > 0 in (2.7), on either branch of the arcsine (the second equation decides which, not the
    shorter t_f); the second equation of (2.8) is then a scalar equation in u_f, solved by a scan and
    Brent's method on each branch. Singular for sin u_f = 0 (due north or south): there use the numerical PMP.
    """
    from scipy.optimize import brentq

    require(k != 0, "shear.k", k, "the closed form needs k ≠ 0 (still water: straight line)")
    a1, a2 = start

    def u0_of(u_f, branch):
        """u₀ on ``branch`` (0: asin, 1: π − asin) of the first equation of (2.8), if t_f > 0."""
        inv = 1 / math.sin(u_f) - k * (a1 - target[0]) / speed
        if abs(inv) < 1.0:
            return None
        base = math.asin(1 / inv)  # inv has the sign of sin u₀
        u0 = np.mod(base if branch == 0 else math.pi - base, TWO_PI)
        # (2.6) keeps the heading in the half-plane of u_f: sin u never changes sign along an extremal
        same_side = math.sin(u0) * math.sin(u_f) > 0
        return u0 if same_side and shear_time(u0, u_f, k) > 0 else None

    def resid(u_f, branch):
        u0 = u0_of(u_f, branch)
        if u0 is None:
            return math.nan
        return float(shear_path(u0, u_f, speed, k, target, s)[1]) - a2

    grid = np.linspace(0, TWO_PI, n_scan, endpoint=False)[1:]
    grid = grid[np.abs(np.sin(grid)) > 1e-6]
    out = []
    for branch in (0, 1):  # both: the east equation picks the branch, not the shorter t_f
        vals = np.array([resid(u, branch) for u in grid])
        for i in range(grid.size - 1):
            r0, r1 = vals[i], vals[i + 1]
            if not (np.isfinite(r0) and np.isfinite(r1)) or r0 * r1 > 0:
                continue
            if np.sign(np.sin(grid[i])) != np.sign(np.sin(grid[i + 1])):
                continue
            try:
                u_f = brentq(resid, grid[i], grid[i + 1], args=(branch,), xtol=1e-15, rtol=1e-15)
            except ValueError:
                continue
            u0 = u0_of(u_f, branch)
            if u0 is None or abs(resid(u_f, branch)) > 1e-3:  # a pole (a sign change through ±∞)
                continue
            out.append(ShearSolution(shear_time(u0, u_f, k), float(u0), float(np.mod(u_f, TWO_PI))))
    return sorted(out, key=lambda z: z.duration)


# --------------------------------------------------------------------------- uniform currents (F1, F1b)
@dataclass(frozen=True)
class UniformSolution:
    reachable: bool
    duration: float | None  #: first arrival [s]
    heading: float | None  #: constant heading [rad]
    exit_time: float | None  #: when |c| > V: B leaves the drifting disc at this time (F1b)
    cone: tuple[float, float] | None  #: reachable bearings [rad] when |c| > V
    bearing: float  #: bearing of B from A [rad]
    closest_approach: float  #: min over t ≥ 0 of the distance from B to the reachable disc [m]
    closest_time: float
    reason: str = ""


def uniform_solution(speed, current, start, target) -> UniformSolution:
    """Minimum time in a uniform current c: smallest root of (c² − V²)t² − 2(d·c)t + d² = 0 (section 2.10).

    The reachable set at time t is the disc of radius Vt about A + ct; with |c| > V the target is reachable
    only inside the cone c ± arcsin(V/|c|), and only during a window (F1, F1b).
    """
    d = np.asarray(target, float) - np.asarray(start, float)
    c = np.asarray(current, float)
    cc, dc, dd = float(c @ c), float(d @ c), float(d @ d)
    a = cc - speed**2
    bearing = float(np.mod(math.atan2(d[1], d[0]), TWO_PI))
    cnorm = math.sqrt(cc)
    cone = None
    if cnorm > speed:
        half = math.asin(speed / cnorm)
        cdir = math.atan2(c[1], c[0])
        cone = (float(np.mod(cdir - half, TWO_PI)), float(np.mod(cdir + half, TWO_PI)))

    def gap(t):
        return float(np.hypot(*(d - c * t)) - speed * t)

    if dd == 0:
        return UniformSolution(True, 0.0, None, None, cone, bearing, 0.0, 0.0)
    roots: list[float] = []
    if abs(a) < 1e-15:
        if dc > 0:
            roots = [dd / (2 * dc)]
    else:
        disc = dc * dc - a * dd
        if disc >= 0:
            sq = math.sqrt(disc)
            roots = sorted(r for r in ((dc - sq) / a, (dc + sq) / a) if r > 0)
    if not roots:
        # closest approach of B to the drifting disc: minimise |d − ct| − Vt over t ≥ 0
        t_star = max(0.0, dc / cc) if cc > 0 else 0.0
        cands = [0.0, t_star]
        ts = min(cands, key=gap)
        reason = (f"current {cnorm:.4f} m/s exceeds ship speed {speed:.4f} m/s; target bearing "
                  f"{math.degrees(bearing):05.1f}° outside the reachable cone "
                  f"[{math.degrees(cone[0]):05.1f}°, {math.degrees(cone[1]):05.1f}°]" if cone else
                  "target not reachable")
        return UniformSolution(False, None, None, None, cone, bearing, max(gap(ts), 0.0), ts, reason)
    t = roots[0]
    w = (d - c * t) / (speed * t)
    heading = float(np.mod(math.atan2(w[1], w[0]), TWO_PI))
    exit_time = roots[1] if (a > 0 and len(roots) > 1) else None
    return UniformSolution(True, t, heading, exit_time, cone, bearing, 0.0, t)


def tidal_uniform_solution(speed, drift, start, target, horizon, n_scan=20000):
    """First t with ‖B − A − ∫₀ᵗ c‖ = V t for a time-varying uniform current (note 002-2.9.5).

    ``drift(t)`` returns ∫₀ᵗ c dt (shape (..., 2)) [m]; returns (t_f, constant heading) or None.
    """
    from scipy.optimize import brentq

    d = np.asarray(target, float) - np.asarray(start, float)
    t = np.linspace(0.0, horizon, n_scan)

    def g(tt):
        return np.hypot(*np.moveaxis(d - drift(tt), -1, 0)) - speed * tt

    val = g(t)
    idx = np.flatnonzero((val[:-1] > 0) & (val[1:] <= 0))
    if idx.size == 0:
        return None
    tf = brentq(lambda x: float(g(np.asarray(x))), t[idx[0]], t[idx[0] + 1], xtol=1e-10, rtol=1e-15)
    w = d - drift(np.asarray(tf))
    return tf, float(np.mod(math.atan2(w[1], w[0]), TWO_PI))


def rotation_time(omega, speed, a, b) -> float:
    """Minimum time through a rigid rotation ω [rad/s] (a Rankine vortex's core) from A to B on a line
    through the centre, on opposite sides at distances a and b [m], the route staying in the rotation.

    In the frame turning with the water the route is a straight line sailed at V towards B, which runs
    backwards round the centre there: T is the first root of a² + b² + 2ab·cos(ωT) = (VT)² — scale-free
    (lengths × s and ω fixed give T × s)."""
    from scipy.optimize import brentq

    def gap(t):
        return math.sqrt(a * a + b * b + 2 * a * b * math.cos(omega * t)) - speed * t

    t, step = 0.0, (a + b) / speed / 200.0  # the gap starts at a + b > 0; its first zero, bracketed
    while gap(t + step) > 0:
        t += step
    return brentq(gap, t, t + step, xtol=1e-12 * (a + b) / speed)


# --------------------------------------------------------------------------- straight course (F6)
@dataclass(frozen=True)
class StraightCourse:
    feasible: bool
    infeasible: list[tuple[float, float]]  #: fractions of AB (from A) where no heading holds the line
    duration: float | None  #: time along AB when feasible [s]
    message: str


def straight_course(field, speed, start, target, t=0.0, n=4001) -> StraightCourse:
    """Can a ship hold the straight line AB (crab angle), and how long does it take? (F6)

    At each point of AB the current's cross-track part must stay below V and the resulting speed along
    the line, c∥ + √(V² − c⊥²), must be positive. Infeasible stretches are reported as fractions of AB,
    with their ends found by Brent's method; the field is taken at time ``t``.
    """
    from scipy.integrate import quad
    from scipy.optimize import brentq

    a = np.asarray(start, float)
    b = np.asarray(target, float)
    length = float(np.hypot(*(b - a)))
    require(length > 0, "target", b.tolist(), "must differ from the start for a straight course")
    along = (b - a) / length
    normal = np.array([-along[1], along[0]])

    def margin(s):
        x = a + np.multiply.outer(np.asarray(s, float), b - a)
        c = field.velocity(t, x[..., 0], x[..., 1])
        cp = c @ normal
        cl = c @ along
        root = np.sqrt(np.maximum(speed**2 - cp**2, 0.0))
        return np.minimum(speed - np.abs(cp), cl + root)

    s = np.linspace(0.0, 1.0, n)
    m = margin(s)
    bad = m <= 0
    intervals = []
    k = 0
    while k < n:
        if bad[k]:
            j = k
            while j + 1 < n and bad[j + 1]:
                j += 1
            lo = 0.0 if k == 0 else brentq(lambda z: float(margin(z)), s[k - 1], s[k], xtol=1e-14)
            hi = 1.0 if j == n - 1 else brentq(lambda z: float(margin(z)), s[j], s[j + 1], xtol=1e-14)
            intervals.append((float(lo), float(hi)))
            k = j + 1
        else:
            k += 1
    if intervals:
        parts = ", ".join(f"{100 * lo:.2f}–{100 * hi:.2f} %" for lo, hi in intervals)
        return StraightCourse(False, intervals, None,
                              f"straight course infeasible over {parts} of AB from the start: the current "
                              "across the line exceeds the ship speed or sets the ship back")

    def ground_speed(z):
        x = a + z * (b - a)
        c = field.velocity(t, x[0], x[1])
        cp, cl = float(c @ normal), float(c @ along)
        return cl + math.sqrt(speed**2 - cp**2)

    dur, _ = quad(lambda z: length / ground_speed(z), 0.0, 1.0, limit=200, epsabs=0, epsrel=1e-12)
    return StraightCourse(True, [], float(dur), f"straight course feasible: {dur:.1f} s")
