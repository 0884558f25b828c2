"""Steps per pass over a chunk in the compiled batch loop (``codegen.JAM_STEPS``): 1, 2 and 4, interleaved.

The batch kernel advances a 256-state chunk ``JAM_STEPS`` steps per state before moving to the next state
(:func:`nambu_bch.numeric.codegen._chunk_step`); each state goes through the same operations whatever the value,
so the script first checks that the three loops give the same bits, then times them in turn (``--repeats``
rounds, CPU time, best and median per state-step, the load average printed): a chunk that stays in cache
(compute only) and the 10^6-state batch of bench_iterate.py.  It prints the CPU each loop's compilation took
first (the loops compiled one after the other in this process, the shared guards' scan before them).

Usage (from the repository root):
    python benchmarks/bench_iterate_jam.py [--system ho3 --word 32123 --repeats 9]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import types
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--system", default="ho3")
    ap.add_argument("--word", default="32123")
    ap.add_argument("--repeats", type=int, default=9)
    args = ap.parse_args(argv)
    import numba

    from nambu_bch.numeric import codegen, kernel
    from nambu_bch.compiled import dispatcher
    from nambu_bch.numeric.codegen import SCAN_FUNCTION
    from nambu_bch.numeric.scan import scan_into

    k = kernel(args.system, args.word)
    K = k.constants(0.1)
    saved, loops = codegen.JAM_STEPS, {}
    try:
        for jam in (1, 2, 4):
            codegen.JAM_STEPS = jam
            module = types.ModuleType(f"nambu_bch_jam{jam}")
            exec(compile(codegen.python_source(k.program), module.__name__, "exec"), module.__dict__)  # noqa: S102
            module.__dict__[SCAN_FUNCTION] = dispatcher(scan_into)  # compiled code calls the numba dispatcher
            loops[jam] = numba.njit(nogil=True, error_model="numpy")(module.run_batch)
    finally:
        codegen.JAM_STEPS = saved
    none = np.zeros(0, dtype=np.int64)
    from nambu_bch.numeric.scan import RESULT_SIZE, scan_range

    scan_range(np.ones((k.N, 8)), 0, 8, np.zeros(RESULT_SIZE, dtype=np.int64))  # the shared scan: compiled first
    compile_cpu = {}
    for jam, fn in loops.items():  # the first call compiles (this process's numba cache is in memory only)
        c0 = time.process_time()
        fn(np.ones((k.N, 8)), K, 2, 2, np.empty((2, k.N, 8)), 256, 1, 0, 0, 8, none)
        compile_cpu[jam] = time.process_time() - c0
    print(f"# compile CPU of the batch loop (load {os.getloadavg()[0]:.2f}): "
          + ", ".join(f"{jam} step(s) per pass {c:.2f} s" for jam, c in compile_cpu.items()))
    print(f"# {args.system} {args.word}: batch loop with 1, 2, 4 steps per pass over a 256-state chunk "
          f"(package default {saved}); {args.repeats} rounds, CPU time, interleaved")
    for B, steps, what in ((4096, 2000, "4096 states x 2000 steps (in cache)"), (10**6, 50, "10^6 states x 50 steps")):
        X0 = np.random.default_rng(0).uniform(0.5, 1.5, size=(k.N, B))
        out = np.empty((2, k.N, B))
        finals = []
        for fn in loops.values():
            fn(X0, K, steps, steps, out, 256, 1, 0, 0, B, none)
            finals.append(out[-1].copy())
        same = all(np.array_equal(finals[0], f) for f in finals)
        cpu = {jam: [] for jam in loops}
        load = os.getloadavg()
        for _ in range(args.repeats):
            for jam, fn in loops.items():
                c0 = time.process_time()
                fn(X0, K, steps, steps, out, 256, 1, 0, 0, B, none)
                cpu[jam].append(time.process_time() - c0)
        print(f"{what}: same bits {same}; load {load[0]:.2f} before, {os.getloadavg()[0]:.2f} after")
        for jam, values in cpu.items():
            print(f"  {jam} step(s) per pass: CPU best {min(values) / B / steps * 1e9:.3f}, "
                  f"median {float(np.median(values)) / B / steps * 1e9:.3f} ns/state-step")


if __name__ == "__main__":
    main()
