"""Ships meeting ships, through the whole loop: the collision-avoidance guidance between LOS and the
frigate's heading autopilot, its kinematic targets and the ``colav`` metrics, SB-MPC's behaviour
(Johansen, Perez & Cristofaro 2016), the standard encounter set in trafficgen's format and the
command's bad input.

References: the closed-form CPA of two constant-velocity ships (written out here), COLREG rules 14
and 17 as the paper describes SB-MPC's behaviour, trafficgen's published traffic-situation format.
Runs use the numpy loop (the guidance's compiled kernel through its derived batch), short encounters
and one batch each, to keep compile and run times to seconds.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

from shipgnc.cli import app
from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import run_scenario
from shipgnc.study import encounters as E
from shipgnc.study import trafficgen as tg

U = 9.0  # the frigate's speed [m/s]


def _run(targets, method="none", t_end=700.0, extra=()):
    scenario = load_scenario("colav-head-on", ["runs=null", f"guidance.method={method}",
                                               f"simulation.t_end={t_end}",
                                               "simulation.backend=numpy",
                                               f"guidance.targets={json.dumps(targets)}", *extra])
    return run_scenario(scenario)


def closed_form_cpa(p, v):
    """d_cpa, t_cpa of relative position p and relative velocity v (both constant)."""
    t = max(0.0, -float(np.dot(p, v)) / float(np.dot(v, v)))
    return float(np.linalg.norm(np.asarray(p) + np.asarray(v) * t)), t


def test_realised_cpa_of_kinematic_targets_is_the_closed_form():
    """No avoidance: the own ship holds course 0 at U, so the least range to each constant-velocity
    target, and when, are the closed form's (to the guidance's 0.5 s sampling)."""
    targets = [{"name": "a", "north": 9000.0, "east": 300.0, "course_deg": 180.0, "speed": 8.0},
               {"name": "b", "north": 4000.0, "east": -3000.0, "course_deg": 80.0, "speed": 6.0}]
    run = _run(targets)
    own_v = np.array([U, 0.0])
    expected = []
    for tg_ in targets:
        c = math.radians(tg_["course_deg"])
        p = np.array([tg_["north"], tg_["east"]])
        v = tg_["speed"] * np.array([math.cos(c), math.sin(c)]) - own_v
        expected.append(closed_form_cpa(p, v))
    j = int(np.argmin([d for d, _ in expected]))
    d_cpa, t_cpa = expected[j]
    m = run.metrics
    rel_speed = 20.0  # ≥ every relative speed here: half a sample's motion bounds the error
    assert m["cpa_target"] == j
    assert m["t_min_range_s"] == pytest.approx(t_cpa, abs=0.25 + 1e-9)
    assert d_cpa <= m["min_range_m"] <= math.hypot(d_cpa, 0.25 * rel_speed) + 1e-6
    assert m["collision"] == int(d_cpa < 200.0)
    # the targets' states in the result: the dead-reckoned tracks, on a target dimension
    ds = run.result
    t = ds["time"].values
    c = math.radians(targets[1]["course_deg"])
    np.testing.assert_allclose(ds["target_north"].sel(target="b").values,
                               targets[1]["north"] + 6.0 * math.cos(c) * t, atol=1e-6)
    np.testing.assert_allclose(ds["target_cog"].sel(target="b").values, c, atol=1e-12)
    np.testing.assert_allclose(ds["target_sog"].sel(target="a").values, 8.0)


def test_sbmpc_turns_to_starboard_in_a_head_on_encounter():
    """Rule 14 as SB-MPC scores it: dead ahead on a reciprocal course, the own ship alters to
    starboard (its first course change is positive), passes port to port and clears the safety
    radius; without avoidance the two collide."""
    target = [{"north": 12000.0, "east": 0.0, "course_deg": 180.0, "speed": U}]
    base, sb = _run(target, "none"), _run(target, "sbmpc")
    assert base.metrics["collision"] == 1
    assert sb.metrics["collision"] == 0 and sb.metrics["min_range_m"] > 200.0
    offset = np.degrees(sb.result["course_cmd"].values - sb.result["course_nominal"].values)
    first = offset[np.flatnonzero(np.abs(offset) > 1e-9)[0]]
    assert first > 0  # starboard
    k = int(np.argmin(np.abs(sb.result["time"].values - sb.metrics["t_min_range_s"])))
    assert sb.result["east"].values[k] > sb.result["target_east"].values[k, 0]  # port to port


def _port_crosser(course_deg):
    """A target from port (bearing -35.5 deg, 8.6 km) at 7 m/s steering ``course_deg``, crossing
    ahead of the own ship: its closed-form CPA and COLREG situation."""
    from shipgnc.colav.colreg import situations

    c = math.radians(course_deg)
    v_t = 7.0 * np.array([math.cos(c), math.sin(c)])
    d_cpa, _ = closed_form_cpa(np.array([7000.0, -5000.0]), v_t - np.array([U, 0.0]))
    code = situations([0.0, 0.0, 0.0, U], [7000.0, -5000.0, *v_t])
    target = [{"north": 7000.0, "east": -5000.0, "course_deg": course_deg, "speed": 7.0}]
    return target, d_cpa, int(code)


def test_stand_on_ship_keeps_course_and_speed():
    """Rule 17(a)(i): a crossing target from port (the own ship stands on) passing ahead at a CPA
    beyond SB-MPC's d_close leaves the own ship on its nominal course and speed throughout."""
    from shipgnc.colav.colreg import STAND_ON

    target, d_cpa, code = _port_crosser(70.0)
    assert code == STAND_ON and 1000.0 < d_cpa < 1852.0
    run = _run(target, "sbmpc", t_end=1000.0)
    ds = run.result
    np.testing.assert_array_equal(ds["course_cmd"].values, ds["course_nominal"].values)
    np.testing.assert_array_equal(ds["speed_cmd"].values, U)
    assert run.metrics["max_cross_track_m"] < 1e-6


