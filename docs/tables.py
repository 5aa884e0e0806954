"""Documentation tables and quoted numbers generated from the runs they describe.

A page marks a table with two HTML comments (invisible in the rendered page)::

    <!-- table: boat-los -->
    | metric | value |
    ...
    <!-- /table -->

and everything between them is the metrics table of ``shipgnc run boat-los``, rendered by
:func:`render`. Options after the name, separated by spaces:

* ``keys=a,b,c`` — only these metrics, in this order (default: every scalar metric);
* ``set=KEY=VALUE`` — an override, as ``--set`` (repeatable);
* ``layout=NAME`` — the page's own table of that run, built by ``LAYOUTS[NAME]`` (rows and columns
  as the page reads best, numbers at the page's precision) instead of one row per metric.

Numbers a page quotes in its prose are listed in ``QUOTES`` (page → quotes): a quote is a run and
a template of the page's text, ``{field:spec}`` standing for a number of that run. ``field`` is a
path into the metrics (``los_fl.settle_time_min``, ``lqr.lqr_gain.0``), optionally followed by
space-separated arithmetic applied left to right (``heading_end_deg - 180``, ``time_s / 60``);
``spec`` is a Python format spec, with ``_`` grouping written as a space, a trailing ``m`` for the
typographic minus sign (−) and ``.Nx`` for N decimals in ``a·10ⁿ`` form. Whitespace in a template
matches any whitespace (line breaks of the prose included). The template must occur exactly once.

Usage (from the repository root)::

    python docs/tables.py                 # regenerate every marked table and quote of the pages
    python docs/tables.py --check         # exit 1 and list each documented number that drifted
    python docs/tables.py docs/001_vectored_thrust_boat.md     # some pages only

``tests/test_docs_tables.py`` runs the check, so a change that moves a documented number fails
until the page is regenerated. Each run is made once per process and shared by every table and
quote that needs it. Metric tables write numbers to 5 significant digits; layouts and quotes to the
page's precision. A documented number drifts when it differs from the run by more than one unit in
its last printed digit (a rounding flip is not a drift); the text around the numbers of a cell
must be the same.
"""

from __future__ import annotations

import argparse
import functools
import operator
import re
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

DOCS = Path(__file__).resolve().parent
#: pages whose tables are generated (the list grows page by page)
PAGES = ("000_mariner_tracking.md", "001_vectored_thrust_boat.md", "002_zermelo_routing.md",
         "003_cybership_autopilot.md", "004_catamaran_fsm.md")
BLOCK = re.compile(r"(?P<open><!-- table: (?P<name>[A-Za-z0-9_.\-]+)(?P<options>[^>]*?)\s*-->\n)"
                   r"(?P<body>.*?)(?P<close><!-- /table -->)", re.S)
DIGITS = 5
MINUS = "\u2212"
SUPERSCRIPT = str.maketrans("-+0123456789", "⁻⁺⁰¹²³⁴⁵⁶⁷⁸⁹")
NORMAL = str.maketrans("⁻⁺⁰¹²³⁴⁵⁶⁷⁸⁹" + MINUS, "-+0123456789-")
#: a number as pages write it: 12, −0.0332, 4.2551e-05, 2.1·10⁻⁶, 39 296.63
NUMBER = r"[-\u2212]?\d{1,3}(?: \d{3})+(?:\.\d+)?|[-\u2212]?\d+(?:\.\d+)?(?:e[-+]?\d+|·10[⁻⁺]?[⁰¹²³⁴⁵⁶⁷⁸⁹]+)?"
NUMBERS = re.compile(f"({NUMBER})")


@dataclass(frozen=True)
class Drift:
    """A documented cell (or quoted number) that no longer matches its run."""

    page: str
    table: str
    row: str
    column: str
    documented: str
    run: str

    def __str__(self) -> str:
        return (f"{self.page}: table {self.table}, {self.row} ({self.column}): documented "
                f"{self.documented}, the run gives {self.run}")


@dataclass(frozen=True)
class Quote:
    """A passage of a page quoting numbers of ``shipgnc run scenario [--set overrides]``."""

    scenario: str
    text: str
    overrides: tuple[str, ...] = ()


