"""Cold numba compilation, per compiled function: CPU of the first call in a fresh process with an empty cache.

Each case runs in its own interpreter with ``NAMBU_BCH_CACHE`` pointing at a new empty directory (removed
afterwards), so nothing is loaded from a disk cache.  The child imports numba first (its import is printed
apart), then makes the first call (compilation) and times it by CPU; numba's compile events attribute that
CPU to each top-level compiled function (callees compiled on the way are included in their caller's
figure, as numba compiles them while typing it).  The warm figure is the best of five later calls (CPU).

``--stages`` also splits the first call's CPU by stage, summed over every function compiled: each numba pass
(type inference, lowering to LLVM IR, ...; exclusive of what is compiled inside it) and LLVM's four steps
(``add_ir_module``: parsing and verifying the IR; ``_optimize_functions``: the per-function passes;
``_optimize_final_module``: the module passes after linking the callees' code in; ``_finalize_specific``: machine
code), with the number of lines of LLVM IR numba generated, in all and per compiled function (numba's own
implementations of ``np.zeros`` and the like included: each is a compile of its own).

With several ``--tree`` directories (source trees: the PYTHONPATH of the child) the cases run interleaved,
tree after tree, ``--repeats`` rounds; the table gives the median per tree and the load average at the start
and end.  Use it to compare a change against its base:

    python benchmarks/bench_compile.py --tree /path/to/base --tree . --repeats 3 [--stages]
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

#: The child: the measuring harness around one case's ``first()`` and ``warm()``.
_CHILD = r'''
import json, sys
from time import process_time
started = process_time()
import numba
from numba.core import codegen, event
numba_import = process_time() - started
stages, frames, ir_lines, ir_by_function = {}, [], [0], {}

def _push(name):
    frames.append([name, process_time(), 0.0])

def _pop():
    name, t0, inner = frames.pop()
    spent = process_time() - t0
    stages[name] = stages.get(name, 0.0) + spent - inner  # exclusive of the stages nested in it
    if frames:
        frames[-1][2] += spent

class Passes(event.Listener):
    def on_start(self, e):
        _push("compile, other" if e.kind == "numba:compile" else "numba " + e.data["name"].split(" [")[0])
    def on_end(self, e):
        _pop()

def _timed(method):
    original = getattr(codegen.JITCodeLibrary, method)
    def timed(self, *args):
        if method == "add_ir_module":
            lines = str(args[0]).count("\n")
            ir_lines[0] += lines
            ir_by_function[self.name] = ir_by_function.get(self.name, 0) + lines
        _push("LLVM " + method)
        try:
            return original(self, *args)
        finally:
            _pop()
    setattr(codegen.JITCodeLibrary, method, timed)

if STAGES:
    passes = Passes()
    event.register("numba:compile", passes)
    event.register("numba:run_pass", passes)
    for method in ("add_ir_module", "_optimize_functions", "_optimize_final_module", "_finalize_specific"):
        _timed(method)

class Compiles(event.Listener):
    def __init__(self):
        self.depth, self.rows, self.t0 = 0, {}, 0.0
    def on_start(self, e):
        if self.depth == 0:
            self.t0 = process_time()
        self.depth += 1
    def on_end(self, e):
        self.depth -= 1
        if self.depth == 0:
            d = e.data["dispatcher"].py_func
            name = d.__module__.split(".")[-1].split("_")[0] + "." + d.__qualname__ if d.__module__.startswith("nambu_bch_") else d.__module__ + "." + d.__qualname__
            name = name.replace("nambu_bch.", "")
            self.rows[name] = self.rows.get(name, 0.0) + process_time() - self.t0

listener = Compiles()
event.register("numba:compile", listener)
CASE
started = process_time()
first()
first_cpu = process_time() - started
event.unregister("numba:compile", listener)
if STAGES:
    event.unregister("numba:compile", passes)
    event.unregister("numba:run_pass", passes)
best = float("inf")
for _ in range(5):
    t = process_time()
    warm()
    best = min(best, process_time() - t)
print(json.dumps({"numba_import": numba_import, "first": first_cpu, "compiles": listener.rows, "warm": best,
                  "stages": stages, "ir_lines": ir_lines[0], "ir_by_function": ir_by_function}))
'''

#: name -> source defining ``first()`` and ``warm()`` (the same calls on every tree).
def _rk_case(method, h_warm, steps_warm):
    """The child's source for a Runge-Kutta method on the rigid body: a short first run (the compile), a long warm one."""
    return f'''
from nambu_bch.numeric.runge_kutta import iterate_runge_kutta
P = {{"I1": 1.0, "I2": 2.0, "I3": 3.0}}
def first():
    iterate_runge_kutta("rigid-body", "{method}", 0.1, 50, [1.0, 0.5, 0.2], P, every=10, backend="numba")
def warm():
    iterate_runge_kutta("rigid-body", "{method}", {h_warm}, {steps_warm}, [1.0, 0.5, 0.2], P, every=10, backend="numba")
'''


