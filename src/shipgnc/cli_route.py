"""``shipgnc route``: time-optimal route in a current (note 002-2.9.6).

    shipgnc route --start N,E --target N,E --speed V --field FIELD [--method auto|pmp|levelset|graph]
                  [--obstacles FILE.geojson] [--units si|nautical] [--json] [--out DIR] [--max-memory 4G]
    shipgnc route --geo --start LAT,LON --target LAT,LON --speed V --field FILE.nc|uniform:..|still
                  [--depart 2026-06-01T06:00Z] [--land default|none|FILE] [--depth FILE.nc --draft M --ukc M]
                  [--xte-m 100] [--sail [--sail-vessel auto|boat|mariner]] [--json] [--out DIR]

``--geo`` (docs/routing_geo.md): positions in decimal degrees on WGS84, currents from CF-NetCDF, land from
the GSHHG coastline (or ``--land``), shallow water from ``--depth``; ``--out`` writes route.gpx,
route.geojson, route.rtz, route.json and route.png; the JSON adds ``distance_nm``, ``eta`` and
``waypoints`` ([lat, lon, eta]) to today's keys. ``--sail`` adds the sailed check
(:func:`shipgnc.routing.geo.sail.sail_check`, the ``sail_*`` keys): the Otter-class boat or the Mariner
(``--sail-vessel``) sails the exported waypoints with LOS guidance through the same current.

Before any work the memory the method needs is estimated (:mod:`shipgnc.routing.memory`: the sweep's
family tables, the level set's grids and stored fronts, the graph's edges); beyond the memory available
(or ``--max-memory``) the command stops with one line naming the estimate (exit 2). On a terminal a progress
display on stderr follows the sweep's polish and the level set's advance (nothing when stderr is a pipe).

SI by default; ``--units nautical`` reads positions in nm, speeds in kn, k and ω in 1/h, Γ in nm²/h and prints
times in h beside s. JSON keys stay SI. Exit codes: 0 a route, 2 bad input, 3 unreachable (one-line reason on
stderr, ``reachable: false`` in the JSON) or undecided (a search stopped by its effort bound: ``reachable:
null``, the reason names the bound), 1 internal error.
"""

from __future__ import annotations

import json
import math
import sys
from contextlib import contextmanager
from pathlib import Path
from typing import Annotated

import typer

from shipgnc.errors import ConfigError, ShipGNCError
from shipgnc.units import KNOT, NAUTICAL_MILE, nautical_text


def _pair(text: str, name: str, scale: float):
    parts = text.split(",")
    try:
        vals = [float(p) for p in parts]
    except ValueError:
        vals = []
    if len(vals) != 2 or not all(math.isfinite(v) for v in vals):
        raise ConfigError(f"{name} = {text!r}: expected two finite numbers N,E")
    return [vals[0] * scale, vals[1] * scale]


