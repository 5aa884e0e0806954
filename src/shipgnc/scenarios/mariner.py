"""Document 000's scenario pieces: the builders of the Mariner, its path frame (note 000-A4, a
guidance), its path controllers and disturbances, named by the component registry
(:mod:`shipgnc.scenarios.components`) and called by :func:`shipgnc.scenarios.runner.build` like any
vessel's, from a validated :class:`~shipgnc.scenarios.schema.Scenario`.

The scenario file keeps the document's units where it names them (``*_nm``, ``*_rad_min2``,
``*_per_min``); everything is converted to SI here, at the boundary.
"""

from __future__ import annotations

import numpy as np

from shipgnc.paths import WaypointPath
from shipgnc.scenarios.schema import Scenario
from shipgnc.units import MINUTE, NAUTICAL_MILE, deg


def vessel(scenario: Scenario):
    """The Mariner model of the scenario and its steering machine (35°, 3.8°/s by default)."""
    from shipgnc.models.mariner import MarinerWitOppe, rudder

    v = scenario.vessel
    model = MarinerWitOppe.from_paper_units(**v.params_paper)
    changes = {"delta_max": deg(v.rudder_max_deg)}
    if v.rudder_rate_deg_s is not None:
        changes["delta_rate"] = deg(v.rudder_rate_deg_s)
    model = MarinerWitOppe(params=model.params.with_(**changes))
    return (model, rudder(model.params, rate_limit=v.rudder_rate_deg_s is not None,
                          rate_mode=v.rudder_rate_mode), None)


def mariner_path(g) -> WaypointPath:
    """The path of note 000-A4 from the printed points [nm] and their ``reading``, in NED [m]."""
    points = np.asarray(g.points_nm, dtype=float)
    if g.reading == "literal":
        north_east = points
    else:  # the printed pairs are (y, x): plot-horizontal (east), then plot-vertical (north)
        north_east = points[:, ::-1]
        if g.reading == "text":  # the third leg is a half-line parallel to OX from the third point
            north_east = np.vstack([north_east[:3], north_east[2] + np.array([1.0, 0.0])])
    return WaypointPath(north_east * NAUTICAL_MILE)


def path_guidance(g):
    """The path frame of note 000-A4's path (:class:`~shipgnc.guidance.path.PathGuidance`): the
    references y_r, ψ_r, π_p the path controllers read."""
    from shipgnc.guidance.path import PathGuidance

    return PathGuidance(mariner_path(g))


def lqr_controller(cfg, model, scenario: Scenario):
    """Document 000's LQR (note 000-0.4): the printed gain ``K_paper``, or designed from Q, R."""
    from shipgnc.control.lqr import PAPER_Q, PAPER_R, PathLQR, design_lqr, gain_to_si

    p = model.params
    if cfg.K_paper is not None:
        K = gain_to_si(cfg.K_paper)
    else:
        Q = PAPER_Q if cfg.Q is None else cfg.Q
        K = design_lqr(p, Q=Q, R=PAPER_R if cfg.R is None else cfg.R).K_si
    return PathLQR(K, Ts=cfg.Ts, delta_max=p.delta_max, anti_windup=cfg.anti_windup)


def _known_disturbance(cfg, scenario: Scenario) -> dict:
    """b_r, d_y and the current's frame handed to a law that ``knows_disturbance`` (A13)."""
    d = scenario.disturbance
    if not cfg.knows_disturbance or d is None:
        return {}
    return {"b_r": d.b_r, "d_y": d.d_y, "current_frame": d.current_frame}


def fl_controller(cfg, model, scenario: Scenario):
    """Document 000's output feedback linearisation (note 000-0.5), l = ``lookahead_nm``."""
    from shipgnc.control.feedback_linearization import OutputFL

    p = model.params
    return OutputFL(p, Ts=cfg.Ts, lookahead=cfg.lookahead_nm * NAUTICAL_MILE,
                    k1=cfg.k1_per_min2 / MINUTE**2, k2=cfg.k2_per_min / MINUTE,
                    delta_max=p.delta_max, **_known_disturbance(cfg, scenario))


