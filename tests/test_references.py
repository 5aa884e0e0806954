"""References resolve inside the repository: every ``note NNN-X`` anchor cited in the code,
the docs, the examples or the README is defined on its document's page; nothing points at a file
outside the repository (the project's former ``spec/`` reconstructions, ``../shared``); every
document page cites its source document; every public module has an API page."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
PAGES = {"000": "000_mariner_tracking", "001": "001_vectored_thrust_boat", "002": "002_zermelo_routing",
         "003": "003_cybership_autopilot", "004": "004_catamaran_fsm"}

#: an anchor of the notes on a document: 001-1.10, 002-2.9.6, 000-A4, 002-Z1, 002-F2, 004-S3
ANCHOR = re.compile(r"(?<![\w.-])(00[0-4]-(?:[0-4]\.\d{1,2}(?:\.\d)?|[A-Z]\d{1,2}))(?![\w]|\.\d)")
LABEL = re.compile(r"^\((00[0-4]-[^)\s]+)\)=\s*$", re.M)
#: references to files that are not in the repository
OUTSIDE = re.compile(
    r"\b[Ss]pecs?(?:'s)?\s+(?:\d{3}\b|§|[ABCFSZ]\d|table\b|section\b|check\b|\d\.\d)"  # spec 001 §1.10, spec B8
    r"|\b[Ss]pec/|\.\./shared\b|\bshared/(?:spec|seeds)\b|/work/shared\b|\bseeds/\d{3}"
    r"|\b[Tt]he spec(?:'s)?\b(?!\s+strings?\b)"
    r"|\b[Dd]ocument 00[0-4](?:'s)?\s+§\s?[0-4]\.\d")  # the notes' numbers are not the document's
MD_LINK = re.compile(r"\]\(([^)\s]+)\)")


def _files():
    for base, suffixes in ((ROOT / "src", {".py", ".yaml", ".yml"}), (DOCS, {".md", ".py", ".rst"}),
                           (ROOT / "examples", {".py", ".rst", ".md"})):
        for path in sorted(base.rglob("*")):
            rel = path.relative_to(ROOT).parts
            if (path.suffix in suffixes and path.is_file() and "__pycache__" not in rel
                    and not any(part.endswith(".egg-info") for part in rel)
                    and rel[:2] not in (("docs", "gallery"), ("docs", "tutorial"), ("docs", "_build"))):
                yield path
    yield ROOT / "README.md"


def defined_anchors() -> dict[str, Path]:
    anchors = {}
    for page in sorted(DOCS.rglob("*.md")):
        for label in LABEL.findall(page.read_text(encoding="utf-8")):
            assert label not in anchors, f"anchor {label} defined twice ({anchors.get(label)}, {page})"
            anchors[label] = page
    return anchors


def test_every_cited_anchor_is_defined_on_its_documents_page():
    anchors = defined_anchors()
    assert len(anchors) > 100, "the document pages define their notes' anchors"
    for label, page in anchors.items():
        assert page.stem == PAGES[label[:3]], f"anchor {label} is on {page.name}, not on document {label[:3]}'s page"
    dangling = []
    for path in _files():
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            for anchor in ANCHOR.findall(line):
                if anchor not in anchors:
                    dangling.append(f"{path.relative_to(ROOT)}:{n}: {anchor}")
    assert not dangling, "anchors no page defines:\n" + "\n".join(dangling)


def test_no_reference_points_outside_the_repository():
    found = []
    for path in _files():
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            m = OUTSIDE.search(line)
            if m:
                found.append(f"{path.relative_to(ROOT)}:{n}: {m.group(0)!r} in {line.strip()[:120]!r}")
    assert not found, "references to files outside the repository:\n" + "\n".join(found)


def test_relative_links_of_the_pages_stay_in_the_repository():
    bad = []
    for page in [*sorted(DOCS.rglob("*.md")), ROOT / "README.md"]:
        if page.relative_to(DOCS if page.is_relative_to(DOCS) else ROOT).parts[:1] in (("gallery",), ("tutorial",)):
            continue
        for target in MD_LINK.findall(page.read_text(encoding="utf-8")):
            if target.startswith(("http://", "https://", "mailto:", "#", "project:", "path:")):
                continue
            path = (page.parent / target.split("#", 1)[0]).resolve()
            generated = path.relative_to(DOCS).parts if path.is_relative_to(DOCS) else ()
            if generated[:1] in (("gallery",), ("tutorial",)):  # sphinx-gallery's pages of examples/
                name = generated[-1]
                path = ROOT / "examples" / generated[0] / ("GALLERY_HEADER.rst" if name == "index" else f"{name}.py")
            if not path.is_relative_to(ROOT) or not path.exists():
                bad.append(f"{page.relative_to(ROOT)}: {target}")
    assert not bad, "links that leave the repository or point nowhere:\n" + "\n".join(bad)


@pytest.mark.parametrize("doc", sorted(PAGES))
def test_each_document_page_cites_its_source_and_defines_its_notes(doc):
    text = (DOCS / f"{PAGES[doc]}.md").read_text(encoding="utf-8")
    assert f"({doc}-notes)=" in text and "**Source.**" in text and "**Source document:**" in text
    labels = set(LABEL.findall(text))
    ambiguities = {"000": "A", "001": "A", "002": "Z", "003": "B", "004": "C"}[doc]
    assert any(label.startswith(f"{doc}-{ambiguities}") for label in labels), "the ambiguities have anchors"


#: modules with nothing a user calls: the command line's plumbing and generated-loop templates
INTERNAL = re.compile(r"(^shipgnc\.__main__$|^shipgnc\.cli(_\w+)?$|_template$|\.kernels$|^shipgnc\.sim\.compiled$"
                      r"|^shipgnc\.scenarios\.builtin$|^shipgnc\.environment\.wave_kernel$)")


def test_every_public_module_is_on_an_api_page():
    documented = set()
    for page in (DOCS / "api").glob("*.md"):
        documented |= set(re.findall(r"automodule:: ([\w.]+)", page.read_text(encoding="utf-8")))
    missing = []
    for path in sorted((ROOT / "src" / "shipgnc").rglob("*.py")):
        rel = path.relative_to(ROOT / "src").with_suffix("")
        parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
        if "__pycache__" in parts or any(p.startswith("_") and p != "__init__" for p in parts[1:]):
            continue
        name = ".".join(parts)
        is_package = rel.name == "__init__"
        if INTERNAL.search(name) or name in documented:
            continue
        if is_package and " as _moved" in path.read_text(encoding="utf-8"):
            continue  # an old name of a module that moved (tests/test_import_layers.py)
        if is_package and any(m.startswith(name + ".") for m in documented):
            continue  # a package whose modules are documented one by one
        missing.append(name)
    assert not missing, "public modules on no API page (docs/api/*.md):\n" + "\n".join(missing)
