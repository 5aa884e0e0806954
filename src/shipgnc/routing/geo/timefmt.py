"""UTC instants as seconds since 1970-01-01T00:00Z and ISO 8601 text."""

from __future__ import annotations

import datetime as _dt

from shipgnc.errors import ConfigError

UTC = _dt.timezone.utc


def parse_iso(text: str, name: str = "--depart") -> float:
    """Seconds since the epoch of an ISO 8601 time; a time without an offset is UTC."""
    s = text.strip()
    if s.endswith(("Z", "z")):
        s = s[:-1] + "+00:00"
    try:
        t = _dt.datetime.fromisoformat(s)
    except ValueError:
        raise ConfigError(f"{name} = {text!r}: expected seconds/hours or an ISO 8601 UTC time such as "
                          "2026-06-01T06:00Z") from None
    if t.tzinfo is None:
        t = t.replace(tzinfo=UTC)
    return t.timestamp()


#: the instants ISO 8601 text can name here: 0001-01-01T00:00Z … 9999-12-31T23:59:59Z [s since the epoch]
FIRST_S, LAST_S = -62_135_596_800.0, 253_402_300_799.0


def in_range(seconds: float) -> bool:
    return FIRST_S <= float(seconds) <= LAST_S


def iso(seconds: float) -> str:
    """ISO 8601 UTC text (whole seconds, 'Z'); an instant beyond the years 1–9999 as seconds since the
    epoch (it has no calendar date)."""
    if not in_range(seconds):
        return f"{float(seconds):.6g} s after 1970-01-01T00:00Z"
    t = _dt.datetime.fromtimestamp(round(float(seconds)), tz=UTC)
    return t.strftime("%Y-%m-%dT%H:%M:%SZ")


def to_datetime(seconds: float) -> _dt.datetime:
    return _dt.datetime.fromtimestamp(round(float(seconds)), tz=UTC)
