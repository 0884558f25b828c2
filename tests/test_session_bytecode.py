"""tests/session_bytecode.py: the workers' shared bytecode is CPython's own, split between them, and removed after."""

import importlib.util
import os

import pytest
import session_bytecode as sb


@pytest.fixture
def tree(tmp_path):
    """A package of three modules and a test module, with no bytecode."""
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    files = []
    for name in ("a", "b", "c"):
        f = pkg / f"{name}.py"
        f.write_text(f"VALUE = {name!r}\n")
        files.append(f)
    test = tmp_path / "test_x.py"
    test.write_text("def test_x():\n    assert 1\n")
    return files + [test]


def test_workers_meet_in_the_middle_and_each_file_is_compiled_once(tree):
    modules = tree[:3]
    assert sb.order_for(modules, 0, 2) == modules and sb.order_for(modules, 1, 2) == modules[::-1]
    assert sb.order_for(modules, 1, 3) == modules[1:] + modules[:1]
    assert sb.precompile(modules[:2], 1, 2) == 2       # worker 1 did the last two ...
    assert sb.precompile(modules, 0, 2) == 1           # ... worker 0 only what was left
    assert sb.precompile(modules, 0, 2) == 0


def test_the_bytecode_is_what_the_import_system_reads(tree, monkeypatch):
    sb.precompile(tree, 0, 1)
    module = tree[0]
    pyc = importlib.util.cache_from_source(str(module))
    assert os.path.isfile(pyc) and sb._fresh_cpython_pyc(module, pyc)
    loader = importlib.machinery.SourceFileLoader("pkg_a_probe", str(module))
    monkeypatch.setattr(loader, "source_to_code", lambda *a, **k: pytest.fail("compiled from source"))
    namespace = {}
    exec(loader.get_code("pkg_a_probe"), namespace)
    assert namespace["VALUE"] == "a"
    # a changed source makes the bytecode stale: compiled again
    module.write_text("VALUE = 'changed, longer'\n")
    assert not sb._fresh_cpython_pyc(module, pyc) and sb.precompile([module], 0, 1) == 1
    # a test module is left to pytest's rewriter, and skipped without one
    assert not os.path.exists(importlib.util.cache_from_source(str(tree[-1])))


def test_only_what_the_session_added_is_removed(tree, tmp_path):
    modules = tree[:3]
    sb.precompile(modules[:1], 0, 1)
    before = sb.snapshot(tree)
    kept = importlib.util.cache_from_source(str(modules[0]))
    sb.precompile(modules, 0, 1)
    cache = os.path.dirname(kept)
    outside = tmp_path / "outside.pyc"
    outside.write_bytes(b"not ours")
    os.symlink(outside, os.path.join(cache, "link.pyc"))
    sb.remove_new(tree, before)
    assert sorted(os.listdir(cache)) == sorted([os.path.basename(kept), "link.pyc"])
    assert outside.read_bytes() == b"not ours"
    # a __pycache__ the session made is removed with its files
    fresh = tree[:1]
    os.remove(os.path.join(cache, "link.pyc"))
    os.remove(kept)
    os.rmdir(cache)
    before = sb.snapshot(fresh)
    sb.precompile(fresh, 0, 1)
    sb.remove_new(fresh, before)
    assert not os.path.exists(cache)


def test_the_initial_sources_are_the_runs_paths_inside_the_rootdir(tree, tmp_path):
    class Config:
        rootpath = tmp_path
        args = ["pkg", "test_x.py::test_x", str(tmp_path.parent)]

        class invocation_params:
            dir = tmp_path

    assert sb.initial_sources(Config) == sorted(tree[:3]) + [tree[-1]]


def test_test_modules_get_the_rewritten_bytecode_pytest_reads(tree, request):
    from _pytest.assertion.rewrite import PYC_TAIL, _read_pyc, get_cache_dir

    rewrite = sb.pytest_rewriter(request.config)
    assert rewrite is not None, "pytest's rewrite parts moved: test modules are no longer shared"
    test = tree[-1]
    assert sb.precompile([test], 0, 1, rewrite) == 1
    assert _read_pyc(test, get_cache_dir(test) / (test.name[:-3] + PYC_TAIL)) is not None
    assert sb.precompile([test], 1, 2, rewrite) == 0  # the other worker finds it
