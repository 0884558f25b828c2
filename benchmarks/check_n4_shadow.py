"""An independent spot check of the N = 4 single split's shadow Hamiltonians at h^8 (issue 23, target row c).

The direct route solves ``X_{H_S,G_S,K_S} = X_eff`` (Horikoshi, Eq. L2, with N = 4: three Hamiltonians) using the
modified field of backward error analysis and the package's Liouville fields in exact ring arithmetic; the
package's own check (``bench_shadow.check_solution``) repeats that comparison.  This script compares the returned
members (alpha = 0 and 1) with what neither of those uses: the modified field of the formal BCH route
(``effective_field_bch``, Lyndon brackets of the pieces' fields) and the Liouville field written as a plain
sympy determinant ``X^i = det(e_i; grad H_S; grad G_S; grad K_S)`` (Eq. gLiouville), both evaluated at a few
rational points ``x0`` as polynomials in ``h``, coefficient by coefficient through ``h^8``.

Run:  PYTHONPATH=. python benchmarks/check_n4_shadow.py     (about 35 s and 1.5 GB for the BCH route's X_eff)
"""

from __future__ import annotations

import os
import resource
import sys
import time

import sympy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_shadow import make_system  # noqa: E402

from nambu_bch.bch.concrete import effective_field_bch  # noqa: E402
from nambu_bch.shadow import shadow_hamiltonians  # noqa: E402

POINTS = [(1, 2, 3, 5), (sympy.Rational(-1, 2), sympy.Rational(1, 3), 2, -3), (7, -1, sympy.Rational(5, 4), 1)]
ORDER = 8


def main() -> bool:
    system = make_system("n4-single")
    xs, h = list(system.coordinates), sympy.Symbol("h")
    t = time.process_time()
    family = shadow_hamiltonians(system, "1234321", ORDER)
    print(f"shadow_hamiltonians: {time.process_time() - t:.1f} s CPU (load {os.getloadavg()[0]:.1f})", flush=True)
    members = {a: family.member(alpha=a) for a in (0, 1)}
    t = time.process_time()
    eff = effective_field_bch(system.splitting, "1234321", ORDER)
    print(f"X_eff by the BCH route: {time.process_time() - t:.1f} s CPU, peak RSS "
          f"{resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB", flush=True)
    ok = True
    for x0 in POINTS:
        at = dict(zip(xs, x0))
        Z = [[sympy.sympify(c).subs(at) for c in eff[j].to_sympy()] for j in range(ORDER + 1)]
        for a, shadows in members.items():
            grads = [[sympy.expand(sympy.diff(S, x).subs(at)) for x in xs] for S in shadows]
            for i in range(len(xs)):
                row = [[1 if k == i else 0 for k in range(len(xs))]] + grads
                X = sympy.Poly(sympy.expand(sympy.Matrix(row).det()), h)
                same = all(X.coeff_monomial(h**j) == Z[j][i] for j in range(ORDER + 1))
                ok = ok and same
        print(f"x0 = {x0}: X_(H_S,G_S,K_S)(x0) = X_eff(x0) through h^{ORDER} for alpha = 0, 1: {ok}", flush=True)
    return ok


if __name__ == "__main__":
    sys.exit(0 if main() else 1)