def route(
    start: Annotated[str, typer.Option("--start", help="Start N,E \\[m | nm].")],
    target: Annotated[str, typer.Option("--target", help="Target N,E \\[m | nm].")],
    speed: Annotated[float, typer.Option("--speed", help="Ship speed through water \\[m/s | kn].")],
    field: Annotated[str, typer.Option("--field", help="Current: uniform:north=..,east=.. | shear:k=.. | "
                                       "rotation:omega=..,north=..,east=.. | "
                                       "lamb-oseen:gamma=..,rc=..,north=..,"
                                       "east=.. | rankine:... ; '+' sums; or a NetCDF file.")],
    method: Annotated[str, typer.Option("--method", help="auto | pmp | levelset | graph")] = "auto",
    obstacles: Annotated[Path | None, typer.Option("--obstacles", help="GeoJSON polygons, [east, north] "
                                                   "coordinates \\[m | nm].")] = None,
    units: Annotated[str, typer.Option("--units", help="si | nautical")] = "si",
    json_: Annotated[bool, typer.Option("--json", help="Print one JSON object on stdout.")] = False,
    out: Annotated[Path | None, typer.Option("--out", help="Write route.png and route.json here.")] = None,
    horizon: Annotated[float | None, typer.Option("--horizon", help="Search horizon \\[s | h] "
                                                  "(default 4·|AB|/V).")] = None,
    radius: Annotated[float, typer.Option("--radius", help="Target disc radius \\[m | nm].")] = 0.0,
    depart: Annotated[str, typer.Option("--depart", help="Departure time t0 \\[s | h], or with --geo an ISO "
                                        "8601 UTC time (default: the current file's first time).")] = "0",
    grid: Annotated[float | None, typer.Option("--grid",
                                               help="Level-set / graph grid spacing \\[m | nm].")] = None,
    geo: Annotated[bool, typer.Option("--geo", help="Start/target as LAT,LON on WGS84; --field a CF-NetCDF "
                                      "file; land avoided (docs/routing_geo.md).")] = False,
    land: Annotated[str, typer.Option("--land", help="With --geo: default (GSHHG coastline), none, or a "
                                      "GeoJSON/shapefile of land polygons \\[lon, lat].")] = "default",
    depth: Annotated[Path | None, typer.Option("--depth", help="With --geo: bathymetry CF-NetCDF; water "
                                               "shallower than draft + UKC is avoided.")] = None,
    draft: Annotated[float, typer.Option("--draft", help="Ship's draught \\[m] (with --depth).")] = 0.0,
    ukc: Annotated[float, typer.Option("--ukc", help="Under-keel clearance \\[m] (with --depth).")] = 0.0,
    xte_m: Annotated[float, typer.Option("--xte-m", help="With --geo: cross-track tolerance of the "
                                         "waypoints \\[m].")] = 100.0,
    sail: Annotated[bool, typer.Option("--sail", help="With --geo: the sailed check, a vessel with LOS "
                                       "guidance sails the exported waypoints through the same current "
                                       "(sail_* keys).")] = False,
    sail_vessel: Annotated[str, typer.Option("--sail-vessel", help="With --sail: auto (the Otter-class boat "
                                             "when the speed is within its reach, else the Mariner) | boat "
                                             "(2 m, up to ≈ 2.3 m/s) | mariner (161 m, sails at 15 kn "
                                             "only).")] = "auto",
    max_memory: Annotated[str | None, typer.Option(
        "--max-memory", help="Memory the route may hold, e.g. 4G or 500M (default: the memory "
                             "available now); a larger estimate is refused before any work.")] = None,
) -> None:
    """Time-optimal route through a current field (Zermelo's problem)."""
    from shipgnc.cli import friendly_errors

    with friendly_errors():
        from shipgnc.errors import require
        from shipgnc.routing.router import METHODS

        if out is not None:
            from shipgnc.outputs import check_out

            check_out(out)  # before any work
        require(units in ("si", "nautical"), "--units", units, "allowed: si, nautical")
        require(method in METHODS, "--method", method, f"allowed: {', '.join(METHODS)}")
        from shipgnc.cli_sweep import parse_size

        limit = None if max_memory is None else parse_size(max_memory, "--max-memory")
        nautical = units == "nautical"
        length = NAUTICAL_MILE if nautical else 1.0
        vel = KNOT if nautical else 1.0
        tscale = 3600.0 if nautical else 1.0
        u_len, u_time = ("nm", "h") if nautical else ("m", "s")
        require(math.isfinite(speed) and speed > 0, "--speed", speed,
                f"must be a finite speed > 0 {'kn' if nautical else 'm/s'}")
        require(math.isfinite(radius) and radius >= 0, "--radius", radius,
                f"must be a finite radius >= 0 {u_len}")
        require(grid is None or (math.isfinite(grid) and grid > 0), "--grid", grid,
                f"must be a finite spacing > 0 {u_len}")
        require(horizon is None or (math.isfinite(horizon) and horizon > 0), "--horizon", horizon,
                f"must be a finite time > 0 {u_time}")
        if geo:
            _geo_route(start, target, speed * vel, field, method, obstacles, units, json_, out, horizon,
                       radius, depart, grid, land, depth, draft, ukc, xte_m, length, tscale, sail,
                       sail_vessel, limit)
            return
        depart_value = _number(depart, "--depart", "s | h; an ISO 8601 time needs --geo")
        geo_only = [name for name, given in (("--depth", depth is not None), ("--land", land != "default"),
                                             ("--draft", draft != 0.0), ("--ukc", ukc != 0.0),
                                             ("--xte-m", xte_m != 100.0), ("--sail", sail),
                                             ("--sail-vessel", sail_vessel != "auto")) if given]
        require(not geo_only, geo_only[0] if geo_only else "", "given", "needs --geo")
        a = _pair(start, "--start", length)
        b = _pair(target, "--target", length)
        with _in_units(nautical):
            _plane_route(a, b, speed * vel, field, units, method, obstacles, json_, out, horizon, radius,
                         depart_value, grid, length, tscale, nautical, limit)


