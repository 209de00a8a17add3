"""Sphinx configuration of the adept_traj documentation.

Build (exactly what ``tests/test_docs.py`` and CI run; warnings are errors)::

    python -m sphinx -W --keep-going -b html docs docs/_build/html

The Markdown pages are read by myst-parser; the API reference (``api.md``) is generated from
the numpy-style docstrings by autodoc + napoleon. The build needs no network: there is no
intersphinx, and MathJax is only *linked* from its CDN (``mathjax_path`` is left at Sphinx's
default), so a reader's browser loads it when a page with formulas is opened.
"""

from __future__ import annotations

import adept_traj

# -- Project -----------------------------------------------------------------------------

project = "adept_traj"
author = "adept_traj developers"
copyright = "adept_traj developers, BSD-3-Clause"  # noqa: A001 (Sphinx's name)
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
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store"]

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
    "show-inheritance": True,
}
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
