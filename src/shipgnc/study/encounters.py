"""The encounter sweep: many encounters, each a member of one batched, compiled run, scored.

Each member is one situation (:mod:`shipgnc.study.trafficgen`: the standard set, its Monte Carlo
variants, or trafficgen files) met with one avoidance method. The own ship (a catalogue vessel under
its heading autopilot, :data:`OWN_SHIP`) starts at the origin on course 0 — a situation read from a
file is turned about the own ship's start so that its course is 0, which changes no relative
geometry — and follows its nominal path north through the collision-avoidance guidance
(:class:`shipgnc.guidance.colav.ColavGuidance`); the avoidance method is a per-member parameter, so
every method runs in the same batch. Members whose own ship sails at the same speed share a batch
(the vessel model depends on its speed).

Scores per member: :mod:`shipgnc.study.encounter_scores` (minimum range, collision, distance and
time lost), plus the COLREG situation at t = 0 (:func:`shipgnc.colav.colreg.situations`) and the
closed-form CPA of the initial motion (:func:`shipgnc.colav.geometry.encounter_geometry`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from shipgnc.colav.tracks import TargetTrack
from shipgnc.errors import ConfigError
from shipgnc.study import trafficgen as tg

#: the own ship of the sweep: van Amerongen's frigate (L = 100 m) at 9 m/s under the PD heading
#: autopilot (Kp = 1, Kd = 20 s: a phase margin over 60° on its Norrbin model)
OWN_SHIP = {"vessel": {"model": "frigate", "speed_mps": 9.0},
            "controller": {"type": "course", "variant": "pd", "Kp": 1.0, "Kd": 20.0}}
#: the duration of every encounter [s] and the step [s]
DURATION, DT = 1200.0, 0.5
#: the ship domain of the scores [m]
SAFETY_RADIUS = 200.0
#: SB-MPC for the own ship: its safety distance scaled to the ships (the ship domain), course offsets
#: only (the frigate model holds its speed); the rest the paper's defaults
SBMPC = {"d_safe": SAFETY_RADIUS, "speed_factors": [1.0]}
#: velocity obstacles likewise: the ship domain as the combined safety radius, course offsets only
VO = {"radius": SAFETY_RADIUS, "speed_factors": [1.0]}
#: the nominal path: north from the origin, long enough for any encounter
PATH_LENGTH = 40_000.0
#: the avoidance horizon of both methods [s]: SB-MPC's prediction horizon T and the velocity
#: obstacles' horizon, their defaults (the sweep keeps them)
HORIZON = 100.0


def sweep_compliance(closing_speed: float):
    """The compliance thresholds (:class:`shipgnc.colav.compliance.ComplianceConfig`) of a sweep
    member from the ship domain R = :data:`SAFETY_RADIUS` and the avoidance horizon
    T = :data:`HORIZON`, ``closing_speed`` v [m/s] the magnitude of the relative velocity at t = 0:

    r_collision = R (a collision is a CPA inside the domain, as the ``collision`` score counts it),
    r_near_miss = 2 R, r_safe = 4 R; r_early = R + v T — the range at which a collision course
    enters the horizon, the earliest an avoidance method can act — and r_late = R + v T/2, half the
    horizon left. Fixed ranges (1 nm, 0.5 nm) would call every action in a slow overtaking late:
    closing at 4.5 m/s, the collision enters a 100 s horizon at 650 m."""
    from shipgnc.colav.compliance import ComplianceConfig

    R, v = SAFETY_RADIUS, max(float(closing_speed), 1e-3)
    return ComplianceConfig(r_collision=R, r_near_miss=2 * R, r_safe=4 * R,
                            r_early=R + v * HORIZON, r_late=R + v * HORIZON / 2)


@dataclass(frozen=True)
class Member:
    """One member of a sweep: a situation (own course 0 at the origin) and a method."""

    situation: tg.Situation
    method: str
    mc: int = 0
    beta_deg: float = math.nan
    spec: tg.EncounterSpec | None = None  # the generated variant (None: read from a file)
    rotation: float = 0.0  # [rad] the situation as its file gave it is this turn of ``situation``
    index: int = 0  # the situation's place in the sweep (its type, or its file): with ``mc`` the AIS draw

    @property
    def draw(self) -> tuple[int, int]:
        """(situation, variant): the key of the member's AIS reports (:func:`seen_tracks`), so
        that every method meets the same reports of the same encounter."""
        return (self.index, self.mc)


@dataclass
class SweepResult:
    members: list[Member]
    scores: dict[str, np.ndarray]
    results: list = field(default_factory=list)  # (member indices, xarray Dataset) per batch
    seconds: float = 0.0
    ship_steps: int = 0


def rotated(track: TargetTrack, angle: float) -> TargetTrack:
    """``track`` turned by ``angle`` [rad] about the origin (clockwise positive, NED)."""
    c, s = math.cos(angle), math.sin(angle)
    return replace(track, north=c * track.north - s * track.east, east=s * track.north + c * track.east,
                   v_north=c * track.v_north - s * track.v_east,
                   v_east=s * track.v_north + c * track.v_east)


def own_frame(sit: tg.Situation) -> tg.Situation:
    """The situation turned so that the own ship's course is 0."""
    if sit.own_course == 0.0:
        return sit
    return replace(sit, own_course=0.0,
                   targets=tuple(rotated(t, -sit.own_course) for t in sit.targets))


