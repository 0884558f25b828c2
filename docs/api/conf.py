"""Sphinx configuration of the API reference, built from the docstrings.

Build (the ``docs`` extra installs Sphinx):  ``sphinx-build -W -b html docs/api docs/api/_build``
(``-W``: warnings are errors; ``tests/test_docs.py`` builds it so into a temporary directory).
"""

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))  # the source tree's package, also when it is not installed

project = "nambu_bch"
author = "the nambu_bch developers"
copyright = "2026, the nambu_bch developers"

extensions = ["sphinx.ext.autodoc", "sphinx.ext.napoleon"]
# numpy-style sections (Parameters, Returns, Examples, References) in the docstrings
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False
# types stay text (the docstrings' types are prose such as "System or model name", not cross-references) and the
# Attributes sections are fields of their class, not a second description of each dataclass field
napoleon_use_param = False
napoleon_use_ivar = True
autodoc_member_order = "bysource"
autodoc_typehints = "none"  # the docstrings say the types; signatures stay readable
autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": False}
# `x` in a docstring is code (the docstrings follow the numpy convention of single backticks for names)
default_role = "literal"
exclude_patterns = ["_build"]
html_theme = "alabaster"
html_static_path = []


def _version():
    try:
        from importlib.metadata import version

        return version("nambu_bch")
    except Exception:  # noqa: BLE001 -- an uninstalled source tree
        return "unknown"


release = version = _version()
