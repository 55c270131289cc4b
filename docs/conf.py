"""Sphinx configuration: the pydata theme, MyST pages and notebooks executed at build time
(myst-nb), and the API reference from the package's NumPy-style docstrings."""

from __future__ import annotations

import os

import collidium

project = "collidium"
author = "the collidium developers"
release = version = collidium.__version__

extensions = [
    "myst_nb",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
]

# Notebooks (MyST markdown with code cells) run on every build, so every figure in the docs is
# what the code gives today; a cell that raises fails the build.
nb_execution_mode = "force"
nb_execution_timeout = 600
nb_execution_raise_on_error = True
nb_merge_streams = True
myst_enable_extensions = ["dollarmath", "colon_fence"]
myst_heading_anchors = 3

napoleon_numpy_docstring = True
napoleon_google_docstring = False
napoleon_use_rtype = False
napoleon_use_ivar = True  # "Attributes" as fields: properties are documented once, as members
autodoc_typehints = "none"  # the docstrings give shapes and units; the signatures show types
autodoc_member_order = "bysource"
autosummary_generate = False
# A docstring's `name` is a cross-reference where it can be, plain code where it cannot.
default_role = "py:obj"
nitpicky = False

html_theme = "pydata_sphinx_theme"
html_title = "collidium"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
}
exclude_patterns = ["_build", "jupyter_execute", "**.ipynb_checkpoints"]
suppress_warnings = ["mystnb.unknown_mime_type"]

# The notebooks' runs stay short on the two cores of CI.
os.environ.setdefault("NUMBA_NUM_THREADS", "2")
