"""The composed compiled loop: any model × actuator × controller × guidance × disturbance whose
components have kernels (:mod:`shipgnc.kernels`), run as one numba loop.

:func:`loop_for` is the loop generator: it writes the loop of a combination as a small module
(the combination's sizes and flags as constants, its components' kernels imported by name, the body
of :mod:`shipgnc.sim.loop_template`), compiles it on first use with numba's disk cache (a later
process loads it in well under a second; numba does not cache closures, hence the module) and
memoises it for the process. Measured first compile: 6–11 s per combination on 2 cores
(``benchmarks/bench_families.py``). The loop is :func:`shipgnc.sim.simulator.run_numpy` step for
step, for one ship at a time:

1. every ``Ts``: the guidance's references and outputs, then the controller's command and
   signals (a non-finite command is a divergence at that sample);
2. the actuator's plan of the step (:mod:`shipgnc.actuators`: saturation, rate limit ``ramp`` or
   ``hold``, first-order lag integrated with the plant) and the applied input at its start;
3. a held disturbance sample;
4. the log (every ``log_every``-th sample, the last one, and the sample where every ship's
   guidance has finished);
5. classic RK4 of ``[x, lag]`` (a continuous controller's law and a ``per_stage`` disturbance in
   every stage), the applied input at the step's end, the divergence guard.

Ships are the outer loop (``numba.prange``), time the inner one. A run is one kernel call or
several (progress, bounded log chunks) that carry each ship's state in its row of ``S`` and give
bit-identical results (:func:`shipgnc.sim.compiled.drive`). :func:`unsupported_reason` names the
first component without a kernel; ``simulate`` then runs the numpy loop.

Navigation (:class:`~shipgnc.navigation.Navigation`: sensors and an estimator) enters at step 1:
at each control sample its step (:mod:`shipgnc.sim.nav_template`, written into the combination's
module so the estimators call the model's kernel by name) turns the true state into the state the
guidance and the controller see and the logged ``<state>_meas``, ``<state>_hat``, ... columns
(after the controller's signals, the order of :func:`~shipgnc.sim.simulator.log_signals`); its
table holds the sensors' draws per control sample, from the same child streams as the numpy loop.

A disturbance with ``kernel_current(batch_shape, dt)`` (a force disturbance and an earth-fixed
current, :class:`~shipgnc.environment.current_field.CurrentDisturbance`) gives the loop a second
kernel, called right after the disturbance's own wherever that one is (step start or every RK
stage), with its own parameters and per-step table: the current channels of the model's
disturbance vector are filled once for every force disturbance.
"""

from __future__ import annotations

import importlib
import itertools
import math
from pathlib import Path
from typing import NamedTuple

import numpy as np

from shipgnc.errors import ConfigError
from shipgnc.jit_cache import (  # noqa: F401  (cache_dir, prune_stale_loops: public here too)
    STALE_AFTER,
    cache_dir,
    import_file,
    importable,
    module_file,
    prune_stale_loops,
)
from shipgnc.kernels import Kernel, NotCompiled, kernel_function

_LOOPS: dict = {}
_SOURCES: dict = {}
#: an event that makes the loop skip a ship (:meth:`Composition.advance`: one not live)
_SKIP = np.iinfo(np.int64).max
#: the loop's body (read as source, never imported)
TEMPLATE = Path(__file__).with_name("loop_template.py")
#: the navigation step, written before the loop's body (it calls the model's kernel by name)
NAV_TEMPLATE = Path(__file__).with_name("nav_template.py")
#: the in-loop scoring step, written after the loop's body (it reads the log's column layout)
SCORE_TEMPLATE = Path(__file__).with_name("score_template.py")


