"""Non-polynomial systems against Henon-Heiles: CPU of ``nb.shadow_hamiltonians`` in fresh processes, as ratios.

Every case runs in a fresh interpreter with an empty cache directory (cold: nothing computed before);
the time is the process CPU time (user + sys) of the ``shadow_hamiltonians`` call alone, which includes
the check of H_S against backward error analysis; the wall time is printed beside it.  Each
non-polynomial case is divided by Henon-Heiles (d = 2, polynomial) at the same word and order, measured
in the same run; the load average is printed with every line (the numbers on a loaded machine are an
upper bound).  The nested sine is run through the command line: answered or refused, with its wall time.

Run:  python benchmarks/bench_nonpolynomial.py
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CENTRAL = 'nb.System("q1 q2 p1 p2", ["(p1**2 + p2**2)/2 - 1/sqrt(q1**2 + q2**2)"], (), name="central")'
HENON = 'nb.model("henon-heiles")'
CASES = [  # (label, system expression, word, order, reference label)
    ("henon-heiles", HENON, "212", 4, None),
    ("henon-heiles", HENON, "212", 6, None),
    ("henon-heiles", HENON, "121", 4, None),
    ("henon-heiles", HENON, "121", 8, None),
    ("central force", CENTRAL, "212", 2, None),
    ("central force", CENTRAL, "212", 4, ("henon-heiles", "212", 4)),
    ("central force", CENTRAL, "212", 6, ("henon-heiles", "212", 6)),
    ("pendulum", 'nb.model("pendulum")', "121", 4, ("henon-heiles", "121", 4)),
    ("pendulum", 'nb.model("pendulum")', "121", 8, ("henon-heiles", "121", 8)),
    ("exp-well", 'nb.model("exp-well")', "121", 4, ("henon-heiles", "121", 4)),
    ("exp-well", 'nb.model("exp-well")', "121", 8, ("henon-heiles", "121", 8)),
    ("rational", 'nb.model("rational")', "121", 4, ("henon-heiles", "121", 4)),
    ("rational", 'nb.model("rational")', "121", 8, ("henon-heiles", "121", 8)),
]

CHILD = """
import json, time
import nambu_bch as nb
system = {system}
t0, w0 = time.process_time(), time.perf_counter()
F = nb.shadow_hamiltonians(system, {word!r}, order={order})
print(json.dumps({{"cpu": time.process_time() - t0, "wall": time.perf_counter() - w0, "exists": F.exists}}))
"""

NESTED = "sin(sin(sin(sin(sin(sin(sin(sin(x1))))))))+x2^2/2"


def run(code, timeout=900):
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, PYTHONPATH=str(ROOT), NAMBU_BCH_CACHE=cache, MPLBACKEND="Agg")
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=timeout)
    if out.returncode:
        return {"error": out.stderr.strip().splitlines()[-1] if out.stderr.strip() else f"exit {out.returncode}"}
    return json.loads(out.stdout.strip().splitlines()[-1])


def main():
    seen = {}
    for label, system, word, order, ref in CASES:
        r = run(CHILD.format(system=system, word=word, order=order))
        seen[(label, word, order)] = r
        load = os.getloadavg()[0]
        if "error" in r:
            print(f"{label:14s} {word} h^{order}: {r['error']}  (load {load:.1f})", flush=True)
            continue
        ratio = ""
        if ref is not None and "cpu" in seen.get(ref, {}):
            ratio = f"  = {r['cpu'] / max(seen[ref]['cpu'], 1e-9):5.2f} x henon-heiles {ref[1]} h^{ref[2]}"
        print(f"{label:14s} {word} h^{order}: cpu {r['cpu']:7.2f} s  wall {r['wall']:7.2f} s{ratio}  (load {load:.1f})",
              flush=True)
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, PYTHONPATH=str(ROOT), NAMBU_BCH_CACHE=cache, MPLBACKEND="Agg")
        t = time.perf_counter()
        out = subprocess.run([sys.executable, "-m", "nambu_bch", "shadow", "--H", NESTED, "--order", "4",
                              "--format", "text"], capture_output=True, text=True, env=env, timeout=900)
        wall = time.perf_counter() - t
    verdict = "answered" if out.returncode == 0 else f"refused (exit {out.returncode})"
    print(f"nested sine x8 h^4 (CLI, whole process): {verdict} in {wall:.2f} s wall  (load {os.getloadavg()[0]:.1f})")


if __name__ == "__main__":
    main()
