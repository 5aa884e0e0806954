"""What a study is: a scenario, a grid of overrides, a Monte Carlo of seeded members.

A study is the product of its grids (each grid key is a scenario field, as in ``--set``) times
``members`` Monte Carlo members. Member *i* has its own random streams,
``SeedSequence(seed).spawn(members)[i]``, split in three children: one draws the member's initial
state offsets (:class:`Perturbation` of a state field), one feeds the scenario's random
disturbances (:class:`~shipgnc.streams.MemberStreams`), one draws the member's plant
parameters (:class:`Perturbation` of ``vessel.params.NAME``). So a member's result depends on
``seed`` and *i* only, never on how the study is chunked or where a chunk runs; and member *i*
meets the same sea, the same offsets and the same plant at every grid point (common random
numbers: differences between grid points are the grid's, not the dice's).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from shipgnc.errors import ConfigError, require
from shipgnc.scenarios.registry import load_scenario, parse_override
from shipgnc.scenarios.schema import Scenario
from shipgnc.units import deg

#: initial-state fields a member may be offset in, with the conversion of the offset to SI
PERTURBABLE = {"north": ("north", 1.0), "east": ("east", 1.0), "psi_deg": ("psi", deg(1.0)),
               "u": ("u", 1.0), "v": ("v", 1.0), "r_deg_s": ("r", deg(1.0))}
#: the unit an offset of each field is given in (and reported in)
PERTURB_UNITS = {"north": "m", "east": "m", "psi_deg": "deg", "u": "m/s", "v": "m/s", "r_deg_s": "deg/s"}
DISTRIBUTIONS = ("normal", "uniform")
#: a perturbed plant parameter is named ``vessel.params.NAME`` (NAME a field of the model's
#: parameter class, in SI)
PARAM_PREFIX = "vessel.params."
#: scenario fields a study sets itself, which --grid and --set may not
STUDY_OWNED = {
    "simulation.seed": "member i's random streams come from --seed "
                       "(SeedSequence(seed).spawn(members)[i]); give --seed instead",
    "simulation.backend": "a study runs every chunk on the compiled loop where one covers the "
                          "setup, else on numpy, so that chunks agree to the bit",
}


@dataclass(frozen=True)
class Perturbation:
    """A random change per member: an offset of one initial-state field, or of one plant parameter.

    ``normal:SIGMA`` (zero mean) or ``uniform:LOW,HIGH``. An initial-state field takes offsets in
    its unit (``psi_deg`` in degrees, ``north`` in metres, ...). A plant parameter
    ``vessel.params.NAME`` takes offsets in SI added to the nominal value, or with a ``%`` suffix
    relative to it (``relative``): ``normal:5%`` draws NAME = nominal · (1 + 0.05 z).
    """

    field: str
    kind: str
    low: float  # normal: 0; uniform: lower bound
    high: float  # normal: sigma; uniform: upper bound
    relative: bool = False  # percent of the nominal value (plant parameters only)

    @classmethod
    def parse(cls, text: str) -> Perturbation:
        """``"psi_deg=uniform:-30,30"``, ``"north=normal:5"`` or ``"vessel.params.m=normal:5%"``."""
        field, sep, rule = text.partition("=")
        field = field.strip().removeprefix("initial_state.")
        param = field.removeprefix(PARAM_PREFIX) if field.startswith(PARAM_PREFIX) else None
        if not sep or (field not in PERTURBABLE and not (param and param.isidentifier())):
            raise ConfigError(f"--perturb {text!r}: expected FIELD=normal:SIGMA or FIELD=uniform:LOW,HIGH "
                              f"with FIELD one of {', '.join(PERTURBABLE)}, or {PARAM_PREFIX}NAME "
                              "(a plant parameter)")
        kind, _, args = rule.partition(":")
        kind = kind.strip()
        if kind not in DISTRIBUTIONS:
            raise ConfigError(f"--perturb {text!r}: distribution {kind!r} unknown; allowed: "
                              f"{', '.join(DISTRIBUTIONS)}")
        items = [a.strip() for a in args.split(",")]
        percent = [a.endswith("%") for a in items]
        relative = any(percent)
        if relative and param is None:
            raise ConfigError(f"--perturb {text!r}: a % spread is relative to a plant parameter's "
                              "nominal value; an initial-state offset takes absolute values")
        if relative and not all(percent):
            raise ConfigError(f"--perturb {text!r}: give every bound in % or none")
        try:
            numbers = [float(a.removesuffix("%")) for a in items]
        except ValueError:
            raise ConfigError(f"--perturb {text!r}: {args!r} is not a list of numbers") from None
        if not all(math.isfinite(v) for v in numbers):
            raise ConfigError(f"--perturb {text!r}: values must be finite")
        if kind == "normal":
            if len(numbers) != 1 or numbers[0] < 0:
                raise ConfigError(f"--perturb {text!r}: normal takes one standard deviation >= 0")
            return cls(field, kind, 0.0, numbers[0], relative)
        if len(numbers) != 2 or numbers[0] > numbers[1]:
            raise ConfigError(f"--perturb {text!r}: uniform takes LOW,HIGH with LOW <= HIGH")
        return cls(field, kind, numbers[0], numbers[1], relative)

    @property
    def param(self) -> str | None:
        """The plant parameter's NAME (``vessel.params.NAME``), None for an initial-state field."""
        return self.field.removeprefix(PARAM_PREFIX) if self.field.startswith(PARAM_PREFIX) else None

    def draw(self, rng: np.random.Generator) -> float:
        if self.kind == "normal":
            return float(rng.normal(0.0, self.high))
        return float(rng.uniform(self.low, self.high))

    def apply(self, nominal: float, offset: float) -> float:
        """A plant parameter's value from its ``nominal`` value and a drawn ``offset``."""
        return float(nominal * (1.0 + offset / 100.0) if self.relative else nominal + offset)

    def __str__(self) -> str:
        pct = "%" if self.relative else ""
        args = f"{self.high:g}{pct}" if self.kind == "normal" else f"{self.low:g}{pct},{self.high:g}{pct}"
        return f"{self.field}={self.kind}:{args}"


