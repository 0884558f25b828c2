"""The test suite's collection and its fixed cost per test, as one pytest worker pays them.

Two measurements, each in fresh pytest processes (what every ``pytest -n 2`` worker pays once):

* **collection**: ``pytest --collect-only -q -n 0 -p no:cacheprovider`` of this tree, ``--repeat`` times.  This file
  is loaded as a pytest plugin (``-p bench_collection``) and reports the CPU of the process at the end of collection,
  the part spent by pytest's assertion rewriting (``_pytest.assertion.rewrite._rewrite_test``: parsing, rewriting
  and compiling each test module), and that of ``tests/conftest.py``'s ``pytest_collection_modifyitems``.  The run
  is cold only if ``tests/`` and ``nambu_bch/`` hold no ``__pycache__`` (a fresh clone; a warning is printed
  otherwise); bytecode writing is off in the children, hypothesis' storage is a temporary directory.
* **fixed cost per test**: ``--tests`` trivial tests (``assert i + 1 == i + 1``) in a temporary directory, run
  ``-n 0`` with a copy of ``tests/conftest.py`` and the ``[tool.pytest.ini_options]`` of ``pyproject.toml`` (the
  suite's hooks, ``addopts`` and plugins), and bare (no conftest, no ini options, ``-p no:hypothesispytest
  -p no:nambu_bch``), interleaved: the CPU of the run loop per test.  The difference is what the suite's own
  configuration adds to every test.

The load average is printed with every line (a loaded machine inflates CPU times too).

    python benchmarks/bench_collection.py [--repeat 3] [--tests 1500] [--skip-collection] [--skip-fixed]
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
_OUT = os.environ.get("BENCH_COLLECTION_OUT")  # set in the children only: this module is then their plugin


def _load() -> str:
    return "%.1f" % os.getloadavg()[0]


# ------------------------------------------------------------------------------------------------------------------
# the plugin side (loaded by the pytest children with -p bench_collection)
# ------------------------------------------------------------------------------------------------------------------
if _OUT is not None:
    import pytest

    _record = {"rewrite": 0.0, "rewritten": 0, "modifyitems": 0.0}

    def _wrap_rewrite():
        from _pytest.assertion import rewrite

        original = rewrite._rewrite_test

        def timed(fn, config):
            t = time.process_time()
            try:
                return original(fn, config)
            finally:
                _record["rewrite"] += time.process_time() - t
                _record["rewritten"] += 1

        rewrite._rewrite_test = timed

    _wrap_rewrite()

    @pytest.hookimpl(trylast=True)
    def pytest_configure(config):
        # conftest's own hook, timed alone (the other plugins' hooks are not the suite's)
        for plugin in config.pluginmanager.get_plugins():
            hook = getattr(plugin, "pytest_collection_modifyitems", None)
            if getattr(plugin, "__file__", "").endswith(os.path.join("tests", "conftest.py")) and hook is not None:
                def timed(session, config, items, _hook=hook):
                    t = time.process_time()
                    try:
                        return _hook(session, config, items)
                    finally:
                        _record["modifyitems"] += time.process_time() - t
                # the plugin manager calls the attribute it registered: replace the implementation it holds
                for impl in config.hook.pytest_collection_modifyitems.get_hookimpls():
                    if impl.plugin is plugin:
                        impl.function = timed

    def pytest_collection_finish(session):
        _record["collected_cpu"] = time.process_time()
        _record["items"] = len(session.items)

    @pytest.hookimpl(wrapper=True)
    def pytest_runtestloop(session):
        t = time.process_time()
        try:
            return (yield)
        finally:
            _record["loop_cpu"] = time.process_time() - t
            _record["ran"] = len(session.items)

    def pytest_unconfigure(config):
        with open(_OUT, "w", encoding="utf-8") as f:
            json.dump(_record, f)


# ------------------------------------------------------------------------------------------------------------------
# the driver side
# ------------------------------------------------------------------------------------------------------------------
def _run_pytest(args, cwd, tmp: Path, plugin_dirs=()) -> dict:
    out = tmp / "record.json"
    out.unlink(missing_ok=True)
    env = {**os.environ, "BENCH_COLLECTION_OUT": str(out), "PYTHONDONTWRITEBYTECODE": "1",
           "HYPOTHESIS_STORAGE_DIRECTORY": str(tmp / "hypothesis"), "MPLBACKEND": "Agg",
           "NAMBU_BCH_CACHE": str(tmp / "cache"),
           "PYTHONPATH": os.pathsep.join([str(REPO), str(Path(__file__).parent), *plugin_dirs])}
    proc = subprocess.run([sys.executable, "-m", "pytest", "-p", "bench_collection", "-p", "no:cacheprovider", *args],
                          cwd=cwd, env=env, capture_output=True, text=True, timeout=3600)
    if not out.exists():
        tail = proc.stdout[-2000:] + proc.stderr[-2000:]
        raise SystemExit(f"pytest wrote no record (exit {proc.returncode}):\n{tail}")
    return json.loads(out.read_text(encoding="utf-8"))


def collection(repeat: int) -> None:
    stale = [p for d in ("tests", "nambu_bch") for p in (REPO / d).rglob("__pycache__")]
    if stale:
        print(f"warning: {len(stale)} __pycache__ directories under tests/ and nambu_bch/: not a cold collection")
    for i in range(repeat):
        with tempfile.TemporaryDirectory() as tmp:
            load = _load()
            r = _run_pytest(["--collect-only", "-q", "-n", "0"], REPO, Path(tmp))
            print(f"collection {i + 1}: CPU {r['collected_cpu']:.2f} s at the end of collection ({r['items']} items "
                  f"selected), assertion rewriting {r['rewrite']:.2f} s ({r['rewritten']} modules), conftest "
                  f"modifyitems {r['modifyitems']:.3f} s; load {load} -> {_load()}")


def _trivial_tree(root: Path, tests: int, suite: bool) -> None:
    (root / "tests").mkdir(parents=True)
    body = "".join(f"def test_t{i}():\n    assert {i} + 1 == {i + 1}\n\n\n" for i in range(tests))
    (root / "tests" / "test_trivial.py").write_text(body, encoding="utf-8")
    if suite:
        (root / "tests" / "conftest.py").write_text((REPO / "tests" / "conftest.py").read_text(encoding="utf-8"),
                                                     encoding="utf-8")
        text = (REPO / "pyproject.toml").read_text(encoding="utf-8")
        section = text[text.index("[tool.pytest.ini_options]"):]
        section = re.sub(r"(?m)^testpaths = .*$", 'testpaths = ["tests"]', section)
        (root / "pyproject.toml").write_text(section, encoding="utf-8")
    else:
        (root / "pyproject.toml").write_text('[tool.pytest.ini_options]\ntestpaths = ["tests"]\n', encoding="utf-8")


def fixed_cost(repeat: int, tests: int) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        _trivial_tree(tmp / "suite", tests, True)
        _trivial_tree(tmp / "bare", tests, False)
        for i in range(repeat):
            for name, extra in (("suite", []), ("bare", ["-p", "no:hypothesispytest", "-p", "no:nambu_bch"])):
                load = _load()
                r = _run_pytest(["-q", "-n", "0", *extra], tmp / name, tmp)
                print(f"fixed cost {i + 1} {name}: {r['ran']} tests, run loop CPU {r['loop_cpu']:.3f} s, "
                      f"{1000 * r['loop_cpu'] / r['ran']:.3f} ms per test; load {load}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--tests", type=int, default=1500)
    parser.add_argument("--skip-collection", action="store_true")
    parser.add_argument("--skip-fixed", action="store_true")
    args = parser.parse_args(argv)
    print(f"load at the start {_load()}")
    if not args.skip_collection:
        collection(args.repeat)
    if not args.skip_fixed:
        fixed_cost(args.repeat, args.tests)
    print(f"load at the end {_load()}")
    return 0


if __name__ == "__main__" and _OUT is None:
    sys.exit(main())
