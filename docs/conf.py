"""Sphinx configuration of the adept_traj documentation.

Build (exactly what ``tests/docs/test_docs.py`` and CI run; warnings are errors)::

    python -m sphinx -W --keep-going -b html docs docs/_build/html

The Markdown pages are read by myst-parser; the API reference (``api.md``) is generated
from the docstrings (numpy sections, RST ``.. math::``) by autodoc + napoleon.
The build needs no network: there is no intersphinx, and MathJax is only *linked* from its
CDN (``mathjax_path`` is left at Sphinx's default), so a reader's browser loads it when a
page with formulas is opened.
"""

from __future__ import annotations

import re

import adept_traj

# -- Project -----------------------------------------------------------------------------

project = "adept_traj"
author = "adept_traj developers"
copyright = "adept_traj developers, BSD-3-Clause"
version = release = adept_traj.__version__

# -- General -----------------------------------------------------------------------------

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
# data/: run outputs kept as evidence (e.g. the seed study), not pages
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "data"]

# Unresolved references to objects of other packages (numpy, pymoo, coal, pinocchio: no
# intersphinx, which would need the network) are rendered as plain text, not reported.
# References inside the project are still checked by -W (ambiguous targets, bad roles, ...).
nitpicky = False

# -- Markdown (myst-parser) --------------------------------------------------------------

myst_enable_extensions = [
    "dollarmath",  # $...$ and $$...$$ in the pages
    "amsmath",  # \begin{align} ... environments
]
# Anchors for "#section" links between pages (h1-h3).
myst_heading_anchors = 3

# -- API reference (autodoc + napoleon) --------------------------------------------------

# The docstrings use numpy sections ("Parameters" + dashes) only (tests/package/test_style.py fails
# on a Google-style "Args:" section): napoleon's Google parser is off.
napoleon_google_docstring = False
napoleon_numpy_docstring = True
# "Attributes" sections become :ivar: fields of their class, not separate object
# descriptions: frozen dataclasses list their fields there, and autodoc documents the
# fields too, which would otherwise describe each attribute twice.
napoleon_use_ivar = True
napoleon_use_rtype = False

autodoc_default_options = {
    "members": True,  # the names in each module's __all__
    "member-order": "bysource",
}
# "show-inheritance" is set per module in api.md where the bases say something (errors,
# pymoo subclasses); elsewhere it would print "Bases: object" under every dataclass.
autodoc_typehints = "signature"
autodoc_typehints_format = "short"
autodoc_class_signature = "mixed"
autodoc_preserve_defaults = True

# -- HTML ----------------------------------------------------------------------------------

# Sphinx's built-in theme: no extra dependency.
html_theme = "alabaster"
html_title = f"adept_traj {release}"
html_theme_options = {
    "description": "Multi-objective, collision-free trajectory planning for industrial robots",
    "fixed_sidebar": True,
    "page_width": "1100px",
    "sidebar_width": "240px",
}
html_static_path: list[str] = []
html_show_sourcelink = False


# -- The project's numpy-section convention ------------------------------------------------
#
# In numpy sections the project writes ``name: description`` (no space before the colon:
# a description, usually starting with a shape such as ``(n, m)``) and keeps
# ``name : type`` (spaced colon) for real types; "Returns" is often one prose paragraph.
# Napoleon's numpy parser would read such a description as a *type* (and cross-reference
# every word of it) and each prose line of "Returns" as another return value. This hook runs
# before napoleon and rewrites those two forms into what napoleon reads as intended:
# ``name`` + indented description, and a ``:returns:`` field.

_FIELD_SECTIONS = {
    "parameters",
    "other parameters",
    "attributes",
    "raises",
    "warns",
    "keyword arguments",
}
_RETURN_SECTIONS = {"returns", "yields"}
_NAMES_COLON_TEXT = re.compile(
    r"^(?P<names>\*{0,2}[A-Za-z_]\w*(?:\s*,\s*\*{0,2}[A-Za-z_]\w*)*):(?!:)\s+(?P<text>\S.*)$"
)

# Any other field line: ``name``, ``name : type``, ``*args``, ``Error`` (Raises).
_FIELD_START = re.compile(r"^\*{0,2}[\w.]+(?:\s*,\s*\*{0,2}\w+)*(?:\s+:.*)?$")


def _indent(line: str) -> int:
    return len(line) - len(line.lstrip())


