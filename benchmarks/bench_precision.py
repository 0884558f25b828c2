"""Speed versus accuracy, measured: truncation order, arithmetic, step size (Sect. 5.5 of the paper).

Three tables for Phi^{32123} on the N = 3 oscillator (m = omega = 1, x(0) = (1, 1, 1)):

1. truncation order k = 2, 4, 6, 8 of the shadow Hamiltonians: seconds to derive them (first
   call in this process) and the size of their residual oscillation / drift over a long run
   (O(h^{k+2}) for this symmetric scheme);
2. arithmetic -- float64, float64 + Kahan, mpmath: seconds per step and the round-off drift of
   the exact invariants H_c, G_c over --steps steps (10^7 by default).  mpmath runs only
   --mp-steps steps; its drift over --steps is EXTRAPOLATED linearly (rate x T) and marked so;
3. the h-scan: max |H(t) - H(0)|, |G|, |H_c|, |G_c| for omega h from 1e-3 up to the stability
   limit omega h -> 2 (steps with omega h >= 2 are reported unstable).

The functions behind the tables are nambu_bch.numeric.{truncation_study, precision_study, h_scan};
a notebook can call them directly.

Usage (from the repository root):
    python benchmarks/bench_precision.py                 # full: ~1-2 minutes
    python benchmarks/bench_precision.py --quick         # smaller runs, ~20 s
    python benchmarks/bench_precision.py --json out.json # also write the numbers
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from nambu_bch.numeric import h_scan, precision_study, truncation_study  # noqa: E402


def table(rows, columns=None, floatfmt="{:.3e}"):
    """Format a list of dicts as a plain-text table."""
    if not rows:
        return "(no rows)"
    columns = columns or list(rows[0])
    cells = [[c for c in columns]]
    for r in rows:
        line = []
        for c in columns:
            v = r.get(c)
            if isinstance(v, bool) or v is None:
                line.append(str(v))
            elif isinstance(v, float):
                line.append(floatfmt.format(v))
            else:
                line.append(str(v))
        cells.append(line)
    widths = [max(len(row[j]) for row in cells) for j in range(len(columns))]
    return "\n".join("  ".join(cell.rjust(w) for cell, w in zip(row, widths)) for row in cells)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--system", default="ho3")
    ap.add_argument("--word", default="32123")
    ap.add_argument("--h", type=float, default=0.1)
    ap.add_argument("--orders", default="2,4,6,8")
    ap.add_argument("--truncation-steps", type=int, default=1_000_000)
    ap.add_argument("--steps", type=int, default=10_000_000, help="float64 steps of the arithmetic study")
    ap.add_argument("--mp-steps", type=int, default=20_000, help="mpmath steps (its drift is extrapolated)")
    ap.add_argument("--dps", type=int, default=30)
    ap.add_argument("--scan-steps", type=int, default=100_000)
    ap.add_argument("--timing-steps", type=int, default=5_000_000,
                    help="steps of the float64 / Kahan timing runs (sampled only at the end; both warm)")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--json", metavar="FILE", help="write all three studies as JSON")
    args = ap.parse_args(argv)
    if args.quick:
        args.truncation_steps, args.steps, args.mp_steps, args.scan_steps, args.repeats = 100_000, 1_000_000, 5_000, 10_000, 2
        args.timing_steps = 2_000_000
    orders = tuple(int(k) for k in args.orders.split(","))
    out = {}

    print(f"# 1. Truncation order: shadow Hamiltonians of {args.word} on {args.system}, h = {args.h}, "
          f"{args.truncation_steps} steps (sampled every 100)")
    start = time.perf_counter()
    tr = truncation_study(args.system, args.word, orders, args.h, args.truncation_steps, every=100)
    print(f"source: {tr.source} (bch = nambu_bch.shadow.shadow_hamiltonians; exact-series = series of F^alpha H_c, F^(1-alpha) G_c)")
    print(table(tr.rows()))
    print(f"({time.perf_counter() - start:.1f} s)\n")
    out["truncation"] = tr.to_dict()

    print(f"# 2. Arithmetic: round-off drift of H_c, G_c over {args.steps:.0e} steps (h = {args.h}, "
          f"T = {args.h * args.steps:.0e}); mpmath dps={args.dps} runs {args.mp_steps} steps, drift EXTRAPOLATED")
    start = time.perf_counter()
    ps = precision_study(args.system, args.word, args.h, args.steps, mp_steps=args.mp_steps, dps=args.dps,
                         repeats=args.repeats, timing_steps=args.timing_steps)
    print(table(ps.rows(), ["arithmetic", "seconds_per_step", "timing_steps", "steps_run", "extrapolated", "state_error_at_mp_steps",
                            "max|dH_c|", "drift(H_c)", "max|dG_c|", "drift(G_c)"]))
    rows = {r["arithmetic"]: r for r in ps.rows()}
    base = rows["float64"]["seconds_per_step"]
    print("cost relative to float64: " + ", ".join(f"{k} {r['seconds_per_step'] / base:.3g}x" for k, r in rows.items()))
    print(f"({time.perf_counter() - start:.1f} s)\n")
    out["precision"] = ps.to_dict()

    print(f"# 3. h-scan of {args.word} on {args.system} up to the stability limit, {args.scan_steps} steps each")
    start = time.perf_counter()
    scan = h_scan(args.system, args.word, steps=args.scan_steps)
    print(table(scan.rows()))
    print(f"largest stable h in the scan: {scan.stability_limit:g} (omega h -> 2 is the limit)")
    for m in scan.messages[:2]:
        print("  " + m)
    print(f"({time.perf_counter() - start:.1f} s)")
    out["h_scan"] = scan.to_dict()

    if args.json:
        Path(args.json).write_text(json.dumps(out, indent=1, allow_nan=False))
        print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