def parse_grid(text: str) -> tuple[str, tuple]:
    """``"controller.omega=0.5,1,2"`` → ``("controller.omega", (0.5, 1, 2))`` (values read as YAML)."""
    key, sep, values = text.partition("=")
    key = key.strip()
    if not sep or not key:
        raise ConfigError(f"--grid {text!r}: expected KEY=V1,V2,... with a dotted scenario key, "
                          f"e.g. controller.omega=0.5,1.0")
    items = [v.strip() for v in values.split(",")]
    if items != [""] and "" in items:
        raise ConfigError(f"--grid {text!r}: an empty value between commas (a trailing or doubled comma); "
                          "give KEY=V1,V2,... without empty entries")
    items = [v for v in items if v]
    if not items:
        raise ConfigError(f"--grid {text!r}: the grid of {key!r} is empty; give at least one value")
    parsed = tuple(parse_override(f"{key}={v}")[1] for v in items)
    for value in parsed:
        if not isinstance(value, (int, float, str)) or isinstance(value, bool):
            raise ConfigError(f"--grid {key}: value {value!r} is not a number or a name")
    if len(set(parsed)) != len(parsed):
        raise ConfigError(f"--grid {key}: repeated values in {list(parsed)}")
    return key, parsed


def _set_keys(item: str) -> list[str]:
    """The dotted keys an override sets: ``a.b=1`` → ``[a.b]``; ``a={b: 1, c: {d: 2}}`` →
    ``[a, a.b, a.c, a.c.d]``."""
    def walk(key, value):
        yield key
        if isinstance(value, dict):
            for k, v in value.items():
                yield from walk(f"{key}.{k}", v)

    return list(walk(*parse_override(item)))


