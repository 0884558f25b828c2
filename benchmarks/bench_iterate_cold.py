"""The first compiled iterate() of a fresh process whose kernel is cached, phase by phase.

Each measurement is a new Python process (the contenders in turn, ``--repeats`` rounds; best and
median of wall and CPU time; the load average printed with the numbers), on a kernel cache that a
first process filled (a temporary ``NAMBU_BCH_CACHE``, so the machine's own cache is not touched):

  python -c pass                 -- the interpreter's own start, for scale
  import numba                   -- the floor of any run that uses numba's machine code
  the run, in phases             -- ``import nambu_bch.numeric`` (sympy, numpy), ``model(system)``,
                                    then the first ``iterate()`` of ``--steps`` steps (more than
                                    ``INTERPRET_STEPS``: compiled), split into importing numba, loading
                                    the cached machine code (numba's type context included) and the rest
  the run with numba imported first -- the same, numba's import moved before the timer
  a short run                    -- the same with ``--short`` steps (within ``INTERPRET_STEPS``: interpreted,
                                    numba not imported)
  a C library (prototype)        -- what the run would cost without numba: the same phases, then the run's
                                    guards (``iterate._prepare``, numpy backend), the SHA-256 check of a shared
                                    library built beforehand from the same step program (``codegen.c_source``,
                                    ``-O3 -march=native -ffp-contract=off``), ``ctypes.CDLL`` and its loop of
                                    ``--steps`` steps; its final state is compared bit for bit with ``iterate()``'s.
                                    Not a package feature: the measurement of what one would take
                                    (docs/numerics.md, "The first compiled run of a process").

Usage (from the repository root):
    python benchmarks/bench_iterate_cold.py                  # ho3, 32123, 10^6 steps
    python benchmarks/bench_iterate_cold.py --repeats 9 --json
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]

CHILD = """
import json, sys, time
clock = lambda: (time.perf_counter(), time.process_time())
marks = {"start": clock()}
if sys.argv[1] == "numba_first":
    import numba
    marks["numba"] = clock()
from nambu_bch import model
from nambu_bch.numeric import iterate, kernel
marks["import"] = clock()
system = model(sys.argv[2])
marks["model"] = clock()
x = iterate(system, sys.argv[3], 0.1, int(sys.argv[4]), [0.7] * system.N, every=int(sys.argv[4]))
marks["iterate"] = clock()
k = kernel(system, sys.argv[3])
print(json.dumps({"marks": marks, "load": k.compile_seconds.get("run"), "interpreted": k.interpreted.get("run", 0),
                  "from_cache": k.from_cache, "numba_import": NUMBA_IMPORT[0] if NUMBA_IMPORT else None}))
"""

CTYPES_CHILD = """
import ctypes, hashlib, json, sys, time
clock = lambda: (time.perf_counter(), time.process_time())
marks = {"start": clock()}
import numpy as np
from nambu_bch import model
from nambu_bch.numeric import kernel
from nambu_bch.numeric.iterate import _prepare
marks["import"] = clock()
system = model(sys.argv[2])
marks["model"] = clock()
steps, path, digest = int(sys.argv[4]), sys.argv[5], sys.argv[6]
k = kernel(system, sys.argv[3])
run = _prepare(system, k, 0.1, steps, 1, [0.7] * system.N, None, "numpy", None, True)
with open(path, "rb") as fh:
    assert hashlib.sha256(fh.read()).hexdigest() == digest
lib = ctypes.CDLL(path)
P = ctypes.POINTER(ctypes.c_double)
x = np.array(run.X, dtype=np.float64)
lib.run.argtypes, lib.run.restype = [P, P, ctypes.c_long], ctypes.c_long
lib.run(x.ctypes.data_as(P), run.K.ctypes.data_as(P), steps)
marks["iterate"] = clock()
print(json.dumps({"marks": marks, "load": None, "final": x.tolist(), "numba": "numba" in sys.modules,
                  "numba_import": None}))
"""

#: Prefix of the run's child: times the first ``import numba`` statement wherever it runs (``__import__``
#: wrapped; ``importlib.util.find_spec``, which locates numba without importing it, does not pass here).
HOOK = """
import builtins, sys, time
NUMBA_IMPORT = []
_import = builtins.__import__
def _timed(name, *args, **kwargs):
    if name != "numba" or NUMBA_IMPORT or "numba" in sys.modules:
        return _import(name, *args, **kwargs)
    start = time.perf_counter()
    try:
        return _import(name, *args, **kwargs)
    finally:
        NUMBA_IMPORT.append(time.perf_counter() - start)
