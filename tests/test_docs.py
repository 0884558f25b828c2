"""The API reference (docs/api, Sphinx autodoc) builds from the docstrings with warnings as errors.

Built into pytest's ``tmp_path`` (``-W``: a docstring that Sphinx cannot read fails the test with its
file and line), and the public entry points appear in it.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("sphinx")

REPO = Path(__file__).resolve().parents[1]


def test_api_reference_builds_without_warnings(tmp_path):
    out = tmp_path / "html"
    env = {**os.environ, "NAMBU_BCH_CACHE": str(tmp_path / "cache"), "MPLBACKEND": "Agg",
           "PYTHONPATH": str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    run = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
                          "-d", str(tmp_path / "doctrees"), str(REPO / "docs" / "api"), str(out)],
                         capture_output=True, text=True, cwd=tmp_path, env=env, timeout=900)
    assert run.returncode == 0, run.stderr[-5000:]
    assert not run.stderr.strip(), run.stderr[-5000:]
    pages = {p.name: p.read_text() for p in out.glob("*.html")}
    assert "nambu_bch.shadow_hamiltonians" in pages["toplevel.html"]
    for name in ("ShadowFamily", "FISpan", "fi_route", "conserved_quantities", "NambuBCHError", "error_constant"):
        assert any(name in text for text in pages.values()), name


def test_every_api_page_is_in_the_index():
    pages = {p.stem for p in (REPO / "docs" / "api").glob("*.rst")} - {"index"}
    index = (REPO / "docs" / "api" / "index.rst").read_text()
    assert pages and all(f"   {p}\n" in index for p in pages)