def _plane_route(a, b, speed, field, units, method, obstacles, json_, out, horizon, radius, depart_value,
                 grid, length, tscale, nautical, limit) -> None:
    """``route`` on the plane (N, E), after the command's own checks; SI from here on."""
    from shipgnc.cli import stderr, stdout
    from shipgnc.environment.field_spec import parse_field
    from shipgnc.routing.router import solve_route

    fld = parse_field(field, units)
    polys = None
    if obstacles is not None:
        from shipgnc.routing.obstacles import load_geojson

        polys = load_geojson(obstacles, units)
    from shipgnc.routing.memory import route_memory_estimate
    from shipgnc.routing.router import _validate, check_grid

    t0 = depart_value * tscale
    t_h = None if horizon is None else horizon * tscale
    spacing = None if grid is None else grid * length
    _validate(fld, speed, a, b, t0, radius * length)  # the router's own errors, before the estimate
    check_grid(spacing, a, b, radius * length)
    _check_memory(route_memory_estimate(fld, speed, a, b, method=method, grid_spacing=spacing, horizon=t_h,
                                        obstacles=polys, t0=t0, radius=radius * length), limit)
    with _progress() as progress:
        res = solve_route(fld, speed, a, b, method=method, obstacles=polys, radius=radius * length, t0=t0,
                          horizon=t_h, grid_spacing=spacing, progress=progress)
    payload = res.to_json()
    text = json.dumps(payload, indent=2, ensure_ascii=False, default=_jsonable)
    if out is not None:  # atomic: a temporary directory moved into place when complete
        from shipgnc.outputs import atomic_dir
        from shipgnc.viz.route_figures import route_figure

        with atomic_dir(out, command="route") as tmp:
            (tmp / "route.json").write_text(text + "\n", encoding="utf-8")
            route_figure(res, tmp / "route.png", nautical=nautical)
        stderr.print(f"wrote route.json, route.png to {out}", soft_wrap=True)
    if json_:
        sys.stdout.write(text + "\n")
    else:
        _print(stdout, res, nautical)
    if not res.reachable:  # exit 3: unreachable, or undecided (the methods cannot resolve the scale)
        reason = " ".join(str(res.reason).split())
        label, reason = (("undecided", reason.removeprefix("undecided: ")) if reason.startswith("undecided")
                         else ("unreachable", reason))
        stderr.print(f"[bold red]{label}:[/] {nautical_text(reason) if nautical else reason}",
                     soft_wrap=True)
        raise typer.Exit(3)


@contextmanager
def _in_units(nautical: bool):
    """With ``--units nautical``, an error from the SI code below speaks nm, h and kn
    (:func:`~shipgnc.units.nautical_text`): the units the user typed."""
    try:
        yield
    except ShipGNCError as exc:
        if nautical:
            exc.args = (nautical_text(str(exc)),)
        raise


