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
# emphasis: escape them before autodoc parses them, in running text only. A paragraph is
# scanned whole (a ``literal`` or a :role:`...` may run over a line break); ``literals``,
# :roles:`...`, literal blocks (after ``::``), directives' bodies (``.. math::``) and doctest
# blocks are left as written (there an escape would be printed as it is).
_LITERAL = re.compile(r"(``.+?``|:[a-z:]+:`[^`]*`)", re.S)
_SHAPE_STAR = re.compile(r"(\(|, )\*(?=[A-Za-z_])")  # (*batch, *t.shape)
_LONE_STRONG = re.compile(r"\*\*(?=[A-Za-z_])")                               # **params in a signature
#: what may follow a literal or a role without an escaped space (``bias_std``² needs one)
_AFTER_INLINE = set(" \t\n.,;:!?)]}'\"/\\–—-")


_DIRECTIVE = re.compile(r"\.\. ([a-z-]+)::")
#: directives whose body is shown as written (any other's body is running text)
_VERBATIM_DIRECTIVES = {"math", "code", "code-block", "sourcecode", "doctest", "testcode"}


def _indent(line):
    return len(line) - len(line.lstrip())


def _verbatim(lines):
    """Indices of the lines shown as written: literal blocks (the lines indented under a line
    ending in ``::``), the bodies of :data:`_VERBATIM_DIRECTIVES` and doctest blocks."""
    out, i = set(), 0
    while i < len(lines):
        text = lines[i].strip()
        directive = _DIRECTIVE.match(text)
        if directive.group(1) in _VERBATIM_DIRECTIVES if directive else text.endswith("::"):
            base, i = _indent(lines[i]), i + 1
            while i < len(lines) and (not lines[i].strip() or _indent(lines[i]) > base):
                out.add(i)
                i += 1
            continue
        if text.startswith(">>>"):
            while i < len(lines) and lines[i].strip():
                out.add(i)
                i += 1
            continue
        i += 1
    return out


def _escape_text(text):
    """One paragraph of running text, escaped outside its literals and roles."""
    parts = _LITERAL.split(text)
    for j in range(0, len(parts), 2):
        part = _SHAPE_STAR.sub(r"\1\\*", parts[j].replace("|", "\\|")).replace("_\\|", "\\_\\|")
        if part.count("**") % 2:                                           # not bold: **kwargs
            part = _LONE_STRONG.sub(r"\\*\\*", part)
        if j > 0 and part and part[0] not in _AFTER_INLINE:             # ``x``² → ``x``\ ²
            part = "\\ " + part
        parts[j] = part
    return "".join(parts)


def _escape_plain_maths(app, what, name, obj, options, lines):
    verbatim = _verbatim(lines)
    i = 0
    while i < len(lines):
        if i in verbatim or not lines[i].strip():
            i += 1
            continue
        j = i
        while j < len(lines) and j not in verbatim and lines[j].strip():
            j += 1
        lines[i:j] = _escape_text("\n".join(lines[i:j])).split("\n")
        i = j


def _no_pydantic_field_types(app, what, name, obj, options, signature, return_annotation):
    """A configuration section (a pydantic model) takes its fields as keyword arguments, whose
    annotations print as ``FieldInfo(...)`` reprs in the parameter list autodoc adds: leave that
    list out. Its fields are its documented attributes, and reference/scenario-fields.md lists
    each with type, range, default and unit."""
    from pydantic import BaseModel

    if what == "class" and isinstance(obj, type) and issubclass(obj, BaseModel):
        document = getattr(app.env, "current_document", None)
        annotations = (getattr(document, "autodoc_annotations", None) if document is not None
                       else app.env.temp_data.get("annotations"))
        if annotations is not None:
            annotations.pop(name, None)


def setup(app):
    app.connect("autodoc-process-docstring", _escape_plain_maths)
    app.connect("autodoc-process-signature", _no_pydantic_field_types)
