"""One chunk of a study: a slice of members at one grid point, run as one batch.

A chunk is the unit of work a backend hands out (thousands of ships per task, not one task per
ship). :func:`run_chunk` is a pure function of the study and the chunk: it builds the scenario of
the grid point, stacks the members' initial states, gives each member its own random stream, runs
the one simulation loop once for the whole slice and scores every member with the scenario's
metrics. The result depends on the members' indices only, not on the slice they came in.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from shipgnc.errors import ConfigError
from shipgnc.models.base import names
from shipgnc.models.per_ship import PerShipModel
from shipgnc.streams import MemberStreams
from shipgnc.study.plant import check_plant, member_params, member_plant, param_variables
from shipgnc.study.spec import PERTURB_UNITS, PERTURBABLE, Study


@dataclass(frozen=True)
class Chunk:
    """Members ``start .. stop-1`` of grid point ``point`` (an index into ``Study.points``),
    controller ``variant`` (None: the scenario's only one)."""

    point: int
    start: int
    stop: int
    variant: str | None = None

    @property
    def size(self) -> int:
        return self.stop - self.start


#: the members × steps, over every grid point of the same plan (:func:`own_loop_pays`), from
#: which a study's chunks are scored in a loop of their plan's own
#: (:func:`shipgnc.sim.scored.score_step_source`: boat-autopilot's heading steps cost ≈ 10
#: instead of ≈ 31 ns per ship-step), compiled once per distinct plan (≈ 15–20 s; another
#: schedule, or a t_end that changes the plan, compiles again) and kept in the disk cache; a
#: smaller study runs in the combination's scored loop, whose step reads any plan at run time, so
#: that runs of other schedules or durations do not each compile a loop. A cold first run
#: compiles one loop either way. 10⁷ ship-steps: ``shipgnc sweep boat-autopilot --mc 10000``
#: (1.4·10⁷), whose loop works ≈ 2 CPU-seconds.
UNROLLED_SHIP_STEPS = 10_000_000


def plan_chunks(study: Study, variants: list[str] | None, chunk_size: int) -> list[Chunk]:
    """Every chunk of the study, grid point by grid point, at most ``chunk_size`` members each."""
    if not isinstance(chunk_size, (int, np.integer)) or isinstance(chunk_size, bool) or chunk_size < 1:
        raise ConfigError(f"--chunk-size {chunk_size!r}: must be an integer >= 1")
    out = []
    for p in range(len(study.points)):
        for variant in variants or [None]:
            for start in range(0, study.members, chunk_size):
                out.append(Chunk(p, start, min(start + chunk_size, study.members), variant))
    return out


def check_sweepable(scenario) -> None:
    """Refuse the scenarios whose runs do not go through the generic loop of one batch, and the
    integrator whose result depends on the batch."""
    if scenario.route is not None:  # its sailed runs sweep; its routing problem has no members
        if scenario.sail is None:
            raise ConfigError(f"scenario {scenario.name!r} is a routing problem (document 002) "
                              "without a sail section: nothing is simulated, so there are no "
                              "members to sweep; sweep a scenario that sails its route (e.g. "
                              "zermelo-sail), or solve this one with shipgnc run")
        return
    if getattr(scenario.vessel, "spread", None) is not None:
        raise ConfigError(f"scenario {scenario.name!r} is itself one batched run of plant draws "
                          "(vessel.spread: its ships take the batch axis a study gives its members): "
                          "sweep catamaran-turn with --mc and --perturb instead")
    if scenario.runs is not None:  # a study runs every member of every run for simulation.t_end
        sim = scenario.simulation
        own = {name: run.simulation for name, run in scenario.run_scenarios().items()
               if (run.simulation.t_end, run.simulation.dt) != (sim.t_end, sim.dt)}
        if own:
            name, first = next(iter(own.items()))
            fix = " ".join(f"--set runs.{n}.simulation.t_end={sim.t_end:g}" for n in own)
            if scenario._spelled_case:  # document 004's comparison builder: its yaw-rate runs
                fix = f"--set case.options.t_end_rate={sim.t_end:g}"
            raise ConfigError(f"scenario {scenario.name!r}: run {name!r} lasts {first.t_end:g} s at "
                              f"dt = {first.dt:g} s, the scenario simulation.t_end = {sim.t_end:g} s "
                              f"at dt = {sim.dt:g} s, and a study runs every member for one "
                              f"duration: {fix} to sweep it")
    if scenario.montecarlo is not None:
        raise ConfigError(f"scenario {scenario.name!r} has its own montecarlo section; sweep the "
                          "single-run scenario with --mc and --perturb instead")
    if scenario.simulation.integrator != "rk4":
        raise ConfigError(f"simulation.integrator = {scenario.simulation.integrator!r}: a study needs "
                          "'rk4' (solve_ivp picks one step size for the whole batch, so a member's "
                          "result would depend on the chunk it shares)")


def check_perturbable(perturb, model, x0=None, flag: str = "--perturb") -> None:
    """Every perturbed field must be a state of ``model``; with the scenario's ``x0``, a uniform
    offset must keep every member inside the model's state range (checked before any work).
    Plant parameters: :func:`shipgnc.study.plant.check_plant`."""
    check_plant(perturb, model, flag)
    state_names = names(model.states)
    limits = np.asarray(model.state_limits, dtype=float)
    for p in (p for p in perturb if p.param is None):
        state, scale = PERTURBABLE[p.field]
        if state not in state_names:
            raise ConfigError(f"{flag} {p.field}: the {type(model).__name__} has no state "
                              f"{state!r} (states: {', '.join(state_names)})")
        if x0 is not None and p.kind == "uniform":
            i = state_names.index(state)
            for bound in (p.low, p.high):
                _check_range(f"{flag} {p}", "members", p.field, float(x0[i]) + scale * bound,
                             limits[i], scale)


def _check_range(what: str, who: str, field: str, value: float, limit: float, scale: float) -> None:
    """A start ``value`` [SI] beyond ``limit`` is a ConfigError in the field's own unit."""
    if abs(value) > limit:
        unit = PERTURB_UNITS[field]
        raise ConfigError(f"{what}: {who} would start at {field} = {value / scale:g} {unit}, beyond "
                          f"the model's range |{field}| <= {limit / scale:g} {unit}; narrow the "
                          "distribution")


def member_initial_states(study: Study, x0: np.ndarray, model, chunk: Chunk) -> np.ndarray:
    """x0 of each member of the chunk: the scenario's x0 plus the member's own offsets; a member
    pushed beyond the model's state range is a ConfigError naming the member and the field."""
    state_names = names(model.states)
    batch = np.tile(np.asarray(x0, dtype=float), (chunk.size, 1))
    fields = [(state_names.index(PERTURBABLE[p.field][0]), PERTURBABLE[p.field][1], p)
              for p in study.offsets]  # each member's draws in this order
    for row, member in enumerate(range(chunk.start, chunk.stop) if fields else ()):
        rng = np.random.default_rng(study.member_stream(member, 0))
        for i, scale, p in fields:
            batch[row, i] += scale * p.draw(rng)
    limits = np.asarray(model.state_limits, dtype=float)
    for p in study.offsets:
        state, scale = PERTURBABLE[p.field]
        i = state_names.index(state)
        outside = np.flatnonzero(np.abs(batch[:, i]) > limits[i])
        if outside.size:
            row = int(outside[0])
            _check_range(f"--perturb {p}", f"member {chunk.start + row}", p.field, batch[row, i],
                         limits[i], scale)
    return batch


def initial_state_variables(study: Study, x0: np.ndarray, model) -> dict:
    """Each member's start value of every perturbed initial-state field, as Dataset variables
    ``initial_state_<FIELD>`` over ``member`` in the field's own unit (``psi_deg`` in degrees):
    the scenario's value plus the member's draw, from ``x0`` of :func:`member_initial_states`."""
    state_names = names(model.states)
    out = {}
    for p in study.offsets:
        state, scale = PERTURBABLE[p.field]
        values = np.asarray(x0, dtype=float)[:, state_names.index(state)] / scale
        out[f"initial_state_{p.field}"] = ("member", values, {
            "long_name": f"initial_state.{p.field} of the member (scenario's value + its draw)",
            "units": PERTURB_UNITS[p.field], "perturb": str(p)})
    return out


def numeric_metrics(metrics: dict) -> dict[str, float]:
    """The scalar figures of a metrics dict as floats (None → NaN; lists and events left out)."""
    out = {}
    for key, value in metrics.items():
        if isinstance(value, bool):
            out[key] = float(value)
        elif isinstance(value, (int, float, np.integer, np.floating)):
            out[key] = float(value)
        elif value is None:
            out[key] = math.nan
    return out


def _simulate(setup, sim, x0, streams, backend: str, log_every: int, on_divergence: str):
    from shipgnc.sim.simulator import simulate

    return simulate(setup.model, x0, t_end=sim.t_end, dt=sim.dt, controller=setup.controller,
                    actuator=setup.actuator, guidance=setup.guidance, disturbance=setup.disturbance,
                    navigation=setup.navigation,
                    u0=setup.u0, integrator=sim.integrator, method=sim.method, rtol=sim.rtol,
                    atol=sim.atol, seed=streams, log_every=log_every, backend=backend,
                    on_divergence=on_divergence, batch_dims=("member",))


def ends_early(setup) -> bool:
    """Whether the guidance can finish (a route's last waypoint), which ends a batch early."""
    if setup.guidance is None:
        return False
    setup.guidance.reset((1,), setup.model)
    return setup.guidance.finished() is not None


def on_log_grid(times, sim) -> np.ndarray:
    """Which ``times`` are on the log grid of ``sim`` (a ``SimulationConfig``: step k with
    k % log_every == 0, or the last)."""
    k = np.rint(np.asarray(times) / sim.dt).astype(np.int64)
    return (k % sim.log_every == 0) | (k == round(sim.t_end / sim.dt))


def route_series(series, sim, done_at: np.ndarray):
    """Each member's series on the log grid of ``sim`` up to its own completion ``done_at`` (NaN:
    never), plus its completion sample; NaN elsewhere. Times no member keeps are dropped."""
    import xarray as xr

    t = series.time.values
    grid = on_log_grid(t, sim)[:, None]
    limit = np.nan_to_num(done_at, nan=np.inf)[None, :]
    keep = (grid | (t[:, None] == limit)) & (t[:, None] <= limit)
    mask = xr.DataArray(keep, dims=("time", "member"), coords={"time": series.time,
                                                                "member": series.member})
    return series.where(mask).isel(time=np.flatnonzero(keep.any(axis=1)))


def _run_batch(setup, sim, x0, seeds, backend: str, route: bool, on_divergence: str = "stop"):
    """One loop call for ``x0``'s members, stepped as ``sim`` says: the result and, for a route,
    each member's completion time (NaN: not completed). A batch is logged at every step, so that
    its metrics see every step whatever ``log_every`` (see :func:`run_chunk`).
    ``on_divergence="mask"``: a member that diverges stops alone (its time in ``diverged_at``)."""
    from shipgnc.sim.simulator import scoring_log_every

    if not route:  # an unthinned record beyond the log limit: name log_every and --chunk-size
        scoring_log_every(setup.model, x0, sim.t_end, sim.dt, sim.log_every,
                          fewer="lower --chunk-size")
    try:
        result = _simulate(setup, sim, x0, MemberStreams(seeds), backend, 1, on_divergence)
    except ConfigError as exc:
        if route and str(exc).startswith("log size"):
            raise ConfigError(f"{exc} (a route study logs every step of a chunk, so that each "
                              f"member's completion is logged: lower --chunk-size)") from None
        raise
    if not route:
        return result, None
    done_at = getattr(setup.guidance, "completion_time", None)
    if done_at is None:
        raise ConfigError(f"guidance {type(setup.guidance).__name__} can finish but keeps no "
                          "completion_time; a study cannot end its members' series")
    return result, np.asarray(done_at, dtype=float).reshape(-1).round(9)


def _survivor(result, done_at, i: int):
    """Member ``i`` of a batch in which another member diverged: its own run (the batch's
    ``diverged`` status is the others')."""
    own = result.isel(member=[i])
    own.attrs = {**result.attrs, "diverged": 0, "message": ""}
    return own, None if done_at is None else done_at[i:i + 1]


def _alone(setup, i: int):
    """``setup`` for its batch's member ``i`` alone (its own plant, when the members have theirs)."""
    model = setup.model
    return replace(setup, model=model.subset(i, i + 1)) if isinstance(model, PerShipModel) else setup


def in_loop_plan(scenario, setup, sim, x0, seeds, backend: str, series: bool = False):
    """The validated run of a chunk and its accumulators (:func:`~shipgnc.analysis.accumulated.plan_for`)
    when the chunk is scored inside the compiled loop and keeps no log; None when it keeps its
    every-step log: its ``series`` are kept, a route ends it (:func:`ends_early`), or the metric
    set, the backend or the setup needs the logged series. The one decision of :func:`run_chunk`
    and of the memory estimate (:func:`shipgnc.study.execute.estimate_memory`)."""
    from shipgnc.analysis.accumulated import plan_for
    from shipgnc.sim.compose import unsupported_reason
    from shipgnc.sim.simulator import _validate, log_signals

    if series or backend not in ("compiled", "compiled-or-numpy") or sim.integrator != "rk4":
        return None
    if ends_early(setup):
        return None
    n_steps = round(sim.t_end / sim.dt)
    run = _validate(setup.model, x0, t_end=sim.t_end, dt=sim.dt, controller=setup.controller,
                    actuator=setup.actuator, guidance=setup.guidance, disturbance=setup.disturbance,
                    u0=setup.u0, integrator=sim.integrator, method=sim.method, rtol=sim.rtol,
                    atol=sim.atol, seed=MemberStreams(seeds), on_divergence="mask", observer=None,
                    progress=None, log_every=max(1, n_steps), navigation=setup.navigation)
    if unsupported_reason(run):  # no compiled loop covers the setup
        return None
    plan = plan_for(scenario, setup, list(log_signals(run)), run.n_steps, run.dt)
    return None if plan is None else (run, plan)


def own_loop_pays(study: Study, chunk: Chunk, sim) -> bool:
    """Whether ``chunk`` is scored in a loop of its plan's own: the members × steps of every grid
    point of the study whose plan has the chunk's signature (:func:`shipgnc.sim.scored.score_plan`;
    its controller variant) reach :data:`UNROLLED_SHIP_STEPS`, however many grid points share it.
    The plans are looked at only when the grid point alone is below it and the whole study is not
    (one build per grid point, once per study)."""
    here = study.members * round(sim.t_end / sim.dt)
    if here >= UNROLLED_SHIP_STEPS or len(study.points) == 1:
        return here >= UNROLLED_SHIP_STEPS and _plan_of(study, chunk.point, chunk.variant) is not None
    if not any(key.startswith("simulation.") for key in study.dims) and \
            here * len(study.points) < UNROLLED_SHIP_STEPS:
        return False  # every grid point runs as many steps: the study as a whole is too small
    plans = [_plan_of(study, p, chunk.variant) for p in range(len(study.points))]
    mine = plans[chunk.point]
    return mine is not None and sum(
        p[1] for p in plans if p is not None and p[0] == mine[0]) >= UNROLLED_SHIP_STEPS


def _plan_of(study: Study, point: int, variant: str | None):
    """The signature of grid ``point``'s plan whose own step the loop would take
    (:func:`shipgnc.sim.scored.own_step`) and its members × steps; None when its chunks are
    not scored in the loop, or in the generic step whatever their size. Kept per study (by its
    ``repr``: a grid value may be a list, which does not hash)."""
    key = (repr(study), point, variant)
    if key not in _PLANS:
        if len(_PLANS) >= 256:
            _PLANS.clear()
        _PLANS[key] = _signature_steps(study, point, variant)
    return _PLANS[key]


#: :func:`_plan_of`'s answers of this process
_PLANS: dict = {}


def _signature_steps(study: Study, point: int, variant: str | None):
    """:func:`_plan_of`, worked out."""
    from shipgnc.sim.scored import own_step, score_plan

    scenario, setup, sim, x0, seeds, _ = chunk_setup(study, Chunk(point, 0, 1, variant))
    planned = in_loop_plan(scenario, setup, sim, x0, seeds, "compiled", study.series)
    if planned is None:
        return None
    run, plan = planned
    signature = score_plan(plan.ops, plan.span, len(run.model.states))
    return (signature, study.members * run.n_steps) if own_step(signature) else None


def scored_in_loop(scenario, setup, sim, x0, seeds, backend: str, series: bool = False,
                   unrolled: bool = False):
    """Every member's metrics scored inside the compiled loop (:mod:`shipgnc.analysis.accumulated`),
    in :func:`~shipgnc.scenarios.runner.metric_arrays`' key order, and which members diverged
    or need their series (their figures NaN here: :func:`run_chunk` runs each again alone with its
    log); None when the chunk keeps its log (:func:`in_loop_plan`). ``unrolled``: in a loop of
    the plan's own (:func:`shipgnc.sim.scored.run_scored`; :data:`UNROLLED_SHIP_STEPS`)."""
    from shipgnc.analysis.accumulated import NEEDS_LOG
    from shipgnc.scenarios.runner import design_figures
    from shipgnc.sim.scored import run_scored

    planned = in_loop_plan(scenario, setup, sim, x0, seeds, backend, series)
    if planned is None:
        return None
    run, plan = planned
    scored = run_scored(run, plan.ops, plan.span, plan.init, unrolled=unrolled)
    if scored is None:
        return None
    figures = plan.finish(scored.acc)
    diverged = (scored.event >= 0) | figures.pop(NEEDS_LOG, False)
    arrays = {k: np.where(diverged, math.nan, v) for k, v in figures.items()}
    for key, value in design_figures(setup).items() if scenario.metrics == "path-tracking" else ():
        if isinstance(value, (int, float)):  # as metric_arrays adds them (not the lists)
            arrays[key] = np.full(x0.shape[0], float(value))
    arrays["diverged"] = np.zeros(x0.shape[0])
    return arrays, diverged


def diverged_alone(scenario, setup, sim, x0, seeds, backend: str, arrays: dict, diverged) -> set:
    """Each ``diverged`` member run again alone up to its divergence, with its log, and scored
    there into its row of ``arrays``; the loops that ran."""
    from shipgnc.scenarios.runner import compute_metrics

    ran_on = set()
    for i in np.flatnonzero(diverged):
        alone, _ = _run_batch(_alone(setup, i), sim, x0[i:i + 1], seeds[i:i + 1], backend, False)
        ran_on.add(alone.attrs.get("backend"))
        row = numeric_metrics(compute_metrics(scenario, alone.isel(member=0), setup))
        for key, values in arrays.items():
            values[i] = row.get(key, math.nan)
    return ran_on


def scored_from_log(scenario, setup, sim, x0, seeds, backend: str, route: bool):
    """The chunk's members run with a log of every step and scored from it (see
    :func:`run_chunk`): their metric arrays, the loops that ran, the result and, for a route, each
    member's completion time."""
    import xarray as xr

    from shipgnc.scenarios.runner import compute_metrics, metric_arrays

    size = x0.shape[0]
    result, done_at = _run_batch(setup, sim, x0, seeds, backend, route, "mask")
    diverged = np.isfinite(result["diverged_at"].values)
    result = result.drop_vars("diverged_at")
    arrays = None
    if diverged.any():
        runs = [_run_batch(_alone(setup, i), sim, x0[i:i + 1], seeds[i:i + 1], backend, route)
                if diverged[i] else _survivor(result, done_at, i) for i in range(size)]
        ran_on = {r.attrs.get("backend") for r, _ in runs}
        members = [r.isel(member=0) for r, _ in runs]
        result = xr.concat([r for r, _ in runs], dim="member", join="outer")
        done_at = np.concatenate([d for _, d in runs]) if route else None
    else:
        ran_on = {result.attrs.get("backend")}
        arrays = metric_arrays(scenario, result, setup)  # every member scored at once
        members = [result.isel(member=i) for i in range(size)] if arrays is None else []
    if route and arrays is None:  # each member scored on its own run, which ends at its completion
        members = [m.isel(time=slice(0, round(d / sim.dt) + 1)) if np.isfinite(d) else m
                   for m, d in zip(members, done_at, strict=True)]
    if arrays is None:
        rows = [numeric_metrics(compute_metrics(scenario, m, setup)) for m in members]
        keys = list(dict.fromkeys(k for row in rows for k in row))
        arrays = {k: np.array([row.get(k, math.nan) for row in rows]) for k in keys}
    return arrays, ran_on, result, done_at


def chunk_setup(study: Study, chunk: Chunk):
    """(scenario, setup, SimulationConfig, x0, seeds, drawn plant parameters) of a chunk: the
    scenario of its grid point built for its controller, with its members' initial states, random
    streams and plants."""
    from shipgnc.scenarios.runner import build, simulation_of

    scenario = study.scenario_at(study.points[chunk.point])
    check_sweepable(scenario)
    setup = build(scenario, chunk.variant, seed=study.seed)
    x0 = member_initial_states(study, setup.x0, setup.model, chunk)
    drawn = member_params(study, setup.model, chunk.start, chunk.stop)  # the plant's parameters
    if drawn:  # each member's own plant; the controller keeps its nominal design
        setup = replace(setup, model=member_plant(study, setup.model, chunk.start, chunk.stop, drawn))
    seeds = study.member_seeds(chunk.start, chunk.stop, 1)  # made when a disturbance draws
    return scenario, setup, simulation_of(scenario, setup), x0, seeds, drawn


def run_chunk(study: Study, chunk: Chunk, backend: str = "compiled-or-numpy"):
    """Run one chunk; an ``xarray.Dataset`` with a ``member`` dimension: every scalar metric, and
    with ``study.series`` every time series; ``attrs["backend"]`` says which code ran it.

    The batch runs in one call of the loop. Without ``study.series``, a metric set with
    accumulators (:mod:`shipgnc.analysis.accumulated`) is scored inside the compiled loop at
    every step and nothing else is logged (:func:`scored_in_loop`); otherwise the batch is logged
    at every step: the metrics see every step, and only the series kept with ``study.series`` are
    thinned to ``simulation.log_every``. A member that diverges stops alone
    (``on_divergence="mask"``: the others run on, each its own run whatever chunk it shares) and
    is run again by itself up to its divergence, so that it is flagged ``diverged = 1`` with its
    figures up to then.

    A route (guidance that finishes at its last waypoint) ends a batch when its last member
    completes; the others keep sailing until then, and the step the batch ends on depends on its
    members. So a route batch is logged at every step, its metrics are computed there, and each
    member's series is thinned to the log grid up to its own completion plus its completion
    sample (NaN elsewhere).
    """
    import xarray as xr

    scenario, setup, sim, x0, seeds, drawn = chunk_setup(study, chunk)
    route = ends_early(setup)
    unrolled = own_loop_pays(study, chunk, sim)
    in_loop = scored_in_loop(scenario, setup, sim, x0, seeds, backend, study.series, unrolled)
    if in_loop is not None:  # no series: the members' figures are all the chunk keeps
        (arrays, diverged), result, done_at = in_loop, None, None
        ran_on = {"compiled"} | diverged_alone(scenario, setup, sim, x0, seeds, backend, arrays,
                                               diverged)
    else:
        arrays, ran_on, result, done_at = scored_from_log(scenario, setup, sim, x0, seeds,
                                                          backend, route)
    # copies: a metric that is a view of the log (a final value) would keep the chunk's whole
    # log alive until the study ends (≈ 190 MB per 1 000 boats of boat-autopilot)
    data = {k: ("member", np.array(v, dtype=float)) for k, v in arrays.items()}
    data.update(param_variables(study, drawn))
    data.update(initial_state_variables(study, x0, setup.model))
    out = xr.Dataset(data, coords={"member": np.arange(chunk.start, chunk.stop)},
                     attrs={"backend": ", ".join(sorted(str(b) for b in ran_on))})
    if study.series:
        series = result.assign_coords(member=np.arange(chunk.start, chunk.stop))
        series.attrs = {}
        if route:
            series = route_series(series, sim, done_at)
        else:  # the series on the log grid (the metrics above saw every step)
            series = series.isel(time=np.flatnonzero(on_log_grid(series.time.values, sim)))
        out = xr.merge([out, series.rename({k: f"series_{k}" for k in series.data_vars})],
                       combine_attrs="override")
    return out
