"""The vessel catalogue: named manoeuvring models with their source, size, speeds and limits.

Each :class:`VesselEntry` builds a model (:mod:`shipgnc.vessels.base` layout: states
``north, east, psi, u, v, r, delta, ...``, first input ``delta_c``) at a speed within its valid
range. Adding a vessel is one module with its model class plus one entry here (docs/extending.md,
"Adding a vessel").
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from shipgnc.errors import ConfigError
from shipgnc.units import KNOT

#: steering-machine options every entry takes (degrees, seconds), beside its own parameters
STEERING_PARAMS = ("rudder_max_deg", "rudder_rate_deg_s", "rudder_time_constant_s")


@dataclass(frozen=True)
class VesselEntry:
    """One catalogue vessel (see docs/extending.md). ``build(speed_mps, **params)`` returns the
    model; ``params`` are the entry's ``param_names`` (e.g. K, T for ``nomoto``) plus the steering
    options ``rudder_max_deg``, ``rudder_rate_deg_s``, ``rudder_time_constant_s``."""

    name: str
    title: str
    source: str
    length_m: float | None
    design_speed_mps: float
    speed_range_mps: tuple[float, float]
    max_rudder_rad: float
    max_rudder_rate_rad_s: float
    can_reverse: bool
    #: builder(speed_mps, steering_kwargs, **params) -> model
    builder: Callable = field(repr=False, compare=False)
    param_names: tuple[str, ...] = ()
    #: state names beyond north, east, psi, u, v, r, delta
    extra_states: tuple[str, ...] = ()
    #: Froude scale λ of a model-scale vessel (its SOLAS steering-gear rate is 2.32°/s·√λ)
    froude_scale: float = 1.0

    @property
    def states(self) -> tuple[str, ...]:
        return ("north", "east", "psi", "u", "v", "r", "delta", *self.extra_states)

    def check_speed(self, speed_mps) -> float:
        """``speed_mps`` as float within the valid range, or a one-line ConfigError."""
        low, high = self.speed_range_mps
        ok = isinstance(speed_mps, (int, float)) and not isinstance(speed_mps, bool)
        if not ok or not math.isfinite(speed_mps) or not low <= speed_mps <= high:
            raise ConfigError(f"vessel {self.name}: speed_mps = {speed_mps!r} is outside the "
                              f"model's valid range {low:g}–{high:g} m/s "
                              f"({low / KNOT:.3g}–{high / KNOT:.3g} kn)")
        return float(speed_mps)

    def build(self, speed_mps: float | None = None, **params):
        """The model at ``speed_mps`` (default: the design speed) with ``params``."""
        speed = self.check_speed(self.design_speed_mps if speed_mps is None else speed_mps)
        allowed = (*self.param_names, *STEERING_PARAMS)
        for key in params:
            if key not in allowed:
                raise ConfigError(f"vessel {self.name}: unknown parameter {key!r}; allowed: "
                                  f"{', '.join(allowed)}")
        for key in STEERING_PARAMS:
            value = params.get(key)
            if value is None:
                continue
            ok = isinstance(value, (int, float)) and not isinstance(value, bool)
            if not ok or not 0 < value < math.inf or (key == "rudder_max_deg" and value > 90):
                rule = "a number in (0, 90]" if key == "rudder_max_deg" else "a positive number"
                raise ConfigError(f"vessel {self.name}: {key} = {value!r}; allowed: {rule}")
        steering = {
            "delta_max": math.radians(params.pop("rudder_max_deg"))
            if params.get("rudder_max_deg") is not None else self.max_rudder_rad,
            "delta_rate": math.radians(params.pop("rudder_rate_deg_s"))
            if params.get("rudder_rate_deg_s") is not None else self.max_rudder_rate_rad_s,
        }
        if params.get("rudder_time_constant_s") is not None:
            steering["T_delta"] = float(params.pop("rudder_time_constant_s"))
        params = {k: v for k, v in params.items() if v is not None and k not in STEERING_PARAMS}
        return self.builder(speed, steering, **params)

    def row(self) -> dict:
        """The entry as a JSON-ready dict (``shipgnc vessels --json``)."""
        return {"name": self.name, "title": self.title, "source": self.source,
                "length_m": self.length_m, "design_speed_mps": self.design_speed_mps,
                "design_speed_kn": self.design_speed_mps / KNOT,
                "speed_range_mps": list(self.speed_range_mps),
                "max_rudder_deg": math.degrees(self.max_rudder_rad),
                "max_rudder_rate_deg_s": math.degrees(self.max_rudder_rate_rad_s),
                "can_reverse": self.can_reverse, "states": list(self.states),
                "params": list(self.param_names),
                "document": None, "source_kind": "paper", "presets": [], "inputs": self.inputs(),
                "speed_note": "the source's range of validity"}

    def inputs(self) -> list[dict]:
        """The inputs with their unit and limits, of the model at its design speed (a model given
        by its parameters, e.g. ``nomoto``, has the rudder command alone)."""
        from shipgnc.vessels.base import RUDDER_INPUT
        from shipgnc.vessels.documents import input_rows

        try:
            model = self.build()
        except ConfigError:  # needs its parameters: the catalogue's rudder command
            return input_rows((RUDDER_INPUT,), [-self.max_rudder_rad], [self.max_rudder_rad])
        return input_rows(model.inputs, *model.input_limits())


def _need(name: str, params: dict, keys: tuple[str, ...]) -> None:
    missing = [k for k in keys if k not in params]
    if missing:
        raise ConfigError(f"vessel {name}: needs parameter{'s' if len(missing) > 1 else ''} "
                          f"{', '.join(missing)}")


# --------------------------------------------------------------------------- builders

def _nomoto(speed, steering, **params):
    from shipgnc.models.nomoto import NomotoModel, NorrbinModel
    from shipgnc.vessels.nomoto import NomotoVessel

    _need("nomoto", params, ("K", "T"))
    if any(k in params for k in ("a1", "a3", "a0", "a2")):
        steer = NorrbinModel(params["K"], params["T"], params.get("a1", 1.0),
                             params.get("a3", 0.0), params.get("a0", 0.0), params.get("a2", 0.0),
                             U=speed)
    else:
        steer = NomotoModel(params["K"], params["T"], U=speed)
    return NomotoVessel(steer, **steering)


def _nomoto2(speed, steering, **params):
    from shipgnc.vessels.nomoto import Nomoto2Vessel

    _need("nomoto2", params, ("K", "T1", "T2", "T3"))
    return Nomoto2Vessel(params["K"], params["T1"], params["T2"], params["T3"], U=speed,
                         **steering)


def _linear(speed, steering, **params):
    from shipgnc.vessels.linear import Linear3DOFVessel, from_dimensions

    if "M" in params or "N" in params:
        _need("linear-3dof", params, ("M", "N", "B"))
        extra = sorted(set(params) - {"M", "N", "B"})
        if extra:
            raise ConfigError(f"vessel linear-3dof: give the matrices M, N, B or the main "
                              f"dimensions (L, B, T, Cb, ...), not both ({', '.join(extra)})")
        return Linear3DOFVessel(params["M"], params["N"], params["B"], U=speed, **steering)
    _need("linear-3dof", params, ("L", "B", "T", "Cb"))
    return from_dimensions(speed_mps=speed, **params, **steering)


def _mariner_cst(speed, steering):
    from shipgnc.vessels.mariner_cst import MarinerCST

    return MarinerCST(U0=speed, **steering)


def _frigate(speed, steering):
    from shipgnc.vessels.frigate import frigate

    return frigate(speed, **steering)


def _kvlcc2(scale):
    def build(speed, steering, T_n=None):
        from shipgnc.vessels.kvlcc2 import KVLCC2

        return KVLCC2(scale, speed, T_n=T_n, **steering)

    return build


VESSELS: Mapping[str, VesselEntry] = {}


def register(entry: VesselEntry) -> VesselEntry:
    """Add ``entry`` to :data:`VESSELS` (a vessel module's one catalogue line)."""
    VESSELS[entry.name] = entry  # type: ignore[index]
    return entry


register(VesselEntry(
    name="mariner-cst", title="Mariner-class cargo ship, nonlinear manoeuvring model",
    source="Chislett & Strøm-Tejsen (1965), Int. Shipbuilding Progress 12(129); Fossen (2021) Handbook of "
           "Marine Craft Hydrodynamics and Motion Control, MSS mariner.m",
    length_m=160.93, design_speed_mps=7.7175, speed_range_mps=(10 * KNOT, 20 * KNOT),
    max_rudder_rad=math.radians(40.0), max_rudder_rate_rad_s=math.radians(5.0),
    can_reverse=False, builder=_mariner_cst))

register(VesselEntry(
    name="frigate", title="frigate, Norrbin autopilot model with speed-dependent K, T",
    source="van Amerongen (1982), PhD thesis, TU Delft; Fossen (2021), MSS frigate.m",
    length_m=100.0, design_speed_mps=9.0, speed_range_mps=(5.0, 12.0),
    max_rudder_rad=math.radians(30.0), max_rudder_rate_rad_s=math.radians(10.0),
    can_reverse=False, builder=_frigate))

register(VesselEntry(
    name="kvlcc2", title="KVLCC2 tanker, MMG model (full scale, L = 320 m)",
    source="Yasukawa & Yoshimura (2015), J. Mar. Sci. Technol. 20:37-52",
    length_m=320.0, design_speed_mps=15.5 * KNOT, speed_range_mps=(5 * KNOT, 16.5 * KNOT),
    max_rudder_rad=math.radians(35.0), max_rudder_rate_rad_s=math.radians(2.34),
    can_reverse=False, builder=_kvlcc2("full"), param_names=("T_n",), extra_states=("n",)))

_L7 = math.sqrt(320.0 / 7.0)  # Froude scale of speeds, model L7
register(VesselEntry(
    name="kvlcc2-l7", title="KVLCC2 tanker, MMG model (the paper's model L7, L = 7 m)",
    source="Yasukawa & Yoshimura (2015), J. Mar. Sci. Technol. 20:37-52",
    length_m=7.0, design_speed_mps=1.179,
    speed_range_mps=(round(5 * KNOT / _L7, 3), round(16.5 * KNOT / _L7, 3)),
    max_rudder_rad=math.radians(35.0), max_rudder_rate_rad_s=math.radians(15.8),
    can_reverse=False, builder=_kvlcc2("model"), param_names=("T_n",), extra_states=("n",),
    froude_scale=320.0 / 7.0))

register(VesselEntry(
    name="nomoto", title="first-order Nomoto steering model (or Norrbin with a0..a3)",
    source="Nomoto, Taguchi, Honda & Hirano (1957), Int. Shipbuilding Progress 4; "
           "Fossen (2021) eq. 7.43",
    length_m=None, design_speed_mps=15 * KNOT, speed_range_mps=(0.1, 40.0),
    max_rudder_rad=math.radians(35.0), max_rudder_rate_rad_s=math.radians(65.0 / 28.0),
    can_reverse=False, builder=_nomoto, param_names=("K", "T", "a0", "a1", "a2", "a3")))

register(VesselEntry(
    name="nomoto2", title="second-order Nomoto steering model",
    source="Nomoto et al. (1957); Fossen (2021) eq. 7.50",
    length_m=None, design_speed_mps=15 * KNOT, speed_range_mps=(0.1, 40.0),
    max_rudder_rad=math.radians(35.0), max_rudder_rate_rad_s=math.radians(65.0 / 28.0),
    can_reverse=False, builder=_nomoto2, param_names=("K", "T1", "T2", "T3"),
    extra_states=("w",)))

register(VesselEntry(
    name="linear-3dof", title="linear 3-DOF manoeuvring model (matrices, or Clarke 1983)",
    source="Fossen (2021) §7.2; Clarke, Gedling & Hine (1983), Trans. RINA 125, 45-68",
    length_m=None, design_speed_mps=15 * KNOT, speed_range_mps=(0.1, 40.0),
    max_rudder_rad=math.radians(35.0), max_rudder_rate_rad_s=math.radians(65.0 / 28.0),
    can_reverse=False, builder=_linear,
    param_names=("M", "N", "B", "L", "T", "Cb", "R66", "xg", "T_surge")))


def listing() -> dict[str, dict]:
    """Every vessel a scenario may name, as :meth:`VesselEntry.row` dicts by name: the documents'
    models (:mod:`shipgnc.vessels.documents`, each with its presets) first, then the catalogue's."""
    from shipgnc.vessels.documents import document_vessels

    rows = {name: vessel.row() for name, vessel in document_vessels().items()}
    rows.update((name, entry.row()) for name, entry in VESSELS.items())
    return rows


def get_vessel(name: str) -> VesselEntry:
    """The catalogue entry called ``name`` (unknown: a ConfigError naming the allowed ones)."""
    if not isinstance(name, str) or name not in VESSELS:
        raise ConfigError(f"vessel {name!r}: unknown vessel; allowed: {', '.join(VESSELS)}")
    return VESSELS[name]
