"""Regenerate the figures shown in README.md and docs/ from the built-in scenarios.

    python docs/make_figures.py [NAME ...]

Each figure is drawn by ``shipgnc run`` into a scratch folder and copied to ``docs/figures/``
under the name the pages use, so the pages show what the code produces.
"""

from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

FIGURES = Path(__file__).resolve().parent / "figures"
#: page figure → (scenario, overrides, file the run writes)
JOBS = {
    "boat-los-dashboard.png": ("boat-los", [], "dashboard.png"),
    "mariner-compare-fig3.png": ("mariner-compare", [], "fig3_tracks.png"),
    "mariner-compare-fig4.png": ("mariner-compare", [], "fig4_heading.png"),
    "mariner-montecarlo.png": ("mariner-montecarlo", [], "montecarlo.png"),
}


def main(names: list[str]) -> None:
    from shipgnc.scenarios.runner import run_scenario, write_outputs

    wanted = names or list(JOBS)
    unknown = sorted(set(wanted) - set(JOBS))
    if unknown:
        raise SystemExit(f"unknown figure(s) {', '.join(unknown)}; known: {', '.join(JOBS)}")
    runs: dict[tuple, Path] = {}
    FIGURES.mkdir(exist_ok=True)
    with tempfile.TemporaryDirectory() as scratch:
        for name in wanted:
            scenario, overrides, produced = JOBS[name]
            key = (scenario, tuple(overrides))
            if key not in runs:
                out = Path(scratch) / f"run{len(runs)}"
                write_outputs(run_scenario(scenario, overrides=overrides), out)
                runs[key] = out
            shutil.copyfile(runs[key] / produced, FIGURES / name)
            print(f"wrote docs/figures/{name}")


if __name__ == "__main__":
    main(sys.argv[1:])
