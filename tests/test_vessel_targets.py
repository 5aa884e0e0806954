"""Targets that are vessels (:mod:`shipgnc.guidance.vessel_targets`): the reduced steering model
against the Nomoto and Norrbin closed forms, the autopilot's heading loop against the linear
second-order closed loop, the track along waypoints against the path's geometry, a straight-running
vessel target against the kinematic target it equals, and targets running their own avoidance
against the behaviour the papers describe (COLREG rules 14 and 15)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.linalg import expm

from shipgnc.guidance.vessel_targets import (
    S_FIXED,
    SCRATCH,
    VesselTarget,
    integrate_vessel,
    vessel_target_sample,
)
from shipgnc.kernels import flat
from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import run_scenario
from shipgnc.vessels.frigate import frigate_gains

U = 9.0  # the frigate's speed [m/s]


def _target(**kw) -> VesselTarget:
    base = {"north": 0.0, "east": 0.0, "psi": 0.0, "U": U, "K": 0.18, "T": 27.0,
            "waypoints": [[1e7, 0.0]]}
    return VesselTarget(**{**base, **kw})


def _state(target: VesselTarget) -> np.ndarray:
    return target.state(S_FIXED + SCRATCH)


def _run(targets, method="none", t_end=700.0, extra=()):
    scenario = load_scenario("colav-head-on", ["runs=null", f"guidance.method={method}",
                                               f"simulation.t_end={t_end}",
                                               "simulation.backend=numpy",
                                               f"guidance.targets={json.dumps(targets)}", *extra])
    return run_scenario(scenario)


def test_constant_rudder_follows_the_nomoto_closed_form():
    """T ṙ + r = K δ from rest with δ held: r = Kδ(1 − e^(−t/T)), ψ = Kδ(t − T(1 − e^(−t/T))), the
    position the integral of U(cos ψ, sin ψ) (quadrature); the steady turning radius U/(Kδ)."""
    tg = _target()
    p = tg.params(0, flat())
    s = _state(tg)
    delta = math.radians(10.0)
    s[4] = s[5] = delta  # rudder at its command: the servo rests
    K, T = tg.K, tg.T
    t_end, h = 600.0, 1.0
    for _ in range(int(t_end / h)):
        integrate_vessel(s, p, h)
    r = K * delta * (1 - math.exp(-t_end / T))
    psi = K * delta * (t_end - T * (1 - math.exp(-t_end / T)))

    def heading(t):
        return K * delta * (t - T * (1 - math.exp(-t / T)))

    north = quad(lambda t: U * math.cos(heading(t)), 0, t_end, limit=400)[0]
    east = quad(lambda t: U * math.sin(heading(t)), 0, t_end, limit=400)[0]
    assert s[3] == pytest.approx(r, rel=1e-9)
    assert s[2] == pytest.approx(psi, rel=1e-9)
    assert s[0] == pytest.approx(north, abs=1e-4) and s[1] == pytest.approx(east, abs=1e-4)
    # the steady turn: the centre is at a distance U/r from the ship, abeam to starboard
    radius = U / r
    centre = (s[0] - radius * math.sin(s[2]), s[1] + radius * math.cos(s[2]))
    for _ in range(200):
        integrate_vessel(s, p, h)
    assert math.hypot(s[0] - centre[0], s[1] - centre[1]) == pytest.approx(radius, rel=1e-6)


def test_short_nomoto_time_constant_is_integrated_stably():
    """T = 0.01 s (far below the guidance sample and T_δ): the sub-step is held below T/2 (RK4's
    real-axis stability bound is 2.785 T), so r follows T ṙ + r = K δ with δ held: r = Kδ within
    round-off after the first step, no blow-up."""
    tg = _target(K=0.1, T=0.01)
    p = tg.params(0, flat())
    s = _state(tg)
    delta = math.radians(10.0)
    s[4] = s[5] = delta
    for _ in range(120):
        integrate_vessel(s, p, 0.5)
    assert np.all(np.isfinite(s[:5]))
    assert s[3] == pytest.approx(0.1 * delta, rel=1e-9)
    assert s[2] == pytest.approx(0.1 * delta * (60.0 - 0.01), rel=1e-6)


def test_short_nomoto_target_runs_and_a_non_finite_target_stops_the_run():
    """The T = 0.01 s target runs to the end with a finite track; a target whose state does become
    non-finite (n₃ r³ far too stiff for the sub-step) stops the run as a divergence at that sample
    instead of being left out of the scores."""
    from shipgnc.errors import DivergenceError

    base = {"north": 11112.0, "east": 150.0, "course_deg": 180.0, "speed": U,
            "waypoints": [[11112.0, 5000.0]]}
    run = _run([{**base, "vessel": {"model": "nomoto", "K": 0.1, "T": 0.01}}], t_end=60.0)
    assert np.all(np.isfinite(run.result["target_north"].values))
    assert not run.metrics["diverged"]
    with pytest.raises(DivergenceError, match=r"diverged at t = "):
        _run([{**base, "vessel": {"model": "nomoto", "K": 0.1, "T": 1.0, "n3": 1e6}}], t_end=60.0)


@pytest.mark.parametrize("backend", ["numpy", "compiled"])
def test_a_diverging_vessel_target_is_named_by_its_field_and_state(backend):
    """The divergence a vessel target causes names the target (``guidance.targets[j]``, its label)
    and its non-finite state, then the command it made non-finite — in either loop."""
    from shipgnc.errors import DivergenceError

    kinematic = {"north": 11112.0, "east": -3000.0, "course_deg": 180.0, "speed": U}
    stiff = {"north": 11112.0, "east": 150.0, "course_deg": 180.0, "speed": U, "name": "Stiff",
             "waypoints": [[11112.0, 5000.0]],
             "vessel": {"model": "nomoto", "K": 0.1, "T": 1.0, "n3": 1e6}}
    pattern = (r"simulation diverged at t = 2 s: vessel target guidance\.targets\[1\] \(Stiff\): "
               r"its state '(north|east|psi|r|delta)' = (nan|-?inf) (m|rad|rad/s) \(not finite\); "
               r"the references from it made the controller command 'delta_c' = nan rad")
    with pytest.raises(DivergenceError, match=pattern):
        _run([kinematic, stiff], t_end=60.0, extra=(f"simulation.backend={backend}",))


def test_frigate_steady_turn_is_the_norrbin_root():
    """Van Amerongen's frigate at 9 m/s (K, T, n₃ of its table) with 20° rudder: the steady yaw rate
    is the real root of n₃ r³ + r = Kδ (Norrbin), and the tactical-scale turning radius U/r."""
    K, T, n3 = frigate_gains(U)
    tg = _target(K=K, T=T, n3=n3)
    p, s = tg.params(0, flat()), _state(tg)
    delta = math.radians(20.0)
    s[4] = s[5] = delta
    for _ in range(20):
        integrate_vessel(s, p, 10.0 * T / 10)  # 20 T in all
    roots = np.roots([n3, 0.0, 1.0, -K * delta])
    r = float(roots[np.abs(roots.imag) < 1e-12].real[0])
    assert s[3] == pytest.approx(r, rel=1e-6)
    assert r < K * delta  # the cubic term limits the turn


def test_heading_loop_is_the_linear_second_order_closed_loop():
    """A target 5° off its straight path with a lookahead so long that ψ_d = 0: the PD autopilot
    (sampled every 0.1 s, a fast servo, no rudder limit reached) on T ṙ + r = Kδ is the closed loop
    T ψ̈ + (1 + K K_D) ψ̇ + K K_P ψ = 0, solved by the matrix exponential; to 1 % of the step."""
    Kp, Kd = 1.0, 20.0
    tg = _target(psi=math.radians(5.0), Kp=Kp, Kd=Kd, T_delta=0.02, delta_rate=10.0,
                 delta_max=math.radians(60.0), lookahead=1e12)
    p, s = tg.params(0, flat()), _state(tg)
    K, T = tg.K, tg.T
    A = np.array([[0.0, 1.0], [-K * Kp / T, -(1 + K * Kd) / T]])
    own = np.array([1e9, 1e9, 0.0, 0.0])  # far away
    times = np.arange(0.0, 300.0 + 1e-9, 0.1)
    psi = np.empty(times.size)
    for k, t in enumerate(times):
        vessel_target_sample(t, own, p, s, 0, 5.0)
        psi[k] = s[2]
    exact = np.array([(expm(A * t) @ [math.radians(5.0), 0.0])[0] for t in times[::50]])
    np.testing.assert_allclose(psi[::50], exact, atol=0.01 * math.radians(5.0))


def test_track_along_waypoints_turns_onto_the_next_leg():
    """From (0, 0) north to (3000, 0), then east to (3000, 4000): the target switches legs, settles
    on the second leg (cross-track < 1 m, heading east within 0.1°) and holds its speed (each
    sample's chord that of an arc no tighter than the rudder limit's)."""
    tg = _target(waypoints=[[3000.0, 0.0], [3000.0, 4000.0]], lookahead=500.0)
    p, s = tg.params(0, flat()), _state(tg)
    own = np.array([1e9, 1e9, 0.0, 0.0])
    path = []
    for t in np.arange(0.0, 700.0, 0.5):
        vessel_target_sample(t, own, p, s, 0, 5.0)
        path.append((s[0], s[1]))
    path = np.array(path)
    assert abs(s[0] - 3000.0) < 1.0
    assert s[2] == pytest.approx(math.pi / 2, abs=math.radians(0.1))
    assert s[1] > 2000.0
    # constant speed: each 0.5 s chord of the arc is U h sin(x)/x, x = r h/2, r ≤ K δ_max
    steps = np.hypot(*np.diff(path, axis=0).T)
    x = tg.K * tg.delta_max * 0.5 / 2
    assert np.all(steps <= U * 0.5 * (1 + 1e-12))
    assert np.all(steps >= U * 0.5 * math.sin(x) / x)
    # the advance past the corner's line: at most the distance sailed before the yaw rate builds
    # (T + T_δ + δ_max/δ̇_max) plus the radius of the hardest turn U/(K δ_max)
    advance = U * (tg.T + tg.T_delta + tg.delta_max / tg.delta_rate) + U / (tg.K * tg.delta_max)
    assert 0.0 < path[:, 0].max() - 3000.0 < advance


def test_straight_running_vessel_target_meets_the_own_ship_as_the_kinematic_one():
    """A frigate target on its course with waypoints ahead on that course sails the kinematic
    target's track: the same encounter (range, time, target states) with and without SB-MPC."""
    kin = {"name": "t", "north": 11112.0, "east": 150.0, "course_deg": 180.0, "speed": U}
    ves = {**kin, "vessel": {"model": "frigate"}, "waypoints": [[0.0, 150.0]]}
    for method in ("none", "sbmpc"):
        a, b = _run([kin], method), _run([ves], method)
        for key in ("min_range_m", "t_min_range_s", "collision", "max_cross_track_m"):
            assert b.metrics[key] == pytest.approx(a.metrics[key], abs=1e-6), key
        for key in ("target_north", "target_east", "target_sog", "target_cog"):
            np.testing.assert_allclose(b.result[key].values, a.result[key].values, atol=1e-6)


