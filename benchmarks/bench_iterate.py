"""Speed of nambu_bch.numeric.iterate against a C reference loop, measured in one run.

Prints nanoseconds per trajectory-step (best of --repeats, both sides warm: compiled and loaded
before timing; the contenders are called in turn in every round, so a change of load on a shared
machine hits them alike, and the load average is printed with the numbers) for
  C (gcc -O3 -march=native, the strongest build; generated from the same step program)
                                                     -- single trajectory and batch,
  C (gcc -O2, for context)                           -- single trajectory and batch,
  C with one exp per piece (hand-written; Lotka-Volterra only) -- single trajectory,
  our numba kernel                                   -- single trajectory and batch (--batch states),
  our numpy fallback                                 -- batch (vectorised) and single (scalar Python loop),
  a plain Python loop over nambu_bch.integrators.step_function,
the ratios to the -O3 -march=native C with the targets (single <= 1.3x, batch through the public
iterate() <= 2x, numpy fallback <= 20x), the kernel compile time (cold: empty cache, in a
subprocess) versus loading it from the disk cache, and the first iterate() of a new process
whose kernel is cached (no sympy on that path).

Usage (from the repository root):
    python benchmarks/bench_iterate.py                       # ho3, 32123 (Sect. 5.5)
    python benchmarks/bench_iterate.py --system lotka-volterra --word 12321 --steps 2000000
    python benchmarks/bench_iterate.py --quick               # smaller sizes, a few seconds
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

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

from nambu_bch import model  # noqa: E402
from nambu_bch.integrators import step_function  # noqa: E402
from nambu_bch.numeric import iterate, kernel  # noqa: E402
from nambu_bch.numeric.kernels import NUMBA_CHUNK, numba_available  # noqa: E402


def best(fn, repeats):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def alternate(work, repeats):
    """Seconds per trajectory-step of each ``{name: (fn, steps per call)}``: the best of ``repeats`` calls,
    the contenders called in turn in every round, so a change of load hits them all alike."""
    times = {name: [] for name in work}
    for _ in range(repeats):
        for name, (fn, _) in work.items():
            start = time.perf_counter()
            fn()
            times[name].append(time.perf_counter() - start)
    return {name: min(times[name]) / steps for name, (_, steps) in work.items()}


COMPILE_SNIPPET = """
import json, sys, time
t0 = time.perf_counter()
from nambu_bch import model
from nambu_bch.numeric import kernel
t1 = time.perf_counter()
system = model(sys.argv[1])
x0 = [0.7] * system.N
t2 = time.perf_counter()
from nambu_bch.numeric import iterate
iterate(system, sys.argv[2], 0.1, 100, x0)          # the first call of the process (auto backend)
t3 = time.perf_counter()
k = kernel(system, sys.argv[2])
t4 = time.perf_counter()
single = k.compile()
batch = k.compile(batch=True)
print(json.dumps({"import": t1 - t0, "first_iterate": t3 - t2, "generate": t4 - t3, "from_cache": k.from_cache,
                  "single": single, "batch": batch}))
