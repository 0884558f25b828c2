"""Packaging: the wheel and the sdist build, pass ``twine check``, hold what they should, and the wheel runs.

The source tree is copied into pytest's ``tmp_path`` first (building writes ``*.egg-info`` and ``build/``
beside the sources), and everything is built and installed there: ``python -m build --no-isolation``
(the ``test`` extra installs ``build``, ``twine`` and the build backend), the wheel installed with
``pip --target`` into ``tmp_path`` and run from there with the README's first command.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tarfile
import tomllib
import zipfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((REPO / "pyproject.toml").read_text())
VERSION = PYPROJECT["project"]["version"]
#: What a build must not copy: version control, caches, environments, earlier builds.
IGNORE = shutil.ignore_patterns(".git", "__pycache__", "*.egg-info", "build", "dist", ".venv", "_build", ".pytest_cache",
                                ".hypothesis", "*.pyc")

pytest.importorskip("build")
pytest.importorskip("twine")


@pytest.fixture(scope="module")
def dist(tmp_path_factory) -> Path:
    """The wheel and sdist of a copy of the source tree, built without network access."""
    root = tmp_path_factory.mktemp("packaging")
    src = root / "src"
    shutil.copytree(REPO, src, ignore=IGNORE)
    out = root / "dist"
    run = subprocess.run([sys.executable, "-m", "build", "--no-isolation", "--outdir", str(out), str(src)],
                         capture_output=True, text=True, cwd=root, timeout=600)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    return out


def _one(dist: Path, pattern: str) -> Path:
    found = sorted(dist.glob(pattern))
    assert len(found) == 1, found
    return found[0]


def test_wheel_and_sdist_pass_twine_check(dist):
    files = [_one(dist, "*.whl"), _one(dist, "*.tar.gz")]
    run = subprocess.run([sys.executable, "-m", "twine", "check", "--strict", *map(str, files)],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    assert run.stdout.count("PASSED") == 2


def test_wheel_holds_only_the_package(dist):
    """Every module of nambu_bch/ and nothing else (no tests, docs, notebooks, tools); the licence in the metadata."""
    names = zipfile.ZipFile(_one(dist, "*.whl")).namelist()
    info = f"nambu_bch-{VERSION}.dist-info/"
    assert {n.split("/")[0] for n in names} == {"nambu_bch", info.rstrip("/")}
    package = {n for n in names if n.startswith("nambu_bch/")}
    sources = {p.relative_to(REPO).as_posix() for p in (REPO / "nambu_bch").rglob("*")
               if p.is_file() and "__pycache__" not in p.parts and p.suffix != ".pyc"}
    assert package == sources  # the package has no data files; a new one must be declared to be shipped
    assert f"{info}licenses/LICENSE" in names
    meta = zipfile.ZipFile(_one(dist, "*.whl")).read(f"{info}METADATA").decode()
    assert f"Version: {VERSION}" in meta and "License-Expression: MIT" in meta
    assert "Provides-Extra: jupyter" in meta and "Provides-Extra: test" in meta


def test_sdist_holds_the_sources_and_the_licence(dist):
    names = tarfile.open(_one(dist, "*.tar.gz")).getnames()
    top = f"nambu_bch-{VERSION}"
    for needed in ("pyproject.toml", "README.md", "LICENSE", "nambu_bch/__init__.py", "nambu_bch/cli/_main.py"):
        assert f"{top}/{needed}" in names, needed


def test_installed_wheel_runs_the_readme_first_command(dist, tmp_path):
    """``pip install`` of the wheel (into tmp_path, dependencies from this environment), then ``nambu-bch shadow``."""
    site = tmp_path / "site"
    run = subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "--no-index", "--target", str(site),
                          str(_one(dist, "*.whl"))], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    env = {**os.environ, "PYTHONPATH": str(site), "NAMBU_BCH_CACHE": str(tmp_path / "cache"), "MPLBACKEND": "Agg"}
    code = "import nambu_bch, sys; from nambu_bch.cli import main; print(nambu_bch.__file__); sys.exit(main(['shadow']))"
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, env=env, timeout=600)
    assert run.returncode == 0, run.stderr
    assert run.stdout.splitlines()[0].startswith(str(site))  # the installed copy, not the source tree
    assert r"H_{S}" in run.stdout and r"\alpha" in run.stdout  # Eqs. (SH12321c), (SG12321c) as LaTeX


def test_one_version():
    """pyproject.toml's version is the one source: the package, CITATION.cff and the changelog's latest release agree."""
    from importlib.metadata import version

    import nambu_bch

    assert nambu_bch.__version__ == version("nambu_bch") == VERSION
    assert re.search(rf'^version: "{re.escape(VERSION)}"$', (REPO / "CITATION.cff").read_text(), re.M)
    released = re.findall(r"^## \[(\d[^\]]*)\]", (REPO / "CHANGELOG.md").read_text(), re.M)
    assert released and released[0] == VERSION


def test_citation_cff_cites_the_package_and_the_paper():
    text = (REPO / "CITATION.cff").read_text()
    assert "cff-version: 1.2.0" in text and "type: software" in text and "license: MIT" in text
    assert "preferred-citation:" in text and "Shadow Hamiltonians of structure-preserving integrators for Nambu mechanics" in text
    assert "family-names: Horikoshi" in text
    licence = (REPO / "LICENSE").read_text()
    assert licence.startswith("MIT License") and "the nambu_bch developers" in licence
    assert PYPROJECT["project"]["license"] == "MIT"
