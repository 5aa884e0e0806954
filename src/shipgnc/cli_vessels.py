"""``shipgnc vessels``: every vessel a scenario may name (:func:`shipgnc.vessels.catalogue.listing`).

    shipgnc vessels [NAME] [--json]

A table of every vessel: the documents' models (document 001's boat with its presets, CyberShip
II, the de Wit–Oppe Mariner, the catamaran) and the catalogue's (:mod:`shipgnc.vessels`): name,
source, length, design speed, valid speed range, rudder limits, other inputs and their limits,
whether it can go astern, and its states. ``--json`` prints one JSON list (SI, plus the design
speed in knots and the rudder limits in degrees). Each name is usable as
``vessel: {model: NAME, ...}`` in a scenario file. ``shipgnc vessels NAME`` (a vessel, or a
preset of one) describes one vessel: its speeds and where they come from, its states and inputs
with units and limits, its parameters (those ``shipgnc sweep --perturb vessel.params.NAME`` may
draw) and presets.
"""

from __future__ import annotations

import json
import math
from typing import Annotated

import typer


def vessels(
    name: Annotated[str | None, typer.Argument(
        help="A vessel (or a preset of one) to describe; left out: list every vessel.",
        show_default=False)] = None,
    json_: Annotated[bool, typer.Option("--json", help="Print JSON on stdout.")] = False,
) -> None:
    """List every vessel (usable as vessel: {model: NAME} in scenarios), or describe one."""
    from shipgnc.cli import friendly_errors

    with friendly_errors():
        from shipgnc.vessels.catalogue import listing

        rows = listing()
        if name is not None:
            row = describe(name, rows)
            if json_:
                print(json.dumps(row, indent=2))
            else:
                _print_one(row)
            return
        if json_:
            print(json.dumps(list(rows.values()), indent=2))
            return
        _print_table(rows)


def _limits(item: dict) -> str:
    """``T 0–200 N`` / ``alpha ±45°`` / ``delta_rate unlimited``: an input and its limits."""
    low, high, unit = item["min"], item["max"], item["unit"]
    if low is None and high is None:
        return f"{item['name']} unlimited"
    if unit == "rad":  # angles in degrees
        low, high, unit = math.degrees(low), math.degrees(high), "°"
    if low is not None and high is not None and math.isclose(low, -high):
        return f"{item['name']} ±{high:.3g}{unit if unit == '°' else ' ' + unit}"
    return f"{item['name']} {low:.3g}–{high:.3g} {unit}"


def _rudder(row: dict) -> str:
    if row["max_rudder_deg"] is None:
        return "—"
    return f"{row['max_rudder_deg']:.3g}, {row['max_rudder_rate_deg_s']:.3g}"


def _other_inputs(row: dict) -> str:
    """The inputs beside the rudder (thrusters, propellers), with their limits."""
    rudder = () if row["max_rudder_deg"] is None else ("delta", "delta_c")
    return ", ".join(_limits(i) for i in row["inputs"] if i["name"] not in rudder) or "—"


def _from(row: dict) -> str:
    return f"doc {row['document']}" if row["document"] else "paper"


def _print_table(rows: dict) -> None:
    from rich import box
    from rich.markup import escape
    from rich.table import Table

    from shipgnc.cli import stdout

    table = Table(title="vessel catalogue (vessel: {model: NAME} in a scenario)",
                  title_justify="left", box=box.SIMPLE_HEAD, pad_edge=False)
    first = next(iter(rows.values()))["states"]
    common = [s for s in first if all(s in row["states"] for row in rows.values())]
    headers = ("name", "from", "L [m]", "U [m/s]", "valid U [m/s]", "rudder [°, °/s]",
               "astern", "+ states")
    for column in headers:
        table.add_column(escape(column), overflow="fold", style="bold" if column == "name" else None,
                         no_wrap=column == "name")
    for row in rows.values():
        low, high = row["speed_range_mps"]
        length = "—" if row["length_m"] is None else f"{row['length_m']:g}"
        table.add_row(
            escape(row["name"]), _from(row), length, f"{row['design_speed_mps']:.3g}",
            f"{low:.3g}–{high:.3g}", _rudder(row), "yes" if row["can_reverse"] else "no",
            ", ".join(s for s in row["states"] if s not in common) or "—")
    stdout.print(table)
    stdout.print(f"states of every vessel: {', '.join(common)}; L —: a model given by its "
                 "parameters (U is then a default); a document's valid U: the straight runs its "
                 "actuators reach (shipgnc vessels NAME says how)")
    others = [f"{escape(row['name'])}: {escape(_other_inputs(row))}" for row in rows.values()
              if _other_inputs(row) != "—"]
    stdout.print("thrusters and propellers: " + "; ".join(others))
    presets = [f"{escape(row['name'])}: {', '.join(row['presets'])}" for row in rows.values()
               if row["presets"]]
    stdout.print("presets (vessel: {model: NAME, preset: PRESET}): " + "; ".join(presets))
    stdout.print("sources:")
    for row in rows.values():
        stdout.print(f"  [bold]{escape(row['name'])}[/]: {escape(row['source'])}")


