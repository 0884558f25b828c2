"""Benchmarks of the BCH engine: each line prints ours vs a baseline measured in the same run.

Run:  python benchmarks/bench_bch.py [--quick]

1. Formal BCH of Phi^{12321} (5 factors, 3 generators, Eq. eL2): degrees 7, 9, 11, and log(e^A e^B)
   at degree 16 (and 20 without --quick), cold (a fresh interpreter per call, CPU time of the call
   alone) and warm (repeat in one process, package caches cleared), and against a
   naive log in the free associative algebra with dicts of Fractions at degree 7 (degree 9 naive is
   minutes), both cold and both warm.  Against the C program: benchmarks/bch_c_reference.py.
2. Concrete X_eff of the six paper words of ho3 to h^6: ours (effective_field_bch) against the same
   formal series evaluated with plain sympy expressions (diff + expand, the same memoisation shared
   across the six words, the same pruning).
3. Rigid body to h^6: backward error analysis in Laurent polynomials (fast=True) and the BCH route
   against the system's ring over QQ(I1, I2, I3) (fast=False, the previous representation).
"""

from __future__ import annotations

import subprocess
import sys
import time
from fractions import Fraction
from math import factorial
from pathlib import Path

import sympy

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the checkout, whatever the working directory

from nambu_bch import clear_caches as clear_package_caches  # noqa: E402
from nambu_bch import model  # noqa: E402
from nambu_bch.bch import BracketEvaluator, clear_cache, effective_field, effective_field_bch, formal_bch, table
from nambu_bch.integrators import PAPER_WORDS, composition


def timed(fn, *args, repeat=1, **kwargs):
    """Best of ``repeat`` runs, each starting from empty caches (ours and sympy's: no run reuses another's work)."""
    best, result = float("inf"), None
    for _ in range(repeat):
        clear_cache()
        sympy.core.cache.clear_cache()
        t = time.process_time()
        result = fn(*args, **kwargs)
        best = min(best, time.process_time() - t)
    return best, result


# -- 1. formal BCH ---------------------------------------------------------------------------------------------

def naive_log(comp, n):
    """log(prod exp(c X)) through degree n in the free associative algebra (dicts of Fractions)."""
    def mul(a, b):
        out = {}
        for u, cu in a.items():
            for v, cv in b.items():
                if len(u) + len(v) <= n:
                    out[u + v] = out.get(u + v, 0) + cu * cv
        return out

    P = {(): Fraction(1)}
    for k, c in comp.factors():
        c = Fraction(int(c.p), int(c.q))
        P = mul(P, {(k,) * j: c**j / factorial(j) for j in range(n + 1)})
    Q = {w: c for w, c in P.items() if w}
    L, power = {}, {(): Fraction(1)}
    for j in range(1, n + 1):
        power = mul(power, Q)
        for w, c in power.items():
            L[w] = L.get(w, 0) + Fraction((-1) ** (j + 1), j) * c
    return {w: c for w, c in L.items() if c}


def _child(kind, spec, degree):
    """Run in a fresh interpreter: CPU seconds of one call (ours or the naive log) and its size."""
    comp = composition(spec)
    t = time.process_time()
    result = formal_bch(comp, degree) if kind == "ours" else naive_log(comp, degree)
    print(time.process_time() - t, len(result))


def cold(kind, spec, degree):
    """CPU seconds of the call alone in a fresh interpreter (package imported, nothing computed yet)."""
    root = Path(__file__).resolve().parents[1]
    out = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--child", kind, spec, str(degree)],
                         capture_output=True, text=True, cwd=root, check=True)
    seconds, size = out.stdout.split()
    return float(seconds), int(size)


def warm(fn, *args, repeat=3):
    """Best CPU seconds of ``repeat`` calls in this process after one untimed call (numba started), every
    in-memory cache of the package cleared before each (``nambu_bch.clear_caches``: nothing is reused)."""
    fn(*args)
    best = float("inf")
    for _ in range(repeat):
        clear_package_caches()
        t = time.process_time()
        fn(*args)
        best = min(best, time.process_time() - t)
    return best


def bench_formal(quick):
    comp = composition("12321")
    label = 6 if quick else 7
    formal_bch(composition("123"), 10)  # warm = numba started (3^10 words: sparse; then it is taken at every size)
    for spec, d in [("12321", 7), ("12321", 9), ("12321", 11)] + [("12", 16)] + ([] if quick else [("12", 20)]):
        t_cold, size = cold("ours", spec, d)
        by = "the shipped table" if spec in ("12", "21", "121", "212") and d <= table.max_degree() else "the engine"
        print(f"[formal] {spec} degree {d}: {size} Lyndon terms, by {by}; cold {t_cold:.4f} s (fresh interpreter, "
              f"call alone), warm {warm(formal_bch, composition(spec), d):.4f} s")
    tn_cold, _ = cold("naive", "12321", label)
    to_cold, _ = cold("ours", "12321", label)
    tn_warm, to_warm = warm(naive_log, comp, label, repeat=1), warm(formal_bch, comp, label)
    print(f"[formal] naive free-associative log to degree {label} (dicts of Fractions, no Lie basis) vs ours: "
          f"both cold {tn_cold:.3f} s / {to_cold:.4f} s = {tn_cold / to_cold:.1f}x; "
          f"both warm {tn_warm:.3f} s / {to_warm:.4f} s = {tn_warm / to_warm:.1f}x")
    print("[formal] against Hofstätter's C program: benchmarks/bch_c_reference.py /path/to/BCH (both cold)")