def test_head_on_both_ships_turn_to_starboard():
    """Rule 14 both ways: own ship and target on reciprocal courses 50 m apart, each running SB-MPC
    with the other as ground truth — the own ship alters to starboard (east), the target to its
    starboard (west, heading past 180°) at the same decision, they pass port to port and clear the
    200 m domain. (Exactly on one line the first ship to decide turns and the other, seeing it
    turn away, may hold: each judges the other's present velocity.)"""
    target = [{"name": "t", "north": 11112.0, "east": 50.0, "course_deg": 180.0, "speed": U,
               "vessel": {"model": "frigate"}, "avoidance": "sbmpc"}]
    run = _run(target, "sbmpc", t_end=900.0)
    ds, m = run.result, run.metrics
    assert m["collision"] == 0 and m["min_range_m"] > 200.0
    own_east, target_east = ds["east"].values, ds["target_east"].values[:, 0]
    offset = ds["course_cmd"].values - ds["course_nominal"].values
    assert offset[np.flatnonzero(np.abs(offset) > 1e-9)[0]] > 0  # own: starboard
    cog = np.degrees(ds["target_cog"].values[:, 0])
    assert cog[np.flatnonzero(np.abs(cog - 180.0) > 0.01)[0]] > 180.0  # target: starboard
    assert own_east.max() > 20.0 and target_east.min() < 50.0 - 20.0
    k = int(np.argmin(np.abs(ds["time"].values - m["t_min_range_s"])))
    assert own_east[k] > target_east[k]  # port to port


