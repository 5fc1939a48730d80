"""Sphinx configuration of the wrist-env docs (MyST Markdown, autodoc API pages).

Build: `sphinx-build -W -b html docs docs/_build/html` (warnings are errors; the tests run it).
The results pages are rendered from the committed results files at build time (`_ext/results.py`).
"""

import inspect
import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent / "_ext"))

project = "wrist-env"
author = "the wrist-env developers"
copyright = "2026, the wrist-env developers"
extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.viewcode",
    "sphinx_gallery.gen_gallery",
    "results",
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}  # .rst: the pages sphinx-gallery writes
# speed/: tables the benchmark scripts write, included by solver.md; examples/: the gallery's sources, which
# sphinx-gallery turns into auto_examples/
exclude_patterns = ["_build", "speed", "examples"]
myst_heading_anchors = 4
myst_enable_extensions = ["dollarmath"]
smartquotes_action = "qe"  # quotes and ellipses; not dashes: a docstring's `--json` stays two hyphens
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_type_aliases = {"ArrayLike": "ArrayLike", "DTypeLike": "DTypeLike"}  # not numpy's expanded unions
autodoc_default_options = {"members": True, "undoc-members": False}
sphinx_gallery_conf = {
    # docs/examples/plot_*.py, each run at build time (small budgets), rendered with its output and figures
    # into docs/auto_examples/ (git-ignored). An example that raises fails the build.
    "examples_dirs": "examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "within_subsection_order": "FileNameSortKey",
    "abort_on_example_error": True,
    "download_all_examples": False,
    "remove_config_comments": True,
    "show_memory": False,
    "image_scrapers": ("matplotlib",),
}
napoleon_numpy_docstring = True
napoleon_google_docstring = False
napoleon_use_rtype = True  # the return type as its own field: autodoc's type hints then do not add it twice
napoleon_use_ivar = True  # an Attributes section as a field list: autodoc documents the attributes themselves
# Gymnasium's sections of an environment's docstring (`envs.wrist.WristEnv`), each rendered as a titled section
napoleon_custom_sections = [
    "Description",
    "Action Space",
    "Observation Space",
    "Rewards",
    "Starting State",
    "Episode End",
    ("Arguments", "Parameters"),  # rendered as Parameters, so autodoc adds the types to the same list
    "Info",
    "Version History",
]
html_theme = "furo"  # the maintained theme Gymnasium's docs use: a navigation sidebar, light and dark
html_title = "wrist-env"
html_theme_options = {"navigation_with_keys": True}


NUMPYDOC_SECTION = re.compile(r"^[A-Z][A-Za-z ]+\n-{3,}$", re.MULTILINE)
"""A numpydoc section header: a title line underlined with dashes (`Parameters`, `Returns`, `Action Space`)."""


def plain_docstrings(app, what, name, obj, options, lines):
    """Most of the code's docstrings are plain text (shapes, units, field lists), not reST: the summary line is
    shown as a paragraph and the rest verbatim, so `|z|`, `(V, 3) mm` and indented fields read as written.
    A docstring in numpydoc sections (the public entry points') is left to napoleon, which renders its
    sections as field lists and titled blocks."""
    if not lines:
        return
    doc = getattr(obj, "__doc__", None)
    if isinstance(doc, str) and NUMPYDOC_SECTION.search(inspect.cleandoc(doc)):
        return
    if what in ("attribute", "data", "property"):
        _undo_inline_type(lines)
    end = next((i for i, line in enumerate(lines) if not line.strip()), len(lines))
    summary = [line.replace("\\", "\\\\").replace("|", "\\|").replace("*", "\\*") for line in lines[:end]]
    rest = lines[end:]
    while rest and not rest[0].strip():
        rest = rest[1:]
    lines[:] = summary + (["", "::", ""] + ["    " + line for line in rest] + [""] if rest else [])


def _undo_inline_type(lines):
    """Napoleon reads the first line of an attribute's docstring as "type: description" and moves the part
    before the colon to a `:type:` line at the end ("Bool array of shape (11,): which ligaments are torn"
    became "which ligaments are torn ... :type: Bool array of shape (11,)"); a plain docstring is put back as
    written."""
    typed = [i for i, line in enumerate(lines) if line.startswith(":type: ")]
    if not typed or not lines:
        return
    i = typed[-1]
    kind = lines[i][len(":type: ") :]
    del lines[i]
    while lines and not lines[-1].strip():
        lines.pop()
    lines[0] = f"{kind}: {lines[0]}" if lines else kind


def setup(app):
    app.connect("autodoc-process-docstring", plain_docstrings)
