"""Sphinx configuration of the shipgnc documentation site (``sphinx-build -W docs site``)."""

import re
from importlib.metadata import version as _version

project = "shipgnc"
author = "shipgnc developers"
release = _version("shipgnc")
extensions = ["myst_parser", "sphinx.ext.autodoc", "sphinx.ext.napoleon",
              "sphinx.ext.mathjax"]
source_suffix = {".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "figures/*.py"]
myst_enable_extensions = ["colon_fence", "dollarmath"]
myst_heading_anchors = 3
autodoc_default_options = {"members": True, "show-inheritance": False}
autodoc_member_order = "bysource"
autodoc_typehints = "description"
napoleon_numpy_docstring = True
napoleon_google_docstring = False
html_theme = "furo"
html_title = "shipgnc"
suppress_warnings = ["myst.header"]
autodoc_inherit_docstrings = False

# Docstrings write mathematics in plain text (|x| for an absolute value, N_|r|r for a coefficient,
# (*batch, n) for a shape), which reStructuredText would read as substitutions, references and
# emphasis: escape them outside
# ``literals`` and :roles:`...` before autodoc parses them.
_LITERAL = re.compile(r"(``.*?``|:[a-z:]+:`[^`]*`)")


_SHAPE_STAR = re.compile(r"(\(|, )\*(?=[A-Za-z_])")  # (*batch, *t.shape)


def _escape_plain_maths(app, what, name, obj, options, lines):
    for i, line in enumerate(lines):
        parts = _LITERAL.split(line)
        lines[i] = "".join(part if j % 2 else _SHAPE_STAR.sub(r"\1\\*", part.replace("|", "\\|"))
                           .replace("_\\|", "\\_\\|") for j, part in enumerate(parts))


def setup(app):
    app.connect("autodoc-process-docstring", _escape_plain_maths)
