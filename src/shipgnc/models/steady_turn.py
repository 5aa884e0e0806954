"""Steady turning of document 004's catamaran: the algebraic turn (S2), ω_max, the characteristic.

A steady turn is u̇ = v̇ = ṙ = 0 (notes 004-4.7 004-S2). It does not depend on the controller, J, T_u
or h. Two parameterisations:

* :func:`steady_turn` — for a given yaw rate r, solve (u, v, δ);
* :func:`steady_state_at_angle` — for a given thruster angle δ, solve (u, v, r) (the fixed-angle
  run S5; at δ = 90° it gives ω_max, :func:`omega_max`).

Both follow the branch continuous from straight running (δ = 0, u = top speed) by numerical
continuation with Newton steps, which avoids the spurious crab-wise root of ``si`` (β_NED ≈ −80°
at r = 0.08, open-loop unstable); the result is checked to have |β| < 45°.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from shipgnc.errors import ConfigError, require
from shipgnc.models.catamaran import Catamaran, CatamaranParams, R, U, V


@dataclass(frozen=True)
class SteadyTurn:
    """One steady turn: yaw rate, thruster angle, velocities, drift angle and diameter (SI)."""

    r: float
    delta: float
    u: float
    v: float

    @property
    def speed(self) -> float:
        return math.hypot(self.u, self.v)

    @property
    def beta(self) -> float:
        """Drift angle β_NED = atan2(v, u) [rad] (= −β of the document)."""
        return math.atan2(self.v, self.u)

    @property
    def diameter(self) -> float:
        """Turning diameter D_c = 2V/|r| [m] (inf on a straight line)."""
        return 2.0 * self.speed / abs(self.r) if self.r != 0 else math.inf

    def state(self) -> np.ndarray:
        """The model state [0, 0, 0, u, v, r, δ] (north, east, ψ at the origin) of this turn."""
        return np.array([0.0, 0.0, 0.0, self.u, self.v, self.r, self.delta])


def _params(vessel) -> CatamaranParams:
    if isinstance(vessel, Catamaran):
        return vessel.params
    if isinstance(vessel, CatamaranParams):
        return vessel
    raise ConfigError(f"vessel = {type(vessel).__name__}: need a Catamaran or CatamaranParams")


def _residual(model: Catamaran, u, v, r, delta) -> np.ndarray:
    x = np.array([0.0, 0.0, 0.0, u, v, r, delta])  # north, east, psi, u, v, r, delta
    p = model.params
    xdot = model.derivatives(x, np.zeros(1))
    return xdot[[U, V, R]] * np.array([p.m_x, p.m_y, p.J]) / (2.0 * p.T_v) / np.array([1.0, 1.0, p.L])


def _newton(fun, y0: np.ndarray, tol: float = 1e-14, max_iter: int = 50) -> np.ndarray | None:
    y = np.array(y0, dtype=float)
    for _ in range(max_iter):
        f = fun(y)
        jac = np.empty((3, 3))
        for j in range(3):
            step = 1e-7 * max(1.0, abs(y[j]))
            e = np.zeros(3)
            e[j] = step
            jac[:, j] = (fun(y + e) - fun(y - e)) / (2 * step)
        try:
            dy = np.linalg.solve(jac, -f)
        except np.linalg.LinAlgError:
            return None
        y = y + dy
        if not np.all(np.isfinite(y)):
            return None
        if np.max(np.abs(dy)) < tol * max(1.0, float(np.max(np.abs(y)))):
            return y
    return y if np.max(np.abs(fun(y))) < 1e-10 else None


def _continue(fun, y_start: np.ndarray, target: float, steps: int) -> np.ndarray:
    """Follow ``fun(y; s) = 0`` from s = 0 (solution ``y_start``) to s = target, halving on failure."""
    y, s, ds = y_start.copy(), 0.0, target / steps
    y_prev, s_prev = None, None
    while abs(target - s) > 0:
        s_next = s + ds if abs(ds) < abs(target - s) else target
        guess = y if y_prev is None else y + (y - y_prev) * (s_next - s) / (s - s_prev)
        sol = _newton(lambda yy, s_next=s_next: fun(yy, s_next), guess)
        if sol is None or abs(math.atan2(sol[1], sol[0])) >= math.pi / 4:
            ds /= 2.0
            if abs(ds) < abs(target) * 1e-9:
                raise ConfigError(f"steady turn: continuation failed near {s:.6g} (target {target:.6g}); "
                                  "no steady turn on the branch from straight running")
            continue
        y_prev, s_prev, y, s = y, s, sol, s_next
    return y


def steady_turn(vessel, r: float, *, steps: int = 40) -> SteadyTurn:
    """The steady turn at yaw rate ``r`` [rad/s]: (u, v, δ) with u̇ = v̇ = ṙ = 0 (note 004-S2).

    ``vessel`` is a :class:`Catamaran` or its parameters. Raises :class:`ConfigError` when no turn
    with |δ| < 90° exists on the branch from straight running (|r| beyond ω_max, printed sign).
    """
    p = _params(vessel)
    require(isinstance(r, (int, float)) and math.isfinite(r), "omega_ref", r,
            "must be a finite yaw rate [rad/s]")
    model = Catamaran(p.with_(delta_row="rate"))
    start = np.array([p.top_speed(), 0.0, 0.0])
    if r == 0:
        return SteadyTurn(0.0, 0.0, float(start[0]), 0.0)
    if p.coriolis == "printed":
        w_max = omega_max(p)
        require(abs(r) < w_max, "omega_ref", r,
                f"beyond the steady-turn limit omega_max = {w_max:.6g} rad/s (thruster angle at 90°)")
    y = _continue(lambda y, s: _residual(model, y[0], y[1], s, y[2]), start, float(r), steps)
    require(abs(y[2]) < math.pi / 2, "omega_ref", r, "the steady turn needs |delta| >= 90°")
    return SteadyTurn(float(r), float(y[2]), float(y[0]), float(y[1]))


def steady_state_at_angle(vessel, delta: float, *, steps: int = 40) -> SteadyTurn:
    """The steady turn with the thruster held at ``delta`` [rad] (fixed-angle run S5)."""
    p = _params(vessel)
    require(isinstance(delta, (int, float)) and math.isfinite(delta) and abs(delta) <= math.pi / 2,
            "delta", delta, "must be a finite angle within ±pi/2 rad")
    model = Catamaran(p.with_(delta_row="rate"))
    start = np.array([p.top_speed(), 0.0, 0.0])
    if delta == 0:
        return SteadyTurn(0.0, 0.0, float(start[0]), 0.0)
    y = _continue(lambda y, s: _residual(model, y[0], y[1], y[2], s), start, float(delta), steps)
    return SteadyTurn(float(y[2]), float(delta), float(y[0]), float(y[1]))


_OMEGA_MAX_CACHE: dict[tuple, float] = {}


def omega_max(vessel) -> float:
    """Largest steady yaw rate with |δ| ≤ 90°: the turn at δ = 90° (note 004-4.12 check 5) [rad/s].

    ω_max depends on the hull and the thrust only (not on J); for per-ship arrays of the
    uncertainty factors it is evaluated with the nominal masses (the factors scale m_x, m_y too,
    which move ω_max slightly).
    """
    p = _params(vessel)
    values = tuple(p.as_dict().values())
    if not all(isinstance(v, (int, float, str)) for v in values):
        p = p.with_(m_x_factor=1.0, m_y_factor=1.0, J_factor=1.0)
        values = tuple(p.as_dict().values())
    if values not in _OMEGA_MAX_CACHE:
        _OMEGA_MAX_CACHE[values] = abs(steady_state_at_angle(p, math.pi / 2).r)
    return _OMEGA_MAX_CACHE[values]


def turning_characteristic(vessel, deltas=None) -> dict[str, np.ndarray]:
    """Steady turns over thruster angles ``deltas`` [rad] (default 0…90° in 1° steps).

    Returns arrays ``delta``, ``r``, ``u``, ``v``, ``speed``, ``beta``, ``diameter``, one per angle,
    followed along the branch from straight running.
    """
    p = _params(vessel)
    deltas = np.radians(np.arange(0.0, 90.5, 1.0)) if deltas is None else np.asarray(deltas, float)
    require(deltas.ndim == 1 and deltas.size > 0 and bool(np.all(np.abs(deltas) <= math.pi / 2)),
            "deltas", "...", "need a 1-D array of angles within ±pi/2 rad")
    order = np.argsort(np.abs(deltas))
    model = Catamaran(p.with_(delta_row="rate"))
    out = np.zeros((deltas.size, 3))
    y, d_prev = np.array([p.top_speed(), 0.0, 0.0]), 0.0
    for i in order:
        d = float(deltas[i])
        if d * d_prev < 0:  # other side: restart from straight running
            y, d_prev = np.array([p.top_speed(), 0.0, 0.0]), 0.0
        if d != d_prev:
            y0 = y.copy()

            def fun(yy, s, d_prev=d_prev, d=d):
                return _residual(model, yy[0], yy[1], yy[2], d_prev + s * (d - d_prev))

            y = _continue(fun, y0, 1.0, 4)
        out[i], d_prev = y, d
    u, v, r = out[:, 0], out[:, 1], out[:, 2]
    speed = np.hypot(u, v)
    with np.errstate(divide="ignore"):
        diameter = np.where(r != 0, 2 * speed / np.abs(np.where(r != 0, r, 1.0)), np.inf)
    return {"delta": deltas, "r": r, "u": u, "v": v, "speed": speed, "beta": np.arctan2(v, u),
            "diameter": diameter}
