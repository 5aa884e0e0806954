"""Encounter situations in the traffic-situation format of DNV's ``trafficgen`` (Ship Traffic
Generator, github.com/dnv-opensource/ship-traffic-generator): generated, perturbed, read, written.

A traffic situation file (JSON, maritime units as trafficgen writes them)::

    {"title": "HO", "description": "...",
     "ownShip": {"static": {"length": 100.0, "width": 12.0, "name": "..."},
                 "initial": {"position": {"lat": 58.76, "lon": 10.49}, "sog": 17.5, "cog": 0.0,
                             "heading": 0.0, "navStatus": "Under way using engine"}},
     "targetShips": [{"static": {...}, "initial": {...}}, ...]}

``sog`` in knots, ``cog`` and ``heading`` in degrees clockwise from north, positions in decimal
degrees; ``static`` (``length``, ``width`` in metres) is optional here, as are trafficgen's other
fields (``waypoints``, ``id``, ``height``, ...), which are read past. Positions are projected to the
local plane (north, east) of the own ship's start (:class:`shipgnc.ais.plane.LocalPlane` about it:
true north up, conformal);
each target then holds its initial course and speed (a kinematic target).

**The standard set** (:data:`STANDARD`): one situation of each encounter type trafficgen generates
(head-on, overtaking give-way and stand-on, crossing give-way and stand-on), built from what
trafficgen's situation input gives an encounter: the target's relative bearing β from the own ship
(``beta``), its speed relative to the own ship's (``relativeSpeed``), and a time T after which the
two would meet at the same point if neither manoeuvred (``vectorTime`` with
``maxMeetingDistance`` 0).
Own ship at the origin with course 0 at speed U; meeting point P = (U T, 0); the target starts at
S = r (cos β, sin β) with |P − S| = U_t T, i.e. r² − 2 r P·e_β + |P|² − (U_t T)² = 0 (the
far root; the near one for overtaking give-way, a slower target ahead), and steers the course
of P − S. β and the relative speed are within trafficgen's
ranges for each type (its encounter settings: ``theta14Criteria`` 5° for head-on, ``theta13``
67.5° for overtaking, ``relativeSpeed`` ranges), T within its ``vectorRange`` of 10–30 min.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from pydantic import AliasChoices, BaseModel, ConfigDict, Field, ValidationError

from shipgnc.colav.tracks import TargetTrack
from shipgnc.errors import ConfigError
from shipgnc.units import KNOT

#: the own ship's start of generated situations (trafficgen's examples: Oslofjord)
ORIGIN = (58.763449, 10.490654)


@dataclass(frozen=True)
class EncounterSpec:
    """One encounter to generate: type, the target's relative bearing ``beta_deg``, its speed
    relative to the own ship's, the time to the meeting point ``vector_time_s``."""

    title: str
    encounter_type: str
    beta_deg: float
    relative_speed: float
    vector_time_s: float


#: the standard set: one situation per encounter type (β within trafficgen's sector of each type:
#: head-on within rule 14's few degrees of dead ahead; crossing from 10° to 112.5° on either bow;
#: overtaking within 67.5° of dead ahead/astern of the slower ship), meeting after 12 minutes
STANDARD = (
    EncounterSpec("HO", "head-on", 2.0, 1.0, 720.0),
    EncounterSpec("OT-GW", "overtaking-give-way", 2.0, 0.5, 720.0),
    EncounterSpec("OT-SO", "overtaking-stand-on", 178.0, 1.5, 720.0),
    EncounterSpec("CR-GW", "crossing-give-way", 45.0, 1.0, 720.0),
    EncounterSpec("CR-SO", "crossing-stand-on", -45.0, 1.0, 720.0),
)
ENCOUNTER_TYPES = tuple(s.encounter_type for s in STANDARD)


def place_target(spec: EncounterSpec, own_speed: float) -> tuple[float, float, float, float]:
    """(north, east, course, speed) of the target at t = 0 for ``spec`` (module docstring), own
    ship at the origin with course 0 and ``own_speed`` [m/s]."""
    U_t = spec.relative_speed * own_speed
    P = np.array([own_speed * spec.vector_time_s, 0.0])
    e = np.array([math.cos(math.radians(spec.beta_deg)), math.sin(math.radians(spec.beta_deg))])
    b = P @ e
    c = P @ P - (U_t * spec.vector_time_s) ** 2
    disc = b * b - c
    if disc < 0:
        raise ConfigError(f"encounter {spec.title}: no start at bearing {spec.beta_deg:g}° meets "
                          f"the own ship after {spec.vector_time_s:g} s at relative speed "
                          f"{spec.relative_speed:g}")
    # the far root: the target comes towards the meeting point from beyond it (or from astern);
    # the near one: a slower target ahead, overtaken on the same heading
    r = b - math.sqrt(disc) if spec.encounter_type == "overtaking-give-way" else b + math.sqrt(disc)
    if r <= 0:
        raise ConfigError(f"encounter {spec.title}: no start at bearing {spec.beta_deg:g}° ahead of "
                          f"the meeting point for relative speed {spec.relative_speed:g}")
    S = r * e
    d = P - S
    return float(S[0]), float(S[1]), math.atan2(d[1], d[0]), U_t


