"""Regenerate every figure shown in README.md and the documentation pages, from the code.

    python docs/make_figures.py [NAME ...]

Scenario figures are drawn by the same code as ``shipgnc run`` into a scratch folder and copied to
``docs/figures/`` under the name the pages use; the document pages' own figure sets (routing,
catamaran) and the study figure come from their generators. So the pages show what the code
produces; ``tests/test_docs.py`` checks that every figure a page shows is one this script writes.
"""

from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

FIGURES = Path(__file__).resolve().parent / "figures"
#: page figure → (scenario, overrides, file the run writes)
JOBS = {
    "boat-stern-kick-dashboard.png": ("boat-stern-kick", [], "dashboard.png"),
    "boat-stern-kick-closeup.png": ("boat-stern-kick", [], "stern_kick_closeup.png"),
    "boat-autopilot-dashboard.png": ("boat-autopilot", [], "dashboard.png"),
    "boat-los-dashboard.png": ("boat-los", [], "dashboard.png"),
    "mariner-compare-fig3.png": ("mariner-compare", [], "fig3_tracks.png"),
    "mariner-compare-fig4.png": ("mariner-compare", [], "fig4_heading.png"),
    "mariner-compare-fig5.png": ("mariner-compare", [], "fig5_rudder.png"),
    "mariner-montecarlo.png": ("mariner-montecarlo", [], "montecarlo.png"),
    "cybership-calm.png": ("cybership-calm", [], "comparison.png"),
    "cybership-waves.png": ("cybership-waves", [], "comparison.png"),
}
#: figure sets drawn by a generator: name → (generator, files it writes)
SETS = {
    "routing": ("shipgnc.viz.route_figures:document_figures",
                ("zermelo-paper.png", "zermelo-vortex.png", "zermelo-shoal.png")),
    "catamaran": ("shipgnc.viz.catamaran:render_document_figures",
                  ("catamaran-fig1-phi3.png", "catamaran-fig2-3-laws.png", "catamaran-turn.png",
                   "catamaran-fig4-5-fixed.png", "catamaran-fig7-sine.png", "catamaran-fig8-heading.png",
                   "catamaran-characteristic.png")),
    "study": ("make_figures:study_figure", ("study-boat-autopilot.png",)),
    "routing-geo": ("shipgnc.routing.geo.figures:document_figure", ("routing-geo-channel.png",)),
    "cybership-analysis": ("cybership_analysis:figure", ("cybership-analysis.png",)),
    "observer-loop": ("observer_loop:figure", ("observer-loop-rudder.png",)),
    "encounters": ("shipgnc.viz.encounter_figures:document_figures",
                   ("encounters-tracks.png", "encounters-cpa-polar.png")),
    "vessel-targets": ("shipgnc.viz.vessel_target_figures:document_figures", ("vessel-targets.png",)),
    "trials": ("shipgnc.viz.trial_figures:document_figures",
               tuple(f"trials-{v}-{w}.png" for v in ("mariner", "kvlcc2")
                     for w in ("turning", "zigzag-20", "zigzag-10", "spiral"))),
}


def produced() -> set[str]:
    """Every file name this script writes into ``docs/figures``."""
    return set(JOBS) | {name for _, names in SETS.values() for name in names}


def study_figure(directory: Path) -> list[Path]:
    """The studies page's figure: ``boat-autopilot`` over three reference-model bandwidths × 200
    members with random initial headings and speeds."""
    from shipgnc.study.execute import run_study
    from shipgnc.study.spec import Perturbation, Study, parse_grid
    from shipgnc.viz.study_summary import spread_figure

    study = Study("boat-autopilot", grid=(parse_grid("controller.omega_ref=0.5,1.0,2.0"),), members=200,
                  seed=1, perturb=(Perturbation.parse("psi_deg=uniform:-30,30"),
                                   Perturbation.parse("u=normal:0.2")))
    return [spread_figure(run_study(study).dataset, Path(directory) / "study-boat-autopilot.png")]


def _generator(path: str):
    import importlib

    module, _, name = path.partition(":")
    if module == "make_figures":
        return globals()[name]
    if module in ("cybership_analysis", "observer_loop"):  # scripts beside this one (docs/)
        sys.path.insert(0, str(Path(__file__).resolve().parent))
    return getattr(importlib.import_module(module), name)


def main(names: list[str]) -> None:
    from shipgnc.scenarios.runner import run_scenario
    from shipgnc.viz.run_files import write_outputs

    known = [*JOBS, *SETS]
    wanted = names or known
    unknown = sorted(set(wanted) - set(known))
    if unknown:
        raise SystemExit(f"unknown figure(s) {', '.join(unknown)}; known: {', '.join(known)}")
    runs: dict[tuple, Path] = {}
    FIGURES.mkdir(exist_ok=True)
    with tempfile.TemporaryDirectory() as scratch:
        for name in wanted:
            if name in SETS:
                for path in _generator(SETS[name][0])(FIGURES):
                    print(f"wrote docs/figures/{Path(path).name}")
                continue
            scenario, overrides, file = JOBS[name]
            key = (scenario, tuple(overrides))
            if key not in runs:
                out = Path(scratch) / f"run{len(runs)}"
                write_outputs(run_scenario(scenario, overrides=overrides), out)
                runs[key] = out
            shutil.copyfile(runs[key] / file, FIGURES / name)
            print(f"wrote docs/figures/{name}")


if __name__ == "__main__":
    main(sys.argv[1:])
