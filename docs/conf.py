"""Sphinx configuration of the pdw documentation site (``make docs`` -> out/docs/html)."""
import pathlib
import re
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
# the types of numpydoc's Parameters are prose (shapes, units, choices: "array_like, shape (N, 8)"),
# not references: rendered as text, so that nitpicky checks the references only
napoleon_use_param = False
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

# Every `name` in single backquotes is a cross-reference (`default_role`), and a reference that
# does not resolve is a warning, which `make docs` (sphinx -W) turns into an error.
default_role = "py:obj"
nitpicky = True
# Not references (each listed with its reason):
nitpick_ignore = [
    ("py:class", "ndarray"),                  # numpy's (third party; no intersphinx offline)
    ("py:class", "scipy.sparse.csr_matrix"),  # scipy's (third party)
    ("py:class", "mapping"),                  # the typing sense: any Mapping
]
# the tokens of a numpydoc shape in a type field, "ndarray, shape (N, 8)": Sphinx's type parser
# reads N and 8 as class names; they are dimensions
nitpick_ignore_regex = [("py:class", r"[A-Za-z]|\d+|shape|len|n_\w+")]


def _plain_cython_signature(app, what, name, obj, options, signature, return_annotation):
    """Cython's embedded signatures carry C memoryview types (``const double[:, ::1] X``),
    which are no Python annotations: keep the parameter names."""
    if signature:
        signature = re.sub(r"(?:const\s+)?\w+\[[^\]]*\]\s+(\w+)", r"\1", signature)
    return signature, return_annotation


def setup(app):
    app.connect("autodoc-process-signature", _plain_cython_signature)