#: the COLREG situation (:data:`shipgnc.colav.colreg.SITUATIONS`) each encounter type is
SITUATION_OF = {"head-on": "head_on", "overtaking-give-way": "overtaking",
                "overtaking-stand-on": "overtaken", "crossing-give-way": "give_way",
                "crossing-stand-on": "stand_on"}
#: the bearing spread of each type's variants [deg]: head-on's sector is only 6° wide on bearing
#: and on reciprocal course, and with equal speeds the target's course is 2β off the reciprocal
#: (the triangle own start, meeting point, target start is isosceles), so β stays within 2 ± 1°
BEARING_SPREAD_DEG = {"head-on": 1.0}


def perturbed(spec: EncounterSpec, rng: np.random.Generator, *, bearing_deg: float | None = None,
              time_frac: float = 0.2, speed_frac: float = 0.1) -> EncounterSpec:
    """``spec`` with uniform perturbations: β ± ``bearing_deg`` (default: 5°, head-on
    :data:`BEARING_SPREAD_DEG`), the meeting time (hence the range) × (1 ± ``time_frac``), the
    relative speed × (1 ± ``speed_frac``)."""
    if bearing_deg is None:
        bearing_deg = BEARING_SPREAD_DEG.get(spec.encounter_type, 5.0)
    return replace(spec,
                   beta_deg=spec.beta_deg + rng.uniform(-bearing_deg, bearing_deg),
                   vector_time_s=spec.vector_time_s * (1 + rng.uniform(-time_frac, time_frac)),
                   relative_speed=spec.relative_speed * (1 + rng.uniform(-speed_frac, speed_frac)))


def classify_spec(spec: EncounterSpec, own_speed: float) -> str:
    """The COLREG situation (:func:`shipgnc.colav.colreg.situations`) of ``spec`` at t = 0."""
    from shipgnc.colav.colreg import SITUATIONS, situations

    n, e, course, speed = place_target(spec, own_speed)
    code = situations([0.0, 0.0, 0.0, own_speed],
                      [n, e, speed * math.cos(course), speed * math.sin(course)])
    return SITUATIONS[int(code)]


def variants(spec: EncounterSpec, rng: np.random.Generator, n: int, own_speed: float, *,
             tries: int = 100) -> list[EncounterSpec]:
    """``n`` perturbed variants of ``spec`` (:func:`perturbed`) that each classify as its type
    (:data:`SITUATION_OF`): a draw outside the type's sector is drawn again (at most ``tries``
    times per variant). Drawn in sequence from ``rng``, so the first k of n variants are the
    k variants."""
    want = SITUATION_OF.get(spec.encounter_type)
    out = []
    for _ in range(n):
        for _ in range(tries):
            v = perturbed(spec, rng)
            try:
                if want is None or classify_spec(v, own_speed) == want:
                    break
            except ConfigError:
                continue
        else:
            raise ConfigError(f"encounter {spec.title}: no perturbed variant in {tries} draws "
                              f"classifies as {want}")
        out.append(v)
    return out


# ----------------------------------------------------------------------------- the file format
class _Position(BaseModel):
    """``lat``/``lon`` (trafficgen's earlier files) or ``latitude``/``longitude`` (its current
    files and the maritime-schema)."""

    model_config = ConfigDict(extra="ignore")
    lat: float = Field(ge=-90, le=90, validation_alias=AliasChoices("lat", "latitude"))
    lon: float = Field(ge=-180, le=180, validation_alias=AliasChoices("lon", "longitude"))


class _Initial(BaseModel):
    model_config = ConfigDict(extra="ignore")
    position: _Position
    sog: float = Field(ge=0, le=100)
    cog: float = Field(ge=-360, le=360)


class _Static(BaseModel):
    model_config = ConfigDict(extra="ignore")
    length: float | None = Field(None, gt=0)
    width: float | None = Field(None, gt=0)
    name: str | None = None
    mmsi: int | None = None