def los_fl_controller(cfg, model, scenario: Scenario):
    """Document 000's (integral) LOS feeding a feedback-linearised yaw loop (note 000-0.5)."""
    from shipgnc.control.feedback_linearization import LOSFL

    p = model.params
    return LOSFL(p, Ts=cfg.Ts, delta_los=cfg.delta_nm * NAUTICAL_MILE,
                 kp=cfg.kp_per_min2 / MINUTE**2, kd=cfg.kd_per_min / MINUTE,
                 delta_max=p.delta_max,
                 integral_gain=cfg.integral_gain * NAUTICAL_MILE / MINUTE,
                 rate_from_positions=not cfg.knows_disturbance, **_known_disturbance(cfg, scenario))


def disturbance(d, path: WaypointPath, current=None):
    """The force part of note 000-0.6's disturbance (A9–A11), in SI: b_r and the optional wave
    noise on ṙ, with document 000's cross current d_y
    (:class:`~shipgnc.environment.current.CrossCurrent`, across the active leg of ``path`` or
    along east) — :class:`~shipgnc.models.mariner.MarinerDisturbance` — or, when the scenario has
    a ``current`` section (``current`` not None: an earth-fixed field, composed beside this part by
    :class:`~shipgnc.environment.current_field.CurrentDisturbance` as on the other vessels), the
    yaw channel alone (:class:`~shipgnc.models.mariner.MarinerYawDisturbance`; d_y must be 0)."""
    from shipgnc.environment.current import CrossCurrent
    from shipgnc.environment.filtered_noise import SecondOrderNoise
    from shipgnc.errors import require
    from shipgnc.models.mariner import MarinerDisturbance, MarinerYawDisturbance

    waves = None
    if d.wave_sigma > 0:  # the literal σ_w, or calibrated to a heading RMS
        waves = SecondOrderNoise(d.wave_sigma, d.wave_period, d.wave_zeta)
    if current is not None:
        require(d.d_y_nm_min == 0.0, "disturbance.d_y_nm_min", d.d_y_nm_min,
                "must be 0 with a current section (give the current once)")
        return MarinerYawDisturbance(d.b_r, waves)
    return MarinerDisturbance(d.b_r, current=CrossCurrent(d.d_y, path, frame=d.current_frame),
                              waves=waves)


def disturbance_section(d, scenario: Scenario):
    """The ``disturbance: {type: mariner}`` section's builder: :func:`disturbance` on the
    scenario's path (its ``guidance`` section) and ``current`` section."""
    return disturbance(d, mariner_path(scenario.guidance), scenario.current)


def check(scenario: Scenario) -> None:
    """The Mariner's own scenario rules (its registry entry's ``check``): the sway is algebraic
    (initial v = 0); with a ``current`` section one current only (d_y = 0) and no oracle
    controller (it knows b_r and d_y, not the current)."""
    if scenario.simulation.initial_state.v != 0:
        raise ValueError("simulation.initial_state.v: the Mariner's sway is algebraic "
                         "(v = r1 r + r2 r^3); leave v at 0")
    if scenario.current is None:
        return
    d = scenario.disturbance
    if d is not None and d.type == "mariner" and d.d_y_nm_min != 0.0:
        raise ValueError(f"disturbance.d_y_nm_min = {d.d_y_nm_min!r} with a current section: "
                         f"give the current once — set d_y_nm_min: 0 (document 000's cross "
                         f"current) or leave the current section out")
    for name, ctrl in scenario.variants.items():
        if getattr(ctrl, "knows_disturbance", False):
            raise ValueError(f"{scenario.where(name)}.knows_disturbance = true with a current "
                             f"section: the document's oracle law knows b_r and d_y only, not the "
                             f"current; set knows_disturbance: false (integral LOS for los-fl)")


def initial_states(scenario: Scenario, seed: int) -> np.ndarray:
    """x0 = (north, east, ψ, u, r): one state, or ``montecarlo.runs`` states with random offsets
    (drawn from a stream of their own, so the waves of the same seed are not shifted)."""
    init = scenario.simulation.initial_state
    x0 = np.array([init.north, init.east, deg(init.psi_deg), init.u, deg(init.r_deg_s)])
    mc = scenario.montecarlo
    if mc is None:
        return x0
    rng = np.random.default_rng(np.random.SeedSequence(seed).spawn(1)[0])
    batch = np.tile(x0, (mc.runs, 1))
    batch[:, 1] += rng.uniform(*mc.east_offset_nm, size=mc.runs) * NAUTICAL_MILE
    batch[:, 2] += deg(rng.uniform(*mc.heading_offset_deg, size=mc.runs))
    return batch
