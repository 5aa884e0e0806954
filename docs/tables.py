"""Documentation tables generated from the runs they describe.

A page marks a table with two HTML comments (invisible in the rendered page)::

    <!-- table: boat-los -->
    | metric | value |
    ...
    <!-- /table -->

and everything between them is the metrics table of ``shipgnc run boat-los``, rendered by
:func:`render`. Options after the name, separated by spaces:

* ``keys=a,b,c`` — only these metrics, in this order (default: every scalar metric);
* ``set=KEY=VALUE`` — an override, as ``--set`` (repeatable).

Usage (from the repository root)::

    python docs/tables.py                 # regenerate every marked table of the pages
    python docs/tables.py --check         # exit 1 and list each documented number that drifted
    python docs/tables.py docs/001_vectored_thrust_boat.md     # some pages only

``tests/test_docs_tables.py`` runs the check for the pages whose scenarios are fast, so a change
that moves a documented number fails until the page is regenerated. Numbers are written to 5
significant digits; a documented number drifts when it differs from the run by more than one unit
in its last printed digit (a rounding flip is not a drift).
"""

from __future__ import annotations

import argparse
import re
import sys
from dataclasses import dataclass
from pathlib import Path

DOCS = Path(__file__).resolve().parent
#: pages whose tables are generated (the list grows page by page)
PAGES = ("001_vectored_thrust_boat.md", "003_cybership_autopilot.md")
BLOCK = re.compile(r"(?P<open><!-- table: (?P<name>[A-Za-z0-9_.\-]+)(?P<options>[^>]*?)\s*-->\n)"
                   r"(?P<body>.*?)(?P<close><!-- /table -->)", re.S)
DIGITS = 5


@dataclass(frozen=True)
class Drift:
    """A documented cell that no longer matches its run."""

    page: str
    table: str
    row: str
    column: str
    documented: str
    run: str

    def __str__(self) -> str:
        return (f"{self.page}: table {self.table}, {self.row} ({self.column}): documented "
                f"{self.documented}, the run gives {self.run}")


def _options(text: str) -> tuple[list[str] | None, list[str]]:
    keys, overrides = None, []
    for item in text.split():
        name, _, value = item.partition("=")
        if name == "keys":
            keys = [k for k in value.split(",") if k]
        elif name == "set":
            overrides.append(value)
        else:
            raise ValueError(f"table option {item!r}: expected keys=a,b or set=KEY=VALUE")
    return keys, overrides


def _scalar(value) -> bool:
    return value is None or isinstance(value, (bool, int, float, str, list, tuple))


def render(name: str, keys: list[str] | None = None, overrides: list[str] | tuple = ()) -> str:
    """The markdown metrics table of ``shipgnc run name`` (one row per metric; a comparison has
    one column per controller)."""
    from shipgnc.scenarios.runner import metric_text, run_scenario

    metrics = run_scenario(name, overrides=list(overrides)).metrics
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


def _cells(body: str) -> dict[tuple[str, str], str]:
    """(row, column) → cell text of a markdown table."""
    lines = [ln for ln in body.strip().splitlines() if ln.startswith("|")]
    if len(lines) < 2:
        return {}
    split = [[c.strip() for c in ln.strip().strip("|").split("|")] for ln in lines]
    header = split[0]
    return {(row[0], header[j]): cell for row in split[2:] for j, cell in enumerate(row) if j}


def _number(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None


def _last_digit(text: str) -> float:
    """One unit in the last printed digit of a number as written (``0.0833`` → 1e-4,
    ``4.255e-05`` → 1e-08, ``121`` → 1)."""
    mantissa, _, exponent = text.strip().lower().partition("e")
    decimals = len(mantissa.partition(".")[2])
    return 10.0 ** (-decimals + (int(exponent) if exponent else 0))


def drifts(documented: str, generated: str, page: str, table: str) -> list[Drift]:
    """The cells of ``documented`` that differ from ``generated`` beyond a rounding flip (and
    rows or columns that appeared or vanished)."""
    old, new = _cells(documented), _cells(generated)
    found = []
    for key in dict.fromkeys([*old, *new]):
        a, b = old.get(key, "(absent)"), new.get(key, "(absent)")
        if a == b:
            continue
        x, y = _number(a), _number(b)
        if x is not None and y is not None and abs(x - y) <= _last_digit(a) * (1 + 1e-9):
            continue
        found.append(Drift(page, table, key[0], key[1], a, b))
    return found


def update(page: Path, *, check: bool = False) -> list[Drift]:
    """Regenerate the marked tables of ``page`` (rewriting it unless ``check``); return the
    drifts found against what the page documented."""
    page = Path(page)
    text = page.read_text(encoding="utf-8")
    found: list[Drift] = []

    def replace(match: re.Match) -> str:
        keys, overrides = _options(match["options"])
        table = render(match["name"], keys, overrides)
        found.extend(drifts(match["body"], table, page.name, match["name"]))
        return match["open"] + table + match["close"]

    new = BLOCK.sub(replace, text)
    if not check and new != text:
        page.write_text(new, encoding="utf-8")
    return found


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
