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


def iso(seconds: float) -> str:
    """ISO 8601 UTC text (whole seconds, 'Z')."""
    t = _dt.datetime.fromtimestamp(round(float(seconds)), tz=UTC)
    return t.strftime("%Y-%m-%dT%H:%M:%SZ")


def to_datetime(seconds: float) -> _dt.datetime:
    return _dt.datetime.fromtimestamp(round(float(seconds)), tz=UTC)