def test_sbmpc_as_written_alters_as_stand_on_when_the_crosser_passes_within_d_close():
    """A departure from rule 17(a)(i), shown, not hidden: SB-MPC's COLREG term μ (Johansen et al.
    2016) charges every predicted instant at which a crossing target is within d_close (1000 m) on
    the own starboard side, whichever ship gives way. A port crosser passing ahead at a CPA of
    ~900 m will be there, so the stand-on own ship turns to starboard (behind the crosser) before
    the CPA instead of keeping its course."""
    from shipgnc.colav.colreg import STAND_ON

    target, d_cpa, code = _port_crosser(80.0)
    assert code == STAND_ON and 600.0 < d_cpa < 1000.0
    ds = _run(target, "sbmpc", t_end=1000.0).result
    offset = ds["course_cmd"].values - ds["course_nominal"].values
    changed = np.flatnonzero(np.abs(offset) > 1e-9)
    assert changed.size and offset[changed[0]] > 0


def test_standard_set_meets_at_the_meeting_point_and_classifies_as_its_type():
    """Each standard situation, written in trafficgen's format and read back through the map
    projection, is on a collision course meeting after its vector time (closed-form CPA 0 at T),
    and COLREG classifies it as the type it was generated for."""
    from shipgnc.colav.colreg import SITUATIONS, situations

    kinds = {"head-on": "head_on", "overtaking-give-way": "overtaking",
             "overtaking-stand-on": "overtaken", "crossing-give-way": "give_way",
             "crossing-stand-on": "stand_on"}
    for spec in tg.STANDARD:
        sit = tg.parse(json.loads(json.dumps(tg.situation_dict(spec, U))), spec.title)
        t = sit.targets[0]
        assert sit.own_speed == pytest.approx(U, rel=1e-5)  # knots to 4 decimals
        p = np.array([t.north[0], t.east[0]])
        v = np.array([t.v_north[0], t.v_east[0]]) - np.array([sit.own_speed, 0.0])
        d_cpa, t_cpa = closed_form_cpa(p, v)
        assert d_cpa < 1.0 and t_cpa == pytest.approx(spec.vector_time_s, rel=1e-4)
        bearing = math.degrees(math.atan2(p[1], p[0]))
        assert bearing == pytest.approx(spec.beta_deg, abs=1e-4)
        code = situations([0.0, 0.0, 0.0, sit.own_speed],
                          [t.north[0], t.east[0], t.v_north[0], t.v_east[0]])
        assert SITUATIONS[int(code)] == kinds[spec.encounter_type]


