"""Where the test suite's time goes: per-test CPU and numba's compiles, recorded by a pytest plugin.

The numbers of docs/suite_time.md come from this file.  Record (a fresh clone, an empty kernel cache: the cold
condition of .ci/run), then report:

    SUITE_PROFILE_DIR=$(mktemp -d) NAMBU_BCH_CACHE=$(mktemp -d) PYTHONPATH=$PWD:$PWD/tools \\
        python -m pytest -n 2 -q -p no:cacheprovider -p suite_profile
    python tools/suite_profile.py DIR [--tests 60] [--files 30]

Each pytest process (the xdist workers, the controller) appends JSON lines to ``DIR/<worker>.jsonl``: its CPU
at start, after collection and at the end (with the load average), and per test the process's own CPU (user +
sys) and that of the child processes it reaped during the test, plus every top-level numba compile above
0.05 s of CPU with the test that caused it, the loop's fast-math variant and the directory of its source (the report
lists each loop compiled more than once).  Without ``SUITE_PROFILE_DIR`` the plugin records nothing.
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import resource
import sys
import time
from pathlib import Path

import pytest

_DIR = os.environ.get("SUITE_PROFILE_DIR")
_WORKER = os.environ.get("PYTEST_XDIST_WORKER", "main")
_state = {"test": "<collection>", "depth": 0, "file": None}


def _write(record: dict) -> None:
    if _DIR is None:
        return
    if _state["file"] is None:
        os.makedirs(_DIR, exist_ok=True)
        path = os.path.join(_DIR, _WORKER + ".jsonl")
        if os.path.lexists(path) and not os.path.isfile(path) or os.path.islink(path):
            raise RuntimeError(f"suite_profile: {path} is not a regular file; give an empty SUITE_PROFILE_DIR")
        _state["file"] = open(path, "a", buffering=1)
    _state["file"].write(json.dumps(record) + "\n")


def _cpu() -> tuple:
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime, children.ru_utime + children.ru_stime


#: The module whose ``Dispatcher.compile`` is timed (a compile, or a load from numba's cache, of one signature).
_DISPATCHER = "numba.core.dispatcher"


class _WatchOnImport:
    """A ``sys.meta_path`` finder that patches :data:`_DISPATCHER` as soon as it is executed: otherwise the compiles
    of the test that first imports numba (in a worker) would be missed, since the patch is applied between tests."""

    def find_spec(self, name, path, target=None):
        if name != _DISPATCHER:
            return None
        for finder in sys.meta_path:
            find = getattr(finder, "find_spec", None)
            spec = None if finder is self or find is None else find(name, path, target)
            if spec is not None:
                break
        else:
            return None
        loader, run = spec.loader, spec.loader.exec_module

        def exec_module(module):
            run(module)
            _watch_numba()

        loader.exec_module = exec_module  # this module's loader only
        return spec


def _watch_numba() -> None:
    """Time numba's top-level compiles (a compile nested in another is counted in its caller)."""
    dispatcher = sys.modules.get(_DISPATCHER)
    if _DIR is None or dispatcher is None or getattr(dispatcher.Dispatcher.compile, "_profiled", False):
        return
    original = dispatcher.Dispatcher.compile

    def compile(self, sig):
        _state["depth"] += 1
        start = time.process_time()
        try:
            return original(self, sig)
        finally:
            _state["depth"] -= 1
            spent = time.process_time() - start
            if _state["depth"] == 0 and spent > 0.05:
                fn = self.py_func
                # the fast-math flags and the source's directory tell a second loop of the same function (fma=True's
                # "+contract") and a probe's own cache from a true second compile of one loop
                fastmath = getattr(self, "targetoptions", {}).get("fastmath") or ()
                _write({"k": "numba", "test": _state["test"], "fn": f"{fn.__module__}.{fn.__qualname__}", "cpu": spent,
                        "variant": "".join("+" + flag for flag in sorted(fastmath)) if fastmath else "",
                        "where": os.path.dirname(fn.__code__.co_filename)})

    compile._profiled = True
    dispatcher.Dispatcher.compile = compile


def pytest_configure(config):
    _write({"k": "start", "cpu": sum(_cpu()), "t": time.time(), "load": os.getloadavg()})
    if _DIR is not None and not any(isinstance(f, _WatchOnImport) for f in sys.meta_path):
        sys.meta_path.insert(0, _WatchOnImport())


def pytest_collection_finish(session):
    _write({"k": "collected", "cpu": sum(_cpu()), "t": time.time(), "n": len(session.items)})


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    _watch_numba()  # numba is imported by some test: patch it as soon as it is there
    _state["test"] = item.nodeid
    own, children = _cpu()
    start = time.time()
    yield
    own2, children2 = _cpu()
    _write({"k": "test", "test": item.nodeid, "own": own2 - own, "ch": children2 - children, "wall": time.time() - start})


