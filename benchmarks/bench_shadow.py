"""Benchmark of nambu_bch.shadow: both routes, and the direct route against a plain-sympy baseline.

Run:  /work/venv/bin/python benchmarks/bench_shadow.py            (the rows below, then the issue-14 rows)
      /work/venv/bin/python benchmarks/bench_shadow.py --issue14  (the issue-14 rows only)
      /work/venv/bin/python benchmarks/bench_shadow.py --issue14 --rows=ab  (rows a and b only)

Prints, measured in this one run (process CPU time, best of a few repeats):
* all six ho3 words through the FI route and the direct route at O(h^2);
* the direct route at O(h^6) for ho3 and O(h^4) for the rigid body;
* the same order-by-order linear solve done with plain sympy expressions and
  ``sympy.solve`` (the baseline, written below, run in a child process with a
  60 s limit: when it hits the limit the ratio is printed as a lower bound),
  and the ratio baseline / ours.
The baseline reproduces the same member (it solves for all unknowns and sets the
free ones to zero), and its result is checked against ours.

The issue-14 rows (docs/history/performance.md, Sect. 3) time the whole ``shadow_hamiltonians`` call
in a fresh child process each (cold, CPU seconds), ours against the package's previous
elimination (``nambu_bch.algebra.elimination.FAST_PATHS = False``: sympy's sparse
``DomainMatrix.rref`` over the full coefficient field; this also switches off
the python-flint arithmetic over ``QQ(params)``: the elimination, the fraction-free fields and the
effective field's brackets, docs/history/performance.md Sect. 5), and for row c also against the
plain-sympy baseline; the two results are compared (members alpha = 0 and 1).
"""

from __future__ import annotations

import multiprocessing as mp
import sys
import time
from itertools import product

import sympy

from timing import cpu  # benchmarks/timing.py (the script's directory is on sys.path)

from nambu_bch import PAPER_WORDS, System, liouville_field, model
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


N4 = ["x1**2/2 + x2**2/2 + x3**2/2 + x4**2/2", "x1**2/2 + x2**2 + 3*x3**2/2 + 2*x4**2", "x1 + x2 + x3 + x4"]


def make_system(name):
    """The systems of the benchmark by name (catalog models, rigid body with I = 1, 2, 3, N = 4 single split)."""
    if name == "rigid-body[I=1,2,3]":
        return model("rigid-body").substitute({"I1": 1, "I2": 2, "I3": 3})
    if name == "n4-single":
        return System("x1 x2 x3 x4", N4, name="n4-single", split="single")
    return model(name)


def _timed_baseline(args, queue):
    name, word, order, degrees = args
    system = make_system(name)
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


def _timed_ours(args, queue):
    name, word, order, fast = args
    from nambu_bch.algebra import elimination

    elimination.FAST_PATHS = fast
    system = make_system(name)
    t = time.process_time()
    fam = shadow_hamiltonians(system, word, order)
    dt = time.process_time() - t
    queue.put((dt, [tuple(map(str, fam.member(alpha=a))) for a in (0, 1)], fam.degree))


def _child(target, args, limit):
    """``target(args, queue)`` in a fresh process; its result, or ``None`` after ``limit`` seconds."""
    import queue as queues

    queue = mp.Queue()
    proc = mp.Process(target=target, args=(args, queue))
    proc.start()
    try:
        out = queue.get(timeout=limit)  # before join: a child with a large result waits until it is read
    except queues.Empty:
        out = None
    if proc.is_alive():
        proc.terminate()
    proc.join()
    return out


ISSUE14 = [  # (row, system, word, order, goal in s)
    ("a: rigid body, symbolic I, 12321, h^8", "rigid-body", "12321", 8, 3.0),
    ("b: rigid body, symbolic I, yoshida:12321, h^4", "rigid-body", "yoshida:12321", 4, 3.0),
    ("b: ho3 yoshida:12321, h^8", "ho3", "yoshida:12321", 8, 3.0),
    ("c: rigid body, I = 1, 2, 3, 12321, h^8", "rigid-body[I=1,2,3]", "12321", 8, None),
    ("c: rigid body, I = 1, 2, 3, 12321, h^10", "rigid-body[I=1,2,3]", "12321", 10, None),
    ("c: rigid body, I = 1, 2, 3, 12321, h^12", "rigid-body[I=1,2,3]", "12321", 12, None),
    ("d: N = 4 single split, 1234321, h^4", "n4-single", "1234321", 4, 5.0),
    ("d: N = 4 single split, 1234321, h^6", "n4-single", "1234321", 6, 30.0),
]


