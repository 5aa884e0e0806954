"""Unit conversions used at model and scenario boundaries (SI inside the toolkit)."""

from __future__ import annotations

import math
import re

KNOT = 1852.0 / 3600.0  #: m/s per knot
NAUTICAL_MILE = 1852.0  #: m per nautical mile
MINUTE = 60.0  #: s per minute
G = 9.81  #: standard gravity used by the Otter rules [m/s^2]


def deg(x):
    """Degrees → radians (works on floats and arrays)."""
    return x * (math.pi / 180.0)


def to_deg(x):
    """Radians → degrees (works on floats and arrays)."""
    return x * (180.0 / math.pi)


_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
#: an SI quantity (or a range ``a…b``) in a message: numbers, an optional space and a unit below
_SI_QUANTITY = re.compile(rf"(?<![\w.])({_NUMBER})(?:…({_NUMBER}))? ?(m²/s|m/s|1/s|m|s)(?![\w/²])")
#: SI unit → (nautical unit, factor from SI)
_TO_NAUTICAL = {"m": ("nm", 1 / NAUTICAL_MILE), "s": ("h", 1 / 3600.0), "m/s": ("kn", 1 / KNOT),
                "1/s": ("1/h", 3600.0), "m²/s": ("nm²/h", 3600.0 / NAUTICAL_MILE**2)}


def nautical_text(text: str) -> str:
    """A message with its SI quantities (``1852 m``, ``3600 s``, ``2.5 m/s``, ``k = 1e-4 1/s``,
    ``Γ = 1e5 m²/s``) restated in the nautical units a user of ``--units nautical`` typed (nm, h,
    kn, 1/h, nm²/h), so that an error speaks the units of its input."""
    def convert(match: re.Match) -> str:
        unit, factor = _TO_NAUTICAL[match.group(3)]
        values = [_restate(v, factor) for v in match.groups()[:2] if v is not None]
        return f"{'…'.join(values)} {unit}"

    return _SI_QUANTITY.sub(convert, text)


def _restate(number: str, factor: float) -> str:
    """``number`` (as printed) × ``factor`` in the fewest significant digits that stay within half a unit
    of the printed number's last digit (scaled): 0.5144 m/s, a printed 1 kn, reads "1", not "0.9999"."""
    x = float(number)
    y = x * factor
    digits = _significant(number)
    if x == 0 or not math.isfinite(y):
        return f"{y:.{digits}g}"
    tol = 0.5 * 10 ** (math.floor(math.log10(abs(x))) - digits + 1) * abs(factor)
    for k in range(1, digits + 1):
        text = f"{y:.{k}g}"
        if abs(float(text) - y) <= tol:
            if "e" in text and 1e-4 <= abs(y) < 1e15:  # "1e+01" → "10"
                text = f"{float(text):f}".rstrip("0").rstrip(".")
            return text
    return f"{y:.{digits}g}"


def _significant(number: str) -> int:
    """The significant digits a number was printed with (at least 3): its conversion keeps them."""
    mantissa = number.lstrip("+-").lower().split("e")[0].replace(".", "").lstrip("0")
    return max(3, len(mantissa))


#: a metric name's unit suffix → the unit it is reported in (the project's naming rule: a metric
#: whose name carries a unit is in that unit), longest suffixes first
METRIC_SUFFIX_UNITS = (("_per_min", "1/min"), ("_deg_s", "deg/s"), ("_rad_s", "rad/s"),
                       ("_mps", "m/s"), ("_kn", "kn"), ("_deg", "deg"), ("_rad", "rad"),
                       ("_min", "min"), ("_nm", "nm"), ("_pct", "%"), ("_hz", "Hz"), ("_s", "s"),
                       ("_m", "m"), ("_h", "h"), ("_n", "N"))


def metric_label(name: str) -> tuple[str, str | None]:
    """A metric key as a human title and its unit from its suffix: ``"settling_time_s"`` →
    ``("settling time", "s")``, ``"crosstrack_rms_after_leg1_nm"`` → ``("crosstrack rms after
    leg1", "nm")``; ``(name with spaces, None)`` for a key without a unit (a count, a fraction,
    a flag, or a figure of document 003 such as ``psi_E``)."""
    for suffix, unit in METRIC_SUFFIX_UNITS:
        if name.endswith(suffix) and len(name) > len(suffix):
            return name[: -len(suffix)].replace("_", " "), unit
    return name.replace("_", " "), None


def axis_label(name: str) -> str:
    """``"settling time [s]"`` for ``settling_time_s``; the title alone without a unit."""
    title, unit = metric_label(name)
    return f"{title} [{unit}]" if unit else title
