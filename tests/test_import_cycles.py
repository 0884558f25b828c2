"""The package's import graph is a DAG, imports inside functions included (tools/import_cycles.py)."""

import importlib.util
import sys
from pathlib import Path

import shared_results as shared

ROOT = Path(__file__).resolve().parents[1]


def _tool():
    spec = importlib.util.spec_from_file_location("_import_cycles_tool", ROOT / "tools" / "import_cycles.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def test_package_has_no_import_cycle():
    tool = _tool()
    package = ROOT / "nambu_bch"
    # the ASTs the package's other source scans read too (test_text_door, test_flint_seam), parsed once per worker
    assert tool.cycles(tool.graph(package, trees=shared.package_trees(str(package)))) == []


def test_a_deferred_import_still_closes_a_cycle(tmp_path):
    # a function-level import that exists to break a cycle is counted: it hides the cycle, it does not remove it
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "a.py").write_text("from .b import g\n\ndef f():\n    return g()\n")
    (package / "b.py").write_text("def g():\n    from .a import f\n    return f\n")
    tool = _tool()
    assert tool.cycles(tool.graph(package)) == [["pkg.a", "pkg.b"]]
    assert tool.cycles(tool.graph(package, deferred=False)) == []
