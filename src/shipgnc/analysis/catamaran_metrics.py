"""Metrics of document 004's catamaran runs (note 004-4.7), computed from a result Dataset.

Names are those of note 004-4.7: ``final_yaw_rate_rad_s``, ``final_delta_deg``, ``final_speed_mps``,
``turning_diameter_m``, ``yaw_rate_settling_s``, ``yaw_rate_overshoot_pct``,
``max_delta_rate_deg_s``, ``final_heading_error_rad`` (heading runs), ``events``, ``stable``; and for
the comparison with the classical baselines ``iae`` (of r − ω* for yaw-rate runs, of the wrapped
heading error for heading runs), ``thruster_travel_deg`` and ``peak_delta_rate_deg_s``.

**Alias.** ``peak_delta_rate_deg_s`` is the same quantity as ``max_delta_rate_deg_s`` (max |δ̇| of
the applied thruster rate, °/s): both keys are kept (the name of note 004-4.7 and the comparison's), the
second defined from the first in :func:`add_aliases` (:data:`ALIASES`). Beside every quality
figure the thruster's effort: ``thruster_travel_deg`` (∫|δ̇| dt) and ``delta_rate_rms_deg_s``
(RMS of δ̇ over the run).

Settling: the time from t = 0 after which the signal stays within ±2 % of its value at t_end.
Events: the controller's (``controller.events`` or ``ds.attrs["events"]``, see :func:`attach_events`)
merged with a ``delta_reached_90`` found in the logged thruster angle.
"""

from __future__ import annotations

import json
import math

import numpy as np

from shipgnc.frames import wrap_angle

#: |r(t_end)| below which the diameter, settling and overshoot are null [rad/s]
R_NULL = 1e-6


def _series(ds, name: str) -> np.ndarray:
    return np.asarray(ds[name].values, dtype=float)


def _final(ds, name: str) -> float:
    return float(_series(ds, name)[-1])


#: a settled stretch shorter than this share of the run does not show a steady state
MIN_SETTLED_SHARE = 0.1


def settling_time(t, y, final: float | None = None, band: float = 0.02) -> float | None:
    """First time after which ``y`` stays within ±band·|final| of ``final`` (default y[-1]).

    None when it never does, or when the settled stretch is shorter than
    :data:`MIN_SETTLED_SHARE` of the run (with ``final = y[-1]`` the last sample is always
    "settled": a run too short to reach a steady state must not report one).
    """
    y = np.asarray(y, dtype=float)
    t = np.asarray(t, dtype=float)
    final = float(y[-1]) if final is None else final
    tol = band * abs(final)
    outside = np.nonzero(np.abs(y - final) > tol)[0]
    if outside.size == 0:
        return float(t[0])
    k = outside[-1] + 1
    if k >= t.size or t[-1] - t[k] < MIN_SETTLED_SHARE * (t[-1] - t[0]):
        return None
    return float(t[k])


def final_yaw_rate_rad_s(ds) -> float:
    return _final(ds, "r")


def final_delta_deg(ds) -> float:
    return math.degrees(_final(ds, "delta"))


def final_speed_mps(ds) -> float:
    return float(math.hypot(_final(ds, "u"), _final(ds, "v")))


def turning_diameter_m(ds) -> float | None:
    """2V/|r| at t_end (None when |r(t_end)| < 1e-6 rad/s)."""
    r = final_yaw_rate_rad_s(ds)
    return None if abs(r) < R_NULL else 2.0 * final_speed_mps(ds) / abs(r)


def track_diameter_m(ds, window_s: float = 200.0) -> float:
    """Mean of the north and east extents of the track over the last ``window_s`` [m]."""
    t = _series(ds, "time") if "time" in ds else np.asarray(ds.time)
    keep = t >= t[-1] - window_s
    return 0.5 * (float(np.ptp(_series(ds, "north")[keep])) + float(np.ptp(_series(ds, "east")[keep])))


def yaw_rate_settling_s(ds) -> float | None:
    r = _series(ds, "r")
    if abs(r[-1]) < R_NULL:
        return None
    return settling_time(ds.time.values, r)


def yaw_rate_overshoot_pct(ds) -> float | None:
    r = _series(ds, "r")
    rf = r[-1]
    if abs(rf) < R_NULL:
        return None
    return float(100.0 * max(0.0, float(np.max(np.sign(rf) * (r - rf)))) / abs(rf))


