"""The documentation site: it builds without a warning, every page's Python example runs, every
gallery script and the tutorial (``examples/``, sphinx-gallery) run at the build and draw their
figures, and every figure a page shows is one ``docs/make_figures.py`` produces from the code."""

from __future__ import annotations

import importlib.util
import re
import subprocess
import sys
import types
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
PAGES = sorted(DOCS.glob("*.md")) + sorted((DOCS / "api").glob("*.md"))
FENCE = re.compile(r"^```python\n(.*?)^```", re.S | re.M)
IMAGE = re.compile(r"!\[[^\]]*\]\(([^)]+)\)")


def _pages_with_examples():
    for page in [*PAGES, ROOT / "README.md"]:
        blocks = [m.group(1) for m in FENCE.finditer(page.read_text(encoding="utf-8"))]
        if blocks:
            yield pytest.param(blocks, id=str(page.relative_to(ROOT)))


def test_site_builds_without_warnings(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
                           str(DOCS), str(tmp_path / "site")], capture_output=True, text=True,
                          cwd=ROOT, timeout=600)
    assert proc.returncode == 0, proc.stderr[-4000:]
    for page in ("index", "concepts", "studies", "rl", "extending", "000_mariner_tracking",
                 "004_catamaran_fsm", "api/sim", "references", "cite", "changelog", "gallery/index",
                 "tutorial/plot_your_vessel_your_autopilot"):
        assert (tmp_path / "site" / f"{page}.html").stat().st_size > 5000
    # the gallery and the tutorial ran (sphinx-gallery, abort_on_example_error): every example's
    # page carries at least one figure it drew
    examples = sorted((ROOT / "examples" / "gallery").glob("plot_*.py"))
    assert len(examples) >= 10
    for script in [*examples, ROOT / "examples" / "tutorial" / "plot_your_vessel_your_autopilot.py"]:
        html = tmp_path / "site" / script.parent.name / f"{script.stem}.html"
        assert f"sphx_glr_{script.stem}_001" in html.read_text(encoding="utf-8"), f"{script.name}: no figure"


@pytest.mark.parametrize("blocks", list(_pages_with_examples()))
def test_page_examples_run(blocks, tmp_path, monkeypatch):
    """A page's Python blocks run in order in one namespace, as a reader would paste them."""
    monkeypatch.chdir(tmp_path)
    module = types.ModuleType("docs_example")
    monkeypatch.setitem(sys.modules, "docs_example", module)  # dataclasses look their module up
    for i, code in enumerate(blocks, start=1):
        exec(compile(code, f"<example {i}>", "exec"), module.__dict__)


def test_every_figure_on_a_page_is_produced_by_the_code():
    spec = importlib.util.spec_from_file_location("make_figures", DOCS / "make_figures.py")
    make_figures = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(make_figures)
    produced = make_figures.produced()
    shown = set()
    for page in [*PAGES, ROOT / "README.md"]:
        for target in IMAGE.findall(page.read_text(encoding="utf-8")):
            path = (page.parent / target).resolve()
            assert path.is_file(), f"{page.name}: {target} is missing"
            assert path.parent == DOCS / "figures", f"{page.name}: {target} is not in docs/figures"
            assert path.name in produced, f"{page.name}: {target} is not drawn by docs/make_figures.py"
            shown.add(path.name)
    assert shown, "no figure on any page"
    unused = sorted(produced - shown)
    assert not unused, f"figures drawn but shown on no page: {unused}"
