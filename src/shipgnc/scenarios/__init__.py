"""Scenarios as data: YAML files validated by a pydantic schema, a registry of built-ins."""
