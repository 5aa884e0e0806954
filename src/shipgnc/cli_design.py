"""``shipgnc design autopilot``: a heading autopilot designed for a vessel
(:mod:`shipgnc.vessels.autopilot_design`).

    shipgnc design autopilot --vessel FILE|NAME [--speed-kn V] [--bandwidth W] [--damping Z]
                             [--integral] [--sample-time TS] [--json]

Prints the design model (the linearised yaw response reduced to K/(1 + Ts), with Nomoto's
T₁ + T₂ − T₃ reduction beside it), the steering machine's bandwidth, the allowed bandwidth range,
the gains and the loop's margins (closed-loop stability, phase and gain margins, sensitivity peak,
the linearised heading step's settling time); the gains go into a scenario as
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
    sample_time: Annotated[float, typer.Option("--sample-time", help="The autopilot's sampling "
                                               "period [s] (a scenario's controller.Ts, by default "
                                               "its simulation.dt); 0: continuous.")] = 0.0,
    json_: Annotated[bool, typer.Option("--json", help="Print one JSON object on stdout.")] = False,
) -> None:
    """Heading autopilot gains for a vessel from its linearised yaw response (Fossen 2021 §15.3)."""
    from shipgnc.cli import friendly_errors, stdout

    with friendly_errors():
        from shipgnc.cli_trials import _vessel
        from shipgnc.errors import require
        from shipgnc.units import KNOT
        from shipgnc.vessels.autopilot_design import design_autopilot
        from shipgnc.vessels.setup import vessel_setup

        if speed_kn is not None:
            require(math.isfinite(speed_kn) and speed_kn > 0, "--speed-kn", speed_kn,
                    "must be a speed > 0 kn")
        require(math.isfinite(sample_time) and sample_time >= 0, "--sample-time", sample_time,
                "must be a period >= 0 s (0: continuous)")
        section, _ = _vessel(vessel)  # read as shipgnc run and shipgnc trial read it
        model = vessel_setup(section, speed_kn * KNOT if speed_kn is not None else None).model
        d = design_autopilot(model, bandwidth=bandwidth, zeta=damping, integral=integral,
                             sample_time=sample_time)
        if json_:
            m, c = d.model, d.check

            def finite(x: float) -> float | None:
                return x if math.isfinite(x) else None

            print(json.dumps({
                "vessel": vessel, "speed_mps": model.speed, "K": m.K, "T": m.T, "b": m.b,
                "K_nomoto": m.K_nomoto, "T_nomoto": m.T_nomoto, "omega_delta": m.omega_delta,
                "sample_time": m.sample_time, "rule": d.rule, "bandwidth": d.bandwidth,
                "zeta": finite(d.zeta), "omega_n": finite(d.omega_n), "Kp": d.Kp,
                "Kd": d.Kd, "Ki": d.Ki, "stable": c.stable, "gain_margin": finite(c.gain_margin),
                "phase_margin_deg": c.phase_margin_deg, "crossover": c.crossover,
                "sensitivity_peak": finite(c.sensitivity_peak),
                "settling_time_s": d.settling_time()}, indent=2))
            return
        stdout.print(f"{vessel} at {model.speed:.4g} m/s ({model.speed / KNOT:.3g} kn)",
                     soft_wrap=True)
        for line in d.lines():
            stdout.print(line, soft_wrap=True, markup=False)
        ts = f", Ts: {sample_time:g}" if sample_time > 0 else ""
        stdout.print(f"scenario: controller: {{type: course, Kp: {d.Kp:.4g}, Kd: {d.Kd:.4g}{ts}}} "
                     f"or {{type: course, design: auto{ts}}}", soft_wrap=True, markup=False)