class LoopSteps(NamedTuple):
    """The steps of one call of the loop, ``k0 <= k < k1``: ``k_last`` the step logged whatever
    ``every`` (the log's period in steps) that ends the run, ``hold`` the control period in steps,
    ``dt`` the step [s], ``s_base`` the run's sample that the log's first sample holds."""

    k0: int
    k1: int
    k_last: int
    hold: int
    every: int
    dt: float
    s_base: int


class LoopParams(NamedTuple):
    """Each component's parameter rows (one row for every ship, or one per ship; the actuator's
    one flat row, :meth:`~shipgnc.actuators.Actuator.kernel_params`)."""

    model: np.ndarray
    actuator: np.ndarray
    controller: np.ndarray
    guidance: np.ndarray
    disturbance: np.ndarray
    current: np.ndarray
    navigation: np.ndarray


class ScoreArrays(NamedTuple):
    """The in-loop scoring step's accumulators (:mod:`shipgnc.sim.score_template`): ``ops``
    (m, 3) int64 log column, kind and gate, ``span`` (m, 4) window start and end [s] and two arguments,
    ``acc`` (ships, 3 m) each ship's numbers. No accumulator (m = 0): nothing is scored."""

    ops: np.ndarray
    span: np.ndarray
    acc: np.ndarray


def no_scoring(n_ships: int) -> ScoreArrays:
    """The scoring step's arrays when nothing is scored in the loop."""
    return ScoreArrays(np.zeros((0, 3), dtype=np.int64), np.zeros((0, 4)), np.zeros((n_ships, 0)))


class LoopTables(NamedTuple):
    """The per-step input tables (step of the call, ship, ·): a noise's draws, a current part's,
    and the sensors' draws per control sample."""

    disturbance: np.ndarray
    current: np.ndarray
    navigation: np.ndarray


@kernel_function
def _no_controller(t, x, ref, z, p, cmd, sig):
    pass


@kernel_function
def _no_guidance(t, x, z, p, ref, out):
    return False


@kernel_function
def _no_disturbance(t, x, z, p, w, d):
    pass


def loop_for(model_fn, ctrl_fn, guid_fn, dist_fn, cur_fn=_no_disturbance, *, nx: int, nu: int,
             nd: int, nref: int, nout: int, nsig: int, nerr: int, nzc: int, nzg: int, nzd: int,
             has_ctrl: bool, continuous: bool, has_guid: bool, has_dist: bool, per_stage: bool,
             has_lag: bool, rate_limited: bool, hold_mode: bool, has_cur: bool = False,
             est_slot: str | None = None, nzn: int = 0, nnsig: int = 0, ne: int = 0,
             has_score: bool = False, plan: tuple | None = None):
    """The composed loop of one combination (compiled on first use, memoised per process).
    ``cur_fn``: a disturbance's current part (``kernel_current``), called right after ``dist_fn``
    with the same arguments and its own parameters, table and (empty) state. ``est_slot``: None
    without navigation, else the slot of the navigation system's estimator (a function of
    :mod:`shipgnc.sim.nav_template`: ``no_estimator``, ``observer_slot``, ``ekf_slot``,
    ``kf_slot``; or an estimator's own kernel function ``"module:function"`` with the slots'
    signature; :meth:`Navigation.kernel`) that runs after the sensors at each control sample
    with ``nzn`` numbers of state per ship and ``nnsig`` logged signals; ``ne`` the EKF's state
    dimension (the model's ``nx`` plus its augmented states; 0: ``nx``). ``has_score``: the loop
    with the in-loop scoring step (:mod:`shipgnc.sim.score_template`), a loop of its own so that
    the others compile without it; ``plan``: with the step written for one plan
    (:func:`shipgnc.sim.scored.score_plan`'s signature), a loop per plan, else the generic step
    that reads the plan at run time."""
    key = (model_fn, ctrl_fn, guid_fn, dist_fn, cur_fn, nx, nu, nd, nref, nout, nsig, nerr, nzc,
           nzg, nzd, has_ctrl, continuous, has_guid, has_dist, per_stage, has_lag, rate_limited,
           hold_mode, has_cur, est_slot, nzn, nnsig, ne or nx, has_score, plan)
    if key not in _LOOPS:
        _LOOPS[key] = _generate(*key)
    return _LOOPS[key]


