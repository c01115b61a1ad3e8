"""Sphinx configuration of dextar's docs (why Sphinx, numpydoc and furo: about.rst).

Build: ``.venv/bin/python -m sphinx -W --keep-going -b html docs docs/_build/html``.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent / "_ext"))

import dextar  # noqa: E402  (the installed package: the docs describe what is installed)

project = "dextar"
author = "the dextar developers"
project_copyright = "the dextar developers"
release = version = dextar.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "numpydoc",
    "dextar_docs",  # docs/_ext: the generated references, the API pages, the runs
]

root_doc = "index"
smartquotes = False  # "+-", "--" and quotes in code-like text stay as typed
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store"]

# the API reference (pages written by dextar_docs into reference/api/ at build time)
# numpydoc loads autosummary; nothing here asks it to generate pages
autosummary_generate = False
add_module_names = False  # (each page and section says its module)
autodoc_default_options = {"member-order": "bysource"}
autodoc_typehints = "signature"
# (preserving the defaults' source text and reading type comments parse every function's
# source again: a tenth of the build)
autodoc_preserve_defaults = False
autodoc_use_type_comments = False
numpydoc_show_class_members = False
numpydoc_xref_param_type = False

# runs beside the examples (dextar_docs runs every examples/* itself): name -> (argv, the
# output folder as the pages say it)
dextar_runs = {
    "getting-started": (["dextar", "run"], "dextar-out/"),
    "simulate-line": (["dextar", "simulate", "examples/line_si.toml"], "sim/"),
}

html_theme = "furo"
html_title = f"dextar {release}"
html_static_path = ["_static"]
html_css_files = ["dextar.css"]
html_show_sourcelink = False
