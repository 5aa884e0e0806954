"""``shipgnc encounters``: the standard encounter set (or trafficgen situation files) met by the
own ship with each collision-avoidance method, as one batched run, scored.

    shipgnc encounters [SITUATION.json ...] [--mc N] [--seed S] [--method none,...] [--out DIR]
                       [--awareness ais [--ais-noise M] [--ais-dropout P]]
                       [--ais-log PATH [--ais-member K]]

Without files: the standard set (:data:`shipgnc.study.trafficgen.STANDARD`: head-on, overtaking
give-way and stand-on, crossing give-way and stand-on), written as trafficgen traffic situations to
``DIR/situations/``; ``--mc N``: N variants of each, bearing, range and speeds perturbed
(:func:`shipgnc.study.trafficgen.perturbed`) from ``--seed``. Prints a summary per encounter type
and method (members, collisions, median and least CPA, median time lost) and writes
``summary.csv/.md``, ``members.csv/.md`` (every member's scores) and the figures (tracks with ship
outlines and the CPA marked; CPA by target bearing); ``--awareness ais``: the avoidance sees the
targets through AIS (reporting intervals of ITU-R M.1371-5, ``--ais-noise`` [m], ``--ais-dropout``,
seeded by ``--seed``), the scores against the truth; ``--ais-log PATH``: member K's run (own ship
``!AIVDO``, its targets ``!AIVDM``, :mod:`shipgnc.study.ais_out`; run again alone, logged every
step) as an NMEA AIS log, one encounter per file so that a chart plotter shows one own ship. A
situation file of the wrong schema, or a target inside the safety radius at t = 0: one line naming
the field, exit 2.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer


def encounters(
    situations: Annotated[list[Path] | None, typer.Argument(
        help="trafficgen traffic situation files (JSON); left out: the standard set.",
        show_default=False)] = None,
    mc: Annotated[int, typer.Option("--mc", min=0, help="Perturbed variants of each standard "
                                    "situation (0: the standard set itself).")] = 0,
    seed: Annotated[int, typer.Option("--seed", min=0, help="Seed of the perturbations.")] = 0,
    method: Annotated[str, typer.Option("--method", help="Avoidance methods, comma-separated.")]
        = "none",
    out: Annotated[Path, typer.Option("--out", help="Output directory.")] = Path("encounters-out"),
    figures: Annotated[bool, typer.Option("--figures/--no-figures", help="Write the figures.")]
        = True,
    backend: Annotated[str, typer.Option("--backend", help="auto (compiled) or numpy.")] = "auto",
    awareness: Annotated[str, typer.Option(
        "--awareness", help="What the avoidance sees of the targets: truth, or ais (their reports "
                            "at the AIS intervals; scores against the truth).")] = "truth",
    ais_noise: Annotated[float, typer.Option(
        "--ais-noise", help="With --awareness ais: the reported position's noise, standard "
                            "deviation [m] in north and in east.")] = 0.0,
    ais_dropout: Annotated[float, typer.Option(
        "--ais-dropout", help="With --awareness ais: the probability that a report is lost.")] = 0.0,
    ais_log: Annotated[Path | None, typer.Option(
        "--ais-log", help="Write one member's run as an NMEA AIS log (own ship !AIVDO, targets "
                          "!AIVDM) to this file.", show_default=False)] = None,
    ais_member: Annotated[int, typer.Option(
        "--ais-member", min=0, help="The member --ais-log writes (see members.csv).")] = 0,
) -> None:
    """Run the standard encounter set (or trafficgen situation files) with each avoidance method."""
    from shipgnc.cli import friendly_errors

    with friendly_errors():
        from shipgnc.errors import ConfigError
        from shipgnc.scenarios.runner import write_table
        from shipgnc.study import encounters as E
        from shipgnc.study import trafficgen as tg

        if backend not in ("auto", "numpy"):
            raise ConfigError(f"--backend {backend!r}: allowed: auto, numpy")
        methods = E.check_methods([m.strip() for m in method.split(",") if m.strip()])
        if not methods:
            raise ConfigError("--method: give at least one avoidance method")
        if situations and mc:
            raise ConfigError("--mc perturbs the standard set; it does not apply to situation files")
        members = E.file_members(situations, methods) if situations else \
            E.standard_members(methods, mc=mc, seed=seed)
        ais = _awareness(awareness, ais_noise, ais_dropout, seed)
        if ais_log is not None:
            from shipgnc.outputs import check_out_file

            check_out_file(ais_log, "--ais-log")  # before the sweep, not after it
        if ais_log is not None and ais_member >= len(members):
            raise ConfigError(f"--ais-member {ais_member}: the sweep has members 0 to "
                              f"{len(members) - 1}")
        out.mkdir(parents=True, exist_ok=True)
        if not situations:
            folder = out / "situations"
            folder.mkdir(exist_ok=True)
            for spec in tg.STANDARD:
                tg.write(tg.situation_dict(spec, members[0].situation.own_speed),
                         folder / f"{spec.title}.json")
            for m in members:  # each Monte Carlo variant, so that a member can be rerun
                if mc and m.spec is not None:
                    tg.write(tg.situation_dict(m.spec, m.situation.own_speed),
                             folder / f"{m.spec.title}-mc{m.mc}.json")
        result = E.run_members(members, backend=backend, keep_results=figures, ais=ais)
        rows = E.summary(result)
        _print(rows, result)
        disagree = sum(row["label_disagrees"] for row in rows)
        print(f"{disagree} of {len(result.members)} members carry a label other than their "
              "COLREG situation at t = 0 (grouped by the situation)")
        written = write_table(rows, out, "summary") + write_table(E.member_rows(result), out,
                                                                  "members")
        if figures:
            from shipgnc.viz.encounter_figures import write_figures

            written += write_figures(result, out)
        if ais_log is not None:
            from shipgnc.study.ais_out import member_log

            log = member_log(ais_log, members[ais_member], backend=backend, ais=ais)
            print(f"wrote the AIS log {log} (member {ais_member}: {members[ais_member].situation.title}, "
                  f"{members[ais_member].method})")
        print(f"wrote {', '.join(p.name for p in written)} to {out}")


def _awareness(awareness: str, noise: float, dropout: float, seed: int):
    """The AIS reception of ``--awareness ais`` (None: the truth); bad values one line each."""
    from pydantic import ValidationError

    from shipgnc.errors import ConfigError
    from shipgnc.scenarios.sections import AISAwarenessConfig

    if awareness not in ("truth", "ais"):
        raise ConfigError(f"--awareness {awareness!r}: allowed: truth, ais")
    if awareness == "truth":
        if noise or dropout:
            raise ConfigError("--ais-noise and --ais-dropout need --awareness ais")
        return None
    try:
        return AISAwarenessConfig(seed=seed, position_noise_m=noise, dropout=dropout)
    except ValidationError as exc:
        err = exc.errors()[0]
        flag = {"position_noise_m": "--ais-noise", "dropout": "--ais-dropout"}.get(
            str(err["loc"][0]), str(err["loc"][0]))
        raise ConfigError(f"{flag} = {err['input']!r}: {err['msg']}") from None


def _print(rows, result) -> None:
    from rich.console import Console
    from rich.table import Table

    table = Table(title=f"encounters: {len(result.members)} members in {result.seconds:.1f} s "
                        f"({len(result.members) / max(result.seconds, 1e-9):.0f} encounters/s)",
                  title_justify="left")
    for name in rows[0]:
        table.add_column(name, justify="left" if name in ("situation", "encounter", "method")
                         else "right")
    for row in rows:
        table.add_row(*(f"{v:.1f}" if isinstance(v, float) else str(v) for v in row.values()))
    Console().print(table)
