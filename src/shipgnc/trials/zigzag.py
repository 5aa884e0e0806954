"""Zig-zag δ/ψ trial (IMO MSC.137(76) §4.2; ``docs/trials.md``).

Rudder to δ₀ + δ (starboard first) or δ₀ − δ (port first) at execution; each time the heading has
changed ψ from the original course in the direction the rudder turns the ship, the rudder is
reversed (:func:`reverse_rudder`). Figures (a ship starting to starboard, s₁ = +1, s₂ = −1, ...):

* **overshoot** k: s_k·ψ_ext,k − ψ, the heading's further excursion beyond ±ψ after the k-th
  reversal, until the yaw rate changes sign (ψ_ext,k the heading at that instant);
* **initial turning time**: from execution to the first reversal (the heading reaching ±ψ);
* **initial turning distance** (10°/10°: the IMO initial turning ability): the distance along the
  track travelled by then;
* **period**: the time between the first and the third heading extreme (one full oscillation).

:class:`ZigZag` is the same manoeuvre as a controller for :func:`shipgnc.sim.simulator.simulate`
(used by :mod:`shipgnc.analysis.identification`, which re-exports it).
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.errors import require


def reverse_rudder(sign, change, psi_switch, rudder_sign: float = 1.0):
    """The rudder's side after a zig-zag check: ``sign`` (±1, per ship) is reversed where the
    heading ``change`` from the original course [rad] has reached ``psi_switch`` [rad] in the
    direction that side turns the ship (``rudder_sign``: the heading change a positive rudder
    produces, +1 when δ > 0 turns the bow to starboard)."""
    turning = rudder_sign * np.sign(sign)
    return np.where(turning * change >= psi_switch, -sign, sign)


class ZigZag:
    """The zig-zag δ/ψ manoeuvre as a controller (``docs/trials.md``; IMO MSC.137(76)).

    The rudder is put to ``offset + delta`` [rad] at ``t_execute``; each time the heading (state
    ``psi_index``) has changed ``psi_switch`` [rad] from the original course in the direction the
    rudder turns the ship, the rudder is reversed about ``offset`` (the trim rudder δ₀, default 0).
    ``delta`` and ``psi_switch`` may be arrays broadcasting over the batch. ``rudder_sign`` is the
    sign of the heading change a positive rudder produces (CyberShip II: −1, δ > 0 turns the bow to
    port; a Nomoto model with K > 0: +1). The command is ``held`` (the other inputs, e.g. the
    propeller speed) with the rudder written at ``rudder_index``. Each ship switches on its own
    heading.
    """

    continuous = False
    signals = ()

    def __init__(self, delta, psi_switch, *, rudder_sign: float = -1.0,
                 held=(), rudder_index: int = -1, t_execute: float = 0.0, Ts: float | None = None,
                 psi_index: int = 2, offset=0.0):
        delta = np.asarray(delta, dtype=float)
        psi_switch = np.asarray(psi_switch, dtype=float)
        require(bool(np.all(np.isfinite(delta)) and np.all(delta != 0)), "zigzag.delta",
                delta.tolist(), "must be a finite angle != 0 rad")
        require(bool(np.all(np.isfinite(psi_switch)) and np.all(psi_switch > 0)), "zigzag.psi_switch",
                psi_switch.tolist(), "must be a finite angle > 0 rad")
        require(rudder_sign in (-1, 1, -1.0, 1.0), "zigzag.rudder_sign", rudder_sign, "must be +1 or -1")
        self.delta = float(delta) if delta.ndim == 0 else delta
        self.psi_switch = float(psi_switch) if psi_switch.ndim == 0 else psi_switch
        self.rudder_sign = float(rudder_sign)
        self.held = np.atleast_1d(np.asarray(held, dtype=float))
        self.rudder_index = int(rudder_index)
        self.t_execute = float(t_execute)
        self.Ts = Ts
        self.psi_index = int(psi_index)
        self.offset = np.asarray(offset, dtype=float)
        self._rudder = None
        self._psi0 = None

    def reset(self, batch_shape) -> None:
        self._batch = tuple(batch_shape)
        self._rudder = None
        self._psi0 = None

    def step(self, t: float, measurement: np.ndarray, reference: np.ndarray) -> np.ndarray:
        psi = np.asarray(measurement[..., self.psi_index], dtype=float)
        cmd = np.zeros((*self._batch, self.held.size + 1))
        cmd[..., [i for i in range(cmd.shape[-1]) if i != self.rudder_index % cmd.shape[-1]]] = self.held
        if t < self.t_execute - 1e-12:
            cmd[..., self.rudder_index] = self.offset
            return cmd
        if self._rudder is None:
            self._rudder = np.broadcast_to(np.asarray(self.delta, dtype=float), psi.shape).copy()
            self._psi0 = psi.copy()
        self._rudder = reverse_rudder(self._rudder, psi - self._psi0, self.psi_switch, self.rudder_sign)
        cmd[..., self.rudder_index] = self.offset + self._rudder
        return cmd

    def signal_values(self) -> dict[str, np.ndarray]:
        return {}


def parse_angles(text: str) -> tuple[float, float]:
    """``"D/PSI"`` [deg] → (δ, ψ) in degrees (one-line error otherwise)."""
    from shipgnc.errors import ConfigError

    parts = str(text).split("/")
    try:
        vals = [float(p) for p in parts]
    except ValueError:
        vals = []
    if len(vals) != 2 or not all(math.isfinite(v) and 0 < v <= 90 for v in vals):
        raise ConfigError(f"--angles = {text!r}: expected D/PSI, two angles in (0, 90] deg, e.g. 20/20")
    return vals[0], vals[1]


def check_rudder(ship, delta_deg: float) -> None:
    """Refuse a zig-zag rudder beyond the vessel's limit (the command would be clipped, and the
    trial labelled with an angle it did not sail)."""
    from shipgnc.errors import ConfigError

    limit = math.degrees(ship.max_rudder)
    if delta_deg > limit + 1e-9:
        raise ConfigError(f"--angles: the zig-zag rudder D = {delta_deg:g}° is beyond "
                          f"{ship.name}'s rudder limit {limit:g}°; allowed: D in (0, {limit:g}]")


def plan(ship, delta_deg: float, psi_deg: float, sides=("starboard", "port"), *, t_max=None):
    """The programme of a zig-zag ``delta_deg``/``psi_deg`` to each of ``sides`` (one ship each)."""
    from shipgnc.trials.core import SIDES, programme

    signs = np.array([SIDES[s] for s in sides])
    amp = signs * math.radians(delta_deg)
    lv = ship.l_over_v(0)
    if t_max is None:
        t_max = 3600.0 if lv is None else max(1200.0, 120.0 * lv)
    return programme(ship, "zigzag", len(sides), zz_amp=amp, zz_psi=math.radians(psi_deg), t_max=t_max)


def finished(ship, view, k: int, sl: slice) -> np.ndarray:
    """Done once each ship's rudder has been reversed five times (four overshoots measured)."""
    cmd = view.command[:, sl] - view.programme.delta_a[sl]
    flips = np.sum(np.diff(np.sign(cmd), axis=0) != 0, axis=0)
    return flips >= 5


