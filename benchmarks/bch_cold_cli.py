"""Cold processes of the BCH table's series: this checkout against a baseline checkout, interleaved.

Two requests, each a whole process measured by ``/usr/bin/time`` (CPU = user + sys, wall, peak RSS):

* ``cli``: ``python -m nambu_bch bch --model ho --integrator TVT --order 12 --format text`` (and ``json``), the
  command line printing a series the shipped table serves;
* ``formal``: the cold process of ``benchmarks/bch_c_reference.py`` (``OURS_COLD``, taken from each checkout's own
  copy of that script): ``formal_bch('12', 18)`` and every term written to a file.

Each side runs with its bytecode cached in a directory of its own (``PYTHONPYCACHEPREFIX``, written by one untimed
run first), as an installed package has it; the sides alternate, ``--repeat`` runs each, medians printed with the
load average.  The children run in ``--work`` (``python -m`` and ``-c`` put the working directory first on
``sys.path``: a checkout there would shadow ``PYTHONPATH``); nothing is written outside it.

Run:  python benchmarks/bch_cold_cli.py --baseline /path/to/other/checkout [--repeat 5]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TIME = Path("/usr/bin/time")
CLI = ["-m", "nambu_bch", "bch", "--model", "ho", "--integrator", "TVT", "--order", "12", "--format"]


def cold_script(checkout: Path) -> str:
    """``OURS_COLD`` of the checkout's ``benchmarks/bch_c_reference.py`` (its own way of writing the series)."""
    namespace: dict = {}
    source = (checkout / "benchmarks" / "bch_c_reference.py").read_text()
    start = source.index('OURS_COLD = r"""')
    exec(source[start : source.index('"""', start + 16) + 3], namespace)
    return namespace["OURS_COLD"]


def timed(args, env, report: Path):
    """``(cpu s, wall s, peak RSS MB)`` of one child process."""
    subprocess.run([str(TIME), "-f", "%U %S %e %M", "-o", str(report), *args], env=env, check=True,
                   stdout=subprocess.DEVNULL, cwd=report.parent)
    user, system, wall, rss = report.read_text().split()[-4:]
    return float(user) + float(system), float(wall), int(rss) / 1024


#: A fresh process of one side: CPU seconds of its phases (``time.process_time`` at each point, the interpreter's
#: start being the time before the first statement), modules imported, peak RSS after the import.
PHASES = r"""
import resource, sys, time
clock = time.process_time
t0, before = clock(), len(sys.modules)
from nambu_bch.bch import formal_bch
t1, modules = clock(), len(sys.modules) - before
rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
B = formal_bch("12", 18)
t2 = clock()
digits = bytes.maketrans(bytes(range(10)), b"0123456789")
with open(sys.argv[1], "w") as fh:
    for d in range(1, 19):
        if hasattr(B, "iter_scaled_words"):
            den, items = B.iter_scaled_words(d)
        else:
            from nambu_bch.bch.lyndon import tree_leaves
            den, items = B.scaled_terms(d)
            items = [(n, tree_leaves(t)) for n, t in items]
        fh.writelines("%s %d %d\n" % (bytes(w).translate(digits).decode(), n, den) for n, w in items)
print(t0, t1 - t0, t2 - t1, clock() - t2, modules, rss)
"""

