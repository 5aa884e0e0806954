"""The level set round a coastline: the reachability front of note 002-2.9.2 (Lolla et al., ICRA 2012;
WENO5, Godunov upwinding, TVD-RK3, the compiled right-hand side of :mod:`shipgnc.routing.levelset`) with
land cells frozen, started from a **clipped** signed distance.

Why clipped: started from the plain signed distance to the first front, φ(x, 0) ≈ |x − A| everywhere, and
φ_t = −V‖∇φ‖ lowers φ at every cell from the first step — behind a wall of frozen land too, where φ then
reaches zero at the straight-line time as if the land were not there (and earlier still where the frozen
cells bend the gradients). With φ clipped to a band of ``band`` cells about the front (Sethian 1999,
*Level set methods and fast marching methods*, §7 "narrow band"), ∇φ = 0 ahead of the band and φ falls
only where the front has come: behind land it arrives by the way round.
"""

from __future__ import annotations

import math

import numpy as np

TWO_PI = 2.0 * math.pi


def _on_grid(field, nn, ee, horizon):
    """The field's time slices bilinearly on the level-set grid (those up to the horizon): the grid's
    velocity at any t is then their linear interpolation, as :class:`GriddedCurrent` interpolates."""
    times = getattr(field, "times", None)
    if field.steady or times is None or times.size == 1 or not hasattr(field, "_slice"):
        return field._velocity(0.0, nn, ee)[None], None
    lo = max(int(np.searchsorted(times, 0.0, side="right")) - 1, 0)
    hi = min(int(np.searchsorted(times, horizon, side="left")) + 1, times.size - 1)
    lo = min(lo, times.size - 2)
    hi = max(hi, lo + 1)
    (n0, n1), (e0, e1) = field.bounds
    fn, fe = np.clip(nn.ravel(), n0, n1), np.clip(ee.ravel(), e0, e1)
    slices = np.stack([field._slice(k, fn, fe, False) for k in range(lo, hi + 1)]).reshape(
        hi - lo + 1, *nn.shape, 2)
    return slices, np.asarray(times[lo:hi + 1], float)


def reach_round_land(field, speed, start, target, domain, spacing, obstacles, *, horizon, band=6, cfl=0.5):
    """(:class:`~shipgnc.routing.levelset.LevelSetResult` with the recovered route, frozen mask)."""
    from shipgnc.routing import levelset as L
    from shipgnc.routing import pmp
    from shipgnc.routing.obstacles import inside_any

    start, target = np.asarray(start, float), np.asarray(target, float)
    (n0, n1), (e0, e1) = domain
    north, east = L._axis(target[0], n0, n1, spacing), L._axis(target[1], e0, e1, spacing)
    if field.bounds is not None:
        (b0, b1), (c0, c1) = field.bounds
        north = north[(north >= b0) & (north <= b1)]
        east = east[(east >= c0) & (east <= c1)]
    nn, ee = np.meshgrid(north, east, indexing="ij")
    ib, jb = int(np.argmin(np.abs(north - target[0]))), int(np.argmin(np.abs(east - target[1])))
    dist = float(np.hypot(*(target - start)))
    r0 = 1.2 * spacing
    t_init = r0 / speed
    ends = pmp.integrate_family(field, speed, start, np.linspace(0, TWO_PI, 360, endpoint=False), 0.0, t_init,
                                20)[-1]
    cap = band * spacing
    phi = np.minimum(L._signed_distance(ends, nn, ee, spacing), cap)
    frozen = inside_any(obstacles, nn, ee) if obstacles else np.zeros(nn.shape, bool)
    speed_grid = np.where(frozen, 0.0, speed)
    vmax = field.max_speed(((north[0], north[-1]), (east[0], east[-1])), 0.0)
    slices, times = _on_grid(field, nn, ee, horizon)
    slices[:, frozen] = 0.0
    out = np.empty_like(phi)

    def rate(t, ph):
        if times is None:
            v = slices[0]
        else:
            k = int(np.clip(np.searchsorted(times, t, side="right") - 1, 0, times.size - 2))
            w = min(max((t - times[k]) / (times[k + 1] - times[k]), 0.0), 1.0)
            v = (1 - w) * slices[k] + w * slices[k + 1]
        vn, ve = v[..., 0], v[..., 1]
        L._front_rate_kernel(L._pad3(ph), spacing, speed_grid, vn, ve, out)
        return out.copy()

    dt = cfl * spacing / (speed + math.sqrt(2) * vmax)
    store_every = max(1, round(0.01 * dist / speed / dt))
    t = t_init
    snaps_t, snaps = [t], [phi.astype(np.float32)]
    hist_t, hist_phi = [t], [float(phi[ib, jb])]
    arrival, steps = None, 0
    max_steps = math.ceil((horizon - t_init) / dt) + 1
    with np.errstate(all="ignore"):
        while steps < max_steps:
            p1 = phi + dt * rate(t, phi)
            p2 = 0.75 * phi + 0.25 * (p1 + dt * rate(t + dt, p1))
            phi = phi / 3 + 2 / 3 * (p2 + dt * rate(t + dt / 2, p2))
            phi = np.minimum(phi, cap)  # keep the band: nothing ahead of it moves
            t += dt
            steps += 1
            hist_t.append(t)
            hist_phi.append(float(phi[ib, jb]))
            if steps % store_every == 0:
                snaps_t.append(t)
                snaps.append(phi.astype(np.float32))
            if hist_phi[-1] <= 0 < hist_phi[-2]:
                arrival = L._cubic_crossing(np.array(hist_t[-4:]), np.array(hist_phi[-4:]))
                snaps_t.append(t)
                snaps.append(phi.astype(np.float32))
                break
    closest = 0.0
    if arrival is None:
        reached = phi <= 0
        gap = np.hypot(nn - target[0], ee - target[1])
        closest = float(np.min(gap[reached])) if np.any(reached) else dist
    res = L.LevelSetResult(arrival, float(spacing), north, east, np.array(snaps_t), np.array(snaps), None,
                           closest, steps, [])
    if arrival is not None:
        res.route = L._recover(field, speed, start, target, res, 0.0, t_init, ends)
    return res, frozen