def delta_rate(ds) -> np.ndarray:
    """The applied thruster rate δ̇ [rad/s]: the input ``delta_rate`` or differences of δ."""
    if "delta_rate" in ds:
        return _series(ds, "delta_rate")
    return np.gradient(_series(ds, "delta"), ds.time.values)


def max_delta_rate_deg_s(ds) -> float:
    rate = delta_rate(ds)
    return math.degrees(float(np.nanmax(np.abs(rate))))


def delta_rate_rms_deg_s(ds) -> float:
    """RMS of the applied thruster rate δ̇ over the logged samples [deg/s]."""
    rate = delta_rate(ds)
    return math.degrees(float(np.sqrt(np.nanmean(rate * rate))))


#: metric keys defined as another key's value (alias → source), in one place
ALIASES = {"peak_delta_rate_deg_s": "max_delta_rate_deg_s"}


def add_aliases(out: dict) -> dict:
    """Fill each alias of :data:`ALIASES` from its source key in ``out`` (in place; returned)."""
    for alias, source in ALIASES.items():
        if source in out:
            out[alias] = out[source]
    return out


def final_heading_error_rad(ds, heading_target: float) -> float:
    """wrap(ψ(t_end) − K*) [rad]."""
    return float(wrap_angle(_final(ds, "psi") - heading_target))


def thruster_travel_deg(ds) -> float:
    """∫|δ̇| dt [deg] (trapezoid on the logged samples)."""
    rate = np.abs(delta_rate(ds))
    t = ds.time.values
    return math.degrees(float(np.sum(0.5 * (rate[1:] + rate[:-1]) * np.diff(t))))


def tracked_error(ds, heading_target: float | None = None, reference=None) -> np.ndarray:
    """The run's tracked error: heading (wrapped ψ − ψ_ref or ψ − K*) [rad] or yaw rate
    (r − ω*) [rad/s]."""
    if heading_target is not None or "psi_error" in ds:
        return (_series(ds, "psi_error") if "psi_error" in ds
                else wrap_angle(_series(ds, "psi") - heading_target))
    if "r_error" in ds:
        return _series(ds, "r_error")
    if reference is not None:
        return _series(ds, "r") - reference
    return _series(ds, "r") - _series(ds, "omega_ref")


def iae(ds, heading_target: float | None = None, reference=None) -> float:
    """Integral of the absolute error (:func:`tracked_error`): [rad·s] for a heading run, [rad]
    for a yaw-rate run."""
    t = ds.time.values
    err = np.abs(tracked_error(ds, heading_target, reference))
    return float(np.sum(0.5 * (err[1:] + err[:-1]) * np.diff(t)))


def attach_events(ds, controller) -> None:
    """Store ``controller.events`` in ``ds.attrs["events"]`` (JSON, survives NetCDF)."""
    ds.attrs["events"] = json.dumps(list(getattr(controller, "events", []) or []))


def events(ds, controller=None) -> list[dict]:
    """Events of a run: the controller's plus a ``delta_reached_90`` seen in the logged δ."""
    found: list[dict] = []
    if controller is not None:
        found = [dict(e) for e in getattr(controller, "events", [])]
    elif "events" in ds.attrs:
        found = json.loads(ds.attrs["events"])
    if "delta" in ds and all(e["kind"] != "delta_reached_90" for e in found):
        delta = _series(ds, "delta")
        hit = np.nonzero(np.abs(delta) >= math.pi / 2)[0]
        if hit.size:
            t = float(ds.time.values[hit[0]])
            found.append({"time_s": t, "kind": "delta_reached_90",
                          "message": f"|delta| reached 90° at t = {t:.4g} s"})
    return sorted(found, key=lambda e: e["time_s"])


#: a heading run is bounded within 90° and converged when its final swing is within 5°; a
#: yaw-rate run converged when its final swing is within 5 % of the commanded rate
STABLE_HEADING_BOUND_RAD = math.pi / 2
STABLE_HEADING_TOL_RAD = math.radians(5.0)
STABLE_RATE_TOL_FRACTION = 0.05


