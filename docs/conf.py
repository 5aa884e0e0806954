"""Sphinx configuration of the shipgnc documentation site (``sphinx-build -W docs site``)."""

import re
from importlib.metadata import version as _version

project = "shipgnc"
author = "shipgnc developers"
release = _version("shipgnc")
extensions = ["myst_parser", "sphinx.ext.autodoc", "sphinx.ext.napoleon",
              "sphinx.ext.mathjax", "sphinx_gallery.gen_gallery"]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "figures/*.py", "**/*.ipynb", "**/*.py", "**/*.zip"]
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

# The example gallery and the tutorial (sphinx-gallery): every script under examples/gallery and
# examples/tutorial runs at each build (run_stale_examples: no cached output is trusted), a
# failing script fails the build, and its figures are the ones the site shows.
sphinx_gallery_conf = {
    "examples_dirs": ["../examples/gallery", "../examples/tutorial"],
    "gallery_dirs": ["gallery", "tutorial"],
    "filename_pattern": r"/plot_",
    "abort_on_example_error": True,
    "run_stale_examples": True,
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "reset_modules": ("matplotlib",),
    "show_memory": False,
    "write_computation_times": True,
}
autodoc_inherit_docstrings = False

# Docstrings write mathematics in plain text (|x| for an absolute value, N_|r|r for a coefficient,
# (*batch, n) for a shape), which reStructuredText would read as substitutions, references and
# emphasis: escape them outside
# ``literals`` and :roles:`...` before autodoc parses them.
_LITERAL = re.compile(r"(``.*?``|:[a-z:]+:`[^`]*`)")


_SHAPE_STAR = re.compile(r"(\(|, )\*(?=[A-Za-z_])")  # (*batch, *t.shape)


# ``bias_std``² : a literal glued to a letter needs an escaped space after it
_LITERAL_GLUED = re.compile(r"(``[^`]+``)(?=[^\s.,;:!?)\]}'\"/\\–—-])")
_LONE_STRONG = re.compile(r"\*\*(?=[A-Za-z_])")                               # **params in a signature


def _escape_plain_maths(app, what, name, obj, options, lines):
    for i, line in enumerate(lines):
        parts = _LITERAL.split(line)
        out = []
        for j, part in enumerate(parts):
            if j % 2 == 0:
                part = _SHAPE_STAR.sub(r"\1\\*", part.replace("|", "\\|")).replace("_\\|", "\\_\\|")
                if part.count("**") % 2:                                   # not bold: **kwargs
                    part = _LONE_STRONG.sub(r"\\*\\*", part)
            out.append(part)
        lines[i] = _LITERAL_GLUED.sub(r"\1\\ ", "".join(out))


def setup(app):
    app.connect("autodoc-process-docstring", _escape_plain_maths)
