"""Scenario metrics computed from a result Dataset (one ship), as spec 001 §1.9–1.10 defines them.

Every function takes a single-ship ``xarray.Dataset`` (see :mod:`shipgnc.sim.result`) and returns a
dict of plain Python numbers (``None`` where a figure does not exist, e.g. a run that never settles).
A metric's name carries the unit it is reported in.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from shipgnc.frames import path_frame, wrap_angle
from shipgnc.units import to_deg


def _sign(value: float) -> int:
    return int(np.sign(value))


def _at(ds, name: str, t: float) -> float:
    """Value of ``name`` at the sample nearest to ``t``."""
    return float(ds[name].sel(time=t, method="nearest"))


def _number(value) -> float | None:
    value = float(value)
    return value if math.isfinite(value) else None


def turn_window(times: np.ndarray, alpha_cmd: np.ndarray) -> tuple[float, float]:
    """Start and end of the first turn command (first sample with α_cmd ≠ 0, first one after it
    with α_cmd back at 0, or the end of the run)."""
    on = np.flatnonzero(alpha_cmd != 0)
    if on.size == 0:
        return float(times[0]), float(times[-1])
    start = on[0]
    off = np.flatnonzero(alpha_cmd[start:] == 0)
    end = start + off[0] if off.size else len(times) - 1
    return float(times[start]), float(times[end])


STERN_KICK_KEYS = ("initial_sway_sign", "initial_yaw_rate_sign", "steady_yaw_rate_sign",
                   "max_speed_mps", "final_speed_mps", "heading_change_deg",
                   "stern_kick_min_lateral_m", "steady_yaw_rate_rad_s", "final_heading_deg")


def stern_kick_metrics(ds) -> dict:
    """Metrics of the open-loop turn (spec 001 §1.9).

    With the turn commanded over [t_on, t_off]: ``initial_sway_sign`` and
    ``initial_yaw_rate_sign`` are the signs of v and r at t_on + dt; ``steady_yaw_rate_sign`` and
    ``steady_yaw_rate_rad_s`` use the mean r over the last 40 % of the turn (every figure is
    ``None`` when the run holds no turn command); ([8, 10] s in the
    document's sequence); ``heading_change_deg`` = ψ(t_off) − ψ(t_on); ``max_speed_mps`` and
    ``final_speed_mps`` use U = √(u² + v²); ``stern_kick_min_lateral_m`` is the least lateral
    offset of the CG during the turn, in the frame of the heading at t_on (positive to starboard).
    """
    t = ds.time.values
    if t.size < 2 or not np.any(ds.alpha_cmd.values != 0):
        # no turn inside the run (too short, or diverged first): the figures do not exist
        return dict.fromkeys(STERN_KICK_KEYS)
    dt = float(t[1] - t[0])
    t_on, t_off = turn_window(t, ds.alpha_cmd.values)
    speed = np.hypot(ds.u.values, ds.v.values)
    steady = (t >= t_off - 0.4 * (t_off - t_on)) & (t <= t_off)
    r_steady = float(ds.r.values[steady].mean())
    turn = (t >= t_on) & (t <= t_off)
    _, lateral = path_frame(ds.north.values[turn], ds.east.values[turn], _at(ds, "north", t_on),
                            _at(ds, "east", t_on), _at(ds, "psi", t_on))
    return {
        "initial_sway_sign": _sign(_at(ds, "v", t_on + dt)),
        "initial_yaw_rate_sign": _sign(_at(ds, "r", t_on + dt)),
        "steady_yaw_rate_sign": _sign(r_steady),
        "max_speed_mps": float(speed.max()),
        "final_speed_mps": float(speed[-1]),
        "heading_change_deg": float(to_deg(_at(ds, "psi", t_off) - _at(ds, "psi", t_on))),
        "stern_kick_min_lateral_m": float(lateral.min()),
        "steady_yaw_rate_rad_s": r_steady,
        "final_heading_deg": float(to_deg(ds.psi.values[-1])),
    }


def heading_step_metrics(ds, step_times, tolerance_deg: float = 2.0) -> dict:
    """Metrics of heading-step tracking (spec 001 §1.10), with e_ψ = wrap(ψ − ψ_d).

    ``heading_rmse_deg``: RMS of e_ψ over the run. For each step at t_k, its settling time is the
    first sample time after which |e_ψ| ≤ 2° holds until the next step (or the end), minus t_k;
    ``settling_time_s`` is the largest (``None`` if some step never settles). ``overshoot_deg``:
    the largest max(0, sign(Δψ_d)·e_ψ) after a step. ``max_thruster_angle_deg`` and
    ``max_thrust_n`` use the applied input; ``max_thrust_cmd_n`` the command.
    """
    t = ds.time.values
    err = to_deg(ds.psi_error.values)
    psi_d = ds.psi_d.values
    bounds = [*step_times, t[-1] + 1.0]
    settling, overshoot = [], []
    for t_k, t_next in itertools.pairwise(bounds):
        window = (t >= t_k - 1e-9) & (t < t_next - 1e-9)
        if not window.any():
            continue
        e_w, t_w = err[window], t[window]
        bad = np.flatnonzero(np.abs(e_w) > tolerance_deg)
        if bad.size == 0:
            settling.append(0.0)
        elif bad[-1] + 1 < t_w.size:
            settling.append(float(t_w[bad[-1] + 1] - t_k))
        else:
            settling.append(None)
        before = psi_d[np.flatnonzero(t < t_k - 1e-9)[-1]] if (t < t_k - 1e-9).any() else psi_d[0]
        direction = np.sign(wrap_angle(psi_d[window][0] - before))
        overshoot.append(float(max(0.0, np.max(direction * e_w))))
    settle = None if any(s is None for s in settling) or not settling else max(settling)
    return {
        "heading_rmse_deg": float(np.sqrt(np.mean(err**2))),
        "settling_time_s": settle,
        "overshoot_deg": max(overshoot) if overshoot else 0.0,
        "max_thruster_angle_deg": float(to_deg(np.abs(ds.alpha.values).max())),
        "max_thrust_n": float(ds["T"].values.max()),
        "settling_times_s": settling,
        "max_thrust_cmd_n": float(ds.T_cmd.values.max()),
        "final_speed_mps": float(ds.u.values[-1]),
    }


def waypoint_metrics(ds, leg_lengths, capture_distance: float = 20.0) -> dict:
    """Metrics of waypoint following (spec 001 §1.10).

    ``completion_time_s``: first sample at which the along-track distance reaches the end of the
    last leg (``None`` if never). ``crosstrack_max_m`` / ``crosstrack_rms_m``: max |e| and RMS of
    e over the samples with along-track distance ≥ ``capture_distance`` on their own leg.
    ``waypoints_reached``: waypoints after the start whose leg was completed. Samples after the
    completion are left out (a ship of a batch keeps sailing until every ship is done).
    """
    t = ds.time.values
    leg = ds.leg.values.astype(int)
    s = ds.along_track.values
    e = ds.cross_track_error.values
    last = len(leg_lengths) - 1
    done = (leg == last) & (s >= leg_lengths[last])
    if done.any():
        end = int(np.argmax(done)) + 1
        t, leg, s, e, done = t[:end], leg[:end], s[:end], e[:end], done[:end]
    captured = s >= capture_distance
    e_c = e[captured]
    return {
        "completion_time_s": float(t[np.argmax(done)]) if done.any() else None,
        "crosstrack_rms_m": _number(np.sqrt(np.mean(e_c**2))) if e_c.size else None,
        "crosstrack_max_m": _number(np.abs(e_c).max()) if e_c.size else None,
        "waypoints_reached": int(leg.max() + (1 if done.any() else 0)),
        "max_thruster_angle_deg": float(to_deg(np.abs(ds.alpha.values[:t.size]).max())),
        "final_crosstrack_m": float(e[-1]),
    }


def course_quality_metrics(ds, *, lam: float = 1.0, t_end: float | None = None,
                           diverged: bool = False, bound_deg: float = 90.0,
                           settle_window_s: float = 30.0, settle_band_deg: float = 2.0) -> dict:
    """Document 003's quality index and course-keeping figures (spec 003 §3.1, §3.8).

    On every sample t_i: Δψ_i = wrap(ψ_d − ψ_i) [rad]; ``psi_E`` = Σ Δψ_i², ``delta_E`` = λ Σ δ_i²
    with the applied rudder δ [rad], ``J`` = ``psi_E`` + ``delta_E`` (eq. 2). ``min_surge_mps``,
    ``final_heading_error_deg`` (Δψ at the last sample), ``max_rudder_deg`` (applied). ``stable``:
    the run reached ``t_end`` without the divergence guard and |Δψ| stayed below 90°. Extras:
    ``settled`` (|Δψ| ≤ 2° over the last 30 s) and ``psi_E_ref`` (Σ wrap(ψ_z − ψ)² against the
    reference model, for controllers that have one; spec 003 B11).
    """
    t = ds.time.values
    dpsi = -ds.psi_error.values  # psi_error = wrap(ψ − ψ_d)
    delta = ds.delta.values
    finite = np.isfinite(dpsi)
    dpsi, delta, t = dpsi[finite], delta[finite], t[finite]
    psi_E = float(np.sum(dpsi**2))
    delta_E = float(lam * np.sum(delta**2))
    reached = t_end is None or (t.size and t[-1] >= t_end - 1e-9)
    late = t >= t[-1] - settle_window_s
    out = {
        "psi_E": psi_E,
        "delta_E": delta_E,
        "J": psi_E + delta_E,
        "min_surge_mps": float(np.min(ds.u.values[np.isfinite(ds.u.values)])),
        "final_heading_error_deg": float(to_deg(dpsi[-1])),
        "max_rudder_deg": float(to_deg(np.max(np.abs(delta)))),
        "stable": bool(reached and not diverged and np.all(np.abs(to_deg(dpsi)) < bound_deg)),
        "settled": bool(np.all(np.abs(to_deg(dpsi[late])) <= settle_band_deg)),
    }
    if "psi_z" in ds and np.isfinite(ds.psi_z.values).any():
        ref = wrap_angle(ds.psi_z.values[finite] - ds.psi.values[finite])
        out["psi_E_ref"] = float(np.nansum(ref**2))
    else:
        out["psi_E_ref"] = None
    return out
