"""``shipgnc design autopilot``: a heading autopilot designed for a vessel
(:mod:`shipgnc.vessels.autopilot_design`).

    shipgnc design autopilot --vessel FILE|NAME [--speed-kn V] [--bandwidth W] [--damping Z]
                             [--integral] [--json]

Prints the design model (the linearised yaw response reduced to K/(1 + Ts), with Nomoto's
T₁ + T₂ − T₃ reduction beside it), the steering machine's bandwidth, the allowed bandwidth range,
the gains and the loop's margins; the gains go into a scenario as
``controller: {type: course, Kp: .., Kd: ..}`` or are designed there with
``controller: {type: course, design: auto}``. A bandwidth the rudder cannot deliver, or a ship the
steering machine cannot hold: one line on stderr, exit 2.
"""

from __future__ import annotations

import json
import math
from typing import Annotated

import typer

app = typer.Typer(add_completion=False, no_args_is_help=True, pretty_exceptions_enable=False,
                  help="Design a controller for a vessel.")


@app.command("autopilot")
def autopilot(
    vessel: Annotated[str, typer.Option("--vessel", help="Catalogue name (shipgnc vessels) or a "
                                        "vessel YAML file.")],
    speed_kn: Annotated[float | None, typer.Option("--speed-kn", help="Speed [kn] (default: the "
                                                    "file's, else the design speed).")] = None,
    bandwidth: Annotated[float | None, typer.Option("--bandwidth", help="Closed-loop bandwidth "
                                                     "[rad/s] (default: the rule's).")] = None,
    damping: Annotated[float, typer.Option("--damping", help="Closed-loop damping ratio.")] = 0.8,
    integral: Annotated[bool, typer.Option("--integral", help="Add the integral gain "
                                           "Ki = ω_n Kp/10.")] = False,
    json_: Annotated[bool, typer.Option("--json", help="Print one JSON object on stdout.")] = False,
) -> None:
    """Heading autopilot gains for a vessel from its linearised yaw response (Fossen 2021 §15.3)."""
    from shipgnc.cli import friendly_errors, stdout

    with friendly_errors():
        from shipgnc.cli_trials import _vessel
        from shipgnc.errors import require
        from shipgnc.units import KNOT
        from shipgnc.vessels.autopilot_design import design_autopilot
        from shipgnc.vessels.catalogue import get_vessel

        if speed_kn is not None:
            require(math.isfinite(speed_kn) and speed_kn > 0, "--speed-kn", speed_kn,
                    "must be a speed > 0 kn")
        name, file_speed, params = _vessel(vessel)
        speed = speed_kn * KNOT if speed_kn is not None else file_speed
        model = get_vessel(name).build(speed, **params)
        d = design_autopilot(model, bandwidth=bandwidth, zeta=damping, integral=integral)
        if json_:
            m, c = d.model, d.check
            print(json.dumps({
                "vessel": vessel, "speed_mps": model.speed, "K": m.K, "T": m.T, "b": m.b,
                "K_nomoto": m.K_nomoto, "T_nomoto": m.T_nomoto, "omega_delta": m.omega_delta,
                "bandwidth": d.bandwidth, "zeta": d.zeta, "omega_n": d.omega_n, "Kp": d.Kp,
                "Kd": d.Kd, "Ki": d.Ki, "stable": c.stable,
                "gain_margin": c.gain_margin if math.isfinite(c.gain_margin) else None,
                "phase_margin_deg": c.phase_margin_deg, "crossover": c.crossover}, indent=2))
            return
        stdout.print(f"{vessel} at {model.speed:.4g} m/s ({model.speed / KNOT:.3g} kn)",
                     soft_wrap=True)
        for line in d.lines():
            stdout.print(line, soft_wrap=True, markup=False)
        stdout.print(f"scenario: controller: {{type: course, Kp: {d.Kp:.4g}, Kd: {d.Kd:.4g}}} or "
                     "{type: course, design: auto}", soft_wrap=True, markup=False)
