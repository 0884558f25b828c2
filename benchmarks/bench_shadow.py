"""Benchmark of nambu_bch.shadow: both routes, and the direct route against a plain-sympy baseline.

Run:  /work/venv/bin/python benchmarks/bench_shadow.py

Prints, measured in this one run (process CPU time, best of a few repeats):
* all six ho3 words through the FI route and the direct route at O(h^2);
* the direct route at O(h^6) for ho3 and O(h^4) for the rigid body;
* the same order-by-order linear solve done with plain sympy expressions and
  ``sympy.solve`` (the baseline, written below, run in a child process with a
  60 s limit: when it hits the limit the ratio is printed as a lower bound),
  and the ratio baseline / ours.
The baseline reproduces the same member (it solves for all unknowns and sets the
free ones to zero), and its result is checked against ours.
"""

from __future__ import annotations

import multiprocessing as mp
import sys
import time
from itertools import product

import sympy

from timing import cpu  # benchmarks/timing.py (the script's directory is on sys.path)

from nambu_bch import PAPER_WORDS, liouville_field, model
from nambu_bch.bch import effective_field
from nambu_bch.shadow import shadow_hamiltonians

H = sympy.Symbol("h")



def baseline(system, word, order, degrees):
    """The direct route with plain sympy: unknown symbols, expanded expressions, ``sympy.solve`` per order."""
    xs = system.coordinates
    Hs = list(system.hamiltonians)
    eff = effective_field(system.splitting, word, order)
    corrections = {}

    def lv(*fs):  # Liouville field X_{f1, f2} of N = 3, as sympy expressions (Eq. gLiouville)
        grads = [[sympy.diff(f, x) for x in xs] for f in fs]
        out = []
        for i in range(len(xs)):
            rows = [[1 if j == i else 0 for j in range(len(xs))]] + grads
            out.append(sympy.expand(sympy.Matrix(rows).det()))
        return out

    for j in range(1, order + 1):
        rhs = [sympy.expand(c) for c in eff[j].to_sympy()]
        for a, b in product(range(1, j), repeat=2):
            if a + b == j and (0, a) in corrections and (1, b) in corrections:
                rhs = [r - c for r, c in zip(rhs, lv(corrections[(0, a)], corrections[(1, b)]))]
        if all(r == 0 for r in rhs):
            continue
        D = degrees[j]
        monos = [sympy.Mul(*(x**e for x, e in zip(xs, exps))) for exps in product(range(D + 1), repeat=len(xs)) if sum(exps) <= D]
        cH = sympy.symbols(f"a{j}_0:{len(monos)}")
        cG = sympy.symbols(f"b{j}_0:{len(monos)}")
        dH = sum(c * mo for c, mo in zip(cH, monos))
        dG = sum(c * mo for c, mo in zip(cG, monos))
        lhs = [p + q for p, q in zip(lv(dH, Hs[1]), lv(Hs[0], dG))]
        eqs = []
        for l, r in zip(lhs, rhs):
            eqs += sympy.Poly(sympy.expand(l - r), *xs).coeffs()
        sol = sympy.solve(eqs, cH + cG, dict=True)
        if not sol:
            return None
        sol = sol[0]
        corrections[(0, j)] = sympy.expand(dH.subs(sol).subs({c: 0 for c in cH + cG}))
        corrections[(1, j)] = sympy.expand(dG.subs(sol).subs({c: 0 for c in cH + cG}))
    return tuple(sympy.expand(Hk + sum(H**j * corrections.get((a, j), 0) for j in range(1, order + 1)))
                 for a, Hk in enumerate(Hs))


def check_solution(system, word, order, shadows):
    """Is X_{H_S,G_S} = X_eff through h^order?  (exact ring arithmetic, backward-error X_eff)"""
    eff = effective_field(system.splitting, word, order)
    alg = eff[0].algebra
    X = liouville_field(alg, *(alg.convert(sympy.expand(S)) for S in shadows))
    ih = alg.n + alg.constants.index(H)
    for j in range(order + 1):
        for comp, Z in zip(X.components, eff[j].components):
            part = {mono[:ih] + (0,) + mono[ih + 1:]: c for mono, c in comp.items() if mono[ih] == j}
            if alg.ring.from_dict(part) != Z:
                return False
    return True


def _timed_baseline(args, queue):
    name, word, order, degrees = args
    system = model(name)
    t = time.process_time()
    out = baseline(system, word, order, degrees)
    queue.put((time.process_time() - t, out is not None and check_solution(system, word, order, out)))


def baseline_with_limit(name, word, order, degrees, limit):
    """The baseline in a child process; ``(seconds, valid)`` or ``(limit, None)`` when it exceeds ``limit``."""
    queue = mp.Queue()
    proc = mp.Process(target=_timed_baseline, args=((name, word, order, degrees), queue))
    proc.start()
    proc.join(limit)
    if proc.is_alive():
        proc.terminate()
        proc.join()
        return limit, None
    return queue.get()


def main(limit: float = 60.0):
    ho3, rb = model("ho3"), model("rigid-body")
    print("nambu_bch.shadow benchmark (process CPU seconds, best of 3)")

    t_fi, _ = cpu(lambda: [shadow_hamiltonians(ho3, w, 2, route="fi") for w in PAPER_WORDS])
    t_di, _ = cpu(lambda: [shadow_hamiltonians(ho3, w, 2, route="direct") for w in PAPER_WORDS])
    print(f"ho3, six words, O(h^2): FI route {t_fi:.3f} s, direct route {t_di:.3f} s, both {t_fi + t_di:.3f} s")

    rows = []
    for label, name, word, order in [("ho3 12321 O(h^6)", "ho3", "12321", 6), ("ho3 32123 O(h^4)", "ho3", "32123", 4),
                                     ("rigid-body 12321 O(h^2)", "rigid-body", "12321", 2),
                                     ("rigid-body 12321 O(h^4)", "rigid-body", "12321", 4)]:
        system = model(name)
        t_ours, fam = cpu(lambda: shadow_hamiltonians(system, word, order), repeat=2)
        ours_ok = check_solution(system, word, order, fam.member(alpha=0))
        t_base, ok = baseline_with_limit(name, word, order, fam.degree, limit)
        bound = ">" if ok is None else ""
        rows.append((label, t_ours, t_base, ok, ours_ok))
        print(f"{label}: ours {t_ours:.3f} s, sympy.solve baseline {bound}{t_base:.3f} s, "
              f"ratio {bound}{t_base / t_ours:.1f}x  (baseline valid: {'timed out' if ok is None else ok}, ours valid: {ours_ok})")
    return rows


if __name__ == "__main__":
    sys.exit(0 if all(r[3] is not False and r[4] for r in main()) else 1)