CASES = {
    "bch 12321 deg 9 (sparse engine)": '''
from nambu_bch.bch import formal as F, formal_bch
import nambu_bch
F.SPARSE_FROM_DEGREE = 1
def first():
    formal_bch("12321", 9)
def warm():
    nambu_bch.clear_caches(); F.SPARSE_FROM_DEGREE = 1
    formal_bch("12321", 9)
''',
    "guards' scan (scan_range)": '''
import numpy as np
from nambu_bch.numeric import scan
X = np.random.default_rng(0).uniform(0.5, 1.5, size=(3, 4096))
res = np.zeros(scan.RESULT_SIZE, dtype=np.int64)
def first():
    scan.scan_range(X, 0, 4096, res)
def warm():
    scan.scan_range(X, 0, 4096, res)
''',
    "lotka-volterra 12321 batch (run_batch)": '''
import numpy as np
from nambu_bch.numeric import iterate
X = np.random.default_rng(0).uniform(0.5, 1.5, size=(3, 2048))
def first():
    iterate("lotka-volterra", "12321", 0.05, 400, X, every=100, backend="numba")
def warm():
    iterate("lotka-volterra", "12321", 0.05, 400, X, every=100, backend="numba")
''',
    "ho3 32123 batch (run_batch)": '''
import numpy as np
from nambu_bch.numeric import iterate
X = np.random.default_rng(0).uniform(0.5, 1.5, size=(3, 2048))
def first():
    iterate("ho3", "32123", 0.1, 400, X, every=100, backend="numba")
def warm():
    iterate("ho3", "32123", 0.1, 400, X, every=100, backend="numba")
''',
    "ho3 32123 batch, one step per pass (JAM_STEPS = 1)": '''
import numpy as np
from nambu_bch.numeric import codegen, iterate
codegen.JAM_STEPS = 1
X = np.random.default_rng(0).uniform(0.5, 1.5, size=(3, 2048))
def first():
    iterate("ho3", "32123", 0.1, 400, X, every=100, backend="numba")
def warm():
    iterate("ho3", "32123", 0.1, 400, X, every=100, backend="numba")
''',
    **{f"rigid-body {method} (Runge-Kutta, {kind})": _rk_case(method, h, steps)
       for method, kind, h, steps in (("gauss4", "Newton's method", 0.01, 200000), ("rk4", "explicit", 0.001, 2000000),
                                       ("kahan", "one linear solve", 0.001, 2000000))},
}