def _number(text: str, name: str, rule: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ConfigError(f"{name} = {text!r}: expected a number ({rule})") from None
    if not math.isfinite(value):
        raise ConfigError(f"{name} = {text!r}: must be finite")
    return value


def _check_memory(need, limit: float | None) -> None:
    """A ConfigError (exit 2, one line) when the estimate ``need``
    (:class:`~shipgnc.routing.memory.RouteMemory`) exceeds ``limit`` bytes (default: the memory
    available now, as ``shipgnc sweep`` measures it)."""
    from shipgnc.memory import available_memory
    from shipgnc.routing.memory import format_bytes

    have = available_memory() if limit is None else limit
    if need.total <= have:
        return
    what = f"{format_bytes(have)} is available" if limit is None else f"--max-memory is {format_bytes(have)}"
    hint = (need.advice(have) if callable(need.advice) else need.advice) or {
        "level set": "use a coarser --grid, a shorter --horizon or --method pmp",
        "graph": "use a coarser --grid or another --method",
        "sweep": "use --method levelset"}.get(need.largest(), "")
    raise ConfigError(f"route: needs about {format_bytes(need.total)} ({need.describe()}) but {what}; "
                      f"{hint + ', or ' if hint else ''}raise --max-memory")


@contextmanager
def _progress():
    """A ``progress(stage, fraction)`` callback drawing a rich progress display on stderr, one bar per
    stage (the sweep's polish, the level set's advance), cleared when done; None when stderr is not a
    terminal (pipes and tests see nothing, and the router does no extra work)."""
    from shipgnc.cli import stderr

    if not stderr.is_terminal:
        yield None
        return
    from rich.progress import BarColumn, Progress, TaskProgressColumn, TextColumn, TimeElapsedColumn

    labels = {"extremals": "extremals: polishing candidates", "level set": "level set: share of the horizon"}
    with Progress(TextColumn("{task.description}"), BarColumn(), TaskProgressColumn(), TimeElapsedColumn(),
                  console=stderr, transient=True) as bar:
        tasks: dict = {}

        def update(stage: str, fraction: float) -> None:
            if stage not in tasks:
                tasks[stage] = bar.add_task(labels.get(stage, stage), total=1.0)
            bar.update(tasks[stage], completed=fraction)

        yield update


def _geo_route(*args, **kw) -> None:
    """``route --geo`` (docs/routing_geo.md), the warnings of the libraries it calls (numpy, shapely,
    pyshp, ...) caught: none is printed before a one-line error; after a route they are its notes."""
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        _geo_route_run(*args, **kw, caught=caught)


def _warning_notes(caught) -> list[str]:
    seen = dict.fromkeys(f"warning ({w.category.__name__}): {' '.join(str(w.message).split())}"
                         for w in caught)
    return list(seen)


def _geo_route_run(start, target, speed, field, method, obstacles, units, json_, out, horizon, radius,
                   depart, grid, land, depth, draft, ukc, xte_m, length, tscale, sail=False,
                   sail_vessel="auto", limit=None, caught=()) -> None:
    from shipgnc.cli import stderr, stdout
    from shipgnc.errors import require
    from shipgnc.routing.geo.router import GeoProblem

    require(sail or sail_vessel == "auto", "--sail-vessel", sail_vessel, "needs --sail")
    if sail:  # the vessel that can sail the route's speed, before any work
        from shipgnc.routing.geo.sail import choose_vessel

        sail_vessel = choose_vessel(speed, sail_vessel)

    require(obstacles is None, "--obstacles", str(obstacles),
            "is for the local plane; with --geo give --land")
    require(radius == 0.0, "--radius", radius, "is not used with --geo (the target is a point)")
    for name, value in (("--draft", draft), ("--ukc", ukc)):  # a draft is checked against a depth only
        require(depth is not None or value == 0.0, name, value,
                "needs --depth (a bathymetry file): without it no water counts as too shallow")
    if out is not None:  # route.rtz's cross-track limits: RTZ 1.1 allows XTD < 10 nm
        from shipgnc.routing.geo.writers import RTZ_XTD_MAX_NM

        require(xte_m < RTZ_XTD_MAX_NM * NAUTICAL_MILE, "--xte-m", xte_m,
                f"with --out, below {RTZ_XTD_MAX_NM * NAUTICAL_MILE:g} m (RTZ 1.1's cross-track limit, "
                f"{RTZ_XTD_MAX_NM:g} nm)")
    a = _pair(start, "--start", 1.0)
    b = _pair(target, "--target", 1.0)
    if a == b:
        raise ConfigError(f"--start = --target = {start!r}: the same point, nothing to route")
    current = _geo_field(field, units)
    try:
        offset, iso_depart = _number(depart, "--depart", "") * tscale, None
    except ConfigError:
        from shipgnc.routing.geo.timefmt import parse_iso

        offset, iso_depart = 0.0, parse_iso(depart)
    problem = GeoProblem(a, b, speed, current=current, land=land, depth=depth, draft=draft, ukc=ukc,
                         grid=None if grid is None else grid * length, xte_m=xte_m,
                         budget=lambda need: _check_memory(need, limit))
    if iso_depart is None and problem.current.times is None and offset:
        raise ConfigError(f"--depart = {depart!r}: the current has no time axis; give an ISO 8601 UTC time")
    t_dep = problem.departure(iso_depart, offset)
    t_h = None if horizon is None else horizon * tscale
    fld = problem.field_from(t_dep)
    need = problem.memory_estimate(fld, method=method, horizon=t_h,
                                   unit=(length, "nm" if length > 1 else "m"))
    _check_memory(need, limit)
    with _progress() as progress:
        res = problem.solve(t_dep, method=method, horizon=t_h, progress=progress)
    payload = res.to_json()
    payload["notes"].extend(_warning_notes(caught))
    if sail and res.reachable:
        from shipgnc.routing.geo.sail import sail_check

        payload.update(sail_check(res, vessel=sail_vessel))
    text = json.dumps(payload, indent=2, ensure_ascii=False, default=_jsonable)
    if out is not None and res.reachable:
        from shipgnc.outputs import atomic_dir
        from shipgnc.routing.geo.figures import geo_route_figure
        from shipgnc.routing.geo.writers import write_geojson, write_gpx, write_rtz

        with atomic_dir(out, command="route") as tmp:
            (tmp / "route.json").write_text(text + "\n", encoding="utf-8")
            write_gpx(tmp / "route.gpx", res.waypoints)
            write_geojson(tmp / "route.geojson", res.waypoints,
                          {"time_s": payload["time_s"], "distance_nm": payload["distance_nm"],
                           "eta": payload["eta"], "xte_m": xte_m})
            write_rtz(tmp / "route.rtz", res.waypoints, xte_m=xte_m)
            geo_route_figure(res, tmp / "route.png")
        stderr.print(f"wrote route.json, route.gpx, route.geojson, route.rtz, route.png to {out}",
                     soft_wrap=True)
    if out is not None and not res.reachable:
        from shipgnc.outputs import atomic_dir

        with atomic_dir(out, command="route") as tmp:
            (tmp / "route.json").write_text(text + "\n", encoding="utf-8")
        stderr.print(f"wrote route.json to {out}", soft_wrap=True)
    if json_:
        sys.stdout.write(text + "\n")
    else:
        _print_geo(stdout, payload)
    if not res.reachable:
        reason = next((n for n in payload["notes"] if n.startswith("unreachable")), "unreachable")
        stderr.print(f"[bold red]unreachable:[/] {' '.join(reason.removeprefix('unreachable: ').split())}",
                     soft_wrap=True)
        raise typer.Exit(3)


def _geo_field(field: str, units: str):
    """A CF-NetCDF path, ``still``/``none``, or ``uniform:north=..,east=..`` (true north/east)."""
    from shipgnc.environment.fields import UniformCurrent

    text = field.strip()
    if text.lower() in ("still", "none", "0"):
        return None
    if text.lower().startswith("uniform"):
        from shipgnc.environment.field_spec import parse_field

        fld = parse_field(text, units)
        if isinstance(fld, UniformCurrent):
            return (fld.north, fld.east)
    if Path(text).suffix.lower() in (".nc", ".nc4", ".netcdf", ".cdf") or Path(text).exists():
        return text
    raise ConfigError(f"--field = {field!r}: with --geo, a CF-NetCDF file, 'still', or "
                      "uniform:north=..,east=.. (true north/east)")


def _print_geo(console, js) -> None:
    from rich.markup import escape
    from rich.table import Table

    table = Table(title="route (WGS84)", title_justify="left")
    table.add_column("quantity", style="bold")
    table.add_column("value", justify="right")

    def row(name, value):
        table.add_row(escape(name), escape(value))

    row("reachable", "yes" if js["reachable"] else "no")
    if js["reachable"]:
        t = js["time_s"]
        row("time to target", f"{t:.0f} s = {t / 3600:.4f} h")
        row("distance [nm]", f"{js['distance_nm']:.2f} (geodesic {js['geodesic_nm']:.2f})")
        if js["depart"]:
            row("departure (UTC)", js["depart"])
            row("arrival (UTC)", js["eta"])
        row("waypoints", f"{len(js['waypoints'])} (cross-track tolerance {js['xte_m']:g} m)")
        row("initial heading [deg]", f"{js['heading_start_deg']:.2f}")
        row("clear of land and shallow water", {True: "yes", False: "NO", None: "—"}[js["land_clear"]])
    if "sail_arrived" in js:
        row("sailed check: vessel", js["sail_vessel"])
        row("sailed check: arrived", (f"yes (within {js['sail_acceptance_radius_m']:.4g} m)"
                                      if js["sail_arrived"] else f"no (miss {js['sail_miss_m']:.1f} m)"))
        if js["sail_time_s"] is not None:
            row("sailed check: time / optimum", f"{js['sail_time_s']:.0f} s / {js['sail_ratio']:.4f}")
        if js["sail_crosstrack_max_m"] is not None:
            row("sailed check: max cross-track [m]", f"{js['sail_crosstrack_max_m']:.1f}")
    row("method", js["method"])
    gc = js["global_check"]
    if gc and gc.get("time_s") is not None and js["method"] != "levelset":
        row("global check by level set (plane)", f"{gc['time_s']:.0f} s ({gc['rel_diff']:+.2e})")
    console.print(table)
    for note in js["notes"]:
        console.print(f"note: {escape(note)}", soft_wrap=True)


def _jsonable(x):
    import numpy as np

    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    raise TypeError(type(x).__name__)


def _print(console, res, nautical: bool) -> None:
    """The route as a quantity/value table, every row named in words with its unit.

    "time to target" is t_f − t₀ (the route's duration); "arrival time" is the clock time of arrival,
    departure + time to target, printed only when ``--depart`` is not 0 (else it equals the former).
    """
    from rich.markup import escape
    from rich.table import Table

    js = res.to_json()
    table = Table(title="route", title_justify="left")
    table.add_column("quantity", style="bold")
    table.add_column("value", justify="right")

    def row(name: str, value: str) -> None:  # "[deg]" is a unit, not rich markup
        table.add_row(escape(name), escape(value))

    row("reachable", {True: "yes", False: "no", None: "undecided"}[js["reachable"]])
    if res.reachable:
        t = js["time_s"]
        row("time to target", f"{t:.2f} s = {t / 3600:.6f} h")
        if res.t0:
            eta = res.t0 + t
            row("arrival time (departure + time to target)",
                f"{eta:.2f} s" + (f" = {eta / 3600:.4f} h" if nautical else ""))
        if js["heading_start_deg"] is not None:
            row("initial heading [deg]", f"{js['heading_start_deg']:.4f}")
            row("final heading [deg]", f"{js['heading_end_deg']:.4f}")
        row("miss distance [m]", f"{js['miss_m']:.3g}")
    row("method", {"pmp": "extremals (maximum principle)", "levelset": "level set",
                   "graph": "graph search"}.get(js["method"], js["method"]))
    if res.grid_spacing:
        g = res.grid_spacing
        row("grid spacing", f"{g:.1f} m" + (f" = {g / NAUTICAL_MILE:.4f} nm" if nautical else ""))
    if js["extremals"]:
        row("extremals: time to target [s]" + (" ([h])" if nautical else ""),
            ", ".join(f"{t:.1f}" + (f" ({t / 3600:.4f})" if nautical else "") for t in js["extremals"]))
    gc = js["global_check"]
    if gc:
        name = {"levelset": "level set", "graph": "graph search"}.get(gc["method"], gc["method"])
        val = ("—" if gc["time_s"] is None
               else f"{gc['time_s']:.1f} s (relative difference {gc['rel_diff']:+.2e}"
               + ("" if "agrees" not in gc else
                  f"; {'agrees' if gc['agrees'] else 'DISAGREES'} within {gc['tolerance']:.2%}") + ")")
        row(f"global check by {name}: time to target", val)
    console.print(table)
    for note in js["notes"]:
        console.print(f"note: {nautical_text(note) if nautical else note}", soft_wrap=True)