@dataclass(frozen=True)
class Study:
    """A sweep of ``scenario`` over the product of ``grid`` times ``members`` seeded members.

    ``grid``: ordered (key, values) pairs; ``overrides``: ``--set`` items applied first;
    ``series``: keep every member's full time series in the result (memory: members × samples).
    """

    scenario: str
    grid: tuple[tuple[str, tuple], ...] = ()
    members: int = 1
    seed: int = 0
    perturb: tuple[Perturbation, ...] = ()
    overrides: tuple[str, ...] = ()
    series: bool = False

    def __post_init__(self) -> None:
        require(isinstance(self.members, (int, np.integer)) and not isinstance(self.members, bool)
                and self.members >= 1, "--mc", self.members, "must be an integer >= 1")
        require(isinstance(self.seed, (int, np.integer)) and not isinstance(self.seed, bool)
                and 0 <= self.seed < 2**63, "--seed", self.seed,
                "must be an integer from 0 to 2**63 - 1 (what the result files store)")
        keys = [k for k, _ in self.grid]
        repeated = sorted({k for k in keys if keys.count(k) > 1})
        require(not repeated, "--grid", ", ".join(repeated), "each key may be gridded once")
        for key, values in self.grid:
            require(len(values) >= 1, f"--grid {key}", "[]", "needs at least one value")
        for flag, key in [*(("--grid", k) for k in keys),
                          *(("--set", k) for o in self.overrides for k in _set_keys(o))]:
            if key in STUDY_OWNED:
                raise ConfigError(f"{flag} {key}: not in a study: {STUDY_OWNED[key]}")
        fields = [p.field for p in self.perturb]
        require(len(set(fields)) == len(fields), "--perturb", ", ".join(fields),
                "each field may be perturbed once")

    @property
    def offsets(self) -> tuple[Perturbation, ...]:
        """The perturbations of initial-state fields."""
        return tuple(p for p in self.perturb if p.param is None)

    @property
    def plant(self) -> tuple[Perturbation, ...]:
        """The perturbations of plant parameters (``vessel.params.NAME``)."""
        return tuple(p for p in self.perturb if p.param is not None)

    @property
    def dims(self) -> tuple[str, ...]:
        return tuple(k for k, _ in self.grid)

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(v) for _, v in self.grid)

    @property
    def points(self) -> list[tuple]:
        """Every grid point (a tuple of values, in grid-key order; ``[()]`` without a grid)."""
        return list(itertools.product(*(v for _, v in self.grid)))

    def scenario_at(self, point: tuple) -> Scenario:
        """The validated scenario of one grid point."""
        extra = [f"{k}={v}" for (k, _), v in zip(self.grid, point, strict=True)]
        try:
            return load_scenario(self.scenario, [*self.overrides, *extra])
        except ConfigError as exc:
            where = ", ".join(extra)
            raise ConfigError(f"{exc} (at grid point {where})" if where else str(exc)) from None

    def member_streams(self, member: int) -> tuple[np.random.SeedSequence, ...]:
        """Member ``member``'s three streams (initial offsets, disturbances, plant parameters):
        ``SeedSequence(seed).spawn(members)[member].spawn(3)``, built directly from the spawn key
        so that no chunk needs the others (the first two are those of ``.spawn(2)``: a plant
        perturbation leaves the offsets and the sea of every member as they were)."""
        return tuple(self.member_stream(member, j) for j in (0, 1, 2))

    def member_stream(self, member: int, which: int) -> np.random.SeedSequence:
        """One of :meth:`member_streams` (0 offsets, 1 disturbances, 2 plant), built alone."""
        return np.random.SeedSequence(int(self.seed), spawn_key=(int(member), int(which)))

    def member_seeds(self, start: int, stop: int, which: int) -> MemberSeeds:
        """Members ``start … stop − 1``'s streams of kind ``which`` (:meth:`member_stream`), each
        made when it is read (a run that draws nothing makes none: ≈ 15 µs a member)."""
        return MemberSeeds(self, start, stop, which)


class MemberSeeds:
    """A sequence of study members' ``SeedSequence`` of one kind (:meth:`Study.member_seeds`)."""

    def __init__(self, study: Study, start: int, stop: int, which: int):
        self.study, self.start, self.stop, self.which = study, int(start), int(stop), int(which)

    def __len__(self) -> int:
        return self.stop - self.start

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(len(self)))]
        if not -len(self) <= index < len(self):
            raise IndexError(index)
        return self.study.member_stream(self.start + index % len(self), self.which)
