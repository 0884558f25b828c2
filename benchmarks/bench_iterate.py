"""Speed of nambu_bch.numeric.iterate against a C reference loop, measured in one run.

Both sides are measured the same way: the call alone (ours: the public ``iterate()``, validation and
result check included; C: the generated loop through ctypes, plus the copy of the start states its
batch loop advances in place), warm (compiled and loaded before timing), called in turn in every
round so that a change of load on a shared machine hits them alike, repeated ``--repeats`` times.
Every row prints the best and the median wall time per trajectory-step and the best CPU time; the
load average is printed with the numbers.  The contenders:

  C, gcc's default optimised build (-O3 -march=native: gcc contracts a*b + c into FMA)
                                                     -- single trajectory and batch,
  C, the same build with -ffp-contract=off (bit for bit the numba kernels) -- single and batch,
  C with one exp per piece (hand-written; Lotka-Volterra only) -- single trajectory,
  numba via iterate(): default (bit-reproducible) and fma=True -- single; batch into out= (both) on one
      thread, batch allocating its result, and the batch kernel alone,
  both sides' batches split across the cores (``--threads``, default all): iterate(workers=T, out=) and the
      default C build called on T contiguous blocks of states from T threads (ctypes releases the GIL),
  the guards' scan of x0 on its own, on one thread and on T (iterate() makes it inside the compiled batch loop,
      chunk by chunk as the states are loaded: no separate pass; the row shows what that fusion saves),
  our numpy fallback                                 -- batch (vectorised) and single (scalar Python loop),
  a plain Python loop over nambu_bch.integrators.step_function,
the ratios with the targets (one trajectory, fma=True, <= 1.05x the default C build; batch through
iterate() into out= <= 1.5x the default C batch loop, on one thread and on all, and like for like: the default
(bit-reproducible) batch against the -ffp-contract=off build, fma=True against the default build; the threaded batch
>= 1.8x faster than one thread on two cores; numpy fallback <= 20x) and the kernel compile
time (cold: empty cache, in a subprocess) versus loading it from the disk cache.  The first compiled
run of a fresh process is measured by bench_iterate_cold.py.

Usage (from the repository root):
    python benchmarks/bench_iterate.py                       # ho3, 32123 (Sect. 5.5)
    python benchmarks/bench_iterate.py --system lotka-volterra --word 12321 --steps 2000000
    python benchmarks/bench_iterate.py --quick               # smaller sizes, a few seconds
    python benchmarks/bench_iterate.py --rows                # also the README's iteration rows (markdown)
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
from nambu_bch.numeric.iterate import available_threads  # noqa: E402
from nambu_bch.numeric.kernels import NUMBA_CHUNK, column_ranges, numba_available  # noqa: E402
from nambu_bch.numeric.samples import n_samples  # noqa: E402


def alternate(work, repeats):
    """``{name: (best wall, median wall, best CPU)}`` in seconds per trajectory-step of each
    ``{name: (fn, steps per call)}``, the contenders called in turn in every round, so a change of
    load hits them all alike."""
    wall = {name: [] for name in work}
    cpu = {name: [] for name in work}
    for _ in range(repeats):
        for name, (fn, _) in work.items():
            c0, t0 = time.process_time(), time.perf_counter()
            fn()
            t1, c1 = time.perf_counter(), time.process_time()
            wall[name].append(t1 - t0)
            cpu[name].append(c1 - c0)
    return {name: (min(wall[name]) / steps, float(np.median(wall[name])) / steps, min(cpu[name]) / steps)
            for name, (_, steps) in work.items()}


COMPILE_SNIPPET = """
import json, sys, time
t0 = time.perf_counter()
from nambu_bch import model
from nambu_bch.numeric import kernel
t1 = time.perf_counter()
k = kernel(model(sys.argv[1]), sys.argv[2])
single = k.compile()
batch = k.compile(batch=True)
print(json.dumps({"import": t1 - t0, "single": single, "batch": batch}))
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


