"""The API pages' docstrings as autodoc hands them to reStructuredText: napoleon, then the
escaping hook of ``docs/conf.py``, then docutils' own parser (no Sphinx build). A reader must see
the plain-text mathematics as written: no escape printed (``\\ ``, ``\\|``, ``\\_``), no raw
``:func:`` role, no substitution or role that docutils could not resolve."""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import re
from pathlib import Path

import pytest

docutils = pytest.importorskip("docutils")
pytest.importorskip("sphinx")

from docutils import frontend, nodes, utils  # noqa: E402
from docutils.parsers.rst import Parser, roles  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
AUTOMODULE = re.compile(r"^\.\. automodule:: ([\w.]+)", re.M)
SPHINX_ROLES = ("func", "class", "meth", "mod", "attr", "data", "obj", "exc", "doc", "ref", "term",
                "py:func", "py:class", "py:meth", "py:mod", "py:attr", "py:data", "py:obj", "numref",
                "eq", "file", "envvar", "program", "option", "command", "kbd")
PRINTED_ESCAPES = ("\\ ", "\\|", "\\_", "\\*")


def _conf():
    spec = importlib.util.spec_from_file_location("docs_conf", ROOT / "docs" / "conf.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _documented():
    """(name, what, object) of every module on an API page and the public members it defines."""
    seen = set()
    for page in sorted((ROOT / "docs" / "api").glob("*.md")):
        for modname in AUTOMODULE.findall(page.read_text(encoding="utf-8")):
            if modname in seen:
                continue
            seen.add(modname)
            module = importlib.import_module(modname)
            yield modname, "module", module
            for name, obj in vars(module).items():
                if name.startswith("_") or getattr(obj, "__module__", None) != modname:
                    continue
                if inspect.isclass(obj):
                    yield f"{modname}.{name}", "class", obj
                    for attr, member in vars(obj).items():
                        if not attr.startswith("_") and (inspect.isfunction(member)
                                                         or isinstance(member, property)):
                            yield f"{modname}.{name}.{attr}", "method", member
                elif inspect.isfunction(obj):
                    yield f"{modname}.{name}", "function", obj


@pytest.fixture(scope="module")
def parsed():
    """Each docstring's doctree, as the site's build would parse it."""
    from sphinx.ext.napoleon import Config
    from sphinx.ext.napoleon.docstring import NumpyDocstring
    from sphinx.util.docstrings import prepare_docstring

    for role in SPHINX_ROLES:
        roles.register_generic_role(role, nodes.literal)
    hook = _conf()._escape_plain_maths
    config = Config(napoleon_numpy_docstring=True, napoleon_google_docstring=False)
    parser = Parser()
    settings = frontend.get_default_settings(Parser)
    settings.report_level = 5
    settings.halt_level = 5
    out = []
    for name, what, obj in _documented():
        doc = inspect.getdoc(obj)
        if not doc:
            continue
        lines = NumpyDocstring(prepare_docstring(doc), config, what=what, name=name, obj=obj).lines()
        hook(None, what, name, obj, {}, lines)
        document = utils.new_document(name, settings)
        parser.parse("\n".join(lines), document)
        out.append((name, doc, document))
    assert len(out) > 500
    return out


def test_no_escape_is_printed(parsed):
    bad = []
    for name, doc, document in parsed:
        for node in document.findall(nodes.Text):
            if node.parent is not None and isinstance(node.parent, (nodes.math, nodes.math_block)):
                continue  # LaTeX: checked below
            text = node.astext()
            for escape in PRINTED_ESCAPES:
                if escape in text and escape not in doc:
                    bad.append(f"{name}: {escape!r} in {text[:80]!r}")
        for node in document.findall(lambda n: isinstance(n, (nodes.math, nodes.math_block))):
            if node.astext().count("\\|") > doc.count("\\|"):
                bad.append(f"{name}: an escaped '|' in the equation {node.astext()[:80]!r}")
    assert not bad, f"{len(bad)} printed escapes, e.g.\n" + "\n".join(bad[:15])


def test_no_raw_role_or_unresolved_markup(parsed):
    bad = []
    for name, _, document in parsed:
        for node in document.findall(nodes.problematic):
            bad.append(f"{name}: {node.astext()[:80]!r}")
        for node in document.findall(nodes.Text):
            if re.search(r":[a-z]+:`", node.astext()):
                bad.append(f"{name}: raw role in {node.astext()[:80]!r}")
    assert not bad, f"{len(bad)} problems, e.g.\n" + "\n".join(bad[:15])


def test_the_hook_keeps_literal_blocks_and_escapes_running_text():
    """Closed cases of the rules: a running-text |x| and N_|r|r are escaped, a literal glued to a
    letter gets an escaped space, a literal running over a line break is left whole, and a
    literal block and a math directive are left as written."""
    hook = _conf()._escape_plain_maths
    lines = ["The damping N_|r|r |r| r and ``x``² with ``{a: 1 |",
             "b: 2}`` over a break, ``y`` (a literal) and ``z``.", "", "Equations::", "",
             "    N_|r|r |r| r", "", ".. math::", "", "    \\|x\\| = |x|", "", "After |y|."]
    hook(None, "function", "f", None, {}, lines)
    assert lines[0] == "The damping N\\_\\|r\\|r \\|r\\| r and ``x``\\ ² with ``{a: 1 |"
    assert lines[1] == "b: 2}`` over a break, ``y`` (a literal) and ``z``."
    assert lines[5] == "    N_|r|r |r| r" and lines[9] == "    \\|x\\| = |x|"
    assert lines[11] == "After \\|y\\|."
