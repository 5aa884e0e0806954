"""Documentation tables are generated from the runs they describe (``docs/tables.py``): a number a
page documents between ``<!-- table: NAME -->`` markers that drifts from ``shipgnc run NAME``
fails here, so documented numbers cannot go stale."""

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


@pytest.mark.parametrize("page", ["001_vectored_thrust_boat.md", "003_cybership_autopilot.md"])
def test_documented_tables_match_their_runs(tables, page):
    text = (DOCS / page).read_text(encoding="utf-8")
    assert "<!-- table: " in text, f"{page} has no generated table"
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


def test_an_unknown_metric_or_option_is_refused(tables):
    with pytest.raises(KeyError, match="no metric"):
        tables.render("boat-stern-kick", ["no_such_metric"])
    with pytest.raises(ValueError, match="table option"):
        tables._options("colour=red")
