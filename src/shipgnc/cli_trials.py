"""``shipgnc trial``: standard manoeuvring trials of a catalogue vessel (docs/trials.md).

    shipgnc trial KIND --vessel NAME [--speed-kn V] [--rudder-deg D] [--angles D/PSI]
                  [--side port|starboard] [--steering-gear solas|model] [--json] [--out DIR]

KIND: turning-circle | zigzag | spiral | stopping | pull-out | all (every trial as one batch, with
the IMO MSC.137(76) criteria report). ``--vessel`` is a catalogue name (``shipgnc vessels``) or a
vessel YAML file (``vessel: {model: NAME, speed_mps: .., params..}``, as ``shipgnc identify``
writes). Bad input: one line on stderr, exit 2 (as every other command); a vessel without
reversing propulsion asked for ``stopping``: one line saying so, exit 2.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Annotated

import typer

from shipgnc.errors import ConfigError
from shipgnc.units import KNOT

KINDS = ("turning-circle", "zigzag", "spiral", "stopping", "pull-out", "all")


def _vessel(text: str):
    """(the vessel, the name it is shown by) from --vessel: a catalogue name, or a vessel file's
    validated section (built as ``shipgnc run`` builds a scenario's vessel section:
    :func:`shipgnc.vessels.setup.vessel_setup`), named by the file."""
    p = Path(text)
    if text.endswith((".yaml", ".yml")) or (p.suffix and p.is_file()):
        from shipgnc.vessels.files import load_vessel_file

        config = load_vessel_file(p, f"--vessel {text!r}")
        return config, f"{p.name} ({config.model})"
    return text, None


def clean(obj):
    """JSON-ready copy: private keys (``_history``) dropped, numpy scalars as floats, NaN as null."""
    import numpy as np

    if isinstance(obj, dict):
        return {k: clean(v) for k, v in obj.items() if not str(k).startswith("_")}
    if isinstance(obj, (list, tuple)):
        return [clean(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return clean(obj.tolist())
    if isinstance(obj, (np.floating, float)):
        v = float(obj)
        return v if math.isfinite(v) else None
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj


def run_trial(kind: str, vessel: str, *, speed_kn: float | None = None, rudder_deg: float | None = None,
              angles: str | None = None, side: str | None = None, steering_gear: str = "solas") -> dict:
    """The trial's result dict (with ``_history`` entries for the figures)."""
    from shipgnc.errors import require
    from shipgnc.trials import imo, pullout, spiral, stopping, turning, zigzag
    from shipgnc.trials.core import prepare

    require(kind in KINDS, "KIND", kind, f"allowed: {', '.join(KINDS)}")
    require(side in (None, "port", "starboard"), "--side", side, "allowed: port, starboard")
    if speed_kn is not None:
        require(math.isfinite(speed_kn) and speed_kn > 0, "--speed-kn", speed_kn, "must be a speed > 0 kn")
    if rudder_deg is not None:
        require(math.isfinite(rudder_deg) and rudder_deg > 0, "--rudder-deg", rudder_deg,
                "must be an angle > 0 deg")
    dz = zigzag.parse_angles(angles) if angles is not None else None
    if angles is not None and kind not in ("zigzag",):
        raise ConfigError(f"--angles = {angles!r}: only for KIND zigzag (all runs 10/10 and 20/20)")
    section, name = _vessel(vessel)
    speed = speed_kn * KNOT if speed_kn is not None else None
    sides = ("starboard", "port") if side is None else (side,)
    if kind == "stopping":
        from shipgnc.trials.core import _entry

        entry = _entry(section)
        if not entry.can_reverse:
            raise ConfigError(f"trial stopping: vessel {entry.name} has no propulsion that can go full "
                              "astern (can_reverse is false), so it has no stopping trial")
    # (the SOLAS gear replaces a vessel file's own rate; "model" keeps it)
    ship = prepare(section, speed, steering_gear=steering_gear, name=name)
    if kind == "turning-circle":
        return turning.turning_circle(ship=ship, rudder_deg=rudder_deg, sides=sides)
    if kind == "zigzag":
        d, p = dz if dz is not None else (20.0, 20.0)
        return zigzag.zigzag(None, d, p, ship=ship, sides=sides)
    if kind == "spiral":
        return spiral.spiral(ship=ship, max_deg=rudder_deg)
    if kind == "pull-out":
        return pullout.pull_out(ship=ship, rudder_deg=rudder_deg, sides=sides)
    if kind == "stopping":
        return stopping.stopping(ship=ship)
    return imo.run_all(ship=ship, rudder_deg=rudder_deg, sides=sides)


