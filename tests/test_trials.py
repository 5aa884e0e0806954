"""Standard manoeuvring trials (shipgnc.trials; docs/trials.md).

Every expected value comes from a closed form or from the published coefficients, never from
shipgnc's own output:

* first-order Nomoto ship: steady r = Kδ, steady radius U/(Kδ) (Nomoto et al. 1957);
* linear course-stable 3-DOF model: the steady turn solves N ν = B δ (Fossen 2021, §7.2);
* Norrbin's course-unstable model T ṙ + a₃r³ − r = Kδ (Norrbin 1963): its equilibria δ = H(r)/K
  have turning points at r* = ±1/√(3a₃), so the spiral loop is 4r*/(3K) wide and the pull-out
  residual yaw rates are ±1/√a₃;
* IMO MSC.137(76) §5 limits computed by hand for given L/V;
* the Chislett & Strøm-Tejsen (1965) Mariner (Fossen's MSS ``mariner.m`` coefficients): its trim
  rudder and its course stability follow from the published linear coefficients.

Literature trial figures for the Mariner model: we searched for published turning-circle and
zig-zag numbers of this model (Fossen's Handbook and MSS examples, papers using the model) and did
not find numbers we could cite with their conditions; rather than invent them, the Mariner checks
below use closed forms from the published coefficients. See docs/trials.md.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

from shipgnc.cli import app
from shipgnc.models.base import Signal
from shipgnc.trials import core, imo, pullout, spiral, stopping, turning, zigzag

runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


# --------------------------------------------------------------------------- closed forms


def test_nomoto_turning_circle_closed_form():
    K, T, U, rudder = 0.05, 20.0, 7.7, 10.0
    res = turning.turning_circle("nomoto", rudder, K=K, T=T, speed_mps=U)
    assert res["trim_rudder_deg"] == pytest.approx(0.0, abs=1e-9)
    for side, s in (("starboard", 1.0), ("port", -1.0)):
        r = res["sides"][side]
        r_ss = K * math.radians(rudder)
        assert math.radians(r["steady_yaw_rate_deg_s"]) == pytest.approx(s * r_ss, rel=1e-3)
        assert r["steady_turning_radius_m"] == pytest.approx(U / r_ss, rel=1e-3)
        assert r["speed_loss_pct"] == pytest.approx(0.0, abs=1e-9)  # constant-speed model


def test_nomoto_advance_transfer_tactical_diameter_by_quadrature():
    # instantaneous rudder step δ at t = 0: ψ(t) = Kδ (t − T (1 − e^{−t/T})) in closed form; the
    # track is the quadrature of U (cos ψ, sin ψ) up to the times ψ = 90° and 180°
    from scipy import integrate, optimize

    from shipgnc.models.nomoto import NomotoModel

    K, T, U, rudder = 0.05, 20.0, 7.7, 10.0
    Om = K * math.radians(rudder)

    def psi(t):
        return Om * (t - T * (1 - math.exp(-t / T)))

    def pos(t):
        n = integrate.quad(lambda s: U * math.cos(psi(s)), 0, t, epsabs=1e-9, limit=200)[0]
        e = integrate.quad(lambda s: U * math.sin(psi(s)), 0, t, epsabs=1e-9, limit=200)[0]
        return n, e

    t90 = optimize.brentq(lambda t: psi(t) - math.pi / 2, 1, 1e4)
    t180 = optimize.brentq(lambda t: psi(t) - math.pi, 1, 1e4)
    adv, tr = pos(t90)
    td = pos(t180)[1]
    ship = core.prepare(NomotoModel(K, T, U=U), dt=0.1)
    res = turning.turning_circle(ship=ship, rudder_deg=rudder, sides=("starboard",))
    assert res["advance_m"] == pytest.approx(adv, rel=1e-4)
    assert res["transfer_m"] == pytest.approx(tr, rel=1e-4)
    assert res["tactical_diameter_m"] == pytest.approx(td, rel=1e-4)


def test_linear_3dof_steady_turn_solves_N_nu_B_delta():
    # a course-stable linear model (SI, over surge, sway, yaw; Fossen 2021 §7.2 form)
    M = np.array([[1.1e7, 0, 0], [0, 2.0e7, -1.0e8], [0, -1.0e8, 3.0e10]])
    N = np.array([[5.0e5, 0, 0], [0, 3.0e6, 2.0e8], [0, 4.0e7, 2.5e10]])
    B = np.array([[0.0], [-1.5e6], [1.2e8]])
    U, rudder = 7.0, 5.0
    res = turning.turning_circle("linear-3dof", rudder, sides=("starboard",), speed_mps=U,
                                 M=M.tolist(), N=N.tolist(), B=B.tolist())
    nu = np.linalg.solve(N, B[:, 0] * math.radians(rudder))
    hist = res["_history"]
    assert float(hist.state("r")[-1, 0]) == pytest.approx(nu[2], rel=1e-3)
    assert float(hist.state("v")[-1, 0]) == pytest.approx(nu[1], rel=1e-3)
    assert res["steady_speed_mps"] == pytest.approx(math.hypot(U + nu[0], nu[1]), rel=1e-4)


NORRBIN = {"K": 0.1, "T": 20.0, "a1": -1.0, "a3": 4400.0}


def test_norrbin_unstable_spiral_loop_and_pull_out():
    ship = core.prepare("nomoto", length_m=60.0, **NORRBIN)  # a length so r′ reaches the loop
    res = spiral.spiral(ship=ship)
    r_star = 1.0 / math.sqrt(3.0 * NORRBIN["a3"])
    width = math.degrees(4.0 * r_star / (3.0 * NORRBIN["K"]))  # δ(−r*) − δ(r*) = 4r*/(3K)
    assert not res["stable"]
    assert res["reverse"]["loop_width_deg"] == pytest.approx(width, rel=0.03)
    step = 0.5  # the default grid's spacing near δ₀
    assert abs(res["loop_width_direct_deg"] - width) <= step + 1e-9
    # both branches exist inside the loop: at δ₀ = 0 the descending sweep turns to starboard
    k0 = int(np.argmin(np.abs(np.asarray(res["rudder_deg"]))))
    r_res = math.degrees(1.0 / math.sqrt(NORRBIN["a3"]))  # H(r) = 0: a₃r³ = r
    assert res["yaw_rate_deg_s"]["descending"][k0] == pytest.approx(r_res, rel=1e-3)
    assert res["yaw_rate_deg_s"]["ascending"][k0] == pytest.approx(-r_res, rel=1e-3)
    po = pullout.pull_out(ship=ship, rudder_deg=20.0)
    assert po["residual_yaw_rate_deg_s"]["starboard"] == pytest.approx(r_res, rel=1e-3)
    assert po["residual_yaw_rate_deg_s"]["port"] == pytest.approx(-r_res, rel=1e-3)
    assert not po["stable"]


def test_stable_nomoto_spiral_has_no_loop():
    res = spiral.spiral("nomoto", K=0.1, T=20.0)
    assert res["stable"] and res["loop_width_deg"] == 0.0 and res["loop_width_direct_deg"] == 0.0
    # the steady curve is r = Kδ on both branches
    d = np.radians(res["rudder_deg"])
    for branch in ("descending", "ascending"):
        np.testing.assert_allclose(np.radians(res["yaw_rate_deg_s"][branch]), 0.1 * d, atol=2e-5)


def test_zigzag_on_nomoto_overshoot_from_closed_form():
    # rudder reversal of a Nomoto ship at the ψ crossing: with an instantaneous rudder the yaw rate
    # after the reversal is r(t) = −Kδ + (r₁ + Kδ) e^{−t/T}; it vanishes at t* = T ln(1 + r₁/(Kδ))
    # and the heading has moved on by −Kδ t* + T (r₁ + Kδ)(1 − e^{−t*/T}) = first overshoot
    from shipgnc.models.nomoto import NomotoModel

    K, T, dz = 0.05, 10.0, 10.0
    d, psi = math.radians(dz), math.radians(dz)
    ship = core.prepare(NomotoModel(K, T, U=7.7), dt=0.02)  # a plain model: no steering machine
    res = zigzag.zigzag(None, dz, dz, ship=ship, sides=("starboard",))
    # time to reach ψ: K δ (t − T (1 − e^{−t/T})) = ψ (Newton), then r₁ = K δ (1 − e^{−t/T})
    t = 5.0
    for _ in range(50):
        f = K * d * (t - T * (1 - math.exp(-t / T))) - psi
        t -= f / (K * d * (1 - math.exp(-t / T)))
    r1 = K * d * (1 - math.exp(-t / T))
    ts = T * math.log(1 + r1 / (K * d))
    over = -K * d * ts + T * (r1 + K * d) * (1 - math.exp(-ts / T))
    # the rudder reverses at the first sample past the crossing (dt = 0.02 s): r·dt ≈ 0.01°
    assert res["initial_turning_time_s"] == pytest.approx(t, abs=1e-3)
    assert res["first_overshoot_deg"] == pytest.approx(math.degrees(over), abs=0.02)


class CoastingShip:
    """A straight-running test ship with a reversing propeller: u̇ = c·n|n|/n_max² − b·u|u|.

    Full astern from u₀ decelerates as u̇ = −c − b u², so (closed form) the ship stops after
    t = atan(u₀√(b/c))/√(bc) having run x = ln(1 + b u₀²/c)/(2b) straight ahead."""

    states = tuple(Signal(n, "-") for n in ("north", "east", "psi", "u", "v", "r"))
    inputs = (Signal("delta_c", "rad"), Signal("n_c", "1/s"))
    disturbances = ()
    state_limits = (1e8,) * 6
    b, c, n_max = 2e-3, 0.05, 2.0
    full_astern = -2.0
    params = None

    def derivatives(self, x, u, d=None):
        n = u[..., 1]
        thrust = self.c * n * np.abs(n) / self.n_max**2
        drag = self.b * x[..., 3] * np.abs(x[..., 3])
        zero = np.zeros_like(x[..., 0])
        psi = x[..., 2]
        return np.stack([np.cos(psi) * x[..., 3], np.sin(psi) * x[..., 3], zero,
                         thrust - drag, zero, zero], axis=-1)

    def straight_inputs(self, x):
        return [0.0, self.n_max * math.sqrt(self.b / self.c) * x[3]]


def test_stopping_closed_form():
    m = CoastingShip()
    u0 = 6.0
    res = stopping.stopping(m, speed_mps=u0, length_m=100.0, dt=0.01)
    b, c = m.b, m.c
    assert res["time_s"] == pytest.approx(math.atan(u0 * math.sqrt(b / c)) / math.sqrt(b * c), rel=1e-4)
    reach = math.log(1 + b * u0 * u0 / c) / (2 * b)
    assert res["track_reach_m"] == pytest.approx(reach, rel=1e-4)
    assert res["head_reach_m"] == pytest.approx(reach, rel=1e-4)
    assert res["lateral_deviation_m"] == pytest.approx(0.0, abs=1e-9)


def test_stopping_refused_without_reversing_propulsion():
    with pytest.raises(core.ConfigError, match="no propulsion that can go full astern"):
        stopping.stopping("nomoto", K=0.05, T=20.0)


# --------------------------------------------------------------------------- IMO limits


@pytest.mark.parametrize("lv, first, second", [(5.0, 10.0, 25.0), (10.0, 10.0, 25.0), (20.0, 15.0, 32.5),
                                               (29.9, 19.95, 39.925), (30.0, 20.0, 40.0),
                                               (50.0, 20.0, 40.0)])
def test_imo_overshoot_limits(lv, first, second):
    # MSC.137(76) 5.4: 10 / (5 + L/(2V)) / 20 and 25 / (17.5 + 0.75 L/V) / 40 degrees
    assert imo.first_overshoot_limit_10(lv) == pytest.approx(first)
    assert imo.second_overshoot_limit_10(lv) == pytest.approx(second)
    assert imo.FIRST_OVERSHOOT_LIMIT_20 == 25.0


def test_imo_criteria_report():
    L, V = 160.0, 8.0  # L/V = 20 s
    side = {"advance_m": 700.0, "tactical_diameter_m": 820.0, "initial_turning_distance_m": 300.0,
            "first_overshoot_deg": 14.0, "second_overshoot_deg": 33.0}
    both = {"sides": {"starboard": side, "port": dict(side, advance_m=730.0)}}
    crit = imo.criteria(L, V, both, both, both, {"track_reach_m": 2500.0})
    by = {c["criterion"].split(":")[0] + ":" + c["criterion"].split(":")[1][:22]: c for c in crit}
    vals = {c["criterion"]: (c["value"], c["limit"], c["pass"]) for c in crit}
    assert vals["turning ability: advance"] == (730.0, 4.5 * L, False)  # the worse side
    assert vals["turning ability: tactical diameter"] == (820.0, 5 * L, False)
    assert vals["initial turning: distance to 10° heading change (10° rudder)"] == (300.0, 2.5 * L, True)
    assert vals["yaw checking: 10°/10° first overshoot"] == (14.0, 15.0, True)
    assert vals["course keeping: 10°/10° second overshoot"] == (33.0, 32.5, False)
    assert vals["yaw checking: 20°/20° first overshoot"] == (14.0, 25.0, True)
    assert vals["stopping: track reach (full astern)"] == (2500.0, 15 * L, False)
    assert by  # every criterion named
    crit = imo.criteria(None, V, both, both, both, "no astern")
    assert all(c["pass"] is None for c in crit if c["unit"] == "m")


# --------------------------------------------------------------------------- the Mariner


def test_mariner_trim_rudder_and_stability_from_published_coefficients():
    from shipgnc.vessels.mariner_cst import COEFFICIENTS as c

    ship = core.prepare("mariner-cst")
    # straight running, r = 0, linear terms: Y_v v' + Y_δ δ_h + Y₀ = 0, N_v v' + N_δ δ_h + N₀ = 0
    A = np.array([[c["Yv"], c["Yd"]], [c["Nv"], c["Nd"]]])
    _, d_h = np.linalg.solve(A, [-c["Y0"], -c["N0"]])
    assert math.degrees(ship.delta0[0]) == pytest.approx(-math.degrees(d_h), abs=0.01)  # δ = −δ_h
    # linear course stability (the coefficients' Y_r, N_r include the mass terms, MSS form):
    # C = Y_v N_r − N_v Y_r > 0 → directionally stable → no spiral loop, pull-out decays to 0
    C = c["Yv"] * c["Nr"] - c["Nv"] * c["Yr"]
    assert C > 0
    res = imo.run_all(ship=ship)
    assert res["spiral"]["stable"] and res["spiral"]["loop_width_deg"] == 0.0
    assert res["pull-out"]["stable"]
    # the 35° turning circle: definitions hold (tactical diameter vs the steady circle), IMO
    # report complete, the 20/20 zig-zag reversed at ±20°
    for side in ("starboard", "port"):
        t = res["turning-circle"]["sides"][side]
        assert 0 < t["transfer_m"] < t["tactical_diameter_m"]
        assert t["tactical_diameter_m"] > 2 * t["steady_turning_radius_m"] * 0.9
        z = res["zigzag-20/20"]["sides"][side]
        assert z["first_overshoot_deg"] > 0 and z["second_overshoot_deg"] > 0
    names = [c["criterion"] for c in res["imo"]["criteria"]]
    assert len(names) == 7 and res["stopping"]["error"].startswith("trial stopping")


def test_all_is_one_batch(monkeypatch):
    calls = []
    real = core.run

    def counting(ship, prog, finished, **kw):
        calls.append(prog.size)
        return real(ship, prog, finished, **kw)

    monkeypatch.setattr(core, "run", counting)
    ship = core.prepare("nomoto", K=0.1, T=20.0)
    res = imo.run_all(ship=ship)
    n_spiral = len(res["spiral"]["rudder_deg"])
    assert len(calls) == 1 and n_spiral >= 20
    assert calls[0] == 2 + 2 + 2 + 2 * n_spiral + len(res["spiral"]["reverse"]["rudder_deg"]) + 2


# --------------------------------------------------------------------------- command line


def test_cli_json_keys(tmp_path):
    r = invoke("trial", "turning-circle", "--vessel", "mariner-cst", "--side", "starboard", "--json")
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    for k in ("advance_m", "transfer_m", "tactical_diameter_m", "steady_turning_radius_m",
              "steady_speed_mps", "speed_loss_pct", "trim_rudder_deg"):
        assert k in d and d[k] is not None
    r = invoke("trial", "zigzag", "--vessel", "mariner-cst", "--angles", "10/10", "--json")
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    for k in ("first_overshoot_deg", "second_overshoot_deg", "initial_turning_time_s",
              "heading_extremes", "period_s"):
        assert k in d and d[k] is not None
    assert set(d["sides"]) == {"starboard", "port"}
    assert all(len(e) == 2 for e in d["heading_extremes"])
    f = tmp_path / "v.yaml"
    f.write_text("vessel: {model: nomoto, K: 0.1, T: 20.0, speed_mps: 7.7}\n")
    r = invoke("trial", "pull-out", "--vessel", f, "--json")
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert set(d["residual_yaw_rate_deg_s"]) == {"starboard", "port"} and d["stable"]
    r = invoke("trial", "spiral", "--vessel", f, "--json")
    d = json.loads(r.stdout)
    assert len(d["rudder_deg"]) >= 20 and d["loop_width_deg"] == 0.0
    assert set(d["yaw_rate_deg_s"]) == {"descending", "ascending"}


@pytest.mark.parametrize("args, text", [
    (("trial", "circle", "--vessel", "mariner-cst"), "KIND = 'circle': allowed"),
    (("trial", "zigzag", "--vessel", "titanic"), "unknown vessel"),
    (("trial", "zigzag", "--vessel", "mariner-cst", "--angles", "20"), "--angles = '20'"),
    (("trial", "zigzag", "--vessel", "mariner-cst", "--angles", "a/b"), "expected D/PSI"),
    (("trial", "turning-circle", "--vessel", "mariner-cst", "--side", "aft"), "--side"),
    (("trial", "turning-circle", "--vessel", "mariner-cst", "--speed-kn", "40"), "valid"),
    (("trial", "stopping", "--vessel", "mariner-cst"), "no propulsion that can go full astern"),
])
def test_cli_bad_input_one_line(args, text):
    r = invoke(*args)
    assert r.exit_code == 2
    err = r.stderr.strip()
    assert err.count("\n") == 0 and text in err and "Traceback" not in r.output


def test_zigzag_reversal_at_the_crossing_not_the_sample():
    # the rudder reverses when the heading crosses ±ψ inside a step: the overshoots converge with
    # the step (RK4: ~h⁴) instead of carrying an error ~ r·h from reversing at the next sample
    res = [zigzag.zigzag("mariner-cst", 10.0, 10.0, sides=("starboard",), dt=h) for h in (1.0, 0.25)]
    assert res[0]["first_overshoot_deg"] == pytest.approx(res[1]["first_overshoot_deg"], abs=5e-3)
    assert res[0]["second_overshoot_deg"] == pytest.approx(res[1]["second_overshoot_deg"], abs=5e-3)
    assert res[0]["initial_turning_time_s"] == pytest.approx(res[1]["initial_turning_time_s"], abs=5e-3)


def test_a_trials_time_series_feeds_identification(tmp_path):
    """`trial zigzag --out` writes the manoeuvre's time series; `identify` fits it as a measured log
    and recovers the frigate's Nomoto constants at 9 m/s, K = 0.18 s⁻¹ and T = 27 s (van Amerongen
    1982, as tabulated in MSS frigate.m) — within 2 % (the model is Norrbin's, whose cubic term
    the first-order fit cannot hold)."""
    out = tmp_path / "zz"
    res = runner.invoke(app, ["trial", "zigzag", "--vessel", "frigate", "--angles", "20/20",
                              "--out", str(out)])
    assert res.exit_code == 0, res.output
    log = out / "zigzag_20_20.nc"
    assert log.exists()
    res = runner.invoke(app, ["identify", str(log), "--model", "nomoto1", "--json"])
    assert res.exit_code == 0, res.output
    fit = json.loads(res.stdout)["parameters"]
    assert fit["K"]["value"] == pytest.approx(0.18, rel=0.02)
    assert fit["T"]["value"] == pytest.approx(27.0, rel=0.02)