def describe(name: str, rows: dict) -> dict:
    """The row of vessel ``name`` (or of the vessel a preset ``name`` belongs to, with that
    preset), with ``perturbable``: the parameters ``--perturb vessel.params.NAME`` may draw on
    its default section (an empty list, and ``perturbable_note``, when the vessel needs
    parameters to be built)."""
    from shipgnc.errors import ConfigError
    from shipgnc.vessels.documents import document_vessels

    documents = document_vessels()
    preset = None
    if name not in rows:
        owner = [v for v in documents.values() if name in v.presets]
        if not owner:
            presets = [p for v in documents.values() for p in v.presets]
            raise ConfigError(f"vessel {name!r}: unknown vessel; allowed: {', '.join(rows)} (or a "
                              f"preset: {', '.join(presets)})")
        name, preset = owner[0].name, name
    row = dict(documents[name].row(preset)) if name in documents else dict(rows[name])
    if preset is not None:
        row["preset"] = preset
    row.update(_perturbable(name, preset, documents))
    return row


def _perturbable(name: str, preset, documents) -> dict:
    """``perturbable`` (and the nominal ``param_values``) of the vessel's default section."""
    from shipgnc.errors import ConfigError
    from shipgnc.models.per_ship import plant_params
    from shipgnc.study.plant import perturbable_params

    if name in documents:
        model = documents[name].model(preset)
    else:
        from shipgnc.vessels.config import CatalogueVesselConfig

        try:
            model = CatalogueVesselConfig.model_validate({"model": name}).build()
        except (ConfigError, ValueError):  # a model given by its parameters (e.g. K, T)
            from shipgnc.vessels.catalogue import get_vessel

            given = ", ".join(get_vessel(name).param_names)
            return {"perturbable": [], "perturbable_note": (
                f"the numbers its vessel section gives (of {given}) and the steering machine's "
                "rudder_rate_deg_s, rudder_time_constant_s, where they enter its equations")}
    values = {k: float(v) for k, v in plant_params(model).items()
              if isinstance(v, (int, float)) and not isinstance(v, bool)}
    return {"perturbable": perturbable_params(model), "param_values": values}


def _print_one(row: dict) -> None:
    from rich.markup import escape

    from shipgnc.cli import stdout

    preset = f", preset: {row['preset']}" if "preset" in row else ""
    stdout.print(f"[bold]{escape(row['name'])}[/]: {escape(row['title'])}")
    stdout.print(escape(f"  in a scenario: vessel: {{model: {row['name']}{preset}}}"))
    stdout.print(f"  from: {_from(row)}; source: {escape(row['source'])}")
    length = "—" if row["length_m"] is None else f"{row['length_m']:g} m"
    low, high = row["speed_range_mps"]
    stdout.print(f"  L = {length}; U = {row['design_speed_mps']:.4g} m/s "
                 f"({row['design_speed_kn']:.3g} kn); valid U = {low:.4g}–{high:.4g} m/s "
                 f"({escape(row['speed_note'])})")
    stdout.print(f"  rudder [°, °/s]: {_rudder(row)}; astern: "
                 f"{'yes' if row['can_reverse'] else 'no'}")
    stdout.print(f"  inputs: {escape('; '.join(_limits(i) for i in row['inputs']))}")
    stdout.print(f"  states: {', '.join(row['states'])}")
    if row["perturbable"]:
        values = row.get("param_values", {})
        shown = ", ".join(f"{p} = {values[p]:.6g}" if p in values else p
                          for p in row["perturbable"])
        stdout.print(escape(f"  perturbable (shipgnc sweep --perturb vessel.params.NAME=...): "
                            f"{shown}"))
    else:
        stdout.print(escape(f"  perturbable: {row.get('perturbable_note', 'none')}"))
    if row["params"]:
        stdout.print(escape(f"  parameters: {', '.join(row['params'])}"))
    if row["presets"]:
        from shipgnc.vessels.documents import document_vessels

        notes = document_vessels()[row["name"]].preset_notes
        stdout.print("  presets (vessel: {model: NAME, preset: PRESET}):")
        for name in row["presets"]:
            stdout.print(escape(f"    {name}: {notes.get(name, '')}"))