def _options(text: str) -> tuple[list[str] | None, list[str], str | None, dict[str, float]]:
    """A table's options: ``keys=a,b``, ``set=KEY=VALUE`` (repeatable), ``layout=NAME`` and
    ``rtol=COLUMN:FRACTION,...`` (``*`` for every column): the columns whose figures round-off
    decides, checked to that relative tolerance instead of one unit in the last digit."""
    keys, overrides, layout, rtol = None, [], None, {}
    for item in text.split():
        name, _, value = item.partition("=")
        if name == "keys":
            keys = [k for k in value.split(",") if k]
        elif name == "set":
            overrides.append(value)
        elif name == "layout":
            layout = value
        elif name == "rtol":
            for part in value.split(","):
                column, _, fraction = part.partition(":")
                try:
                    rtol[column.strip("`")] = float(fraction)
                except ValueError:
                    raise ValueError(f"table option {item!r}: expected rtol=COLUMN:FRACTION,...") from None
        else:
            raise ValueError(f"table option {item!r}: expected keys=a,b, set=KEY=VALUE, layout=NAME "
                             f"or rtol=COLUMN:FRACTION")
    return keys, overrides, layout, rtol


def _scalar(value) -> bool:
    return value is None or isinstance(value, (bool, int, float, str, list, tuple))


@functools.cache
def _run(name: str, overrides: tuple[str, ...] = ()) -> dict:
    """The metrics of ``shipgnc run name --set ...``, run once per process."""
    from shipgnc.scenarios.runner import run_scenario

    return run_scenario(name, overrides=list(overrides)).metrics


