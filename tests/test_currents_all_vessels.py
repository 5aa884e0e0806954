"""The scenario ``current`` section on every vessel that takes it, the catamaran and the Mariner
included: an earth-fixed current as relative velocity ν_r = ν − ν_c (Fossen 2021 §10.3).

Closed forms: in a current constant in NED the motion through the water is the still-water motion
and the track over ground is the still-water track moved by c·t (for the catamaran, whose state is
ν over ground, ν_r = ν − R(ψ)ᵀc obeys ν̇_r = f(ν_r); for the Mariner, whose u and r are through the
water, the current enters the kinematics only); a ship held on a straight track across a current
V⊥ steers the crab angle asin(V⊥/U), U its speed through the water, and plain LOS holds it at the
cross-track offset Δ·tan(asin(V⊥/U)) where the LOS angle equals the crab. The composed compiled
loop equals the numpy loop (1e-9 relative or 1e-12 absolute) with the same field objects."""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

from shipgnc.cases import catamaran as C
from shipgnc.environment.current_field import CurrentDisturbance, GaussMarkovCurrent
from shipgnc.environment.fields import SumField, UniformCurrent
from shipgnc.errors import ConfigError
from shipgnc.models.catamaran import EAST, NORTH, U, V
from shipgnc.models.mariner import MarinerParams, MarinerWitOppe, MarinerYawDisturbance
from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import build, run_scenario
from shipgnc.scenarios.schema import CURRENT_VESSELS
from shipgnc.sim.simulator import simulate

RTOL, ATOL = 1e-9, 1e-12
VN, VE = 0.3, -0.4  # a current towards the south-east, 0.5 m/s
UNIFORM = f"uniform:north={VN},east={VE}"
GM = ("gauss-markov:speed=0.4,direction=60,speed_std=0.1,speed_tau=40,direction_std=15,"
      "direction_tau=60,step=1.2")


def _equal(a, b, names):
    for k in names:
        np.testing.assert_allclose(a[k].values, b[k].values, rtol=RTOL, atol=ATOL, err_msg=k)


# ----------------------------------------------------------------------------------------------
# the schema: which vessels take a current, the Mariner's legacy cross current
# ----------------------------------------------------------------------------------------------

def test_current_section_on_catamaran_and_mariner():
    assert set(CURRENT_VESSELS) == {"vectored-thrust-boat", "cybership2", "catamaran", "mariner"}
    cat = load_scenario("catamaran-turn", [f"current={UNIFORM}"])
    assert cat.current.field == UNIFORM
    disturbances = [build(cat, name).disturbance for name in cat.variants]
    assert len({id(d) for d in disturbances}) == 2  # every run with its own object
    for name in cat.variants:
        setup = build(cat, name)
        assert isinstance(setup.disturbance, CurrentDisturbance)
        setup.disturbance.bind_model(setup.model)  # as the simulator does at the run's start
        assert setup.disturbance.position_index == (NORTH, EAST)  # found by name
    setup = build(cat)
    assert setup.disturbance is not None
    np.testing.assert_array_equal(setup.disturbance(0.0, setup.x0), [0, 0, 0, VN, VE])
    # without the section the catamaran's runs stay in calm water
    calm = load_scenario("catamaran-turn")
    assert all(build(calm, name).disturbance is None for name in calm.variants)

    mar = load_scenario("mariner-los-fl", ["disturbance.d_y_nm_min=0", f"current={UNIFORM}"])
    d = build(mar).disturbance
    assert isinstance(d, CurrentDisturbance) and isinstance(d.force, MarinerYawDisturbance)
    x = np.array([100.0, -50.0, 0.3, 7.7, 0.0])
    d.reset((), np.random.default_rng(0))
    np.testing.assert_allclose(d(0.0, x), [0.1 / 3600.0, VN, VE], rtol=1e-15)  # b_r kept
    # a current section alone: no b_r, no d_y
    alone = load_scenario("mariner-los-fl", ["disturbance=null", f"current={UNIFORM}"])
    assert alone.disturbance is None
    d = build(alone).disturbance
    d.reset((), np.random.default_rng(0))
    np.testing.assert_array_equal(d(0.0, x), [0.0, VN, VE])


