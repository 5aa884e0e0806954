"""Hostile scenario files and values: each refused with one line and exit 2, before any work,
in bounded time and memory (nothing silently wrong)."""

from __future__ import annotations

import time

import pytest
from typer.testing import CliRunner

from shipgnc.cli import app
from shipgnc.errors import ConfigError
from shipgnc.scenarios.registry import MAX_NESTING, MAX_SCENARIO_BYTES, load_scenario
from shipgnc.study.spec import Study

runner = CliRunner()

BOAT = """name: mine
vessel: {model: vectored-thrust-boat}
simulation: {dt: 0.05, t_end: 1.0}
controller: {type: open-loop, schedule: [{t: 0.0, T: 10.0, alpha_deg: 0.0}]}
"""


def _refused(tmp_path, text: str | bytes, *words: str) -> str:
    path = tmp_path / "bad.yaml"
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    result = runner.invoke(app, ["show", str(path)])
    assert result.exit_code == 2, (result.exit_code, result.stdout, result.stderr)
    message = result.stderr.strip()
    assert len(message.splitlines()) == 1, message
    for word in words:
        assert word in message, message
    return message


def test_the_well_formed_boat_file_loads(tmp_path):
    path = tmp_path / "ok.yaml"
    path.write_text(BOAT)
    assert load_scenario(str(path)).name == "mine"


def test_non_utf8_file(tmp_path):
    _refused(tmp_path, BOAT.encode() + b"# caf\xe9\n", "not UTF-8", "0xe9")


def test_nesting_is_bounded_before_parsing(tmp_path):
    _refused(tmp_path, "a: " + "[" * 5000 + "]" * 5000 + "\n", "nested more than", str(MAX_NESTING))


def test_alias_bomb_is_refused_quickly(tmp_path):
    """Nine levels of ten aliases (~10⁹ values when expanded) in under a kilobyte."""
    lines = ["l0: &l0 [x, x, x, x, x, x, x, x, x, x]"]
    lines += [f"l{i}: &l{i} [{', '.join([f'*l{i - 1}'] * 10)}]" for i in range(1, 10)]
    start = time.perf_counter()
    _refused(tmp_path, "\n".join(lines) + "\n", "aliases expand")
    assert time.perf_counter() - start < 5.0  # bounded work, not the expansion (a generous bound)


def test_duplicate_section_is_refused(tmp_path):
    _refused(tmp_path, BOAT + "simulation: {dt: 0.1, t_end: 2.0}\n", "'simulation' given twice",
             "lines 3 and 5")


def test_oversized_file(tmp_path):
    _refused(tmp_path, BOAT + "#" * (MAX_SCENARIO_BYTES + 10) + "\n", "bytes", "limited")


def test_device_file_is_read_only_up_to_the_cap():
    with pytest.raises(ConfigError, match="more than"):
        load_scenario("/dev/zero")


def test_directory_is_named_as_a_directory(tmp_path):
    with pytest.raises(ConfigError, match="is a directory"):
        load_scenario(str(tmp_path))


@pytest.mark.parametrize("seed", [2**64, 2**63])
def test_seed_beyond_int64(seed):
    with pytest.raises(ConfigError, match="seed"):
        load_scenario("boat-autopilot", [f"simulation.seed={seed}"])
    with pytest.raises(ConfigError, match="--seed"):
        Study("boat-autopilot", members=2, seed=seed)


def test_heading_reference_beyond_ten_turns():
    with pytest.raises(ConfigError, match="psi_deg"):
        load_scenario("boat-autopilot", ["guidance.schedule.1.psi_deg=1e300"])


def _boat():
    from shipgnc.models.fossen3dof import VectoredThrustBoat

    return VectoredThrustBoat.from_preset("otter")


@pytest.mark.parametrize("role", ["controller", "guidance", "disturbance", "actuator"])
def test_api_component_of_the_wrong_kind(role):
    from shipgnc.sim.simulator import simulate

    with pytest.raises(ConfigError, match=f"{role} = 'pid': not a {role} object"):
        simulate(_boat(), [0.0] * 6, t_end=1.0, dt=0.1, **{role: "pid"})


