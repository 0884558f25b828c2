"""A sweep of many small ``check`` tasks: serial, joblib's loky and a local Dask cluster, in one run.

Every backend runs the same ``--tasks`` tasks (``check`` of ho3 with 32123, ``--steps`` steps, H and G
only, the starting point and the step varied), the results are compared with the serial ones (their
``to_dict()``, which holds every number but the wall time), and each backend's wall time is printed
with the load average.  The parallel wall times include starting the worker processes (loky's are
reused by joblib between calls; the Dask cluster is started outside the timing).  CPU time of
this process is printed too; the workers' CPU is not in it.

Usage (from the repository root):
    python benchmarks/bench_sweep.py                     # 1000 tasks, 2 workers
    python benchmarks/bench_sweep.py --tasks 200 --workers 2 --no-dask
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import nambu_bch as nb  # noqa: E402


def tasks(count, steps):
    hs = (0.05, 0.1, 0.2, 0.4)
    return [{"system": "ho3", "word": "32123", "h": hs[i % len(hs)], "steps": steps,
             "x0": (1.0, 0.001 * i, 1.0 + 0.0005 * i), "include": ("H", "G")} for i in range(count)]


def timed(fn):
    wall, cpu = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - wall, time.process_time() - cpu


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tasks", type=int, default=1000)
    parser.add_argument("--steps", type=int, default=200)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--no-dask", action="store_true")
    args = parser.parse_args(argv)
    work = tasks(args.tasks, args.steps)
    nb.sweep(nb.check, work[:2], backend="serial")  # warm this process (imports, ho3's expressions)
    print(f"{args.tasks} tasks of check(ho3, 32123, steps={args.steps}); load {os.getloadavg()}")
    serial, wall, cpu = timed(lambda: nb.sweep(nb.check, work, backend="serial"))
    reference = [r.to_dict() for r in serial]
    print(f"serial          wall {wall:7.2f} s  cpu {cpu:7.2f} s")
    loky, wall, cpu = timed(lambda: nb.sweep(nb.check, work, backend="loky", n_jobs=args.workers))
    print(f"loky x{args.workers}         wall {wall:7.2f} s  cpu {cpu:7.2f} s  (cold workers)  "
          f"identical: {[r.to_dict() for r in loky] == reference}")
    loky, wall, cpu = timed(lambda: nb.sweep(nb.check, work, backend="loky", n_jobs=args.workers))
    print(f"loky x{args.workers}         wall {wall:7.2f} s  cpu {cpu:7.2f} s  (warm workers)  "
          f"identical: {[r.to_dict() for r in loky] == reference}")
    if not args.no_dask:
        from distributed import Client, LocalCluster

        with tempfile.TemporaryDirectory() as scratch, \
                LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True, dashboard_address=None,
                             local_directory=scratch) as cluster, Client(cluster) as client:
            for label in ("cold", "warm"):
                dask, wall, cpu = timed(lambda: nb.sweep(nb.check, work, client=client))
                print(f"dask x{args.workers}         wall {wall:7.2f} s  cpu {cpu:7.2f} s  ({label} workers)  "
                      f"identical: {[r.to_dict() for r in dask] == reference}")
    print(f"load {os.getloadavg()}")


if __name__ == "__main__":
    main()