def trial(
    kind: Annotated[str, typer.Argument(help="turning-circle | zigzag | spiral | stopping | pull-out | all")],
    vessel: Annotated[str, typer.Option("--vessel", help="Catalogue name (shipgnc vessels) or a vessel "
                                        "YAML file.")],
    speed_kn: Annotated[float | None, typer.Option("--speed-kn", help="Test speed \\[kn] (default: the "
                                                   "design speed).")] = None,
    rudder_deg: Annotated[float | None, typer.Option(
        "--rudder-deg", help="Rudder \\[deg] of turning circle and pull-out (default 35 or the limit), "
                             "largest angle of the spiral (default 25).")] = None,
    angles: Annotated[str | None, typer.Option("--angles", help="Zig-zag D/PSI \\[deg] (default "
                                               "20/20).")] = None,
    side: Annotated[str | None, typer.Option("--side", help="port | starboard (default: both).")] = None,
    steering_gear: Annotated[str, typer.Option(
        "--steering-gear", help="solas: the rudder at SOLAS II-1 reg. 29's 35° to 30° in 28 s "
                                "(2.32°/s), as the IMO criteria presume; model: the vessel's own "
                                "rate.")] = "solas",
    json_: Annotated[bool, typer.Option("--json", help="Print only the result JSON on stdout.")] = False,
    out: Annotated[Path | None, typer.Option(
        "--out", help="Write trial.json, the figures and each manoeuvre's time series (.nc) here.")] = None,
) -> None:
    """Standard manoeuvring trials (IMO MSC.137(76)) of a vessel; see docs/trials.md."""
    from shipgnc.cli import friendly_errors, stderr, stdout

    with friendly_errors():
        if out is not None:
            from shipgnc.outputs import check_out

            check_out(out)
        res = run_trial(kind, vessel, speed_kn=speed_kn, rudder_deg=rudder_deg, angles=angles, side=side,
                        steering_gear=steering_gear)
        payload = clean(res)
        text = json.dumps(payload, indent=2, ensure_ascii=False)
        if out is not None:
            from shipgnc.outputs import atomic_dir
            from shipgnc.trials.series import write_series
            from shipgnc.viz.trial_figures import trial_figures

            with atomic_dir(out, command="trial") as tmp:
                (tmp / "trial.json").write_text(text + "\n", encoding="utf-8")
                written = trial_figures(res, tmp) + write_series(res, tmp)
            stderr.print(f"wrote trial.json, {', '.join(p.name for p in written)} to {out}", soft_wrap=True)
        if json_:
            sys.stdout.write(text + "\n")
        else:
            _print(stdout, payload)


#: rows of the printed summary per trial: (key, label, format)
_ROWS = {
    "turning-circle": [("advance_m", "advance [m]", ".1f"), ("transfer_m", "transfer [m]", ".1f"),
                       ("tactical_diameter_m", "tactical diameter [m]", ".1f"),
                       ("steady_turning_radius_m", "steady turning radius [m]", ".1f"),
                       ("steady_speed_mps", "steady speed [m/s]", ".3f"),
                       ("speed_loss_pct", "speed loss [%]", ".1f")],
    "zigzag": [("first_overshoot_deg", "first overshoot [deg]", ".2f"),
               ("second_overshoot_deg", "second overshoot [deg]", ".2f"),
               ("initial_turning_time_s", "initial turning time [s]", ".1f"),
               ("period_s", "period [s]", ".1f")],
    "stopping": [("track_reach_m", "track reach [m]", ".1f"), ("head_reach_m", "head reach [m]", ".1f"),
                 ("lateral_deviation_m", "lateral deviation [m]", ".1f"), ("time_s", "time [s]", ".1f")],
}


