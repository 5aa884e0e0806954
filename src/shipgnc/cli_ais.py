"""``shipgnc ais``: logged AIS files (:mod:`shipgnc.ais`).

    shipgnc ais info FILE [--origin LAT,LON] [--skip-unknown] [--json]

Reads a logged AIS file (NMEA ``!AIVDM``/``!AIVDO`` with tag-block or leading times, or a CSV of
MMSI, time, lat, lon, SOG, COG, heading: :mod:`shipgnc.ais.logs`) and prints its targets: MMSI,
name, reports, the time span and the speeds, with the file's time span and the local plane's origin.
A file that does not read is one line naming the line or field, exit 2.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Annotated

import typer

app = typer.Typer(add_completion=False, no_args_is_help=True, help="Logged AIS files (NMEA or CSV).")


def _origin(text: str | None):
    from shipgnc.errors import ConfigError

    if text is None:
        return None
    try:
        lat, lon = (float(v) for v in text.split(","))
    except ValueError:
        raise ConfigError(f"--origin {text}: must be LAT,LON in degrees, e.g. --origin 57.7,10.6") from None
    return lat, lon


@app.command("info")
def info(
    file: Annotated[Path, typer.Argument(help="The AIS log: NMEA sentences or a CSV.", show_default=False)],
    origin: Annotated[str | None, typer.Option(
        "--origin", help="LAT,LON [deg] of the local plane's origin (default: the data's centre).")] = None,
    skip_unknown: Annotated[bool, typer.Option(
        "--skip-unknown", help="Leave out sentences and AIS message types that are not read "
                               "(default: they are an error).")] = False,
    untimed: Annotated[str, typer.Option(
        "--untimed", help="A message without a time: refuse, or previous (the latest line's "
                          "time before it).")] = "refuse",
    json_: Annotated[bool, typer.Option("--json", help="Print JSON on stdout.")] = False,
) -> None:
    """The targets of a logged AIS file: MMSI, name, reports, time span, speeds."""
    from shipgnc.cli import friendly_errors, print_columns, stdout

    with friendly_errors():
        from shipgnc.ais.logs import read_log, read_reports, utc_text
        from shipgnc.units import KNOT

        reports = read_reports(file, skip_unknown=skip_unknown, untimed=untimed)
        t0 = min(r.time for r in reports) if reports else 0.0
        left_out: list[int] = []
        tracks, org = read_log(file, origin=_origin(origin), t0=t0, reports=reports,
                               skip_unknown=skip_unknown, left_out=left_out)
        t1 = max(r.time for r in reports)
        rows = []
        for tr in tracks:
            speed = [math.hypot(a, b) / KNOT for a, b in zip(tr.v_north, tr.v_east, strict=True)]
            rows.append(dict(mmsi=tr.mmsi, name=tr.name, source=tr.source, reports=int(tr.t.size),
                             first_utc=utc_text(t0 + tr.t[0]), last_utc=utc_text(t0 + tr.t[-1]),
                             span_min=round(float(tr.t[-1] - tr.t[0]) / 60.0, 2),
                             min_sog_kn=round(min(speed), 1), max_sog_kn=round(max(speed), 1)))
        summary = dict(file=str(file), messages=len(reports), targets=len(tracks), first_utc=utc_text(t0),
                       last_utc=utc_text(t1), span_min=round((t1 - t0) / 60.0, 2), origin=list(org),
                       no_position=left_out)
        if json_:
            stdout.print_json(json.dumps(dict(summary, tracks=rows)))
            return
        stdout.print(f"{file}: {len(reports)} messages, {len(tracks)} targets, {summary['first_utc']} to "
                     f"{summary['last_utc']} ({summary['span_min']:g} min); local plane about "
                     f"{org[0]:.5f}°, {org[1]:.5f}°", soft_wrap=True)
        names = ["name", "source", "reports", "first_utc", "last_utc", "span_min", "min_sog_kn", "max_sog_kn"]
        print_columns(stdout, "targets", "MMSI", [str(r["mmsi"]) for r in rows],
                     {n: [str(r[n]) for r in rows] for n in names})
        if left_out:
            stdout.print(f"note: left out (static data only, no position report): MMSI "
                         f"{', '.join(str(m) for m in left_out)}", soft_wrap=True)
