"""python-flint behind one seam (:mod:`nambu_bch.algebra._flint`).

* No module of the package but the seam imports ``flint``: ``import flint``, ``from flint import ..``,
  ``import_module("flint")`` or ``__import__("flint")`` anywhere in its AST (deferred imports included).
* The switch ``NAMBU_BCH_DISABLE_FLINT`` is read at every call (and ``elimination.flint_available`` is the seam's).
* The conversions: rationals to ``fmpq`` and back, contexts cached per number of variables, exponents as ints.
"""

from __future__ import annotations

import ast
import pathlib
from fractions import Fraction

import pytest
import shared_results as shared
from sympy.polys.domains import QQ

import nambu_bch
from nambu_bch.algebra import _flint, elimination

PACKAGE = pathlib.Path(nambu_bch.__file__).parent
SEAM = PACKAGE / "algebra" / "_flint.py"


def _imports_flint(tree) -> list:
    """Line numbers of the imports of ``flint`` (or ``flint.*``) in ``tree``."""
    hits = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            if any(a.name == "flint" or a.name.startswith("flint.") for a in node.names):
                hits.append(node.lineno)
        elif isinstance(node, ast.ImportFrom):
            if node.level == 0 and node.module and (node.module == "flint" or node.module.startswith("flint.")):
                hits.append(node.lineno)
        elif isinstance(node, ast.Call) and node.args:
            func = node.func
            name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", None)
            first = node.args[0]
            if (name in ("import_module", "__import__") and isinstance(first, ast.Constant)
                    and isinstance(first.value, str) and first.value.split(".")[0] == "flint"):
                hits.append(node.lineno)
    return hits


def test_detector_sees_every_spelling():
    src = "import flint\nfrom flint import fmpq\nimport importlib\nimportlib.import_module('flint')\n" \
          "def f():\n    import flint.types\n    return __import__('flint')\n"
    assert _imports_flint(ast.parse(src)) == [1, 2, 4, 6, 7]
    assert _imports_flint(ast.parse("from . import _flint\nfrom ._flint import exponents\nimport flintlock\n")) == []


@pytest.fixture(scope="module")
def package_trees() -> dict:
    """``{path: AST}`` of every module of the package, parsed once for the tests that walk them."""
    return shared.package_trees(str(PACKAGE))


def test_only_the_seam_imports_flint(package_trees):
    offenders = {}
    for path, tree in package_trees.items():
        hits = _imports_flint(tree)
        if hits and path != SEAM:
            offenders[str(path.relative_to(PACKAGE))] = hits
    assert offenders == {}
    assert _imports_flint(package_trees[SEAM])  # the seam itself does


def test_switch_is_read_at_every_call(monkeypatch):
    monkeypatch.setenv("NAMBU_BCH_DISABLE_FLINT", "1")
    assert not _flint.available() and not elimination.flint_available()
    for off in ("true", " YES ", "on"):
        monkeypatch.setenv("NAMBU_BCH_DISABLE_FLINT", off)
        assert _flint.disabled()
    monkeypatch.setenv("NAMBU_BCH_DISABLE_FLINT", "0")
    assert not _flint.disabled()
    monkeypatch.delenv("NAMBU_BCH_DISABLE_FLINT")
    if _flint._import() is None:
        pytest.skip("python-flint is not installed")
    assert _flint.available() and elimination.flint_available()


@pytest.fixture
def flint_on(monkeypatch):
    monkeypatch.delenv("NAMBU_BCH_DISABLE_FLINT", raising=False)
    if not _flint.available():
        pytest.skip("python-flint is not installed")


def test_rationals_round_trip(flint_on):
    fmpq = _flint.module().fmpq
    for value, expected in ((QQ(-3, 7), fmpq(-3, 7)), (Fraction(5, 4), fmpq(5, 4)), (6, fmpq(6)),
                            (fmpq(2, 9), fmpq(2, 9))):
        out = _flint.fmpq(value)
        assert _flint.is_fmpq(out) and out == expected
    assert _flint.fmpq(3, 12) == fmpq(1, 4)
    assert _flint.qq_is_fmpq(fmpq) and not _flint.qq_is_fmpq(Fraction)


def test_contexts_are_cached_and_exponents_are_ints(flint_on):
    assert _flint.fmpz_mpoly_context(3) is _flint.fmpz_mpoly_context(3)
    assert _flint.fmpq_mpoly_context(2) is _flint.fmpq_mpoly_context(2)
    ctx = _flint.fmpq_mpoly_context(2)
    x, y = ctx.gens()
    p = 3 * x**2 * y - y + 1
    exps = _flint.exponents(p)
    assert sorted(exps) == [(0, 0), (0, 1), (2, 1)]  # lexicographic: x first
    assert all(type(e) is int for m in exps for e in m)


def test_elimination_over_qq_same_with_and_without_flint(monkeypatch, flint_on):
    """The dense fmpq_mat route and the pure route give the same reduced echelon form (the RREF is unique)."""
    rows = {0: {0: QQ(1, 2), 1: QQ(3)}, 1: {0: QQ(1), 2: QQ(-1, 5)}, 2: {1: QQ(6), 2: QQ(2, 5)}}
    with_flint = elimination._rref_flint_qq(rows, 3, 3)
    monkeypatch.setenv("NAMBU_BCH_DISABLE_FLINT", "1")
    R, pivots = elimination._sdm(rows, 3, 3, QQ).rref()
    assert with_flint == ({k: v for k, v in R.rep.to_sdm().items()}, tuple(pivots))


def _import_cycles_tool():
    import importlib.util

    path = pathlib.Path(__file__).resolve().parents[1] / "tools" / "import_cycles.py"
    spec = importlib.util.spec_from_file_location("_import_cycles", path)
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    return tool


def test_the_arithmetic_layer_has_no_import_cycle(package_trees):
    """No cycle through nambu_bch.algebra, counting imports inside functions (a deferred import that breaks a cycle
    is still one); the detector itself finds a planted cycle."""
    tool = _import_cycles_tool()
    found = tool.cycles(tool.graph(PACKAGE, deferred=True, trees=package_trees))
    assert [c for c in found if any(m.startswith("nambu_bch.algebra") for m in c)] == []
    assert tool.cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