def standard_members(methods, *, mc: int = 0, seed: int = 0, own_speed: float = 9.0,
                     specs=tg.STANDARD) -> list[Member]:
    """The standard set (``mc`` = 0) or ``mc`` perturbed variants of each of its situations
    (:func:`shipgnc.study.trafficgen.variants`, each classifying as its type), each met with every
    method. Each situation type draws from its own child of ``seed``
    (``SeedSequence(seed).spawn``), so the variants of ``mc`` = 5 are the first five of 10."""
    children = np.random.SeedSequence(seed).spawn(len(specs))
    members = []
    for i, (spec, child) in enumerate(zip(specs, children, strict=True)):
        variants = [spec] if mc == 0 else tg.variants(spec, np.random.default_rng(child), mc,
                                                     own_speed)
        for k, variant in enumerate(variants):
            sit = tg.parse(tg.situation_dict(variant, own_speed), variant.title)
            sit = replace(sit, encounter_type=spec.encounter_type, title=spec.title)
            for method in methods:
                members.append(Member(sit, method, k, variant.beta_deg, variant, index=i))
    return members


def file_members(paths, methods) -> list[Member]:
    """Situations read from trafficgen files, each met with every method."""
    from shipgnc.units import KNOT
    from shipgnc.vessels.frigate import SPEED_RANGE

    low, high = SPEED_RANGE  # the own ship's (OWN_SHIP) valid speeds
    members = []
    for i, path in enumerate(paths):
        given = tg.read(path)
        sit = own_frame(given)
        if not low <= sit.own_speed <= high:
            raise ConfigError(f"{path}: ownShip.initial.sog = {sit.own_speed / KNOT:g} kn (own ship "
                              f"sails {low / KNOT:.1f}–{high / KNOT:.1f} kn)")
        bearing = _bearing_deg(sit)
        for method in methods:
            members.append(Member(sit, method, 0, bearing, rotation=given.own_course, index=i))
    return members


def _bearing_deg(sit: tg.Situation) -> float:
    t = sit.targets[0]
    return math.degrees(math.atan2(t.east[0], t.north[0]))


