"""The level set round a coastline: the reachability front of note 002-2.9.2 (Lolla et al., ICRA 2012;
WENO5, Godunov upwinding, TVD-RK3) with land cells frozen — :func:`shipgnc.routing.levelset.reachability`
itself, with the geo router's settings.

That level set clips φ to a narrow band of ``band`` cells about the front (Sethian 1999, *Level set methods
and fast marching methods*; see :mod:`shipgnc.routing.levelset`): started from the plain signed
distance to the first front, φ(x, 0) ≈ |x − A| everywhere and φ_t = −V‖∇φ‖ lowers φ at every cell from the
first step — behind a wall of frozen land too, where φ then reaches zero at the straight-line time as if the
land were not there (and earlier still where the frozen cells bend the gradients). With the band, ∇φ = 0
ahead of it and φ falls only where the front has come: behind land it arrives by the way round. A gridded,
time-varying current is interpolated onto the level-set grid one time slice at a time, so a step costs a
blend of two slices.

The geo settings: the first front a short one (r₀ = 1.2 h, 360 short-time extremals of 20 steps), since
the start may lie a few cells off the coast; the departure is t = 0 on the plane field's clock (the geo
router shifts the field's time axis by the departure, :meth:`~.router.GeoProblem.field_from`).
"""

from __future__ import annotations


def reach_round_land(field, speed, start, target, domain, spacing, obstacles, *, horizon, band=6, cfl=0.5):
    """(:class:`~shipgnc.routing.levelset.LevelSetResult` with the recovered route, frozen mask): the level
    set from ``start`` to ``target`` round ``obstacles`` (plane polygons, (north, east) m), departing at
    t = 0 on ``field``'s clock; ``band`` cells of narrow band, ``horizon`` [s]."""
    from shipgnc.routing.levelset import reachability

    res = reachability(field, speed, start, target, domain, spacing, t0=0.0, horizon=horizon,
                       obstacles=obstacles or None, cfl=cfl, band=band, r0=1.2 * spacing, n_rays=360,
                       ray_steps=20)
    return res, res.frozen
