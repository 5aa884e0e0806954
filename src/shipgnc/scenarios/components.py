"""The component registry: every vessel, controller, guidance, disturbance and metric set a scenario
may name, with its configuration section, its builder and what it fits.

The scenario schema derives from these tables its unions (which ``vessel.model``, ``controller.type``,
``guidance.type``, ``disturbance.type`` are allowed), its compatibility checks (a controller that
does not fit the vessel, the guidance a controller needs, the sections a vessel reads) and the
runner its dispatch (which function builds the vessel, the controller, the guidance). Adding a
component is its module, its configuration section (:mod:`shipgnc.scenarios.sections`) and one
entry here; neither the schema's checks nor the runner's dispatch names it
(``docs/extending.md``; the RL environments and the live dashboard keep their own short lists).
Sensors and estimators declare their records in their own modules
(:mod:`shipgnc.navigation.records`), collected here from :data:`NAVIGATION_MODULES`; third-party
packages add records of every kind through the entry-point group :data:`ENTRY_POINT_GROUP`
(:func:`load_plugins`).

Builders are named ``"module:function"`` and imported when first used, so that reading a scenario
file does not import every model and controller.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import Literal

from shipgnc.errors import ConfigError
from shipgnc.navigation.records import EstimatorKind, SensorKind
from shipgnc.scenarios import sections as S
from shipgnc.vessels.config import CATALOGUE_VESSELS, CatalogueVesselConfig


def resolve(target):
    """The function named ``"module:function"`` (a function itself: that function)."""
    if callable(target):
        return target
    module, _, name = target.partition(":")
    return getattr(importlib.import_module(module), name)


@dataclass(frozen=True)
class VesselKind:
    """A ``vessel.model``.

    ``build(scenario) -> (model, actuator, u0)``; ``controllers``, ``disturbances``: the types of
    those sections that fit it; ``navigation``: takes ``sensors`` and ``estimator``; ``current``:
    takes a ``current`` section; ``sections``: other top-level sections it reads (e.g. the boat's
    ``actuator``); ``ignores``: dotted fields of those sections it does not read (a ``--set`` into
    one is refused, ``shipgnc show`` leaves it out); ``comparisons``: takes a ``controllers``
    mapping; ``capabilities``: what the vessel offers a controller (:data:`RUDDER_STATE`: the
    steering machine is in the model), so that a controller kind with a builder for a capability
    (:attr:`ControllerKind.by_capability`) fits it without being listed in ``controllers``.
    Optional hooks, each ``"module:function"``: ``initial_state(scenario, seed) -> x0``,
    ``check(scenario)`` (rules of its own, raising ValueError)."""

    model: str
    config: type
    build: str
    controllers: tuple[str, ...] = ()
    disturbances: tuple[str, ...] = ()
    navigation: bool = False
    current: bool = False
    sections: tuple[str, ...] = ()
    ignores: tuple[str, ...] = ()
    comparisons: bool = True
    capabilities: tuple[str, ...] = ()
    initial_state: str | None = None
    check: str | None = None


#: a vessel capability: the steering machine is part of the model (states ``psi`` at 2, ``r`` at 5,
#: ``delta`` at 6, first input ``delta_c``, a steady straight run ``straight_state()``: the vessel
#: catalogue's layout, :mod:`shipgnc.vessels.base`)
RUDDER_STATE = "rudder-state"


@dataclass(frozen=True)
class ControllerKind:
    """A ``controller.type``: its section, the guidance types it needs (one of them; empty: none)
    and its builder ``(cfg, model, scenario)``. ``continuous``: ``Ts`` null is a continuous law,
    which holds the guidance object and reads it at every RK stage (not sampled at ``dt``); its
    builder is ``(cfg, model, scenario, guidance)``.

    ``by_capability``: ``(capability, "module:function")`` pairs, the builder for a vessel that
    declares that capability (:attr:`VesselKind.capabilities`; the first that matches), in place of
    ``build``; every vessel that declares one of them fits this type."""

    type: str
    config: type
    guidance: tuple[str, ...] = ()
    build: str | None = None
    continuous: bool = False
    by_capability: tuple[tuple[str, str], ...] = ()


@dataclass(frozen=True)
class GuidanceKind:
    """A ``guidance.type``: its section, its builder ``(cfg) -> guidance`` (``reads_scenario``:
    ``(cfg, scenario)``, a reference computed from the vessel) and the vessel models it serves
    (None: any)."""

    type: str
    config: type
    build: str | None = None
    vessels: tuple[str, ...] | None = None
    reads_scenario: bool = False


@dataclass(frozen=True)
class DisturbanceKind:
    """A ``disturbance.type``: its section and its builder ``(cfg, scenario)``."""

    type: str
    config: type
    build: str | None = None


@dataclass(frozen=True)
class MetricKind:
    """A ``metrics`` set: the guidance type it scores against (None: any), the controller types it
    needs (None: any), the sections it reads, the scenario shape it scores (``controlled``,
    ``route``; None: any) and the vessel models it scores (None: any)."""

    name: str
    shape: Literal["controlled", "route"] | None = None
    guidance: str | None = None
    controllers: tuple[str, ...] | None = None
    sections: tuple[str, ...] = ()
    vessels: tuple[str, ...] | None = None
    #: its scorer ``(scenario, result, setup) -> dict`` (``"module:function"`` or the function);
    #: None: a built-in set scored by :func:`shipgnc.scenarios.runner.compute_metrics`
    score: object = None


#: document 004's yaw-rate references, which its continuous laws read at every RK stage
_YAW_RATE_REFERENCES = ("yaw-rate", "yaw-rate-sine", "heading-capture", "steady-turn")

CONTROLLERS: dict[str, ControllerKind] = {k.type: k for k in (
    ControllerKind("open-loop", S.OpenLoopConfig, build="shipgnc.scenarios.runner:open_loop_controller"),
    ControllerKind("heading-speed", S.HeadingSpeedConfig, guidance=("schedule", "los"),
                   build="shipgnc.scenarios.runner:heading_speed_controller"),
    ControllerKind("course", S.CourseControllerConfig, guidance=("course-schedule", "colav"),
                   build="shipgnc.scenarios.runner:course_controller",
                   by_capability=((RUDDER_STATE, "shipgnc.vessels.autopilot:course_autopilot"),)),
    ControllerKind("lqr", S.PathLQRConfig, guidance=("path",),
                   build="shipgnc.scenarios.mariner:lqr_controller"),
    ControllerKind("fl", S.OutputFLConfig, guidance=("path",),
                   build="shipgnc.scenarios.mariner:fl_controller"),
    ControllerKind("los-fl", S.LOSFLConfig, guidance=("path",),
                   build="shipgnc.scenarios.mariner:los_fl_controller"),
    ControllerKind("yaw-rate-fsm", S.YawRateFSMConfig, guidance=_YAW_RATE_REFERENCES,
                   build="shipgnc.scenarios.catamaran:fsm_controller", continuous=True),
    ControllerKind("yaw-rate-place", S.YawRateBaselineConfig, guidance=_YAW_RATE_REFERENCES,
                   build="shipgnc.scenarios.catamaran:baseline_controller", continuous=True),
    ControllerKind("yaw-rate-pi-design", S.YawRateBaselineConfig, guidance=_YAW_RATE_REFERENCES,
                   build="shipgnc.scenarios.catamaran:baseline_controller", continuous=True),
    ControllerKind("yaw-rate-pi", S.YawRateBaselineConfig, guidance=_YAW_RATE_REFERENCES,
                   build="shipgnc.scenarios.catamaran:baseline_controller", continuous=True),
    ControllerKind("heading-lqr", S.HeadingLQRConfig, build="shipgnc.scenarios.catamaran:heading_lqr",
                   continuous=True),
    ControllerKind("fixed-angle", S.FixedAngleConfig, build="shipgnc.scenarios.catamaran:fixed_angle"),
)}

GUIDANCE: dict[str, GuidanceKind] = {k.type: k for k in (
    GuidanceKind("schedule", S.ScheduleGuidanceConfig, build="shipgnc.scenarios.runner:reference_schedule"),
    GuidanceKind("los", S.LOSConfig, build="shipgnc.scenarios.runner:los_guidance"),
    GuidanceKind("course-schedule", S.CourseScheduleConfig, build="shipgnc.scenarios.runner:course_schedule"),
    GuidanceKind("path", S.PathConfig, build="shipgnc.scenarios.mariner:path_guidance",
                 vessels=("mariner",)),
    # document 004's references: a continuous law holds the object and evaluates it at every
    # RK stage (ControllerKind.continuous)
    GuidanceKind("yaw-rate", S.YawRateGuidanceConfig, vessels=("catamaran",),
                 build="shipgnc.scenarios.catamaran:yaw_rate_reference"),
    GuidanceKind("yaw-rate-sine", S.YawRateSineConfig, vessels=("catamaran",),
                 build="shipgnc.scenarios.catamaran:sine_reference"),
    GuidanceKind("heading-capture", S.HeadingCaptureConfig, vessels=("catamaran",),
                 build="shipgnc.scenarios.catamaran:heading_capture"),
    GuidanceKind("steady-turn", S.SteadyTurnGuidanceConfig, vessels=("catamaran",),
                 build="shipgnc.scenarios.catamaran:steady_turn_reference", reads_scenario=True),
    GuidanceKind("colav", S.ColavConfig, build="shipgnc.study.encounters:colav_guidance",
                 reads_scenario=True),
)}

DISTURBANCES: dict[str, DisturbanceKind] = {k.type: k for k in (
    DisturbanceKind("constant", S.ConstantForceConfig, build="shipgnc.scenarios.runner:constant_force"),
    DisturbanceKind("gaussian", S.GaussianForceConfig, build="shipgnc.scenarios.runner:gaussian_force"),
    DisturbanceKind("waves", S.WavesConfig, build="shipgnc.scenarios.runner:wave_loads"),
    DisturbanceKind("mariner", S.MarinerDisturbanceConfig,
                    build="shipgnc.scenarios.mariner:disturbance_section"),
)}

METRICS: dict[str, MetricKind] = {k.name: k for k in (
    MetricKind("stern-kick", "controlled", controllers=("open-loop",)),
    MetricKind("heading-steps", "controlled", guidance="schedule"),
    MetricKind("waypoints", "controlled", guidance="los"),
    MetricKind("course-quality", "controlled", guidance="course-schedule", sections=("quality",)),
    MetricKind("path-tracking", "controlled", guidance="path"),
    MetricKind("catamaran", vessels=("catamaran",)),
    MetricKind("catamaran-comparison", vessels=("catamaran",)),
    MetricKind("route", "route"),
    MetricKind("colav", "controlled", guidance="colav",
               score="shipgnc.study.encounter_scores:score"),
    MetricKind("none"),
)}

VESSEL_KINDS: dict[str, VesselKind] = {k.model: k for k in (
    VesselKind("vectored-thrust-boat", S.VesselConfig, "shipgnc.scenarios.runner:boat_parts",
               controllers=("open-loop", "heading-speed"), disturbances=("constant", "gaussian"),
               navigation=True, current=True, sections=("actuator",), comparisons=False),
    VesselKind("cybership2", S.CyberShipVesselConfig, "shipgnc.scenarios.runner:cybership_parts",
               controllers=("course",), disturbances=("constant", "gaussian", "waves"),
               navigation=True, current=True),
    VesselKind("mariner", S.MarinerVesselConfig, "shipgnc.scenarios.mariner:vessel",
               controllers=("lqr", "fl", "los-fl"), disturbances=("mariner",),
               navigation=True, current=True, sections=("montecarlo",),
               initial_state="shipgnc.scenarios.mariner:initial_states",
               check="shipgnc.scenarios.mariner:check"),
    VesselKind("catamaran", S.CatamaranVesselConfig, "shipgnc.scenarios.catamaran:vessel_parts",
               controllers=("yaw-rate-fsm", "yaw-rate-place", "yaw-rate-pi-design", "yaw-rate-pi",
                            "heading-lqr", "fixed-angle"), current=True,
               # its runs set their own initial state (document 004: u = 4 m/s, the rest 0)
               # and integrate with RK4 at their step
               ignores=("simulation.initial_state", "simulation.integrator", "simulation.method",
                        "simulation.rtol", "simulation.atol"),
               initial_state="shipgnc.scenarios.catamaran:initial_state",
               check="shipgnc.scenarios.catamaran:check"),
    *(VesselKind(name, CatalogueVesselConfig, "shipgnc.vessels.scenario:vessel",
                 capabilities=(RUDDER_STATE,), initial_state="shipgnc.vessels.scenario:initial_state")
      for name in CATALOGUE_VESSELS),
)}


def of_vessel(model: str) -> VesselKind:
    """The registry entry of vessel model ``model`` (ConfigError naming the allowed ones)."""
    try:
        return VESSEL_KINDS[model]
    except KeyError:
        raise ConfigError(f"vessel.model = {model!r}: unknown vessel model; allowed: "
                          f"{', '.join(VESSEL_KINDS)}") from None


def controller_types(kind: VesselKind) -> tuple[str, ...]:
    """The ``controller.type`` values that fit vessel ``kind``: those its entry lists, then those
    with a builder for a capability it declares (in registry order)."""
    served = (t for t, c in CONTROLLERS.items()
              if any(cap in kind.capabilities for cap, _ in c.by_capability))
    return tuple(dict.fromkeys((*kind.controllers, *served)))


def controller_builder(type_: str, kind: VesselKind) -> str | None:
    """The builder ``"module:function"`` of controller type ``type_`` on vessel ``kind``: the one
    for the first capability the vessel declares (:attr:`ControllerKind.by_capability`), else the
    type's own ``build``."""
    entry = CONTROLLERS[type_]
    for capability, target in entry.by_capability:
        if capability in kind.capabilities:
            return target
    return entry.build


