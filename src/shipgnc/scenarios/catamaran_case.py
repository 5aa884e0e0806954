"""The older spelling of document 004's comparisons, ``case: {builder, options}``, read as the
equivalent ``runs`` when a scenario is loaded (:class:`~shipgnc.scenarios.schema.Scenario`).

Each builder of :mod:`shipgnc.cases.catamaran` becomes the sections it set up: the controller and
guidance every run shares, and per run what differs — the law, the reference, the plant
(``vessel.thruster``, ``vessel.spread``) or the duration (``simulation.t_end``). The run names are
the builders' keys (``law20@0.008``, ``T2_k1``, ``S3/place``...), so the metrics keep theirs.
Options: ``t_end`` and ``dt`` set ``simulation``; a builder's other options keep their meaning.
"""

from __future__ import annotations

import math

from pydantic import ValidationError

from shipgnc.config_types import format_validation_error

#: each builder's options and their defaults (``t_end``, ``dt``: the simulation section's)
OPTIONS: dict[str, dict[str, object]] = {
    "turn": {"omega": 0.08, "t_end": None, "dt": None, "Ts": None},
    "steps": {"t_end": None},
    "fixed-angle": {"t_end": None, "delta": None},
    "sine": {"law": 21, "reading": "pi", "t_end": None},
    "heading": {"law": 21, "psi_target": 0.8, "omega_c": 0.0022, "t_end": None, "ramp_s": 0.0},
    "actuator": {"omega": 0.08, "t_end": None, "T_a": 2.0, "k_a": 1.0},
    "montecarlo": {"n": 40, "seed": 10, "omega": 0.06, "t_end": None, "law": 21},
    "compare": {"t_end": None, "t_end_rate": 300.0, "baselines": "all"},
}


def _fsm(law: int = 21, **more) -> dict:
    return {"type": "yaw-rate-fsm", "law": law, **more}


def _rate(omega: float) -> dict:
    return {"type": "yaw-rate", "omega": omega}


def _options(case: dict) -> tuple[str, dict]:
    """The builder and its options, checked: a known builder, known options, numbers finite
    (whole where the default is)."""
    from shipgnc.scenarios.sections import CatamaranCaseConfig

    try:
        cfg = CatamaranCaseConfig.model_validate(case)
    except ValidationError as exc:
        raise ValueError(format_validation_error(exc, "case").removeprefix("scenario case: ")
                         .replace("builder", "case.builder", 1)) from None
    allowed = OPTIONS[cfg.builder]
    for key, value in cfg.options.items():
        if key not in allowed:
            raise ValueError(f"case.options.{key}: not an option of builder {cfg.builder!r}; "
                             f"allowed: {', '.join(allowed)}")
        default = allowed[key]
        numeric = isinstance(default, (int, float)) and not isinstance(default, bool)
        if numeric or key in ("t_end", "dt"):
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ValueError(f"case.options.{key} = {value!r}: must be a finite number")
            if isinstance(default, int) and not isinstance(value, int):
                raise ValueError(f"case.options.{key} = {value!r}: must be a whole number")
    return cfg.builder, {**allowed, **cfg.options}


