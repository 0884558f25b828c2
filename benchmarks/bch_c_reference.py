"""Formal BCH: ours against Hofstätter's C program ``bch``, both cold, ratios measured in one run.

The C program (github.com/HaraldHofstaetter/BCH) is NOT vendored: pass the path of a local
checkout; this script builds it with its own Makefile at its strongest flags
(``CFLAGS=-O3 -fPIC -march=native -fopenmp``), then for every degree runs

* C, cold: a fresh ``bch`` process, single-threaded (``OMP_NUM_THREADS=1``), CPU time
  (user + sys, ``getrusage``) and peak RSS of the child; output to a file;
* ours, cold: a fresh Python interpreter (``formal_bch`` imported, with sympy; numba not yet
  imported, its cached machine code on disk), CPU time of the ``formal_bch`` call alone, which
  includes importing and starting numba when the sparse engine runs, and the RSS growth of that call;
* ours, data memory: in a third fresh interpreter, numba started first (a small sparse series),
  the peak-RSS growth of the call: the engine's own memory, comparable with the C process's;
* ours, warm: the same call again in that interpreter, numba started (if the cold call took the
  dense engine, a small sparse series runs first, untimed) and every in-memory cache of the
  package cleared (``nambu_bch.clear_caches``: Lyndon tables rebuilt).  The column ``engine``
  names the engine of the cold / warm call: ``formal_bch`` takes the dense engine for small
  problems in a process where numba has not started yet, the sparse one once it has.

Every run is checked: the C table (``table_output=1``: index, degree, standard factors,
coefficient) is rebuilt into Lyndon words and compared coefficient by coefficient with ours.

Run:  python benchmarks/bch_c_reference.py /path/to/BCH [--degrees 10,12,14,16,18,20] [--no-build]

Workloads: ``log(e^A e^B)`` (pieces "12") at the given degrees, and the five-factor Strang word
12321 (``log(e^{A/2} e^{B/2} e^C e^{B/2} e^{A/2})``) at degrees 9 and 11.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CFLAGS = "-O3 -fPIC -march=native -fopenmp -Wall"

OURS = r"""
import json, resource, sys, time
from nambu_bch import clear_caches
from nambu_bch.bch import formal_bch
spec, n, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
t = time.process_time(); B = formal_bch(spec, n); cold = time.process_time() - t  # imports numba if it needs it
rss1 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
engine = "sparse" if "nambu_bch.bch.modular" in sys.modules and sys.modules["nambu_bch.bch.modular"].runs else "dense"
from nambu_bch.bch import modular
if not modular.runs:  # warm = numba started: a small sparse series first (3^10 words > DENSE_COLD_WORDS)
    formal_bch("123", 10)
clear_caches()  # every in-memory cache of the package (Lyndon tables, the dense engine's logs, ...)
runs = modular.runs
t = time.process_time(); formal_bch(spec, n); warm = time.process_time() - t
engine_warm = "sparse" if modular.runs > runs else "dense"
rows = [[list(w), str(c)] for d in range(1, n + 1) for c, w in B.words(d)]
json.dump({"cold": cold, "warm": warm, "rss_kb": rss1 - rss0, "rss_total_kb": rss1, "terms": rows,
           "engine": engine + "/" + engine_warm}, open(out, "w"))