#: The warm degree-10 call of this checkout by part (in this process; ``clear_caches()`` before each call).
WARM_PARTS = r"""
import time
from nambu_bch import clear_caches
from nambu_bch.bch import formal, formal_bch, table
from nambu_bch.bch.light import parse_word

def best(f, k=2000):
    out = []
    for _ in range(5):
        t = time.process_time()
        for _ in range(k):
            f()
        out.append((time.process_time() - t) / k * 1e6)
    return min(out)

def header():
    table._HEADER.clear()
    table._header()

formal_bch("12", 10)
h = table._header()

def load():
    table._FACTORS.clear()
    table._NUMERATORS.clear()
    table._load(h, "12", 10)

word = parse_word("12")
whole = best(lambda: (clear_caches(), formal_bch("12", 10))) - best(clear_caches)
parts = {"header read and parsed": best(header), "degrees 1-10 checked and decoded": best(load),
         "the request (decoded table in hand)": best(lambda: formal._from_table(word, [1, 1], [1, 1], 10))}
print("; ".join(f"{k} {v:.0f} us" for k, v in parts.items()) + f"; whole call {whole:.0f} us")
"""


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", type=Path, required=True, help="another checkout of this package (e.g. main)")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--work", type=Path, default=Path("/tmp/bch_cold_cli"))
    args = ap.parse_args(argv)
    if not TIME.exists():
        print(f"error: {TIME} is needed to measure the children's CPU time and peak RSS", file=sys.stderr)
        return 2
    args.work.mkdir(parents=True, exist_ok=True)
    sides = {"baseline": args.baseline.resolve(), "this": ROOT}
    base_env = {k: v for k, v in os.environ.items() if k not in ("PYTHONDONTWRITEBYTECODE", "PYTHONPATH")}
    envs = {name: dict(base_env, PYTHONPATH=str(path), PYTHONPYCACHEPREFIX=str(args.work / f"pyc_{name}"))
            for name, path in sides.items()}
    requests = {
        "cli text": lambda name: [sys.executable, *CLI, "text"],
        "cli json": lambda name: [sys.executable, *CLI, "json"],
        "formal 12 18": lambda name: [sys.executable, "-c", cold_script(sides[name]), "12", "18",
                                      str(args.work / f"series_{name}.txt")],
    }
    for name in sides:  # untimed: the bytecode written, the files in the page cache
        for make in requests.values():
            subprocess.run(make(name), env=envs[name], check=True, stdout=subprocess.DEVNULL, cwd=args.work)
    print(f"# baseline {sides['baseline']}, this {sides['this']}; {sys.executable}; each side's bytecode cached")
    print(f"{'request':>13} {'side':>8} | {'CPU s':>6} {'wall s':>6} {'MB':>6} | median of {args.repeat} | load")
    for label, make in requests.items():
        rows = {name: [] for name in sides}
        for _ in range(args.repeat):
            for name in sides:
                rows[name].append(timed(make(name), envs[name], args.work / "time.txt"))
        medians = {name: [statistics.median(r[i] for r in rows[name]) for i in range(3)] for name in sides}
        for name in sides:
            cpu, wall, rss = medians[name]
            print(f"{label:>13} {name:>8} | {cpu:>6.3f} {wall:>6.2f} {rss:>6.1f} | "
                  f"CPU {cpu / max(medians['baseline'][0], 1e-9):.2f}x baseline | {os.getloadavg()[0]:.2f}", flush=True)
    print(f"# phases of one fresh process (CPU s; median of {args.repeat}): start = the interpreter before the first "
          "statement, import = from nambu_bch.bch import formal_bch (modules it adds; RSS MB after it), call = "
          "formal_bch('12', 18), write = every term as 'word numerator denominator' (words from iter_scaled_words "
          "where the checkout has it, else tree_leaves)")
    for name in sides:
        runs = []
        for _ in range(args.repeat):
            out = subprocess.run([sys.executable, "-c", PHASES, str(args.work / f"phases_{name}.txt")], env=envs[name],
                                 check=True, capture_output=True, text=True, cwd=args.work).stdout.split()
            runs.append([float(v) for v in out])
        start, imp, call, write, modules, rss = (statistics.median(r[i] for r in runs) for i in range(6))
        print(f"# {name:>8}: start {start:.3f} import {imp:.3f} ({modules:.0f} modules, {rss:.1f} MB) call {call:.3f} "
              f"write {write:.3f} | load {os.getloadavg()[0]:.2f}")
    parts = subprocess.run([sys.executable, "-c", WARM_PARTS], env=envs["this"], check=True, capture_output=True,
                           text=True, cwd=args.work).stdout.strip()
    print(f"# this checkout's warm formal_bch('12', 10) by part (best of 5 x 2000 calls): {parts} | load "
          f"{os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
