"""The CPU of one numba compile per generated loop, in a fresh process and an empty kernel cache.

The per-kind table of docs/suite_time.md ("Session 20") comes from this file:

    PYTHONPATH=$PWD python tools/compile_cost.py ho3 32123 run_batch lotka-volterra 12321 run_batch_kahan ...

Arguments are triples ``SYSTEM WORD LOOP`` (``LOOP``: ``run``, ``run_kahan``, ``run_batch``, ``run_batch_kahan``, each
optionally ending in ``+fma``: the loop of ``fma=True``), or ``rk SYSTEM METHOD`` for the Runge-Kutta module.  The
guards' scan the batch loops call (:func:`nambu_bch.numeric.scan.scan_into`) is compiled first and printed on its own
line, so that it is not counted in the first batch loop.  Each line gives the process CPU (user + sys) of the compile
and the load average after it; time two trees by running this once per tree, interleaved.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time


def main(argv=None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    if not args or len(args) % 3:
        print("usage: compile_cost.py SYSTEM WORD LOOP [SYSTEM WORD LOOP ...] (or rk SYSTEM METHOD)", file=sys.stderr)
        return 2
    os.environ["NAMBU_BCH_CACHE"] = tempfile.mkdtemp(prefix="compile_cost_")  # nothing loaded from a cache
    import numpy as np

    from nambu_bch import model
    from nambu_bch.compiled import dispatcher
    from nambu_bch.numeric import kernel
    from nambu_bch.numeric.runge_kutta import iterate_runge_kutta
    from nambu_bch.numeric.scan import RESULT_SIZE, scan_into

    def timed(label, work):
        start = time.process_time()
        work()
        print(f"{time.process_time() - start:6.2f} s CPU  {label}  (load {os.getloadavg()[0]:.1f})", flush=True)

    timed("scan_into", lambda: dispatcher(scan_into)(np.zeros((2, 1)), 0, 1, np.zeros((2, 3, 1)),
                                                      np.zeros(RESULT_SIZE, dtype=np.int64)))
    for first, second, third in zip(args[::3], args[1::3], args[2::3]):
        if first == "rk":
            system = model(second)
            timed(f"rk {second} {third}", lambda: iterate_runge_kutta(system, third, 0.01, 1, (0.5,) * system.N,
                                                                    backend="numba"))
            continue
        loop, _, fma = third.partition("+")
        k = kernel(model(first), second)
        timed(f"{first} {second} {third}", lambda: k.compile(kahan="kahan" in loop, batch="batch" in loop,
                                                             fma=bool(fma)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