def test_trafficgen_file_read_as_published(tmp_path):
    """A traffic situation in the layout trafficgen publishes (static, initial with lat/lon, sog in
    knots, cog in degrees, waypoints) is read with its target where the projection puts it."""
    data = {"title": "HO", "description": "one target",
            "ownShip": {"static": {"id": "x", "length": 122.0, "width": 20.0, "height": 8.0,
                                   "speedMax": 17.0, "mmsi": 257847600, "name": "own",
                                   "shipType": "Passenger"},
                        "initial": {"position": {"lat": 58.0, "lon": 10.0}, "sog": 10.0,
                                    "cog": 0.0, "heading": 0.0,
                                    "navStatus": "Under way using engine"},
                        "waypoints": [{"position": {"lat": 58.0, "lon": 10.0}}]},
            "targetShips": [{"static": {"length": 178.0, "width": 30.0, "name": "t1"},
                             "initial": {"position": {"lat": 58.05, "lon": 10.0}, "sog": 12.0,
                                         "cog": 180.0, "heading": 180.0,
                                         "navStatus": "Under way using engine"}}]}
    path = tmp_path / "ho.json"
    path.write_text(json.dumps(data))
    sit = tg.read(path)
    t = sit.targets[0]
    # 0.05° of latitude at 58° N on WGS84: 5566 m (meridian arc, pyproj's Geod)
    from pyproj import Geod

    _, _, dist = Geod(ellps="WGS84").inv(10.0, 58.0, 10.0, 58.05)
    assert t.north[0] == pytest.approx(dist, rel=1e-6) and abs(t.east[0]) < 1e-6
    assert t.v_north[0] == pytest.approx(-12.0 * 1852 / 3600) and t.length == 178.0
    assert sit.own_speed == pytest.approx(10.0 * 1852 / 3600)


def test_encounters_command_bad_input_is_one_line_exit_2(tmp_path):
    runner = CliRunner()
    wrong = tmp_path / "wrong.json"
    wrong.write_text(json.dumps({"title": "x", "ownShip": {"initial": {
        "position": {"lat": 58.0, "lon": 10.0}, "cog": 0.0}}, "targetShips": []}))
    done = runner.invoke(app, ["encounters", str(wrong), "--out", str(tmp_path / "o")])
    assert done.exit_code == 2
    assert "ownShip.initial.sog" in done.output and "Traceback" not in done.output
    on_top = tmp_path / "on_top.json"
    ship = {"initial": {"position": {"lat": 58.0, "lon": 10.0}, "sog": 10.0, "cog": 0.0}}
    on_top.write_text(json.dumps({"title": "T", "ownShip": ship, "targetShips": [ship]}))
    done = runner.invoke(app, ["encounters", str(on_top), "--out", str(tmp_path / "o")])
    assert done.exit_code == 2
    assert "targetShips[0]" in done.output and "safety radius" in done.output
    done = runner.invoke(app, ["encounters", "--method", "magic", "--out", str(tmp_path / "o")])
    assert done.exit_code == 2 and "--method 'magic'" in done.output


def test_scenario_target_on_top_of_own_ship_names_the_field():
    from shipgnc.errors import ConfigError

    with pytest.raises(ConfigError, match=r"guidance\.targets\[0\]: 50\.0 m from the own ship"):
        _run([{"north": 50.0, "east": 0.0, "course_deg": 0.0, "speed": 1.0}])