def run_case(tree: str, source: str, stages: bool = False) -> dict:
    cache = tempfile.mkdtemp(prefix="nambu_bch_compile_")
    try:
        env = {**os.environ, "PYTHONPATH": str(Path(tree).resolve()), "NAMBU_BCH_CACHE": cache,
               "PYTHONDONTWRITEBYTECODE": "1"}
        env.pop("NAMBU_BCH_DISABLE_NUMBA", None)
        child = _CHILD.replace("CASE", source).replace("if STAGES:", f"if {stages}:")
        # cwd: the empty cache directory, as ``python -c`` puts the working directory first on sys.path (a run
        # from inside a source tree would import that tree's package whatever --tree says)
        done = subprocess.run([sys.executable, "-c", child], env=env, cwd=cache,
                              capture_output=True, text=True, timeout=900)
        if done.returncode:
            raise SystemExit(f"{tree}: {done.stderr.strip().splitlines()[-1:]}")
        return json.loads(done.stdout.strip().splitlines()[-1])
    finally:
        shutil.rmtree(cache, ignore_errors=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tree", action="append", help="a source tree (default: this repository)")
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--only", default="", help="run the cases whose name contains this")
    ap.add_argument("--stages", action="store_true", help="split the first call by numba pass and LLVM step")
    args = ap.parse_args(argv)
    trees = args.tree or [str(Path(__file__).resolve().parents[1])]
    cases = {k: v for k, v in CASES.items() if args.only in k}
    load0 = os.getloadavg()[0]
    results = {(c, t): [] for c in cases for t in trees}
    for _ in range(args.repeats):
        for case, source in cases.items():
            for tree in trees:
                results[case, tree].append(run_case(tree, source, args.stages))
    print(f"# cold numba compilation, CPU s (median of {args.repeats}), fresh process and empty cache per run; "
          f"load {load0:.1f} at the start, {os.getloadavg()[0]:.1f} at the end")
    print("# trees: " + ", ".join(f"[{i}] {Path(t).resolve()}" for i, t in enumerate(trees)))
    for case in cases:
        print(f"\n{case}")
        names = sorted({n for t in trees for r in results[case, t] for n in r["compiles"]})
        for name in names:
            cols = [statistics.median(r["compiles"].get(name, 0.0) for r in results[case, t]) for t in trees]
            print(f"  {name:48s}" + "".join(f" [{i}] {c:6.2f}" for i, c in enumerate(cols)))
        for key, label in (("first", "first call, CPU s"), ("numba_import", "numba import, CPU s"),
                           ("warm", "warm call, best of 5, CPU s")):
            cols = [statistics.median(r[key] for r in results[case, t]) for t in trees]
            print(f"  {label:48s}" + "".join(f" [{i}] {c:8.5f}" for i, c in enumerate(cols)))
        if args.stages:
            print("  stages of the first call (CPU s, median; the largest, then the rest together):")
            totals: dict = {}  # for the ranking only: every run of every tree
            for t in trees:
                for r in results[case, t]:
                    for n, v in r["stages"].items():
                        totals[n] = totals.get(n, 0.0) + v
            shown = sorted(totals, key=totals.get, reverse=True)[:10]
            for name in shown:
                cols = [statistics.median(r["stages"].get(name, 0.0) for r in results[case, t]) for t in trees]
                print(f"    {name:46s}" + "".join(f" [{i}] {c:6.2f}" for i, c in enumerate(cols)))
            cols = [statistics.median(sum(v for n, v in r["stages"].items() if n not in shown)
                                      for r in results[case, t]) for t in trees]
            print(f"    {'the other stages':46s}" + "".join(f" [{i}] {c:6.2f}" for i, c in enumerate(cols)))
            cols = [statistics.median(r["ir_lines"] for r in results[case, t]) for t in trees]
            print(f"    {'lines of LLVM IR generated':46s}" + "".join(f" [{i}] {c:6.0f}" for i, c in enumerate(cols)))
            print("  lines of LLVM IR generated per compiled function (median; the largest):")
            sizes: dict = {}
            for t in trees:
                for r in results[case, t]:
                    for n, v in r["ir_by_function"].items():
                        sizes[n] = max(sizes.get(n, 0), v)
            for name in sorted(sizes, key=sizes.get, reverse=True)[:12]:
                cols = [statistics.median(r["ir_by_function"].get(name, 0) for r in results[case, t]) for t in trees]
                print(f"    {name[:46]:46s}" + "".join(f" [{i}] {c:6.0f}" for i, c in enumerate(cols)))


if __name__ == "__main__":
    main()
