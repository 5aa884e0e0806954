"""The worked example of ``docs/extending.md`` is a package that works: its captioned code blocks,
written into a directory exactly as the page shows them, are a distribution (``*.dist-info`` with
the ``shipgnc.components`` entry points) whose own tests pass, and whose scenario runs and sweeps
through ``python -m shipgnc``, compiled, with the figures its sources give; and the registry's handling of
plug-ins (records collected, a broken plug-in one line naming it)."""

from __future__ import annotations

import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "extending.md"
BLOCK = re.compile(r"^```\{code-block\} \w+\n:caption: (\S+)\n\n(.*?)^```", re.S | re.M)

#: the example scenario's sensor and estimator settings (kt-ship-heading.yaml)
ANTENNA_STD, BASELINE, ALPHA, BETA = 0.01, 2.0, 0.2, 0.02


def example_files() -> dict[str, str]:
    """The page's captioned blocks: path → text."""
    files = dict(BLOCK.findall(PAGE.read_text(encoding="utf-8")))
    assert len(files) >= 12, sorted(files)
    return files


@pytest.fixture(scope="module")
def package(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("plugin")
    for name, text in example_files().items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return root


def shipgnc(root: Path, *args: str, cwd: Path | None = None, module: str = "shipgnc"):
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(root), str(ROOT / "src")]),
           "MPLBACKEND": "Agg"}
    return subprocess.run([sys.executable, "-m", module, *args], capture_output=True, text=True,
                          env=env, cwd=cwd or root, timeout=600)


def test_the_page_shows_each_component_as_one_module_plus_its_test():
    files = example_files()
    modules = sorted(n for n in files if n.startswith("shipgnc_ktship/") and n != "shipgnc_ktship/__init__.py")
    assert modules == ["shipgnc_ktship/alphabeta.py", "shipgnc_ktship/autopilot.py",
                       "shipgnc_ktship/satcompass.py", "shipgnc_ktship/vessel.py"]
    tests = sorted(n for n in files if n.startswith("tests/"))
    assert len(tests) == len(modules)
    entry_points = files["shipgnc_ktship-0.1.dist-info/entry_points.txt"]
    for module in modules:  # every module is an entry point of the group
        assert module.removesuffix(".py").replace("/", ".") in entry_points


def test_the_example_package_s_own_tests_pass(package):
    proc = shipgnc(package, "-q", "-n", "0", "-p", "no:cacheprovider", "tests", module="pytest")
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-2000:]
    assert "5 passed" in proc.stdout, proc.stdout[-3000:]


def test_the_example_runs_and_sweeps_through_the_entry_point(package, tmp_path):
    """The satellite compass's heading error is √2 σ / b (the baseline's angular error); the α-β
    tracker's is Kalata's σ² (2α² + 2β − 3αβ) / (α (4 − 2α − β)) on a held heading. A run of
    6000 control samples: the RMS of N white samples has a relative std 1/√(2N); the tracker's
    errors are correlated (poles |z| = √(1 − α)), so the sweep's members give the band: the mean
    of M members within 4 of their standard errors."""
    sigma = math.sqrt(2) * ANTENNA_STD / BASELINE
    kalata = sigma * math.sqrt((2 * ALPHA**2 + 2 * BETA - 3 * ALPHA * BETA)
                               / (ALPHA * (4 - 2 * ALPHA - BETA)))
    proc = shipgnc(package, "run", "kt-ship-heading.yaml", "--no-figures", "--out", str(tmp_path / "run"))
    assert proc.returncode == 0, proc.stderr[-3000:]
    metrics = json.loads((tmp_path / "run" / "metrics.json").read_text())
    n = 6000
    assert abs(math.radians(metrics["heading_meas_rmse_deg"]) / sigma - 1) < 4 / math.sqrt(2 * n)
    with xr.open_dataset(tmp_path / "run" / "result.nc") as result:
        assert result.attrs["backend"] == "compiled"  # every component brings its kernel
    proc = shipgnc(package, "sweep", "kt-ship-heading.yaml", "--mc", "8", "--no-figures",
                   "--out", str(tmp_path / "sweep"))
    assert proc.returncode == 0, proc.stderr[-3000:]
    with xr.open_dataset(tmp_path / "sweep" / "sweep.nc") as sweep:
        assert sweep.attrs["backend"] == "compiled"
        est = np.radians(sweep.heading_est_rmse_deg.values)
        meas = np.radians(sweep.heading_meas_rmse_deg.values)
    assert est.size == 8
    for values, reference in ((est, kalata), (meas, sigma)):
        se = values.std(ddof=1) / math.sqrt(values.size)
        assert abs(values.mean() - reference) < 4 * se + 1e-3 * reference, (values, reference)


def test_a_broken_plug_in_is_one_line_naming_its_distribution_and_entry_point(tmp_path):
    info = tmp_path / "shipgnc_broken-2.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: shipgnc-broken\nVersion: 2.0\n")
    (info / "entry_points.txt").write_text("[shipgnc.components]\nsonar = shipgnc_broken.sonar\n")
    proc = shipgnc(tmp_path, "show", "boat-los-gnss")
    assert proc.returncode == 2, proc.stderr
    lines = [line for line in proc.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, proc.stderr
    assert "'sonar' = 'shipgnc_broken.sonar'" in lines[0]
    assert "shipgnc-broken 2.0" in lines[0]
    assert "ModuleNotFoundError" in lines[0]


def test_a_plug_in_without_records_or_with_a_taken_name_is_refused(tmp_path):
    info = tmp_path / "shipgnc_dup-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: shipgnc-dup\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text("[shipgnc.components]\ngnss = shipgnc_dup\n")
    (tmp_path / "shipgnc_dup.py").write_text(
        "from shipgnc.navigation.sensors import GNSS_SENSOR as AGAIN\n")
    proc = shipgnc(tmp_path, "show", "boat-los-gnss")
    assert proc.returncode == 2
    assert "sensors[].type 'gnss' is already registered" in proc.stderr
    (tmp_path / "shipgnc_dup.py").write_text("X = 1\n")
    proc = shipgnc(tmp_path, "show", "boat-los-gnss")
    assert proc.returncode == 2
    assert "names no component record" in proc.stderr
