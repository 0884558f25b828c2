"""optimize_composition's float evaluation: per polynomial (as before) against one array per group (``_FloatStack``).

Both sides run in this process, interleaved, ``--repeats`` rounds, on the same templates; each round times a whole
``optimize_composition`` call by CPU (``time.process_time``) and wall, and checks that both sides give the same
designed composition (the float values are bit for bit the same, so the critical points found are too).  The
"per polynomial" side is the former ``_Problem.values`` (``_PolyEval.float`` on each polynomial of the nested
lists), patched in for its rounds.  The load average is printed at the start and the end.

    python benchmarks/bench_optimize.py [--repeats 2]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from nambu_bch.design import optimize as O  # noqa: E402

STACKED = O._Problem.values
CASES = (dict(spec="strang", parts=3, order=4, stages=5), dict(spec="strang", parts=2, order=6, stages=7))


def per_polynomial(self, name, x, lib):
    """The former ``_Problem.values``: each polynomial evaluated on its own."""
    if lib == "mp":
        return STACKED(self, name, x, lib)

    def ev(obj):
        return [ev(o) for o in obj] if isinstance(obj, list) else obj.float(x)

    return ev(getattr(self, name))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=2)
    args = parser.parse_args(argv)
    print(f"load at start: {os.getloadavg()}")
    O.optimize_composition(**CASES[0])  # warm: sympy's caches, the imports
    cpu, wall, results = {}, {}, {}
    for _ in range(args.repeats):
        for side, values in (("per polynomial", per_polynomial), ("one array", STACKED)):
            O._Problem.values = values
            for case in CASES:
                key = (side, case["order"], case["stages"])
                t, w = time.process_time(), time.perf_counter()
                D = O.optimize_composition(**case)
                cpu.setdefault(key, []).append(time.process_time() - t)
                wall.setdefault(key, []).append(time.perf_counter() - w)
                results.setdefault(key[1:], set()).add(repr(D.summary()))
    O._Problem.values = STACKED
    print("| evaluation | order | stages | CPU median (s) | wall median (s) |")
    print("|---|---|---|---|---|")
    for key in cpu:
        print(f"| {key[0]} | {key[1]} | {key[2]} | {statistics.median(cpu[key]):.2f} | {statistics.median(wall[key]):.2f} |")
    same = all(len(v) == 1 for v in results.values())
    print(f"same designed compositions on both sides: {same}")
    print(f"load at end: {os.getloadavg()}")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
