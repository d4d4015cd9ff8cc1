"""Sphinx configuration of the vibroimpact documentation (``make docs``).

Built with warnings as errors: a gallery script that fails, a dead cross-reference, a public
name without a docstring or a scenario key without a description stops the build. Nothing is
downloaded (no intersphinx): references outside the package are listed in ``nitpick_ignore``.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))
# The installed package (`pip install .` puts the compiled core there, not in the sources);
# a checkout without one builds from its own sources, where the compiled core must be beside
# them (as after `pip install -e .` or a copied _core*.so).
try:
    import vibroimpact
except ImportError:
    sys.path.insert(0, str(HERE.parent / "python"))
    import vibroimpact

project = "vibroimpact"
author = "the vibroimpact developers"
copyright = "the vibroimpact developers, MIT licence"  # noqa: A001
release = version = vibroimpact.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "sphinx_gallery.gen_gallery",
    "api_reference",
    "scenario_reference",
    "cli_reference",
    "run_output",
]

exclude_patterns = ["_build", "gallery_src/README.rst", "tutorials_src/README.rst"]
html_theme = "alabaster"
html_theme_options = {"description": vibroimpact.__doc__.splitlines()[0].split(": ", 1)[1]}
# MathJax is loaded by the reader's browser from its CDN; the build downloads nothing.
templates_path: list[str] = []
# Quotes stay as written: the scenario values they enclose are TOML strings.
smartquotes = False

nitpicky = True
# Types of other packages and typing's private aliases: documented elsewhere, not here.
nitpick_ignore_regex = [
    (r"py:.*", r"(numpy|np|npt|xarray|pandas|dask|matplotlib|collections|typing|pathlib)\..*"),
    (r"py:.*", r"(NDArray|ArrayLike|Axes|Figure|Path|Any|Callable|Iterable|Iterator|Mapping)"),
    (r"py:.*", r"(Sequence|Literal|Self|TypeAlias|ndarray|DataFrame|Dataset|Client)"),
    (r"py:class", r"(_FloatArray|_IntArray|_StrArray|_Array|_Number|_Signal|_Law)"),
    (r"py:class", r"(float|int|str|bool|complex|bytes|object|type|dict|list|tuple|set)"),
    (r"py:class", r"(Exception|ValueError|UserWarning|RuntimeError|KeyboardInterrupt)"),
    (r"py:meth", r"BaseException\..*"),
    (r"py:class", r"os\.PathLike"),
    # Internal classes that public signatures name (a base class, a return type): their
    # public faces are documented, they are not.
    (r"py:class", r"vibroimpact\.(model\.parts\.Part|scenario\.system\.SystemScenario)"),
    (r"py:class", r"vibroimpact\.analysis\.sweeps\._T|UsageError"),
]

autodoc_typehints = "description"
autodoc_member_order = "bysource"
autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": True}

sphinx_gallery_conf = {
    "examples_dirs": ["gallery_src", "tutorials_src"],
    "gallery_dirs": ["gallery", "tutorials"],
    "filename_pattern": r"/plot_",
    # A failing script fails the build (with -W and on its own).
    "abort_on_example_error": True,
    "only_warn_on_example_error": False,
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    # Every script starts from the repository root's examples/.
    "reset_modules": ("matplotlib",),
    "matplotlib_animations": False,
    "plot_gallery": "True",
}
