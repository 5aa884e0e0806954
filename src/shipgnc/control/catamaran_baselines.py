"""Classical baselines for document 004's catamaran on the same plant (spec 004 §4.11.3).

* :class:`YawRatePI` — a fixed-gain PI yaw-rate controller with the bandwidth of law (20):
  law (20) with cos δ frozen at 1, i.e. δ̇ = K_i (ω* − ω) − K_p ṙ with K_i = J/(T_u h L T_v),
  K_p = J/(T_u L T_v) (``si``: K_i = 2.223, K_p = 5.558 s); in position form
  δ = K_i ∫(ω* − ω) dt − K_p ω. ṙ is the model's Φ₃ at the measured state, as in law (20).
* :class:`HeadingLQR` — a heading autopilot designed with ``control.lqr`` on the linearisation
  about straight running (4.42 m/s), state [v, r, ψ − ψ_r, δ], input δ̇. Since δ integrates δ̇,
  the law δ̇ = −K x is a PID on the heading error (I on e_ψ, P through r, D through ṙ ~ δ) with
  sway feedback. The heading reference is the ramp of the capture profile (17).

Both are stateless continuous laws (their integral is the physical δ), like the FSM laws, so the
comparison runs them in the same ``continuous`` mode.
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.batchmath import row_dot
from shipgnc.control.finite_state import HeadingCapture, as_rate_reference, default_gains
from shipgnc.errors import require
from shipgnc.frames import wrap_angle
from shipgnc.models.base import Signal
from shipgnc.models.catamaran import DELTA, PSI, Catamaran, R, V, linearize, straight_running_state


def pi_gains(params, T_u: float, h: float) -> tuple[float, float]:
    """(K_i [1/s... rad/(rad/s)/s], K_p [s]) = (J/(T_u h L T_v), J/(T_u L T_v)) of the equal-bandwidth PI."""
    k = params.J / (params.L * params.T_v)
    return k / (T_u * h), k / T_u


class YawRatePI:
    """Fixed-gain PI yaw-rate controller (law (20) without the 1/cos δ scheduling)."""

    def __init__(self, model: Catamaran, *, T_u: float, h: float, omega_ref, Ts: float | None = None):
        require(T_u > 0 and h > 0, "controller.T_u/h", (T_u, h), "must be > 0 s")
        self.model = model
        self.K_i, self.K_p = pi_gains(model.params, T_u, h)
        self.omega_ref = as_rate_reference(omega_ref)
        self.Ts, self.continuous = Ts, Ts is None
        self.signals = (Signal("omega_ref", "rad/s", "yaw-rate reference"),)
        self.events: list[dict] = []
        self._last: dict = {}

    def reset(self, batch_shape) -> None:
        self.omega_ref.reset(batch_shape)
        self.events = []

    def law(self, t, x, reference):
        w = self.omega_ref.value(t, x)
        u = self.K_i * (w - x[..., R]) - self.K_p * self.model.yaw_acceleration(x)
        self._last = {"omega_ref": w}
        return u[..., None]

    step = law

    def signal_values(self):
        return dict(self._last)


def heading_lqr_gain(model: Catamaran, q=(0.0, 1.0e3, 1.0, 0.0), r: float = 1.0e3) -> np.ndarray:
    """LQR gain K (1×4) on [v, r, ψ, δ] with input δ̇ about straight running (python-control)."""
    import control

    A, B = linearize(model, straight_running_state(model.params))
    keep = [V, R, PSI, DELTA]
    K, _, _ = control.lqr(A[np.ix_(keep, keep)], B[keep], np.diag(q), np.array([[r]]))
    return np.asarray(K)[0]


class HeadingLQR:
    """Heading autopilot δ̇ = −K [v, r − r_r, wrap(ψ − ψ_r), δ] with the ramp reference of (17)."""

    def __init__(self, model: Catamaran, psi_target: float, omega_c: float = 0.0022, *, gain=None,
                 Ts: float | None = None):
        self.model = model
        self.K = heading_lqr_gain(model) if gain is None else np.asarray(gain, dtype=float)
        self.capture = HeadingCapture(psi_target, omega_c)
        self.Ts, self.continuous = Ts, Ts is None
        self.signals = (Signal("psi_ref", "rad", "heading reference (ramp)", angle=True),)
        self.events: list[dict] = []
        self._last: dict = {}

    def reset(self, batch_shape) -> None:
        self.capture.reset(batch_shape)
        self.events = []

    def heading_reference(self, t, x):
        r_ref = self.capture.value(t, x)
        cap = self.capture
        diff = wrap_angle(cap.psi_target - cap.psi0)
        t_star = cap.switch_time()
        psi_ref = cap.psi0 + np.sign(diff) * cap.omega_c * np.clip(t - cap.t0, 0.0, t_star - cap.t0)
        return psi_ref, r_ref

    def law(self, t, x, reference):
        psi_ref, r_ref = self.heading_reference(t, x)
        err = np.stack([x[..., V], x[..., R] - r_ref, wrap_angle(x[..., PSI] - psi_ref), x[..., DELTA]], -1)
        self._last = {"psi_ref": psi_ref}
        return -row_dot(err, self.K)[..., None]

    step = law

    def signal_values(self):
        return dict(self._last)


def comparison_cases(preset_name: str = "si", t_end_rate: float = 300.0, t_end_heading: float = 600.0,
                     vessel: dict | None = None):
    """``catamaran-compare``: FSM laws against the baselines on S3 (ω* = 0.08), S4 (ω* = 0.008) and S7
    (K* = 0.8 rad, ω_c = 0.0022 rad/s). Returns ``{"S3/law20": case, ...}``."""
    from shipgnc.cases.catamaran import CatamaranCase, heading, initial_state, yaw_rate_case
    from shipgnc.control.finite_state import ConstantRate

    T_u, h = default_gains(preset_name)
    cases = {}
    for label, w in (("S3", 0.08), ("S4", 0.008)):
        for law in (20, 21):
            cases[f"{label}/law{law}"] = yaw_rate_case(f"compare/{label}/law{law}", preset_name, law, w,
                                                       t_end=t_end_rate, vessel=vessel)
        model = Catamaran.from_preset(preset_name, **(vessel or {}))
        ref = ConstantRate(w)
        cases[f"{label}/pi"] = CatamaranCase(f"compare/{label}/pi", model, initial_state(),
                                             YawRatePI(model, T_u=T_u, h=h, omega_ref=ref), ref, t_end_rate)
    cases["S7/law21"] = heading(preset_name, 21, 0.8, 0.0022, t_end=t_end_heading, vessel=vessel)
    model = Catamaran.from_preset(preset_name, **(vessel or {}))
    lqr = HeadingLQR(model, 0.8, 0.0022)
    cases["S7/lqr"] = CatamaranCase("compare/S7/lqr", model, initial_state(), lqr, None, t_end_heading,
                                    heading_target=0.8)
    return cases


def run_comparison(preset_name: str = "si", **kwargs) -> dict[str, dict]:
    """Run every comparison case; returns run key → comparison metrics (IAE, travel, peak rate...)."""
    from shipgnc.analysis.catamaran_metrics import comparison_metrics

    out = {}
    for key, case in comparison_cases(preset_name, **kwargs).items():
        ds = case.run()
        out[key] = comparison_metrics(ds, case.heading_target)
        out[key]["final_yaw_rate_rad_s"] = float(ds.r[-1])
        out[key]["final_delta_deg"] = math.degrees(float(ds.delta[-1]))
    return out