def colav_guidance(g, scenario):
    """The ``guidance: {type: colav}`` section's :class:`~shipgnc.guidance.colav.ColavGuidance`
    (the registry's builder): its targets and those of its AIS log, placed against the own ship's
    start (a target inside the safety radius at t = 0 is refused, naming it)."""
    from shipgnc.guidance.colav import ColavGuidance, check_clear
    from shipgnc.guidance.los import LOSGuidance
    from shipgnc.paths import WaypointPath

    speed = g.speed if g.speed is not None else getattr(scenario.vessel, "speed_mps", None)
    if speed is None:
        raise ConfigError(f"guidance.speed: vessel model {scenario.vessel.model!r} has no "
                          "straight-run speed; give the nominal speed in m/s")
    los = LOSGuidance(WaypointPath(g.waypoints), lookahead=g.lookahead, speed=speed,
                      switch_radius=g.switch_radius)
    init = scenario.simulation.initial_state if scenario.simulation is not None else None
    own = (init.north, init.east) if init is not None else (0.0, 0.0)
    tracks = []
    for j, target in enumerate(g.targets):
        track = _target(target, j)
        check_clear(track, own, g.safety_radius, f"guidance.targets[{j}]")
        tracks.append(track)
    if g.ais_log is not None:
        from shipgnc.ais.logs import read_log

        logged, _ = read_log(g.ais_log.path, origin=g.ais_log.origin, untimed=g.ais_log.untimed)
        for track in logged:
            if track.source == "ais-own":
                continue
            check_clear(track, own, g.safety_radius, f"guidance.ais_log: MMSI {track.mmsi}")
            tracks.append(track)
    seen = None
    if g.awareness == "ais":
        seen = seen_tracks(tracks, g.ais, t_end=scenario.simulation.t_end,
                           origin=g.ais_log.origin if g.ais_log and g.ais_log.origin else (0.0, 0.0))
    return ColavGuidance(los, tracks, method=g.method, configs={"sbmpc": g.sbmpc, "vo": g.vo},
                         decision_interval=g.decision_interval, seen=seen)


def seen_tracks(tracks, ais, *, t_end: float, member: int | tuple = 0, origin=(0.0, 0.0)) -> list:
    """The ``tracks`` as the own ship hears them through AIS set by ``ais`` (a
    :class:`~shipgnc.scenarios.sections.AISAwarenessConfig`) up to ``t_end`` [s]
    (:func:`shipgnc.ais.reporting.seen_tracks`; ``member`` the key of the draw)."""
    from shipgnc.ais.reporting import seen_tracks as observed

    return observed(tracks, seed=ais.seed, t_end=t_end, member=member, origin=origin,
                    position_noise_m=ais.position_noise_m, dropout=ais.dropout,
                    ais_class=ais.ais_class, anchored=ais.anchored, every=ais.interval)


def _target(target, j: int):
    """``guidance.targets[j]`` as a track (kinematic) or a vessel target (its speed checked against
    its model's range, naming the field)."""
    if target.vessel is None:
        return target.track(label=f"target {j + 1}")
    if target.vessel.model == "frigate":
        from shipgnc.vessels.frigate import SPEED_RANGE

        low, high = SPEED_RANGE
        if not low <= target.speed <= high:
            raise ConfigError(f"guidance.targets[{j}].speed = {target.speed:g} m/s is outside the "
                              f"frigate model's valid range {low:g}–{high:g} m/s (van Amerongen "
                              "1982); use vessel: {model: nomoto, K: ..., T: ...}")
    return target.vessel_target(label=f"target {j + 1}", where=f"guidance.targets[{j}]")


def check_members(members: list[Member], safety_radius: float = SAFETY_RADIUS) -> None:
    """A target inside the safety radius at t = 0: a one-line ConfigError naming it."""
    from shipgnc.guidance.colav import check_clear

    for member in members:
        for j, track in enumerate(member.situation.targets):
            check_clear(track, (0.0, 0.0), safety_radius,
                        f"situation {member.situation.title}: targetShips[{j}]")


def own_scenario(own_speed: float, method: str):
    """The scenario of the own ship (validated like a scenario file)."""
    from shipgnc.scenarios.schema import validate

    return validate({
        "name": "encounter", "metrics": "colav",
        "vessel": {**OWN_SHIP["vessel"], "speed_mps": own_speed},
        "simulation": {"dt": DT, "t_end": DURATION,
                       "initial_state": {"north": 0.0, "east": 0.0, "psi_deg": 0.0}},
        "controller": OWN_SHIP["controller"],
        "guidance": {"type": "colav", "method": method, "waypoints": [[0.0, 0.0], [PATH_LENGTH, 0.0]],
                     "lookahead": 1000.0, "safety_radius": SAFETY_RADIUS, "sbmpc": SBMPC,
                     "vo": VO}},
                    "encounter sweep")


