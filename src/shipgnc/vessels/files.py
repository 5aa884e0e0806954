"""A vessel section read from a file or a mapping, validated once (the scenario schema's
:class:`~shipgnc.vessels.config.CatalogueVesselConfig`), for ``shipgnc trial --vessel FILE``,
the YAML ``shipgnc identify`` writes, and a scenario's ``vessel:`` section alike."""

from __future__ import annotations

from pathlib import Path

from shipgnc.errors import ConfigError


def vessel_config(data: object, source: str):
    """``{model: NAME, speed_mps: …, params…}`` (or ``{vessel: {…}}``) as a validated
    :class:`~shipgnc.vessels.config.CatalogueVesselConfig`; a one-line :class:`ConfigError`
    naming the field, the value and the rule otherwise."""
    from pydantic import ValidationError

    from shipgnc.config_types import format_validation_error
    from shipgnc.vessels.config import CatalogueVesselConfig

    if isinstance(data, dict) and isinstance(data.get("vessel"), dict):
        data = data["vessel"]
    if not isinstance(data, dict) or not isinstance(data.get("model"), str):
        raise ConfigError(f"{source}: expected a mapping 'vessel: {{model: NAME, ...}}' "
                          "(names: shipgnc vessels)")
    try:
        return CatalogueVesselConfig.model_validate(data)
    except ValidationError as exc:
        raise ConfigError(format_validation_error(exc, source).removeprefix("scenario ")) from None


def load_vessel_file(path: str | Path, source: str | None = None):
    """The vessel section of a YAML file (size-bounded, strict YAML as for scenarios)."""
    from shipgnc.user_files import read_text, read_yaml

    source = source or repr(str(path))
    return vessel_config(read_yaml(read_text(Path(path), source), source), source)