def having(flag: str) -> tuple[str, ...]:
    """The vessel models whose entry sets ``flag`` (``navigation``, ``current``) or reads the
    section named ``flag``."""
    return tuple(name for name, kind in VESSEL_KINDS.items()
                 if getattr(kind, flag, False) is True or flag in kind.sections)


def config_classes(table: dict) -> tuple[type, ...]:
    """The distinct configuration classes of a table's entries, in entry order."""
    return tuple(dict.fromkeys(kind.config for kind in table.values()))


# ---- records declared beside their components, and third-party packages' ------------------------
#: the built-in modules that declare sensor and estimator records (:mod:`shipgnc.navigation.records`)
NAVIGATION_MODULES = ("shipgnc.navigation.sensors", "shipgnc.navigation.ekf",
                      "shipgnc.navigation.passive_observer")
#: the entry-point group of third-party components: an entry point names a module (its records
#: are the record instances among its module-level names) or a record list (``module:NAME``)
ENTRY_POINT_GROUP = "shipgnc.components"

SENSORS: dict[str, SensorKind] = {}
ESTIMATORS: dict[str, EstimatorKind] = {}

#: record class → (its table, the field that names it, what a scenario file calls it)
RECORD_TABLES: dict[type, tuple[dict, str, str]] = {
    VesselKind: (VESSEL_KINDS, "model", "vessel.model"),
    ControllerKind: (CONTROLLERS, "type", "controller.type"),
    GuidanceKind: (GUIDANCE, "type", "guidance.type"),
    DisturbanceKind: (DISTURBANCES, "type", "disturbance.type"),
    MetricKind: (METRICS, "name", "metrics"),
    SensorKind: (SENSORS, "type", "sensors[].type"),
    EstimatorKind: (ESTIMATORS, "type", "estimator.type"),
}