builtins.__import__ = _timed
"""


def child(kind, args, env):
    """One fresh process; its JSON line, or ``{"wall": ..., "cpu": ...}`` of the whole process for the floors."""
    if kind in ("pass", "numba"):
        code = "pass" if kind == "pass" else "import numba"
        start = time.perf_counter()
        before = os.times()
        subprocess.run([sys.executable, "-c", code], env=env, check=True)
        after = os.times()
        return {"wall": time.perf_counter() - start,
                "cpu": (after.children_user - before.children_user) + (after.children_system - before.children_system)}
    steps = args.short if kind == "short" else args.steps
    code, extra = (CTYPES_CHILD, list(args.library)) if kind == "ctypes" else (HOOK + CHILD, [])
    res = subprocess.run([sys.executable, "-c", code, kind, args.system, args.word, str(steps), *extra],
                         env=env, capture_output=True, text=True, check=True)
    return json.loads(res.stdout.strip().splitlines()[-1])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--system", default="ho3")
    ap.add_argument("--word", default="32123")
    ap.add_argument("--steps", type=int, default=1_000_000, help="steps of the run (compiled: > INTERPRET_STEPS)")
    ap.add_argument("--short", type=int, default=100, help="steps of the short run (interpreted)")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    env.pop("NAMBU_BCH_DISABLE_NUMBA", None)
    with tempfile.TemporaryDirectory(prefix="nambu_bch_cold_") as cache:
        env["NAMBU_BCH_CACHE"] = cache
        filled = child("run", args, env)  # compiles and caches the kernel
        rows = {"pass": [], "numba": [], "run": [], "numba_first": [], "short": []}
        cref = _c_library(args, cache)
        if cref is not None:
            rows["ctypes"] = []
        load_before = os.getloadavg()
        for _ in range(args.repeats):
            for kind in rows:
                rows[kind].append(child(kind, args, env))
        load_after = os.getloadavg()
        if cref is not None:
            cref.close()
    print(f"# first iterate() of a fresh process: {args.system} {args.word}, {args.steps} steps, kernel cached "
          f"(the filling process compiled in {filled['load']:.2f} s); {args.repeats} rounds")
    print(f"load average (1, 5, 15 min) before {load_before[0]:.2f} {load_before[1]:.2f} {load_before[2]:.2f}, "
          f"after {load_after[0]:.2f} {load_after[1]:.2f} {load_after[2]:.2f} on {os.cpu_count()} CPUs")

    def stat(values):
        return f"{min(values):7.3f} {float(np.median(values)):7.3f}"

    print(f"{'seconds':58s} {'wall best / median':>17s}  {'CPU best / median':>17s}")
    for kind, label in (("pass", "python -c pass (whole process)"),
                        ("numba", "python -c 'import numba' (whole process)")):
        print(f"{label:58s} {stat([r['wall'] for r in rows[kind]])}  {stat([r['cpu'] for r in rows[kind]])}")
    summary = {}
    if "ctypes" in rows:
        same = all(r["final"] == args.reference for r in rows["ctypes"]) and not any(r["numba"] for r in rows["ctypes"])
        print(f"C library prototype: final state == iterate() bit for bit, numba never imported: {same}")
    for kind, title in (("run", "the run"), ("numba_first", "the run, numba imported before the timer"),
                        ("short", f"a short run, {args.short} steps"),
                        ("ctypes", "prototype: the same loop as a verified C library through ctypes (no numba)")):
        if kind not in rows:
            continue
        phases = {}
        for r in rows[kind]:
            m = r["marks"]
            order = [p for p in ("start", "numba", "import", "model", "iterate") if p in m]
            for a, b in zip(order, order[1:]):
                phases.setdefault(b, []).append((m[b][0] - m[a][0], m[b][1] - m[a][1]))
            if r["numba_import"] is not None and kind == "run":
                phases.setdefault("iterate: of which import numba", []).append((r["numba_import"], float("nan")))
            if r["load"] is not None:
                phases.setdefault("iterate: of which loading the machine code", []).append((r["load"], float("nan")))
        print(f"{title}:")
        labels = {"numba": "import numba", "import": "import nambu_bch.numeric (sympy, numpy)",
                  "model": f"model({args.system!r})",
                  "iterate": (f"kernel, guards, digest, CDLL, {args.steps} steps" if kind == "ctypes" else
                              f"first iterate(), {args.short if kind == 'short' else args.steps} steps")}
        for name, values in phases.items():
            wall = [w for w, _ in values]
            cpu = [c for _, c in values]
            cpu_text = stat(cpu) if not np.isnan(cpu).all() else f"{'-':>7s} {'-':>7s}"
            print(f"  {labels.get(name, name):56s} {stat(wall)}  {cpu_text}")
            summary[f"{kind}:{name}"] = {"wall_best": min(wall), "wall_median": float(np.median(wall))}
    if args.json:
        print(json.dumps({"system": args.system, "word": args.word, "steps": args.steps,
                          "load_average": [round(v, 2) for v in load_before + load_after], "phases": summary}))


def _c_library(args, cache):
    """Build the C loop of the kernel (``-ffp-contract=off``: the numba kernel's bits) for the prototype row; sets
    ``args.library`` (path, SHA-256) and ``args.reference`` (``iterate()``'s final state); None without a compiler."""
    import hashlib

    sys.path.insert(0, str(ROOT))
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    os.environ["NAMBU_BCH_CACHE"] = cache
    from bench_iterate_c import EXACT_FLAGS, CReference, c_compiler

    from nambu_bch import model
    from nambu_bch.numeric import iterate, kernel

    if c_compiler() is None:
        return None
    system = model(args.system)
    cref = CReference(kernel(system, args.word).program, EXACT_FLAGS)
    path = os.path.join(cref.dir, "step.so")
    with open(path, "rb") as fh:
        args.library = (path, hashlib.sha256(fh.read()).hexdigest())
    args.reference = iterate(system, args.word, 0.1, args.steps, [0.7] * system.N, every=args.steps)[-1].tolist()
    return cref


if __name__ == "__main__":
    main()
