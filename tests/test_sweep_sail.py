"""Document 002's sailed routes in studies (``shipgnc sweep``): the route is solved once, each
sailed run (``path``, ``sail``, ``legs``) is a controller of the study, and a member without
offsets scores what ``shipgnc run`` reports for that run (note 002-2.9.7)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr

from shipgnc.errors import ConfigError
from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.routing import sail_runs
from shipgnc.scenarios.runner import build, run_scenario
from shipgnc.study.execute import run_study
from shipgnc.study.spec import Perturbation, Study

KEYS = ("arrived", "arrival_s", "arrival_ratio", "miss_m")


@pytest.fixture(scope="module")
def sailed():
    """``shipgnc run zermelo-sail``'s metrics and a study of it with one member and no offsets."""
    return (run_scenario("zermelo-sail").metrics,
            run_study(Study("zermelo-sail", members=1, seed=3)).dataset)


def test_a_member_without_offsets_scores_as_shipgnc_run(sailed):
    """Each sailed run of the study is the run ``shipgnc run`` sails (same route, ship, step and
    duration): its figures to round-off (both loops compiled; the run's arrival is interpolated
    between samples)."""
    metrics, ds = sailed
    assert ds.controller.values.tolist() == ["path", "sail", "legs"]
    for run in ("path", "sail", "legs"):
        for key in KEYS:
            want = metrics[f"{run}_{key}"]
            got = float(ds[key].sel(controller=run, member=0))
            if want is None:
                assert math.isnan(got), (run, key)
            else:
                assert got == pytest.approx(float(want), rel=1e-9, abs=1e-9), (run, key)
    for key in ("crosstrack_rms_m", "crosstrack_max_m"):
        assert float(ds[key].sel(controller="path", member=0)) == pytest.approx(
            metrics[f"path_{key}"], rel=1e-9)
        assert np.isnan(ds[key].sel(controller="sail", member=0))


def test_members_are_the_same_bits_in_any_chunking():
    study = Study("zermelo-sail", members=3, seed=5,
                  perturb=(Perturbation.parse("north=normal:5"), Perturbation.parse("psi_deg=normal:5")),
                  grid=(("sail.legs", (2,)),))
    a = run_study(study, chunk_size=3).dataset
    b = run_study(study, chunk_size=1).dataset
    xr.testing.assert_identical(a, b)
    # the offsets move where the ship ends: three members, three closest approaches
    assert len(np.unique(a["miss_m"].sel(controller="sail").values)) == 3


def test_the_runs_follow_the_vessel_and_are_named():
    assert sail_runs(load_scenario("zermelo-sail-mariner")) == ["sail", "legs"]
    scenario = load_scenario("zermelo-sail")
    setup = build(scenario, "legs")
    # the run's own step and duration: the route's time x (1 + margin), the sail section's step
    assert setup.simulation.dt == 0.1
    assert setup.simulation.t_end >= setup.case[0].route.time_s
    with pytest.raises(ConfigError, match=r"'lost': not a sailed run .* have path, sail, legs"):
        build(scenario, "lost")


@pytest.mark.parametrize(("name", "perturb", "message"), [
    ("zermelo-paper", (), r"routing problem \(document 002\) without a sail section"),
    ("zermelo-sail", ("vessel.params.m=normal:5%",), r"a route scenario's ship is sail\.vessel"),
])
def test_what_cannot_be_swept_is_refused_with_the_reason(name, perturb, message):
    with pytest.raises(ConfigError, match=message):
        run_study(Study(name, members=2, perturb=tuple(Perturbation.parse(p) for p in perturb)))


def test_a_grid_point_that_leaves_the_target_unreachable_is_named():
    """A horizon of 0.05 h (3 min) is far below the crossing's optimum (about 11 min): no route."""
    with pytest.raises(ConfigError, match=r"not reachable .*\(at grid point route\.horizon=0\.05\)"):
        run_study(Study("zermelo-sail", grid=(("route.horizon", (0.05,)),)))
