"""Every field of a scenario or vessel file has its unit, ``shipgnc show`` prints it, and the
reference pages docs/reference/*.md are the ones docs/make_reference.py writes from the schema."""

from __future__ import annotations

import typing

import pytest
import yaml
from typer.testing import CliRunner

from shipgnc.cli import app
from shipgnc.config_types import field_unit, sections
from shipgnc.scenarios.schema import Scenario
from shipgnc.vessels.config import CatalogueVesselConfig


def _holds_float(annotation) -> bool:
    return annotation is float or any(_holds_float(a) for a in typing.get_args(annotation))


@pytest.mark.parametrize("root", [Scenario, CatalogueVesselConfig])
def test_every_real_valued_field_has_a_unit(root):
    missing = [f"{cls.__name__}.{name}" for cls in sections(root)
               for name, field in cls.model_fields.items()
               if _holds_float(field.annotation) and field_unit(cls, name) is None]
    assert not missing


def test_a_unit_suffix_names_the_unit_and_a_misleading_one_is_overridden():
    from shipgnc.scenarios.sections import CourseControllerConfig, GNSSConfig, LOSConfig, SpeedLogConfig

    assert field_unit(GNSSConfig, "bias_time_constant_s") == "s"
    assert field_unit(LOSConfig, "lookahead") == "m"
    assert field_unit(CourseControllerConfig, "omega_n") == "rad/s"  # not "_n" → N
    assert field_unit(SpeedLogConfig, "noise_m_s") == "m/s"  # not "_s" → s


def test_show_prints_units_as_comments_and_reads_back():
    result = CliRunner().invoke(app, ["show", "boat-los"])
    assert result.exit_code == 0, result.output
    assert "  lookahead: 8.0  # m\n" in result.stdout
    assert "  dt: 0.05  # s\n" in result.stdout
    assert "  waypoints:  # m\n" in result.stdout
    assert yaml.safe_load(result.stdout)["guidance"]["lookahead"] == 8.0
    nautical = CliRunner().invoke(app, ["show", "zermelo-paper"]).stdout
    assert "  speed: 0.5  # kn\n" in nautical  # a route in units: nautical


def test_show_lists_a_catalogue_vessels_optional_fields_commented_out():
    args = ["show", "mariner-cst-heading", "--set", "vessel.model=linear-3dof",
            *[f"--set=vessel.{k}={v}" for k, v in
              {"L": 12, "B": 4, "T": 1.2, "Cb": 0.5, "speed_mps": 5.14}.items()]]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    text = result.stdout
    assert "  # rudder_rate_deg_s: null  # deg/s, optional\n" in text
    assert "  # R66: null  # m, optional\n" in text
    assert "# M: null" not in text  # matrices or main dimensions, not both
    assert "  L: 12.0  # m\n" in text
    assert "  T: 1.2  # m\n" in text  # a draught here, a Nomoto time constant [s] elsewhere
    # uncommented with a value, the line is a field the vessel takes
    edited = yaml.safe_load(text.replace("# rudder_rate_deg_s: null", "rudder_rate_deg_s: 15"))
    from shipgnc.scenarios.schema import validate

    assert validate(edited, "edited").vessel.rudder_rate_deg_s == 15


def _make_reference():
    import importlib.util
    from pathlib import Path

    docs = Path(__file__).resolve().parents[1] / "docs"
    spec = importlib.util.spec_from_file_location("make_reference", docs / "make_reference.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return docs / "reference", module


def test_reference_pages_are_the_ones_the_schema_writes():
    """The committed pages cannot drift from the schema: regenerate with
    ``python docs/make_reference.py``."""
    where, module = _make_reference()
    for name, page in module.pages().items():
        assert (where / name).read_text(encoding="utf-8") == page, \
            f"docs/reference/{name} is stale: run python docs/make_reference.py"


def test_reference_pages_list_every_field_with_its_unit():
    where, _ = _make_reference()
    fields = (where / "scenario-fields.md").read_text(encoding="utf-8")
    vessel = (where / "vessel-file.md").read_text(encoding="utf-8")
    for cls in sections(Scenario):
        assert f"\n## {cls.__name__}\n" in fields
        for name in cls.model_fields:
            unit = field_unit(cls, name) or ""
            assert f"| `{name}` |" in fields, (cls.__name__, name)
            if unit:
                assert any(line.startswith(f"| `{name}` |") and f"| {unit} |" in line
                           for line in fields.splitlines()), (cls.__name__, name, unit)
    assert "| `rudder_rate_deg_s` | number > 0 | `null` | deg/s |" in vessel
    assert "| `lookahead` | number > 0 | `8.0` | m |" in fields


def test_a_field_note_is_not_read_as_a_type_by_the_api_pages():
    """A ``#:`` note whose first line holds ``text: more`` is split by napoleon into a type
    ("text") and a description on the API pages: the notes say ``(null = ...)`` instead."""
    napoleon = pytest.importorskip("sphinx.ext.napoleon")
    from sphinx.ext.napoleon.docstring import NumpyDocstring

    _, module = _make_reference()
    config = napoleon.Config(napoleon_numpy_docstring=True)
    split = []
    for root in (Scenario, CatalogueVesselConfig):
        for cls in sections(root):
            for name, note in module.notes(cls, trailing_comments=False).items():
                parsed = str(NumpyDocstring(note.split("\n"), config, what="attribute", name=name))
                if ":type:" in parsed:
                    split.append(f"{cls.__name__}.{name}: {note.splitlines()[0]}")
    assert not split