@pytest.mark.parametrize("overrides,match", [
    (["current=uniform:north=0,east=0.5"], "d_y_nm_min"),  # the built-in's d_y = 0.04 nm/min
    (["disturbance.d_y_nm_min=0", "controller.knows_disturbance=true",
      "current=uniform:north=0,east=0.5"], "knows_disturbance"),
])
def test_mariner_current_refused_with_a_second_current_or_the_oracle(overrides, match):
    with pytest.raises(ConfigError, match=match):
        load_scenario("mariner-los-fl", overrides)


def test_current_refused_where_it_does_not_apply():
    from shipgnc.scenarios.registry import raw_scenario, validate

    data, source = raw_scenario("mariner-cst-heading")  # a catalogue vessel: no current section
    with pytest.raises(ConfigError, match=r"vessel models .*catamaran.*not to vessel model 'mariner-cst'"):
        validate({**data, "current": "uniform:north=0,east=0.5"}, source)


def test_mariner_cross_current_default_is_earth_fixed_and_builtins_keep_path():
    """A user's own Mariner disturbance takes d_y along east (earth-fixed) unless it says ``path``;
    every document-000 scenario says ``path`` (the document's reading, A10)."""
    from shipgnc.scenarios import builtin
    from shipgnc.scenarios.schema import MarinerDisturbanceConfig

    assert MarinerDisturbanceConfig(type="mariner").current_frame == "global"
    from pathlib import Path

    folder = Path(builtin.__file__).parent
    mariner = [p for p in sorted(folder.glob("*.yaml"))
               if (yaml.safe_load(p.read_text()).get("vessel") or {}).get("model") == "mariner"]
    assert len(mariner) >= 8
    for path in mariner:
        data = yaml.safe_load(path.read_text())
        assert data["disturbance"]["current_frame"] == "path", path.name
        assert load_scenario(path.stem).disturbance.current_frame == "path"


# ----------------------------------------------------------------------------------------------
# closed forms: the motion through the water is the still-water motion, the track drifts by c·t
# ----------------------------------------------------------------------------------------------

def _catamaran_pair(case_of, dt=None):
    """(calm, current) runs of a controller-free catamaran case, ``case_of(current spec or None)``,
    the current run starting with the calm run's velocity through the water (ψ(0) = 0: body axes
    are NED)."""
    runs = []
    for current in (None, UNIFORM):
        case = case_of(current)
        assert case.controller is None and (case.disturbance is None) == (current is None)
        x0 = np.array(case.x0, dtype=float)
        if current is not None:
            x0[U] += VN  # ψ(0) = 0: the body axes are north, east
            x0[V] += VE
        kw = case.simulate_kwargs()
        if dt is not None:
            kw["dt"] = dt
        runs.append(simulate(case.model, x0, **kw, backend="numpy"))
    return runs


def _through_water(ds):
    psi = ds.psi.values
    u_r = ds.u.values - (np.cos(psi) * VN + np.sin(psi) * VE)
    v_r = ds.v.values - (-np.sin(psi) * VN + np.cos(psi) * VE)
    t = ds.time.values
    return {"u": u_r, "v": v_r, "r": ds.r.values, "psi": psi, "delta": ds.delta.values,
            "north": ds.north.values - VN * t, "east": ds.east.values - VE * t}


def test_catamaran_straight_run_drifts_by_current_times_time():
    """S1 (δ = 0, no controller) in a uniform current: ψ stays 0, so ν_r = ν − c exactly; the
    motion through the water is S1's and the track is S1's moved by c·t (round-off level)."""
    calm, drift = _catamaran_pair(
        lambda cur: C.straight(t_end=300.0) if cur is None else C.with_current(
            C.straight(t_end=300.0), cur))
    got = _through_water(drift)
    for k in ("u", "v", "r", "psi", "delta"):
        np.testing.assert_allclose(got[k], calm[k].values, rtol=0, atol=1e-12, err_msg=k)
    for k in ("north", "east"):
        np.testing.assert_allclose(got[k], calm[k].values, rtol=0, atol=1e-9, err_msg=k)
    assert drift.north.values[-1] - calm.north.values[-1] == pytest.approx(VN * 300.0, rel=1e-12)
    assert drift.east.values[-1] - calm.east.values[-1] == pytest.approx(VE * 300.0, rel=1e-12)


