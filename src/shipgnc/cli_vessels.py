"""``shipgnc vessels``: the vessel catalogue (:mod:`shipgnc.vessels`).

    shipgnc vessels [--json]

A table of every catalogue entry: name, source, length, design speed, valid speed range, rudder
limits, whether it can go astern, and its states. ``--json`` prints one JSON list (SI, plus the
design speed in knots and the rudder limits in degrees). Each name is usable as
``vessel: {model: NAME, ...}`` in a scenario file.
"""

from __future__ import annotations

import json
from typing import Annotated

import typer


def vessels(
    json_: Annotated[bool, typer.Option("--json", help="Print one JSON list on stdout.")] = False,
) -> None:
    """List the vessel catalogue (usable as vessel: {model: NAME} in scenarios)."""
    from shipgnc.cli import friendly_errors, stdout

    with friendly_errors():
        from rich import box
        from rich.markup import escape
        from rich.table import Table

        from shipgnc.vessels import VESSELS

        rows = [entry.row() for entry in VESSELS.values()]
        if json_:
            print(json.dumps(rows, indent=2))
            return
        table = Table(title="vessel catalogue (vessel: {model: NAME} in a scenario)",
                      title_justify="left", box=box.SIMPLE_HEAD, pad_edge=False)
        common = [name for name in next(iter(VESSELS.values())).states
                  if all(name in entry.states for entry in VESSELS.values())]
        headers = ("name", "L [m]", "U [m/s]", "valid U [m/s]", "rudder [°, °/s]", "astern",
                   "+ states")
        for column in headers:
            table.add_column(column, overflow="fold", style="bold" if column == "name" else None)
        for entry, row in zip(VESSELS.values(), rows, strict=True):
            low, high = entry.speed_range_mps
            length = "—" if entry.length_m is None else f"{entry.length_m:g}"
            table.add_row(
                escape(entry.name), length,
                f"{entry.design_speed_mps:.3g}",
                f"{low:.3g}–{high:.3g}",
                f"{row['max_rudder_deg']:.3g}, {row['max_rudder_rate_deg_s']:.3g}",
                "yes" if entry.can_reverse else "no",
                ", ".join(name for name in entry.states if name not in common) or "—")
        stdout.print(table)
        stdout.print(f"states of every vessel: {', '.join(common)}; L —: a model given by its "
                     "parameters (U is then a default)")
        stdout.print("sources:")
        for entry in VESSELS.values():
            stdout.print(f"  [bold]{escape(entry.name)}[/]: {escape(entry.source)}")