def test_sweep_members_are_their_scenarios():
    """A member of the batched sweep scores as the same encounter run alone as a scenario."""
    spec = tg.STANDARD[3]  # crossing give-way
    members = E.standard_members(["sbmpc"], specs=(spec,))
    sweep = E.run_members(members, backend="numpy")
    t = members[0].situation.targets[0]
    course = math.degrees(math.atan2(t.v_east[0], t.v_north[0]))
    alone = _run([{"north": float(t.north[0]), "east": float(t.east[0]), "course_deg": course,
                   "speed": float(math.hypot(t.v_north[0], t.v_east[0]))}], "sbmpc", t_end=1200.0)
    # the target's course goes through degrees and back in the scenario: round-off, amplified by
    # 20 minutes of closed loop, moves the result by well under a centimetre
    assert sweep.scores["min_range_m"][0] == pytest.approx(alone.metrics["min_range_m"], abs=0.01)
    assert sweep.scores["time_lost_s"][0] == pytest.approx(alone.metrics["time_lost_s"], abs=0.01)
    assert sweep.scores["collision"][0] == alone.metrics["collision"] == 0


def test_targets_replayed_from_an_ais_log(tmp_path):
    """A target written as an NMEA AIS log (reports every 10 s, pyais) and replayed through
    ``guidance.ais_log`` moves as the constant-velocity track it was written from, to the message's
    quantisation, and its realised CPA is the closed form's to the same tolerance. The bound: half
    a position step (1/10000 arc minute: 0.09 m north, 0.05 m east at 58° N) plus 10 s of dead
    reckoning on half a SOG step (0.05 kn: 0.26 m) and half a COG step (0.05° of 8 m/s: 0.07 m),
    0.5 m in all; 1 m allowed (the plane's scale error at 8 km is 10⁻⁶, mm)."""
    from shipgnc.ais.write import write_log
    from shipgnc.colav.tracks import TargetTrack

    origin = (58.0, 10.0)
    course = math.radians(200.0)
    true = TargetTrack.constant(8000.0, 2500.0, course, 8.0)
    t = np.arange(0.0, 701.0, 10.0)
    own = {"north": U * t, "east": 0.0 * t, "sog": np.full_like(t, U), "cog": 0.0 * t}
    path = write_log(tmp_path / "log.nmea", t, own, [true], origin, 257000001, [257000002],
                     interval=10.0)
    run = _run([], extra=(f"guidance.ais_log={json.dumps({'path': str(path), 'origin': origin})}",))
    ds = run.result
    n, e, _, _ = true.at(ds["time"].values)
    assert ds.sizes["target"] == 1
    np.testing.assert_allclose(ds["target_north"].values[:, 0], n, atol=1.0)
    np.testing.assert_allclose(ds["target_east"].values[:, 0], e, atol=1.0)
    v = 8.0 * np.array([math.cos(course), math.sin(course)]) - np.array([U, 0.0])
    d_cpa, t_cpa = closed_form_cpa(np.array([8000.0, 2500.0]), v)
    assert run.metrics["min_range_m"] == pytest.approx(d_cpa, abs=1.0)
    assert run.metrics["t_min_range_s"] == pytest.approx(t_cpa, abs=2.0)


def test_monte_carlo_variants_classify_as_their_type_and_nest():
    """Every perturbed variant of the standard set is, by COLREG rules 13–17 at t = 0, the
    situation its type names; each type draws from its own child seed, so the variants of
    ``mc`` = 5 are the first five of ``mc`` = 10."""
    from shipgnc.colav.colreg import SITUATIONS

    ten = E.standard_members(["none"], mc=10, seed=3, own_speed=U)
    five = E.standard_members(["none"], mc=5, seed=3, own_speed=U)
    scores = E.initial_scores(ten, range(len(ten)))
    for m, code in zip(ten, scores["situation"], strict=True):
        assert SITUATIONS[int(code)] == tg.SITUATION_OF[m.situation.encounter_type], m.spec
    first = [m.spec for m in ten if m.mc < 5]
    assert first == [m.spec for m in five]