def _is_header(lines: list[str], i: int) -> bool:
    if i + 1 >= len(lines) or not lines[i].strip():
        return False
    rule = lines[i + 1].strip()
    return len(rule) >= 3 and set(rule) == {"-"} and _indent(lines[i + 1]) == _indent(lines[i])


def _project_numpy_sections(app, what, name, obj, options, lines: list[str]) -> None:
    out: list[str] = []
    i, n = 0, len(lines)
    while i < n:
        if not _is_header(lines, i):
            out.append(lines[i])
            i += 1
            continue
        title = lines[i].strip().lower()
        base = _indent(lines[i])
        end = i + 2
        while end < n and not _is_header(lines, end):
            end += 1
        body = lines[i + 2 : end]
        if title in _FIELD_SECTIONS:
            out += lines[i : i + 2]
            previous = lines[i + 1]
            for line in body:
                m = _NAMES_COLON_TEXT.match(line.strip())
                at_base = _indent(line) == base and line.strip()
                if m and at_base:
                    pad = " " * base
                    out += [pad + m["names"], pad + "    " + m["text"]]
                elif at_base and not previous.strip() and not _FIELD_START.match(line.strip()):
                    # A paragraph after the fields: end the section first (two blank lines).
                    out += ["", line]
                else:
                    out.append(line)
                previous = line
        elif title in _RETURN_SECTIONS and _is_prose(body, base):
            # One description without a type line: a plain ":returns:" field, after two
            # blank lines (napoleon's end of the previous section).
            body = list(body)
            while not body[0].strip():
                body.pop(0)
            while not body[-1].strip():
                body.pop()
            pad = " " * base
            first, *rest = body
            out += ["", "", pad + ":returns: " + first.strip()]
            out += [(pad + "    " + r[base:]) if r.strip() else "" for r in rest]
            out.append("")
        else:
            out += lines[i:end]
        i = end
    lines[:] = out


def _is_prose(body: list[str], base: int) -> bool:
    """True if a Returns body is not ``type`` + indented description(s)."""
    text = [line for line in body if line.strip()]
    if not text:
        return False
    if len(text) == 1:
        # A lone line is a description unless it is a bare (dotted) type name.
        return not re.fullmatch(r"[\w.]+", text[0].strip())
    return _indent(text[1]) <= base


# Napoleon turns the first line ``(nq,) bool: text`` of a property's docstring into a
# ``:type:`` field, whose words Sphinx cross-references one by one (``nq`` names several
# attributes, hence "more than one target" warnings). The shapes are not references: show
# the same field as plain text.
def _plain_property_type(app, what, name, obj, options, lines: list[str]) -> None:
    if what in ("property", "attribute", "data"):
        for k, line in enumerate(lines):
            if line.startswith(":type: "):
                lines[k] = ":Type: " + line[len(":type: ") :]


# ``q_min, q_max: ...`` in an "Attributes" section becomes ``:ivar q_min, q_max:``, which
# Sphinx reads as the variable ``q_max`` of type ``q_min,``. One field per name instead.
_MULTI_IVAR = re.compile(r"^:(?P<kind>ivar|vartype) (?P<names>\w+(?:, \w+)+):(?P<rest>.*)$")


def _split_multi_name_ivars(app, what, name, obj, options, lines: list[str]) -> None:
    out: list[str] = []
    k = 0
    while k < len(lines):
        m = _MULTI_IVAR.match(lines[k])
        if not m:
            out.append(lines[k])
            k += 1
            continue
        end = k + 1
        while end < len(lines) and lines[end].startswith(" ") and lines[end].strip():
            end += 1
        continuation = [c.strip() for c in lines[k + 1 : end]]
        for one in m["names"].split(", "):
            out.append(f":{m['kind']} {one}:{m['rest']}")
            out += ["   " + c for c in continuation]
        k = end
    lines[:] = out


def _public_bases(app, name, obj, options, bases: list) -> None:
    """Show a private base class as its own bases."""
    public: list = []
    for base in bases:
        if getattr(base, "__name__", "").startswith("_"):
            public += [b for b in base.__bases__ if b is not object]
        else:
            public.append(base)
    bases[:] = public


def setup(app):
    # Priorities: lower runs first; napoleon's hook has the default 500.
    app.connect("autodoc-process-docstring", _project_numpy_sections, priority=400)
    app.connect("autodoc-process-docstring", _plain_property_type, priority=600)
    app.connect("autodoc-process-docstring", _split_multi_name_ivars, priority=600)
    app.connect("autodoc-process-bases", _public_bases)
    return {"parallel_read_safe": True}