def analyse(ship, hist, delta_deg: float, psi_deg: float, i: int = 0) -> dict:
    """Figures of ship ``i`` of a zig-zag history (module docstring)."""
    from shipgnc.trials.core import at, crossing, finite, track_length

    prog = hist.programme
    s1 = float(np.sign(prog.zz_amp[i]))
    psi = hist.state("psi")[:, i] - hist.x[0, i, hist.index["psi"]]
    r = hist.state("r")[:, i]
    t = hist.time
    cmd = hist.command[:, i] - prog.delta_a[i]
    flips = np.nonzero(np.diff(np.sign(cmd)) != 0)[0] + 1  # samples whose command is reversed
    psi_sw = math.radians(psi_deg)
    k1 = crossing(s1 * psi, psi_sw)
    extremes = []
    for j, f in enumerate(flips):
        # the yaw rate's sign change after reversal j: heading extreme
        sgn = s1 * (1 if j % 2 == 0 else -1)  # direction the ship was turning before reversal j
        seg = sgn * r[f:]
        hit = np.nonzero(seg <= 0)[0]
        if hit.size == 0:
            break
        m = int(f + hit[0])
        if m == 0:
            continue
        a, b = r[m - 1], r[m]
        w = float(a / (a - b)) if a != b else 0.0
        extremes.append([float(t[m - 1] + w * (t[m] - t[m - 1])),
                         float(np.degrees(psi[m - 1] + w * (psi[m] - psi[m - 1])))])
    overshoots = [s1 * (1 if j % 2 == 0 else -1) * e[1] - psi_deg for j, e in enumerate(extremes)]
    north, east = hist.state("north")[:, i], hist.state("east")[:, i]
    dist = track_length(north, east)
    return {
        "angles": f"{delta_deg:g}/{psi_deg:g}",
        "side": "starboard" if s1 > 0 else "port",
        "first_overshoot_deg": finite(overshoots[0]) if overshoots else None,
        "second_overshoot_deg": finite(overshoots[1]) if len(overshoots) > 1 else None,
        "overshoots_deg": [float(o) for o in overshoots],
        "initial_turning_time_s": None if k1 is None else at(t, k1),
        "initial_turning_distance_m": None if k1 is None else at(dist, k1),
        "heading_extremes": extremes,
        "period_s": finite(extremes[2][0] - extremes[0][0]) if len(extremes) >= 3 else None,
    }


def zigzag(vessel, delta_deg: float = 20.0, psi_deg: float = 20.0, *, sides=("starboard", "port"),
           speed_mps=None, ship=None, **kw) -> dict:
    """Run the zig-zag ``delta_deg``/``psi_deg`` to each side as one batch; the figures per side."""
    from shipgnc.trials.core import prepare, run_parts

    ship = ship if ship is not None else prepare(vessel, speed_mps, **kw)
    check_rudder(ship, delta_deg)
    (hist,) = run_parts(ship, [(plan(ship, delta_deg, psi_deg, sides), finished)])
    return collect(ship, hist, delta_deg, psi_deg, sides)


def collect(ship, hist, delta_deg, psi_deg, sides) -> dict:
    from shipgnc.trials.core import header

    out = {"trial": "zigzag", **header(ship), "angles": f"{delta_deg:g}/{psi_deg:g}"}
    per = {side: analyse(ship, hist, delta_deg, psi_deg, j) for j, side in enumerate(sides)}
    out.update({k: v for k, v in per[sides[0]].items() if k not in ("angles", "side")})
    out["sides"] = per
    out["_history"] = hist
    return out