def case_as_runs(data: dict) -> dict:
    """Scenario data with a ``case`` section → the same scenario with ``controller``,
    ``guidance`` and ``runs`` (ValueError naming the field for a bad builder or option)."""
    case = data["case"]
    out = {k: v for k, v in data.items() if k != "case"}
    for name in ("controller", "controllers", "guidance", "runs", "disturbance", "montecarlo"):
        if out.get(name) is not None:
            raise ValueError(f"{name}: a scenario with a case section takes its runs from the case "
                             "builder (set them in case.options); or leave out case and give "
                             "controller and guidance, or runs")
    if not isinstance(case, dict):
        raise ValueError(f"case = {case!r}: expected a mapping with builder and options")
    builder, o = _options(case)
    simulation = dict(out.get("simulation") or {})
    for key in ("t_end", "dt"):
        if o.get(key) is not None:
            simulation[key] = o[key]
    out["simulation"] = simulation
    vessel = dict(out.get("vessel") or {})
    runs: dict[str, dict] = {}
    if builder == "turn":
        out["guidance"] = _rate(o["omega"])
        runs = {f"law{law}": {"controller": _fsm(law, Ts=o["Ts"])} for law in (20, 21)}
    elif builder == "steps":
        runs = {f"law{law}@{w:g}": {"controller": _fsm(law), "guidance": _rate(w)}
                for w in (0.008, 0.00072) for law in (20, 21)}
    elif builder == "fixed-angle":
        delta = o["delta"]
        runs = {"fixed": {"controller": {"type": "fixed-angle", "delta_rad": delta}},
                "law20_same_angle": {"controller": _fsm(20),
                                     "guidance": {"type": "steady-turn", "delta_rad": delta}},
                "law20@0.00072": {"controller": _fsm(20), "guidance": _rate(0.00072)}}
    elif builder == "sine":
        out["controller"] = _fsm(o["law"])
        out["guidance"] = {"type": "yaw-rate-sine", "reading": o["reading"]}
    elif builder == "heading":
        out["controller"] = _fsm(o["law"])
        out["guidance"] = {"type": "heading-capture", "psi_target_rad": o["psi_target"],
                           "omega_c": o["omega_c"], "ramp_s": o["ramp_s"]}
    elif builder == "actuator":
        from shipgnc.cases.catamaran import ACTUATOR_RUNS  # S8's true thrusters
        out["guidance"] = _rate(o["omega"])
        runs = {"ideal": {"controller": _fsm(21)}}
        for key, (T_t, k_t) in ACTUATOR_RUNS.items():
            runs[key] = {"vessel": {"thruster": {"T_t": T_t, "k_t": k_t}},
                         "controller": _fsm(21, T_a=o["T_a"], k_a=o["k_a"])}
    elif builder == "montecarlo":
        vessel["spread"] = {"n": o["n"], "seed": o["seed"]}
        out["controller"] = _fsm(o["law"])
        out["guidance"] = _rate(o["omega"])
    else:
        runs = _compare(o, simulation)
        if out.get("metrics", "catamaran") == "catamaran":
            out["metrics"] = "catamaran-comparison"
    out["vessel"] = vessel
    if runs:
        out["runs"] = runs
    return out


def _compare(o: dict, simulation: dict) -> dict:
    """``catamaran-compare``'s runs: S3 (ω* = 0.08) and S4 (ω* = 0.008) for ``t_end_rate`` (at
    most ``simulation.t_end``), S7 (K* = 0.8 rad at ω_c = 0.0022 rad/s) for ``simulation.t_end``;
    the FSM laws and the ``baselines``: ``designed`` (pole placement, designed PI),
    ``reproduction`` (the PI and LQR of note 004-4.11.3) or ``all``."""
    from shipgnc.cases.catamaran import BASELINES

    if o["baselines"] not in BASELINES:
        raise ValueError(f"case.options.baselines = {o['baselines']!r}: allowed: "
                         f"{', '.join(BASELINES)}")
    designed, reproduction = o["baselines"] in ("all", "designed"), o["baselines"] in ("all", "reproduction")
    t_end = simulation.get("t_end")
    rate_end = o["t_end_rate"] if not isinstance(t_end, (int, float)) else min(o["t_end_rate"], t_end)
    capture = {"type": "heading-capture", "psi_target_rad": 0.8, "omega_c": 0.0022}
    runs = {}
    for label, w in (("S3", 0.08), ("S4", 0.008)):
        rate = {"simulation": {"t_end": rate_end}, "guidance": _rate(w)}
        for law in (20, 21):
            runs[f"{label}/law{law}"] = {**rate, "controller": _fsm(law)}
        if designed:
            runs[f"{label}/place"] = {**rate, "controller": {"type": "yaw-rate-place"}}
            runs[f"{label}/pi_design"] = {**rate, "controller": {"type": "yaw-rate-pi-design"}}
        if reproduction:
            runs[f"{label}/pi"] = {**rate, "controller": {"type": "yaw-rate-pi"}}
    runs["S7/law21"] = {"guidance": capture, "controller": _fsm(21)}
    if designed:
        runs["S7/place"] = {"guidance": capture, "controller": {"type": "yaw-rate-place"}}
    if reproduction:
        runs["S7/lqr"] = {"guidance": None, "controller": {"type": "heading-lqr", "psi_target_rad": 0.8,
                                                           "omega_c": 0.0022}}
    return runs