def stable(ds, run_events: list[dict] | None = None, heading_target: float | None = None) -> bool:
    """``stable`` as everywhere in shipgnc (:func:`shipgnc.analysis.metrics.stable_arrays`:
    reached the end without the divergence guard, bounded, no limit cycle in the final 20 % of
    the run), on the tracked error (:func:`tracked_error`), and the thruster never reached 90°
    (``delta_reached_90``, where the law's 1/cos δ is singular)."""
    from shipgnc.analysis.metrics import stable_arrays

    run_events = events(ds) if run_events is None else run_events
    diverged = bool(int(ds.attrs.get("diverged", 0)))
    t = ds.time.values
    t_end = float(ds.attrs.get("t_end", t[-1]))
    reached = abs(float(t[-1]) - t_end) <= 1e-6 * max(1.0, t_end)
    no_singularity = all(e["kind"] != "delta_reached_90" for e in run_events)
    try:
        error = tracked_error(ds, heading_target)
    except KeyError:  # a run that logs no reference: bounded by the guard alone
        return reached and not diverged and no_singularity
    if heading_target is not None or "psi_error" in ds:
        bound, tol = STABLE_HEADING_BOUND_RAD, STABLE_HEADING_TOL_RAD
    else:
        command = _series(ds, "r") - error  # ω* (error = r − ω*)
        scale = float(np.nanmax(np.abs(command))) if np.any(np.isfinite(command)) else 0.0
        bound, tol = np.inf, max(STABLE_RATE_TOL_FRACTION * scale, 1e-4)
    verdict = stable_arrays(t, error, bound=bound, oscillation_tol=tol, reached=reached,
                            diverged=diverged)
    return bool(np.all(verdict["stable"])) and no_singularity  # a batch: every ship


def catamaran_metrics(ds, controller=None, heading_target: float | None = None) -> dict:
    """Every metric of note 004-4.7 for one (unbatched) run, as plain Python values (a heading
    run — ``heading_target`` given — has no yaw-rate step, so its yaw-rate settling and overshoot
    are null)."""
    run_events = events(ds, controller)
    out = {
        "final_yaw_rate_rad_s": final_yaw_rate_rad_s(ds),
        "final_delta_deg": final_delta_deg(ds),
        "final_speed_mps": final_speed_mps(ds),
        "turning_diameter_m": turning_diameter_m(ds),
        "yaw_rate_settling_s": None if heading_target is not None else yaw_rate_settling_s(ds),
        "yaw_rate_overshoot_pct": None if heading_target is not None else yaw_rate_overshoot_pct(ds),
        "max_delta_rate_deg_s": max_delta_rate_deg_s(ds),
        "thruster_travel_deg": thruster_travel_deg(ds),
        "delta_rate_rms_deg_s": delta_rate_rms_deg_s(ds),
        "events": run_events,
        "stable": stable(ds, run_events, heading_target),
    }
    if heading_target is not None:
        out["final_heading_error_rad"] = final_heading_error_rad(ds, heading_target)
    return out


def comparison_metrics(ds, heading_target: float | None = None) -> dict:
    """IAE, thruster travel, rate RMS and peak thruster rate (with settling and overshoot) for the
    comparison (``peak_delta_rate_deg_s``: the alias of ``max_delta_rate_deg_s``, :data:`ALIASES`)."""
    return add_aliases({
        "iae": iae(ds, heading_target),
        "thruster_travel_deg": thruster_travel_deg(ds),
        "delta_rate_rms_deg_s": delta_rate_rms_deg_s(ds),
        "max_delta_rate_deg_s": max_delta_rate_deg_s(ds),
        "yaw_rate_settling_s": None if heading_target is not None else yaw_rate_settling_s(ds),
        "yaw_rate_overshoot_pct": None if heading_target is not None else yaw_rate_overshoot_pct(ds),
        **({"final_heading_error_rad": final_heading_error_rad(ds, heading_target)}
           if heading_target is not None else {}),
    })


def model_fields(model, preset_name: str | None = None) -> dict:
    """``model_note`` (what the hull is, in words) and ``reproduction`` (true for the document's
    printed Coriolis sign or paper units) of a run's catamaran."""
    from shipgnc.models.catamaran import model_note

    note, reproduction = model_note(model.params, preset_name or getattr(model, "preset_name", None))
    return {"model_note": note, "reproduction": reproduction}