def _generate(*key):
    """The combination's loop: from a module written to the disk cache and compiled with numba's
    cache (loaded in ≈ 0.1 s by later processes) when every kernel is importable by name; else
    compiled in memory, once per process (a kernel defined in a script or a notebook), its source
    written to the cache all the same (``shipgnc_memory_*.py``: what runs, to read);
    :func:`source_path` names the file (None when the cache is not writable)."""
    functions = key[:5]
    importable_by_name = all(importable(fn) for fn in functions)
    source = _source(*key, imports=importable_by_name)
    slot = key[24]  # an estimator's own kernel ("module:function"): its file keys the loop too
    hashed = (*functions, _resolve(slot)) if slot and ":" in slot else functions
    if importable_by_name:  # numba's cache rebuilds the loop's module by name
        path = module_file(source, hashed, prefix="shipgnc_loop")
        if path is not None:
            loop = import_file(path).loop
            _SOURCES[loop] = path
            return loop
    namespace = dict(zip(("model_fn", "ctrl_fn", "guid_fn", "dist_fn", "cur_fn"), functions,
                         strict=True))
    source = source.replace("CACHE = True", "CACHE = False")
    path = module_file(source, hashed, prefix="shipgnc_memory")  # to read, never imported
    exec(compile(source, str(path) if path else "<shipgnc composed loop>", "exec"), namespace)
    _SOURCES[namespace["loop"]] = path
    return namespace["loop"]


def source_path(loop) -> Path | None:
    """The file holding the source of a composed ``loop`` (:func:`loop_for`; also
    :attr:`Composition.source_path`): exactly what runs."""
    return _SOURCES.get(loop)


def _resolve(target: str):
    module, _, name = target.partition(":")
    return getattr(importlib.import_module(module), name)


def _source(model_fn, ctrl_fn, guid_fn, dist_fn, cur_fn, nx, nu, nd, nref, nout, nsig, nerr, nzc,
            nzg, nzd, has_ctrl, continuous, has_guid, has_dist, per_stage, has_lag, rate_limited,
            hold_mode, has_cur, est_slot, nzn, nnsig, ne, has_score=False, plan=None, *,
            imports: bool):
    """Source of the combination's module: constants, the components' kernels, the navigation
    step, the loop body, the scoring step (generic, or of ``plan``)."""
    from shipgnc.sim.scored import score_step_source

    nl = nu if has_lag else 0
    lay = row_layout(nx, nl, nu, nref, nout, nsig, nd, nzc, nzg, nzd, nzn, nnsig)
    constants = {
        "nx": nx, "nu": nu, "nd": nd, "nref": nref, "nout": nout, "nsig": nsig, "nerr": nerr,
        "nzc": nzc, "nzg": nzg, "nzd": nzd, "nl": nl, "nz": nx + nl,
        "has_ctrl": has_ctrl, "continuous": continuous, "has_guid": has_guid,
        "has_dist": has_dist, "per_stage": per_stage, "has_lag": has_lag,
        "rate_limited": rate_limited, "hold_mode": hold_mode, "has_cur": has_cur,
        "has_nav": est_slot is not None, "nzn": nzn, "nnsig": nnsig, "ne": ne,
        "has_score": has_score,
        **{f"o_{name}": lay[key] for name, key in (
            ("x", "x"), ("lag", "lag"), ("app", "applied"), ("cmd", "cmd"), ("ref", "ref"),
            ("out", "out"), ("sig", "sig"), ("d", "d"), ("done", "done"), ("zc", "zc"),
            ("zg", "zg"), ("zd", "zd"), ("zn", "zn"), ("nsg", "nsg"))},
        **{f"c_{name}": col for name, col in log_columns(
            nx, nu, nref, nerr, nout, nsig, nnsig).items()},
    }
    lines = ["# generated by shipgnc.sim.compose: the loop of one combination of components",
             "CACHE = True"]
    for alias, fn in (("model_fn", model_fn), ("ctrl_fn", ctrl_fn), ("guid_fn", guid_fn),
                      ("dist_fn", dist_fn), ("cur_fn", cur_fn)):
        py = getattr(fn, "py_func", fn)
        if imports:
            lines.append(f"from {py.__module__} import {py.__qualname__} as {alias}")
        else:  # bound by the compiler's namespace (not importable by name)
            lines.append(f"# {alias} = {py.__module__}.{py.__qualname__}")
    lines += [f"{name} = {value!r}" for name, value in constants.items()]
    slot = f"\nest_slot = {est_slot or 'no_estimator'}\n"
    if est_slot is not None and ":" in est_slot:  # an estimator's own kernel, by its module
        module, _, name = est_slot.partition(":")
        slot = f"\nfrom {module} import {name} as est_slot\n"
    elif est_slot is not None and not est_slot.isidentifier():
        raise ValueError(f"est_slot = {est_slot!r}: not a slot of the navigation template")
    return ("\n".join(lines) + "\n" + NAV_TEMPLATE.read_text() + slot + "\n" + TEMPLATE.read_text()
            + "\n" + SCORE_TEMPLATE.read_text() + "\n\n" + score_step_source(plan)
            + '\nloop = numba.njit(parallel=True, **{**JIT_OPTIONS, "cache": CACHE})(loop)\n')