# -- 2. concrete X_eff: ours vs plain sympy -----------------------------------------------------------------------

def sympy_evaluator(splitting):
    """Memoised bracket trees on fields held as plain sympy expressions (diff + expand)."""
    coords = splitting.system.coordinates
    fields = {p.number: tuple(sympy.sympify(c) for c in p.field.to_sympy()) for p in splitting.pieces}

    def bracket(X, Y):
        return tuple(
            sympy.expand(sum(X[j] * sympy.diff(Y[i], x) - Y[j] * sympy.diff(X[i], x) for j, x in enumerate(coords)))
            for i in range(len(coords))
        )

    return BracketEvaluator(fields, bracket, lambda X: all(c == 0 for c in X))


def sympy_effective_field(splitting, word, order, E):
    """The same formal series evaluated with the plain sympy evaluator ``E`` (shared across words, as ours)."""
    coords = splitting.system.coordinates
    series = formal_bch(composition(word, len(splitting)), order + 1)
    Z = []
    for j in range(order + 1):
        total = [sympy.Integer(0)] * len(coords)
        for c, tree in series.terms(j + 1):
            value = E.value(tree)
            if value is not None:
                total = [t + c * v for t, v in zip(total, value)]
        Z.append(tuple(sympy.expand(t) for t in total))
    return Z


def bench_concrete(quick):
    S = model("ho3").splitting
    comps = [composition(w) for w in PAPER_WORDS]

    def ours():
        return [effective_field_bch(S, c, 6) for c in comps]

    def baseline():
        E = sympy_evaluator(S)
        return [sympy_effective_field(S, c, 6, E) for c in comps]

    t_ours, a = timed(ours, repeat=5)
    t_base, b = timed(baseline, repeat=5)
    same = all(
        sympy.expand(x - y) == 0
        for X, Y in zip(a, b) for j in range(7) for x, y in zip(X[j].to_sympy(), Y[j])
    )
    t_formal, _ = timed(lambda: [formal_bch(c, 7) for c in comps], repeat=5)
    print(f"[concrete] ho3, six paper words to h^6 (end to end, formal series included): ours {t_ours:.4f} s, "
          f"plain sympy {t_base:.4f} s, ratio {t_base / t_ours:.1f}x (results identical: {same})")
    print(f"[concrete]   of which the shared formal series takes {t_formal:.4f} s; evaluation stage alone: "
          f"ours {t_ours - t_formal:.4f} s, plain sympy {t_base - t_formal:.4f} s, "
          f"ratio {(t_base - t_formal) / max(t_ours - t_formal, 1e-9):.1f}x")


# -- 3. rigid body to h^6 -----------------------------------------------------------------------------------------

def bench_rigid_body(quick):
    S = model("rigid-body").splitting
    comp = composition("12321")
    t_fast, A = timed(effective_field, S, comp, 6)
    t_bch, B = timed(effective_field_bch, S, comp, 6)
    t_bch_plain, C = timed(effective_field_bch, S, comp, 6, fast=False)
    line = (f"[rigid-body] 12321 to h^6: backward Laurent {t_fast:.3f} s, BCH Laurent {t_bch:.3f} s, "
            f"BCH over QQ(I1,I2,I3) {t_bch_plain:.3f} s")
    if not quick:
        t_plain, D = timed(effective_field, S, comp, 6, fast=False)
        same = all(A[j] == B[j] == C[j] == D[j] for j in range(7))
        line += (f", backward over QQ(I1,I2,I3) {t_plain:.3f} s; ratios QQ(I)/Laurent: backward "
                 f"{t_plain / t_fast:.1f}x, BCH {t_bch_plain / t_bch:.1f}x (identical: {same})")
    else:
        line += f"; ratio BCH QQ(I)/Laurent {t_bch_plain / t_bch:.1f}x"
    print(line)


if __name__ == "__main__":
    if sys.argv[1:2] == ["--child"]:
        _child(sys.argv[2], sys.argv[3], int(sys.argv[4]))
        sys.exit(0)
    quick = "--quick" in sys.argv
    bench_formal(quick)
    bench_concrete(quick)
    bench_rigid_body(quick)