def _crossing_from_port(avoidance):
    """A frigate target at 7 m/s on course 90° from the own ship's port side, on a collision course
    (both at north 8100 m at t = 900 s): it has the own ship on its starboard side and gives way
    (rule 15); the own ship, without avoidance, stands on."""
    target = {"name": "t", "north": U * 900.0, "east": -7.0 * 900.0, "course_deg": 90.0,
              "speed": 7.0}
    if avoidance:
        target.update(vessel={"model": "frigate"}, avoidance=avoidance)
    return _run([target], "none", t_end=1100.0)


def _first_turn(run, course_deg):
    cog = np.degrees(run.result["target_cog"].values[:, 0])
    k = np.flatnonzero(np.abs(cog - course_deg) > 0.01)[0]
    return float(run.result["time"].values[k]), float(cog[k] - course_deg)


def _passes_astern_and_clear(run):
    ds, m = run.result, run.metrics
    assert m["collision"] == 0 and m["min_range_m"] > 200.0
    assert m["max_cross_track_m"] < 1e-6  # the own ship stood on
    k = int(np.argmin(np.abs(ds["time"].values - m["t_min_range_s"])))
    assert ds["target_north"].values[k, 0] < ds["north"].values[k]  # astern of the own ship


def test_give_way_vo_target_alters_to_starboard_while_the_own_ship_stands_on():
    """Rules 15–17 with the velocity obstacles (Kuwata et al. 2014): the give-way target's
    alteration is to starboard, it passes astern of the own ship, which stands on, and the two
    clear the domain; the kinematic target on that course collides."""
    assert _crossing_from_port(None).metrics["collision"] == 1
    run = _crossing_from_port("vo")
    assert _first_turn(run, 90.0)[1] > 0
    _passes_astern_and_clear(run)


