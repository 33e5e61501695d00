"""Sphinx configuration of the pdw documentation site (``make docs`` -> out/docs/html)."""
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

project = "pdw"
copyright = "2026 the pdw authors, MIT licence"
author = "pdw developers"
extensions = ["sphinx.ext.autodoc", "sphinx.ext.napoleon", "sphinx.ext.mathjax", "myst_parser",
              "sphinx_gallery.gen_gallery"]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "continuations", "figures/README.md", "gallery"]
napoleon_numpy_docstring = True
napoleon_google_docstring = False
napoleon_use_rtype = False
autodoc_member_order = "bysource"
autodoc_typehints = "none"
myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath"]
html_theme = "alabaster"
html_static_path = []
sphinx_gallery_conf = {
    "examples_dirs": "gallery",          # runnable scripts, executed at every build
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "abort_on_example_error": True,
    "matplotlib_animations": False,
}
# the Markdown pages link to source files of the repository (paths outside the site): those are
# links for readers of the repository, not cross-references
suppress_warnings = ["myst.xref_missing"]
