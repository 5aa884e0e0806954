"""Numbers and the figure of docs/003_cybership_autopilot.md, sections "Identified design model",
"Wave-load calibration" and "Why the PD's ψ_E is lower in waves".

Run: ``python docs/cybership_analysis.py`` (about a minute); writes
``docs/figures/cybership-analysis.png`` and prints the tables.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from shipgnc.analysis import identification as idn
from shipgnc.cases.cybership import PRINTED_EQ18
from shipgnc.control.course import CoursePD
from shipgnc.environment.waves import FroudeKrylovWaveLoads, WaveSpectrum
from shipgnc.guidance.schedule import CourseSchedule
from shipgnc.models.cybership2 import (
    CyberShip2,
    CyberShip2Params,
    steering_machine,
    surge_equilibrium,
)
from shipgnc.models.nomoto_reduction import davidson_schiff
from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import build
from shipgnc.sim.simulator import simulate

OUT = Path(__file__).parent / "figures" / "cybership-analysis.png"


def identification(ax):
    fit = idn.identify_cybership2()
    print(f"identified (20/20 zig-zag): K = {fit.K:.4f} 1/s, T = {fit.T:.3f} s, a22 = {fit.a22:.4f}, "
          f"b2 = {fit.b2:.5f}, residual RMS = {math.degrees(fit.residual_rms):.3f} deg/s, "
          f"r RMS = {math.degrees(fit.r_rms):.3f} deg/s, fit = {fit.fit:.3f}")
    a22, b2 = PRINTED_EQ18
    printed = idn.NomotoFit(K=-b2 / a22, T=-1 / a22, residual_rms=0, r_rms=0, fit=0, cost=0)
    for dz in ((20, 20), (25, 25), (30, 10), (35, 35)):
        ds = idn.cybership2_zigzag(delta_deg=dz[0], psi_deg=dz[1])
        rec = (ds["time"].values, ds["delta"].values, ds["r"].values)
        own, eq18 = fit.residual(*rec), printed.residual(*rec)
        print(f"  zig-zag {dz[0]}/{dz[1]}: fit identified {own['fit']:.2f} "
              f"(residual {math.degrees(own['residual_rms']):.2f} deg/s), eq18 {eq18['fit']:.2f}; "
              f"min u {float(ds['u'].min()):.3f} m/s")
        if dz == (25, 25):
            t = rec[0]
            ax.plot(t, np.degrees(rec[2]), "k", label="plant, zig-zag 25°/25° (held out)")
            ax.plot(t, np.degrees(fit.predict(*rec[:2], rec[2][0])), "C0--",
                    label=f"identified K = {fit.K:.3f}/s, T = {fit.T:.2f} s")
            ax.plot(t, np.degrees(printed.predict(*rec[:2], rec[2][0])), "C3:", label="(18) as printed")
    ax.set(ylabel="r [°/s]", xlabel="t [s]", title="Nomoto model identified on the 20°/20° zig-zag")
    ax.set_ylim(-12, 12)
    ax.legend(fontsize=7)


def calibration():
    p = CyberShip2Params()
    psi0 = math.radians(30.0)
    for seed in (2024, 1, 2):
        loads = FroudeKrylovWaveLoads(WaveSpectrum.modified_pierson_moskowitz(0.0429, 0.8))
        ds = simulate(CyberShip2(p), np.array([0, 0, psi0, surge_equilibrium(p, 8.13), 0, 0.0]),
                      t_end=220.0, dt=0.05, controller=CoursePD(Ts=0.05), actuator=steering_machine(p),
                      guidance=CourseSchedule([0.0], [psi0]), disturbance=loads, seed=seed,
                      backend="numpy")
        keep = ds["time"].values >= 20

        def band(x, keep=keep):
            x = x[keep] - x[keep].mean()
            spec = np.fft.rfft(x)
            spec[2 * np.pi * np.fft.rfftfreq(x.size, 0.05) < 2.0] = 0
            return np.fft.irfft(spec, x.size)

        speed = float(ds["u"].values[keep].mean())
        lin = davidson_schiff(p, speed)
        est = loads.linear_response(psi0, speed, lin.M, lin.N)
        print(f"calibration seed {seed}: heading RMS sim {np.degrees(np.std(band(ds['psi'].values))):.3f}"
              f" deg, linear {math.degrees(float(est['psi_rms'])):.3f} deg; yaw rate sim "
              f"{np.degrees(np.std(band(ds['r'].values))):.2f}, "
              f"linear {math.degrees(float(est['r_rms'])):.2f}"
              f" deg/s; omega_e {float(est['omega_e_mean']):.2f} rad/s")


def _run(name, overrides=(), seed=2024):
    sc = load_scenario(name, list(overrides))
    s = build(sc, "pd", seed=seed)
    return simulate(s.model, s.x0, t_end=300, dt=0.1, controller=s.controller, actuator=s.actuator,
                    guidance=s.guidance, disturbance=s.disturbance, u0=s.u0, seed=seed, backend="numpy")


def _lp(x, n=31):
    return np.convolve(x, np.ones(n) / n, mode="same")


def rectification(ax_psi, ax_rud):
    limit = math.radians(2.32 * math.sqrt(70))
    rows = [("calm", "cybership-calm", (), 2024)]
    rows += [(f"waves seed {s}", "cybership-waves", (), s) for s in (2024, 1, 2, 3)]
    rows += [("waves, yaw load only", "cybership-waves", ("disturbance.gains=[0,0,1]",), 2024),
             ("waves, surge load only", "cybership-waves", ("disturbance.gains=[1,0,0]",), 2024),
             ("waves, no rate limit", "cybership-waves", ("vessel.rudder_rate_deg_s=null",), 2024),
             ("calm, K_P, K_D x 0.6", "cybership-calm", ("controllers.pd.Kp=1.2", "controllers.pd.Kd=30"),
              2024)]
    print("| run | ψ_E | δ_E | overshoot after +30° [°] | low-frequency rudder gain | at rate limit |")
    for label, name, over, seed in rows:
        ds = _run(name, over, seed)
        t = ds["time"].values
        e = np.angle(np.exp(1j * (ds["psi_d"].values - ds["psi"].values)))
        d, dz = ds["delta"].values, ds["delta_cmd"].values
        lz, ld = _lp(dz), _lp(d)
        m = (np.abs(lz) < 0.4) & (t > 12) & (t < 295)
        gain = float(np.sum(lz[m] * ld[m]) / np.sum(lz[m] ** 2))
        at_limit = float(np.mean(np.abs(np.diff(d)) / 0.1 > 0.99 * limit))
        over = float(np.degrees(np.max(ds["psi"].values[(t > 10) & (t < 110)]))) - 30
        print(f"| {label} | {np.sum(e**2):.1f} | {np.sum(d**2):.1f} | {over:.2f} | {gain:.2f} | "
              f"{100 * at_limit:.0f} % |")
        if label in ("calm", "waves seed 2024", "calm, K_P, K_D x 0.6"):
            sel = (t >= 5) & (t <= 110)
            ax_psi.plot(t[sel], np.degrees(ds["psi"].values[sel]), label=label)
            if label != "calm, K_P, K_D x 0.6":
                ax_rud.plot(t[sel], np.degrees(d[sel]), lw=0.6, alpha=0.5, label=f"δ, {label}")
                ax_rud.plot(t[sel], np.degrees(ld[sel]), lw=1.5, label=f"δ 3-s mean, {label}")
    ax_psi.axhline(30, color="0.5", lw=0.5)
    ax_psi.set(ylabel="ψ [°]", title="PD, first course change: waves act like a 0.6 × softer PD")
    ax_psi.legend(fontsize=7)
    ax_rud.set(ylabel="δ [°]", xlabel="t [s]")
    ax_rud.legend(fontsize=7)


def figure(directory: Path = OUT.parent) -> list[Path]:
    """Draw ``cybership-analysis.png`` into ``directory`` (``docs/make_figures.py`` calls this)."""
    fig, axes = plt.subplots(3, 1, figsize=(9, 10), constrained_layout=True)
    identification(axes[0])
    calibration()
    rectification(axes[1], axes[2])
    out = Path(directory) / OUT.name
    fig.savefig(out, dpi=90)
    plt.close(fig)
    return [out]


def main():
    print(f"wrote {figure()[0]}")


if __name__ == "__main__":
    main()