# ----------------------------------------------------------------------------------------------
# entry points: which setups the composed loop covers, and running one
# ----------------------------------------------------------------------------------------------

def _roles(setup):
    return (("model", setup.model), ("controller", setup.controller),
            ("guidance", setup.guidance), ("disturbance", setup.disturbance))


def unsupported_reason(setup) -> str | None:
    """None when every component of ``setup`` has a kernel, else which one has none and why."""
    if setup.integrator != "rk4":
        return f"integrator {setup.integrator!r} is not compiled (only 'rk4')"
    if setup.observer is not None:
        return "an observer callback needs the Python loop"
    nav = getattr(setup, "navigation", None)
    if nav is not None:
        why = getattr(nav, "kernel_reason", None)
        reason = why() if callable(why) else "it has no kernel"
        if reason:
            return f"navigation: {reason}"
    for role, component in _roles(setup):
        if component is None:
            continue
        if not callable(getattr(component, "kernel", None)):
            return f"{role} {type(component).__name__} has no kernel"
        why = getattr(component, "kernel_reason", None)
        reason = why() if callable(why) else None
        if reason:
            return f"{role} {type(component).__name__}: {reason}"
    return None


class Composition:
    """A setup's composed loop with its carried state: each ship's row of ``S`` (state, lag,
    applied input, command, references, components' states; :func:`row_layout`), the log
    ``out`` (column, sample, ship) in the order of :func:`~shipgnc.sim.simulator.log_signals`,
    each ship's divergence ``event`` (2k: a bad command at sample k, 2k + 1: a bad state after
    step k; −1: none; a ship with an event is skipped) and ``done_at``. Built after the
    components' reset (:func:`~shipgnc.sim.simulator.reset_components`); :meth:`call` runs steps
    ``k0 … k1 − 1`` of every ship. :func:`run` drives it over a whole run; the loop's transition
    (:class:`~shipgnc.sim.transition.Transition`, an agent's episode) a control period at a time
    (:meth:`advance`, :meth:`carried`, :meth:`put_state`), with a log of
    ``log_samples`` samples from sample :attr:`s_base` (set before each call) instead of the whole
    run's. ``scored``: the loop with the in-loop scoring step (:meth:`score_in_loop`)."""

    def __init__(self, setup, log_samples: int | None = None, scored: bool = False):
        from shipgnc.sim.compiled import log_length
        from shipgnc.sim.simulator import log_signals

        model, act, ctrl, gd, dist = (setup.model, setup.actuator, setup.controller,
                                      setup.guidance, setup.disturbance)
        self.setup, self.scored = setup, scored
        batch = setup.batch_shape
        n = math.prod(batch)
        try:
            km = model.kernel()
            kc = ctrl.kernel(batch) if ctrl is not None else None
            kg = gd.kernel(batch) if gd is not None else None
            kd = dist.kernel(batch, dt=setup.dt) if dist is not None else None
            # a disturbance with a current part (environment.current_field.CurrentDisturbance)
            cur = getattr(dist, "kernel_current", None)
            ku = cur(batch, dt=setup.dt) if callable(cur) else None
            nav = setup.navigation
            kn = nav.kernel(batch, dt=setup.dt, x0=setup.x0) if nav is not None else None
        except NotCompiled as exc:  # a setting only known after reset: the caller falls back
            raise ConfigError(f"compiled loop: {exc}") from None
        empty = Kernel(_no_controller)
        kc_, kg_, kd_ = kc or empty, kg or empty, kd or empty
        self._stateful = ((kc, "zc"), (kg, "zg"), (kd, "zd"))

        nx, nu = len(model.states), act.n
        nd = len(model.disturbances)
        refs = tuple(gd.references) if gd is not None else ()
        nout = len(gd.outputs) if gd is not None else 0
        nsig = len(getattr(ctrl, "signals", ())) if ctrl is not None else 0
        state_names = [s.name for s in model.states]
        err = np.array([(state_names.index(s.tracks), j, int(s.angle)) for j, s in enumerate(refs)
                        if s.tracks], dtype=np.int64).reshape(-1, 3)
        zc0, zg0, zd0 = kc_.state_for(n), kg_.state_for(n), kd_.state_for(n)
        zn0 = kn.state_for(n) if kn else np.zeros((n, 0))
        nnsig = kn.n_signals if kn else 0
        continuous = bool(getattr(ctrl, "continuous", False))
        self._loop_for = lambda plan: loop_for(
            km.function, kc.function if kc else _no_controller,
            kg.function if kg else _no_guidance, kd.function if kd else _no_disturbance,
            nx=nx, nu=nu, nd=nd, nref=len(refs), nout=nout, nsig=nsig, nerr=err.shape[0],
            nzc=zc0.shape[1], nzg=zg0.shape[1], nzd=zd0.shape[1], has_ctrl=ctrl is not None,
            continuous=continuous, has_guid=gd is not None, has_dist=dist is not None,
            per_stage=bool(getattr(dist, "per_stage", False)), has_lag=act.has_lag,
            rate_limited=act.has_rate_limit, hold_mode=act.rate_mode == "hold",
            cur_fn=ku.function if ku else _no_disturbance, has_cur=ku is not None,
            est_slot=kn.estimator if kn else None, nzn=zn0.shape[1], nnsig=nnsig,
            ne=kn.n_filter if kn else 0, has_score=scored, plan=plan)
        self.loop = loop = self._loop_for(None)  # compiled at its first call
        #: the file holding the loop's generated source, exactly what runs (:func:`source_path`)
        self.source_path = source_path(loop)
        self._nx = nx
        lay = row_layout(nx, nu if act.has_lag else 0, nu, len(refs), nout, nsig, nd,
                         zc0.shape[1], zg0.shape[1], zd0.shape[1], zn0.shape[1], nnsig)
        self.layout = lay
        self.widths = {"zc": zc0.shape[1], "zg": zg0.shape[1], "zd": zd0.shape[1]}

        S = np.zeros((n, lay["row"]))
        S[:, :nx] = setup.x0.reshape(n, nx)
        command = np.broadcast_to(setup.u0, (*batch, nu)).reshape(n, nu)
        applied = act.initial(command)
        if act.has_lag:
            S[:, lay["lag"]:lay["lag"] + nu] = applied
        S[:, lay["applied"]:lay["applied"] + nu] = applied
        S[:, lay["cmd"]:lay["cmd"] + nu] = command
        S[:, lay["zc"]:lay["zc"] + zc0.shape[1]] = zc0
        S[:, lay["zg"]:lay["zg"] + zg0.shape[1]] = zg0
        S[:, lay["zd"]:lay["zd"] + zd0.shape[1]] = zd0
        S[:, lay["zn"]:lay["zn"] + zn0.shape[1]] = zn0
        self.S = S

        self.signals = log_signals(setup)
        cols = log_columns(nx, nu, len(refs), err.shape[0], nout, nsig, nnsig)
        n_columns = cols["end"]
        if n_columns != len(self.signals):  # the loop's column layout must match the numpy log
            raise RuntimeError(f"compiled loop: {n_columns} log columns for {list(self.signals)}")
        #: log columns of the state and of the applied input
        self.columns = {"x": cols["x"], "cmd": cols["cmd"], "applied": cols["app"]}
        self.out = np.empty((n_columns, log_length(setup) if log_samples is None else log_samples, n))
        #: the run's sample that ``out[:, 0]`` holds
        self.s_base = 0
        self.event = np.full(n, -1, dtype=np.int64)
        # only guidance that can finish (a route's last waypoint) ends a run early
        can_finish = gd is not None and gd.finished() is not None
        self.done_at = np.full(n, -1, dtype=np.int64) if can_finish else None
        self._no_done = np.zeros(n, dtype=np.int64)
        self._params = [_param_rows(k, n) for k in (km, kc_, kg_, kd_)]
        self._pa = act.kernel_params()
        self._limits = np.asarray(model.state_limits, dtype=np.float64)
        self._err = err
        self._table = {"W": np.zeros((1, n, 0)), "Wu": np.zeros((1, n, 0)), "Wn": np.zeros((1, n, 0))}
        self._tabled = (("W", kd), ("Wu", ku), ("Wn", kn))
        self._kn = kn
        self._pu = _param_rows(ku or empty, n)
        self._pn = _param_rows(kn or empty, n)
        #: the in-loop scoring step's accumulators (none unless :meth:`score_in_loop`)
        self.score = no_scoring(n)
        self._plan = None  # the plan whose own scoring step the loop takes (None: generic)

    def score_in_loop(self, ops: np.ndarray, span: np.ndarray, acc: np.ndarray,
                      unrolled: bool = False) -> None:
        """Score every step in the loop into ``acc`` (ships, 3 m), updated in place
        (:class:`ScoreArrays`; :mod:`shipgnc.sim.scored`); ``unrolled``: in the loop of this
        plan's own step (:func:`shipgnc.sim.scored.score_plan`: compiled at its first call unless
        it is in the disk cache; not for an empty plan nor one of more than
        :data:`~shipgnc.sim.scored.OWN_STEP_MAX_ACCUMULATORS`), else in the combination's scored
        loop (also when a loop of another plan's own step ran before)."""
        from shipgnc.sim.scored import own_step, score_plan

        if not self.scored:
            raise ValueError("score_in_loop: the Composition was built without scored=True")
        n = self.S.shape[0]
        ops = np.ascontiguousarray(ops, dtype=np.int64).reshape(-1, 3)
        span = np.ascontiguousarray(span, dtype=np.float64).reshape(-1, 4)
        if acc.shape != (n, 3 * ops.shape[0]) or acc.dtype != np.float64 or not acc.flags.c_contiguous:
            raise ValueError(f"score_in_loop: acc must be C-contiguous float64 of shape "
                             f"({n}, {3 * ops.shape[0]}), not {acc.dtype} {acc.shape}")
        if ops.shape[0] and not (0 <= ops[:, 0].min() and ops[:, 0].max() < len(self.signals)):
            raise ValueError(f"score_in_loop: log columns {ops[:, 0].tolist()} outside "
                             f"0 … {len(self.signals) - 1}")
        signature = score_plan(ops, span, self._nx)  # checks the plan whichever loop runs it
        # the loop of this plan's own step, or the generic one again (a loop written for another
        # plan would read past this plan's arrays: numba checks no bounds)
        self._plan = signature if unrolled and own_step(signature) else None
        self.loop = self._loop_for(self._plan)
        self.source_path = source_path(self.loop)
        self.score = ScoreArrays(ops, span, acc)

    def prepare(self, k0: int, k1: int) -> None:
        """The input tables of steps ``k0 … k1 − 1`` (a noise's draws, the sensors' draws)."""
        n = self.S.shape[0]
        table = self._table
        for name, k in self._tabled:
            if k is not None and k.table is not None:
                table[name] = np.ascontiguousarray(k.table(k0, k1), dtype=np.float64)
            else:
                table[name] = np.zeros((k1 - k0, n, 0))
        if self._kn is not None and table["Wn"].shape[0] == 0:  # a chunk without a control sample
            table["Wn"] = np.zeros((1, n, self._kn.n_table))

    def call(self, k0: int, k1: int, k_last: int) -> None:
        """Steps ``k0 <= k < k1`` of every ship without an event (``k_last``: the step logged
        whatever ``log_every`` that ends the run); :meth:`prepare` first."""
        setup, table, params = self.setup, self._table, self._params
        if self._plan is not None and len(self._plan) != self.score.ops.shape[0]:
            raise ValueError(f"Composition.call: the loop is written for a plan of "
                             f"{len(self._plan)} accumulators, the scoring arrays hold "
                             f"{self.score.ops.shape[0]}")
        steps = LoopSteps(int(k0), int(k1), int(k_last), int(setup.hold), int(setup.log_every),
                          float(setup.dt), int(self.s_base))
        self.loop(steps, self.S, self.out, self.event,
                  self.done_at if self.done_at is not None else self._no_done,
                  LoopParams(params[0], self._pa, params[1], params[2], params[3], self._pu,
                             self._pn),
                  LoopTables(table["W"], table["Wu"], table["Wn"]), self._limits, self._err,
                  self.score)

    def put_state(self, x: np.ndarray) -> None:
        """Each ship's plant state ``x`` (B, n) into its row (e.g. a member's drawn start)."""
        self.S[:, :x.shape[-1]] = x.reshape(self.S.shape[0], -1)

    def carried(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Copies of each ship's plant state, applied input and actuator lag state (B, ·)."""
        lay, S = self.layout, self.S
        nx, nu = len(self.setup.model.states), self.setup.actuator.n
        return (S[:, :nx].copy(), S[:, lay["applied"]:lay["applied"] + nu].copy(),
                S[:, lay["lag"]:lay["lag"] + nu].copy())

    def advance(self, command: np.ndarray, live: np.ndarray, k0: int, k1: int, k_last: int):
        """Steps ``k0 … k1 − 1`` of the ``live`` ships (the others skipped) with ``command``
        (B, m) held in their rows, the log being these steps (a :class:`Composition` built with
        ``log_samples`` ≥ k1 − k0). A ship whose state goes bad after step k is replayed from the
        period's start up to that step (the same table's draws), so it stays frozen before it, as
        the numpy loop's members do. Returns the state and the applied input at each step's start
        (steps, B, ·), which ships diverged (B,) and the step of each one's bad state
        (``k_last`` for none)."""
        lay, S, out = self.layout, self.S, self.out
        nx, nu = len(self.setup.model.states), self.setup.actuator.n
        S[:, lay["cmd"]:lay["cmd"] + nu] = command
        start = S.copy()
        self.event[:] = np.where(live, -1, _SKIP)
        self.s_base = k0  # the log holds this period's steps
        self.prepare(k0, k1)
        self.call(k0, k1, k_last)
        bad = live & (self.event >= 0)
        k_bad = np.where(bad, self.event // 2, k_last)  # a bad state after step k_bad
        x_log = out[:nx, :k1 - k0].transpose(1, 2, 0).copy()
        a = self.columns["applied"]
        applied_log = out[a:a + nu, :k1 - k0].transpose(1, 2, 0).copy()
        for i in np.flatnonzero(bad):  # frozen before its bad step
            S[i] = start[i]
            self.event[:] = _SKIP
            self.event[i] = -1
            self.call(k0, int(k_bad[i]), k_last)
        return x_log, applied_log, bad, k_bad

    def restore(self) -> None:
        """Leave the components as the numpy loop would (their carried states)."""
        lay, S = self.layout, self.S
        for k, key in self._stateful:
            if k is not None and k.restore is not None:
                width = self.widths[key]
                k.restore(S[:, lay[key]:lay[key] + width].copy())


def run(setup):
    """Run ``setup`` in its composed loop; returns the same ``Log`` as ``run_numpy(setup)``."""
    from shipgnc.sim.compiled import drive, make_log
    from shipgnc.sim.simulator import reset_components

    reason = unsupported_reason(setup)
    if reason:
        raise ConfigError(f"compiled loop: {reason}")
    reset_components(setup)  # the same side effects on the components as the numpy loop
    comp = Composition(setup)
    stop = drive(setup, comp.call, comp.S, comp.event, prepare=comp.prepare, done_at=comp.done_at)
    comp.restore()
    return make_log(setup, comp.signals, comp.out, comp.S, stop.event, state_slot=0,
                    cmd_slot=comp.layout["cmd"], k_end=stop.k_end, interrupted=stop.interrupted,
                    events=comp.event)


def _param_rows(kernel: Kernel, n_ships: int) -> np.ndarray:
    """A kernel's parameters as rows: ``(1, n_p)`` shared by every ship, or ``(n_ships, n_p)``."""
    rows = np.ascontiguousarray(np.atleast_2d(kernel.params), dtype=np.float64)
    if rows.shape[0] not in (1, n_ships):
        raise ConfigError(f"compiled loop: {rows.shape[0]} parameter rows for {n_ships} ships")
    return rows


def offsets(widths: dict[str, int]) -> dict[str, int]:
    """Where each named block starts when the blocks of ``widths`` follow each other in order."""
    return dict(zip(widths, itertools.accumulate(widths.values(), initial=0), strict=False))


def row_layout(nx, nl, nu, nref, nout, nsig, nd, nzc, nzg, nzd, nzn=0, nnsig=0) -> dict[str, int]:
    """Offsets of a ship's row of ``S``: state, lag, applied input, command, references, guidance
    outputs, controller signals, held disturbance, finished flag, the components' own states,
    the navigation's state and its held logged signals; ``row``: the row's length."""
    return offsets({"x": nx, "lag": nl, "applied": nu, "cmd": nu, "ref": nref, "out": nout,
                    "sig": nsig, "d": nd, "done": 1, "zc": nzc, "zg": nzg, "zd": nzd, "zn": nzn,
                    "nsg": nnsig, "row": 0})


def log_columns(nx, nu, nref, nerr, nout, nsig, nnsig) -> dict[str, int]:
    """First column of each block of the loop's log, in the order of
    :func:`~shipgnc.sim.simulator.log_signals`: state, command, applied input, references,
    tracking errors, guidance outputs, controller signals, navigation signals; ``end``: the
    number of columns."""
    return offsets({"x": nx, "cmd": nu, "app": nu, "ref": nref, "err": nerr, "out": nout,
                    "sig": nsig, "nav": nnsig, "end": 0})
