"""Reading and checking a logged run for identification: CSV or NetCDF (``shipgnc identify``).

A log is a table of samples: a time column [s] and the signals the model needs, each found by its
*role* (``time``, ``rudder``, ``heading``, ``yaw_rate``, ``u``, ``v``). A role's column is the one
named with ``--columns role=NAME``, else the first present of :data:`DEFAULT_COLUMNS` (shipgnc's
own ``result.nc`` names them ``time``, ``delta``, ``psi``, ``r``, ``u``, ``v``). Angles
(rudder, heading, yaw rate) are in radians (rad/s) unless ``units="deg"``; a NetCDF variable's
``units`` attribute decides when no unit is given. Speeds are m/s, time s.

Every problem is a one-line :class:`~shipgnc.errors.ConfigError` naming it: the file missing or
unreadable, a missing or misnamed column (with the columns present), a cell that is not a number,
time not strictly increasing (at which row), rows holding NaN (which rows), a rudder that looks
like degrees read as radians. CSV rows are named by their line in the file (1 = the first line,
the header counted); NetCDF rows by their time index (0 = the first sample).

A log sampled at uneven steps is interpolated linearly onto a uniform grid at its median step
(the fitters integrate exactly between equally spaced samples); a note says so.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from shipgnc.errors import ConfigError

#: uneven steps up to this many median steps are interpolated; a longer gap is refused
MAX_GAP_STEPS = 10

#: the roles a log's columns play, in order
ROLES = ("time", "rudder", "heading", "yaw_rate", "u", "v")
#: default column names of each role, first match wins (shipgnc's result.nc first)
DEFAULT_COLUMNS = {
    "time": ("time", "t"),
    "rudder": ("delta", "rudder"),
    "heading": ("psi", "heading"),
    "yaw_rate": ("r", "yaw_rate"),
    "u": ("u", "surge"),
    "v": ("v", "sway"),
}
#: roles holding angles, and their SI unit
ANGLE_ROLES = {"rudder": "rad", "heading": "rad", "yaw_rate": "rad/s"}
#: unit attribute spellings (NetCDF ``units``) read as radians or degrees
_RAD_UNITS = {"rad", "radian", "radians", "rad/s", "rad s-1", "rad/sec", "radian/s", "radians/s"}
_DEG_UNITS = {"deg", "degree", "degrees", "deg/s", "deg s-1", "degree/s", "degrees/s", "°", "°/s"}
#: at least this many samples
MIN_SAMPLES = 20
_NAN_WORDS = {"", "nan", "na", "n/a", "null", "none", "-nan"}
_NETCDF_SUFFIXES = {".nc", ".nc4", ".netcdf", ".cdf", ".h5", ".hdf5"}


@dataclass
class Log:
    """A checked log in SI (angles rad, heading unwrapped), equally spaced in time."""

    path: str
    kind: str                          # "csv" | "netcdf"
    t: np.ndarray
    data: dict[str, np.ndarray]        # role -> samples
    names: dict[str, str]              # role -> column name in the file
    present: tuple[str, ...]           # every column of the file
    units: str                         # "rad" | "deg" (of the angle columns as read)
    ship: int | None = None
    notes: list[str] = field(default_factory=list)

    @property
    def dt(self) -> float:
        return float(self.t[1] - self.t[0])

    def has(self, role: str) -> bool:
        return role in self.data


def parse_columns(text: str | None) -> dict[str, str]:
    """``"time=t,rudder=delta_deg"`` → ``{"time": "t", "rudder": "delta_deg"}`` (roles checked)."""
    if text is None or not text.strip():
        return {}
    out: dict[str, str] = {}
    for part in text.split(","):
        if not part.strip():
            continue
        role, sep, name = part.partition("=")
        role, name = role.strip().replace("-", "_"), name.strip()
        if not sep or not name:
            raise ConfigError(f"--columns {part.strip()!r}: expected ROLE=NAME (roles: {', '.join(ROLES)})")
        if role not in ROLES:
            raise ConfigError(f"--columns {role!r}: unknown role; allowed: {', '.join(ROLES)}")
        if role in out:
            raise ConfigError(f"--columns {role!r}: given twice")
        out[role] = name
    return out


class _Table:
    """The raw columns of a file: name → strings (CSV) or floats (NetCDF), with row labels."""

    def __init__(self, kind, names, cells, row_word, row_ids, attrs=None, batch_note=None, ship=None):
        self.kind, self.names, self.cells = kind, tuple(names), cells
        self.row_word, self.row_ids = row_word, np.asarray(row_ids)
        self.attrs = attrs or {}
        self.batch_note, self.ship = batch_note, ship

    def rows(self, idx) -> str:
        """'lines 3, 7 and 9' / 'time index 4' for the rows at positions ``idx``."""
        ids = [int(self.row_ids[i]) for i in idx]
        word = self.row_word + ("s" if len(ids) > 1 and not self.row_word.endswith("index") else "")
        if self.row_word.endswith("index") and len(ids) > 1:
            word = self.row_word[:-5] + "indices"
        shown = ", ".join(str(i) for i in ids[:10])
        more = f" (+{len(ids) - 10} more)" if len(ids) > 10 else ""
        return f"{word} {shown}{more}"


def _read_csv(path: Path, shown: str) -> _Table:
    try:
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        raise ConfigError(f"LOG {shown}: not a text CSV file (and not NetCDF); "
                          "give a CSV with a header row or a NetCDF file") from None
    except OSError as exc:
        raise ConfigError(f"LOG {shown}: cannot read ({exc.strerror or exc})") from None
    lines = [(i + 1, ln) for i, ln in enumerate(text.splitlines())
             if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise ConfigError(f"LOG {shown}: empty (no header row)")
    header_line = lines[0][1]
    delim = next((d for d in (",", ";", "\t") if d in header_line), None)

    def split(line: str) -> list[str]:
        if delim is None:
            return line.split()
        return next(csv.reader([line], delimiter=delim))

    names = [h.strip() for h in split(header_line)]
    if any(not n for n in names):
        raise ConfigError(f"LOG {shown}: the header (line {lines[0][0]}) has an empty column name")
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ConfigError(f"LOG {shown}: column name{'s' if len(dup) > 1 else ''} "
                          f"{', '.join(map(repr, dup))} appear more than once in the header")
    rows, ids = [], []
    for lineno, line in lines[1:]:
        cells = [c.strip() for c in split(line)]
        if len(cells) != len(names):
            raise ConfigError(f"LOG {shown}: line {lineno} has {len(cells)} fields, the header "
                              f"has {len(names)}")
        rows.append(cells)
        ids.append(lineno)
    columns = {n: [r[j] for r in rows] for j, n in enumerate(names)}
    return _Table("csv", names, columns, "line", ids)


def _read_netcdf(path: Path, shown: str, ship: int | None) -> _Table:
    import xarray as xr

    try:
        with xr.open_dataset(path) as ds:
            ds = ds.load()
    except Exception as exc:  # any reader failure is "unreadable"
        reason = " ".join(str(exc).split())[:160]
        raise ConfigError(f"LOG {shown}: cannot read as NetCDF ({type(exc).__name__}: {reason})") from None
    names = [str(n) for n in list(ds.coords) + list(ds.data_vars)]
    tname = "time" if "time" in ds.dims else None
    if tname is None:
        one_d = [d for d in ds.dims if ds.sizes[d] > 1]
        tname = str(one_d[0]) if len(one_d) == 1 else None
    if tname is None:
        raise ConfigError(f"LOG {shown}: no 'time' dimension (dimensions: "
                          f"{', '.join(f'{d}={n}' for d, n in ds.sizes.items())})")
    batch_dims = [str(d) for d in ds.dims if d != tname and ds.sizes[d] > 1
                  and any(d in ds[v].dims for v in ds.data_vars)]
    note, chosen = None, None
    if batch_dims:
        sizes = [ds.sizes[d] for d in batch_dims]
        total = int(np.prod(sizes))
        if ship is None:
            chosen = 0
        else:
            if not (isinstance(ship, int) and 0 <= ship < total):
                raise ConfigError(f"--ship {ship!r}: the log holds {total} runs along "
                                  f"{' x '.join(batch_dims)}; allowed 0..{total - 1}")
            chosen = ship
        index = dict(zip(batch_dims, np.unravel_index(chosen, sizes), strict=True))
        labels = []
        for d, i in index.items():
            lab = ds[d].values[i] if d in ds.coords else i
            labels.append(f"{d}={lab}")
        ds = ds.isel({d: int(i) for d, i in index.items()})
        if ship is None:
            note = (f"the log holds {total} runs along {' x '.join(batch_dims)}; identified run 0 "
                    f"({', '.join(labels)}); choose another with --ship INDEX")
        else:
            note = f"identified run {chosen} of {total} ({', '.join(labels)})"
    cells, attrs = {}, {}
    n = ds.sizes[tname]
    for name in names:
        var = ds[name]
        extra = [d for d in var.dims if d != tname]
        if tname not in var.dims or any(ds.sizes[d] > 1 for d in extra):
            continue  # not a time series of this run
        try:
            values = np.asarray(var.squeeze(extra).values, dtype=float).reshape(-1)
        except (TypeError, ValueError):
            continue
        if values.size == n:
            cells[name] = values
            attrs[name] = str(var.attrs.get("units", "")).strip()
    return _Table("netcdf", [nm for nm in names if nm in cells], cells, "time index", np.arange(n),
                  attrs=attrs, batch_note=note, ship=chosen)


def _open(path, ship) -> tuple[_Table, str]:
    p = Path(path)
    shown = repr(str(path))
    if not p.exists():
        raise ConfigError(f"LOG {shown}: no such file")
    if p.is_dir():
        raise ConfigError(f"LOG {shown}: is a directory, not a log file (for a run, give its result.nc)")
    try:
        with p.open("rb") as fh:
            head = fh.read(8)
    except OSError as exc:
        raise ConfigError(f"LOG {shown}: cannot read ({exc.strerror or exc})") from None
    is_nc = p.suffix.lower() in _NETCDF_SUFFIXES or head.startswith((b"CDF", b"\x89HDF"))
    if is_nc:
        return _read_netcdf(p, shown, ship), shown
    if ship not in (None, 0):
        raise ConfigError(f"--ship {ship!r}: a CSV log holds one run (--ship is for a batched NetCDF)")
    return _read_csv(p, shown), shown


def _resolve(table: _Table, shown: str, role: str, given: dict[str, str], required: bool):
    if role in given:
        name = given[role]
        if name not in table.cells:
            raise ConfigError(f"LOG {shown}: no column {name!r} (given for {role} by --columns); "
                              f"columns present: {', '.join(table.names)}")
        return name
    for name in DEFAULT_COLUMNS[role]:
        if name in table.cells:
            return name
    if required:
        looked = " or ".join(repr(n) for n in DEFAULT_COLUMNS[role])
        raise ConfigError(f"LOG {shown}: no column for the {role.replace('_', ' ')} (looked for "
                          f"{looked}); columns present: {', '.join(table.names)}; name it with "
                          f"--columns {role}=NAME")
    return None


def _numbers(table: _Table, shown: str, name: str) -> np.ndarray:
    raw = table.cells[name]
    if table.kind == "netcdf":
        return np.asarray(raw, dtype=float)
    out = np.empty(len(raw))
    for i, cell in enumerate(raw):
        if cell.lower() in _NAN_WORDS:
            out[i] = np.nan
            continue
        try:
            out[i] = float(cell)
        except ValueError:
            raise ConfigError(f"LOG {shown}: line {table.row_ids[i]}, column {name!r}: {cell!r} "
                              "is not a number" + (" (time must be in seconds)"
                                                   if name in DEFAULT_COLUMNS["time"] else "")) from None
    return out


def _angle_scale(table: _Table, name: str, units: str | None) -> tuple[float, str]:
    if units is not None:
        return (math.pi / 180.0 if units == "deg" else 1.0), units
    unit = table.attrs.get(name, "").lower()
    if unit in _DEG_UNITS:
        return math.pi / 180.0, "deg"
    return 1.0, "rad"


def read_log(path, *, required=("time", "rudder"), optional=("heading", "yaw_rate", "u", "v"),
             columns: dict[str, str] | str | None = None, units: str | None = None,
             ship: int | None = None, need_one_of: tuple[str, ...] = ()) -> Log:
    """Read and check the log at ``path`` (module docstring).

    ``required`` roles must be present, ``optional`` ones are read when present, and at least one
    role of ``need_one_of`` (e.g. ``("yaw_rate", "heading")``) must be found. ``columns`` maps
    roles to column names (or the ``--columns`` text); ``units`` is ``"deg"``, ``"rad"`` or None
    (NetCDF: each variable's ``units`` attribute, else rad; CSV: rad). ``ship`` picks a run of a
    batched NetCDF result (default run 0, with a note).
    """
    if units is not None and units not in ("deg", "rad"):
        raise ConfigError(f"--units {units!r}: allowed: deg, rad")
    given = parse_columns(columns) if isinstance(columns, str) or columns is None else dict(columns)
    for role in given:
        if role not in ROLES:
            raise ConfigError(f"--columns {role!r}: unknown role; allowed: {', '.join(ROLES)}")
    table, shown = _open(path, ship)
    names: dict[str, str] = {}
    for role in ROLES:
        if role in required or role in optional or role in need_one_of or role in given:
            name = _resolve(table, shown, role, given, role in required)
            if name is not None:
                names[role] = name
    if need_one_of and not any(r in names for r in need_one_of):
        looked = "; ".join(f"{r.replace('_', ' ')}: {' or '.join(map(repr, DEFAULT_COLUMNS[r]))}"
                           for r in need_one_of)
        wanted = " or the ".join(r.replace("_", " ") for r in need_one_of)
        raise ConfigError(f"LOG {shown}: needs a column for the {wanted} "
                          f"(looked for {looked}); columns present: {', '.join(table.names)}; "
                          f"name one with --columns {need_one_of[0]}=NAME")
    values = {role: _numbers(table, shown, name) for role, name in names.items()}
    n = values["time"].size
    # NaN rows of the columns used
    bad = np.zeros(n, dtype=bool)
    cols_bad = []
    for role, arr in values.items():
        nan = ~np.isfinite(arr)
        if nan.any():
            cols_bad.append(names[role])
        bad |= nan
    if bad.any():
        idx = np.flatnonzero(bad)
        raise ConfigError(f"LOG {shown}: NaN or missing values at {table.rows(idx)} (column"
                          f"{'s' if len(cols_bad) > 1 else ''} {', '.join(cols_bad)}): remove or "
                          "fill those rows")
    if n < MIN_SAMPLES:
        raise ConfigError(f"LOG {shown}: {n} samples; need at least {MIN_SAMPLES}")
    t = values.pop("time")
    steps = np.diff(t)
    if np.any(steps <= 0):
        i = int(np.flatnonzero(steps <= 0)[0])
        raise ConfigError(f"LOG {shown}: time not strictly increasing at {table.rows([i + 1])} "
                          f"(t = {t[i + 1]:.6g} s after {t[i]:.6g} s)")
    # angles to radians
    used_units = set()
    for role in ANGLE_ROLES:
        if role in values:
            scale, unit = _angle_scale(table, names[role], units)
            used_units.add(unit)
            values[role] = values[role] * scale
    if "rudder" in values:
        peak = float(np.max(np.abs(values["rudder"])))
        if peak > math.pi / 2:
            raise ConfigError(f"LOG {shown}: the rudder column {names['rudder']!r} reaches "
                              f"{peak:.4g} rad (> 90°): it looks like degrees; pass --units deg")
    if "heading" in values:
        values["heading"] = np.unwrap(values["heading"])
    notes = []
    if table.batch_note:
        notes.append(table.batch_note)
    h = float(np.median(steps))
    if not np.allclose(steps, h, rtol=1e-6, atol=1e-9):
        gap = int(np.argmax(steps))
        if steps[gap] > MAX_GAP_STEPS * h:  # a gap, not jitter: interpolating across it invents data
            raise ConfigError(f"LOG {shown}: a gap of {steps[gap]:.6g} s in time at "
                              f"{table.rows([gap + 1])} (t = {t[gap]:.6g} → {t[gap + 1]:.6g} s), "
                              f"more than {MAX_GAP_STEPS} × the median step {h:.4g} s; split the log "
                              "there or cut it")
        m = math.floor((t[-1] - t[0]) / h + 1e-9) + 1
        grid = t[0] + h * np.arange(m)
        values = {role: np.interp(grid, t, arr) for role, arr in values.items()}
        notes.append(f"uneven time steps ({steps.min():.4g}–{steps.max():.4g} s): interpolated "
                     f"linearly onto a uniform {h:.4g} s grid ({m} samples)")
        t = grid
    unit = "deg" if used_units == {"deg"} else ("rad" if used_units <= {"rad"} else "mixed")
    return Log(path=str(path), kind=table.kind, t=t, data=values, names=names,
               present=table.names, units=unit, ship=table.ship, notes=notes)
