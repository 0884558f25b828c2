"""The command line's parser: building it (what ``main`` did on every call) against parsing with the built one.

``main`` now builds its parser once per process (``nambu_bch.cli._main._parser``); an in-process caller of ``main``
(a notebook, the test suite) paid a build per call before.  Both are timed here in one process, interleaved,
``--rounds`` rounds of ``--calls`` calls each (CPU by ``time.process_time``, per call); the load average is printed
at the start and the end.

    python benchmarks/bench_cli_parser.py [--rounds 5] [--calls 50]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from nambu_bch.cli import _main, build_parser  # noqa: E402

ARGV = ["check", "--model", "rigid-body", "--steps", "10", "--x0", "1,2,3", "--format", "json"]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--calls", type=int, default=50)
    args = parser.parse_args(argv)
    print(f"load at start: {os.getloadavg()}")
    build_parser()  # the subcommand modules imported once, as in any process that ran main
    built = _main._parser()
    times = {"build_parser()": [], "parse with the built parser": []}
    for _ in range(args.rounds):
        for label, work in (("build_parser()", build_parser),
                            ("parse with the built parser", lambda: built.parse_known_args(ARGV))):
            t = time.process_time()
            for _ in range(args.calls):
                work()
            times[label].append((time.process_time() - t) / args.calls)
    print("| per call | CPU median (ms) |")
    print("|---|---|")
    for label, values in times.items():
        print(f"| {label} | {1000 * statistics.median(values):.2f} |")
    print(f"load at end: {os.getloadavg()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
