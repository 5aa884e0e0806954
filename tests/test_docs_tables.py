"""Documentation tables are generated from the runs they describe (``docs/tables.py``): a number a
page documents between ``<!-- table: NAME -->`` markers, or quotes in its prose (``QUOTES``), that
drifts from ``shipgnc run NAME`` fails here, so documented numbers cannot go stale."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[1] / "docs"


@pytest.fixture(scope="module")
def tables():
    spec = importlib.util.spec_from_file_location("doc_tables", DOCS / "tables.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["doc_tables"] = module  # its dataclass looks its module up
    try:
        spec.loader.exec_module(module)
        yield module
    finally:
        sys.modules.pop("doc_tables", None)


@pytest.mark.parametrize("page", [
    "000_mariner_tracking.md", "001_vectored_thrust_boat.md", "002_zermelo_routing.md",
    "003_cybership_autopilot.md",
    # catamaran-compare: 13 single-ship runs, ≈ 40 s in the numpy loop or at their loops' first
    # compile, ≈ 4 s once they are cached
    pytest.param("004_catamaran_fsm.md", marks=pytest.mark.slow),
])
def test_documented_tables_match_their_runs(tables, page):
    text = (DOCS / page).read_text(encoding="utf-8")
    assert "<!-- table: " in text, f"{page} has no generated table"
    assert page in tables.PAGES
    drifts = tables.update(DOCS / page, check=True)
    assert not drifts, "regenerate with `python docs/tables.py`:\n" + "\n".join(map(str, drifts))
    assert (DOCS / page).read_text(encoding="utf-8") == text  # a check writes nothing


def test_a_drifted_number_is_reported_and_a_rounding_flip_is_not(tables, tmp_path):
    """The page's numbers for the stern kick of document 001 (74.075° heading change, −0.0332 m port
    excursion): a changed digit is a drift, one unit in the last digit is not."""
    page = tmp_path / "page.md"
    body = tables.render("boat-stern-kick", ["heading_change_deg", "stern_kick_min_lateral_m"])
    assert "| `heading_change_deg` | 74.075 |" in body  # note 001-1.9
    assert "| `stern_kick_min_lateral_m` | -0.033225 |" in body
    drifted = body.replace("74.075", "74.175").replace("-0.033225", "-0.033224")
    page.write_text(f"x\n<!-- table: boat-stern-kick keys=heading_change_deg,"
                    f"stern_kick_min_lateral_m -->\n{drifted}<!-- /table -->\ny\n", encoding="utf-8")
    found = tables.update(page, check=True)
    assert [(d.row, d.documented, d.run) for d in found] == [
        ("`heading_change_deg`", "74.175", "74.075")]
    tables.update(page)  # regenerate: the page now holds the run's numbers, the rest untouched
    text = page.read_text(encoding="utf-8")
    assert text.startswith("x\n") and text.endswith("<!-- /table -->\ny\n") and "74.075" in text
    assert tables.update(page, check=True) == []


def test_an_unknown_metric_option_or_layout_is_refused(tables):
    with pytest.raises(KeyError, match="no metric"):
        tables.render("boat-stern-kick", ["no_such_metric"])
    with pytest.raises(KeyError, match="no layout"):
        tables.render("boat-stern-kick", layout="no-such-layout")
    with pytest.raises(ValueError, match="table option"):
        tables._options("colour=red")


def test_a_quoted_number_is_checked_and_rewritten_in_place(tables, tmp_path, monkeypatch):
    """A number quoted in prose (the 74.075° heading change of note 001-1.9, written to 0.1°): a
    rounding flip passes, a changed digit is a drift, and regenerating rewrites only the number."""
    page = tmp_path / "quoted.md"
    quote = tables.Quote("boat-stern-kick", "the heading turns by {heading_change_deg:.1f}°, and")
    monkeypatch.setitem(tables.QUOTES, page.name, (quote,))
    page.write_text("x\nthe heading\n  turns by 74.0°, and y\n", encoding="utf-8")
    assert tables.update(page, check=True) == []  # 74.0 is one unit from the run's 74.1
    page.write_text("x\nthe heading\n  turns by 74.3°, and y\n", encoding="utf-8")
    found = tables.update(page, check=True)
    assert [(d.column, d.documented, d.run) for d in found] == [("heading_change_deg", "74.3", "74.1")]
    tables.update(page)
    assert page.read_text(encoding="utf-8") == "x\nthe heading\n  turns by 74.1°, and y\n"
    page.write_text("the passage was edited away\n", encoding="utf-8")
    assert [d.documented for d in tables.update(page, check=True)] == ["(the passage occurs 0 times)"]


def test_cells_compare_the_text_and_each_number_at_its_printed_precision(tables):
    same = tables._same
    assert same("21.3 / 56.8 s", "21.2 / 56.8 s")  # one unit in the last digit: a rounding flip
    assert not same("21.3 / 56.8 s", "21.3 / 56.6 s")
    assert not same("21.3 / 56.8 s", "21.3 / 56.8 %")  # the text around the numbers counts
    assert not same("21.3 s", "21.3 / 56.8 s")
    assert same("−2.09·10⁻⁶ (law 21)", "−2.08·10⁻⁶ (law 21)")
    assert not same("−2.09·10⁻⁶", "−2.09·10⁻⁵")
    assert same("39 296.63 s", "39 296.64 s") and not same("39 296.63 s", "39 296.73 s")
    assert tables._number("−2.1·10⁻⁶") == -2.1e-6 and tables._last_digit("2.1·10⁻⁶") == pytest.approx(1e-7)
    assert tables.fmt(-2.0861e-6, ".2x") == "−2.09·10⁻⁶"
    assert tables.fmt(2497.8, "_.0f") == "2 498" and tables.fmt(-9.166, ".2fm") == "−9.17"
    assert tables.sig(58.025) == "58.0" and tables.sig(145.8) == "146" and tables.sig(0.0) == "0"


def test_a_column_round_off_decides_is_held_to_its_stated_tolerance(tables):
    """``rtol=COLUMN:FRACTION`` (a chattering law, a rate limit flipping on round-off): within the
    fraction is no drift, beyond it is; the other columns keep one unit in the last digit."""
    documented = "| metric | `a` | `b` |\n|---|---:|---:|\n| `J` | 100.0 | 50.0 |\n"
    within = "| metric | `a` | `b` |\n|---|---:|---:|\n| `J` | 104.0 | 50.3 |\n"
    assert [d.column for d in tables.drifts(documented, within, "p", "t", {"a": 0.05})] == ["`b`"]
    assert tables.drifts(documented, within, "p", "t", {"*": 0.05}) == []
    assert len(tables.drifts(documented, within, "p", "t")) == 2  # no tolerance: both drift
    beyond = within.replace("104.0", "106.0")
    assert [d.column for d in tables.drifts(documented, beyond, "p", "t", {"*": 0.05})] == ["`a`"]
    assert tables._options("keys=J rtol=a:0.05,`b`:0.1")[3] == {"a": 0.05, "b": 0.1}
    with pytest.raises(ValueError, match="rtol"):
        tables._options("rtol=a")