def _fmt(v, f):
    return "—" if v is None else format(v, f)


def _print(console, res: dict) -> None:
    from rich.markup import escape
    from rich.table import Table

    def head(r):
        lv = r.get("l_over_v_s")
        return (f"{r['vessel']} at {r['speed_kn']:.2f} kn ({r['speed_mps']:.3f} m/s), trim rudder "
                f"δ0 = {r['trim_rudder_deg']:+.3f}°" + ("" if lv is None else f", L/V = {lv:.2f} s")
                + f", rudder {r['rudder_rate_deg_s']:.3g}°/s ({r['steering_gear']} steering gear)")

    def sided(r, kind, title):
        sides = r.get("sides", {})
        table = Table(title=escape(title), title_justify="left")
        table.add_column("quantity", style="bold")
        for s in sides:
            table.add_column(s, justify="right")
        for key, label, f in _ROWS[kind]:
            table.add_row(escape(label), *(_fmt(sides[s].get(key), f) for s in sides))
        console.print(table)

    kind = res["trial"]
    console.print(escape(head(res)), soft_wrap=True)
    parts = ({"turning-circle": res["turning-circle"], "zigzag 10/10": res["zigzag-10/10"],
              "zigzag 20/20": res["zigzag-20/20"], "spiral": res["spiral"], "pull-out": res["pull-out"],
              "stopping": res["stopping"]} if kind == "all" else {kind: res})
    for title, r in parts.items():
        k = r.get("trial", title)
        if "error" in r:
            console.print(f"{escape(title)}: {escape(r['error'])}", soft_wrap=True)
        elif k == "turning-circle":
            sided(r, k, f"turning circle, rudder {r['rudder_deg']:g}°")
        elif k == "zigzag":
            sided(r, k, f"zig-zag {r['angles']}")
        elif k == "stopping":
            table = Table(title="stopping (full astern)", title_justify="left")
            table.add_column("quantity", style="bold")
            table.add_column("value", justify="right")
            for key, label, f in _ROWS["stopping"]:
                table.add_row(escape(label), _fmt(r.get(key), f))
            console.print(table)
        elif k == "spiral":
            verdict = "directionally stable" if r["stable"] else "directionally unstable"
            console.print(f"spiral: {len(r['rudder_deg'])} rudder angles × 2 directions, loop width "
                          f"{r['loop_width_deg']:.2f}° ({verdict})", soft_wrap=True)
        elif k == "pull-out":
            rr = r["residual_yaw_rate_deg_s"]
            console.print("pull-out: residual yaw rate " + ", ".join(
                f"{s} {_fmt(v, '+.4f')}°/s" for s, v in rr.items()), soft_wrap=True)
    if kind == "all":
        table = Table(title="IMO MSC.137(76) criteria", title_justify="left")
        for c in ("criterion", "value", "limit", "pass"):
            table.add_column(c, justify="left" if c == "criterion" else "right")
        for c in res["imo"]["criteria"]:
            ok = {True: "yes", False: "NO", None: "—"}[c["pass"]]
            table.add_row(escape(c["criterion"]), _fmt(c["value"], ".1f") + f" {c['unit']}",
                          _fmt(c["limit"], ".1f") + f" {c['unit']}", ok)
        console.print(table)
        for c in res["imo"]["criteria"]:
            if c.get("note") and c["pass"] is None:
                console.print(f"note: {escape(c['note'])}", soft_wrap=True)