def test_trafficgen_current_layout_latitude_longitude():
    """trafficgen's current files (and the maritime-schema) spell positions latitude/longitude."""
    ship = {"initial": {"position": {"latitude": 58.0, "longitude": 10.0}, "sog": 10.0,
                        "cog": 0.0}}
    target = {"initial": {"position": {"latitude": 58.05, "longitude": 10.0}, "sog": 10.0,
                          "cog": 180.0}}
    sit = tg.parse({"ownShip": ship, "targetShips": [target]})
    assert sit.origin == (58.0, 10.0) and sit.targets[0].north[0] == pytest.approx(5566, abs=5)


def test_a_far_away_target_is_refused_with_its_distance():
    """A target beyond the local plane's 60 km: one line naming it and its geodesic distance."""
    from pyproj import Geod

    from shipgnc.errors import ConfigError

    own = {"initial": {"position": {"lat": 58.0, "lon": 10.0}, "sog": 15.0, "cog": 0.0}}
    far = {"initial": {"position": {"lat": 59.0, "lon": 10.0}, "sog": 10.0, "cog": 180.0}}
    _, _, d = Geod(ellps="WGS84").inv(10.0, 58.0, 10.0, 59.0)
    with pytest.raises(ConfigError, match=rf"F: targetShips\[0\] is {d / 1000:.0f} km from"):
        tg.parse({"ownShip": own, "targetShips": [far]}, "F")


def test_bad_seed_own_speed_and_schedule_with_course(tmp_path):
    """--seed -1 is a usage error; an own ship slower than the frigate's 5–12 m/s (van Amerongen's
    table) names the file's field in knots; a target with both a schedule and a course is refused."""
    from shipgnc.errors import ConfigError
    from shipgnc.scenarios.sections import TargetConfig

    runner = CliRunner()
    done = runner.invoke(app, ["encounters", "--seed", "-1", "--out", str(tmp_path / "o")])
    assert done.exit_code == 2 and "Traceback" not in done.output
    slow = tmp_path / "slow.json"
    own = {"initial": {"position": {"lat": 58.0, "lon": 10.0}, "sog": 0.5, "cog": 0.0}}
    target = {"initial": {"position": {"lat": 58.05, "lon": 10.0}, "sog": 10.0, "cog": 180.0}}
    slow.write_text(json.dumps({"ownShip": own, "targetShips": [target]}))
    with pytest.raises(ConfigError, match=r"slow\.json: ownShip\.initial\.sog = 0\.5 kn \(own ship "
                                          r"sails 9\.7–23\.3 kn\)"):
        E.file_members([slow], ["none"])
    with pytest.raises(ValueError, match="course_deg with a schedule"):
        TargetConfig(north=1e3, east=0.0, course_deg=10.0,
                     schedule=[{"t": 0.0, "course_deg": 60.0, "speed": 6.0}])


def test_a_target_is_absent_before_its_first_sample(tmp_path):
    """Targets first heard at t = 150 s (their first AIS reports; the log's own-ship !AIVDO reports
    start at 0) are not there before: no report written before, NaN states in the result, no
    avoidance and no range before 150 s. Dead-reckoned backwards, the head-on one would be met
    221 s after t = 0 (3100 m at 14 m/s closing), inside SB-MPC's 100 s horizon from t = 121 s;
    the receding one (12 m/s ahead of the own ship's 9) would be nearest at t = 0 (1050 m)."""
    from shipgnc.ais.write import write_log
    from shipgnc.colav.tracks import TargetTrack

    first, origin = 150.0, (58.0, 10.0)
    head_on = TargetTrack.constant(U * first + 1000.0, 0.0, math.pi, 5.0, t0=first)
    receding = TargetTrack.constant(U * first + 1500.0, 3000.0, 0.0, 12.0, t0=first)
    t = np.arange(0.0, 701.0, 10.0)
    own = {"north": U * t, "east": 0.0 * t, "sog": np.full_like(t, U), "cog": 0.0 * t}
    path = write_log(tmp_path / "log.nmea", t, own, [head_on, receding], origin, 257000001,
                     [257000002, 257000003], interval=10.0)
    log = json.dumps({"path": str(path), "origin": origin})
    run = _run([], "sbmpc", extra=(f"guidance.ais_log={log}",))
    ds = run.result
    before = ds["time"].values < first
    assert np.all(np.isnan(ds["target_north"].values[before]))
    assert np.all(np.isfinite(ds["target_north"].values[~before]))
    np.testing.assert_array_equal(ds["course_cmd"].values[before], ds["course_nominal"].values[before])
    assert not np.array_equal(ds["course_cmd"].values, ds["course_nominal"].values)  # it does avoid
    assert run.metrics["t_min_range_s"] >= first