@pytest.mark.parametrize("dims, words", [(("a", "a"), "distinct"), (("a", "b"), "need 1 names"),
                                         ("ship", "tuple of names")])
def test_api_batch_dims_checked_before_the_run(dims, words):
    from shipgnc.sim.simulator import simulate

    with pytest.raises(ConfigError, match=words):
        simulate(_boat(), [[0.0] * 6], t_end=1.0, dt=0.1, batch_dims=dims)


def test_api_autopilot_given_a_preset_name():
    from shipgnc.control.heading_speed import HeadingSpeedAutopilot

    with pytest.raises(ConfigError, match="must be BoatParams"):
        HeadingSpeedAutopilot("otter")


def test_api_schedule_lengths_and_complex_state():
    from shipgnc.guidance.schedule import ReferenceSchedule
    from shipgnc.sim.simulator import simulate

    with pytest.raises(ConfigError, match="times: 3, psi_d: 2, u_d: 3"):
        ReferenceSchedule([0, 1, 2], [0.0, 0.1], [1, 1, 1])
    with pytest.raises(ConfigError, match="complex"):
        simulate(_boat(), [1j, 0, 0, 0, 0, 0], t_end=1.0, dt=0.1)


def test_sweep_memory_estimated_before_any_chunk_is_planned():
    """Row 3: a trillion members is refused at once, naming the estimate and what to change."""
    from shipgnc.study.execute import run_study

    start = time.perf_counter()
    with pytest.raises(ConfigError, match=r"needs about .* GiB.*\(--mc\)"):
        run_study(Study("boat-autopilot", members=10**12, overrides=("simulation.t_end=5",)))
    assert time.perf_counter() - start < 5.0


def test_sweep_series_total_counts_against_max_memory():
    """Row 4: each chunk fits, the total of every member's series does not."""
    from shipgnc.study.execute import estimate_memory, run_study

    study = Study("boat-autopilot", members=1_000_000, series=True)
    need = estimate_memory(study, None, 1000)
    assert need["result"] > 100 * need["chunk"]
    with pytest.raises(ConfigError, match="drop --series"):
        run_study(study, max_memory=need["chunk"] * 2)
    with pytest.raises(ConfigError, match="smaller --chunk-size"):
        run_study(Study("boat-autopilot", members=10), max_memory=1e5)


def test_obstacles_from_an_endless_device_are_refused():
    """Row 17: ``--obstacles /dev/zero`` is read up to a cap, then refused."""
    from shipgnc.routing.obstacles import load_geojson

    with pytest.raises(ConfigError, match="MiB"):
        load_geojson("/dev/zero")


def test_obstacle_ring_with_nan_is_one_line(tmp_path):
    from shipgnc.routing.obstacles import load_geojson

    path = tmp_path / "o.geojson"
    path.write_text('{"type": "Polygon", "coordinates": [[[0, 0], [1, NaN], [1, 1], [0, 0]]]}')
    with pytest.raises(ConfigError, match="finite numbers"):
        load_geojson(path)


def test_sweep_max_memory_option(tmp_path):
    from shipgnc.cli import app

    runner_ = CliRunner()
    result = runner_.invoke(app, ["sweep", "boat-autopilot", "--mc", "10", "--series", "--max-memory", "1M",
                                  "--out", str(tmp_path / "o")])
    assert result.exit_code == 2, result.stderr
    assert "more than --max-memory" in " ".join(result.stderr.split()), result.stderr
    bad = runner_.invoke(app, ["sweep", "boat-autopilot", "--max-memory", "lots"])
    assert bad.exit_code == 2 and "expected a size" in bad.stderr


def test_yaml_merge_keys_still_work_and_may_be_overridden(tmp_path):
    """``<<:`` merges are YAML, not duplicate keys; a key after the merge overrides it."""
    path = tmp_path / "merge.yaml"
    path.write_text(BOAT.replace("simulation: {dt: 0.05, t_end: 1.0}",
                                 "simulation: {<<: {dt: 0.05, t_end: 2.0}, t_end: 1.0}"))
    assert load_scenario(str(path)).simulation.t_end == 1.0


