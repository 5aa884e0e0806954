"""``simulate``: the one simulation loop of shipgnc.

    guidance ──ref──▶ controller ──command──▶ actuator ──u──▶ model ẋ = f(x, u, d) ◀── disturbance

At each sample t_k = k·dt the state x(t_k) is logged together with the command and the applied
input acting from t_k (document 001's loop records the state before the step, note 001-A13).
Every ``Ts/dt`` samples the guidance and the controller are evaluated; the command is held in
between. The plant (and any actuator lag) is integrated with fixed-step RK4 or with
``scipy.integrate.solve_ivp`` over each ``dt``. The last sample is t_end itself.

Batched: ``x0`` of shape ``(..., n)`` simulates every leading index as one ship, in one array
operation per RK stage. The same loop compiled: :mod:`shipgnc.sim.compose` composes the kernels of
the components (:mod:`shipgnc.kernels`) into one numba loop for any combination whose components
all have one; ``backend="numpy"`` forces this readable reference loop.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from shipgnc.actuators import Actuator
from shipgnc.errors import ConfigError, DivergenceError, Interrupted, require
from shipgnc.frames import wrap_angle
from shipgnc.interrupts import note
from shipgnc.models.base import Signal, names
from shipgnc.sim.integrators import rk4_step, solve_ivp_step
from shipgnc.sim.transition import step_end, step_start
from shipgnc.streams import MemberStreams, is_generator

INTEGRATORS = ("rk4", "solve_ivp")
BACKENDS = ("auto", "numpy", "compiled", "compiled-or-numpy")
#: what a run does when a ship diverges (see :func:`simulate`)
ON_DIVERGENCE = ("raise", "stop", "mask")
#: ``backend="auto"`` uses the composed loop from this batch size (compilation then pays off) ...
COMPILED_MIN_BATCH = 64
#: ... or from this much work, ships × steps: a few ships' numpy loop needs ≈ 0.3 ms a step, a
#: combination's first compile ≈ 10 s, paid once per machine (the loop is cached on disk and
#: loaded in ≈ 0.1 s by every later process), so a run of more than half a second compiles it
#: for every later run; setups no twin covers run in the numpy loop
COMPILED_MIN_WORK = 2_000
#: the compiled loops (modules of ``shipgnc.sim``), asked in this order, and the name each
#: records in ``attrs["backend"]``: the composed loop of components with kernels
COMPILED_TWINS = {"compose": "compiled"}
#: most steps of one run, and most logged numbers (8 bytes each, 4 GB) of one result
MAX_STEPS = 1e8
MAX_LOGGED = 5e8


class StopSimulation(Exception):
    """Raised by an observer to end a run early and keep what was gathered."""


@dataclass
class Log:
    """Samples gathered by a loop: variable name → array ``(time, *batch)`` plus metadata."""

    time: np.ndarray
    data: dict[str, np.ndarray]
    signals: dict[str, Signal]
    status: dict = field(default_factory=dict)
    #: ``on_divergence="mask"``: each ship's divergence time [s] (NaN: it ran to the end)
    diverged_at: np.ndarray | None = None


@dataclass
class SimSetup:
    """Validated inputs of one run (shared by the numpy loop and the compiled twin)."""

    model: object
    x0: np.ndarray
    t_end: float
    dt: float
    n_steps: int
    hold: int  # samples per control period, Ts/dt
    controller: object | None
    actuator: Actuator
    guidance: object | None
    disturbance: object | None
    integrator: str
    solver_options: dict
    rng: np.random.Generator
    on_divergence: str
    observer: Callable | None
    progress: Callable | None
    log_every: int
    u0: np.ndarray
    navigation: object | None = None  # sensors and estimator (shipgnc.navigation)
    #: called once the loop has ended without a Ctrl-C, before its Log is built (simulate's
    #: ``on_complete``)
    on_complete: Callable[[], None] | None = None

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return self.x0.shape[:-1]


def simulate(model, x0, *, t_end: float, dt: float, controller=None, actuator=None,
             guidance=None, disturbance=None, u0=None, integrator: str = "rk4",
             method: str = "RK45", rtol: float = 1e-3, atol: float = 1e-6, seed=None,
             on_divergence: str = "raise", observer: Callable | None = None,
             progress: Callable | None = None, log_every: int = 1,
             batch_dims: tuple[str, ...] | None = None, backend: str = "auto",
             attrs: dict | None = None, navigation=None,
             on_complete: Callable[[], None] | None = None):
    """Simulate ``model`` from ``x0`` (shape ``(..., n)``) for ``t_end`` seconds.

    Parameters
    ----------
    controller : a :class:`~shipgnc.control.base.Controller` (``Ts`` = its sample time, default
        ``dt``) or ``None`` for a constant input ``u0``. An event-driven controller (a manoeuvring
        trial's rudder programme, :mod:`shipgnc.trials.programme`) may also have
        ``finished()`` (per ship: its programme is complete; the run ends when every ship is
        finished, as with a guidance's ``finished()``) and ``switch_within_step(t, x0, x1,
        command)`` (a command that switches on a state crossing inside the step:
        :func:`switch_within_step`; numpy loop).
    actuator : :class:`~shipgnc.actuators.Actuator`; default: the model's own input limits.
    guidance : references for the controller (:mod:`shipgnc.guidance`).
    disturbance : see :mod:`shipgnc.environment.disturbance`; drawn from ``seed``.
    integrator : ``"rk4"`` (fixed step) or ``"solve_ivp"`` (adaptive, ``method``/``rtol``/``atol``,
        one call per ``dt`` with the batch flattened).
    on_divergence : ``"raise"`` (default) raises :class:`DivergenceError` naming time, state,
        value and ship; ``"stop"`` returns the partial result with ``attrs["diverged"] = 1``;
        ``"mask"`` stops only the ships that diverge: each one's record is NaN from the sample
        its divergence was found at (its command at that sample, or its state after the step
        before), the others run on exactly as they would alone; the result gets a per-ship
        variable ``diverged_at`` [s] (NaN: never), ``attrs["diverged"]`` = the number of ships
        that diverged and ``attrs["message"]`` the first one's error (``integrator="rk4"`` only;
        a stopped ship's controller and guidance keep running on its held state in the numpy loop
        and are skipped in the compiled one: only its record is defined).
    observer : ``observer(t, x, command, applied)`` at every logged sample (live plots); it may
        raise :class:`StopSimulation` to end the run and keep the result. Ctrl-C (a
        KeyboardInterrupt) ends either loop too: it raises :class:`~shipgnc.errors.Interrupted`
        carrying the samples computed so far (``.partial``, ``attrs["interrupted"] = 1``).
    progress : ``progress(k, n_steps)`` called about a hundred times per run.
    on_complete : ``on_complete()`` called by either loop once it has ended without a Ctrl-C
        (every step run, every ship finished, or a divergence stopped it), before its log and
        the result are built: from then on a Ctrl-C meets a complete run (the runner holds it
        with ``--keep-partial`` and writes the run whole; gathering a long run's log and
        building its Dataset take a noticeable fraction of a second).
    log_every : keep every n-th sample (large batches); the final sample is always kept.
    batch_dims : names of the batch dimensions (default ``("ship",)`` for one batch axis).
    navigation : :class:`~shipgnc.navigation.Navigation` (sensors and an estimator) or None. At
        each control sample ``navigation.observe(t, x, applied)`` turns the true state into the
        state the guidance and the controller see (the estimate, else the measurements); its
        signals (``<state>_meas``, ``<state>_hat``, ...) are logged. None: they read the truth.
        Both loops run it (the compiled one through ``navigation.kernel``; an estimator without
        a kernel keeps the run in this loop).
    backend : ``"numpy"`` (this loop), ``"compiled"`` (a numba twin; ConfigError naming each twin's
        reason when none covers the setup), ``"auto"``: a twin that covers the setup when the
        batch has ≥ :data:`COMPILED_MIN_BATCH` ships or the run ≥ :data:`COMPILED_MIN_WORK`
        ship-steps, else this loop, or ``"compiled-or-numpy"``: a twin whenever one covers the
        setup, whatever the batch size (a study's chunks of any size then take the same path).
        Both give the same result to round-off; with ``"rk4"`` each gives a ship the same result
        to the bit whatever the batch it shares (``"solve_ivp"`` controls one step size for the
        whole batch, so there the batch's other ships move the steps).

    Returns
    -------
    xarray.Dataset
        See :mod:`shipgnc.sim.result`; ``attrs["backend"]`` names the loop that ran (``numpy``,
        ``compiled``), with ``+wave_kernel`` when the numpy loop called a
        disturbance's compiled twin (the wave loads of document 003; never with
        ``backend="numpy"``).
    """
    setup = _validate(model, x0, t_end=t_end, dt=dt, controller=controller, actuator=actuator,
                      guidance=guidance, disturbance=disturbance, u0=u0, integrator=integrator,
                      method=method, rtol=rtol, atol=atol, seed=seed,
                      on_divergence=on_divergence, observer=observer, progress=progress,
                      log_every=log_every, navigation=navigation, on_complete=on_complete)
    require(backend in BACKENDS, "backend", backend, f"allowed: {', '.join(BACKENDS)}")
    _require_batch_dims(batch_dims, setup.batch_shape)
    log, ran_on = None, "numpy"
    if wants_compiled(backend, math.prod(setup.batch_shape), setup.n_steps):
        twin, reasons = _compiled_twin(setup)
        if twin is not None:
            log, ran_on = twin.run(setup), COMPILED_TWINS[twin.__name__.rsplit(".", 1)[-1]]
        elif backend == "compiled":
            raise ConfigError(f"backend = 'compiled': no compiled loop covers this run "
                              f"({'; '.join(reasons)}); use backend='numpy'")
    if log is None:
        # a disturbance with a compiled twin of its own (the wave loads of document 003) stays in
        # numpy with backend="numpy"; else the numpy loop records the twin it called
        numpy_only = getattr(disturbance, "numpy_only", None) if backend == "numpy" else None
        with numpy_only() if numpy_only is not None else contextlib.nullcontext():
            log = run_numpy(setup)
            evaluator = getattr(disturbance, "evaluator", None)
            if evaluator is not None and evaluator() != "numpy":
                ran_on = f"{ran_on}+{evaluator()}"
    run_attrs = result_attrs(setup, ran_on, attrs)
    if log.status.get("interrupted"):  # the partial Dataset is built (xarray imported) only if
        last = float(log.time[-1]) if log.time.size else 0.0  # someone reads it

        def partial():
            from shipgnc.sim.result import build_dataset

            return build_dataset(log, setup.batch_shape, batch_dims, run_attrs)

        error = Interrupted(last, partial=partial if log.time.size else None)
        note(str(error))  # the line said if the command is not done by the deadline
        raise error
    from shipgnc.sim.result import batch_dim_names, build_dataset

    result = build_dataset(log, setup.batch_shape, batch_dims, run_attrs)
    if log.diverged_at is not None:
        dims = batch_dim_names(setup.batch_shape, batch_dims)
        result["diverged_at"] = (dims, log.diverged_at.reshape(setup.batch_shape),
                                 {"units": "s", "long_name": "time the ship diverged (NaN: never)"})
    return result


def wants_compiled(backend: str, n_ships: int, n_steps: int) -> bool:
    """Whether ``backend`` asks for a compiled loop for a run of ``n_ships`` × ``n_steps``
    (``"auto"``: from :data:`COMPILED_MIN_BATCH` ships or :data:`COMPILED_MIN_WORK` ship-steps)."""
    return backend in ("compiled", "compiled-or-numpy") or (backend == "auto" and (
        n_ships >= COMPILED_MIN_BATCH or n_ships * n_steps >= COMPILED_MIN_WORK))


def result_attrs(setup: SimSetup, ran_on: str, attrs: dict | None = None) -> dict:
    """The attributes of a run's result: integrator, the loop that ran, steps, model, ``attrs``."""
    return {"integrator": setup.integrator, "backend": ran_on, "dt": setup.dt,
            "Ts": setup.dt * setup.hold, "t_end": setup.t_end, "model": type(setup.model).__name__,
            **(attrs or {})}


def _compiled_twin(setup: SimSetup):
    """The first compiled twin covering ``setup`` (a module with ``run``), or None and each twin's
    reason for refusing it."""
    import importlib

    reasons = []
    for name in COMPILED_TWINS:
        twin = importlib.import_module(f"shipgnc.sim.{name}")
        reason = twin.unsupported_reason(setup)
        if not reason:
            return twin, []
        reasons.append(reason)
    return None, reasons


def _require_component(role: str, obj, methods: tuple[str, ...], example: str) -> None:
    """A clear ConfigError when ``obj`` lacks what the loop calls (``controller="pid"``)."""
    missing = [m for m in methods if not hasattr(obj, m)]
    if missing:
        shown = repr(obj) if len(repr(obj)) <= 40 else type(obj).__name__
        raise ConfigError(f"{role} = {shown}: not a {role} object (it has no "
                          f"{', '.join(missing)}); {example}")


def _require_batch_dims(batch_dims, batch_shape: tuple[int, ...]) -> None:
    """``batch_dims``: one distinct, non-empty name per batch axis (checked before the run)."""
    if batch_dims is None:
        return
    ok = (isinstance(batch_dims, (tuple, list)) and all(isinstance(d, str) and d and d != "time"
                                                        for d in batch_dims))
    require(ok, "batch_dims", batch_dims, "must be a tuple of names (strings other than 'time')")
    require(len(set(batch_dims)) == len(batch_dims), "batch_dims", tuple(batch_dims),
            "names must be distinct")
    require(len(batch_dims) == len(batch_shape), "batch_dims", tuple(batch_dims),
            f"need {len(batch_shape)} names for a batch of shape {batch_shape}")


def _validate(model, x0, *, t_end, dt, controller, actuator, guidance, disturbance, u0,
              integrator, method, rtol, atol, seed, on_divergence, observer, progress,
              log_every, navigation=None, on_complete=None) -> SimSetup:
    _require_component("model", model, ("states", "inputs", "derivatives"), "e.g. CyberShip2()")
    for role, obj, methods, example in (
            ("controller", controller,
             ("reset", "law" if getattr(controller, "continuous", False) else "step"),
             "e.g. CoursePD(...), or None"),
            ("guidance", guidance, ("reset", "reference"), "e.g. ReferenceSchedule(...)"),
            ("disturbance", disturbance, ("reset", "__call__"), "e.g. GaussianForceNoise(...)"),
            ("actuator", actuator, ("n", "saturate"), "e.g. Actuator.for_model(model)"),
            ("navigation", navigation, ("reset", "observe", "signal_values"),
             "e.g. Navigation(sensors=[GNSS(), Compass()])")):
        if obj is not None:
            _require_component(role, obj, methods, example)
    for name, value in (("dt", dt), ("t_end", t_end)):
        require(isinstance(value, (int, float)) and math.isfinite(value) and value > 0,
                name, value, "must be a finite number > 0 s")
    n_steps = whole_steps(t_end, dt)
    hold = samples_per_period(getattr(controller, "Ts", None) or dt, dt)
    require(integrator in INTEGRATORS, "integrator", integrator,
            f"allowed: {', '.join(INTEGRATORS)}")
    require(on_divergence in ON_DIVERGENCE, "on_divergence", on_divergence,
            f"allowed: {', '.join(ON_DIVERGENCE)}")
    require(on_divergence != "mask" or integrator == "rk4", "on_divergence", on_divergence,
            f"'mask' needs integrator 'rk4' ({integrator!r} steps the whole batch as one system, so "
            "one ship's blow-up stops them all)")
    require(isinstance(log_every, int) and log_every >= 1, "log_every", log_every,
            "must be an integer >= 1")
    n_states = len(model.states)
    if np.iscomplexobj(np.asarray(x0)):
        raise ConfigError("x0: complex values given; the state is real (north, east, ... in SI)")
    try:
        x0 = np.array(x0, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"x0: not a numeric array ({exc})") from None
    require(x0.ndim >= 1 and x0.shape[-1] == n_states, "x0 shape", x0.shape,
            f"last axis must hold the {n_states} states {', '.join(names(model.states))}")
    require(bool(np.all(np.isfinite(x0))), "x0", x0.tolist() if x0.size < 20 else "...",
            "initial state must be finite")
    limits = np.asarray(model.state_limits, dtype=float)
    outside = np.argwhere(np.abs(x0) > limits)
    if outside.size:
        i = int(outside[0][-1])
        s = model.states[i]
        raise ConfigError(f"initial_state.{s.name} = {float(x0[tuple(outside[0])]):g}: beyond the "
                          f"model's range |{s.name}| <= {limits[i]:g} {s.unit}")
    logged = logged_numbers(model, x0.shape[:-1], n_steps, log_every)
    require(logged <= MAX_LOGGED, "log size", f"{logged * 8 / 2**30:.1f} GiB",
            "too large: log fewer samples (log_every), shorten t_end or use fewer ships")
    if actuator is None:
        actuator = Actuator.for_model(model)
    require(actuator.n == len(model.inputs), "actuator channels", actuator.n,
            f"the model has {len(model.inputs)} inputs ({', '.join(names(model.inputs))})")
    u0 = np.zeros(actuator.n) if u0 is None else np.asarray(u0, dtype=float)
    require(u0.shape[-1:] == (actuator.n,), "u0 shape", u0.shape,
            f"must end in {actuator.n} (one value per input)")
    require(bool(np.all(np.isfinite(u0))), "u0", u0.tolist(), "initial input must be finite")
    needed = getattr(controller, "reference_names", ())
    if needed:
        given = tuple(s.name for s in getattr(guidance, "references", ()))
        require(given[:len(needed)] == tuple(needed), "guidance", type(guidance).__name__,
                f"{type(controller).__name__} needs references {', '.join(needed)} "
                f"(e.g. ReferenceSchedule, LOSGuidance; PathGuidance for a path law)")
    if getattr(controller, "continuous", False):
        limited = np.isfinite(actuator.rate)
        require(bool(np.all(actuator.tau[limited] > 0)), "actuator.rate",
                actuator.rate.tolist(), "a continuous controller needs a lag (tau > 0) on "
                "every rate-limited channel")
    if navigation is not None and getattr(controller, "continuous", False):
        raise ConfigError(f"navigation: the continuous controller {type(controller).__name__} is "
                          "evaluated at every RK stage on the true state; navigation needs a "
                          "sampled controller (step at Ts)")
    if seed is not None and not is_generator(seed):
        require(isinstance(seed, (int, np.integer)) and not isinstance(seed, bool) and seed >= 0,
                "seed", seed, "must be a non-negative integer, a numpy Generator or MemberStreams")
    if isinstance(seed, MemberStreams):
        require(x0.shape[:-1] == (len(seed),), "seed", f"{len(seed)} member streams",
                f"need one stream per ship of the batch {x0.shape[:-1]}")
    rng = seed if is_generator(seed) else np.random.default_rng(seed)
    return SimSetup(model=model, x0=x0, t_end=float(t_end), dt=float(dt), n_steps=n_steps,
                    hold=hold, controller=controller, actuator=actuator, guidance=guidance,
                    disturbance=disturbance, integrator=integrator,
                    solver_options={"method": method, "rtol": rtol, "atol": atol}, rng=rng,
                    on_divergence=on_divergence, observer=observer, progress=progress,
                    log_every=log_every, u0=u0, navigation=navigation, on_complete=on_complete)


def whole_steps(t_end: float, dt: float, *, section: str = "") -> int:
    """The steps of a run, ``t_end / dt``: a whole number (the last sample is t_end itself), at
    most :data:`MAX_STEPS`. The one check of this rule, for :func:`simulate` and for a scenario's
    ``simulation`` section (``section``: the section the message names the fields in, e.g.
    ``simulation.t_end``); a one-line :class:`ConfigError` otherwise."""
    at = f"{section}." if section else ""
    steps = t_end / dt
    require(math.isfinite(steps) and steps <= MAX_STEPS, f"{section}: t_end / dt" if section
            else "t_end / dt", steps, f"at most {MAX_STEPS:.0e} steps per run")
    n_steps = round(steps)
    require(n_steps >= 1 and abs(n_steps * dt - t_end) <= 1e-9 * max(1.0, t_end), f"{at}t_end",
            t_end, f"must be a whole multiple of {at}dt = {dt:g} s")
    return n_steps


def samples_per_period(Ts: float, dt: float, *, field: str = "controller.Ts",
                       dt_field: str = "dt") -> int:
    """Samples per control period, ``Ts / dt``: a whole number >= 1. The one check of this rule,
    for :func:`simulate` and for a scenario's controllers (``field``: e.g. ``controllers.pd.Ts``);
    a one-line :class:`ConfigError` otherwise."""
    require(isinstance(Ts, (int, float)) and math.isfinite(Ts) and Ts > 0, field, Ts,
            "must be > 0 s")
    hold = round(Ts / dt)
    require(hold >= 1 and abs(hold * dt - Ts) <= 1e-9 * Ts, field, Ts,
            f"must be a whole multiple of {dt_field} = {dt:g} s")
    return hold


def logged_numbers(model, batch_shape: tuple[int, ...], n_steps: int, log_every: int = 1) -> int:
    """An estimate of the numbers a run logs (the :data:`MAX_LOGGED` guard's measure)."""
    return (int(n_steps) // int(log_every) + 2) * max(1, math.prod(batch_shape)) * (
        2 * len(model.states) + 3 * len(model.inputs))


def scoring_log_every(model, x0, t_end: float, dt: float, log_every: int, *,
                      scored: bool = True, what: str = "simulation.log_every",
                      fewer: str | None = None) -> int:
    """The ``log_every`` to simulate with so that metrics see every step: 1 when the run is
    ``scored`` (thin the written result afterwards with :func:`thin`), else ``log_every``. An
    unthinned record beyond :data:`MAX_LOGGED` is a ConfigError naming ``what`` (thinning the
    written result does not thin the record the metrics are computed from)."""
    if not scored or log_every == 1:
        return log_every
    steps = t_end / dt
    if not math.isfinite(steps) or steps > MAX_STEPS:
        return log_every  # simulate's own check names it
    batch = np.shape(x0)[:-1]
    numbers = logged_numbers(model, batch, round(steps), 1)
    if numbers > MAX_LOGGED:
        fits = _fitting_t_end(t_end, MAX_LOGGED / numbers)
        if fewer is None:
            fewer = "use fewer ships" if math.prod(batch) > 1 else ""
        raise ConfigError(f"{what} = {log_every}: the metrics are computed from every step, and "
                          f"this run's unthinned record ({numbers * 8 / 2**30:.1f} GiB) exceeds the "
                          f"{MAX_LOGGED * 8 / 2**30:.0f} GiB log limit ({what} thins only the written "
                          f"result): shorten simulation.t_end (about {fits:g} s fits), raise "
                          f"simulation.dt" + (f" or {fewer}" if fewer else ""))
    return 1


def _fitting_t_end(t_end: float, share: float) -> float:
    """``t_end · share`` rounded down to two significant digits (a t_end that fits)."""
    value = t_end * min(share, 1.0)
    if value <= 0:
        return 0.0
    scale = 10.0 ** (math.floor(math.log10(value)) - 1)
    return math.floor(value / scale) * scale


#: the arrays a run holds besides its record, in records: the metrics' derived series and the
#: written file's encoding (the sweep's chunk estimate counts the same)
RUN_MEMORY_FACTOR = 2


def check_run_memory(model, x0, t_end: float, dt: float, log_every: int, *,
                     limit: float | None = None, scored: bool = False,
                     tables: int = 0) -> None:
    """A ConfigError (exit 2) naming the estimate and what fits when a run's record (logged
    every ``log_every`` steps, :func:`logged_numbers`), about :data:`RUN_MEMORY_FACTOR` times
    over, needs more than ``limit`` bytes (default: the memory available now, ``ulimit -v``
    counted: :func:`shipgnc.memory.available_memory`). ``scored``: the metrics are computed
    from every step (see :func:`scoring_log_every`), so ``simulation.log_every`` would not help
    and is not named. ``tables``: float64 numbers held besides the record (a Monte Carlo
    batch's per-step input tables, :func:`shipgnc.scenarios.montecarlo.table_numbers`)."""
    from shipgnc.memory import available_memory

    steps = t_end / dt
    if not math.isfinite(steps) or steps > MAX_STEPS:
        return  # simulate's own check names it
    batch = np.shape(x0)[:-1]
    numbers = logged_numbers(model, batch, round(steps), log_every)
    if numbers > MAX_LOGGED:
        return  # simulate's own log-size guard names it
    need = 8 * (RUN_MEMORY_FACTOR * numbers + tables)
    have = available_memory() if limit is None else limit
    if need <= have:
        return
    fits = _fitting_t_end(t_end, have / need)
    gib = 2.0 ** 30
    advice = f"shorten simulation.t_end (about {fits:g} s fits) or raise simulation.dt"
    if not scored:
        advice += ", or log fewer samples (simulation.log_every)"
    if math.prod(batch) > 1:
        advice += ", or use fewer ships"
    raise ConfigError(f"simulation.t_end = {t_end:g} s: the run needs about {need / gib:.1f} GiB "
                      f"({round(steps):,} steps of {dt:g} s logged every {log_every}), more than the "
                      f"memory available ({have / gib:.1f} GiB): {advice}")


def thin(result, log_every: int):
    """``result`` (logged at every step) on the log grid of ``log_every``: every ``log_every``-th
    sample and the last one, the samples a run with ``log_every`` logs itself (for a run that
    diverged or was interrupted, the last sample before it stopped is kept too)."""
    n = result.sizes.get("time", 0)
    if log_every <= 1 or n == 0:
        return result
    keep = np.flatnonzero((np.arange(n) % log_every == 0) | (np.arange(n) == n - 1))
    out = result.isel(time=keep)
    out.attrs = dict(result.attrs)
    return out


def log_signals(setup: SimSetup) -> dict[str, Signal]:
    """Every variable a run logs, in order: states, commands, inputs, references, errors, ..."""
    model, ctrl, gd = setup.model, setup.controller, setup.guidance
    out: dict[str, Signal] = {s.name: s for s in model.states}
    for s in model.inputs:
        out[f"{s.name}_cmd"] = Signal(f"{s.name}_cmd", s.unit, f"commanded {s.long_name}",
                                      s.angle)
    out.update({s.name: s for s in model.inputs})
    if gd is not None:
        out.update({s.name: s for s in gd.references})
        state_signals = {s.name: s for s in model.states}
        for s in gd.references:
            if s.tracks:
                tracked = state_signals[s.tracks]
                out[f"{s.tracks}_error"] = Signal(f"{s.tracks}_error", tracked.unit,
                                                  f"{s.tracks} - {s.name}", tracked.angle)
        out.update({s.name: s for s in gd.outputs})
    if ctrl is not None:
        out.update({s.name: s for s in getattr(ctrl, "signals", ())})
    if setup.navigation is not None:
        out.update({s.name: s for s in setup.navigation.signals})
    return out


def tracking_errors(setup: SimSetup, x: np.ndarray, ref: np.ndarray) -> dict[str, np.ndarray]:
    """``<state>_error = state − reference`` (wrapped to (−π, π] for angles)."""
    out = {}
    state_names = names(setup.model.states)
    for i, s in enumerate(setup.guidance.references):
        if s.tracks:
            err = x[..., state_names.index(s.tracks)] - ref[..., i]
            out[f"{s.tracks}_error"] = wrap_angle(err) if s.angle else err
    return out


def check_divergence(setup: SimSetup, t: float, x: np.ndarray | None = None,
                     command: np.ndarray | None = None) -> DivergenceError | None:
    """None if the state (or the command) is sane, else the error naming time, signal, value, ship.

    A state is bad when it is not finite or beyond the model's ``state_limits``; a command when it
    is not finite (checked at the sample where the controller produced it). A guidance whose own
    states can go bad and make the command non-finite (a vessel target's) says which through its
    ``divergence_cause(index)``, and the message names that first.
    """
    if x is not None:
        limits = np.asarray(setup.model.state_limits, dtype=float)
        bad = ~np.isfinite(x) | (np.abs(x) > limits)
        where, source, kind = x, setup.model.states, "state"
    else:
        limits = None
        bad = ~np.isfinite(command)
        where, source, kind = command, setup.model.inputs, "controller command"
    if not bad.any():
        return None
    idx = tuple(int(i) for i in np.argwhere(bad)[0])
    signal = source[idx[-1]]
    value = float(where[idx])
    ship = f" of ship {idx[:-1]}" if idx[:-1] else ""
    rule = ("not finite" if not math.isfinite(value) else
            f"beyond the runaway limit |{signal.name}| <= {limits[idx[-1]]:g} {signal.unit}")
    message = (f"simulation diverged at t = {t:.4g} s: {kind} '{signal.name}'{ship} = "
               f"{value:.6g} {signal.unit} ({rule})")
    cause = getattr(setup.guidance, "divergence_cause", None) if x is None else None
    why = cause(idx[:-1]) if callable(cause) else None
    if why:  # a guidance-internal state (a vessel target) went bad first: name it
        message = (f"simulation diverged at t = {t:.4g} s: {why}{ship}; the references from "
                   f"it made the {kind} '{signal.name}' = {value:.6g} {signal.unit} ({rule})")
    return DivergenceError(message, time=t, state=signal.name, value=value, index=idx[:-1])


def advance_plant(setup: SimSetup, t0: float, x: np.ndarray, lag: np.ndarray | None, plan,
                  command: np.ndarray, ref: np.ndarray, d_held) -> tuple[np.ndarray, np.ndarray | None]:
    """The plant (and the actuator lag states) from t0 to t0 + dt under one step's input ``plan``
    (:meth:`Actuator.begin_step`): RK4 or ``solve_ivp``. A continuous controller's law is evaluated
    in every stage; a held disturbance sample ``d_held`` is used unless the disturbance is
    ``per_stage``. Returns (x, lag); NaN when the adaptive solver gives up (a divergence)."""
    model, act, ctrl, dist = setup.model, setup.actuator, setup.controller, setup.disturbance
    n, dt = x.shape[-1], setup.dt
    continuous = bool(getattr(ctrl, "continuous", False))

    def rhs(t: float, z: np.ndarray) -> np.ndarray:
        xs = z[..., :n]
        lag_s = z[..., n:] if lag is not None else None
        if continuous:
            cmd = ctrl.law(t, xs, ref)
            u = act.saturate(cmd) if lag_s is None else np.where(act.tau > 0, lag_s, act.saturate(cmd))
        else:
            cmd = command
            u = act.input_at(plan, (t - t0) / dt, lag_s)
        d = dist(t, xs) if (dist is not None and dist.per_stage) else d_held
        xdot = model.derivatives(xs, u, d)
        if lag_s is None:
            return xdot
        return np.concatenate([xdot, act.lag_derivative(cmd, lag_s)], axis=-1)

    z = x if lag is None else np.concatenate([x, lag], axis=-1)
    with np.errstate(all="ignore"):
        if setup.integrator == "rk4":
            z = rk4_step(rhs, t0, z, dt)
        else:
            try:
                z = solve_ivp_step(rhs, t0, z, dt, **setup.solver_options)
            except (FloatingPointError, ValueError, OverflowError):
                z = np.full_like(z, np.nan)  # the solver gave up: report it as a divergence
    return z[..., :n], (z[..., n:] if lag is not None else None)


def reset_disturbance(disturbance, model, batch_shape, rng) -> None:
    """A run's start for a disturbance: bound to the model first (``bind_model``: one that reads
    the state finds north, east and ψ by name in ``model``'s states), then ``reset``."""
    bind = getattr(disturbance, "bind_model", None)
    if callable(bind):
        bind(model)
    disturbance.reset(batch_shape, rng)


def reset_components(setup: SimSetup) -> None:
    """Reset the controller, guidance and disturbance for the run's batch (every loop starts so;
    the disturbance draws its initial state from the run's generator)."""
    batch = setup.batch_shape
    if setup.controller is not None:
        setup.controller.reset(batch)
    if setup.guidance is not None:
        setup.guidance.reset(batch, setup.model)
    if setup.disturbance is not None:
        reset_disturbance(setup.disturbance, setup.model, batch, setup.rng)
    if setup.navigation is not None:  # draws from child streams of rng, not from rng itself
        setup.navigation.reset(batch, setup.rng, setup.model, setup.dt * setup.hold)


def run_numpy(setup: SimSetup) -> Log:
    """The reference loop in plain numpy (readable; batched over ships). Each step ``k``: at a
    control sample the state seen, the references and the command (:meth:`_NumpyRun.sample`);
    the actuator's plan of the step and the held disturbance
    (:func:`~shipgnc.sim.transition.step_start`); the log (every ``log_every``-th step, the last
    one, and the step where every ship has finished); the observer; the plant over the step
    (:meth:`_NumpyRun.advance`)."""
    reset_components(setup)
    run = _NumpyRun.start(setup)
    n_steps, progress_every = setup.n_steps, max(1, setup.n_steps // 100)
    try:
        for k in range(n_steps + 1):
            t = k * setup.dt
            if k % setup.hold == 0 and not run.sample(t):
                break
            plan, applied_now, held_d = step_start(setup, t, run.x, run.lag, run.applied,
                                                   run.command)
            last = k == n_steps
            finished = finished_ships(setup.controller, setup.guidance)
            all_done = finished is not None and bool(np.all(finished | ~run.alive))
            if k % setup.log_every == 0 or last or all_done:
                run.log(t, applied_now)
            if setup.observer is not None and not run.observe(t, applied_now):
                break
            if setup.progress is not None and (k % progress_every == 0 or last):
                setup.progress(k, n_steps)
            if last or all_done or not run.advance(t, plan, held_d):
                break
        if setup.on_complete is not None:  # before the Log is built (see simulate)
            setup.on_complete()
    except KeyboardInterrupt:  # Ctrl-C: keep the samples logged so far (see simulate)
        run.interrupted()
    return run.result()


@dataclass
class _NumpyRun:
    """The numpy loop's carried state (:func:`run_numpy`): the plant state ``x``, command,
    applied input, actuator ``lag``, references, the extra logged signals, which ships are
    ``alive`` (``on_divergence="mask"``), and the log being written."""

    setup: SimSetup
    x: np.ndarray
    command: np.ndarray
    applied: np.ndarray
    lag: np.ndarray | None
    data: dict[str, np.ndarray]
    times: np.ndarray
    ref: np.ndarray
    alive: np.ndarray
    diverged_at: np.ndarray
    extra: dict[str, np.ndarray] = field(default_factory=dict)
    status: dict = field(default_factory=lambda: {"diverged": 0, "stopped_early": 0,
                                                  "message": ""})
    first_error: DivergenceError | None = None
    n_logged: int = 0

    @classmethod
    def start(cls, setup: SimSetup) -> _NumpyRun:
        batch, act = setup.batch_shape, setup.actuator
        n_log = setup.n_steps // setup.log_every + 2
        command = np.broadcast_to(setup.u0, (*batch, act.n)).copy()
        applied = act.initial(command)
        return cls(setup, x=setup.x0.copy(), command=command, applied=applied,
                   lag=applied.copy() if act.has_lag else None,
                   data={name: np.full((n_log, *batch), np.nan) for name in log_signals(setup)},
                   times=np.full(n_log, np.nan), ref=np.zeros((*batch, 0)),
                   alive=np.ones(batch, dtype=bool), diverged_at=np.full(batch, np.nan))

    @property
    def masking(self) -> bool:
        return self.setup.on_divergence == "mask"

    def sample(self, t: float) -> bool:
        """A control sample: the state guidance and controller see (the truth, or navigation's
        estimate), the references, the command; False when a bad command ends the run."""
        setup = self.setup
        nav, gd, ctrl = setup.navigation, setup.guidance, setup.controller
        seen = self.x if nav is None else nav.observe(t, self.x, self.applied)
        if gd is not None:
            self.ref = gd.reference(t, seen)
            self.extra = dict(gd.output_values())
        if nav is not None:
            self.extra.update(nav.signal_values())
        if ctrl is None:
            return True
        continuous = bool(getattr(ctrl, "continuous", False))
        command = ctrl.law(t, self.x, self.ref) if continuous else ctrl.step(t, seen, self.ref)
        command = np.asarray(command, dtype=float)
        setup.actuator.check_command_shape(command)
        self.extra.update(ctrl.signal_values())
        if self.masking:  # a ship whose command is bad stops here, the others run on
            self._stop_ships(*newly_diverged(setup, t, self.alive, command=command), t)
            command = np.where(self.alive[..., None], command, 0.0)
        self.command = command
        return self._go_on(None if self.masking else check_divergence(setup, t, command=command))

    def log(self, t: float, applied_now: np.ndarray) -> None:
        """The sample at ``t`` (the state, command, input applied at the step's start, references,
        the extra signals, the tracking errors of the state against the held reference)."""
        setup, data, n = self.setup, self.data, self.n_logged
        self.times[n] = t
        for i, s in enumerate(setup.model.states):
            data[s.name][n] = self.x[..., i]
        for i, name in enumerate(names(setup.model.inputs)):
            data[f"{name}_cmd"][n] = self.command[..., i]
            data[name][n] = applied_now[..., i]
        if setup.guidance is not None:
            for i, s in enumerate(setup.guidance.references):
                data[s.name][n] = self.ref[..., i]
        for name, value in self.extra.items():
            data[name][n] = value
        if setup.guidance is not None:
            for name, value in tracking_errors(setup, self.x, self.ref).items():
                data[name][n] = value
        self.n_logged += 1

    def observe(self, t: float, applied_now: np.ndarray) -> bool:
        """The setup's observer; False when it stops the run."""
        try:
            self.setup.observer(t, self.x, self.command, applied_now)
        except StopSimulation as stop:
            self.status.update(stopped_early=1, message=str(stop) or "stopped by observer")
            return False
        return True

    def advance(self, t: float, plan, held_d) -> bool:
        """The plant over the step from ``t``; False when a bad state ends the run."""
        setup = self.setup
        x_before, lag_before = self.x, self.lag
        x, lag, applied = step_end(setup, t, self.x, self.lag, plan, self.command, self.ref,
                                   held_d)
        if getattr(setup.controller, "switch_within_step", None) is not None:
            x = switch_within_step(setup, t, x_before, x, self.command, held_d)
        if self.masking:  # a ship whose state is bad stops here; a stopped ship's state is held
            self._stop_ships(*newly_diverged(setup, t + setup.dt, self.alive, x=x), t + setup.dt)
            held = ~self.alive[..., None]
            x = np.where(held, x_before, x)
            lag = None if lag is None else np.where(held, lag_before, lag)
            applied = setup.actuator.input_at(plan, 1.0, lag)
        self.x, self.lag, self.applied = x, lag, applied
        return self._go_on(None if self.masking else check_divergence(setup, t + setup.dt, x))

    def _stop_ships(self, bad, error, t: float) -> None:
        if bad is not None:
            self.first_error = self.first_error or error
            self.diverged_at[bad] = t
            self.alive &= ~bad

    def _go_on(self, error) -> bool:
        if error is None:
            return True
        if self.setup.on_divergence == "raise":
            raise error
        self.status.update(diverged=1, message=str(error))
        return False

    def interrupted(self) -> None:
        last = float(self.times[self.n_logged - 1]) if self.n_logged else 0.0
        self.status.update(stopped_early=1, interrupted=1,
                           message=f"interrupted at t = {last:.6g} s")

    def result(self) -> Log:
        n = self.n_logged
        log = Log(time=self.times[:n], data={k: v[:n] for k, v in self.data.items()},
                  signals=log_signals(self.setup), status=self.status)
        if not self.masking:
            return log
        return mask_diverged(log, self.diverged_at, self.first_error, self.setup.dt)


def finished_ships(controller, guidance):
    """Which ships are done (the run ends when every ship is): those whose guidance has
    finished (``guidance.finished()``, e.g. the last waypoint) or whose controller's programme is
    complete (an event-driven controller's ``finished()``, e.g. a manoeuvring trial's rudder
    programme); None when neither says."""
    said = [c.finished() for c in (guidance, controller)
            if c is not None and callable(getattr(c, "finished", None))]
    said = [np.asarray(f, dtype=bool) for f in said if f is not None]
    if not said:
        return None
    return said[0] if len(said) == 1 else np.logical_or(*said)


def switch_within_step(setup: SimSetup, t0: float, x0: np.ndarray, x1: np.ndarray,
                       command: np.ndarray, d_held) -> np.ndarray:
    """A command that switches on a state crossing inside the step (a zig-zag's reversal at ±ψ):
    the controller's ``switch_within_step(t0, x0, x1, command)`` gives, per ship, the fraction θ
    of the step [t0, t0 + dt] at which its crossing happened (NaN: none) and the command after
    it (or None for no ship); those ships are integrated again, RK4 with the old command over θ·dt
    and with the new one over (1 − θ)·dt, so the switch happens at the crossing, not at the next
    sample. The actuator must be static (the input follows the command at once)."""
    said = setup.controller.switch_within_step(t0, x0, x1, command)
    if said is None:
        return x1
    theta, after = said
    hit = np.isfinite(theta)
    if not hit.any():
        return x1
    act, model, dist = setup.actuator, setup.model, setup.disturbance
    require(act.is_static and not (dist is not None and dist.per_stage), "controller",
            type(setup.controller).__name__, "a command that switches inside a step needs a "
            "static actuator and no per-stage disturbance")
    theta = np.where(hit, theta, 1.0)[..., None]

    def rhs(u):
        return lambda t, z: model.derivatives(z, u, d_held)

    with np.errstate(all="ignore"):
        mid = rk4_step(rhs(act.saturate(command)), t0, x0, theta * setup.dt)
        end = rk4_step(rhs(act.saturate(after)), t0 + theta * setup.dt, mid,
                       (1.0 - theta) * setup.dt)
    return np.where(hit[..., None], end, x1)


def newly_diverged(setup: SimSetup, t: float, alive: np.ndarray, *, x: np.ndarray | None = None,
                   command: np.ndarray | None = None):
    """``on_divergence="mask"``: which ships still running have a bad state ``x`` (or
    ``command``) at ``t`` — a boolean mask over the batch, or None — and the first one's
    :class:`DivergenceError` (:func:`check_divergence`; ships already stopped are not checked)."""
    values = x if x is not None else command
    sane = np.where(alive[..., None], values, 0.0)
    error = check_divergence(setup, t, sane) if x is not None else check_divergence(
        setup, t, command=sane)
    if error is None:
        return None, None
    bad = ~np.isfinite(sane)
    if x is not None:
        bad |= np.abs(sane) > np.asarray(setup.model.state_limits, dtype=float)
    return bad.any(axis=-1), error


def mask_diverged(log: Log, diverged_at: np.ndarray, first_error, dt: float) -> Log:
    """``on_divergence="mask"``, both loops: each diverged ship's record NaN from its
    divergence time ``diverged_at`` on (NaN: it ran to the end); ``status`` counts the ships
    that diverged and carries the first one's message."""
    flat = diverged_at.reshape(-1)
    after = log.time[:, None] >= flat[None, :] - 0.5 * dt  # NaN compares False: kept
    for name, values in log.data.items():
        rows = values.reshape(values.shape[0], flat.size)  # (also no samples: Ctrl-C at once)
        rows[after] = np.nan
        log.data[name] = rows.reshape(values.shape)
    n = int(np.count_nonzero(np.isfinite(flat)))
    if n:
        said = f"{first_error} ({n} of {flat.size} ships diverged: each one's record is NaN from then "
        said += "on; the others ran on)"
        earlier = log.status.get("message")  # an interrupt or an observer's stop keeps its word
        log.status.update(diverged=n, message=f"{earlier}; {said}" if earlier else said)
    log.diverged_at = diverged_at
    return log
