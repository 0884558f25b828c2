"""What printing from the exact data saves: ``shadow_hamiltonians`` plus its outputs, this tree against another.

Run:  /work/venv/bin/python benchmarks/bench_results.py --baseline DIR [--repeat 2] [--rows a,b,c]

``DIR`` is another source tree of the package (e.g. ``git archive 36359ea | tar -x -C DIR``).  Each row runs one
request in a fresh process per tree, the two trees interleaved (baseline, this tree, baseline, ...), and prints for
each tree the best process CPU seconds (and wall) of

* ``compute``: ``shadow_hamiltonians(...)`` alone;
* ``+json``: then ``to_dict()`` (what a program reading the JSON pays, no text or LaTeX);
* ``+all``: then ``to_text()`` and ``to_latex()`` as well (what ``nambu-bch shadow`` pays for the three formats);

with the load average at the start of each row.  The outputs of the two trees are compared (SHA-256 of text,
LaTeX and JSON): a row whose outputs differ is marked.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: (key, model, word, order) of each row
ROWS = (
    ("a", "ho3", "12321", 6),
    ("b", "lotka-volterra", "12321", 6),
    ("c", "rigid-body", "12321", 4),
    ("d", "rigid-body", "12321", 6),
)

CHILD = r"""
import hashlib, json, sys, time
model, word, order = sys.argv[1], sys.argv[2], int(sys.argv[3])
import nambu_bch
from nambu_bch.shadow import shadow_hamiltonians
from nambu_bch.systems import model as get_model
S = get_model(model)
c0, w0 = time.process_time(), time.perf_counter()
F = shadow_hamiltonians(S, word, order=order)
c1, w1 = time.process_time(), time.perf_counter()
d = json.dumps(F.to_dict(), sort_keys=True)
c2, w2 = time.process_time(), time.perf_counter()
t, l = F.to_text(), F.to_latex()
c3, w3 = time.process_time(), time.perf_counter()
digest = hashlib.sha256("\x00".join((t, l, d)).encode()).hexdigest()[:12]
print(json.dumps({"cpu": [c1 - c0, c2 - c0, c3 - c0], "wall": [w1 - w0, w2 - w0, w3 - w0], "digest": digest}))
"""


def run(tree: Path, row) -> dict:
    env = dict(os.environ, PYTHONPATH=str(tree), NAMBU_BCH_PROGRESS="0")
    out = subprocess.run([sys.executable, "-c", CHILD, *map(str, row[1:])], env=env, capture_output=True, text=True,
                         check=True, cwd=tree)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", required=True, type=Path, help="another source tree of the package")
    parser.add_argument("--repeat", type=int, default=2, help="fresh processes per tree and row (best is printed)")
    parser.add_argument("--rows", default="abcd", help="row keys, e.g. abc")
    args = parser.parse_args(argv)
    trees = {"baseline": args.baseline.resolve(), "this tree": ROOT}
    print(f"{'row':32s} {'tree':10s} {'compute':>9s} {'+json':>9s} {'+all':>9s}   (CPU s; wall s in brackets)")
    for row in ROWS:
        if row[0] not in args.rows:
            continue
        load = os.getloadavg()[0]
        best: dict = {name: None for name in trees}
        for _ in range(args.repeat):
            for name, tree in trees.items():  # interleaved
                r = run(tree, row)
                if best[name] is None or r["cpu"][2] < best[name]["cpu"][2]:
                    best[name] = r
        same = len({r["digest"] for r in best.values()}) == 1
        label = f"{row[0]}) {row[1]} {row[2]} h^{row[3]} (load {load:.1f})"
        for name, r in best.items():
            cells = " ".join(f"{c:9.2f}" for c in r["cpu"])
            walls = " ".join(f"{w:.2f}" for w in r["wall"])
            print(f"{label:32s} {name:10s} {cells}   [{walls}]")
            label = ""
        ratio = best["baseline"]["cpu"][2] / max(best["this tree"]["cpu"][2], 1e-9)
        print(f"{'':32s} {'ratio':10s} {'':>9s} "
              f"{best['baseline']['cpu'][1] / max(best['this tree']['cpu'][1], 1e-9):9.2f} {ratio:9.2f}"
              + ("" if same else "   OUTPUTS DIFFER"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
