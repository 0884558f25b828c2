"""Re-run the existence claims of README "Results beyond the paper" and notebook 04 with the three outcomes.

Writes the table between the markers of docs/existence.md:

    PYTHONPATH=$PWD python tools/existence_table.py            # prints and updates docs/existence.md
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from nambu_bch import System, model
from nambu_bch.shadow import shadow_hamiltonians

N4 = ["x1**2/2 + x2**2/2 + x3**2/2 + x4**2/2", "x1**2/2 + x2**2 + 3*x3**2/2 + 2*x4**2", "x1 + x2 + x3 + x4"]
EX17 = ["x1**2/2 + x2**2/2 + x2**4/4 + x3**2", "x1**2/2 + x1**4/8 + x2**2/2 + x3**2/2 + x3**4/4"]

CASES = [
    ("ho3, full", lambda: model("ho3"), "12321", 6),
    ("ho3, full", lambda: model("ho3"), "123", 2),
    ("ho3, full", lambda: model("ho3"), "132", 2),
    ("ho3, full", lambda: model("ho3"), "lie-trotter", 2),
    ("rigid-body, full", lambda: model("rigid-body"), "12321", 6),
    ("rigid-body, full", lambda: model("rigid-body"), "123", 2),
    ("lotka-volterra, single", lambda: model("lotka-volterra"), "12321", 4),
    ("lotka-volterra, single", lambda: model("lotka-volterra"), "123", 2),
    ("ho3-composite, single", lambda: model("ho3-composite"), "121", 4),
    ("ho3-composite, single", lambda: model("ho3-composite"), "12", 2),
    ("N = 4 separable, full", lambda: System("x1 x2 x3 x4", N4, name="n4"), "1234321", 2),
    ("N = 4 separable, full", lambda: System("x1 x2 x3 x4", N4, name="n4"), "1234", 1),
    ("N = 4 separable, single", lambda: System("x1 x2 x3 x4", N4, name="n4", split="single"), "1234321", 2),
    ("N = 4 separable, single", lambda: System("x1 x2 x3 x4", N4, name="n4", split="single"), "1234", 2),
    ("quartic example, full", lambda: System("x1 x2 x3", EX17, name="ex17"), "12321", 2),
    ("quartic example, full", lambda: System("x1 x2 x3", EX17, name="ex17"), "123", 2),
]


def row(label, make, word, order):
    t = time.time()
    F = shadow_hamiltonians(make(), word, order)
    secs = time.time() - t
    if F.shadows:
        degs = sorted(set(F.degree.values()))
        return f"| {label} | {word} | h^{order} | polynomial pair (degrees {', '.join(map(str, degs))}) | exact solve | {secs:.1f} |", F
    ev = F.evidence or {}
    outcome = {True: "**smooth pair, not polynomial**", False: "**none (certified)**", None: "undecided"}[F.exists]
    how = ev.get("method") or "-"
    detail = ""
    if F.exists is False:
        if ev.get("averages"):
            detail = "; ".join(f"⟨R·∇{k}⟩ = `{v}`" for k, v in ev["averages"].items())
        else:
            o = ev["certificate_orbit"]
            detail = "; ".join(f"{a:.4g}±{e:.0e}" for a, e in zip(o["averages"], o["errors"])) + " on one orbit"
        m = ev.get("measured_drift", [])
        if m:
            keys = list(m[0]["measured"])
            r1 = ", ".join(f"{m[0]['measured'][k] / m[0]['predicted'][k]:.3f}" for k in keys)
            r2 = ", ".join(f"{m[1]['measured'][k] / m[1]['predicted'][k]:.3f}" for k in keys)
            q = ", ".join(f"{m[0]['measured'][k] / m[1]['measured'][k]:.2f}" for k in keys)
            detail += (f"; measured/predicted drift of {', '.join(keys)}: {r1} (h = {m[0]['h']:.2g}), {r2} (h/2); "
                       f"drift(h)/drift(h/2) = {q}")
    elif F.exists is True:
        worst = max(max(abs(a) for a in o["averages"]) for o in ev["orbits"] if o.get("closed"))
        detail = (f"{', '.join(ev.get('involutions', []))} reverse the flow and make R·∇H, R·∇G odd; "
                  f"{ev.get('orbits_closed')} sampled orbits, numerically max abs⟨g⟩ = {worst:.1e}")
    else:
        detail = ev.get("reason", "")
    poly = f"no polynomial pair at h^{F.failed_order} (degree {F.degree.get(F.failed_order)})"
    return f"| {label} | {word} | h^{order} | {outcome}: {poly} | {how}: {detail} | {secs:.1f} |", F


def main():
    lines = ["| system, splitting | word | order | outcome | how decided | seconds |", "|---|---|---|---|---|---|"]
    for case in CASES:
        line, _ = row(*case)
        print(line, flush=True)
        lines.append(line)
    doc = Path(__file__).resolve().parent.parent / "docs" / "existence.md"
    start, end = "<!-- existence-table:start -->", "<!-- existence-table:end -->"
    if doc.exists() and "--no-write" not in sys.argv:
        text = doc.read_text()
        if start in text and end in text:
            head, rest = text.split(start, 1)
            _, tail = rest.split(end, 1)
            doc.write_text(head + start + "\n" + "\n".join(lines) + "\n" + end + tail)


if __name__ == "__main__":
    main()
