"""The scenario schema: what a scenario YAML file may contain, validated by pydantic.

Each section is a model of :mod:`shipgnc.scenarios.sections`; which sections a scenario may hold,
and which go together, comes from the component registry (:mod:`shipgnc.scenarios.components`):
the unions below and the checks of :class:`Scenario` are derived from its tables. Angles in
scenario files are in degrees and say so in their names (``psi_deg``, ``alpha_deg``); everything
else is SI. Unknown fields are rejected, and every error names the field, the value and what is
allowed (:func:`format_validation_error`).
"""

from __future__ import annotations

import math
import re
from typing import Annotated, Any, ClassVar, Literal, Union

from pydantic import (
    Discriminator,
    Field,
    PrivateAttr,
    Tag,
    ValidationError,
    field_validator,
    model_validator,
)

from shipgnc.config_types import Finite, Strict, format_validation_error
from shipgnc.errors import ConfigError
from shipgnc.scenarios import components as C
from shipgnc.scenarios.sections import (  # noqa: F401  (re-exported: the sections by their old home)
    CATAMARAN_BUILDERS,
    ActuatorConfig,
    CatamaranCaseConfig,
    CurrentConfig,
    MarinerDisturbanceConfig,
    MonteCarloConfig,
    QualityConfig,
    RouteConfig,
    SailConfig,
    SimulationConfig,
    VesselConfig,
)
from shipgnc.vessels.config import CATALOGUE_VESSELS, CatalogueVesselConfig  # noqa: F401  (re-exported)

C.load_plugins()  # third-party components (entry-point group shipgnc.components), once

#: vessel models a scenario's ``current`` section applies to, and those that take navigation
CURRENT_VESSELS = C.having("current")
NAVIGATION_VESSELS = C.having("navigation")


def _vessel_tag(value) -> str:
    model = (value.get("model", "vectored-thrust-boat") if isinstance(value, dict)
             else getattr(value, "model", "vectored-thrust-boat"))
    kind = C.VESSEL_KINDS.get(model) if isinstance(model, str) else None
    return kind.config.__name__ if kind is not None else "unknown vessel model"


def _union_by_type(table: dict):
    """A ``type``-discriminated union of the configuration classes of a registry table."""
    return Annotated[Union[C.config_classes(table)], Field(discriminator="type")]  # noqa: UP007


Vessel = Annotated[
    Union[tuple(Annotated[cls, Tag(cls.__name__)]  # noqa: UP007
                for cls in C.config_classes(C.VESSEL_KINDS))],
    Discriminator(_vessel_tag, custom_error_type="vessel_model",
                  custom_error_message="unknown vessel model; allowed: "
                                       + ", ".join(C.VESSEL_KINDS)),
]
ControllerConfig = _union_by_type(C.CONTROLLERS)
GuidanceConfig = _union_by_type(C.GUIDANCE)
DisturbanceConfig = _union_by_type(C.DISTURBANCES)
SensorConfig = _union_by_type(C.SENSORS)
EstimatorConfig = _union_by_type(C.ESTIMATORS)
MetricSet = Literal[tuple(C.METRICS)]
#: the sections a run of ``runs`` may override (the scenario's identity, its metric set, a
#: route and the runs themselves are the scenario's)
RUN_SECTIONS = ("vessel", "actuator", "simulation", "controller", "guidance", "disturbance",
                "current", "sensors", "estimator", "quality", "montecarlo")
#: what a run's name may hold (it keys the run's metrics and its ``controller`` coordinate)
RUN_NAME = re.compile(r"[A-Za-z0-9_.@/\-]+")


#: the fields that say which kind a section is: a section whose kind changes is replaced whole
KIND_FIELDS = ("type", "model")


def merged(base: dict, override: dict) -> dict:
    """``base`` with ``override`` laid over it: mappings merged key by key, except a section whose
    kind (``type``, or a vessel's ``model``) changes, which is replaced whole; any other value
    (``null`` too) replaces."""
    out = dict(base)
    for key, value in override.items():
        old = out.get(key)
        if (isinstance(old, dict) and isinstance(value, dict)
                and all(value.get(k, old.get(k)) == old.get(k) for k in KIND_FIELDS)):
            out[key] = merged(old, value)
        else:
            out[key] = value
    return out


