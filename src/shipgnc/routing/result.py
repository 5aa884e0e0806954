"""The router's result (note 002-2.9.6): one object for a route or an explicit, worded failure (note
002-2.8)."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from dataclasses import field as dc_field

import numpy as np

from shipgnc.errors import ShipGNCError

TWO_PI = 2.0 * math.pi


class Unreachable(ShipGNCError):
    """The target cannot be reached (F1): CLI exit status 3; the message is the one-line reason."""

    exit_code = 3

    def __init__(self, result: RouteResult):
        super().__init__(result.reason)
        self.result = result


@dataclass
class LegPlan:
    """Constant-heading legs approximating the optimal heading programme (note 002-2.9.6)."""

    times: np.ndarray  #: leg start times [s], plus the arrival time as the last entry
    headings: np.ndarray  #: one heading per leg [rad]
    duration: float  #: arrival time after t₀ with these legs [s]
    penalty: float  #: duration − optimal duration [s]
    miss: float  #: |x(arrival) − B| [m]

    def heading(self, t):
        """Piecewise-constant ψ(t) [rad]."""
        k = np.searchsorted(self.times, np.asarray(t, float), side="right") - 1
        k = np.clip(k, 0, self.headings.size - 1)
        return self.headings[k]


@dataclass
class RouteResult:
    """A solved (or unreachable) route; SI throughout. ``to_json()`` gives the keys of note 002-2.9.6."""

    reachable: bool
    start: np.ndarray
    target: np.ndarray
    speed: float
    t0: float = 0.0
    time_s: float | None = None  #: t_f − t₀ [s]
    heading_start: float | None = None  #: u(t₀) [rad]
    heading_end: float | None = None  #: u(t_f) [rad]
    miss_m: float | None = None
    method: str = "pmp"
    extremals: list[dict] = dc_field(default_factory=list)  #: every extremal found: time_s, headings, status
    #: the extremals themselves (``pmp.Extremal``: ``sample``, ``position``), for figures; not in JSON
    extremal_paths: list = dc_field(default_factory=list, repr=False)
    #: {"method", "time_s", "rel_diff", and for the level set "agrees", "tolerance"} or None
    global_check: dict | None = None
    reason: str | None = None
    notes: list[str] = dc_field(default_factory=list)  #: failure modes and remarks, in words (note 002-2.8)
    grid_spacing: float | None = None  #: of the global method [m]
    closest_approach_m: float | None = None
    closest_time_s: float | None = None
    radius: float = 0.0  #: disc target radius [m] (Z12)
    field: object = dc_field(default=None, repr=False)
    path: object = dc_field(default=None, repr=False)  #: callable t -> (north, east) and heading(t)
    isochrones: object = dc_field(default=None, repr=False)  #: (times [s], north grid, east grid, phi stack)
    waypoints: list = dc_field(default_factory=list)  #: obstacle vertices the route touches [m]

    # ------------------------------------------------------------------ route access
    @property
    def t_end(self) -> float:
        return self.t0 + (self.time_s or 0.0)

    def heading(self, t):
        """ψ(t) [rad], the continuous heading programme (the reference for an autopilot)."""
        if self.path is None:
            return np.full(np.shape(t), self.heading_start if self.heading_start is not None else 0.0)
        return self.path.heading(t)

    def position(self, t):
        """Route position (north, east) [m] at clock time(s) t [s], t₀ … t₀ + time_s: every route (extremal,
        level set, graph, chain) takes the field's clock, not the time since departure."""
        if self.path is None:
            return np.broadcast_to(self.start, (*np.shape(t), 2)).copy()
        return self.path.position(t)

    def heading_schedule(self, n: int = 1001):
        """(t [s], ψ [rad]) on n instants from t₀ to t_f, for a heading autopilot (note 002-2.9.6)."""
        t = np.linspace(self.t0, self.t_end, n)
        return t, self.heading(t)

    def sample(self, n: int = 1001):
        """(t, north, east, heading) arrays along the route, on n clock times t from t₀ to t₀ + time_s."""
        t = np.linspace(self.t0, self.t_end, n)
        x = self.position(t)
        return t, x[:, 0], x[:, 1], self.heading(t)

    def constant_heading_legs(self, n_legs: int = 4) -> LegPlan:
        """Replace ψ(t) by ``n_legs`` constant-heading legs of equal duration (note 002-2.9.6).

        The leg headings and the arrival time are re-optimised (SLSQP: minimum time subject to reaching
        B), starting from the circular mean of ψ(t) over each leg; returns the plan and its time penalty.
        """
        from scipy.integrate import solve_ivp
        from scipy.optimize import minimize

        if not self.reachable or not self.time_s:
            raise ShipGNCError("constant_heading_legs: no route to approximate")
        fld, V = self.field, self.speed
        t_opt = self.time_s
        edges = np.linspace(0.0, 1.0, n_legs + 1)
        h0 = []
        for a, b in itertools.pairwise(edges):
            psi = self.heading(self.t0 + t_opt * np.linspace(a, b, 50))
            h0.append(math.atan2(np.mean(np.sin(psi)), np.mean(np.cos(psi))))

        def end_point(z):
            heads, dur = z[:-1], z[-1]
            x = np.array(self.start, float)
            for j in range(n_legs):
                ta, tb = self.t0 + dur * edges[j], self.t0 + dur * edges[j + 1]
                e = np.array([math.cos(heads[j]), math.sin(heads[j])])
                sol = solve_ivp(lambda t, y, e=e: V * e + fld.velocity(t, y[0], y[1]), (ta, tb), x,
                                rtol=1e-10, atol=1e-6)
                x = sol.y[:, -1]
            return x - self.target

        scale = max(float(np.hypot(*(self.target - self.start))), 1.0)
        z0 = np.array([*h0, t_opt])
        res = minimize(lambda z: z[-1] / t_opt, z0, method="SLSQP",
                       constraints=[{"type": "eq", "fun": lambda z: end_point(z) / scale}],
                       options={"maxiter": 100, "ftol": 1e-12})
        z = res.x
        miss = float(np.hypot(*end_point(z)))
        times = self.t0 + z[-1] * edges
        return LegPlan(times, np.mod(z[:-1], TWO_PI), float(z[-1]), float(z[-1] - t_opt), miss)

    # ------------------------------------------------------------------ output
    def to_json(self) -> dict:
        """The keys of note 002-2.9.6 (SI): reachable, time_s, time_h, heading_start_deg, ...

        ``reachable`` is true (a route), false (none of duration ≤ the horizon) or null when the answer is
        undecided (a search stopped by its effort bound or unable to resolve the scale; ``reason`` says
        which and how far it looked)."""
        def deg(x):
            return None if x is None else float(np.mod(math.degrees(x), 360.0))

        undecided = not self.reachable and str(self.reason or "").startswith("undecided")
        out = {
            "reachable": None if undecided else bool(self.reachable),
            "time_s": None if self.time_s is None else float(self.time_s),
            "time_h": None if self.time_s is None else float(self.time_s / 3600.0),
            "heading_start_deg": deg(self.heading_start),
            "heading_end_deg": deg(self.heading_end),
            "miss_m": None if self.miss_m is None else float(self.miss_m),
            "method": self.method,
            "extremals": sorted(float(e["time_s"]) for e in self.extremals),
            "global_check": self.global_check,
            "t0_s": float(self.t0),
            "grid_spacing_m": self.grid_spacing,
            "extremal_details": self.extremals,
            "notes": list(self.notes),
        }
        if self.radius:
            out["target_radius_m"] = float(self.radius)
        if self.waypoints:
            out["via_m"] = [[float(v) for v in w] for w in self.waypoints]
        if not self.reachable:
            out["reason"] = self.reason
            out["closest_approach_m"] = self.closest_approach_m
            out["closest_approach_time_s"] = self.closest_time_s
        return out

    def to_dataset(self, n: int = 1001):
        """The route as an ``xarray.Dataset`` on time (note 002-2.9.6), units in attrs."""
        import xarray as xr

        t, north, east, psi = self.sample(n)
        v = self.field.velocity(t, north, east) if self.field is not None else np.zeros((t.size, 2))
        vel = self.speed * np.stack([np.cos(psi), np.sin(psi)], axis=-1) + v
        sog = np.hypot(vel[:, 0], vel[:, 1])
        cog = np.mod(np.arctan2(vel[:, 1], vel[:, 0]), TWO_PI)

        def var(x, unit, long):
            return ("time", x, {"units": unit, "long_name": long})

        ds = xr.Dataset(
            {"north": var(north, "m", "north"), "east": var(east, "m", "east"),
             "heading": var(psi, "rad", "heading through water, clockwise from north"),
             "course": var(cog, "rad", "course over ground"),
             "speed_over_ground": var(sog, "m/s", "speed over ground"),
             "current_north": var(v[:, 0], "m/s", "current north"),
             "current_east": var(v[:, 1], "m/s", "current east")},
            coords={"time": ("time", t, {"units": "s"})},
            attrs={"method": self.method, "time_s": float(self.time_s or 0.0), "speed_mps": self.speed})
        return ds