LABELS = {
    "c_single": "C -O3 -march=native (gcc default, FMA), single",
    "c_exact_single": "C ... -ffp-contract=off, single",
    "c_one_exp_single": "C one exp per piece (hand-written), single",
    "numba_single": "iterate(), single",
    "numba_single_fma": "iterate(fma=True), single",
    "c_batch": "C -O3 -march=native (gcc default, FMA), batch",
    "c_exact_batch": "C ... -ffp-contract=off, batch",
    "c_batch_threads": "C -O3 -march=native, batch, T threads",
    "numba_batch": "iterate(out=, workers=1), batch",
    "numba_batch_threads": "iterate(out=, workers=T), batch",
    "numba_batch_fma": "iterate(out=, fma=True), batch",
    "numba_batch_alloc": "iterate(), batch (allocates its result)",
    "numba_batch_kernel": "numba batch kernel alone",
    "numba_scan": "the guards' scan of x0 alone (fused in iterate)",
    "numba_scan_threads": "the same scan alone on T threads",
    "numpy_batch": "numpy fallback iterate(), batch",
    "numpy_batch_kernel": "numpy fallback kernel alone, batch",
    "numpy_single_python": "numpy fallback, single (scalar Python loop)",
    "plain_python_loop": "plain Python loop over step_function",
}
#: (ours, peer, target or None): the ratios printed, ours / peer, from the best times.
RATIOS = [("numba_single_fma", "c_single", 1.05), ("numba_single", "c_exact_single", None),
          ("numba_single", "c_single", None), ("numba_single", "c_one_exp_single", 1.3),
          ("numba_single_fma", "c_one_exp_single", None),
          ("numba_batch", "c_batch", 1.5), ("numba_batch_threads", "c_batch_threads", 1.5),
          ("numba_batch_fma", "c_batch", 1.5), ("numba_batch", "c_exact_batch", 1.5),
          ("numba_batch_alloc", "c_batch", None), ("numba_batch_kernel", "c_batch", None),
          ("numpy_batch", "c_batch", 20.0), ("numpy_batch_kernel", "c_batch", None),
          ("numpy_single_python", "c_single", None), ("plain_python_loop", "c_single", None)]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--system", default="ho3")
    ap.add_argument("--word", default="32123")
    ap.add_argument("--h", type=float, default=0.1)
    ap.add_argument("--steps", type=int, default=10_000_000, help="steps of the single-trajectory runs")
    ap.add_argument("--batch", type=int, default=1_000_000, help="states of the batch runs")
    ap.add_argument("--batch-steps", type=int, default=50)
    ap.add_argument("--threads", type=int, default=None, help="threads of the threaded batch rows (default: all cores)")
    ap.add_argument("--numpy-steps", type=int, default=10, help="steps of the numpy batch run")
    ap.add_argument("--python-steps", type=int, default=20_000)
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--quick", action="store_true", help="1e6 steps, 1e5 states, 3 repeats")
    ap.add_argument("--json", action="store_true", help="also print the numbers as one JSON line")
    ap.add_argument("--rows", action="store_true", help="also print the README's iteration rows (markdown)")
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
    threads = args.threads or available_threads()
    print(f"# {system.name} {args.word}: {len(k.program.updates)} sub-flows, ~{k.program.n_operations} flops/step; "
          f"h = {args.h}; {args.repeats} rounds; threaded batch rows: T = {threads}")
    from concurrent.futures import ThreadPoolExecutor

    pool = ThreadPoolExecutor(max(1, threads))
    results = {}

    # -- compile times -------------------------------------------------------------------------------------
    if numba_available() and not args.no_compile_times:
        cold, warm = compile_times(args.system, args.word)
        results["compile_cold_s"] = cold["single"] + cold["batch"]
        results["compile_warm_s"] = warm["single"] + warm["batch"]
        print(f"kernel compile (empty cache, single + batch):   {results['compile_cold_s']:.2f} s "
              f"(import of nambu_bch {cold['import']:.2f} s)")
        print(f"kernel load from disk cache (single + batch):   {results['compile_warm_s']:.3f} s")

    # -- the contenders: (callable, trajectory-steps per call); all warmed up, then timed alternately ------------
    work = {}
    batch_work = args.batch_steps * args.batch
    finals, closers = {}, []
    try:
        from bench_iterate_c import DEFAULT_FLAGS, EXACT_FLAGS, CReference, c_compiler

        builds = {"c": CReference(k.program, DEFAULT_FLAGS), "c_exact": CReference(k.program, EXACT_FLAGS)} \
            if c_compiler() else {}
    except Exception as exc:  # no compiler, or compilation failed: report and go on
        print(f"(no C reference: {exc})")
        builds = {}
    for name, cref in builds.items():
        closers.append(cref)
        x, X = x0.copy(), X0.copy()

        def c_single(cref=cref, x=x):
            x[:] = x0
            cref.run(x, K, args.steps)

        def c_batch(cref=cref, X=X):  # the C loop advances X in place: a fresh copy of the start states each call
            np.copyto(X, X0)
            cref.run_batch(X, K, args.batch_steps, NUMBA_CHUNK)

        c_single(), c_batch()
        finals[f"{name}_single"], finals[f"{name}_batch"] = x.copy(), X.copy()
        work[f"{name}_single"] = (c_single, args.steps)
        work[f"{name}_batch"] = (c_batch, batch_work)
    if "c" in builds and threads > 1:  # the same C loop on T contiguous blocks of states, one thread each
        cref = builds["c"]
        blocks = [(lo, hi, np.empty((N, hi - lo))) for lo, hi in column_ranges(args.batch, NUMBA_CHUNK, threads)]

        def c_block(block, cref=cref):
            lo, hi, Xb = block
            np.copyto(Xb, X0[:, lo:hi])
            cref.run_batch(Xb, K, args.batch_steps, NUMBA_CHUNK)

        def c_batch_threads():
            list(pool.map(c_block, blocks))

        work["c_batch_threads"] = (c_batch_threads, batch_work)

    # Lotka-Volterra: the hand-written one-exp-per-piece C loop (the reference)
    if builds and system.name == "lotka-volterra":
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
        batch_out = {fma: np.empty((n_samples(args.batch_steps, args.batch_steps), N, args.batch)) for fma in (0, 1)}
        for fma in (False, True):  # compile / load outside the timing
            iterate(system, args.word, args.h, 10, x0, fma=fma, backend="numba")
            iterate(system, args.word, args.h, 10, X0[:, :10], fma=fma, backend="numba")

        def single(fma):
            holder["x", fma] = iterate(system, args.word, args.h, args.steps, x0, every=args.steps, fma=fma)[-1].copy()

        def batch(fma, workers=1):
            holder["X", fma, workers] = iterate(system, args.word, args.h, args.batch_steps, X0,
                                                every=args.batch_steps, fma=fma, out=batch_out[fma], workers=workers)

        work["numba_single"] = (lambda: single(False), args.steps)
        work["numba_single_fma"] = (lambda: single(True), args.steps)
        work["numba_batch"] = (lambda: batch(False), batch_work)
        work["numba_batch_fma"] = (lambda: batch(True), batch_work)
        if threads > 1:
            work["numba_batch_threads"] = (lambda: batch(False, threads), batch_work)
        work["numba_batch_alloc"] = (lambda: iterate(system, args.word, args.h, args.batch_steps, X0,
                                                     every=args.batch_steps, workers=1), batch_work)
        out = np.empty((2, N, args.batch))
        Xk = X0.copy()

        def kernel_batch():  # like the C loop: a fresh copy of the start states, advanced in place
            np.copyto(Xk, X0)
            k.run_batch(Xk, K, args.batch_steps, args.batch_steps, out)

        work["numba_batch_kernel"] = (kernel_batch, batch_work)
        # the guards' pass over x0 (non-finite, subnormal, extreme states) on its own: iterate() makes it inside
        # the batch loop as each chunk is loaded; per trajectory-step of the batch, to read against the rows above
        work["numba_scan"] = (lambda: k.scan(X0, 1), batch_work)
        if threads > 1:
            work["numba_scan_threads"] = (lambda: k.scan(X0, threads), batch_work)

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
    times = alternate(work, args.repeats)
    load_after = os.getloadavg()
    results["load_average"] = [round(v, 2) for v in load_before + load_after]
    print(f"load average (1, 5, 15 min) before {load_before[0]:.2f} {load_before[1]:.2f} {load_before[2]:.2f}, "
          f"after {load_after[0]:.2f} {load_after[1]:.2f} {load_after[2]:.2f} on {os.cpu_count()} CPUs "
          f"({args.repeats} rounds, contenders in turn)")
    if "numba_single" in work and "c_exact_single" in finals:
        same = (np.array_equal(holder["x", False], finals["c_exact_single"]),
                np.array_equal(holder["X", False, 1][-1], finals["c_exact_batch"]))
        print(f"iterate() == C -ffp-contract=off bit for bit: single {same[0]}, batch {same[1]}")
    if ("X", False, threads) in holder:
        print(f"iterate(workers={threads}) == iterate(workers=1) bit for bit: "
              f"{np.array_equal(holder['X', False, threads], holder['X', False, 1])}")
        for what, ours, theirs in (("single", holder["x", True], finals["c_single"]),
                                   ("batch", holder["X", True, 1][-1], finals["c_batch"])):
            ref = holder["x", False] if what == "single" else holder["X", False, 1][-1]
            rel = float(np.max(np.abs(ours - ref) / np.maximum(np.abs(ref), 1e-300)))
            print(f"iterate(fma=True), {what}: == C default build bit for bit {np.array_equal(ours, theirs)}; "
                  f"largest relative difference to the default run {rel:.1e}")
    if "numba_single" in work and "c_one_exp_single" in finals:
        ref = finals["c_one_exp_single"]
        rel = float(np.max(np.abs(holder["x", False] - ref) / np.abs(ref)))
        print(f"iterate() vs the one-exp C loop after {args.steps} steps: max relative difference {rel:.1e} (rounding)")

    # -- report --------------------------------------------------------------------------------------------------
    ns = {key: tuple(v * 1e9 for v in t) for key, t in times.items()}
    print(f"{'ns / trajectory-step':48s} {'best':>9s} {'median':>9s} {'CPU best':>9s}")
    for key, label in LABELS.items():
        if key in ns:
            print(f"{label:48s} {ns[key][0]:9.3f} {ns[key][1]:9.3f} {ns[key][2]:9.3f}")
    print(f"ratios, ours / peer (best; median in brackets), batch of {args.batch:.0e} x {args.batch_steps} steps:")
    ratios = {}
    for a, b, target in RATIOS:
        if a in ns and b in ns:
            r, rm = ns[a][0] / ns[b][0], ns[a][1] / ns[b][1]
            ratios[f"{a}/{b}"] = (r, rm)
            verdict = "" if target is None else f"  (target <= {target:g}: {'met' if r <= target else 'MISSED'})"
            print(f"  {LABELS[a]:44s} / {LABELS[b]:46s}: {r:6.2f} ({rm:5.2f}){verdict}")
    for ours, one in (("numba_batch_threads", "numba_batch"), ("c_batch_threads", "c_batch")):
        if ours in ns and one in ns:
            print(f"  speed-up on {threads} threads, {LABELS[ours]}: {ns[one][0] / ns[ours][0]:.2f}x "
                  f"(median {ns[one][1] / ns[ours][1]:.2f}x)" + ("  (target >= 1.8 on two cores: "
                  f"{'met' if ns[one][0] / ns[ours][0] >= 1.8 else 'MISSED'})" if ours.startswith("numba") else ""))
    if args.rows:
        print_rows(args, system, ns, ratios, results["load_average"])
    if args.json:
        print(json.dumps({"system": system.name, "word": args.word, "ns_per_step": ns,
                          "ratios": ratios, **{k2: v for k2, v in results.items()}}))
    pool.shutdown()
    for c in closers:
        c.close()