def test_catamaran_turning_circle_drifts_by_current_times_time():
    """The fixed-angle run of ``catamaran-fixed-angle`` (δ held, no controller; 1.6 turns in
    300 s) built from the scenario with a ``current`` section: its motion through the water is the
    calm run's and its circle drifts by c·t. The rotating current is integrated by RK4 with ν over
    ground, so the two agree to RK4's truncation error, O(dt⁴): halving dt divides it by ≈ 16."""
    def fixed(current):
        extra = [] if current is None else [f"current={current}"]
        scenario = load_scenario("catamaran-fixed-angle", ["simulation.t_end=300", *extra])
        setup = build(scenario, "fixed")
        return C.CatamaranCase("fixed", setup.model, setup.x0, setup.controller, setup.guidance,
                               t_end=300.0, disturbance=setup.disturbance)

    errors = []
    for dt in (C.DT, C.DT / 2):
        calm, drift = _catamaran_pair(fixed, dt)
        assert abs(calm.psi.values[-1]) > 2 * math.pi  # it really turns
        got = _through_water(drift)
        err = max(np.max(np.abs(got[k] - calm[k].values)) / max(1.0, np.max(np.abs(calm[k].values)))
                  for k in ("u", "v", "r", "psi", "north", "east"))
        errors.append(err)
    assert errors[0] < 1e-9
    assert errors[1] < errors[0] / 8  # fourth order: the difference is the integrator's


@pytest.mark.parametrize("backend", ["numpy", "compiled"])
def test_mariner_turn_drifts_by_current_times_time(backend):
    """The Mariner in a steady 10° rudder turn (no controller) in a uniform current: u, r, ψ (through
    the water) are the calm run's bit for bit — the hull equations do not see the current — and the
    turning circle drifts by c·t (RK4 integrates a constant exactly: round-off)."""
    model = MarinerWitOppe()
    x0 = np.zeros((2, 5))
    x0[:, 3] = model.params.U
    x0[1, 2] = 1.0
    current = UniformCurrent(VN, VE)
    calm, drift = (simulate(model, x0, t_end=1800.0, dt=0.3, u0=[math.radians(10.0)],
                            disturbance=d, backend=backend)
                   for d in (None, CurrentDisturbance(current, n_force=1)))
    assert drift.attrs["backend"] == backend
    for k in ("u", "r", "psi"):
        np.testing.assert_array_equal(drift[k].values, calm[k].values, err_msg=k)
    t = drift.time.values[:, None]
    np.testing.assert_allclose(drift.north.values - VN * t, calm.north.values, rtol=0, atol=1e-9)
    np.testing.assert_allclose(drift.east.values - VE * t, calm.east.values, rtol=0, atol=1e-9)
    assert np.ptp(calm.north.values) > 1000.0  # a real circle, several hundred metres across


@pytest.mark.parametrize("V", [1.0, 2.5])
def test_mariner_los_settles_at_the_crab_angle(V):
    """Integral LOS on a straight leg north across an earth-fixed current V towards east: the ship
    settles on the track (course over ground north) heading −asin(V/U) (U = S/f = 7.7167 m/s, its
    speed through the water; r = 0 gives v = 0): 7.45° for 1 m/s, 18.90° for 2.5 m/s. Tolerance
    0.01°, set by how far the integral has settled in 100 min (the run's last 30 min: ≈ 1e-4°)."""
    U = MarinerParams().U
    common = ["guidance.points_nm=[[0,0],[0,40]]", "disturbance=null",
              f"current=uniform:north=0,east={V}", "simulation.t_end=6000",
              "simulation.backend=numpy"]
    ds = run_scenario("mariner-los-fl", overrides=common).result
    crab = -math.asin(V / U)
    late = ds.time.values >= 4200.0
    np.testing.assert_allclose(ds.psi.values[late], crab, atol=math.radians(0.01))
    assert np.max(np.abs(ds.east.values[late])) < 0.01 * 1852.0  # on the track (0.01 nm)
    # plain LOS: the same crab, held where the LOS angle −atan(e/Δ) equals it, e = Δ tan(asin(V/U))
    plain = run_scenario("mariner-los-fl", overrides=[*common,
                                                      "controller.integral_gain_nm_min=0"]).result
    late = plain.time.values >= 4200.0
    np.testing.assert_allclose(plain.psi.values[late], crab, atol=math.radians(0.01))
    offset = 0.5 * 1852.0 * math.tan(math.asin(V / U))
    np.testing.assert_allclose(plain.east.values[late], offset, rtol=1e-3)


