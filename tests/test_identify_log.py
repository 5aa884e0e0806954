"""Identification from a logged run (``shipgnc identify``; shipgnc.identify).

Truths are published models, never our own output: van Amerongen's frigate (1982; data as in
Fossen's MSS ``frigate.m``: at U = 9 m/s, K = 0.18 1/s, T = 27 s, Norrbin n₃ = 0.6) and a
Clarke, Gedling & Hine (1983) ship (L = 100 m, B = 15 m, T = 5 m, C_b = 0.7 at 5 m/s) whose
linear coefficients are −M⁻¹N and M⁻¹B of :func:`shipgnc.models.linear3dof.clarke83`.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import yaml
from scipy import stats
from typer.testing import CliRunner

from shipgnc.analysis.identification import zigzag_trial
from shipgnc.cli import app
from shipgnc.errors import ConfigError
from shipgnc.identify import identify_log, identify_nomoto1, read_log
from shipgnc.models.base import state_index
from shipgnc.viz.identify_report import build_vessel, resimulate, vessel_yaml

runner = CliRunner()

FRIGATE_U, FRIGATE_K, FRIGATE_T, FRIGATE_N3 = 9.0, 0.18, 27.0, 0.6
NOISE_R = math.radians(0.05)   # rate-gyro noise [rad/s], 1 sigma
NOISE_PSI = math.radians(0.1)  # compass noise [rad]


def _frigate():
    """The catalogue's frigate at 9 m/s when it exists; else the same published Norrbin model
    (van Amerongen 1982) through shipgnc.models.nomoto with a 10°/s, ±30° steering machine."""
    from shipgnc.vessels import VESSELS

    if "frigate" in VESSELS:
        model = VESSELS["frigate"].build(FRIGATE_U)
        return model, None, model.straight_state(FRIGATE_U)
    from shipgnc.actuators import Actuator
    from shipgnc.models.nomoto import NorrbinModel

    model = NorrbinModel(K=FRIGATE_K, T=FRIGATE_T, a1=1.0, a3=FRIGATE_N3, U=FRIGATE_U)
    act = Actuator(np.array([-math.radians(30)]), np.array([math.radians(30)]),
                   rate=[math.radians(10.0)], names=("delta",))
    return model, act, np.zeros(4)


def test_frigate_switches_to_the_catalogue_entry_when_it_exists():
    """Switch: the frigate checks use shipgnc.vessels' 'frigate' once the catalogue has it, else
    the same published Norrbin model built here (delete the fallback when the entry lands)."""
    from shipgnc.vessels import VESSELS

    model, _, _ = _frigate()
    assert ("frigate" in VESSELS) == hasattr(model, "straight_state")


def _write_csv(path, columns: dict, header_comment: str = ""):
    names = list(columns)
    rows = np.column_stack([np.asarray(columns[n], dtype=float) for n in names])
    with open(path, "w", encoding="utf-8") as fh:
        if header_comment:
            fh.write(f"# {header_comment}\n")
        fh.write(",".join(names) + "\n")
        for row in rows:
            fh.write(",".join(f"{v:.10g}" for v in row) + "\n")
    return path


@pytest.fixture(scope="module")
def frigate_log(tmp_path_factory):
    """A noisy 20°/20° zig-zag of the frigate written as a CSV in degrees (as a logger would)."""
    model, act, x0 = _frigate()
    ds = zigzag_trial(model, act, x0, delta_deg=20, psi_deg=20, t_end=400.0, dt=0.1,
                      rudder_sign=1.0, rudder_index=0)
    rng = np.random.default_rng(19)
    t = ds["time"].values
    r = ds["r"].values + rng.normal(0.0, NOISE_R, t.size)
    psi = ds["psi"].values + rng.normal(0.0, NOISE_PSI, t.size)
    path = tmp_path_factory.mktemp("frigate") / "zigzag.csv"
    _write_csv(path, {"t": t, "rudder_deg": np.degrees(ds["delta"].values),
                      "heading_deg": np.degrees(psi), "yaw_rate_deg_s": np.degrees(r)},
               "frigate 20/20 zig-zag, angles in degrees")
    return path


FRIGATE_COLUMNS = "time=t,rudder=rudder_deg,heading=heading_deg,yaw_rate=yaw_rate_deg_s"


@pytest.fixture(scope="module")
def frigate_fit(frigate_log):
    log = read_log(frigate_log, columns=FRIGATE_COLUMNS, units="deg",
                   need_one_of=("yaw_rate", "heading"))
    return identify_log(log, "nomoto1", speed=FRIGATE_U)


def test_frigate_nomoto_gains_recovered_from_a_noisy_zigzag(frigate_fit):
    """K and T of van Amerongen's frigate within 5 % from its noisy 20/20
    zig-zag (the Norrbin cubic term n₃r³ is < 1 % of r at these yaw rates)."""
    assert frigate_fit.value("K") == pytest.approx(FRIGATE_K, rel=0.05)
    assert frigate_fit.value("T") == pytest.approx(FRIGATE_T, rel=0.05)
    # the held-out last 30 % is predicted to within the gyro noise: NRMSE small
    assert frigate_fit.nrmse_holdout["r"] < 0.1
    assert frigate_fit.condition_number < 100


def _linear_truth():
    from shipgnc.models.linear3dof import clarke83, rudder_input

    U, L, B, T, Cb = 5.0, 100.0, 15.0, 5.0, 0.7
    M, N = clarke83(U, L, B, T, Cb, 0.25 * L, 0.0, L)
    Bd = rudder_input(U, L, T)
    A = -np.linalg.solve(M, N)
    b = np.linalg.solve(M, Bd)[:, 0]
    truth = {"a_uu": A[0, 0], "U": U, "a_vv": A[1, 1], "a_vr": A[1, 2], "a_rv": A[2, 1],
             "a_rr": A[2, 2], "b_v": b[1], "b_r": b[2]}
    return (M, N, Bd, U), truth


@pytest.fixture(scope="module")
def linear_fit(tmp_path_factory):
    """A noisy zig-zag of a Clarke-83 ship starting 0.5 m/s above its speed (surge transient)."""
    from shipgnc.vessels.linear import Linear3DOFVessel

    (M, N, Bd, U), truth = _linear_truth()
    model = Linear3DOFVessel(M, N, Bd, U=U)
    x0 = model.straight_state(U)
    x0[state_index(model, "u")] = U + 0.5
    ds = zigzag_trial(model, None, x0, delta_deg=20, psi_deg=20, t_end=600.0, dt=0.2,
                      rudder_sign=1.0, rudder_index=0)
    rng = np.random.default_rng(83)
    n = ds["time"].size
    cols = {"time": ds["time"].values, "delta": ds["delta"].values,
            "psi": ds["psi"].values + rng.normal(0, NOISE_PSI, n),
            "r": ds["r"].values + rng.normal(0, NOISE_R, n),
            "u": ds["u"].values + rng.normal(0, 0.01, n),
            "v": ds["v"].values + rng.normal(0, 0.01, n)}
    path = _write_csv(tmp_path_factory.mktemp("clarke") / "log.csv", cols)
    log = read_log(path, optional=("heading", "yaw_rate", "u", "v"))
    return identify_log(log, "linear-3dof"), truth, path


def test_clarke83_linear_coefficients_recovered(linear_fit):
    """Every coefficient of −M⁻¹N, M⁻¹B within 10 %, truth inside the 95 %
    interval widened by 2 (coloured residuals aside, a sanity check of the interval's scale)."""
    ident, truth, _ = linear_fit
    assert set(ident.parameters) == set(truth)
    for name, true in truth.items():
        p = ident.parameters[name]
        assert p.value == pytest.approx(true, rel=0.10), (name, p.value, true)
        half = p.ci95[1] - p.value
        assert abs(p.value - true) <= 2 * half + 1e-12, (name, p.value, p.ci95, true)
    assert ident.nrmse_holdout["r"] < 0.2 and ident.nrmse_holdout["v"] < 0.3


def test_confidence_intervals_cover_the_truth_in_a_seeded_monte_carlo():
    """30 noise realisations on one Nomoto zig-zag: each 95 % interval should miss ~1.5 times;
    at least 25 of 30 must cover (P(X <= 24) = 1.6 % for a true 95 % interval)."""
    from shipgnc.actuators import Actuator
    from shipgnc.models.nomoto import NomotoModel

    K, T = 0.1, 20.0
    act = Actuator(np.array([-math.radians(35)]), np.array([math.radians(35)]),
                   rate=[math.radians(5.0)], names=("delta",))
    ds = zigzag_trial(NomotoModel(K=K, T=T, U=5.0), act, np.zeros(4), delta_deg=10, psi_deg=10,
                      t_end=200.0, dt=0.2, rudder_sign=1.0, rudder_index=0)
    t, d, r = ds["time"].values, ds["delta"].values, ds["r"].values
    assert stats.binom.cdf(24, 30, 0.95) < 0.02
    cover = {"K": 0, "T": 0}
    for seed in range(30):
        rn = r + np.random.default_rng(seed).normal(0.0, 4 * NOISE_R, r.size)
        ident = identify_nomoto1(t, d, rn, holdout=0.0, speed=5.0)
        for name, true in (("K", K), ("T", T)):
            lo, hi = ident.parameters[name].ci95
            cover[name] += lo <= true <= hi
    assert cover["K"] >= 25 and cover["T"] >= 25, cover


def test_written_vessel_yaml_loads_and_resimulates_the_fit(frigate_fit, linear_fit, tmp_path):
    """vessel.yaml → yaml → the scenario schema and the catalogue's model → the logged rudder:
    the fitted response."""
    from shipgnc.scenarios.schema import CatalogueVesselConfig

    for ident in (frigate_fit, linear_fit[0]):
        path = tmp_path / f"{ident.model}.yaml"
        path.write_text(vessel_yaml(ident, source="test"), encoding="utf-8")
        spec = yaml.safe_load(path.read_text(encoding="utf-8"))["vessel"]
        assert spec == ident.vessel
        CatalogueVesselConfig.model_validate(spec)  # a scenario's vessel: section accepts it
        model = build_vessel(spec)
        x0 = model.straight_state(spec["speed_mps"])
        for key in ("u", "v", "r"):
            if key in ident.measured:
                x0[state_index(model, key)] = ident.simulated[key][0]
        states = resimulate(model, ident.t, ident.rudder, x0)
        for key in ident.measured:
            got = states[:, state_index(model, key)]
            want = ident.simulated[key]
            scale = np.max(np.abs(want - np.mean(want))) if key != "u" else 1.0
            assert np.max(np.abs(got - want)) < 1e-3 * scale, (ident.model, key)


# --------------------------------------------------------------------------- bad logs

def _good(n=50):
    t = np.arange(n) * 0.5
    d = 0.2 * np.sign(np.sin(2 * np.pi * t / 10.0))
    r = np.convolve(d, np.ones(5) / 50, mode="same")
    return {"time": t, "delta": d, "r": r}


def _cli_error(*args):
    result = runner.invoke(app, ["identify", *[str(a) for a in args]])
    assert result.exit_code == 2, (result.exit_code, result.stdout, result.stderr)
    lines = [ln for ln in result.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:"), result.stderr
    return " ".join(lines[0].split())


def test_missing_file(tmp_path):
    assert "no such file" in _cli_error(tmp_path / "nope.csv")


def test_unreadable_netcdf(tmp_path):
    path = tmp_path / "broken.nc"
    path.write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(range(200)))
    assert "cannot read as NetCDF" in _cli_error(path)


def test_misnamed_column_lists_those_present(tmp_path):
    cols = _good()
    cols["rudder_angle"] = cols.pop("delta")
    path = _write_csv(tmp_path / "log.csv", cols)
    msg = _cli_error(path)
    assert "no column for the rudder" in msg and "columns present: time, r, rudder_angle" in msg
    assert "--columns rudder=NAME" in msg
    msg = _cli_error(path, "--columns", "rudder=rudder_deg")
    assert "no column 'rudder_deg'" in msg and "rudder_angle" in msg


def test_time_not_increasing_names_the_row(tmp_path):
    cols = _good()
    cols["time"][10] = cols["time"][9]
    path = _write_csv(tmp_path / "log.csv", cols)
    # header on line 1, sample i on line i + 2
    assert "time not strictly increasing at line 12" in _cli_error(path)


def test_a_gap_in_time_is_refused_not_interpolated(tmp_path):
    """One wrong time stamp (1e9 s at the end) would make a 2·10⁹-sample uniform grid: refused with
    the line of the gap instead of filling memory with invented samples."""
    cols = _good()
    cols["time"][-1] = 1e9
    path = _write_csv(tmp_path / "log.csv", cols)
    msg = _cli_error(path)
    assert "a gap of" in msg and f"line {len(cols['time']) + 1}" in msg


def test_nan_rows_are_named(tmp_path):
    cols = _good()
    cols["r"][3] = np.nan
    cols["delta"][20] = np.nan
    path = _write_csv(tmp_path / "log.csv", cols)
    msg = _cli_error(path)
    assert "lines 5, 22" in msg and "delta, r" in msg


def test_too_little_excitation_gives_the_condition_number(tmp_path):
    n = 200
    t = np.arange(n) * 0.5
    d = np.full(n, 0.1)  # a steady turn: r = K delta, the regressor's columns are collinear
    path = _write_csv(tmp_path / "steady.csv", {"time": t, "delta": d, "r": 0.02 * d + 0 * t})
    path2 = _write_csv(tmp_path / "steady2.csv", {"time": t, "delta": d + 0.05 * (t > 50),
                                                  "r": 0.01 * (d + 0.05 * (t > 50))})
    msg = _cli_error(path)
    assert "too little excitation" in msg and "rudder spans" in msg
    msg = _cli_error(path2)
    assert "too little excitation" in msg and "condition number" in msg and "allowed <= 1e+03" in msg


def test_degrees_read_as_radians_are_caught(tmp_path):
    cols = _good()
    cols["delta"] = np.degrees(cols["delta"])
    msg = _cli_error(_write_csv(tmp_path / "log.csv", cols))
    assert "looks like degrees" in msg and "--units deg" in msg


def test_a_cell_that_is_not_a_number_is_named(tmp_path):
    path = tmp_path / "log.csv"
    path.write_text("time,delta,r\n0,0,0\n0.5,0.1,abc\n", encoding="utf-8")
    assert "line 3, column 'r': 'abc' is not a number" in _cli_error(path)


def test_read_log_errors_are_config_errors(tmp_path):
    with pytest.raises(ConfigError, match="unknown role"):
        read_log(tmp_path / "x.csv", columns="rudderr=delta")


# --------------------------------------------------------------------------- command line

JSON_KEYS = {"log", "format", "ship", "columns", "units", "model", "method", "samples", "dt_s",
             "duration_s", "split", "parameters", "confidence", "nrmse_holdout", "nrmse_fit",
             "residual_rms", "residual_lag1_autocorrelation", "excitation", "vessel", "notes"}


def test_cli_json_keys_and_outputs(frigate_log, tmp_path):
    out = tmp_path / "fit"
    result = runner.invoke(app, ["identify", str(frigate_log), "--columns", FRIGATE_COLUMNS,
                                 "--units", "deg", "--speed", "9", "--json", "--out", str(out)])
    assert result.exit_code == 0, result.stderr
    data = json.loads(result.stdout)
    assert set(data) == JSON_KEYS
    assert set(data["parameters"]) == {"K", "T"}
    for p in data["parameters"].values():
        assert {"value", "ci95", "std_error", "unit"} <= set(p) and p["ci95"][0] < p["value"] < p["ci95"][1]
    assert data["split"]["holdout_fraction"] == 0.3
    assert data["confidence"]["level"] == 0.95 and data["confidence"]["distribution"] == "student-t"
    assert data["vessel"]["model"] == "nomoto" and data["vessel"]["speed_mps"] == 9.0
    files = {p.name: p.stat().st_size for p in out.iterdir()}
    assert files["identify.png"] > 10_000 and files["vessel.yaml"] > 50
    assert json.loads((out / "identify.json").read_text()) == data


def test_identify_a_shipgnc_run_of_a_cybership_scenario(tmp_path):
    """``shipgnc run`` of the built-in cybership-calm (kept to its pd and smc_consistent
    controllers and 150 s for speed) logs rudder ``delta``, heading ``psi`` and yaw rate ``r`` per
    controller; identify reads run 0 by default (and says so) and another run with --ship. The
    smc_consistent run (large rudder, like a zig-zag) gives the steering model of the plant's
    20/20 zig-zag identification (analysis.identification) within 25 % (the plant is nonlinear:
    its speed drops in the turns, so manoeuvres of different size give somewhat different K, T)."""
    from shipgnc.analysis.identification import identify_cybership2

    shown = runner.invoke(app, ["show", "cybership-calm"])
    assert shown.exit_code == 0, shown.stderr
    sc = yaml.safe_load(shown.stdout)
    sc["controllers"] = {k: v for k, v in sc["controllers"].items() if k in ("pd", "smc_consistent")}
    sc["simulation"]["t_end"] = 150.0
    sc.pop("document_figures", None)
    scenario = tmp_path / "calm.yaml"
    scenario.write_text(yaml.safe_dump(sc), encoding="utf-8")
    run = tmp_path / "run"
    result = runner.invoke(app, ["run", str(scenario), "--no-figures", "--out", str(run)])
    assert result.exit_code == 0, result.stderr
    result = runner.invoke(app, ["identify", str(run / "result.nc"), "--json"])
    assert result.exit_code == 0, result.stderr
    data = json.loads(result.stdout)
    assert data["ship"] == 0 and data["format"] == "netcdf"
    assert any("identified run 0" in n and "--ship" in n for n in data["notes"])
    assert data["columns"]["rudder"] == "delta" and data["columns"]["yaw_rate"] == "r"
    result = runner.invoke(app, ["identify", str(run / "result.nc"), "--ship", "1", "--json"])
    assert result.exit_code == 0, result.stderr
    data = json.loads(result.stdout)
    assert any("smc_consistent" in n for n in data["notes"])
    zigzag = identify_cybership2()
    assert data["parameters"]["K"]["value"] == pytest.approx(zigzag.K, rel=0.25)
    assert data["parameters"]["T"]["value"] == pytest.approx(zigzag.T, rel=0.25)
    msg = _cli_error(run / "result.nc", "--ship", "9")
    assert "allowed 0..1" in msg


def test_second_order_nomoto_recovered_with_intervals_covering_the_truth():
    """A known second-order Nomoto ship (K = 0.1 1/s, T₁ = 20 s, T₂ = 4 s, T₃ = 6 s, the
    catalogue's nomoto2) from its noisy 20/20 zig-zag: K within 5 %, T₁ + T₂ and T₁T₂ within
    15 %, and each 95 % interval holds the truth."""
    from shipgnc.identify import identify_nomoto2
    from shipgnc.vessels import get_vessel

    truth = {"K": 0.1, "T1": 20.0, "T2": 4.0, "T3": 6.0}
    model = get_vessel("nomoto2").build(5.0, **truth)
    ds = zigzag_trial(model, None, model.straight_state(5.0), delta_deg=20, psi_deg=20,
                      t_end=300.0, dt=0.2, rudder_sign=1.0, rudder_index=0)
    r = ds["r"].values + np.random.default_rng(2).normal(0.0, NOISE_R, ds["time"].size)
    ident = identify_nomoto2(ds["time"].values, ds["delta"].values, r, speed=5.0)
    truth.update({"T1+T2": 24.0, "T1*T2": 80.0})
    assert ident.value("K") == pytest.approx(0.1, rel=0.05)
    assert ident.value("T1+T2") == pytest.approx(24.0, rel=0.15)
    assert ident.value("T1*T2") == pytest.approx(80.0, rel=0.15)
    for name, true in truth.items():
        lo, hi = ident.parameters[name].ci95
        assert lo <= true <= hi, (name, lo, hi, true)


def test_heading_only_log_with_uneven_steps(tmp_path):
    """No yaw-rate column: r from the differentiated heading; uneven sampling: resampled (notes)."""
    from shipgnc.actuators import Actuator
    from shipgnc.models.nomoto import NomotoModel

    act = Actuator(np.array([-1.0]), np.array([1.0]), rate=[math.radians(5.0)], names=("delta",))
    ds = zigzag_trial(NomotoModel(K=0.1, T=15.0, U=5.0), act, np.zeros(4), delta_deg=15,
                      psi_deg=15, t_end=240.0, dt=0.1, rudder_sign=1.0, rudder_index=0)
    keep = np.ones(ds["time"].size, dtype=bool)
    keep[1::7] = False  # drop every 7th sample: steps of 0.1 and 0.2 s
    wrapped = np.angle(np.exp(1j * (ds["psi"].values + 3.0)))  # a compass wrapping at ±180°
    path = _write_csv(tmp_path / "log.csv", {"time": ds["time"].values[keep],
                                             "delta": ds["delta"].values[keep],
                                             "heading": wrapped[keep]})
    log = read_log(path, need_one_of=("yaw_rate", "heading"))
    ident = identify_log(log, "nomoto1")
    assert any("uniform" in n for n in ident.notes)
    assert any("differentiated heading" in n for n in ident.notes)
    assert ident.value("K") == pytest.approx(0.1, rel=0.05)
    assert ident.value("T") == pytest.approx(15.0, rel=0.05)
