"""The printed edge built from exact data: sympy's canonical sums by a sort key, coefficients factored by flint.

Every expression built here must be the very object sympy builds (same arguments in the same order), and every
printed byte the same as through ``sympy.Add``, ``sympy.factor`` and ``sympy.expand``: the tests compare with those.
"""

from __future__ import annotations

import pickle
import random
from functools import cmp_to_key

import pytest
import sympy

from nambu_bch.algebra import _flint
from nambu_bch.algebra.canonical import canonical_add, coordinate_coefficients, sort_key
from nambu_bch.algebra.polynomial import PolynomialAlgebra
from nambu_bch.printing import _coefficients
from nambu_bch.shadow.family import _exact_series

from shared_results import family

x, y, z, a, b, c, al = sympy.symbols("x y z a b c alpha")
COMPARE = cmp_to_key(sympy.Basic.compare)
needs_flint = pytest.mark.skipif(not _flint.available(), reason="python-flint is not available")


def _random_terms(rng, count):
    """Distinct products of rational numbers and integer powers of symbols (an expanded polynomial's terms)."""
    terms, parts = [], set()
    while len(terms) < count:
        exps = [rng.randint(-2, 3) for _ in range(5)]
        part = sympy.Mul(*[s**e for s, e in zip((x, y, z, a, al), exps)])
        if part in parts or part.is_Number:
            continue
        parts.add(part)
        terms.append(rng.choice([1, -1, 2, sympy.Rational(-3, 4), sympy.Rational(5, 7)]) * part)
    return terms


def test_sort_key_is_the_order_of_basic_compare():
    rng = random.Random(3)
    exprs = _random_terms(rng, 40) + [x, y, a, sympy.Integer(2), sympy.Rational(1, 3), sympy.S.NegativeOne, x**2, 1 / (a + b), (a - b) ** 2,
                                      sympy.sin(x), x + y, sympy.Integer(0), sympy.pi]
    assert sorted(exprs, key=sort_key) == sorted(exprs, key=COMPARE)


def test_canonical_add_is_sympy_add():
    rng = random.Random(5)
    for count in (1, 2, 3, 17, 60):
        terms = _random_terms(rng, count)
        rng.shuffle(terms)
        for extra in ([], [sympy.Rational(3, 2)], [sympy.Integer(2), sympy.Integer(-2)]):
            fast, slow = canonical_add(terms + extra), sympy.Add(*(terms + extra))
            assert fast == slow and fast.args == slow.args


@pytest.mark.parametrize("terms", [
    [x, 2 * x],  # repeated part: collected
    [x + y, x],  # a sum among the terms
    [sympy.oo, x],  # an infinite number
    [x, -x],  # cancels to zero
    [sympy.Integer(0)],
    [],
])
def test_canonical_add_falls_back_to_sympy(terms):
    assert canonical_add(terms) == sympy.Add(*terms)


def test_expanded_terms_record_their_sort_keys():
    A = PolynomialAlgebra([x, y], [a, b], [al])
    p = A.convert(x**2 * y * (a**2 - 3 * b) / (2 * a * b**2) + al * y / a - x + sympy.Rational(3, 5))
    memo: dict = {}
    terms = A.expanded_terms(p, (sympy.Symbol("h") ** 2,), memo)
    for t in terms:
        assert memo[t] == sort_key(t)
    assert canonical_add(terms, memo).args == sympy.expand(A.to_sympy(p) * sympy.Symbol("h") ** 2).args


def _rational_function(rng, variables, params):
    def poly(vs, n):
        return sum(rng.choice([-3, -1, 1, 2, sympy.Rational(1, 2), sympy.Rational(-5, 3)])
                   * sympy.Mul(*[v ** rng.randint(0, 2) for v in vs]) for _ in range(n))
    num = poly(variables, 3)
    den = poly(params, 2) * rng.choice(params)
    return num / (den if den != 0 else 1)


@needs_flint
@pytest.mark.parametrize("params, constants", [([a, b, c], [al]), ([b, a], []), ([c], [al])])
def test_coordinate_coefficients_are_sympy_factor(params, constants):
    """Factors with negative leading coefficients, sums in denominators, cancellations across powers of alpha."""
    rng = random.Random(len(params) + 7 * len(constants))
    A = PolynomialAlgebra([x, y], params, constants)
    for _ in range(4):
        expr = sum(_rational_function(rng, params + constants, params) * x ** rng.randint(0, 2) * y ** rng.randint(0, 1)
                   for _ in range(2))
        p = A.convert(expr)
        rows = coordinate_coefficients(p, 2)
        reference = _coefficients(sympy.Add(*A.expanded_terms(p)), [x, y])
        assert [m for m, _ in rows] == [m for m, _ in reference]
        for (_, fast), (_, coefficient) in zip(rows, reference):
            slow = sympy.factor(coefficient)
            assert fast == slow and str(fast) == str(slow) and sympy.latex(fast) == sympy.latex(slow)


def test_coordinate_coefficients_need_flint(monkeypatch):
    monkeypatch.setenv("NAMBU_BCH_DISABLE_FLINT", "1")
    A = PolynomialAlgebra([x], [a], [])
    assert coordinate_coefficients(A.convert(x / a), 1) is None


def _outputs(F):
    return F.to_text(), F.to_latex(), repr(F.to_dict())


@needs_flint
@pytest.mark.parametrize("name, word", [("ho3", "12321"), ("ho", "121")])
def test_printed_family_is_the_same_through_sympy(name, word, monkeypatch):
    """The exact layout (flint factors, series read off the corrections) prints what sympy's factor/expand print."""
    F = family(name, word, 4)
    fast = _outputs(pickle.loads(pickle.dumps(F)))  # a fresh copy: no layout computed yet
    monkeypatch.setenv("NAMBU_BCH_DISABLE_FLINT", "1")
    copy = pickle.loads(pickle.dumps(F))
    slow = _outputs(copy)  # sympy.factor per coefficient
    assert fast == slow


@pytest.mark.parametrize("name, word", [("ho", "121"), ("lotka-volterra", "12321")])
def test_exact_series_is_the_expanded_layout(name, word):
    """With monomial denominators, the expanded layout is each correction's own expanded form (ShadowFamily.series)."""
    F = family(name, word, 4)
    for slot, hamiltonian in enumerate(F.system.hamiltonians):
        exact = _exact_series(F.details, slot, hamiltonian)
        expanded = {k: sympy.expand(c) for k, c in F._layout(slot, with_base=True)}
        assert list(exact) == list(expanded)
        for k, c in exact.items():
            assert str(c) == str(expanded[k]) and c == sympy.Add(*sympy.Add.make_args(expanded[k]))


def test_symbolic_rigid_body_h10_is_solved_within_the_budget():
    """The rigid body with symbolic I at h^10 (910 unknowns over QQ(I1, I2, I3), elimination estimate 3.5e9) is solved
    exactly under the default bounded work (about 7 s) instead of being refused for the existence decision (about
    116 s, benchmarks/bench_shadow.py --targets, row b)."""
    from nambu_bch import model
    from nambu_bch.shadow.api import SOLVE_UNKNOWNS
    from nambu_bch.shadow.direct_route import direct_route

    R = direct_route(model("rigid-body"), "12321", 10, max_unknowns=SOLVE_UNKNOWNS)
    assert R.exists and [o.status for o in R.orders][-1] == "solved" and R.orders[-1].degree is not None
