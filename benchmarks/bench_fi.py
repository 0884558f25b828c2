"""Benchmark of the FI route at h^4: the six ho3 words, FI route against the direct route, and where the time goes.

Run:  PYTHONPATH=. python benchmarks/bench_fi.py  [--order 4]

Prints, measured in this one run (process CPU seconds):
* the first call (cold caches: formal BCH series, brackets, fields) of each route over the six
  words of Eq. (words) -- the direct route runs first, so the FI route's first call still
  pays for its own hulls and formal sums but shares the formal BCH series;
* the best of three further calls (warm caches) and the ratio FI / direct;
* a profile of the FI route on one word with its caches cleared, grouped by stage: the h^2 labelled representations
  (Eqs. 1AX-2BY), the BCH brackets (formal series + expansion into Liouville terms), the
  recursive hulls (``fi_nested``), the formal columns and cross terms (``LiouvilleSum``), the
  exact linear algebra (``solve_affine``, ``normal_form``), and the sympy forms of the exact families (built on
  first access: ``H_S, G_S`` and the gauge the result prints).
Both routes' families are checked to be equal (ho3: the FI alpha-family is the direct one).
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import time

import sympy

from timing import cpu  # benchmarks/timing.py (the script's directory is on sys.path)

from nambu_bch import PAPER_WORDS, model
from nambu_bch.bch.formal import clear_cache as bch_clear_cache
from nambu_bch.shadow import shadow_hamiltonians
from nambu_bch.shadow.fi_route import clear_cache as fi_clear_cache

STAGES = [  # (stage, (file, function) pairs whose cumulative CPU time is attributed to it); the stages do not nest
    ("h^2 labelled forms and their formal sums (Eqs. 1AX-2BY)", [("fi_route.py", "_distinct_forms")]),
    ("recursive hulls (fi_nested.nested_hull)", [("fi_nested.py", "nested_hull")]),
    ("BCH brackets (formal_bch + expand_terms)", [("formal.py", "formal_bch"), ("expansion.py", "expand_terms")]),
    ("cross terms (lower orders fed in)", [("fi_route.py", "_cross_terms")]),
    ("formal target columns (X_{H,x^e}, X_{x^e,G})", [("fi_route.py", "_monomial_column")]),
    ("exact linear algebra (solve_affine, normal_form, kernel_rref)",
     [("elimination.py", "solve_affine"), ("elimination.py", "normal_form"), ("elimination.py", "kernel_rref")]),
    # the families are exact data; their sympy forms are built on first access (the lazy properties' getter)
    ("sympy forms of the families (on first access)", [("fi_route.py", "get")]),
]



def profile(word, order):
    """Profile one FI call with the FI caches cleared (hulls, labelled forms, evaluators; the formal BCH series too)."""
    ho3 = model("ho3")
    fi_clear_cache()
    bch_clear_cache()
    prof = cProfile.Profile(time.process_time)  # CPU time: the machine may be shared
    prof.enable()
    shadow_hamiltonians(ho3, word, order, route="fi")
    prof.disable()
    stats = pstats.Stats(prof).stats
    total = next(v[3] for (fname, line, func), v in stats.items() if func == "shadow_hamiltonians")
    rows = []
    for stage, names in STAGES:
        cum = sum(v[3] for (fname, line, func), v in stats.items()
                  if any(fname.endswith(f) and func == name for f, name in names) and "nambu_bch" in fname)
        rows.append((stage, cum))
    rows.append(("the rest (vanishing rule on directions, echelon forms, bookkeeping)", total - sum(c for _, c in rows)))
    return total, rows


def main(order: int = 4):
    ho3 = model("ho3")
    print(f"FI route vs direct route, ho3, six words, O(h^{order}) (process CPU seconds)")
    t0 = time.process_time()
    direct = [shadow_hamiltonians(ho3, w, order) for w in PAPER_WORDS]
    cold_direct = time.process_time() - t0
    t0 = time.process_time()
    fi = [shadow_hamiltonians(ho3, w, order, route="fi") for w in PAPER_WORDS]
    cold_fi = time.process_time() - t0
    same = all(sympy.expand(a - b) == 0 for F, D in zip(fi, direct) for a, b in zip(F.shadows, D.shadows))
    print(f"first call: FI {cold_fi:.3f} s, direct {cold_direct:.3f} s, ratio {cold_fi / cold_direct:.1f}x")
    t_di, _ = cpu(lambda: [shadow_hamiltonians(ho3, w, order) for w in PAPER_WORDS])
    t_fi, _ = cpu(lambda: [shadow_hamiltonians(ho3, w, order, route="fi") for w in PAPER_WORDS])
    print(f"best of 3:  FI {t_fi:.3f} s, direct {t_di:.3f} s, ratio {t_fi / t_di:.1f}x (goal: within 5x)")
    print(f"the two alpha-families are equal for all six words: {same}")
    for o in fi[0].details.orders:
        if o.status == "solved":
            print(f"  {PAPER_WORDS[0]}, h^{o.order}: {len(o.commutators)} brackets, {len(o.directions)} independent FI "
                  f"directions, FI family dimension {o.fi_dim} of the direct route's {o.direct_dim}")
    total, rows = profile("21312", order)
    print(f"profile of the FI route, 21312, O(h^{order}), FI caches cleared (profiled CPU: {total:.3f} s):")
    for stage, cum in rows:
        print(f"  {stage:<66} {cum:7.3f} s  ({100 * cum / total:4.0f} %)")
    return t_fi, t_di


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--order", type=int, default=4, choices=(4, 6))
    main(ap.parse_args().order)