def test_sweep_compliance_thresholds_fit_the_domain_and_horizon():
    """The sweep's compliance thresholds come from its ship domain and the methods' horizon: a CPA
    inside the domain (a collision) scores safety 0; a clean SB-MPC pass in the overtaking
    give-way (closing at 4.5 m/s: the collision enters the 100 s horizon at 200 + 450 = 650 m,
    inside a fixed 0.5 nm 'too late') is not scored rule_16 = 0."""
    from shipgnc.colav.compliance import safety_score
    from shipgnc.colav.sbmpc import SBMPCConfig
    from shipgnc.colav.vo import VOConfig

    assert SBMPCConfig().horizon == VOConfig().horizon == E.HORIZON
    c = E.sweep_compliance(0.5 * U)
    assert (c.r_collision, c.r_early, c.r_late) == (E.SAFETY_RADIUS, 650.0, 425.0)
    assert safety_score(E.SAFETY_RADIUS - 1e-6, c) == 0.0 < safety_score(E.SAFETY_RADIUS + 1.0, c)
    sweep = E.run_members(E.standard_members(["sbmpc"], specs=(tg.STANDARD[1],)), backend="numpy")
    assert sweep.scores["collision"][0] == 0 and sweep.scores["rule_16"][0] > 0.0


def test_an_ais_log_with_untimed_lines_replays_with_untimed_previous(tmp_path):
    """``guidance.ais_log.untimed``: a log whose later sentences lost their tag block (no time of
    their own) is refused by default naming the line, and with ``untimed: previous`` each such
    report takes the time of the line before it (as ``shipgnc ais info --untimed previous``)."""
    from shipgnc.ais.logs import read_log
    from shipgnc.ais.write import write_log
    from shipgnc.colav.tracks import TargetTrack
    from shipgnc.errors import ConfigError

    origin = (58.0, 10.0)
    t = np.arange(0.0, 301.0, 10.0)
    own = {"north": U * t, "east": 0.0 * t, "sog": np.full_like(t, U), "cog": 0.0 * t}
    true = TargetTrack.constant(8000.0, 2500.0, math.radians(200.0), 8.0)
    path = write_log(tmp_path / "log.nmea", t, own, [true], origin, 257000001, [257000002],
                     interval=10.0)
    lines = path.read_text().splitlines()
    lines[-1] = lines[-1][lines[-1].rindex("\\") + 1:]  # the last sentence without its tag block
    path.write_text("\n".join(lines) + "\n")
    log = {"path": str(path), "origin": origin}
    with pytest.raises(ConfigError, match=rf"line {len(lines)}: no time"):
        _run([], extra=(f"guidance.ais_log={json.dumps(log)}",))
    run = _run([], extra=(f"guidance.ais_log={json.dumps({**log, 'untimed': 'previous'})}",))
    tracks, _ = read_log(path, origin=origin, untimed="previous")
    seen = next(tr for tr in tracks if tr.source == "ais")
    assert run.result.sizes["target"] == 1 and seen.t[-1] == pytest.approx(300.0)
