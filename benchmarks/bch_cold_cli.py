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
    return 0


if __name__ == "__main__":
    sys.exit(main())
