"""The documents' vessels in the one vessel catalogue (``shipgnc vessels``): document 001's boat
(with its parameter presets), document 003's CyberShip II, document 000's de Wit–Oppe Mariner and
document 004's catamaran, each described as a catalogue entry is (source, length, speeds, actuator
limits, states), read from the model's own parameters rather than restated.

Their speeds are the models' straight runs, not a source's validity range (no document states
one): the design speed is the straight run of the document's runs, the valid range the straight
runs the actuators reach (:attr:`DocumentVessel.speed_note` says which, per vessel).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

from shipgnc.errors import ConfigError
from shipgnc.units import KNOT


@dataclass(frozen=True)
class DocumentVessel:
    """One document's vessel model (``vessel: {model: NAME}``). ``build(preset)`` returns the
    model of a preset (None: the default); ``speeds(model)`` its (design speed, (low, high))
    [m/s], the basis of both being :attr:`speed_note`."""

    name: str
    title: str
    document: str
    source: str
    build: Callable = field(repr=False, compare=False)
    speeds: Callable = field(repr=False, compare=False)
    speed_note: str = ""
    presets: tuple[str, ...] = ()
    #: what each preset is (overrides of the default, or the document's own note)
    preset_notes: dict = field(default_factory=dict, compare=False)

    def model(self, preset: str | None = None):
        """The model of ``preset`` (None: the default)."""
        if preset is not None and preset not in self.presets:
            allowed = ", ".join(self.presets) if self.presets else "none"
            raise ConfigError(f"vessel {self.name}: unknown preset {preset!r}; allowed: {allowed}")
        return self.build(preset)

    def row(self, preset: str | None = None) -> dict:
        """The vessel as a JSON-ready dict, with the keys of
        :meth:`shipgnc.vessels.VesselEntry.row` (SI; rudder limits in degrees, null for a vessel
        steered by thrusters) and ``document``, ``presets``, ``inputs``, ``speed_note``."""
        model = self.model(preset)
        design, (low, high) = self.speeds(model)
        rudder = rudder_limits(model)
        lower, upper = model.input_limits()
        # astern: a thrust or propeller-speed input that may turn negative
        can_reverse = any(s.name in ("T", "n") and lo < 0 for s, lo in zip(model.inputs, lower,
                                                                          strict=True))
        return {"name": self.name, "title": self.title, "source": self.source,
                "length_m": float(model.length), "design_speed_mps": design,
                "design_speed_kn": design / KNOT, "speed_range_mps": [low, high],
                "max_rudder_deg": None if rudder is None else math.degrees(rudder[0]),
                "max_rudder_rate_deg_s": None if rudder is None else math.degrees(rudder[1]),
                "can_reverse": bool(can_reverse),
                "states": [s.name for s in model.states],
                "params": sorted(model.params.as_dict()),
                "document": self.document, "source_kind": "document",
                "presets": list(self.presets), "inputs": input_rows(model.inputs, lower, upper),
                "speed_note": self.speed_note}


def rudder_limits(model) -> tuple[float, float] | None:
    """(δ_max [rad], δ̇_max [rad/s]) of a model steered by a rudder (an input or state ``delta``
    with ``params.delta_max``, ``delta_rate``), None for one steered by thrusters."""
    params = getattr(model, "params", None)
    if not hasattr(params, "delta_max") or not hasattr(params, "delta_rate"):
        return None
    return float(params.delta_max), float(params.delta_rate)


def input_rows(inputs, lower, upper) -> list[dict]:
    """Input signals with their unit and limits (null: unlimited)."""
    def bound(value) -> float | None:
        return float(value) if math.isfinite(value) else None

    return [{"name": s.name, "unit": s.unit, "min": bound(lo), "max": bound(hi)}
            for s, lo, hi in zip(inputs, lower, upper, strict=True)]


# --------------------------------------------------------------------------- the four documents

def _boat(preset):
    from shipgnc.models.fossen3dof import VectoredThrustBoat

    return VectoredThrustBoat.from_preset(preset or "otter")


def _boat_speeds(model):
    p = model.params
    return model.params.top_speed(p.T_max), (model.params.top_speed(p.T_min),
                                             model.params.top_speed(p.T_max))


def _cybership(preset):
    from shipgnc.models.cybership2 import CyberShip2

    return CyberShip2()


def _cybership_speeds(model):
    from shipgnc.models.cybership2 import CRUISE_RPS, surge_equilibrium

    p = model.params
    return (surge_equilibrium(p, CRUISE_RPS),
            (surge_equilibrium(p, p.n_min), surge_equilibrium(p, p.n_max)))


def _mariner(preset):
    from shipgnc.models.mariner import MarinerWitOppe

    return MarinerWitOppe()


def _mariner_speeds(model):
    U = model.params.U
    return U, (U, U)


def _catamaran(preset):
    from shipgnc.models.catamaran import Catamaran

    return Catamaran.from_preset(preset) if preset else Catamaran.from_preset()


def _catamaran_speeds(model):
    from shipgnc.models.catamaran import V_MIN_FIT

    top = model.params.top_speed()
    return top, (V_MIN_FIT, top)


def _boat_presets() -> dict:
    from shipgnc.models.fossen3dof import PRESETS

    return {name: ", ".join(f"{k} = {v:g}" for k, v in changes.items()) or "the Otter-derived set"
            for name, changes in PRESETS.items()}


def _catamaran_presets() -> dict:
    from shipgnc.models.catamaran import PRESET_NOTES

    return dict(PRESET_NOTES)


def document_vessels() -> dict[str, DocumentVessel]:
    """The documents' vessels by ``vessel.model``, in document order of the registry."""
    boat = _boat_presets()
    catamaran = _catamaran_presets()
    vessels = (
        DocumentVessel(
            name="vectored-thrust-boat", title="small boat with one vectored thruster, Fossen 3-DOF",
            document="001",
            source="document 001 (S. Markowski, PUT Powertrain, 2026); parameters of Fossen's Otter "
                   "USV model (MSS otter.m; Fossen 2021, Handbook of Marine Craft Hydrodynamics "
                   "and Motion Control), note 001-1.6",
            build=_boat, speeds=_boat_speeds,
            speed_note="straight-run speeds T/(−X_u) for thrust T_min..T_max (note 001-1.7); U at "
                       "T_max; the document states no validity range",
            presets=tuple(boat), preset_notes=boat),
        DocumentVessel(
            name="cybership2", title="CyberShip II, 1:70 supply-vessel model", document="003",
            source="document 003 (M. Tomera, Gdynia Maritime University); Skjetne, Smogeli & "
                   "Fossen (2004), Modeling, Identification and Control 25(1)",
            build=_cybership, speeds=_cybership_speeds,
            speed_note="straight-run speeds over the propeller range n_min..n_max (2T(n, u) = "
                       "d₁₁(u)u, δ = 0); U at document 003's 8.13 rps (note 003-3.5)"),
        DocumentVessel(
            name="mariner", title="Mariner-class cargo ship, de Wit–Oppe simulation model (25)",
            document="000",
            source="document 000 (Polish article; de Wit–Oppe model (25)); distinct from the "
                   "catalogue's mariner-cst",
            build=_mariner, speeds=_mariner_speeds,
            speed_note="one speed: the model's surge settles at U = S/f (0.25 nm/min, 15 kn; "
                       "note 000-0.1); its coefficients hold at that speed"),
        DocumentVessel(
            name="catamaran", title="twin-azimuth-thruster research catamaran (22.3 m, 155 t)",
            document="004",
            source="document 004 (Shushlyapin, Karapetyan, Bezuglaya, Afonina, SPIIRAS "
                   "Proceedings 2017), note 004-4.3",
            build=_catamaran, speeds=_catamaran_speeds,
            speed_note="from the resistance fit's minimum V_m (below it a quadratic continuation, "
                       "note 004-C8) to the straight-run top speed 2T_v = R(V) (note 004-S1)",
            presets=tuple(catamaran), preset_notes=catamaran),
    )
    return {v.name: v for v in vessels}