def run_members(members: list[Member], *, backend: str = "auto", log_every: int = 10,
                keep_results: bool = False, compliance: bool = True, ais=None) -> SweepResult:
    """Run every member (one batch per own-ship speed) and score it (``compliance``: with the
    COLREG compliance scores, from the log at every ``log_every``-th step). ``ais``: an
    :class:`~shipgnc.scenarios.sections.AISAwarenessConfig` — the avoidance sees the targets
    through AIS (:func:`seen_tracks`, each member drawing by its :attr:`Member.draw` — seed,
    situation, variant, then target — so that every method meets the same reports of an encounter
    and a member run again alone sees what it saw in the sweep), scored against the truth."""
    import time

    from shipgnc.colav.compliance import SCORES
    from shipgnc.guidance.colav import ColavGuidance
    from shipgnc.scenarios.runner import build
    from shipgnc.sim.simulator import simulate
    from shipgnc.study.encounter_scores import COLAV_KEYS, batch_arrays, compliance_arrays

    check_members(members)
    speeds = sorted({round(m.situation.own_speed, 9) for m in members})
    keys = (*COLAV_KEYS, "situation", "d_cpa0_m", "t_cpa0_s",
            *((*SCORES, "compliance") if compliance else ()))
    scores = {key: np.full(len(members), np.nan) for key in keys}
    out = SweepResult(members, scores)
    start = time.perf_counter()
    for speed in speeds:
        index = [i for i, m in enumerate(members) if round(m.situation.own_speed, 9) == speed]
        methods = [members[i].method for i in index]
        scenario = own_scenario(speed, methods[0])
        setup = build(scenario)
        g0 = setup.guidance
        g = scenario.guidance
        seen = None if ais is None else [
            seen_tracks(members[i].situation.targets, ais, t_end=DURATION,
                        member=members[i].draw,
                        origin=members[i].situation.origin) for i in index]
        guidance = ColavGuidance(g0.los, [list(members[i].situation.targets) for i in index],
                                 methods=methods, configs={"sbmpc": g.sbmpc, "vo": g.vo},
                                 decision_interval=g.decision_interval, seen=seen)
        x0 = np.tile(setup.x0, (len(index), 1))
        result = simulate(setup.model, x0, t_end=DURATION, dt=DT, controller=setup.controller,
                          actuator=setup.actuator, guidance=guidance, u0=setup.u0,
                          log_every=log_every, backend=backend, on_divergence="mask")
        result = guidance.add_targets(result)
        out.ship_steps += len(index) * round(DURATION / DT)
        arrays = batch_arrays(result, guidance, SAFETY_RADIUS)
        codes = situation_codes(members, index)
        arrays.update(initial_scores(members, index, codes))
        if compliance:
            closing = [math.hypot(m.situation.targets[0].v_north[0] - m.situation.own_speed,
                                  m.situation.targets[0].v_east[0])
                       for m in (members[i] for i in index)]  # own course 0 at t = 0
            arrays.update(compliance_arrays(result, [members[i].situation.targets for i in index],
                                            codes,
                                            [sweep_compliance(v) for v in closing]))
        for key, value in arrays.items():
            scores[key][index] = value
        if keep_results:
            out.results.append((index, result))
    out.seconds = time.perf_counter() - start
    return out


