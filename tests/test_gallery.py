"""Gallery examples run as scripts (``python plot_….py``): each saves its figure, and the ones
whose content was wrong are checked against physics (the thruster's sign, the units drawn, the
spread a Monte Carlo shows). The docs build (tests/test_docs.py) runs every example as well."""

from __future__ import annotations

import runpy
import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pytest

GALLERY = Path(__file__).resolve().parents[1] / "examples" / "gallery"


def run_example(name: str, tmp_path, monkeypatch) -> dict:
    """The example run as ``python <name>.py`` in ``tmp_path``: its globals; its figure saved."""
    script = GALLERY / f"{name}.py"
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "argv", [str(script)])
    plt.close("all")
    namespace = runpy.run_path(str(script), run_name="__main__")
    assert (tmp_path / f"{name}.png").stat().st_size > 10_000, "the script saved no figure"
    return namespace


def test_every_example_ends_by_saving_its_figure():
    for script in sorted(GALLERY.glob("plot_*.py")):
        lines = [line for line in script.read_text(encoding="utf-8").splitlines() if line.strip()]
        assert lines[-1].startswith("show_example()"), f"{script.name} does not end with show_example()"


def test_the_scripted_policy_steers_the_boat_to_its_reference(tmp_path, monkeypatch):
    """psi_error = ψ − ψ_ref and a thruster angle α > 0 turns the boat to port (yaw moment
    −L_m T sin α), so the PD must turn α with the error's sign. Then its return beats a policy that
    holds the thruster straight, and the heading ends on its reference (within the 2° of the
    settling metric); the opposite sign spins the boat and does worse than not steering at all."""
    ns = run_example("plot_09_gymnasium_loop", tmp_path, monkeypatch)
    env, policy_return = ns["env"], sum(ns["rewards"])

    def episode(alpha) -> float:
        obs, _ = env.reset(seed=0)
        total = 0.0
        for _ in range(len(ns["rewards"])):
            o = env.unwrapped.named(obs)
            obs, reward, terminated, truncated, _ = env.step(np.array([120.0, alpha(o)]))
            total += reward
            if terminated or truncated:
                break
        return total

    straight = episode(lambda o: 0.0)
    reversed_sign = episode(lambda o: np.clip(-1.5 * o["psi_error"] - 1.0 * o["r"], -0.78, 0.78))
    assert policy_return > 0.25 * straight, (policy_return, straight)  # returns ≤ 0: cost < ¼
    assert reversed_sign < straight, (reversed_sign, straight)
    assert abs(ns["psi_error"][-1]) < 2.0  # [deg]


def test_read_result_labels_degrees_as_degrees(tmp_path, monkeypatch):
    ns = run_example("plot_10_read_result_nc", tmp_path, monkeypatch)
    label = ns["ax1"].get_ylabel()
    assert "[deg]" in label and "rad" not in label, label
    lines = ns["ax1"].get_lines()
    assert max(np.abs(line.get_ydata()).max() for line in lines) > 30.0  # the 45° step, in degrees


def test_sweep_box_plots_show_the_members_spread(tmp_path, monkeypatch):
    """Members start at headings uniform in ±30°: the plotted metric must differ between them at
    every grid point (a box plot of identical members is a line)."""
    ns = run_example("plot_06_sweep", tmp_path, monkeypatch)
    ax = ns["ax"]
    assert ax.get_ylabel() == "heading RMSE [deg]"
    plotted = ns["ds"]["heading_rmse_deg"]
    spread = plotted.max("member") - plotted.min("member")
    assert np.all(spread.values > 0.5), spread.values
    start = ns["ds"]["initial_state_psi_deg"].isel({"controller.omega_ref": 0}).values
    assert np.ptp(start) > 20.0 and np.all(np.abs(start) <= 30.0)


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")
