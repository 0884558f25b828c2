"""Compute the FI-vs-direct comparison tables of docs/fi_route.md and write them between the markers.

Run:  PYTHONPATH=. python tools/fi_route_table.py          (rewrites docs/fi_route.md in place, atomically)
      PYTHONPATH=. python tools/fi_route_table.py --print  (prints the tables only)

For each system (ho3, rigid body, Lotka-Volterra) and each of the six words of Eq. (words), at
h^4 and h^6:
* the FI route (``fi_route``, lower orders from the FI route itself): the number of BCH brackets,
  of independent FI directions, the ansatz degree ``D``, the dimension of the corrections reached
  by FI representations (``fi_dim``) and of the direct route's kernel at the same degree ``D``
  (``direct_dim``); "whole" when they agree, "proper part" when ``fi_dim < direct_dim``;
* whether the FI alpha-family equals the direct route's (same normal forms; the direct route
  chooses its own degree, shown as ``D_direct``, with its kernel dimension).
Rigid body: the FI route is obstructed at h^2 already; a second table feeds the direct route's
h^2 family in and asks the FI question at h^4 only.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from pathlib import Path

import sympy

from nambu_bch import PAPER_WORDS, model
from nambu_bch.atomic import write_atomic
from nambu_bch.bch import formal_bch
from nambu_bch.shadow import direct_route, fi_route
from nambu_bch.shadow.fi_nested import RawOps

fi = importlib.import_module("nambu_bch.shadow.fi_route")
DOC = Path(__file__).resolve().parents[1] / "docs" / "fi_route.md"
BEGIN, END = "<!-- fi_route_table.py: begin -->", "<!-- fi_route_table.py: end -->"


def _same(a, b) -> bool:
    return all(sympy.expand(x - y) == 0 for x, y in zip(a, b))


def main_rows(systems=("ho3", "rigid-body", "lotka-volterra"), words=PAPER_WORDS, orders=(4, 6)):
    rows = []
    for name in systems:
        S = model(name)
        for word in words:
            R = fi_route(S, word, max(orders))
            D = direct_route(S, word, max(orders))
            for j in orders:
                d = D.orders[j - 1]
                o = next((o for o in R.orders if o.order == j), None)
                if o is None or o.status != "solved":
                    at = R.failed_order or R.power
                    rows.append((name, word, j, "-", "-", "-", "-", "-", f"{d.degree} / {d.kernel_dim}",
                                 f"FI obstructed at h^{at}", "-"))
                    continue
                verdict = "whole" if o.whole else "proper part"
                same = _same(o.corrections, d.corrections)
                rows.append((name, word, j, len(o.commutators), len(o.directions), o.degree, o.fi_dim, o.direct_dim,
                             f"{d.degree} / {d.kernel_dim}", verdict, "yes" if same else "no"))
    return rows


def hybrid_rows(name="rigid-body", words=PAPER_WORDS, j=4):
    """FI at h^j with the direct route's lower-order alpha-family fed into the cross terms."""
    S = model(name)
    atoms, per_slot = fi._atoms(S)
    ctx = {"algebra": S.algebra, "atoms": atoms, "per_slot": per_slot}
    ops, memo = RawOps(S.algebra, atoms), {}
    rows = []
    for word in words:
        D = direct_route(S, word, j)
        corrections = {(a, o.order): fi._alpha_parts(S.algebra, c)
                       for o in D.orders[: j - 1] if o.status == "solved" for a, c in enumerate(o.corrections)}
        o = fi._solve_order(S, ctx, ops, memo, formal_bch(word, j + 1), j, corrections, None)
        d = D.orders[j - 1]
        if o.status != "solved":
            rows.append((name, word, j, len(o.commutators), len(o.directions), o.degree, "-", "-",
                         f"{d.degree} / {d.kernel_dim}", "FI obstructed", "-"))
            continue
        rows.append((name, word, j, len(o.commutators), len(o.directions), o.degree, o.fi_dim, o.direct_dim,
                     f"{d.degree} / {d.kernel_dim}", "whole" if o.whole else "proper part",
                     "yes" if _same(o.corrections, d.corrections) else "no"))
    return rows


HEADER = ("| system | word | order | brackets | FI directions | D | FI dim | direct dim at D | "
          "D_direct / direct dim | FI span vs direct | same alpha-family |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|")


def table(rows) -> str:
    return "\n".join([HEADER, *("| " + " | ".join(f"h^{c}" if i == 2 else str(c) for i, c in enumerate(r)) + " |"
                                for r in rows)])


def family_and_gauge(name="ho3", word="12321", order=6) -> str:
    """The FI alpha-family through h^order, and at each solved order the FI gauge next to the direct one."""
    S = model(name)
    R, D = fi_route(S, word, order), direct_route(S, word, order)
    lines = [f"{name}, {word}: the FI alpha-family (corrections of H and G by powers of h)"]
    lines += [f"  h^{R.power}: dH = {sympy.factor(R.corrections[0])},  dG = {sympy.factor(R.corrections[1])}"]
    for o in R.orders:
        if o.status == "solved":
            lines.append(f"  h^{o.order}: dH = {sympy.factor(o.corrections[0])},  dG = {sympy.factor(o.corrections[1])}")
    for o in R.orders:
        if o.status == "solved":
            d = D.orders[o.order - 1]
            lines.append(f"  gauge at h^{o.order}: FI {[tuple(sympy.factor(c) for c in v) for v in o.kernel]}")
            lines.append(f"                direct {[tuple(sympy.factor(c) for c in v) for v in d.gauge]}")
    return "\n".join(lines)


def render() -> str:
    parts = ["**FI route (lower orders from the FI route).**", "", table(main_rows()), "",
             "**Rigid body, FI at h^4 with the direct route's h^2 family fed in.**", "", table(hybrid_rows()), "",
             "**The ho3 family through h^6 and the gauge, FI against direct.**", "", "```",
             family_and_gauge(), "```"]
    return "\n".join(parts)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--print", action="store_true", help="print the tables instead of rewriting docs/fi_route.md")
    args = ap.parse_args(argv)
    text = render()
    if args.print:
        print(text)
        return 0
    doc = DOC.read_text()
    if BEGIN not in doc or END not in doc:
        print(f"{DOC}: markers {BEGIN} / {END} not found", file=sys.stderr)
        return 2
    head, rest = doc.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    write_atomic(DOC, head + BEGIN + "\n" + text + "\n" + END + tail)
    print(f"wrote {DOC}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