"""


def compile_times(system, word):
    """Cold (empty cache) and warm (cache filled by the cold run) kernel compile/load times, in subprocesses."""
    root = Path(__file__).resolve().parents[1]
    env = dict(os.environ, PYTHONPATH=str(root) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    with tempfile.TemporaryDirectory(prefix="nambu_bch_cache_") as cache:
        env["NAMBU_BCH_CACHE"] = cache
        env.pop("NAMBU_BCH_DISABLE_NUMBA", None)
        out = []
        for _ in range(2):
            res = subprocess.run([sys.executable, "-c", COMPILE_SNIPPET, system, word], env=env,
                                 capture_output=True, text=True, check=True)
            out.append(json.loads(res.stdout.strip().splitlines()[-1]))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--system", default="ho3")
    ap.add_argument("--word", default="32123")
    ap.add_argument("--h", type=float, default=0.1)
    ap.add_argument("--steps", type=int, default=10_000_000, help="steps of the single-trajectory runs")
    ap.add_argument("--batch", type=int, default=1_000_000, help="states of the batch runs")
    ap.add_argument("--batch-steps", type=int, default=50)
    ap.add_argument("--numpy-steps", type=int, default=10, help="steps of the numpy batch run")
    ap.add_argument("--python-steps", type=int, default=20_000)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="1e6 steps, 1e5 states, 3 repeats")
    ap.add_argument("--json", action="store_true", help="also print the numbers as one JSON line")
    ap.add_argument("--no-compile-times", action="store_true")
    args = ap.parse_args(argv)
    if args.quick:
        args.steps, args.batch, args.repeats, args.python_steps = 1_000_000, 100_000, 3, 5_000

    system = model(args.system)
    N = system.N
    k = kernel(system, args.word)
    K = k.constants(args.h)
    x0 = np.full(N, 0.7)
    X0 = np.random.default_rng(0).uniform(0.5, 1.5, size=(N, args.batch))
    print(f"# {system.name} {args.word}: {len(k.program.updates)} sub-flows, ~{k.program.n_operations} flops/step; "
          f"h = {args.h}; best of {args.repeats}")
    results = {}

    # -- compile times -------------------------------------------------------------------------------------
    if numba_available() and not args.no_compile_times:
        cold, warm = compile_times(args.system, args.word)
        results["compile_cold_s"] = cold["single"] + cold["batch"]
        results["compile_warm_s"] = warm["single"] + warm["batch"]
        results["first_iterate_cold_s"] = cold["first_iterate"]
        results["first_iterate_cached_s"] = warm["first_iterate"]
        print(f"kernel compile (empty cache, single + batch):   {results['compile_cold_s']:.2f} s "
              f"(import of nambu_bch {cold['import']:.2f} s)")
        print(f"kernel load from disk cache (single + batch):   {results['compile_warm_s']:.3f} s")
        print(f"first iterate() of a process, 100 steps: empty cache {cold['first_iterate']:.3f} s, "
              f"kernel cached {warm['first_iterate']:.3f} s (target < 0.05 s; cached source used: {warm['from_cache']})")

    # -- the contenders: (callable, trajectory-steps per call); all warmed up, then timed alternately ------------
    work = {}
    batch_work = args.batch_steps * args.batch
    cref = None
    try:
        from bench_iterate_c import CReference, c_compiler

        if c_compiler():
            cref = CReference(k.program, flags=("-O3", "-march=native"))
    except Exception as exc:  # no compiler, or compilation failed: report and go on
        print(f"(no C reference: {exc})")
    finals, closers = {}, []
    if cref is not None:
        closers.append(cref)
        x, X = x0.copy(), X0.copy()

        def c_single():
            x[:] = x0
            cref.run(x, K, args.steps)

        def c_batch():  # the C loop advances X in place: a fresh copy of the start states each call (counted)
            np.copyto(X, X0)
            cref.run_batch(X, K, args.batch_steps, NUMBA_CHUNK)

        c_single(), c_batch()
        finals["c_single"], finals["c_batch"] = x.copy(), X.copy()
        work["c_single"] = (c_single, args.steps)
        work["c_batch"] = (c_batch, batch_work)
        try:  # the plain -O2 build, for context
            o2 = CReference(k.program, flags=("-O2",))
            closers.append(o2)
            work["c_o2_single"] = (lambda: o2.run(x0.copy(), K, args.steps), args.steps)
            work["c_o2_batch"] = (lambda: o2.run_batch(X0.copy(), K, args.batch_steps, NUMBA_CHUNK), batch_work)
        except Exception as exc:  # pragma: no cover - depends on the compiler
            print(f"(no -O2 build: {exc})")

    # Lotka-Volterra: the hand-written one-exp-per-piece C loop (the reference)
    if cref is not None and system.name == "lotka-volterra":
        from bench_iterate_c import CSource, lotka_volterra_one_exp_source

        factors = k.composition.factors()
        lv = CSource(lotka_volterra_one_exp_source(factors))
        closers.append(lv)
        KL = np.array([float(c) * args.h for _, c in factors])
        xl = x0.copy()
        lv.run(xl, KL, args.steps)
        finals["c_one_exp_single"] = xl
        work["c_one_exp_single"] = (lambda: lv.run(x0.copy(), KL, args.steps), args.steps)

    holder = {}
    if numba_available():
        iterate(system, args.word, args.h, 10, x0)            # compile / load outside the timing
        iterate(system, args.word, args.h, 10, X0[:, :10])
        work["numba_single"] = (lambda: holder.__setitem__(
            "x", iterate(system, args.word, args.h, args.steps, x0, every=args.steps)), args.steps)
        work["numba_batch"] = (lambda: holder.__setitem__(
            "X", iterate(system, args.word, args.h, args.batch_steps, X0, every=args.batch_steps)), batch_work)
        out = np.empty((2, N, args.batch))
        Xk = X0.copy()

        def kernel_batch():  # like the C loop: a fresh copy of the start states, advanced in place
            np.copyto(Xk, X0)
            k.run_batch(Xk, K, args.batch_steps, args.batch_steps, out)

        work["numba_batch_kernel"] = (kernel_batch, batch_work)

    work["numpy_batch"] = (lambda: iterate(system, args.word, args.h, args.numpy_steps, X0, every=args.numpy_steps,
                                           backend="numpy"), args.numpy_steps * args.batch)
    Xn, outn = X0.copy(), np.empty((2, N, args.batch))

    def numpy_kernel():
        np.copyto(Xn, X0)
        k.run_batch(Xn, K, args.numpy_steps, args.numpy_steps, outn, backend="numpy")

    work["numpy_batch_kernel"] = (numpy_kernel, args.numpy_steps * args.batch)
    work["numpy_single_python"] = (lambda: iterate(system, args.word, args.h, args.python_steps, x0,
                                                   every=args.python_steps, backend="numpy"), args.python_steps)
    step = step_function(system.splitting, args.word)

    def plain():
        x = x0.copy()
        for _ in range(args.python_steps // 4):
            x = step(x, args.h)

    work["plain_python_loop"] = (plain, args.python_steps // 4)
    for fn, _ in work.values():  # warm: compiled, loaded, caches touched
        fn()
    load_before = os.getloadavg()
    results.update(alternate(work, args.repeats))
    results["load_average"] = [round(v, 2) for v in load_before + os.getloadavg()]
    print(f"load average (1, 5, 15 min) before {load_before[0]:.2f} {load_before[1]:.2f} {load_before[2]:.2f}, "
          f"after {results['load_average'][3]:.2f} on {os.cpu_count()} CPUs (best of {args.repeats}, run alternately)")
    if "numba_single" in work and "c_single" in finals:
        same_single = np.array_equal(holder["x"][-1], finals["c_single"])
        same_batch = np.array_equal(holder["X"][-1], finals["c_batch"])
        print(f"numba == C bit for bit: single {same_single}, batch {same_batch}")
    if "numba_single" in work and "c_one_exp_single" in finals:
        ref = finals["c_one_exp_single"]
        rel = float(np.max(np.abs(holder["x"][-1] - ref) / np.abs(ref)))
        print(f"numba vs the one-exp C loop after {args.steps} steps: max relative difference {rel:.1e} (rounding)")

    # -- report --------------------------------------------------------------------------------------------------
    ns = {key: v * 1e9 for key, v in results.items() if not key.startswith(("compile", "first", "load"))}
    labels = {
        "c_single": "C -O3 -march=native, single trajectory",
        "c_batch": f"C -O3 -march=native, batch of {args.batch:.0e}",
        "c_one_exp_single": "C one exp per piece (hand-written), single",
        "c_o2_single": "C -O2, single (context)",
        "c_o2_batch": "C -O2, batch (context)",
        "numba_single": "numba, single trajectory via iterate()",
        "numba_batch": f"numba, batch of {args.batch:.0e} via iterate()",
        "numba_batch_kernel": f"numba, batch of {args.batch:.0e}, kernel only",
        "numpy_batch": f"numpy fallback, batch of {args.batch:.0e} via iterate()",
        "numpy_batch_kernel": f"numpy fallback, batch of {args.batch:.0e}, kernel only",
        "numpy_single_python": "numpy fallback, single (scalar Python loop)",
        "plain_python_loop": "plain Python loop over step_function",
    }
    print(f"{'':46s} {'ns / trajectory-step':>22s}")
    for key, label in labels.items():
        if key in ns:
            print(f"{label:46s} {ns[key]:22.2f}")
    print("ratios (target):")
    checks = [("numba_single", "c_single", 1.3), ("numba_single", "c_one_exp_single", 1.3), ("numba_batch", "c_batch", 2.0), ("numba_batch_kernel", "c_batch", None),
              ("numpy_batch", "c_batch", 20.0), ("numpy_batch_kernel", "c_batch", None),
              ("numba_single", "c_o2_single", None), ("numba_batch", "c_o2_batch", None),
              ("numpy_single_python", "c_single", None), ("plain_python_loop", "c_single", None)]
    for a, b, target in checks:
        if a in ns and b in ns:
            r = ns[a] / ns[b]
            verdict = "" if target is None else (f"  (target <= {target:g}: {'met' if r <= target else 'MISSED'})")
            print(f"  {labels[a]:44s} / {labels[b]:36s}: {r:7.2f}{verdict}")
    if args.json:
        print(json.dumps({"system": system.name, "word": args.word, "ns_per_step": ns,
                          **{k2: v for k2, v in results.items() if k2.startswith(("compile", "first", "load"))}}))
    for c in closers:
        c.close()


if __name__ == "__main__":
    main()