"""


DATA = r"""
import resource, sys
from nambu_bch.bch import formal_bch
formal_bch("123", 10)  # numba imported and started, engine code loaded (3^10 words: the sparse engine)
spec, n = sys.argv[1], int(sys.argv[2])
rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
formal_bch(spec, n)
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - rss0)
"""


def build(checkout: Path) -> Path:
    subprocess.run(["make", "-C", str(checkout), "clean"], check=True, capture_output=True)
    subprocess.run(["make", "-C", str(checkout), f"CFLAGS={CFLAGS}", "bch"], check=True, capture_output=True)
    exe = checkout / "bch"
    if not exe.exists():
        raise SystemExit(f"build failed: no {exe}")
    return exe


TIME = Path("/usr/bin/time")


def run_c(exe: Path, n: int, expression: str | None, out: Path):
    """CPU seconds, peak RSS (kB) and the table of one cold single-threaded run.

    CPU time from this process's ``wait4`` on the ``bch`` child.  The peak RSS from a second run
    under ``/usr/bin/time`` when it exists: Linux keeps ``ru_maxrss`` across ``execve``, so a child
    forked from this (large) Python process reports at least this process's size.  Without
    ``/usr/bin/time`` the value is that upper bound."""
    env = dict(os.environ, OMP_NUM_THREADS="1", LD_LIBRARY_PATH=str(exe.parent))
    args = [str(exe), f"N={n}", "table_output=1"]
    if expression:
        args.append(f"expression={expression}")
    with open(out, "w") as fh:
        proc = subprocess.Popen(args, stdout=fh, env=env)
        _, status, usage = os.wait4(proc.pid, 0)  # this child's own rusage (CPU and peak RSS)
        proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode:
        raise SystemExit(f"bch failed with exit code {proc.returncode}: {' '.join(args)}")
    rss = usage.ru_maxrss
    if TIME.exists():
        report = out.with_suffix(".time")
        subprocess.run([str(TIME), "-f", "%M", "-o", str(report)] + args, stdout=subprocess.DEVNULL, env=env,
                       check=True)
        rss = int(report.read_text().split()[-1])
    return usage.ru_utime + usage.ru_stime, rss, out.read_text().splitlines()


def c_terms(lines, letters: int) -> dict:
    """``{Lyndon word (letters 0..): Fraction}`` from the C table (standard factors p1, p2 per basis element)."""
    words, out = {}, {}
    for line in lines:
        fields = line.split()
        if len(fields) != 5:
            continue
        i, d, p1, p2, c = int(fields[0]), int(fields[1]), int(fields[2]), int(fields[3]), Fraction(fields[4])
        words[i] = (i,) if d == 1 and i < letters else words[p1] + words[p2]
        if c:
            out[words[i]] = c
    return out


def run_ours(spec: str, n: int, out: Path):
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    subprocess.run([sys.executable, "-c", OURS, spec, str(n), str(out)], check=True, env=env, cwd=ROOT)
    data = json.loads(out.read_text())
    memory = subprocess.run([sys.executable, "-c", DATA, spec, str(n)], check=True, env=env, cwd=ROOT,
                            capture_output=True, text=True)
    data["data_kb"] = int(memory.stdout.split()[-1])
    terms = {}
    for word, c in data["terms"]:
        key = tuple(k - 1 for k in word)  # piece k is the letter k - 1 (A = 1, B = 2, C = 3)
        terms[key] = Fraction(c)
    return data, terms


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("checkout", type=Path, help="local checkout of github.com/HaraldHofstaetter/BCH (not vendored)")
    ap.add_argument("--degrees", default="10,12,14,16,18,20")
    ap.add_argument("--no-build", action="store_true", help="use the existing ./bch of the checkout")
    ap.add_argument("--work", type=Path, default=Path("/tmp/bch_c_reference"))
    args = ap.parse_args(argv)
    checkout = args.checkout.resolve()
    if not (checkout / "Makefile").exists() or not (checkout / "bch.c").exists():
        print(f"error: {checkout} is not a checkout of HaraldHofstaetter/BCH (no Makefile / bch.c)", file=sys.stderr)
        return 2
    exe = checkout / "bch" if args.no_build else build(checkout)
    args.work.mkdir(parents=True, exist_ok=True)
    jobs = [("12", int(d), None) for d in args.degrees.split(",")]
    jobs += [("12321", d, "log(exp(1/2*A)*exp(1/2*B)*exp(C)*exp(1/2*B)*exp(1/2*A))") for d in (9, 11)]
    print(f"# C: {exe} built with CFLAGS='{CFLAGS}', OMP_NUM_THREADS=1; CPU seconds; both sides cold (fresh processes)")
    print(f"{'word':>6} {'N':>3} {'terms':>7} {'C cpu s':>9} {'ours cold':>10} {'ratio':>7} {'ours warm':>10} "
          f"{'ratio':>7} {'C MB':>6} {'ours +MB':>8} {'data MB':>7}  identical  engine")
    for spec, n, expr in jobs:
        cpu, rss, lines = run_c(exe, n, expr, args.work / f"c_{spec}_{n}.txt")
        data, ours = run_ours(spec, n, args.work / f"ours_{spec}_{n}.json")
        reference = c_terms(lines, 3 if expr else 2)
        same = reference == ours
        print(f"{spec:>6} {n:>3} {len(ours):>7} {cpu:>9.4f} {data['cold']:>10.4f} {data['cold'] / max(cpu, 1e-4):>6.1f}x "
              f"{data['warm']:>10.4f} {data['warm'] / max(cpu, 1e-4):>6.1f}x {rss / 1024:>6.1f} {data['rss_kb'] / 1024:>8.1f}"
              f" {data['data_kb'] / 1024:>7.1f}"
              f"  {str(same):9}  {data['engine']}")
    print("# ratio = ours / C (CPU time; C's includes process start and writing the table; C times below 1e-4 s "
          "count as 1e-4 s). 'C MB': peak RSS of the C process. 'ours +MB': peak-RSS growth of the cold call "
          "(importing numba included; the interpreter with sympy holds ~130 MB before it). 'data MB': peak-RSS "
          "growth of the call in a fresh process where numba is already started (the engine's own memory).")
    return 0


if __name__ == "__main__":
    sys.exit(main())