def print_rows(args, system, ns, ratios, load):
    """The README's iteration rows (markdown) from this run's numbers, labelled with the load."""
    where = f"load {load[0]:.1f}-{load[3]:.1f} on {os.cpu_count()} CPUs"
    cmd = f"`bench_iterate.py{'' if system.name == 'ho3' else f' --system {system.name} --word {args.word}'}`"
    rows = []

    def row(what, a, b, extra=""):
        if a in ns and b in ns:
            r, rm = ratios[f"{a}/{b}"]
            rows.append(f"| {what} ({cmd}, {where}) | {ns[a][0]:.2f} ns/step (median {ns[a][1]:.2f}) | "
                        f"{LABELS[b]}: {ns[b][0]:.2f} (median {ns[b][1]:.2f}) | {r:.2f}× (median {rm:.2f}×){extra} |")

    row(f"iteration, {system.name} {args.word}, one trajectory, `fma=True`", "numba_single_fma", "c_single")
    row(f"iteration, {system.name} {args.word}, one trajectory, default (bit-reproducible)", "numba_single",
        "c_exact_single")
    row(f"iteration, {system.name} {args.word}, one trajectory, default", "numba_single", "c_single")
    row(f"iteration, batch of {args.batch:.0e} x {args.batch_steps} steps, `iterate(out=)`", "numba_batch", "c_batch")
    row(f"iteration, same batch, `iterate(out=)` default (bit-reproducible)", "numba_batch", "c_exact_batch")
    row(f"iteration, same batch, `iterate(out=, fma=True)`", "numba_batch_fma", "c_batch")
    row(f"iteration, same batch, `iterate(out=, workers=T)` vs C on T threads (T = {args.threads or available_threads()})",
        "numba_batch_threads", "c_batch_threads")
    row(f"iteration, same batch, `iterate()` allocating its result", "numba_batch_alloc", "c_batch")
    row(f"numpy fallback, batch of {args.batch:.0e} x {args.numpy_steps} steps", "numpy_batch", "c_batch")
    print("\n".join(rows))


if __name__ == "__main__":
    main()