class Scenario(Strict):
    """A complete, runnable scenario: one ``controller``, or ``controllers`` to compare by name."""

    field_units: ClassVar[dict[str, str]] = {"document_figures": "each metric's (its key's suffix)"}

    name: Annotated[str, Field(min_length=1, pattern=r"^[A-Za-z0-9_.\-]+$")]
    description: str = ""
    document: str = ""
    metrics: MetricSet = "none"
    vessel: Vessel = Field(default_factory=VesselConfig)
    actuator: ActuatorConfig = Field(default_factory=ActuatorConfig)
    simulation: SimulationConfig | None = None
    controller: ControllerConfig | None = None
    controllers: dict[Annotated[str, Field(pattern=r"^[A-Za-z0-9_]+$")], ControllerConfig] | None = None
    guidance: GuidanceConfig | None = None
    disturbance: DisturbanceConfig | None = None
    quality: QualityConfig = Field(default_factory=QualityConfig)
    montecarlo: MonteCarloConfig | None = None
    #: runs by name (letters, digits and ``_ . @ / -``), each a partial override of the sections
    #: vessel, actuator, simulation, controller, guidance, disturbance, current, sensors,
    #: estimator, quality, montecarlo, e.g. the reference, the plant or the duration: one result
    #: with a ``controller`` dimension keyed by run, like ``controllers`` (``case: {builder,
    #: options}``, document 004's older spelling, is read as runs)
    runs: dict[str, dict[str, Any]] | None = None
    #: document 002's routing problem, and optionally a ship sailing the route
    route: RouteConfig | None = None
    sail: SailConfig | None = None
    #: the document's own figures, by controller (shown beside ours in comparison tables)
    document_figures: dict[str, dict[str, Finite]] = Field(default_factory=dict)
    #: an earth-fixed current on the vessel (:data:`CURRENT_VESSELS`), with any force disturbance
    current: CurrentConfig | None = None
    #: navigation, the sensors between the true state and the controller, and an
    #: estimator between the sensors and the controller (the controller acts on its estimate)
    sensors: list[SensorConfig] = Field(default_factory=list)
    estimator: EstimatorConfig | None = None
    #: each run of ``runs`` as a scenario of its own (set when validated)
    _runs: dict | None = PrivateAttr(default=None)
    #: written with the older ``case`` section (a ``--set case.options.…`` is then read)
    _spelled_case: bool = PrivateAttr(default=False)

    @field_validator("current")
    @classmethod
    def _current_fits(cls, current, info):
        if current is None:
            return current
        vessel = getattr(info.data.get("vessel"), "model", None)
        if info.data.get("route") is not None or vessel not in CURRENT_VESSELS:
            what = "a route" if info.data.get("route") is not None else f"vessel model {vessel!r}"
            raise ValueError(f"a current section applies to vessel models "
                             f"{', '.join(CURRENT_VESSELS)}, not to {what} (a route takes its "
                             f"field from route.field)")
        return current

    @property
    def kind(self) -> C.VesselKind:
        """The registry entry of the scenario's vessel model."""
        return C.of_vessel(self.vessel.model)

    @property
    def shape(self) -> str:
        """``route`` (a route section) or ``controlled`` (vessel, controller(s), guidance,
        disturbance; with ``runs``, one such set-up per run)."""
        return "route" if self.route is not None else "controlled"

    @property
    def variants(self) -> dict[str, object]:
        """Controllers by name (one unnamed controller is called ``controller``); with ``runs``,
        each run's controller by run name."""
        if self._runs is not None:
            return {name: run.controller for name, run in self._runs.items()}
        return dict(self.controllers) if self.controllers else {"controller": self.controller}

    def run_scenarios(self) -> dict[str, Scenario]:
        """Each run of ``runs`` as the scenario it makes: the common sections with the run's laid
        over them (:func:`merged`), validated as one."""
        if self._runs is None:
            raise ConfigError(f"scenario {self.name!r} has no runs section")
        return dict(self._runs)

    def where(self, name: str) -> str:
        """The field that holds controller ``name``: ``controller``, ``controllers.NAME`` or
        ``runs.NAME.controller``."""
        if self.runs is not None:
            return f"runs.{name}.controller"
        return "controller" if self.controller is not None else f"controllers.{name}"

    def used_sections(self) -> tuple[str, ...]:
        """The top-level sections this kind of scenario reads; a ``--set`` into any other would
        be silently ignored, so :func:`~shipgnc.scenarios.registry.load_scenario` refuses it.
        Every scenario reads its identity (``name``, ``description``, ``document``, ``metrics``,
        ``document_figures``); a route reads ``route`` and ``sail``; the others their vessel,
        simulation, controller(s), guidance and disturbance, plus the sections their registry
        entry names (the boat's ``actuator``, the Mariner's ``montecarlo``), ``current`` and
        ``sensors``/``estimator`` where the vessel takes them, the metric set's (document
        003's ``quality``), and ``runs`` (``case``, its older spelling, where given)."""
        common = ("name", "description", "document", "metrics", "document_figures")
        if self.route is not None:
            return (*common, "route", "sail")
        kind = self.kind
        used = [*common, "vessel", "simulation", "controller",
                *(() if self.runs is not None else ("controllers",)), "guidance", "runs"]
        if kind.disturbances:
            used.append("disturbance")
        if self._spelled_case:
            used.append("case")
        used += kind.sections
        if kind.current:
            used.append("current")
        if kind.navigation:
            used += ["sensors", "estimator"]
        used += C.METRICS[self.metrics].sections
        return tuple(used)

    def ignored_fields(self) -> tuple[str, ...]:
        """Dotted fields of the used sections that this scenario's vessel does not read (its
        registry entry's ``ignores``: the catamaran's runs set their own initial state)."""
        return () if self.route is not None else self.kind.ignores

    @model_validator(mode="wrap")
    @classmethod
    def _equilibrium_surge(cls, data, handler) -> Scenario:
        """``simulation.initial_state.u: null`` → the vessel's surge equilibrium (InitialState),
        from its section's ``surge_equilibrium()``."""
        scenario = handler(data)
        sim = scenario.simulation
        if (sim is None or sim.initial_state.u is not None or scenario.route is not None
                or "simulation.initial_state" in scenario.kind.ignores):  # refused in _consistent
            return scenario
        vessel = scenario.vessel
        if not hasattr(vessel, "surge_equilibrium"):
            have = [name for name, kind in C.VESSEL_KINDS.items()
                    if hasattr(kind.config, "surge_equilibrium")]
            raise ValueError(f"simulation.initial_state.u = null (the surge equilibrium) is "
                             f"defined for vessel models {', '.join(have)}, not "
                             f"{vessel.model!r}; give u in m/s")
        init = sim.initial_state.model_copy(update={"u": float(vessel.surge_equilibrium())})
        return scenario.model_copy(
            update={"simulation": sim.model_copy(update={"initial_state": init})})

    @model_validator(mode="wrap")
    @classmethod
    def _older_case(cls, data, handler) -> Scenario:
        """A ``case`` section (document 004's case builders) read as the ``runs`` it makes
        (:func:`~shipgnc.scenarios.catamaran_case.case_as_runs`)."""
        if isinstance(data, dict) and "case" in data and data["case"] is None:  # --set case=null
            data = {key: value for key, value in data.items() if key != "case"}
        if not (isinstance(data, dict) and "case" in data):
            return handler(data)
        vessel = data.get("vessel")
        if not isinstance(vessel, dict) or vessel.get("model") != "catamaran":
            raise ValueError("case: document 004's case builders need vessel model 'catamaran'")
        from shipgnc.scenarios.catamaran_case import case_as_runs

        scenario = handler(case_as_runs(data))
        scenario._spelled_case = True
        return scenario

    @model_validator(mode="after")
    def _consistent(self) -> Scenario:
        self._consistent_navigation()
        if self.route is not None or self.sail is not None:
            return self._consistent_route()
        if self.simulation is None:
            raise ValueError("simulation: required field is missing (dt, t_end, ...)")
        if self.runs is not None:
            return self._consistent_runs()
        kind = self.kind
        self._ignored_unset(kind)
        self._sections_fit(kind)
        self._controllers_fit(kind)
        self._guidance_fits(kind)
        dist = self.disturbance.type if self.disturbance is not None else None
        if dist is not None and dist not in kind.disturbances:
            allowed = (f"allowed: {', '.join(kind.disturbances)}" if kind.disturbances
                       else "it takes none; an earth-fixed current is the current section")
            raise ValueError(f"disturbance type {dist!r} does not fit vessel model "
                             f"{self.vessel.model!r} ({allowed})")
        if kind.check is not None:
            C.resolve(kind.check)(self)
        return self

    def _consistent_navigation(self) -> None:
        if self.sensors or self.estimator is not None:
            if self.route is not None or self.vessel.model not in NAVIGATION_VESSELS:
                what = "a route" if self.route is not None else f"vessel {self.vessel.model!r}"
                raise ValueError(f"sensors / estimator: not available for {what} (allowed for "
                                 f"vessel models {', '.join(NAVIGATION_VESSELS)})")
            if self.montecarlo is not None:
                raise ValueError("sensors / estimator with montecarlo: the Monte Carlo summary is "
                                 "scored without navigation figures; sweep the scenario instead "
                                 "(shipgnc sweep NAME --mc N scores every member's navigation)")
            steps = self.simulation.t_end / self.simulation.dt if self.simulation else math.inf
            for i, sensor in enumerate(self.sensors):  # a latency is held in memory, sample by sample
                if sensor.latency > steps:
                    raise ValueError(f"sensors.{i}.latency = {sensor.latency}: longer than the run "
                                     f"({steps:.0f} steps of simulation.dt = {self.simulation.dt:g} s "
                                     f"in t_end = {self.simulation.t_end:g} s); the latency counts "
                                     "control samples")
            if self.estimator is not None and not self.sensors:
                raise ValueError("estimator: needs sensors to correct it (e.g. sensors: "
                                 "[{type: gnss}, {type: compass}])")
        for name, ctrl in (self.variants.items() if self.route is None else ()):
            sees = getattr(ctrl, "sees", None)
            if sees == "estimate" and self.estimator is None:
                raise ValueError(f"{self.where(name)}.sees = 'estimate': the scenario has no estimator")
            if sees == "measurement" and not self.sensors:
                raise ValueError(f"{self.where(name)}.sees = 'measurement': the scenario has no sensors")

    def _ignored_unset(self, kind: C.VesselKind) -> None:
        """A field the vessel does not read (its entry's ``ignores``) is refused when given, in
        the file or by a ``--set`` of its whole section, rather than silently ignored."""
        for field in kind.ignores:
            *parents, leaf = field.split(".")
            node = self
            for part in parents:
                node = getattr(node, part, None)
            if node is not None and leaf in node.model_fields_set:
                raise ValueError(f"{field}: vessel model {self.vessel.model!r} does not read it (its "
                                 f"runs set it themselves); leave it out")

    def _sections_fit(self, kind: C.VesselKind) -> None:
        """A section that only some vessels read (their entries' ``sections``) is refused on
        another, with the vessels that read it."""
        optional = dict.fromkeys(s for k in C.VESSEL_KINDS.values() for s in k.sections)
        for section in optional:
            default = type(self).model_fields[section].get_default(call_default_factory=True)
            if getattr(self, section) != default and section not in kind.sections:
                readers = C.having(section)
                raise ValueError(f"{section}: applies to vessel model {' and '.join(readers)} in "
                                 f"this release, not {self.vessel.model!r}"
                                 + ("; the steering machine is set in vessel (rudder_max_deg, "
                                    "rudder_rate_deg_s)" if section == "actuator"
                                    and hasattr(self.vessel, "rudder_max_deg") else ""))

    def _controllers_fit(self, kind: C.VesselKind) -> None:
        if (self.controller is None) == (self.controllers is None):
            raise ValueError("give either 'controller' or 'controllers' (a mapping name: controller)")
        if self.controllers is not None and not self.controllers:
            raise ValueError("'controllers' is empty")
        if self.controllers is not None and not kind.comparisons:
            comparing = [n for n, k in C.VESSEL_KINDS.items() if k.comparisons and C.controller_types(k)]
            raise ValueError(f"controllers: comparisons run on vessel models "
                             f"{', '.join(comparing)} in this release; for the "
                             f"{self.vessel.model} give one 'controller'")
        fitting = C.controller_types(kind)
        for name, ctrl in self.variants.items():
            where = self.where(name)
            if ctrl.type not in fitting:
                raise ValueError(f"{where}: type {ctrl.type!r} does not fit vessel model "
                                 f"{self.vessel.model!r} (allowed: {', '.join(fitting)})")
            needs = C.CONTROLLERS[ctrl.type].guidance
            if needs and (self.guidance is None or self.guidance.type not in needs):
                raise ValueError(f"{where}: type {ctrl.type!r} needs a guidance section of type "
                                 f"{' or '.join(needs)}")
            from shipgnc.sim.simulator import samples_per_period  # (the rule's one check)

            samples_per_period(getattr(ctrl, "Ts", None) or self.simulation.dt,  # None: follows dt
                               self.simulation.dt, field=f"{where}.Ts", dt_field="simulation.dt")

    def _guidance_fits(self, kind: C.VesselKind) -> None:
        if self.guidance is not None:
            serves = C.GUIDANCE[self.guidance.type].vessels
            if serves is not None and kind.model not in serves:
                raise ValueError(f"guidance type {self.guidance.type!r} needs vessel model "
                                 f"{' or '.join(map(repr, serves))}")
        metric = C.METRICS[self.metrics]
        if metric.guidance and (self.guidance is None or self.guidance.type != metric.guidance):
            raise ValueError(f"metrics = {self.metrics!r} needs guidance type {metric.guidance!r}")
        if metric.controllers and any(c.type not in metric.controllers for c in self.variants.values()):
            raise ValueError(f"metrics = {self.metrics!r} needs controller type "
                             f"{' or '.join(map(repr, metric.controllers))}")
        if metric.shape not in (None, "controlled"):
            raise ValueError(f"metrics = {self.metrics!r}: scores a route scenario")
        if metric.vessels is not None and self.vessel.model not in metric.vessels:
            raise ValueError(f"metrics = {self.metrics!r}: scores vessel model "
                             f"{' or '.join(map(repr, metric.vessels))}, not {self.vessel.model!r}")

    def _consistent_route(self) -> Scenario:
        if self.route is None:
            raise ValueError("sail: needs a route section (the route to sail)")
        for name in ("controller", "controllers", "guidance", "disturbance", "montecarlo", "runs"):
            if getattr(self, name) is not None:
                raise ValueError(f"{name}: a route scenario takes its route from the route section "
                                 "(and its ship from sail)")
        if self.metrics not in ("route", "none"):
            raise ValueError(f"metrics = {self.metrics!r}: a route scenario reports 'route'")
        return self

    def _consistent_runs(self) -> Scenario:
        """Each run: the common sections with the run's laid over them, validated as a scenario
        of its own (every check above, per run)."""
        if not self.runs:
            raise ValueError("runs: empty; give at least one run (name: the sections it changes)")
        if self.controllers is not None:
            raise ValueError("controllers: with runs, each run gives its controller "
                             "(runs.NAME.controller), or a common controller")
        base = self.model_dump(mode="json", exclude_unset=True, exclude={"runs"})
        runs = {}
        for name, override in self.runs.items():
            if not RUN_NAME.fullmatch(name):
                raise ValueError(f"runs: {name!r} is not a run name: letters, digits and _ . @ / - "
                                 "only (it keys the run's metrics)")
            bad = [key for key in override if key not in RUN_SECTIONS]
            if bad:
                raise ValueError(f"runs.{name}.{bad[0]}: belongs to the scenario, not to a run; a "
                                 f"run overrides the sections {', '.join(RUN_SECTIONS)}")
            try:
                runs[name] = type(self).model_validate(merged(base, override))
            except ValidationError as exc:
                parts = format_validation_error(exc, "run").removeprefix("scenario run: ").split("; ")
                raise ValueError("; ".join(f"runs.{name}.{part.removeprefix('scenario: ')}"
                                           for part in parts)) from None
        self._runs = runs
        return self


def validate(data: object, source: str) -> Scenario:
    """Validate raw scenario data, raising :class:`ConfigError` with a one-line message."""
    if not isinstance(data, dict):
        raise ConfigError(f"scenario {source}: expected a mapping of fields at the top level, "
                          f"got {type(data).__name__}")
    try:
        return Scenario.model_validate(data)
    except ValidationError as exc:
        raise ConfigError(format_validation_error(exc, source)) from None