class _Ship(BaseModel):
    model_config = ConfigDict(extra="ignore")
    static: _Static = Field(default_factory=_Static)
    initial: _Initial


class _Situation(BaseModel):
    model_config = ConfigDict(extra="ignore")
    title: str = ""
    description: str = ""
    ownShip: _Ship
    targetShips: list[_Ship] = Field(min_length=1)


@dataclass(frozen=True)
class Situation:
    """A situation in the own ship's local plane: own start (north, east) = (0, 0), its course
    [rad] and speed [m/s], the targets as tracks; ``title`` and ``encounter_type`` label it."""

    title: str
    own_course: float
    own_speed: float
    targets: tuple[TargetTrack, ...]
    encounter_type: str = ""
    origin: tuple[float, float] = ORIGIN
    own_length: float = 100.0
    own_width: float = 12.0


def parse(data: dict, where: str = "situation") -> Situation:
    """A trafficgen traffic situation (a parsed JSON object) as a :class:`Situation`; the wrong
    schema is a one-line ConfigError naming the field."""
    try:
        s = _Situation.model_validate(data)
    except ValidationError as exc:
        err = exc.errors()[0]
        field = ".".join(str(p) for p in err["loc"])
        raise ConfigError(f"{where}: {field}: {err['msg']} (a trafficgen traffic situation: "
                          "ownShip and targetShips with initial position lat/lon, sog [kn], "
                          "cog [deg])") from None
    from shipgnc.ais.plane import LocalPlane, check_range

    o = s.ownShip.initial.position
    plane = LocalPlane((o.lat, o.lon))
    targets = []
    for j, ship in enumerate(s.targetShips):
        check_range((o.lat, o.lon), ship.initial.position.lat, ship.initial.position.lon,
                    f"{where}: targetShips[{j}]")
        n, e = plane.to_plane(ship.initial.position.lat, ship.initial.position.lon)
        st = ship.static
        targets.append(TargetTrack.constant(float(n), float(e), math.radians(ship.initial.cog),
                                            ship.initial.sog * KNOT, name=st.name or f"target {j + 1}",
                                            mmsi=st.mmsi or 0, length=st.length or 100.0,
                                            beam=st.width or 20.0))
    own = s.ownShip
    return Situation(s.title or where, math.radians(own.initial.cog), own.initial.sog * KNOT,
                     tuple(targets), origin=(o.lat, o.lon),
                     own_length=own.static.length or 100.0, own_width=own.static.width or 12.0)


def read(path) -> Situation:
    """A trafficgen traffic situation file (module docstring)."""
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise ConfigError(f"{path}: cannot be read ({exc.strerror})") from None
    except json.JSONDecodeError as exc:
        raise ConfigError(f"{path}: not JSON (line {exc.lineno}: {exc.msg})") from None
    if not isinstance(data, dict):
        raise ConfigError(f"{path}: a trafficgen traffic situation is a JSON object, got "
                          f"{type(data).__name__}")
    return parse(data, str(path))


def situation_dict(spec: EncounterSpec, own_speed: float, *, own_length: float = 100.0,
                   own_width: float = 12.0, origin=ORIGIN) -> dict:
    """The trafficgen traffic situation of ``spec`` (own ship course 0 at ``own_speed`` m/s from
    ``origin``), in its maritime units."""
    from shipgnc.ais.plane import LocalPlane

    plane = LocalPlane(origin)
    n, e, course, speed = place_target(spec, own_speed)
    lat, lon = plane.to_geo(n, e)

    def ship(lat, lon, sog, cog, static):
        cog = math.degrees(cog) % 360.0
        return {"static": static,
                "initial": {"position": {"lat": round(float(lat), 8), "lon": round(float(lon), 8)},
                            "sog": round(sog / KNOT, 4), "cog": round(cog, 4),
                            "heading": round(cog, 4), "navStatus": "Under way using engine"}}

    return {"title": spec.title,
            "description": f"{spec.encounter_type}: target at relative bearing "
                           f"{spec.beta_deg:.2f} deg, relative speed {spec.relative_speed:.3f}, "
                           f"meeting after {spec.vector_time_s / 60:.2f} min",
            "ownShip": ship(origin[0], origin[1], own_speed, 0.0,
                            {"length": own_length, "width": own_width, "name": "own ship"}),
            "targetShips": [ship(lat, lon, speed, course,
                                 {"length": 100.0, "width": 20.0, "name": "target_ship_1"})]}


def write(situation: dict, path) -> Path:
    path = Path(path)
    path.write_text(json.dumps(situation, indent=4) + "\n", encoding="utf-8")
    return path
