"""Parse the CLI's FIELD strings (note 002-2.9.1) into SI current fields.

    uniform:north=..,east=..                 c₀ [m/s | kn]
    shear:k=..                               v_E = k·x_N [1/s | 1/h]
    rotation:omega=..,north=..,east=..       ω [rad/s | rad/h] about (north, east) [m | nm]
    lamb-oseen:gamma=..,rc=..,north=..,east=..   Γ [m²/s | nm²/h], r_c and centre [m | nm]
    rankine:gamma=..,rc=..,north=..,east=..
    lamb-oseen:…,drift_north=..,drift_east=..    a vortex whose centre moves [m/s | kn]
    gyre:speed=..,length=..,north=..,east=..  double gyre, U [m/s | kn], cell L and centre [m | nm]
    A+B                                      the sum
    path/to/file.nc[:cubic]                  gridded field (SI data)

``units="nautical"`` reads the values in the second unit of each bracket.
"""

from __future__ import annotations

import math
from pathlib import Path

from shipgnc.errors import ConfigError, require
from shipgnc.units import KNOT, NAUTICAL_MILE

HOUR = 3600.0
#: name -> {parameter: (required, SI factor for nautical input)}
_SPECS = {
    "uniform": {"north": (False, KNOT), "east": (False, KNOT)},
    "shear": {"k": (True, 1 / HOUR)},
    "rotation": {"omega": (True, 1 / HOUR), "north": (False, NAUTICAL_MILE), "east": (False, NAUTICAL_MILE)},
    "lamb-oseen": {"gamma": (True, NAUTICAL_MILE**2 / HOUR), "rc": (True, NAUTICAL_MILE),
                   "north": (False, NAUTICAL_MILE), "east": (False, NAUTICAL_MILE)},
    "rankine": {"gamma": (True, NAUTICAL_MILE**2 / HOUR), "rc": (True, NAUTICAL_MILE),
                "north": (False, NAUTICAL_MILE), "east": (False, NAUTICAL_MILE)},
    "gyre": {"speed": (True, KNOT), "length": (True, NAUTICAL_MILE), "north": (False, NAUTICAL_MILE),
             "east": (False, NAUTICAL_MILE)},
}
for _vortex in ("lamb-oseen", "rankine"):
    _SPECS[_vortex].update({"drift_north": (False, KNOT), "drift_east": (False, KNOT)})
UNITS = ("si", "nautical")


def _term(text: str, units: str):
    from shipgnc.environment import fields as F

    name, _, args = text.partition(":")
    name = name.strip().lower()
    if name not in _SPECS:
        path = Path(text.strip())
        method = "linear"
        if not path.exists() and text.strip().endswith((":cubic", ":linear")):
            path_text, _, method = text.strip().rpartition(":")
            path = Path(path_text)
        if path.suffix in (".nc", ".nc4", ".netcdf") or path.exists():
            require(path.is_file(), "--field", text, "NetCDF file not found")
            return F.GriddedCurrent.from_netcdf(path, method)
        raise ConfigError(f"--field = {text!r}: unknown field; allowed: {', '.join(_SPECS)}, a sum joined "
                          "with '+', or a NetCDF file")
    spec = _SPECS[name]
    values = {key: number * (spec[key][1] if units == "nautical" else 1.0)
              for key, number in key_values(args, spec, f"--field {name}").items()}
    missing = [k for k, (req, _) in spec.items() if req and k not in values]
    require(not missing, f"--field {name}", text, f"missing {', '.join(missing)}")
    centre = (values.get("north", 0.0), values.get("east", 0.0))
    if name == "uniform":
        return F.UniformCurrent(values.get("north", 0.0), values.get("east", 0.0))
    if name == "shear":
        return F.shear(values["k"])
    if name == "rotation":
        return F.RigidRotation(values["omega"], centre)
    if name == "gyre":
        return F.DoubleGyre(values["speed"], values["length"], centre)
    cls = F.LambOseenVortex if name == "lamb-oseen" else F.RankineVortex
    drift = (values.get("drift_north", 0.0), values.get("drift_east", 0.0))
    return cls(values["gamma"], values["rc"], centre, drift)


def parse_field(text: str, units: str = "si"):
    """A current field from a FIELD string (module docstring); terms joined by '+' are summed."""
    require(units in UNITS, "--units", units, f"allowed: {', '.join(UNITS)}")
    require(isinstance(text, str) and text.strip() != "", "--field", text, "must name a field")
    parts = text.split("+")
    if any(not t.strip() for t in parts):
        raise ConfigError(f"--field = {text!r}: an empty term in the sum (a leading, trailing or doubled "
                          "'+'); give FIELD+FIELD")
    terms = [_term(t, units) for t in parts]
    if len(terms) == 1:
        return terms[0]
    from shipgnc.environment.fields import SumField

    return SumField(terms)


def key_values(args: str, keys, where: str) -> dict[str, float]:
    """``"a=1, b=2.5"`` → ``{"a": 1.0, "b": 2.5}``: keys (case-insensitive) among ``keys``, finite
    numbers; anything else a one-line ConfigError naming ``where``."""
    values: dict[str, float] = {}
    for part in filter(None, (a.strip() for a in args.split(","))):
        key, eq, val = part.partition("=")
        key = key.strip().lower()
        require(eq == "=" and key in keys, where, part,
                f"expected key=value with key in {', '.join(keys)}")
        try:
            number = float(val)
        except ValueError:
            raise ConfigError(f"{where}.{key} = {val!r}: must be a number") from None
        require(math.isfinite(number), f"{where}.{key}", val, "must be finite")
        values[key] = number
    return values