def initial_scores(members, index, codes=None) -> dict[str, np.ndarray]:
    """The COLREG situation (code of :data:`shipgnc.colav.colreg.SITUATIONS`) and the closed-form
    CPA at t = 0 towards each member's first target (``codes``: :func:`situation_codes`, if
    already computed)."""
    from shipgnc.colav.geometry import encounter_geometry

    own = np.array([[0.0, 0.0, members[i].situation.own_course, members[i].situation.own_speed]
                    for i in index])
    target = np.array([[t.north[0], t.east[0], t.v_north[0], t.v_east[0]]
                       for t in (members[i].situation.targets[0] for i in index)])
    geo = encounter_geometry(own, target)
    codes = situation_codes(members, index) if codes is None else codes
    return {"situation": codes[:, 0].astype(float),
            "d_cpa0_m": geo["d_cpa"], "t_cpa0_s": geo["t_cpa"]}


def situation_codes(members, index) -> np.ndarray:
    """COLREG situation codes at t = 0 of every target of the members ``index`` (member, target)."""
    from shipgnc.colav.colreg import situations

    n_max = max(len(members[i].situation.targets) for i in index)
    codes = np.zeros((len(index), n_max), dtype=int)
    for k, i in enumerate(index):
        sit = members[i].situation
        own = [0.0, 0.0, sit.own_course, sit.own_speed]
        for j, t in enumerate(sit.targets):
            codes[k, j] = int(situations(own, [t.north[0], t.east[0], t.v_north[0], t.v_east[0]]))
    return codes


def summary(result: SweepResult) -> list[dict]:
    """One row per (COLREG situation computed at t = 0, method): the members' labels
    (``encounter``), how many of them carry a label of another situation (``label_disagrees``,
    :data:`shipgnc.study.trafficgen.SITUATION_OF`), members, collisions, median and least minimum
    range, median time lost, median compliance (the least score of the rules invoked, after
    Woerner)."""
    from shipgnc.colav.colreg import SITUATIONS

    s = result.scores
    computed = [SITUATIONS[int(c)] if np.isfinite(c) else "unknown" for c in s["situation"]]
    rows = []
    keys = dict.fromkeys((computed[i], m.method) for i, m in enumerate(result.members))
    for kind, method in keys:
        idx = [i for i, m in enumerate(result.members) if computed[i] == kind and m.method == method]
        labels = [result.members[i].situation.encounter_type or result.members[i].situation.title
                  for i in idx]
        disagree = sum(1 for label in labels if label in tg.SITUATION_OF
                       and tg.SITUATION_OF[label] != kind)
        rng = s["min_range_m"][idx]
        rows.append({"situation": kind, "encounter": "/".join(dict.fromkeys(labels)),
                     "label_disagrees": disagree, "method": method, "members": len(idx),
                     "collisions": int(np.nansum(s["collision"][idx])),
                     "median_min_range_m": float(np.nanmedian(rng)),
                     "min_range_m": float(np.nanmin(rng)),
                     "median_time_lost_s": float(np.nanmedian(s["time_lost_s"][idx]))})
        if "compliance" in s:
            c = s["compliance"][idx]
            rows[-1]["median_compliance"] = float(np.nanmedian(c)) if np.isfinite(c).any() \
                else float("nan")
    return rows


def member_rows(result: SweepResult) -> list[dict]:
    """One row per member with its scores."""
    from shipgnc.colav.colreg import SITUATIONS

    rows = []
    for i, m in enumerate(result.members):
        row = {"member": i, "title": m.situation.title, "encounter": m.situation.encounter_type,
               "method": m.method, "mc": m.mc, "beta_deg": m.beta_deg,
               "relative_speed": m.spec.relative_speed if m.spec else math.nan,
               "vector_time_s": m.spec.vector_time_s if m.spec else math.nan}
        for key, value in result.scores.items():
            row[key] = SITUATIONS[int(value[i])] if key == "situation" else float(value[i])
        rows.append(row)
    return rows


def check_methods(methods) -> list[str]:
    """The ``--method`` list, each a known avoidance method (ConfigError naming the bad one)."""
    from shipgnc.guidance.colav import METHODS

    out = []
    for method in methods:
        if method not in METHODS:
            raise ConfigError(f"--method {method!r}: unknown avoidance method; allowed: "
                              f"{', '.join(METHODS)}")
        out.append(method)
    return out