def test_a_reader_that_leaves_early_is_not_an_internal_error():
    """`shipgnc vessels --json | true`: the pipe closes under the writer; the command stops
    quietly with the shell's SIGPIPE status (128 + 13), not an "internal error" line."""
    import subprocess
    import sys

    proc = subprocess.Popen([sys.executable, "-m", "shipgnc", "vessels", "--json"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()  # the reader leaves before the command (still importing) writes a byte
    stderr = proc.stderr.read().decode()
    assert proc.wait(timeout=60) == 141
    assert "internal error" not in stderr


@pytest.mark.parametrize("override, words", [
    # F15: an OverflowError in the run (the variance noise² is not a float)
    ("sensors.2.noise_deg_s=1e300", ["sensors.2.gyro.noise_deg_s", "at most 1e+150"]),
    ("sensors.1.bias_std_deg=1e200", ["sensors.1.compass.bias_std_deg", "at most"]),
    ("sensors.0.noise_m=1e300", ["sensors.0.gnss.noise_m", "at most"]),
    # F16: MemoryError, 29.8 GiB for the latency's pipe
    ("sensors.0.latency=1000000000", ["sensors.0.latency = 1000000000", "longer than the run"]),
    # a latency longer than the run (300 s of 0.05 s steps) was accepted
    ("sensors.0.latency=6001", ["sensors.0.latency = 6001", "longer than the run"]),
])
def test_sensor_fields_are_checked_before_the_run(override, words):
    """F15, F16: sensor noise whose square overflows, and a latency longer than the run, are one
    line naming the field (exit 2) before any work."""
    result = runner.invoke(app, ["show", "boat-los-gnss", "--set", override])
    assert result.exit_code == 2, (result.exit_code, result.stderr)
    message = result.stderr.strip()
    assert len(message.splitlines()) == 1, message
    for word in words:
        assert word in message, message


def test_a_sensor_latency_within_the_run_is_accepted():
    sc = load_scenario("boat-los-gnss", ["sensors.0.latency=6000", "sensors.2.noise_deg_s=1e150"])
    assert sc.sensors[0].latency == 6000


@pytest.mark.parametrize("bad", [123, None, ["boat-autopilot"]])
def test_load_scenario_of_a_non_name_is_one_clear_error(bad):
    """``load_scenario(123)`` was a raw TypeError from the path machinery."""
    with pytest.raises(ConfigError, match="expected a built-in scenario name or the path"):
        load_scenario(bad)


def _warnings_to_stderr(monkeypatch):
    """Warnings printed on stderr, as outside pytest (which records them instead)."""
    import sys
    import warnings

    def show(message, category, filename, lineno, file=None, line=None):
        sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))

    monkeypatch.setattr(warnings, "showwarning", show)


@pytest.mark.filterwarnings("default")
def test_a_librarys_warning_is_not_printed_before_the_one_line_error(monkeypatch):
    """A numpy RuntimeWarning printed by the work before the command's one-line error made it
    several lines; warnings are shown when the command succeeds, and dropped when it fails."""
    import warnings

    import shipgnc.scenarios.registry as registry

    def warns_then_fails(*args, **kwargs):
        warnings.warn("overflow encountered in multiply", RuntimeWarning, stacklevel=1)
        raise ConfigError("simulation.dt = 1e308: too large")

    _warnings_to_stderr(monkeypatch)
    monkeypatch.setattr(registry, "load_scenario", warns_then_fails)
    result = runner.invoke(app, ["show", "boat-autopilot"])
    assert result.exit_code == 2
    assert result.stderr.strip().splitlines() == ["error: simulation.dt = 1e308: too large"]


@pytest.mark.filterwarnings("default")
def test_a_librarys_warning_is_still_shown_when_the_command_succeeds(monkeypatch):
    import warnings

    import shipgnc.scenarios.registry as registry

    real = registry.load_scenario

    def warns(*args, **kwargs):
        warnings.warn("something to know", UserWarning, stacklevel=1)
        return real(*args, **kwargs)

    _warnings_to_stderr(monkeypatch)
    monkeypatch.setattr(registry, "load_scenario", warns)
    result = runner.invoke(app, ["show", "boat-autopilot"])
    assert result.exit_code == 0 and "something to know" in result.stderr
