"""Document 004's cases S1–S10 as plain builders, ready for ``simulate`` (note 004-4.7).

Each builder returns a :class:`CatamaranCase` (or a dict of them keyed like the metrics of note 004-4.7,
e.g. ``{"law20": ..., "law21": ...}``) holding ``model, x0, actuator, controller, guidance,
t_end, dt`` and, for heading runs, ``heading_target``. A runner calls::

    case = turn()["law20"]
    ds = simulate(case.model, case.x0, t_end=case.t_end, dt=case.dt, controller=case.controller,
                  actuator=case.actuator, guidance=case.guidance, on_divergence="stop")
    metrics = case.metrics(ds)          # document 004 metrics, events included

or simply ``ds = case.run()`` (``backend="auto"``: the composed compiled loop when the run is long
or batched and every component has a kernel, see ``simulate``). Common settings: u(0) = 4 m/s,
everything else 0; RK4 with dt = 0.0625 s; t_f = 1500 s; gains per preset (``paper``:
T_u = 0.1 s, h = 0.0625 s; ``si`` and ``si-consistent``: T_u = h = 2.5 s); the laws in continuous
mode; preset ``si-consistent`` (the physically consistent hull) unless given — ``si``
(printed Coriolis sign) and ``paper`` (the listing's units) are the document's reproductions.
``vessel`` (a dict of :class:`~shipgnc.models.catamaran.CatamaranParams` overrides,
e.g. ``{"coriolis": "consistent"}``) changes the catamaran itself — plant and the controller's
model alike — for every builder.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from shipgnc.control.catamaran_baselines import DesignedPI, HeadingLQR, PolePlacementRate, YawRatePI
from shipgnc.control.finite_state import (
    ConstantRate,
    HeadingCapture,
    SineRate,
    YawRateFSM,
    default_gains,
)
from shipgnc.errors import require
from shipgnc.models.base import state_index
from shipgnc.models.catamaran import DEFAULT_PRESET, Catamaran

DT = 0.0625
T_END = 1500.0
U0 = 4.0
#: fixed thruster angle of S5 [rad]
FIXED_ANGLE = 0.6
#: S5 on the consistent hull: the yaw rate of the 0.6 rad run of ``si`` [rad/s] (the consistent hull
#: has no steady turn at 0.6 rad: it turns ever tighter), so the fixed angle is the one that gives it
FIXED_ANGLE_RATE_SI = 0.036434


@dataclass
class CatamaranCase:
    """Everything ``simulate`` needs for one run, plus what its metrics need."""

    name: str
    model: Catamaran
    x0: np.ndarray
    controller: object | None
    guidance: object | None
    t_end: float = T_END
    dt: float = DT
    actuator: object | None = None
    heading_target: float | None = None
    notes: dict = field(default_factory=dict)
    #: the run's disturbance (None: calm water), e.g. an earth-fixed current with
    #: :func:`with_current`
    disturbance: object | None = None

    def simulate_kwargs(self) -> dict:
        return {"t_end": self.t_end, "dt": self.dt, "controller": self.controller, "actuator": self.actuator,
                "guidance": self.guidance, "disturbance": self.disturbance}

    def run(self, **kwargs):
        """``simulate`` this case (``on_divergence="stop"``; ``backend="auto"``: the composed
        compiled loop for a long or batched run, ``"numpy"``/``"compiled"`` to choose); events in
        ``attrs``."""
        from shipgnc.analysis.catamaran_metrics import attach_events
        from shipgnc.sim.simulator import simulate

        options = {"backend": "auto", "on_divergence": "stop", "attrs": {"case": self.name}, **kwargs}
        ds = simulate(self.model, self.x0, **self.simulate_kwargs(), **options)
        attach_events(ds, self.controller)
        return ds

    def metrics(self, ds) -> dict:
        from shipgnc.analysis.catamaran_metrics import catamaran_metrics, model_fields

        return {**catamaran_metrics(ds, None, self.heading_target),
                **model_fields(self.model, self.notes.get("preset"))}


def with_current(case: CatamaranCase, current, force=None) -> CatamaranCase:
    """``case`` in an earth-fixed ``current`` (a :class:`~shipgnc.environment.fields.CurrentField`,
    :class:`~shipgnc.environment.current_field.GaussMarkovCurrent` or a sum; a spec string of
    :func:`~shipgnc.environment.current_field.parse_current`), with an optional body-axis ``force``
    disturbance: the catamaran's disturbance ``[X_env, Y_env, N_env, current_north,
    current_east]``, the hull forces on the velocity through the water
    (:func:`~shipgnc.models.catamaran.catamaran_rhs`). Sets ``case.disturbance`` and returns
    ``case``."""
    from shipgnc.environment.current_field import CurrentDisturbance, parse_current

    if isinstance(current, str):
        current = parse_current(current)
    north, east = (state_index(case.model, name) for name in ("north", "east"))
    case.disturbance = CurrentDisturbance(current, force, n_force=3, position_index=(north, east))
    return case


def initial_state(u0: float = U0, delta0: float = 0.0, batch: int | None = None) -> np.ndarray:
    x0 = np.array([0.0, 0.0, 0.0, u0, 0.0, 0.0, delta0])  # north, east, psi, u, v, r, delta
    return x0 if batch is None else np.tile(x0, (batch, 1))


def _gains(preset_name: str, T_u, h):
    T_u0, h0 = default_gains(preset_name)
    return (T_u0 if T_u is None else T_u), (h0 if h is None else h)


def yaw_rate_case(name: str, preset_name: str = DEFAULT_PRESET, law: int = 21, omega_ref=0.08, *,
                  t_end: float = T_END, dt: float = DT, Ts: float | None = None, T_u: float | None = None,
                  h: float | None = None,
                  plant: dict | None = None, actuator_model: tuple[float, float] | None = None,
                  batch: int | None = None, delta_max: float | None = None, vessel: dict | None = None,
                  **controller_options) -> CatamaranCase:
    """A yaw-rate FSM run: plant ``preset_name`` (+ ``vessel`` and ``plant`` overrides), law (20)/(21)
    on the nominal model (``preset_name`` + ``vessel``), reference ``omega_ref`` (number, per-ship
    array or reference object; a :class:`HeadingCapture` sets the run's ``heading_target``)."""
    T_u, h = _gains(preset_name, T_u, h)
    plant_model = Catamaran.from_preset(preset_name, **{**(vessel or {}), **(plant or {})})
    nominal = Catamaran.from_preset(preset_name, **(vessel or {}))
    ref = omega_ref if not isinstance(omega_ref, (int, float, np.ndarray, list)) else ConstantRate(omega_ref)
    ctrl = YawRateFSM(nominal, law, T_u=T_u, h=h, omega_ref=ref, Ts=Ts, actuator=actuator_model,
                      delta_max=delta_max, **controller_options)
    if batch is None and isinstance(ref, ConstantRate) and np.ndim(ref.omega) == 1:
        batch = len(ref.omega)
    return CatamaranCase(name, plant_model, initial_state(batch=batch), ctrl, ref, t_end, dt,
                         heading_target=float(ref.psi_target) if isinstance(ref, HeadingCapture) else None,
                         notes={"preset": preset_name, "law": law, "T_u": T_u, "h": h})


# --- S1–S10 -----------------------------------------------------------------------------------------
def straight(preset_name: str = DEFAULT_PRESET, t_end: float = 300.0,
             vessel: dict | None = None) -> CatamaranCase:
    """S1: straight run from 4 m/s with δ = 0 (no controller): the speed rises to 4.42306 m/s."""
    return CatamaranCase("catamaran-straight", Catamaran.from_preset(preset_name, **(vessel or {})),
                         initial_state(), None, None, t_end, DT, notes={"preset": preset_name})


def turn(preset_name: str = DEFAULT_PRESET, omega: float = 0.08, t_end: float = T_END, dt: float = DT,
         Ts: float | None = None, vessel: dict | None = None) -> dict[str, CatamaranCase]:
    """S3 ``catamaran-turn``: ω* = 0.08 rad/s with laws (20) and (21)."""
    return {f"law{law}": yaw_rate_case(f"catamaran-turn/law{law}", preset_name, law, omega, t_end=t_end,
                                       dt=dt, Ts=Ts, vessel=vessel) for law in (20, 21)}


def steps(preset_name: str = DEFAULT_PRESET, t_end: float = T_END,
          vessel: dict | None = None) -> dict[str, CatamaranCase]:
    """S4 ``catamaran-steps``: ω* = 0.008 and 0.00072 with both laws (Figs. 1–3, 5–6)."""
    return {f"law{law}@{w:g}": yaw_rate_case(f"catamaran-steps/law{law}@{w:g}", preset_name, law, w,
                                             t_end=t_end, vessel=vessel)
            for w in (0.008, 0.00072) for law in (20, 21)}


def fixed_angle(preset_name: str = DEFAULT_PRESET, t_end: float = T_END, delta: float | None = None,
                vessel: dict | None = None) -> dict[str, CatamaranCase]:
    """S5 ``catamaran-fixed-angle``: δ held (no controller), the FSM at the same steady angle
    (ω* = the fixed run's steady r) and the document's pairing ω* = 0.00072 (C10).

    ``delta`` [rad]: the document's 0.6 rad for the printed-sign presets; on a hull with the
    consistent sign (no steady turn at 0.6 rad) the angle of the steady turn at r = 0.036434 rad/s,
    the 0.6 rad run's rate in ``si``."""
    from shipgnc.models.steady_turn import steady_state_at_angle

    model = Catamaran.from_preset(preset_name, **(vessel or {}))
    delta = fixed_angle_of(model, delta)
    same = steady_state_at_angle(model, delta).r
    return {
        "fixed": CatamaranCase("catamaran-fixed-angle/fixed", model, initial_state(delta0=delta), None,
                               None, t_end, DT, notes={"preset": preset_name, "delta": delta}),
        "law20_same_angle": yaw_rate_case("catamaran-fixed-angle/law20_same_angle", preset_name, 20, same,
                                          t_end=t_end, vessel=vessel),
        "law20@0.00072": yaw_rate_case("catamaran-fixed-angle/law20@0.00072", preset_name, 20, 0.00072,
                                       t_end=t_end, vessel=vessel),
    }


def fixed_angle_of(model: Catamaran, delta: float | None = None) -> float:
    """S5's thruster angle [rad] on ``model``: ``delta`` when given, else the document's 0.6 rad
    on a printed-sign hull, and on the consistent hull (no steady turn at 0.6 rad) the angle of
    the steady turn at r = 0.036434 rad/s, the 0.6 rad run's rate in ``si``."""
    from shipgnc.models.steady_turn import steady_turn

    if delta is not None:
        return delta
    return (FIXED_ANGLE if model.params.coriolis == "printed"
            else steady_turn(model, FIXED_ANGLE_RATE_SI).delta)


def sine(preset_name: str = DEFAULT_PRESET, law: int = 21, reading: str = "pi", t_end: float = T_END,
         vessel: dict | None = None) -> CatamaranCase:
    """S6 ``catamaran-sine``: ω* = 0.0072 sin(8πt/t_f) (reading C11; ``"literal"``: sin(8t/t_f))."""
    return yaw_rate_case(f"catamaran-sine/law{law}", preset_name, law, SineRate.document(reading, T_END),
                         t_end=t_end, vessel=vessel)


def heading(preset_name: str = DEFAULT_PRESET, law: int = 21, psi_target: float = 0.8,
            omega_c: float = 0.0022, t_end: float | None = None, ramp_s: float = 0.0,
            vessel: dict | None = None) -> CatamaranCase:
    """S7 ``catamaran-heading``: heading capture (17) from K(0) = 0 to K*.

    t_end: 1500 s for ω_c < 0.02 rad/s, else 600 s.
    """
    require(isinstance(psi_target, (int, float)) and math.isfinite(psi_target), "heading_target", psi_target,
            "must be a finite heading [rad]")
    t_end = t_end if t_end is not None else (T_END if omega_c < 0.02 else 600.0)
    cap = HeadingCapture(psi_target, omega_c, ramp_s=ramp_s)
    return yaw_rate_case(f"catamaran-heading/law{law}", preset_name, law, cap, t_end=t_end, vessel=vessel)


#: S8's true thruster (T_t [s], k_t) per run key; the controller assumes T_a = 2 s, k_a = 1
ACTUATOR_RUNS = {"T2_k1": (2.0, 1.0), "T3_k1": (3.0, 1.0), "T1_k1": (1.0, 1.0), "T2_k0.8": (2.0, 0.8),
                 "T2_k1.2": (2.0, 1.2)}


def actuator(preset_name: str = DEFAULT_PRESET, omega: float = 0.08, t_end: float = 600.0,
             T_a: float = 2.0, k_a: float = 1.0, vessel: dict | None = None) -> dict[str, CatamaranCase]:
    """S8 ``catamaran-actuator``: law (21) through the inverse (23) on a plant with the lag (22)."""
    cases = {"ideal": yaw_rate_case("catamaran-actuator/ideal", preset_name, 21, omega, t_end=t_end,
                                    vessel=vessel)}
    for key, (T_t, k_t) in ACTUATOR_RUNS.items():
        cases[key] = yaw_rate_case(f"catamaran-actuator/{key}", preset_name, 21, omega, t_end=t_end,
                                   plant={"delta_row": "lag", "T_t": T_t, "k_t": k_t},
                                   actuator_model=(T_a, k_a), vessel=vessel)
    return cases


def limit(preset_name: str = "paper", law: int = 21, omega: float = 0.081, t_end: float = T_END,
          delta_max: float | None = None, vessel: dict | None = None) -> CatamaranCase:
    """S9: a reference at the feasibility limit (``paper`` law (21) fails from 0.081)."""
    return yaw_rate_case(f"catamaran-limit/law{law}@{omega:g}", preset_name, law, omega, t_end=t_end,
                         delta_max=delta_max, vessel=vessel)


def robustness(preset_name: str = DEFAULT_PRESET, n: int = 40, seed: int = 10, omega: float = 0.06,
               t_end: float = T_END, law: int = 21, vessel: dict | None = None) -> CatamaranCase:
    """S10 / ``catamaran-montecarlo``: plant J uniform ±30 %, m_x and m_y uniform ±10 % each, the
    controller nominal, law (21); one batched run (the ship axis) with per-ship plant parameters."""
    require(isinstance(n, int) and n >= 1, "montecarlo.n", n, "need at least 1 draw")
    rng = np.random.default_rng(seed)
    J_f = rng.uniform(0.7, 1.3, n)
    mx_f = rng.uniform(0.9, 1.1, n)
    my_f = rng.uniform(0.9, 1.1, n)
    case = yaw_rate_case(f"catamaran-montecarlo/{n}", preset_name, law, omega, t_end=t_end, batch=n,
                         plant={"J_factor": J_f, "m_x_factor": mx_f, "m_y_factor": my_f}, vessel=vessel)
    case.notes.update({"seed": seed, "J_factor": J_f, "m_x_factor": mx_f, "m_y_factor": my_f})
    return case


def montecarlo(n: int = 1000, seed: int = 16, t_end: float = 300.0,
               preset_name: str = "si") -> CatamaranCase:
    """Check 16: 1000 draws, ``si`` (check 16 of note 004-4.12; any preset by name), law (21), ω* = 0.06,
    300 s."""
    return robustness(preset_name, n=n, seed=seed, t_end=t_end)


#: scenario name → builder (note 004-4.7 names); each returns a case or a dict of cases
SCENARIOS = {
    "catamaran-turn": turn,
    "catamaran-steps": steps,
    "catamaran-fixed-angle": fixed_angle,
    "catamaran-sine": lambda preset_name=DEFAULT_PRESET: {"law21": sine(preset_name, 21)},
    "catamaran-heading": lambda preset_name=DEFAULT_PRESET: {"law21": heading(preset_name, 21)},
    "catamaran-actuator": actuator,
    "catamaran-montecarlo": lambda preset_name=DEFAULT_PRESET: {
        "montecarlo": montecarlo(preset_name=preset_name)},
}


def compare(preset_name: str = DEFAULT_PRESET, vessel: dict | None = None) -> dict[str, CatamaranCase]:
    """``catamaran-compare``: FSM laws against the baselines on S3, S4 (ω* = 0.008) and S7."""
    return comparison_cases(preset_name, vessel=vessel)


#: ``catamaran-compare``'s baseline sets: the equal-bandwidth designs, the
#: note 004-4.11.3 baselines kept as reproductions (run keys ``pi``, ``lqr``), or both
BASELINES = ("all", "designed", "reproduction")
#: what each comparison run is (figure legends, docs)
RUN_LABELS = {
    "law20": "FSM law (20)", "law21": "FSM law (21)",
    "place": "pole placement at the FSM poles", "pi_design": "PI designed for the FSM poles",
    "pi": "law (20) with cos δ frozen (reproduction)", "lqr": "LQR of note 004-4.11.3 (reproduction)",
}


def comparison_cases(preset_name: str = DEFAULT_PRESET, t_end_rate: float = 300.0,
                     t_end_heading: float = 600.0, vessel: dict | None = None,
                     baselines: str = "all"):
    """``catamaran-compare``: FSM laws against the baselines on S3 (ω* = 0.08), S4 (ω* = 0.008) and S7
    (K* = 0.8 rad, ω_c = 0.0022 rad/s). Returns ``{"S3/law20": case, ...}``.

    ``baselines``: ``designed`` — pole placement (``place``) and the designed PI (``pi_design``) at
    the FSM's poles −1/T_u, −1/h; ``reproduction`` — the PI of note 004-4.11.3 (law (20) with cos δ frozen,
    ``pi``) and LQR (``lqr``); ``all`` (default) — both, the designed ones first."""
    require(baselines in BASELINES, "case.options.baselines", baselines, f"allowed: {', '.join(BASELINES)}")
    designed, reproduction = baselines in ("all", "designed"), baselines in ("all", "reproduction")
    T_u, h = default_gains(preset_name)

    def model():
        return Catamaran.from_preset(preset_name, **(vessel or {}))

    cases = {}
    for label, w in (("S3", 0.08), ("S4", 0.008)):
        for law in (20, 21):
            cases[f"{label}/law{law}"] = yaw_rate_case(f"compare/{label}/law{law}", preset_name, law, w,
                                                       t_end=t_end_rate, vessel=vessel)
        if designed:
            ref = ConstantRate(w)
            cases[f"{label}/place"] = CatamaranCase(
                f"compare/{label}/place", model(), initial_state(),
                PolePlacementRate(model(), T_u=T_u, h=h, omega_ref=ref), ref, t_end_rate)
            ref = ConstantRate(w)
            cases[f"{label}/pi_design"] = CatamaranCase(
                f"compare/{label}/pi_design", model(), initial_state(),
                DesignedPI(model(), T_u=T_u, h=h, omega_ref=ref), ref, t_end_rate)
        if reproduction:
            ref = ConstantRate(w)
            cases[f"{label}/pi"] = CatamaranCase(f"compare/{label}/pi", model(), initial_state(),
                                                 YawRatePI(model(), T_u=T_u, h=h, omega_ref=ref), ref,
                                                 t_end_rate)
    cases["S7/law21"] = heading(preset_name, 21, 0.8, 0.0022, t_end=t_end_heading, vessel=vessel)
    if designed:
        cap = HeadingCapture(0.8, 0.0022)
        cases["S7/place"] = CatamaranCase("compare/S7/place", model(), initial_state(),
                                          PolePlacementRate(model(), T_u=T_u, h=h, omega_ref=cap), cap,
                                          t_end_heading, heading_target=0.8)
    if reproduction:
        lqr = HeadingLQR(model(), 0.8, 0.0022)
        cases["S7/lqr"] = CatamaranCase("compare/S7/lqr", model(), initial_state(), lqr, None,
                                        t_end_heading, heading_target=0.8)
    return cases


def run_comparison(preset_name: str = DEFAULT_PRESET, **kwargs) -> dict[str, dict]:
    """Run every comparison case; returns run key → comparison metrics (IAE, travel, peak rate...)."""
    from shipgnc.analysis.catamaran_metrics import comparison_metrics

    out = {}
    for key, case in comparison_cases(preset_name, **kwargs).items():
        ds = case.run()
        out[key] = comparison_metrics(ds, case.heading_target)
        out[key]["final_yaw_rate_rad_s"] = float(ds.r[-1])
        out[key]["final_delta_deg"] = math.degrees(float(ds.delta[-1]))
    return out