def test_give_way_sbmpc_target_first_alters_to_port_at_ship_scale():
    """A departure from the paper's described behaviour, shown, not hidden: as a give-way target
    with the ship-scale settings (d_safe = 200 m, d_close = 1000 m, T = 100 s) SB-MPC's first
    alteration is 15° to *port*, at the first decision at which the own ship comes within d_close
    inside the horizon: closing at |v_rel| = √(9² + 7²) m/s on a collision course the range at the
    horizon's end is |v_rel| (τ − T), ≤ d_close once τ ≤ T + d_close/|v_rel| = 187.7 s before the
    collision, so at the first 5 s decision instant after that (τ = 185 s), the turn showing in the
    course before the next one. Holding course then costs κ = 3
    (a crossing target within d_close on the starboard side inside the horizon); the port turn
    opens the range enough that d_close is not reached within T, so μ = 0 and it costs only
    (k_χ,p + k_Δχ,p)(π/12)² = 0.19. The method alone, at that geometry, chooses the same (so the
    integration adds nothing); later it turns hard to starboard, passes astern and clears."""
    from shipgnc.colav.sbmpc import SBMPCConfig, sbmpc_choose, sbmpc_params

    c, interval = SBMPCConfig(), 5.0  # the scenario's horizon, d_close and decision interval
    tau_reach = c.horizon + c.d_close / math.hypot(U, 7.0)
    t_decide = interval * math.ceil((900.0 - tau_reach) / interval)
    run = _crossing_from_port("sbmpc")
    t_turn, first = _first_turn(run, 90.0)
    assert first < 0 and t_decide < t_turn < t_decide + interval
    _passes_astern_and_clear(run)
    assert np.degrees(run.result["target_cog"].values[:, 0]).max() > 90.0 + 30.0
    tm = 900.0 - t_decide  # the method alone, the same geometry at that decision
    out = np.zeros(2)
    sbmpc_choose(0.0, np.array([0.0, -7.0 * tm, math.pi / 2, 7.0]), np.array([-U * tm, 0.0, U, 0.0]),
                 1, np.array([math.pi / 2, 7.0]),
                 sbmpc_params(SBMPCConfig(d_safe=200.0, speed_factors=[1.0])), np.zeros(2), out)
    assert math.degrees(out[0]) - 90.0 == pytest.approx(-15.0)


def test_compiled_loop_runs_the_vessel_targets_as_the_numpy_loop():
    """The composed compiled loop and the numpy loop integrate the same vessel targets (one own
    ship, a head-on target running SB-MPC and a kinematic crosser): the same encounter to
    round-off."""
    targets = [{"name": "v", "north": 11112.0, "east": 50.0, "course_deg": 180.0, "speed": U,
                "vessel": {"model": "frigate"}, "avoidance": "sbmpc"},
               {"name": "k", "north": 6000.0, "east": -6000.0, "course_deg": 80.0, "speed": 6.0}]
    a = _run(targets, "sbmpc", t_end=800.0)
    b = _run(targets, "sbmpc", t_end=800.0, extra=("simulation.backend=auto",))
    for key in ("min_range_m", "t_min_range_s", "cpa_target", "max_cross_track_m"):
        assert b.metrics[key] == pytest.approx(a.metrics[key], rel=1e-9, abs=1e-9), key
    for key in ("north", "east", "target_north", "target_east", "target_cog"):
        np.testing.assert_allclose(b.result[key].values, a.result[key].values, atol=1e-6)


