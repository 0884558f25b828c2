"""The matrices the direct route eliminates over QQ, and their elimination by each route.

Run:  /work/venv/bin/python benchmarks/bench_elimination_qq.py            (the four cases below)
      /work/venv/bin/python benchmarks/bench_elimination_qq.py --quick    (Lotka-Volterra h^6 and h^8 only)

For each case (system, word, order) one ``shadow_hamiltonians(...).shadows`` call records every ``QQ`` block that
``elimination._rref`` eliminates (the blocks of its sparsity graph, right-hand sides included, as
``elimination._blocks`` splits them), then prints:

* the blocks: how many, the largest (rows x columns, non-zero entries and entries per row, rank, the largest
  numerator or denominator of an entry and of the reduced echelon form, in bits);
* the process CPU seconds of eliminating all of them again, interleaved, by: flint's dense ``fmpq_mat.rref`` read
  as before (every entry of the reduced form made an object), flint's dense ``fmpq_mat.rref`` read at the pivots'
  rows and free columns only (``SPARSE_RATIO = None``), the sparse pass run to the end on every block
  (``SPARSE_RATIO = 0``), and the package's choice (sparse pass for sparse rows within its budget, else dense);
  best of three, with the load.

Every route must give the same reduced echelon forms; the script checks that too.
"""

from __future__ import annotations

import os
import sys
import time

from sympy.polys.domains import QQ

from bench_shadow import make_system  # benchmarks/ is on sys.path when the script runs

from nambu_bch.algebra import elimination as E
from nambu_bch.shadow import shadow_hamiltonians

CASES = [("lotka-volterra", "12321", 6), ("lotka-volterra", "12321", 8), ("lotka-volterra", "12321", 10),
         ("lotka-volterra", "12321", 12), ("rigid-body[I=1,2,3]", "12321", 10), ("n4-single", "1234321", 6)]


def record(name, word, order):
    """The ``QQ`` blocks ``(rows, nrows, ncols)`` (rows renumbered per block) of one call, in the order eliminated."""
    blocks = []
    original = E._rref

    def watched(rows, nrows, ncols, domain, lift=True, link=None):
        if domain.is_QQ:
            live = {i: {j: v for j, v in r.items() if v} for i, r in rows.items()}
            live = {i: r for i, r in live.items() if r}
            for members in E._blocks(live, ncols if link is None else link).values():
                cols = sorted({j for i in members for j in live[i]})
                index = {c: k for k, c in enumerate(cols)}
                blocks.append(({k: {index[j]: v for j, v in live[i].items()} for k, i in enumerate(members)},
                               len(members), len(cols)))
        return original(rows, nrows, ncols, domain, lift, link)

    E._rref = watched
    try:
        shadow_hamiltonians(make_system(name), word, order).shadows
    finally:
        E._rref = original
    return blocks


def _bits(values) -> int:
    return max((max(abs(int(v.numerator)).bit_length(), int(v.denominator).bit_length()) for v in values), default=0)


def _rref_flint_every_entry(rows, nrows, ncols):
    """The dense route as it was read before: every entry of flint's reduced form (``R.entries()``) as an object."""
    M = E._flint.fmpq_mat(nrows, ncols)
    for i, row in rows.items():
        for j, v in row.items():
            M[i, j] = v
    R, rank = M.rref()
    entries = R.entries()
    out, pivots = {}, []
    for i in range(rank):
        out[i] = {j: v for j, v in enumerate(entries[i * ncols:(i + 1) * ncols]) if v}
        pivots.append(min(out[i]))
    return out, tuple(pivots)


def eliminate_all(blocks, ratio, every_entry=False):
    """CPU seconds of ``_rref_block`` on every block with ``SPARSE_RATIO = ratio``, and the results."""
    old, dense = E.SPARSE_RATIO, E._rref_flint_qq
    E.SPARSE_RATIO = ratio
    if every_entry:
        E._rref_flint_qq = _rref_flint_every_entry
    try:
        t = time.process_time()
        out = [E._rref_block(rows, nrows, ncols, QQ) for rows, nrows, ncols in blocks]
        return time.process_time() - t, out
    finally:
        E.SPARSE_RATIO, E._rref_flint_qq = old, dense


def report(name, word, order):
    blocks = record(name, word, order)
    if not blocks:
        print(f"{name}, {word}, h^{order}: no QQ blocks (the coefficient field has parameters)")
        return True
    largest = sorted(blocks, key=lambda b: -b[1] * b[2])[:3]
    shapes = []
    for rows, nrows, ncols in largest:
        nnz = sum(map(len, rows.values()))
        R, pivots = E._rref_block(rows, nrows, ncols, QQ)
        shapes.append(f"{nrows}x{ncols} ({nnz} entries, {nnz / nrows:.1f} a row, rank {len(pivots)}, "
                      f"{_bits(v for r in rows.values() for v in r.values())} -> "
                      f"{_bits(v for r in R.values() for v in r.values())} bits)")
    routes = {"dense, every entry read (before)": (None, True), "dense (flint fmpq_mat)": (None, False),
              "sparse pass throughout": (0, False), "the package's choice": (E.SPARSE_RATIO, False)}
    best = {label: float("inf") for label in routes}
    results = {}
    for _ in range(3):  # interleaved
        for label, (ratio, every_entry) in routes.items():
            t, out = eliminate_all(blocks, ratio, every_entry)
            best[label] = min(best[label], t)
            results[label] = out
    same = len({repr(out) for out in results.values()}) == 1
    print(f"{name}, {word}, h^{order}: {len(blocks)} QQ blocks; largest {'; '.join(shapes)}")
    print("    " + ", ".join(f"{label} {t:.3f} s" for label, t in best.items())
          + f"  (identical forms: {same}; load {os.getloadavg()[0]:.1f})", flush=True)
    return same


if __name__ == "__main__":
    if not E.flint_available():
        sys.exit("python-flint is off (NAMBU_BCH_DISABLE_FLINT): this script compares against its dense route")
    cases = CASES[:2] if "--quick" in sys.argv else CASES
    print("QQ blocks of the direct route, eliminated again by each route "
          f"(CPU s, best of 3; load {os.getloadavg()[0]:.1f})")
    ok = all([report(*case) for case in cases])
    sys.exit(0 if ok else 1)