def render(name: str, keys: list[str] | None = None, overrides: list[str] | tuple = (),
           layout: str | None = None) -> str:
    """The markdown metrics table of ``shipgnc run name`` (one row per metric; a comparison has
    one column per controller), or the page's own table ``LAYOUTS[layout]`` of that run."""
    from shipgnc.scenarios.runner import metric_text

    metrics = _run(name, tuple(overrides))
    if layout is not None:
        if layout not in LAYOUTS:
            raise KeyError(f"table {name}: no layout {layout!r}; have {', '.join(LAYOUTS)}")
        return "\n".join(LAYOUTS[layout](metrics)) + "\n"
    compare = bool(metrics) and all(isinstance(v, dict) for v in metrics.values())
    runs = metrics if compare else {"value": metrics}
    rows = keys or [k for k in dict.fromkeys(k for m in runs.values() for k in m)
                    if all(_scalar(m.get(k)) for m in runs.values()) and k != "diverged"]
    missing = [k for k in rows if not any(k in m for m in runs.values())]
    if missing:
        raise KeyError(f"table {name}: no metric {', '.join(missing)}; have "
                       f"{', '.join(k for m in runs.values() for k in m)}")
    lines = ["| metric | " + " | ".join(f"`{c}`" if compare else c for c in runs) + " |",
             "|---|" + "---:|" * len(runs)]
    for key in rows:
        cells = [metric_text(m.get(key), digits=DIGITS) for m in runs.values()]
        lines.append(f"| `{key}` | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


# --- numbers as written ---------------------------------------------------------------------------

def _plain(text: str) -> str:
    """A written number in Python's syntax (``−2.1·10⁻⁶`` → ``-2.1e-6``, ``39 296.6`` → ``39296.6``)."""
    text = text.strip().replace(" ", "")
    mantissa, dot, exponent = text.partition("·10")
    return (mantissa + "e" + exponent if dot else mantissa).translate(NORMAL)


def _number(text: str) -> float | None:
    try:
        return float(_plain(text))
    except ValueError:
        return None


def _last_digit(text: str) -> float:
    """One unit in the last printed digit of a number as written (``0.0833`` → 1e-4,
    ``4.255e-05`` → 1e-08, ``2.1·10⁻⁶`` → 1e-07, ``121`` → 1)."""
    mantissa, _, exponent = _plain(text).lower().partition("e")
    decimals = len(mantissa.partition(".")[2])
    return 10.0 ** (-decimals + (int(exponent) if exponent else 0))


def _close(documented: str, run: str, rtol: float = 0.0) -> bool:
    """``run`` equals the ``documented`` number within one unit in its last printed digit, or
    within ``rtol`` of it."""
    x, y = _number(documented), _number(run)
    return x is not None and y is not None and abs(x - y) <= max(
        _last_digit(documented) * (1 + 1e-9), rtol * abs(x))


def _same(documented: str, run: str, rtol: float = 0.0) -> bool:
    """Two cells say the same: equal text around their numbers, each number within one unit in
    the documented number's last digit (or within ``rtol`` of it)."""
    if documented == run:
        return True
    a, b = NUMBERS.split(documented), NUMBERS.split(run)
    return (len(a) == len(b) and a[::2] == b[::2]
            and all(_close(x, y, rtol) for x, y in zip(a[1::2], b[1::2], strict=True)))


def fmt(value, spec: str = "") -> str:
    """A number as a page writes it: a Python format ``spec``, ``_`` grouping as a space, a
    trailing ``m`` for the typographic minus, ``.Nx`` for ``a·10ⁿ`` with N decimals; None is —."""
    if value is None:
        return "—"
    minus = spec.endswith("m")
    spec = spec[:-1] if minus else spec
    if spec.endswith("x"):
        mantissa, _, exponent = format(value, spec[:-1] + "e").partition("e")
        return mantissa.replace("-", MINUS) + "·10" + str(int(exponent)).translate(SUPERSCRIPT)
    text = format(value, spec).replace("_", " ")
    return text.replace("-", MINUS) if minus else text


def sig(value, digits: int = 3, unit: str = "") -> str:
    """``value`` to ``digits`` significant digits, trailing zeros kept (58.0, 0.0444), exact zero
    as 0, typographic minus, None as —."""
    if value is None:
        return "—"
    text = "0" if value == 0 else format(value, f"#.{digits}g").rstrip(".")
    return text.replace("-", MINUS) + unit


def _field(metrics: dict, field: str) -> float:
    """``path [op number]...`` of the metrics: ``lqr.lqr_gain.0``, ``time_s / 60``."""
    path, *ops = field.split()
    value, key = metrics, ""
    for part in path.split("."):  # a key may hold dots (`law20@0.00072`): the longest that exists
        key = f"{key}.{part}" if key else part
        if isinstance(value, (list, tuple)):
            value, key = value[int(key)], ""
        elif key in value:
            value, key = value[key], ""
    if key:
        raise KeyError(f"quote field {field!r}: no metric {key!r}")
    if len(ops) % 2:
        raise ValueError(f"quote field {field!r}: expected `path [op number]...`")
    for op, number in zip(ops[::2], ops[1::2], strict=True):
        value = ARITHMETIC[op](value, float(number))
    return value


ARITHMETIC = {"+": operator.add, "-": operator.sub, "*": operator.mul, "/": operator.truediv}
_FIELD = re.compile(r"\{(?P<field>[^{}:]+)(?::(?P<spec>[^{}]*))?\}")


def _pattern(text: str) -> tuple[re.Pattern, list[tuple[str, str]]]:
    """The regex of a quote's template (one capture per field) and its fields."""
    parts, fields, at = [], [], 0
    for match in _FIELD.finditer(text):
        parts.append(re.sub(r"\\\s+|\s+", r"\\s+", re.escape(text[at:match.start()])))
        parts.append(f"({NUMBER})")
        fields.append((match["field"].strip(), match["spec"] or ""))
        at = match.end()
    parts.append(re.sub(r"\\\s+|\s+", r"\\s+", re.escape(text[at:])))
    return re.compile("".join(parts)), fields


def _quotes(page: Path, text: str, found: list[Drift]) -> str:
    """Check (into ``found``) and rewrite the page's quoted numbers; return the new text."""
    for quote in QUOTES.get(page.name, ()):
        pattern, fields = _pattern(quote.text)
        matches = list(pattern.finditer(text))
        label = quote.text if len(quote.text) < 60 else quote.text[:57] + "..."
        if len(matches) != 1:
            found.append(Drift(page.name, "prose", repr(label), quote.scenario,
                               f"(the passage occurs {len(matches)} times)", "once"))
            continue
        match, metrics = matches[0], _run(quote.scenario, quote.overrides)
        for group in range(len(fields), 0, -1):  # from the end: spans stay valid
            field, spec = fields[group - 1]
            documented, run = match[group], fmt(_field(metrics, field), spec)
            if documented != run and not _close(documented, run):
                found.append(Drift(page.name, "prose", repr(label), field, documented, run))
            text = text[:match.start(group)] + run + text[match.end(group):]
    return text


def _cells(body: str) -> dict[tuple[str, str], str]:
    """(row, column) → cell text of a markdown table."""
    lines = [ln for ln in body.strip().splitlines() if ln.startswith("|")]
    if len(lines) < 2:
        return {}
    split = [[c.strip() for c in ln.strip().strip("|").split("|")] for ln in lines]
    header = split[0]
    return {(row[0], header[j]): cell for row in split[2:] for j, cell in enumerate(row) if j}


def drifts(documented: str, generated: str, page: str, table: str,
           rtol: dict[str, float] | None = None) -> list[Drift]:
    """The cells of ``documented`` that differ from ``generated`` beyond a rounding flip, or
    beyond ``rtol[column]`` (``rtol["*"]`` for every column) where given (and rows or columns
    that appeared or vanished)."""
    old, new = _cells(documented), _cells(generated)
    rtol = rtol or {}
    found = []
    for key in dict.fromkeys([*old, *new]):
        a, b = old.get(key, "(absent)"), new.get(key, "(absent)")
        if not _same(a, b, rtol.get(key[1].strip("`"), rtol.get("*", 0.0))):
            found.append(Drift(page, table, key[0], key[1], a, b))
    return found


def update(page: Path, *, check: bool = False) -> list[Drift]:
    """Regenerate the marked tables and the quoted numbers of ``page`` (rewriting it unless
    ``check``); return the drifts found against what the page documented."""
    page = Path(page)
    text = page.read_text(encoding="utf-8")
    found: list[Drift] = []

    def replace(match: re.Match) -> str:
        keys, overrides, layout, rtol = _options(match["options"])
        table = render(match["name"], keys, overrides, layout)
        found.extend(drifts(match["body"], table, page.name, match["name"], rtol))
        return match["open"] + table + match["close"]

    new = _quotes(page, BLOCK.sub(replace, text), found)
    if not check and new != text:
        page.write_text(new, encoding="utf-8")
    return found


# --- the pages' own tables ------------------------------------------------------------------------

def _row(label: str, cells: list[str]) -> str:
    return f"| {label} | " + " | ".join(cells) + " |"


#: document 000: the notes' indicative values (note 000-0.8), as the notes print them
MARINER_NOTES = {
    "lqr_paper": {"settle": "25.9", "overshoot": "0.63", "max": "0.21", "heading": "−9.17"},
    "lqr": {"settle": "25.9", "overshoot": "0.63", "max": "0.22", "heading": "−9.16"},
    "fl_lookahead": {"settle": "8.7", "overshoot": "0.033", "max": "0.27"},
    "los_fl_oracle": {"settle": "11.1", "overshoot": "0", "max": "0.26"},
}
MARINER_ROWS = {
    "lqr_paper": "`lqr_paper`", "lqr": "`lqr`", "fl_paper": "`fl_paper`",
    "fl_lookahead": "`fl_lookahead`",
    "los_fl_oracle": "`los_fl_oracle` (the notes' `los_fl`: b_r, d_y handed to it)",
    "los_fl": "`los_fl` (integral LOS, nothing known; the default)",
}


def mariner_compare(metrics: dict) -> list[str]:
    """Document 000: one row per controller of ``mariner-compare``, the notes' indicative values
    in brackets."""
    def note(value: str, name: str, key: str) -> str:
        printed = MARINER_NOTES.get(name, {}).get(key)
        return f"{value} ({printed})" if printed else value

    def fixed(value, decimals: int) -> str:
        return "null" if value is None else "0" if value == 0 else fmt(value, f".{decimals}fm")

    lines = ["| controller | settle [min] | overshoot [nm] | max \\|y_r\\| after leg 1 [nm] | final y_r [nm] "
             "| final ψ_r [deg] | final δ [deg] | rudder RMS [deg] | stable |",
             "|---|---|---|---|---|---|---|---|---|"]
    for name, label in MARINER_ROWS.items():
        m = metrics[name]
        y = m["final_crosstrack_nm"]
        final_y = fixed(y, 4 if abs(y) < 1 else 1)
        if name == "fl_lookahead":
            final_y += " = l·d_y/U"
        rudder = sig(m["final_rudder_deg"])
        worst = fixed(m["crosstrack_max_after_leg1_nm"], 3)
        if not m["stable"]:
            final_y = f"**{final_y}**"
            rudder += f" (saturated {100 * m['saturation_fraction']:.0f} % of the time)"
        if m["crosstrack_max_after_leg1_nm"] is None:
            worst += " (never leaves leg 1)"
        stable = str(m["stable"]).lower()
        lines.append(_row(label, [
            note(fixed(m["settle_time_min"], 2), name, "settle"),
            note(fixed(m["overshoot_nm"], 3), name, "overshoot"),
            note(worst, name, "max"), final_y,
            note(sig(m["final_heading_error_deg"]), name, "heading"), rudder,
            sig(m["rudder_rms_deg"]), stable if m["stable"] else f"**{stable}**"]))
    return lines


def zermelo_sail(metrics: dict) -> list[str]:
    """Document 002: the route sailed three ways by ``zermelo-sail``."""
    m = metrics
    miss = "0" if m["miss_m"] < 5e-3 else f"{fmt(m['miss_m'], '.2f')} m"  # the route's own miss
    lines = [f"| run | arrived (R = {fmt(m['acceptance_radius_m'], '.0f')} m) | time to target "
             "| miss distance |", "|---|---|---|---|",
             _row("optimum (route)", ["—", f"{fmt(m['time_s'], '.2f')} s", miss])]
    runs = {"path": f"path (LOS through {m['path_waypoints']} waypoints)", "sail": "heading programme",
            "legs": f"{m['legs']} constant-heading legs"}
    for prefix, label in runs.items():
        arrived = m[f"{prefix}_arrived"]
        time = (f"**{fmt(m[f'{prefix}_arrival_s'], '.1f')} s = "
                f"{fmt(m[f'{prefix}_arrival_ratio'], '.3f')} × optimum**" if arrived else "—")
        miss = f"{fmt(m[f'{prefix}_miss_m'], '.2f' if arrived else '.1f')} m"
        if prefix == "path":
            miss += (f" (cross-track RMS {fmt(m['path_crosstrack_rms_m'], '.1f')} m, "
                     f"max {fmt(m['path_crosstrack_max_m'], '.1f')} m)")
        lines.append(_row(label, ["**yes**" if arrived else "**no**", time, miss]))
    return lines


#: document 004: rows of the comparison table (label, runs of ``catamaran-compare``)
CATAMARAN_ROWS = (
    ("S3 law (20)", ("S3/law20",)), ("S3 law (21)", ("S3/law21",)), ("S3 place", ("S3/place",)),
    ("S3 pi_design", ("S3/pi_design",)), ("S3 pi (reproduction)", ("S3/pi",)),
    ("S4 law (20) / (21)", ("S4/law20", "S4/law21")),
    ("S4 place / pi_design", ("S4/place", "S4/pi_design")), ("S4 pi (reproduction)", ("S4/pi",)),
    ("S7 law (21) / place / lqr", ("S7/law21", "S7/place", "S7/lqr")),
)


def catamaran_compare(metrics: dict) -> list[str]:
    """Document 004: settling, overshoot, IAE, thruster travel and rate of ``catamaran-compare``,
    runs of a row joined by " / " (one value when they agree at the printed precision)."""
    def small(value, decimals: int, digits: int) -> str:  # fixed decimals, significant digits below 1
        return "0" if value == 0 else fmt(value, f".{decimals}f") if value >= 1 else sig(value, digits)

    columns = (
        ("r settling", "yaw_rate_settling_s", lambda v: fmt(v, ".1f"), " s"),
        ("overshoot", "yaw_rate_overshoot_pct",
         lambda v: "—" if v is None else "0" if v == 0 else fmt(v, ".2f") if v < 1 else sig(v), " %"),
        ("IAE", "iae", sig, " rad"),
        ("travel", "thruster_travel_deg", sig, "°"),
        ("δ̇ RMS", "delta_rate_rms_deg_s", lambda v: fmt(v, ".3f") if v < 1 else sig(v), "°/s"),
        ("peak δ̇", "peak_delta_rate_deg_s", lambda v: small(v, 2, 2), "°/s"),
    )
    lines = ["| run | " + " | ".join(c[0] for c in columns) + " |", "|---" * (len(columns) + 1) + "|"]
    for label, runs in CATAMARAN_ROWS:
        cells = []
        for _, key, form, unit in columns:
            values = list(dict.fromkeys(form(metrics[run][key]) for run in runs))
            if key == "iae" and label.startswith("S7"):
                unit = " rad·s"  # a heading error integrated over time
            text = " / ".join(values)
            cells.append(text if text == "—" else text + unit)
        lines.append(_row(label, cells))
    return lines


LAYOUTS: dict[str, Callable[[dict], list[str]]] = {
    "mariner-compare": mariner_compare,
    "zermelo-sail": zermelo_sail,
    "catamaran-compare": catamaran_compare,
}


# --- the pages' quoted numbers --------------------------------------------------------------------

QUOTES: dict[str, tuple[Quote, ...]] = {
    "000_mariner_tracking.md": (
        Quote("mariner-compare", "R = 1 gives **[{lqr.lqr_gain.0:.4f}, {lqr.lqr_gain.1:.4f}, "
              "{lqr.lqr_gain.2:.4f}, {lqr.lqr_gain.3:.4f}]**"),
        Quote("mariner-compare", "R = 0.5 gives [{lqr.lqr_gain.0:.4f}, {lqr.lqr_gain.1:.4f}, "
              "{lqr.lqr_gain.2:.4f}, {lqr.lqr_gain.3:.4f}]", ("controllers.lqr.R=0.5",)),
        Quote("mariner-compare", "settles in {los_fl.settle_time_min:.1f} min — as slowly as the LQR "
              "({lqr_paper.settle_time_min:.1f} min), with a third of its overshoot "
              "({los_fl.overshoot_nm:.2f} vs {lqr_paper.overshoot_nm:.2f} nm)"),
        Quote("mariner-compare", "**+U/|r₁| = +{fl_paper.zero_dynamics_pole_per_min:.2f} /min**"),
        Quote("mariner-compare", "(1.5 nm capture: {lqr.settle_time_min:.2f} min, overshoot "
              "{lqr.overshoot_nm:.3f} nm)", ("controllers.lqr.anti_windup=true",)),
        Quote("mariner-compare", "sailing across the path, {fl_paper.final_crosstrack_nm * -1:.0f} nm off "
              "after 100 min"),
    ),
    "002_zermelo_routing.md": (
        Quote("zermelo-paper", "# {time_h:.4f} h (the document: 10.93 h)"),
        Quote("zermelo-paper", "| 30.0182° | {heading_end_deg - 180:.4f}° | Z-1, Z-3 |"),
        Quote("zermelo-paper", "| 344.9809° | {heading_start_deg:.5f}° | Z-1 |"),
        Quote("zermelo-paper", "| 210.0182° | {heading_end_deg:.5f}° | Z-1 |"),
        Quote("zermelo-paper", "| 10.915731 h | {time_h:.6f} h = {time_s:_.2f} s | Z-1, Z-6 |"),
        Quote("zermelo-paper", "| 4.647788 h, straight 5.1013 h | {time_h:.6f} h, 5.1013 h | Z-8 |",
              ("route.field=shear:k=0.5",)),
        Quote("zermelo-sail", "the optimum takes **{time_s:.2f} s = {time_s / 60:.3f} min**"),
        Quote("zermelo-sail", "(2.9.6: +{legs_plan_penalty_s:.1f} s for a point that turns at once)"),
        Quote("zermelo-sail", "the boat ends {sail_miss_m:.0f} m"),
        Quote("zermelo-sail", "arrives, {path_arrival_ratio * 100 - 100:.1f} % late"),
        Quote("zermelo-sail", "standing cross-track offset (up to {path_crosstrack_max_m:.0f} m)"),
        Quote("zermelo-sail", "changes this little ({path_arrival_s:.1f} s, {path_crosstrack_max_m:.1f} m)",
              ("sail.integral_gain=0.5",)),
        Quote("zermelo-sail-mariner", "enters the {acceptance_radius_m:.0f} m (2 L) circle at "
              "{sail_arrival_s:.1f} s ({sail_arrival_ratio:.3f} × the {time_s:.2f} s optimum"),
        Quote("zermelo-sail-mariner", "with a closest approach of {sail_miss_m:.0f} m; the four legs miss by "
              "{legs_miss_m:_.0f} m"),
    ),
    "004_catamaran_fsm.md": (
        Quote("catamaran-compare",
              "Final heading errors (S7): {S7/law21.final_heading_error_rad:.2x} (law 21), "
              "{S7/place.final_heading_error_rad:.2x} (place), {S7/lqr.final_heading_error_rad:.1x} rad "
              "(lqr). Steady states: δ = {S3/law20.final_delta_deg:.3f}°, V = {S3/law20.final_speed_mps:.3f} "
              "m/s, D_c = {S3/law20.turning_diameter_m:.2f} m at 0.08 rad/s; δ = "
              "{S4/law20.final_delta_deg:.3f}° at 0.008."),
        Quote("catamaran-turn", "| δ = {law20.final_delta_deg:.3f}°, D_c = {law20.turning_diameter_m:.3f} m "
              "(`paper`);", ("vessel.preset=paper",)),
        Quote("catamaran-turn", "m (`paper`); {law20.final_delta_deg:.3f}°, {law20.turning_diameter_m:.3f} m "
              "(`si`) |", ("vessel.preset=si",)),
        Quote("catamaran-turn", "| {law20.final_delta_deg:.3f}°, {law20.turning_diameter_m:.3f} m (`paper`) "
              "| check 4, 6 |", ("vessel.preset=paper",)),
        Quote("catamaran-fixed-angle", "fixed: r_ss = {fixed.final_yaw_rate_rad_s:.6f}, settles "
              "{fixed.yaw_rate_settling_s:.0f} s; FSM at the same angle ω* = "
              "{law20_same_angle.final_yaw_rate_rad_s:.6f}", ("vessel.preset=paper",)),
        Quote("catamaran-fixed-angle", "| **{law20@0.00072.final_delta_deg:.4f}°** | check 9 |",
              ("vessel.preset=paper",)),
        Quote("catamaran-fixed-angle", "| {law20@0.00072.yaw_rate_settling_s:.0f} s / "
              "{fixed.yaw_rate_settling_s:.0f} s (2 % band), FSM slower |", ("vessel.preset=paper",)),
        Quote("catamaran-fixed-angle", "The steady angle for 0.00072 rad/s is "
              "{law20@0.00072.final_delta_deg:.4f}° = "
              "{law20@0.00072.final_delta_deg / 57.29577951308232:.5f} rad", ("vessel.preset=paper",)),
        Quote("catamaran-heading", "| K(t_end) − K* = {final_heading_error_rad:.2x} rad |",
              ("vessel.preset=paper",)),
        Quote("catamaran-heading", "| three decimals | {final_heading_error_rad * -1:.1x} rad | check 10 |",
              ("vessel.preset=paper",)),
        Quote("catamaran-compare", "law (21) overshoots {S3/law21.yaw_rate_overshoot_pct:.0f}–"
              "{S4/law21.yaw_rate_overshoot_pct:.0f} % and law (20) {S3/law20.yaw_rate_overshoot_pct:.0f}–"
              "{S4/law20.yaw_rate_overshoot_pct:.0f} %"),
        Quote("catamaran-compare", "settle in {S3/place.yaw_rate_settling_s:.0f}–"
              "{S3/pi_design.yaw_rate_settling_s:.0f} s without overshoot, at the price of twice the peak "
              "thruster rate ({S3/pi_design.peak_delta_rate_deg_s:.0f}°/s"),
    ),
}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("pages", nargs="*", type=Path, help="pages (default: every page in PAGES)")
    parser.add_argument("--check", action="store_true", help="report drifts, write nothing")
    args = parser.parse_args(argv)
    pages = args.pages or [DOCS / name for name in PAGES]
    found = [d for page in pages for d in update(page, check=args.check)]
    for drift in found:
        print(drift)
    if args.check:
        return 1 if found else 0
    print(f"regenerated the tables of {len(pages)} page(s); {len(found)} number(s) changed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