def records_in(obj) -> list:
    """The registry records ``obj`` holds: a record, a list or tuple of records, or a module (its
    module-level record instances, in definition order)."""
    kinds = tuple(RECORD_TABLES)
    if isinstance(obj, kinds):
        return [obj]
    if isinstance(obj, (list, tuple)):
        return [r for r in obj if isinstance(r, kinds)]
    namespace = getattr(obj, "__dict__", None) if type(obj).__name__ == "module" else None
    return [r for r in (namespace or {}).values() if isinstance(r, kinds)]


def register(record, origin: str) -> None:
    """Add ``record`` to its table; a name already taken is a ConfigError naming ``origin``."""
    table, field, what = RECORD_TABLES[type(record)]
    name = getattr(record, field)
    if not isinstance(name, str) or not name:
        raise ConfigError(f"{origin}: {type(record).__name__}.{field} = {name!r}: must be a "
                          f"non-empty name")
    if name in table:
        raise ConfigError(f"{origin}: {what} {name!r} is already registered; give the component "
                          f"another name")
    table[name] = record


for _module in NAVIGATION_MODULES:
    for _record in records_in(importlib.import_module(_module)):
        register(_record, _module)

_plugins_loaded = False


def load_plugins() -> None:
    """Register the records of every ``shipgnc.components`` entry point, once: called by the
    scenario schema before it derives its unions (the registry's first use), not on import of
    this module, which a plug-in imports for the record classes. A plug-in that fails to load,
    or names no record, is a one-line ConfigError naming its distribution and entry point."""
    global _plugins_loaded
    if _plugins_loaded:
        return
    _plugins_loaded = True
    from importlib.metadata import entry_points

    for ep in entry_points(group=ENTRY_POINT_GROUP):
        dist = getattr(ep, "dist", None)
        origin = (f"plug-in {ep.name!r} = {ep.value!r} (entry point of distribution "
                  f"{dist.name if dist is not None else '?'} "
                  f"{dist.version if dist is not None else ''}, group {ENTRY_POINT_GROUP})")
        try:
            loaded = ep.load()
        except Exception as exc:  # any failure of third-party code: one line, naming the plug-in
            detail = " ".join(str(exc).split())
            raise ConfigError(f"{origin}: cannot be loaded: {type(exc).__name__}: {detail}") from None
        records = records_in(loaded)
        if not records:
            raise ConfigError(f"{origin}: names no component record (VesselKind, ControllerKind, "
                              "GuidanceKind, DisturbanceKind, MetricKind, SensorKind, "
                              "EstimatorKind)")
        for record in records:
            register(record, origin)
