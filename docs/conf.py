"""Sphinx configuration of lfqt's documentation.

Build from the repository root (tests/test_docs.py builds it the same way):

    python -m sphinx -W --keep-going -b html docs docs/_build/html
"""
import os
import sys

# The documented lfqt is the one in this repository, installed or not.
ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
sys.path.insert(0, ROOT)

import lfqt  # noqa: E402

project = "lfqt"
author = "the lfqt developers"
copyright = "2026, the lfqt developers"
release = lfqt.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "numpydoc",
    "myst_parser",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build"]

# The API page lists its objects itself: autosummary writes no stub pages,
# and numpydoc adds no second table of a class's members.
autosummary_generate = False
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
# Signatures without annotations: the numpydoc Parameters give each type in
# words, and the annotations (npt.NDArray[...]) only repeat them at length.
autodoc_typehints = "none"
autodoc_member_order = "bysource"

myst_heading_anchors = 3
html_theme = "furo"
html_title = f"lfqt {release}"
