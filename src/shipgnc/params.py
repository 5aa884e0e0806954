"""What every vessel's parameter dataclass shares: a validated copy with changes, and its fields
as a dict (one place, instead of a copy in each model module)."""

from __future__ import annotations

from dataclasses import fields, replace

from shipgnc.errors import ConfigError


class Params:
    """Mixin of the frozen parameter dataclasses (``BoatParams``, ``MarinerParams``, ...)."""

    def with_(self, **changes):
        """A copy with some parameters changed, validated by the class's ``__post_init__``; an
        unknown name is a ConfigError listing the allowed ones."""
        known = {f.name for f in fields(self)}
        for key in changes:
            if key not in known:
                raise ConfigError(f"vessel.params.{key}: unknown parameter; allowed: "
                                  f"{', '.join(sorted(known))}")
        return replace(self, **changes)

    def as_dict(self) -> dict:
        """Every parameter by name (the values as stored: numbers, or arrays where a class allows)."""
        return {f.name: getattr(self, f.name) for f in fields(self)}