def test_each_batch_member_moves_its_own_targets():
    """One batch of two encounters — a steering SB-MPC target and, in the other member, a kinematic
    crosser and a second steering target — gives each member the run it has alone (the targets'
    blocks padded per member, slots a member does not use left empty)."""
    from shipgnc.guidance.colav import ColavGuidance
    from shipgnc.scenarios.runner import build
    from shipgnc.sim.simulator import simulate
    from shipgnc.study.encounter_scores import batch_arrays

    head_on = {"name": "v", "north": 11112.0, "east": 50.0, "course_deg": 180.0, "speed": U,
               "vessel": {"model": "frigate"}, "avoidance": "sbmpc"}
    crosser = {"name": "k", "north": 6000.0, "east": -6000.0, "course_deg": 80.0, "speed": 6.0}
    wide = {"name": "w", "north": 9000.0, "east": 3000.0, "course_deg": 250.0, "speed": 7.0,
            "vessel": {"model": "frigate"}, "avoidance": "vo"}
    members = [[head_on], [crosser, wide]]
    alone = [_run(m, "sbmpc", t_end=600.0) for m in members]
    scenarios = [load_scenario("colav-head-on", ["runs=null", "guidance.method=sbmpc",
                                                 f"guidance.targets={json.dumps(m)}"])
                 for m in members]
    setups = [build(sc) for sc in scenarios]
    setup, g = setups[0], scenarios[0].guidance
    encounters = [s.guidance.members[0] for s in setups]  # the targets as each run builds them
    guidance = ColavGuidance(setup.guidance.los, encounters, methods=["sbmpc", "sbmpc"],
                             configs={"sbmpc": g.sbmpc, "vo": g.vo})
    result = simulate(setup.model, np.tile(setup.x0, (2, 1)), t_end=600.0, dt=0.5,
                      controller=setup.controller, actuator=setup.actuator, guidance=guidance,
                      u0=setup.u0, backend="numpy")
    result = guidance.add_targets(result)
    scores = batch_arrays(result, guidance, 200.0)
    for k, run in enumerate(alone):
        assert scores["min_range_m"][k] == pytest.approx(run.metrics["min_range_m"], rel=1e-12)
        n = len(members[k])
        np.testing.assert_allclose(result["target_north"].values[:, k, :n],
                                   run.result["target_north"].values, atol=1e-9)
    assert np.all(np.isnan(result["target_north"].values[:, 0, 1]))  # member 0 has one target


@pytest.mark.parametrize("target, message", [
    ({"vessel": {"model": "frigate"}, "schedule": [{"t": 0, "course_deg": 0, "speed": 5}]},
     "schedule with a vessel target"),
    ({"waypoints": [[0.0, 1.0]], "speed": 5.0}, "waypoints needs a vessel target"),
    ({"vessel": {"model": "nomoto", "K": 0.1}, "speed": 5.0}, "model nomoto needs K"),
    ({"vessel": {"model": "frigate", "T": 10.0}, "speed": 9.0}, "T with model frigate"),
    ({"vessel": {"model": "frigate"}, "speed": 0.0}, "speed > 0"),
    ({"vessel": {"model": "frigate"}, "speed": 20.0},
     r"guidance.targets\[0\].speed = 20 m/s is outside the frigate model's valid range 5–12"),
    ({"vessel": {"model": "frigate"}, "speed": 9.0, "waypoints": [[9000.0, 0.0], [9000.0, 3000.0]]},
     r"^guidance\.targets\[0\]\.waypoints: repeat a point \(or the start\)$"),
    ({"vessel": {"model": "frigate", "switch_radius": 5000.0}, "speed": 9.0,
      "waypoints": [[12000.0, 0.0]]},
     r"^guidance\.targets\[0\]\.vessel\.switch_radius = 5000 m must be shorter than the "
     r"shortest leg \(3000 m\)$"),
])
def test_bad_vessel_targets_are_one_line_naming_the_field(target, message):
    from shipgnc.errors import ConfigError

    entry = {"north": 9000.0, "east": 0.0, **target}
    with pytest.raises(ConfigError, match=message) as info:
        _run([entry])
    assert "\n" not in str(info.value).strip()
