"""Collision-avoidance guidance: between the path guidance and the autopilot.

Each sample the guidance

1. computes the nominal course χ_n and speed U_n toward the waypoints with lookahead LOS
   (:func:`shipgnc.guidance.los.los_reference`, the same law and leg switching as ``type: los``);
2. dead-reckons every target from its track table (:class:`shipgnc.colav.tracks.TargetTrack`:
   the last sample at or before t, moved on at constant velocity) to its position and velocity
   over ground at t, and keeps the least range to any target so far (``range_min``, its time and
   target: the realised closest point of approach, at every guidance sample whatever the log's
   thinning); targets that are vessels (:mod:`shipgnc.guidance.vessel_targets`: their own
   steering, autopilot, waypoints and avoidance) are integrated from the last sample to t instead,
   seeing the own ship's state as the guidance sees it; with ``seen`` tracks (the targets as the
   own ship's AIS receiver hears them, :func:`shipgnc.ais.reporting.seen_tracks`) the avoidance is
   handed the seen targets — the last report received, dead-reckoned from its SOG and COG, absent
   until first heard — while ``range_min`` (and so the scores) stays the true tracks' (seen tracks
   exist for track targets only: a run seeing through AIS refuses vessel targets,
   :func:`_seen_members`);
3. hands the own ship ``[north, east, χ, U]`` (course and speed over ground,
   χ = ψ + atan2(v, u), U = √(u² + v²)), the targets and the nominal ``[χ_n, U_n]`` to the
   avoidance method, which returns the commanded course and speed; with ``method = none`` the
   command is the nominal;
4. hands the autopilot the commanded course as its heading reference ``psi_d`` (the sideslip of
   a steady straight run is zero on the catalogue's course-keeping models, so course and heading
   references coincide there; Johansen, Perez & Cristofaro 2016 likewise give the autopilot the
   chosen course) and the commanded speed as ``u_d`` (followed by controllers that take a speed
   reference; the catalogue's heading autopilot holds its propeller).

Batched: each ship of a batch may meet its own targets — the parameters are one row per ship
(targets padded to the batch's largest count and sample count), so every member of a batch can be
a different encounter. The per-ship arithmetic is one kernel (:func:`colav_reference`); the numpy
loop calls its derived batch (:func:`shipgnc.derive.per_ship`).
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.colav.sbmpc import sbmpc_choose
from shipgnc.colav.tracks import TargetTrack
from shipgnc.colav.vo import vo_choose
from shipgnc.derive import per_ship
from shipgnc.errors import ConfigError, require
from shipgnc.guidance.los import LOSGuidance, los_reference
from shipgnc.guidance.vessel_targets import S_FIXED, SCRATCH, VesselTarget, vessel_targets
from shipgnc.kernels import Kernel, flat, kernel_function, wrap
from shipgnc.models.base import Signal, state_index
from shipgnc.navigation.layout import Layout

#: avoidance methods by name → the kernel's method code
METHODS = {"none": 0, "sbmpc": 1, "vo": 2}
#: the fixed head of a parameter row (:meth:`ColavGuidance.params`), every offset from its names
HEAD = Layout("colav parameters", ("n_los", 1), ("method", 1), ("n_targets", 1), ("n_samples", 1),
              ("n_max", 1), ("i_north", 1), ("i_east", 1), ("i_psi", 1), ("i_u", 1), ("i_v", 1),
              ("n_mp", 1), ("memory", 1), ("interval", 1), ("n_seen", 1), ("n_vessels", 1),
              ("width_p", 1), ("width_z", 1),
              tail="the LOS parameters (n_los), the true tables (n_max × n_samples × 5), the "
                   "method's parameters (n_mp), the seen tables (n_max × n_seen × 5), the vessel "
                   "targets' blocks (n_vessels × width_p)")
HEAD_SIZE = HEAD.size
(_N_LOS, _METHOD, _N_TARGETS, _N_SAMPLES, _N_MAX, _I_NORTH, _I_EAST, _I_PSI, _I_U, _I_V, _N_MP,
 _MEMORY, _INTERVAL, _N_SEEN, _N_VESSELS, _WIDTH_P, _WIDTH_Z) = HEAD.at(*(f for f, _ in HEAD.fields))
#: logged per vessel target slot (:mod:`shipgnc.guidance.vessel_targets`): north, east, heading,
#: after the guidance's nine outputs (:attr:`ColavGuidance.outputs`)
_VESSEL_OUT = ("north", "east", "psi")
#: a vessel target's integrated state (its block's first numbers) and units
_VESSEL_STATE = (("north", "m"), ("east", "m"), ("psi", "rad"), ("r", "rad/s"), ("delta", "rad"))
_BASE_OUT = 9
#: the LOS part of the per-ship state, then [next decision time, course offset, speed factor,
#: least range so far, its time, its target]
_LOS_STATE = 6
_HOLD = 6


def method_parts(method: str, config=None) -> tuple[np.ndarray, int]:
    """(flat parameters, memory length) of avoidance ``method`` with its ``config`` (None: the
    method's defaults)."""
    if method == "sbmpc":
        from shipgnc.colav.sbmpc import SBMPC_MEMORY, sbmpc_params

        return sbmpc_params(config), SBMPC_MEMORY
    if method == "vo":
        from shipgnc.colav.vo import VO_MEMORY, vo_params

        return vo_params(config), VO_MEMORY
    return flat(0.0), 0


class ColavGuidance:
    """LOS toward the waypoints, then collision avoidance against ``encounters`` (module
    docstring): ``encounters`` is one list of :class:`TargetTrack` per batch member (a list of
    tracks alone: the same targets for every member). ``seen``: the targets as the avoidance sees
    them, the same shape (None for a target never heard); None: the true tracks."""

    references = (
        Signal("psi_d", "rad", "desired heading: the commanded course", angle=True, tracks="psi"),
        Signal("u_d", "m/s", "desired surge speed: the commanded speed", tracks="u"),
    )
    outputs = (
        *LOSGuidance.outputs,
        Signal("course_nominal", "rad", "nominal course toward the waypoints (LOS)", angle=True),
        Signal("course_cmd", "rad", "course commanded by the collision avoidance", angle=True),
        Signal("speed_cmd", "m/s", "speed commanded by the collision avoidance"),
        Signal("range_min", "m", "least range to any target so far (at the guidance samples)"),
        Signal("t_range_min", "s", "time of range_min"),
        Signal("target_range_min", "1", "target (0-based) of range_min"),
    )

    def __init__(self, los: LOSGuidance, encounters, *, method: str = "none", methods=None,
                 configs=None, decision_interval: float = 5.0, seen=None):
        methods = [method] if methods is None else list(methods)
        for m in methods:
            require(m in METHODS, "guidance.method", m, f"allowed: {', '.join(METHODS)}")
        require(math.isfinite(decision_interval) and decision_interval >= 0,
                "guidance.decision_interval", decision_interval, "must be >= 0 s")
        members = [list(encounters)] if not encounters or isinstance(
            encounters[0], (TargetTrack, VesselTarget)) \
            else [list(m) for m in encounters]
        for m, tracks in enumerate(members):
            for track in tracks:
                if not isinstance(track, (TargetTrack, VesselTarget)):
                    raise ConfigError(f"targets of member {m}: {track!r} is not a TargetTrack "
                                      "or a VesselTarget")
        self.los = los
        if len(methods) not in (1, len(members)) and len(members) != 1:
            raise ConfigError(f"methods: {len(methods)} for {len(members)} encounters (give one, "
                              "or one per encounter)")
        self.members = members
        self.methods = methods
        self.decision_interval = float(decision_interval)
        configs = configs or {}
        self.parts = {m: method_parts(m, configs.get(m)) for m in dict.fromkeys(methods)}
        self.memory = max(memory for _, memory in self.parts.values())
        self.n_max = max(1, max(len(t) for t in members))
        self.n_samples = max([1] + [tr.t.size for tracks in members for tr in tracks
                                    if isinstance(tr, TargetTrack)])
        self._vessels_init(members, configs)
        self.seen = None if seen is None else _seen_members(seen, members)
        self.n_seen = 0 if self.seen is None else max(
            [1] + [tr.t.size for tracks in self.seen for tr in tracks if tr is not None])
        self._z = None
        self._outputs: dict[str, np.ndarray] = {}

    # ------------------------------------------------------------------ vessel targets
    def _vessels_init(self, members, configs) -> None:
        """The vessel targets (:class:`~shipgnc.guidance.vessel_targets.VesselTarget`) of every
        member, their avoidance's parameters (the own ship's ``configs``, course offsets only: the
        reduced model holds its speed), block widths and logged slots."""
        from shipgnc.colav.sbmpc import SBMPCConfig
        from shipgnc.colav.vo import VOConfig

        configs = configs or {}
        self._vessels = [[(j, tr) for j, tr in enumerate(tracks) if isinstance(tr, VesselTarget)]
                         for tracks in members]
        self.n_vessels = max([0] + [len(v) for v in self._vessels])
        kinds = dict.fromkeys(tr.avoidance for v in self._vessels for _, tr in v
                              if tr.avoidance != "none")
        defaults = {"sbmpc": SBMPCConfig, "vo": VOConfig}
        self._vessel_mp, memory = {}, 0
        for kind in kinds:
            config = (configs.get(kind) or defaults[kind]()).model_copy(
                update={"speed_factors": [1.0]})
            self._vessel_mp[kind], m = method_parts(kind, config)
            memory = max(memory, m)
        self._width_z = S_FIXED + memory + SCRATCH if self.n_vessels else 0
        self._width_p = max([0] + [tr.params(j, self._vessel_mp.get(tr.avoidance, flat())).size
                                   for v in self._vessels for j, tr in v])
        if self.n_vessels:
            self.outputs = (*ColavGuidance.outputs, *(
                Signal(f"vessel_target{k}_{q}", "rad" if q == "psi" else "m",
                       f"vessel target slot {k}: {q}", angle=q == "psi")
                for k in range(self.n_vessels) for q in _VESSEL_OUT))

    def _vessel_params(self, tracks) -> np.ndarray:
        """The vessel targets' parameter blocks of one member, ``(n, width)`` zero-padded."""
        blocks = [tr.params(j, self._vessel_mp.get(tr.avoidance, flat()))
                  for j, tr in enumerate(tracks) if isinstance(tr, VesselTarget)]
        out = np.zeros((len(blocks), self._width_p))
        for k, block in enumerate(blocks):
            out[k, :block.size] = block
        return out

    def _vessels_reset(self, n: int) -> None:
        """Every row's vessel targets at their start."""
        zo = _LOS_STATE + _HOLD + self.memory + 8 + 4 * self.n_max
        w = self._width_z
        for row in range(n if self.n_vessels else 0):
            for k, (_, tr) in enumerate(self._vessels[row % len(self._vessels)]):
                self._z[row, zo + k * w:zo + (k + 1) * w] = tr.state(w)

    def divergence_cause(self, index: tuple = ()) -> str | None:
        """Why ship ``index`` of the batch got non-finite references: its first vessel target
        whose state (n, e, ψ, r, δ) is no longer finite, named by its scenario field
        (``guidance.targets[j]``) and state, as ``vessel target FIELD (LABEL): its state 'NAME' =
        VALUE UNIT (not finite)`` — or None (no vessel target went bad). The state is the one at
        the sample the run stopped on (the components' carried states)."""
        if not self.n_vessels or self._z is None:
            return None
        row = int(np.ravel_multi_index(index, self._batch_shape)) if index else 0
        zo = _LOS_STATE + _HOLD + self.memory + 8 + 4 * self.n_max
        w = self._width_z
        for k, (j, tr) in enumerate(self._vessels[row % len(self._vessels)]):
            block = self._z[row, zo + k * w:zo + k * w + len(_VESSEL_STATE)]
            for (name, unit), value in zip(_VESSEL_STATE, block, strict=True):
                if not math.isfinite(value):
                    where = tr.where or f"target {j + 1}"
                    return (f"vessel target {where} ({tr.label}): its state '{name}' = "
                            f"{value:g} {unit} (not finite)")
        return None

    def _vessel_states(self, states, result):
        """``states`` (time, member, target) per ship of ``result``, the vessel targets' from
        their logged slots; returns (states per ship, the slots' variable names)."""
        time = result["time"].values
        n_ships = math.prod(result["north"].shape[1:])
        rows = np.arange(n_ships) % len(self.members)
        out = {key: value[:, rows, :].copy() for key, value in states.items()}
        names = [f"vessel_target{k}_{q}" for k in range(self.n_vessels) for q in _VESSEL_OUT]
        logged = {name: result[name].values.reshape(time.size, n_ships) for name in names}
        for i, m in enumerate(rows):
            for k, (j, tr) in enumerate(self._vessels[m]):
                out["target_north"][:, i, j] = logged[f"vessel_target{k}_north"][:, i]
                out["target_east"][:, i, j] = logged[f"vessel_target{k}_east"][:, i]
                out["target_sog"][:, i, j] = tr.U
                out["target_cog"][:, i, j] = np.mod(logged[f"vessel_target{k}_psi"][:, i],
                                                    2 * np.pi)
        return out, names

    # ------------------------------------------------------------------ set-up
    @property
    def path(self):
        return self.los.path

    @property
    def speed(self) -> float:
        return self.los.speed

    def params(self) -> np.ndarray:
        """One parameter row per member, shape ``(n_members, n_p)``, shorter rows padded with zeros.

        A row holds the head :data:`HEAD` (n_los, method, n_targets, n_samples, n_max, i_north,
        i_east, i_psi, i_u, i_v (−1 for none), n_method_params, memory, the decision interval,
        n_seen (the seen tables' sample count, 0: the avoidance sees the true tables), the number
        of vessel targets and the widths of their parameter and state blocks), then the LOS
        parameters (n_los numbers), the targets (n_max × n_samples × (t, north, east, v_north,
        v_east), unused samples — and every sample of a vessel target — at t = +inf), the method's
        parameters, the seen targets (n_max × n_seen × 5) and the vessel targets' parameter blocks
        (:meth:`_vessel_params`).
        """
        los = self.los.kernel(self._batch_shape).params
        rows = []
        n = max(len(self.members), len(self.methods))
        for m in range(n):
            tracks = self.members[m % len(self.members)]
            method = self.methods[m % len(self.methods)]
            mp, _ = self.parts[method]
            table = _tables(tracks, self.n_max, self.n_samples)
            seen = _tables(self.seen[m % len(self.seen)], self.n_max, self.n_seen) \
                if self.seen is not None else np.zeros(0)
            vessels = self._vessel_params(tracks)
            i_north, i_east, i_psi, i_u, i_v = self._index
            head = HEAD.pack(n_los=los.size, method=METHODS[method], n_targets=len(tracks),
                             n_samples=self.n_samples, n_max=self.n_max, i_north=i_north,
                             i_east=i_east, i_psi=i_psi, i_u=i_u, i_v=i_v, n_mp=mp.size,
                             memory=self.memory, interval=self.decision_interval,
                             n_seen=self.n_seen, n_vessels=vessels.shape[0],
                             width_p=self._width_p, width_z=self._width_z)
            rows.append(flat(head, los, table, mp, seen, vessels))
        width = max(r.size for r in rows)
        return np.vstack([np.pad(r, (0, width - r.size)) for r in rows])

    def reset(self, batch_shape, model) -> None:
        self._batch_shape = tuple(batch_shape)
        n = math.prod(self._batch_shape)
        rows = max(len(self.members), len(self.methods))
        if rows not in (1, n):
            raise ConfigError(f"targets: {rows} encounters for a batch of {n} ships "
                              "(give one, or one per ship)")
        self.los.reset(batch_shape, model)
        self._index = (state_index(model, "north"), state_index(model, "east"),
                       state_index(model, "psi"), state_index(model, "u"),
                       state_index(model, "v") if "v" in [s.name for s in model.states] else -1)
        self._params = self.params()
        self._z = np.zeros((n, self.state_width))
        self._z[:, 3] = np.nan  # LOS: no sample yet
        self._z[:, 4] = np.nan  # LOS: completion time
        self._z[:, _LOS_STATE + 2] = 1.0  # held speed factor: the nominal
        self._z[:, _LOS_STATE + 3:_LOS_STATE + 6] = (np.inf, np.nan, -1.0)  # no range yet
        self._vessels_reset(n)

    @property
    def state_width(self) -> int:
        """LOS state, the held decision [next decision time, course offset, speed factor], the
        method's memory, then scratch: own (4), nominal (2), command (2), targets (4 n_max); then
        the vessel targets' states (:mod:`shipgnc.guidance.vessel_targets`)."""
        return _LOS_STATE + _HOLD + self.memory + 8 + 4 * self.n_max \
            + self.n_vessels * self._width_z

    # ------------------------------------------------------------------ numpy loop
    def reference(self, t: float, x: np.ndarray) -> np.ndarray:
        x2 = np.asarray(x, dtype=float).reshape(-1, x.shape[-1])
        ref, out, _ = per_ship(colav_reference, "t i z p o o -> r")(
            t, x2, self._z, self._params, 2, len(self.outputs))
        shape = self._batch_shape
        self._outputs = {s.name: out[:, k].reshape(shape) for k, s in enumerate(self.outputs)}
        return ref.reshape(*shape, 2)

    def output_values(self) -> dict[str, np.ndarray]:
        return self._outputs

    def finished(self) -> np.ndarray:
        return self._z[:, 1].reshape(self._batch_shape) > 0

    @property
    def completion_time(self) -> np.ndarray:
        return self._z[:, 4].reshape(self._batch_shape)

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`reference` for the composed loop: :func:`colav_reference` with one parameter row
        per member."""
        def restore(z: np.ndarray) -> None:
            self._z = np.ascontiguousarray(z.reshape(-1, self.state_width))

        return Kernel(colav_reference, self._params, self._z.copy(), restore=restore)

    # ------------------------------------------------------------------ results
    def target_states(self, t: np.ndarray, *, seen: bool = False) -> dict[str, np.ndarray]:
        """Every member's targets at times ``t``: ``target_north``, ``target_east`` [m],
        ``target_sog`` [m/s], ``target_cog`` [rad], each ``(time, member, target)`` (NaN where a
        member has fewer targets, and for vessel targets: they are integrated in the run, their
        states logged, :meth:`add_targets`); ``seen``: as the avoidance saw them, keys
        ``target_seen_*`` (NaN before a target is first heard)."""
        t = np.asarray(t, dtype=float)
        shape = (t.size, len(self.members), self.n_max)
        prefix = "target_seen_" if seen else "target_"
        out = {prefix + k: np.full(shape, np.nan) for k in ("north", "east", "sog", "cog")}
        for m, tracks in enumerate(self.seen if seen else self.members):
            for j, track in enumerate(tracks):
                if not isinstance(track, TargetTrack):
                    continue  # never heard, or a vessel target: its logged states (add_targets)
                n, e, vn, ve = track.at(t)
                out[prefix + "north"][:, m, j], out[prefix + "east"][:, m, j] = n, e
                out[prefix + "sog"][:, m, j] = np.hypot(vn, ve)
                out[prefix + "cog"][:, m, j] = np.mod(np.arctan2(ve, vn), 2 * np.pi)
        return out

    def add_targets(self, result):
        """``result`` with the targets' states on a ``target`` dimension (the member dimension of
        a batch result; none for one ship)."""
        time = result["time"].values
        states = self.target_states(time)
        if self.seen is not None:
            states.update(self.target_states(time, seen=True))
        per_ship = len(self.members) > 1
        if self.n_vessels:  # integrated in the run: each ship's own, from the logged slots
            states, slots = self._vessel_states(states, result)
            result = result.drop_vars(slots)
            per_ship = True
        ship_dims = [d for d in result["north"].dims if d != "time"]
        names = [tr.label for tr in self.members[0]] + [""] * (self.n_max - len(self.members[0]))
        units = {f"target_{s}{k}": u for s in ("", "seen_") for k, u in
                 (("north", "m"), ("east", "m"), ("sog", "m/s"), ("cog", "rad"))}
        for key, value in states.items():
            if ship_dims:
                dims = ("time", *ship_dims, "target")
                value = value.reshape(time.size, *result["north"].shape[1:], self.n_max) \
                    if per_ship else np.broadcast_to(
                        value, (time.size, *result["north"].shape[1:], self.n_max))
            else:
                dims, value = ("time", "target"), value[:, 0, :]
            result[key] = (dims, np.array(value), {"units": units[key]})
        if len(self.members) == 1:
            result = result.assign_coords(target=names)
        return result


@kernel_function
def course_over_ground(psi, u, v):
    """χ = ψ + atan2(v, u) [rad]: the course over ground of a ship with heading ψ and body
    velocities (u, v) (no current); scalars in a kernel, arrays through ``py_func``."""
    return psi + np.arctan2(v, u)


@kernel_function
def last_sample(rows, n_samples, t):
    """Index of the last sample at or before ``t`` of a track table (``n_samples`` rows of
    ``[t, north, east, v_north, v_east]`` flattened, unused rows at t = +inf); −1 before the
    first (the target is not there yet, or not yet heard)."""
    if t < rows[0]:
        return -1
    k = 0
    while k + 1 < n_samples and rows[(k + 1) * 5] <= t:
        k += 1
    return k


@kernel_function
def tail_offsets(p):
    """Where the variable blocks of a parameter row (:data:`HEAD`'s tail) start, from the head's
    counts: (true tables, method parameters, seen tables, vessel blocks, end); the LOS parameters
    start at the head's end, ``HEAD.size``."""
    at_table = HEAD_SIZE + int(p[_N_LOS])
    at_mp = at_table + int(p[_N_MAX]) * int(p[_N_SAMPLES]) * 5
    at_seen = at_mp + int(p[_N_MP])
    at_vessels = at_seen + int(p[_N_MAX]) * int(p[_N_SEEN]) * 5
    return at_table, at_mp, at_seen, at_vessels, at_vessels + int(p[_N_VESSELS]) * int(p[_WIDTH_P])


@kernel_function
def colav_reference(t, x, z, p, ref, out):
    """One sample of :class:`ColavGuidance` for one ship (module docstring): LOS for the nominal
    course, the targets dead-reckoned from their tables, then the avoidance method — called every
    decision interval (the paper's re-planning period; 0: every sample), its choice held as an
    offset from the nominal course and a factor of the nominal speed in between."""
    method, n_targets = int(p[_METHOD]), int(p[_N_TARGETS])
    n_samples, n_max = int(p[_N_SAMPLES]), int(p[_N_MAX])
    i_north, i_east, i_psi = int(p[_I_NORTH]), int(p[_I_EAST]), int(p[_I_PSI])
    i_u, i_v = int(p[_I_U]), int(p[_I_V])
    memory, interval = int(p[_MEMORY]), p[_INTERVAL]
    n_seen, n_vessels = int(p[_N_SEEN]), int(p[_N_VESSELS])
    at_table, at_mp, at_seen, at_vessels, _ = tail_offsets(p)
    finished = los_reference(t, x, z[:_LOS_STATE], p[HEAD_SIZE:at_table], ref, out)
    table = p[at_table:at_mp]
    mp = p[at_mp:at_seen]
    seen = p[at_seen:at_vessels]
    hold = z[_LOS_STATE:_LOS_STATE + _HOLD]
    zm = z[_LOS_STATE + _HOLD:_LOS_STATE + _HOLD + memory]
    s = _LOS_STATE + _HOLD + memory  # scratch
    own, nominal, cmd = z[s:s + 4], z[s + 4:s + 6], z[s + 6:s + 8]
    targets = z[s + 8:s + 8 + 4 * n_max]
    nominal[0], nominal[1] = ref[0], ref[1]
    present = 0  # targets heard by now (before its first sample a target is absent), packed first
    for j in range(n_targets):
        rows = table[j * n_samples * 5:(j + 1) * n_samples * 5]
        k = last_sample(rows, n_samples, t)
        if k >= 0:  # the true target: the range bookkeeping (the scores)
            dt = t - rows[k * 5]
            d = math.hypot(rows[k * 5 + 1] + rows[k * 5 + 3] * dt - x[i_north],
                           rows[k * 5 + 2] + rows[k * 5 + 4] * dt - x[i_east])
            if d < hold[3]:
                hold[3], hold[4], hold[5] = d, t, float(j)
        if n_seen > 0:  # the target as the avoidance sees it
            rows = seen[j * n_seen * 5:(j + 1) * n_seen * 5]
            k = last_sample(rows, n_seen, t)
        if k < 0:
            continue
        dt = t - rows[k * 5]
        m = 4 * present
        targets[m] = rows[k * 5 + 1] + rows[k * 5 + 3] * dt
        targets[m + 1] = rows[k * 5 + 2] + rows[k * 5 + 4] * dt
        targets[m + 2] = rows[k * 5 + 3]
        targets[m + 3] = rows[k * 5 + 4]
        present += 1
    decide = method > 0 and t >= hold[0] - 1e-9 * max(1.0, abs(t))
    if decide or n_vessels > 0:  # the own ship over ground, for the method and the vessel targets
        v = x[i_v] if i_v >= 0 else 0.0
        own[0], own[1] = x[i_north], x[i_east]
        own[2] = course_over_ground(x[i_psi], x[i_u], v)
        own[3] = math.sqrt(x[i_u] * x[i_u] + v * v)
    if n_vessels > 0:
        present = _vessels_sample(t, p, z, s + 8 + 4 * n_max, at_vessels, own, targets, present,
                                  hold, out)
        if present < 0:  # a vessel target's state is not finite: the run stops as diverged
            ref[0], ref[1] = np.nan, np.nan
            out[3], out[4], out[5] = np.nan, np.nan, np.nan
            return finished
    if decide:
        if method == 1:
            sbmpc_choose(t, own, targets, present, nominal, mp, zm, cmd)
        else:
            vo_choose(t, own, targets, present, nominal, mp, zm, cmd)
        hold[0] = t + interval
        hold[1] = wrap(cmd[0] - nominal[0])
        hold[2] = cmd[1] / nominal[1] if nominal[1] > 0.0 else 1.0
    ref[0] = wrap(nominal[0] + hold[1]) if hold[1] != 0.0 else nominal[0]
    ref[1] = hold[2] * nominal[1]
    out[3], out[4], out[5] = nominal[0], ref[0], ref[1]
    out[6], out[7], out[8] = hold[3], hold[4], hold[5]
    return finished


def _tables(tracks, n_max: int, n_samples: int) -> np.ndarray:
    """The tracks as one ``(n_max, n_samples, 5)`` table (unused rows at t = +inf; a None track,
    never heard, and a vessel target, integrated in the run, all unused)."""
    table = np.zeros((n_max, n_samples, 5))
    table[:, :, 0] = np.inf
    for j, track in enumerate(tracks):
        if isinstance(track, TargetTrack):
            table[j, :track.t.size] = track.table()
    return table


def _seen_members(seen, members) -> list[list]:
    """``seen`` in the shape of ``members`` (one list per member), checked against it; a member
    with a vessel target is refused (its AIS reports would have to be drawn inside the kernel from
    its integrated state: not implemented)."""
    seen = [list(seen)] if not seen or isinstance(seen[0], (TargetTrack, type(None))) \
        else [list(m) for m in seen]
    if len(seen) != len(members) or any(len(a) != len(b) for a, b in zip(seen, members, strict=True)):
        raise ConfigError(f"seen: {[len(a) for a in seen]} targets per member for "
                          f"{[len(b) for b in members]} true ones (one seen track, or None, each)")
    for m, tracks in enumerate(seen):
        for track in tracks:
            if track is not None and not isinstance(track, TargetTrack):
                raise ConfigError(f"seen targets of member {m}: {track!r} is not a TargetTrack")
    for m, tracks in enumerate(members):
        for track in tracks:
            if isinstance(track, VesselTarget):
                raise ConfigError(f"seen: member {m} has vessel target {track.label!r}; AIS "
                                  "awareness sees kinematic and logged targets only (seen=None "
                                  "for vessel targets)")
    return seen


@kernel_function
def _vessels_sample(t, p, z, zo, po, own, targets, present, hold, out):
    """The member's vessel targets at ``t`` (:func:`~shipgnc.guidance.vessel_targets.vessel_targets`;
    their parameter blocks from ``p[po]``, states from ``z[zo]``), each slot's north, east, heading
    logged after the nine outputs (NaN in a slot the member does not use); returns the count of
    targets present (−1: a target's state is not finite)."""
    n_vessels, width_p, width_z = int(p[_N_VESSELS]), int(p[_WIDTH_P]), int(p[_WIDTH_Z])
    interval = p[_INTERVAL]
    zv = z[zo:zo + n_vessels * width_z]
    present = vessel_targets(t, own, p[po:po + n_vessels * width_p], width_p, zv, width_z,
                             n_vessels, width_z - S_FIXED - SCRATCH, interval, targets, present,
                             hold)
    for k in range((out.size - _BASE_OUT) // 3):
        for q in range(3):
            out[_BASE_OUT + 3 * k + q] = zv[k * width_z + q] if k < n_vessels else np.nan
    return present


def check_clear(track, own, safety_radius: float, where: str) -> None:
    """A target (a track or a vessel) inside the safety radius of the own ship at t = 0 is a
    ConfigError naming it."""
    n, e = track.start() if isinstance(track, VesselTarget) else track.at(0.0)[:2]
    distance = math.hypot(float(n) - own[0], float(e) - own[1])
    if distance < safety_radius:
        raise ConfigError(f"{where}: {distance:.1f} m from the own ship at t = 0, inside the "
                          f"safety radius {safety_radius:g} m; place it farther away")