def pytest_unconfigure(config):
    _write({"k": "end", "cpu": sum(_cpu()), "t": time.time(), "load": os.getloadavg()})


def report(directory, n_tests: int = 60, n_files: int = 30) -> str:
    """The recorded run as text: per-test CPU in all, per worker, per file, the costliest tests, numba's compiles."""
    tests, compiles, marks = [], [], []
    for path in sorted(Path(directory).glob("*.jsonl")):
        for line in path.read_text().splitlines():
            record = json.loads(line)
            record["worker"] = path.stem
            {"test": tests, "numba": compiles}.get(record["k"], marks).append(record)
    cost = lambda t: t["own"] + t["ch"]  # noqa: E731
    lines = [f"tests {len(tests)}, per-test CPU {sum(map(cost, tests)):.1f} s "
             f"(own {sum(t['own'] for t in tests):.1f}, children {sum(t['ch'] for t in tests):.1f})"]
    by_worker = collections.Counter()
    for t in tests:
        by_worker[t["worker"]] += cost(t)
    lines += [f"  {w}: {v:.1f} s" for w, v in sorted(by_worker.items())]
    lines += [f"  {m['worker']} {m['k']}: CPU {m['cpu']:.1f} s" + (f", load {m['load'][0]:.1f}" if "load" in m else "")
              for m in marks]
    lines += _timeline(marks)
    by_file = collections.Counter()
    for t in tests:
        by_file[t["test"].split("::")[0]] += cost(t)
    lines.append("--- files")
    lines += [f"{v:7.1f} {k}" for k, v in by_file.most_common(n_files)]
    lines.append("--- tests (own, children)")
    lines += [f"{t['own']:6.2f} {t['ch']:6.2f} {t['test']}" for t in sorted(tests, key=cost, reverse=True)[:n_tests]]
    lines.append(f"--- numba compiles: {len(compiles)}, {sum(c['cpu'] for c in compiles):.1f} s")
    lines += [f"{c['cpu']:6.2f} {c['fn']}{c.get('variant', '')}  <- {c['test']}"
              for c in sorted(compiles, key=lambda c: -c["cpu"])]
    lines += _repeated(compiles)
    return "\n".join(lines)


def _timeline(marks) -> list:
    """Wall seconds from the time stamps: the whole run (the controller's start to its end), each worker's
    collection, and the last worker's end (its session over) to the run's end -- the workers' exit."""
    t = {(m["worker"], m["k"]): m["t"] for m in marks if "t" in m}
    if ("main", "start") not in t or ("main", "end") not in t:
        return []
    lines = [f"  wall: the run {t['main', 'end'] - t['main', 'start']:.1f} s"]
    workers = sorted({w for w, _ in t if w != "main"})
    lines += [f"  wall: {w} collection {t[w, 'collected'] - t[w, 'start']:.1f} s"
              for w in workers if (w, "start") in t and (w, "collected") in t]
    ends = [t[w, "end"] for w in workers if (w, "end") in t]
    if ends:
        lines.append(f"  wall: the last worker's end -> the run's end {t['main', 'end'] - max(ends):.1f} s")
    return lines


def _repeated(compiles) -> list:
    """Lines naming each loop (function and fast-math variant) compiled more than once, with the worker and test of
    each compile: in the same source directory (one cache: two workers needing it at once, or a lost cache entry)
    or in several (a probe's own cache directory, whose compile is its subject)."""
    groups = collections.defaultdict(list)
    for c in compiles:
        groups[c["fn"] + c.get("variant", "")].append(c)
    repeated = {key: group for key, group in groups.items() if len(group) > 1}
    if not repeated:
        return []
    lines = ["--- compiled more than once"]
    for key, group in sorted(repeated.items(), key=lambda kv: -sum(c["cpu"] for c in kv[1])):
        places = len({c.get("where") for c in group})
        where = "one directory" if places == 1 else f"{places} directories"
        lines.append(f"{sum(c['cpu'] for c in group):6.2f} {key}: {len(group)} times, {where}")
        lines += [f"       {c['cpu']:6.2f} {c['worker']} {c['test']}" for c in group]
    return lines


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description="Report a run recorded by the suite_profile pytest plugin.")
    parser.add_argument("directory")
    parser.add_argument("--tests", type=int, default=60, help="how many of the costliest tests to list")
    parser.add_argument("--files", type=int, default=30, help="how many test files to list")
    args = parser.parse_args(argv)
    print(report(args.directory, args.tests, args.files))
    return 0


if __name__ == "__main__":
    sys.exit(main())