# ----------------------------------------------------------------------------------------------
# the composed compiled loop equals the numpy loop
# ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("waves", [False, True])
def test_mariner_compiled_equals_numpy_in_a_field_and_gauss_markov_current(waves):
    """``mariner-los-fl`` with b_r, a uniform + Gauss–Markov current (and wave noise: the current
    then held over each step with it): the composed loop's run equals the numpy run."""
    overrides = ["disturbance.d_y_nm_min=0", f"current={UNIFORM}+{GM}", "simulation.t_end=900"]
    if waves:
        overrides.append("disturbance.wave_heading_sigma_deg=1.0")
    scenario = load_scenario("mariner-los-fl", overrides)
    d = build(scenario).disturbance
    assert d.per_stage is (not waves)
    runs = [run_scenario("mariner-los-fl", overrides=[*overrides, f"simulation.backend={b}"]).result
            for b in ("numpy", "compiled")]
    assert [r.attrs["backend"] for r in runs] == ["numpy", "compiled"]
    _equal(runs[1], runs[0], ("north", "east", "psi", "u", "r", "delta"))
    # the current acts: the same run without it ends elsewhere
    calm = run_scenario("mariner-los-fl", overrides=["simulation.t_end=900",
                                                     "disturbance.d_y_nm_min=0",
                                                     "simulation.backend=numpy"]).result
    assert abs(float(calm.north[-1]) - float(runs[0].north[-1])) > 100.0  # along the first leg


def test_catamaran_compiled_equals_numpy_in_a_field_and_gauss_markov_current():
    """``catamaran-heading`` (law (21), heading capture) in a uniform + Gauss–Markov current: the
    composed loop equals the numpy loop, and the current moves the track."""
    overrides = ["simulation.t_end=300", f"current={UNIFORM}+{GM}"]
    runs = [run_scenario("catamaran-heading", overrides=[*overrides, f"simulation.backend={b}"])
            for b in ("numpy", "compiled")]
    assert [r.result.attrs["backend"] for r in runs] == ["numpy", "compiled"]
    _equal(runs[1].result, runs[0].result, ("u", "v", "r", "north", "east", "psi", "delta"))
    calm = run_scenario("catamaran-heading", overrides=["simulation.t_end=300",
                                                        "simulation.backend=numpy"]).result
    moved = np.hypot(float(calm.north[-1] - runs[0].result.north[-1]),
                     float(calm.east[-1] - runs[0].result.east[-1]))
    assert moved > 50.0


def test_mariner_yaw_channel_alone():
    """The yaw channel beside a scenario current: [b_r (+ waves)], one channel, per stage without
    waves."""
    yaw = MarinerYawDisturbance(0.002)
    x = np.zeros((4, 5))
    yaw.reset((4,), np.random.default_rng(0))
    np.testing.assert_array_equal(yaw(0.0, x), np.full((4, 1), 0.002))
    assert yaw.per_stage
    field = SumField([UniformCurrent(0.1, 0.2), GaussMarkovCurrent(0.3, 1.0)])
    d = CurrentDisturbance(field, yaw, n_force=1)
    d.reset((4,), np.random.default_rng(0))
    np.testing.assert_allclose(d(0.0, x)[0], [0.002, 0.1 + 0.3 * math.cos(1.0),
                                              0.2 + 0.3 * math.sin(1.0)], rtol=1e-15)