def issue14(limit: float = 150.0, only=None):
    """The issue-14 rows: ours and the previous elimination, each cold in a child process (CPU s).

    ``only``: the row letters to run (e.g. ``"ab"``; ``--rows=ab`` on the command line), default all.
    """
    import os

    print(f"the --issue14 rows (cold child process each, CPU s; load average {os.getloadavg()[0]:.1f})")
    rows = []
    for label, name, word, order, goal in ISSUE14:
        if only and label[0] not in only:
            continue
        ours = _child(_timed_ours, (name, word, order, True), limit)
        before = _child(_timed_ours, (name, word, order, False), limit)
        t_ours = ours[0] if ours else None
        t_before = before[0] if before else limit
        same = None if not (ours and before) else ours[1] == before[1] or _same_members(name, ours[1], before[1])
        line = (f"{label}: ours {'>' + str(limit) if t_ours is None else f'{t_ours:.2f}'} s, previous elimination "
                f"{'>' if before is None else ''}{t_before:.2f} s")
        if t_ours:
            line += f", ratio {'>' if before is None else ''}{t_before / t_ours:.1f}x"
        if goal:
            line += f", goal < {goal:g} s: {'met' if t_ours is not None and t_ours < goal else 'not met'}"
        line += f"  (same members: {same})"
        if name == "rigid-body[I=1,2,3]" and order == 8 and ours:
            t_base, ok = baseline_with_limit(name, word, order, ours[2], 60.0)
            line += (f"; plain sympy (exact map + sympy.solve) {'>' if ok is None else ''}{t_base:.2f} s, "
                     f"ratio {'>' if ok is None else ''}{t_base / t_ours:.1f}x (goal >= 50x; baseline valid: {ok})")
        print(line, flush=True)
        rows.append((label, t_ours, t_before, same))
    return rows


def _same_members(name, u, v):
    """The members printed differently: equal as expressions (algebraic fields have no unique normal form)."""
    return all(sympy.expand(sympy.together(sympy.sympify(p) - sympy.sympify(q))) == 0
               for mu, mv in zip(u, v) for p, q in zip(mu, mv))


def main(limit: float = 60.0):
    ho3 = model("ho3")
    print("nambu_bch.shadow benchmark (process CPU seconds, best of 3)")

    t_fi, _ = cpu(lambda: [shadow_hamiltonians(ho3, w, 2, route="fi") for w in PAPER_WORDS])
    t_di, _ = cpu(lambda: [shadow_hamiltonians(ho3, w, 2, route="direct") for w in PAPER_WORDS])
    print(f"ho3, six words, O(h^2): FI route {t_fi:.3f} s, direct route {t_di:.3f} s, both {t_fi + t_di:.3f} s")

    rows = []
    for label, name, word, order in [("ho3 12321 O(h^6)", "ho3", "12321", 6), ("ho3 32123 O(h^4)", "ho3", "32123", 4),
                                     ("rigid-body 12321 O(h^2)", "rigid-body", "12321", 2),
                                     ("rigid-body 12321 O(h^4)", "rigid-body", "12321", 4)]:
        system = make_system(name)
        t_ours, fam = cpu(lambda: shadow_hamiltonians(system, word, order), repeat=2)
        ours_ok = check_solution(system, word, order, fam.member(alpha=0))
        t_base, ok = baseline_with_limit(name, word, order, fam.degree, limit)
        bound = ">" if ok is None else ""
        rows.append((label, t_ours, t_base, ok, ours_ok))
        print(f"{label}: ours {t_ours:.3f} s, sympy.solve baseline {bound}{t_base:.3f} s, "
              f"ratio {bound}{t_base / t_ours:.1f}x  (baseline valid: {'timed out' if ok is None else ok}, ours valid: {ours_ok})")
    return rows


if __name__ == "__main__":
    ok = True
    if "--issue14" not in sys.argv:
        ok = all(r[3] is not False and r[4] for r in main())
    only = next((a.split("=", 1)[1] for a in sys.argv if a.startswith("--rows=")), None)
    ok = all(r[3] is not False for r in issue14(only=only)) and ok
    sys.exit(0 if ok else 1)
