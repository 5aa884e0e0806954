"""What the pages state is the code's: "the N built-in scenarios" is what ``shipgnc list`` prints,
and the two getting-started pages (README, docs/index.md), which begin from the install
commands, activate the venv before a bare ``shipgnc``."""

from __future__ import annotations

import re
from pathlib import Path

from shipgnc.scenarios.registry import list_scenarios

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
COUNT = re.compile(r"(\d+) built-in scenarios")
BASH_BLOCK = re.compile(r"^```bash\n(.*?)^```", re.S | re.M)


def test_the_stated_number_of_built_in_scenarios_is_the_registry_s():
    n = len(list_scenarios())
    stated = [(page.name, int(m)) for page in PAGES for m in COUNT.findall(page.read_text(encoding="utf-8"))]
    assert stated, "no page states the number of built-in scenarios"
    assert all(count == n for _, count in stated), (n, stated)


def test_a_bare_shipgnc_comes_after_the_venv_is_activated():
    for page in (ROOT / "README.md", ROOT / "docs" / "index.md"):
        activated = False
        for block in BASH_BLOCK.findall(page.read_text(encoding="utf-8")):
            for line in block.splitlines():
                activated |= line.strip().startswith("source .venv/bin/activate")
                if line.startswith("shipgnc "):
                    assert activated, f"{page.name}: `{line.split('#')[0].strip()}` before the venv is activated"
