"""The four fast-tier tests that pay for an invariant search, cold, in two checkouts, interleaved.

One ``pytest -q -n 0`` process per test and checkout, each with an empty ``NAMBU_BCH_CACHE``; the checkouts
alternate (which goes first flips every round).  Printed per run: pytest's ``call`` duration, the process's wall
and CPU (user + sys of the child) and the load average before it.  Usage::

    git -C . archive <old commit> | tar -x -C /tmp/old
    python benchmarks/bench_invariant_tests.py --base /tmp/old --new . [--rounds 2]
"""

from __future__ import annotations

import argparse
import os
import re
import resource
import subprocess
import sys
import tempfile
import time

TESTS = ("tests/test_cli.py::test_check",
         "tests/test_hardening_numeric.py::test_rigid_body_default_parameters_run",
         "tests/test_exact_invariants.py::test_no_invariant_near_H_for_rigid_body",
         "tests/test_exact_invariants.py::test_exponential_map_lotka_volterra")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", required=True, help="the older checkout")
    parser.add_argument("--new", required=True, help="the newer checkout")
    parser.add_argument("--rounds", type=int, default=2)
    args = parser.parse_args()
    sides = [("base", os.path.abspath(args.base)), ("new", os.path.abspath(args.new))]
    with tempfile.TemporaryDirectory(prefix="bench_invariant_tests_") as scratch:
        for r in range(args.rounds):
            for test in TESTS:
                for side, root in (sides if r % 2 == 0 else sides[::-1]):
                    env = dict(os.environ, PYTHONPATH=root, NAMBU_BCH_CACHE=tempfile.mkdtemp(dir=scratch),
                               MPLBACKEND="Agg")
                    before, load = resource.getrusage(resource.RUSAGE_CHILDREN), os.getloadavg()[0]
                    start = time.perf_counter()
                    out = subprocess.run([sys.executable, "-m", "pytest", "-q", "-n", "0", "-p", "no:cacheprovider",
                                          "--durations=1", test], cwd=root, env=env, capture_output=True,
                                         text=True).stdout
                    wall = time.perf_counter() - start
                    after = resource.getrusage(resource.RUSAGE_CHILDREN)
                    cpu = after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
                    call = re.search(r"([\d.]+)s call", out)
                    status = "ok" if "passed" in out and "failed" not in out else "FAIL"
                    name, took = test.split("::")[1][:45], call.group(1) if call else "-"
                    print(f"round {r} {side:4s} {name:45s} call {took:>5s} s"
                          f"  process wall {wall:5.2f} s cpu {cpu:5.2f} s  load {load:.2f}  {status}", flush=True)


if __name__ == "__main__":
    main()
