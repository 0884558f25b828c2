"""The one ansatz of the exact linear solves (nambu_bch/algebra/ansatz.py): monomials, interning, priority, canonical rule.

The canonical member is the package's rule for the alpha-family (Horikoshi Eq. Xeff3 generalised; for ho3 and
12321 Eqs. SH12321a-SH12321c): the normal form of a solution modulo the kernel for the priority of
:meth:`Ansatz.priority`.  It is computed two ways (reduction of a solution, elimination in reverse priority)
and the two are compared, also on random systems (hypothesis).
"""

from itertools import combinations_with_replacement, product
from math import comb

import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st
from sympy.polys.domains import QQ

from nambu_bch.algebra.ansatz import MAX_COLUMNS, Ansatz, Rows
from nambu_bch.algebra.elimination import SparseMatrix, solve_affine
from nambu_bch.errors import NambuBCHError, ResourceLimitError


@pytest.mark.parametrize("n,degree", [(1, 0), (1, 4), (2, 3), (3, 2), (3, 4), (4, 3)])
def test_lex_monomials_are_all_of_degree_at_most_d_lexicographic_with_x_n_first(n, degree):
    A = Ansatz(n, degree)
    brute = [e for e in product(range(degree + 1), repeat=n) if sum(e) <= degree]
    assert sorted(A.monomials) == sorted(brute) and len(set(A.monomials)) == len(brute)
    # descending, x_N the most significant exponent
    assert list(A.monomials) == sorted(brute, key=lambda e: tuple(reversed(e)), reverse=True)
    assert A.monomials[-1] == (0,) * n and len(A) == Ansatz.size(n, degree) == comb(degree + n, n)


@pytest.mark.parametrize("n,degree", [(2, 3), (3, 2), (3, 4)])
def test_graded_monomials_are_the_invariant_search_order(n, degree):
    """Degree 1..d, ascending degree, within a degree x_1 the most significant exponent, descending."""
    A = Ansatz(n, degree, lowest=1, order="graded")
    expected = [tuple(c.count(i) for i in range(n)) for d in range(1, degree + 1)
                for c in combinations_with_replacement(range(n), d)]
    assert list(A.monomials) == expected
    assert [sum(e) for e in A.monomials] == sorted(sum(e) for e in A.monomials)
    assert len(A) == Ansatz.size(n, degree, lowest=1) == comb(degree + n, n) - 1


def test_columns_are_slot_major_and_interned():
    A = Ansatz(3, 2, slots=2)
    assert len(A) == 2 * 10 and A.columns[:10] == tuple((0, e) for e in A.monomials)
    assert all(A.index[c] == k for k, c in enumerate(A.columns))
    assert A.columns[10] == (1, (0, 0, 2))


def test_expressions_and_polynomials_round_trip():
    x1, x2 = sympy.symbols("x1 x2")
    from sympy.polys.rings import ring

    R, *_ = ring("x1 x2 alpha", QQ)
    A = Ansatz(2, 2, slots=2)
    vec = {7: QQ(3), A.index[(0, (1, 0))]: QQ(-1, 2)}   # column 7 = slot 1, x1*x2
    assert A.columns[7] == (1, (1, 1))
    assert A.expressions(vec, (x1, x2), QQ) == (-x1 / 2, 3 * x1 * x2)
    polys = A.polynomials(vec, R, tail=(2,))
    assert [p.as_expr() for p in polys] == [-sympy.Symbol("alpha") ** 2 * x1 / 2, 3 * sympy.Symbol("alpha") ** 2 * x1 * x2]
    shifted = {k + 4: v for k, v in vec.items()}
    shifted[0] = QQ(9)     # a weight column below the offset is ignored
    assert A.expressions(shifted, (x1, x2), QQ, offset=4) == (-x1 / 2, 3 * x1 * x2)


def test_expressions_equal_the_term_by_term_sum_and_the_ring_polynomials():
    """expressions() builds one Add per slot: structurally equal (==) to the running sum of the terms, and to the
    ring's polynomials() converted to sympy (two independent constructions), on a dense vector of mixed rationals."""
    from sympy.polys.rings import ring

    xs = sympy.symbols("x1 x2 x3")
    R, *_ = ring("x1 x2 x3", QQ)
    A = Ansatz(3, 3, slots=2)
    vec = {k: QQ((-1) ** k * (k + 1), 1 + k % 5) for k in range(len(A)) if k % 3}
    running = [sympy.Integer(0)] * 2
    for k, v in vec.items():
        a, e = A.columns[k]
        running[a] += QQ.to_sympy(v) * A.monomial(e, xs)
    got = A.expressions(vec, xs, QQ)
    assert got == tuple(running)
    assert [sympy.expand(g - p.as_expr()) for g, p in zip(got, A.polynomials(vec, R))] == [0, 0]


def test_priority_rule_for_ho3():
    """ho3 (Eqs. H, G): H = m w^2 x3/2 + x2^2/(2m), G = x3 - x1^2.  alpha = 0: constants, then H's own monomials
    x3, x2^2 in slot 0 (in the ansatz order), then slot 0's other monomials, then G's x3, x1^2, then slot 1's rest."""
    A = Ansatz(3, 2, slots=2)
    own = [[(0, 0, 1), (0, 2, 0)], [(0, 0, 1), (2, 0, 0)]]
    p0, p1 = A.priorities(own)
    cols0 = [A.columns[c] for c in p0]
    assert cols0[:2] == [(0, (0, 0, 0)), (1, (0, 0, 0))]
    assert cols0[2:4] == [(0, (0, 0, 1)), (0, (0, 2, 0))]                # x3 before x2^2 (x_N first)
    assert [c[0] for c in cols0[2:11]] == [0] * 9 and cols0[11:13] == [(1, (0, 0, 1)), (1, (2, 0, 0))]
    cols1 = [A.columns[c] for c in p1]
    assert cols1[:2] == cols0[:2] and cols1[2:4] == [(1, (0, 0, 1)), (1, (2, 0, 0))]
    for p in (p0, p1):     # a permutation of the columns
        assert sorted(p) == list(range(len(A)))
    # own monomials outside the ansatz are skipped; offset and rest place the ansatz in a larger system
    assert A.priority([[(0, 0, 5)], []], (0, 1), offset=3, rest=[0, 1, 2])[-3:] == [0, 1, 2]
    assert min(A.priority([[], []], (0, 1), offset=3)) == 3
    one = Ansatz(2, 1)
    assert one.priorities([[(1, 0)]])[0] == one.priorities([[(1, 0)]])[1]


def test_canonical_member_on_a_gauge_example():
    """L(a, b) = a + b with b = 2 (one equation, a one-dimensional kernel): the canonical member clears the
    first priority column it can (the normal form), computed both ways."""
    columns, rhs = [{0: QQ(1)}, {0: QQ(1)}], [{0: QQ(2)}]
    S = solve_affine(SparseMatrix.from_columns(columns, 1, QQ), rhs)
    for prio, expected in (([0, 1], {1: QQ(2)}), ([1, 0], {0: QQ(2)})):
        assert Ansatz.canonical(S.particular, S.kernel, prio, QQ) == [expected]
        assert Ansatz.solve_canonical(columns, rhs, 1, QQ, prio).particular == [expected]


_entries = st.integers(-2, 2).map(QQ)


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 4), st.integers(1, 5), st.data())
def test_canonical_rule_two_ways_on_random_systems(nrows, ncols, data):
    """Property: for a consistent L x = b, elimination in reverse priority gives the normal form of any solution
    (the same vector), it solves the system, and it does not depend on which solution is reduced."""
    L = [[data.draw(_entries) for _ in range(ncols)] for _ in range(nrows)]
    x0 = [data.draw(_entries) for _ in range(ncols)]
    b = {i: sum((L[i][j] * x0[j] for j in range(ncols)), QQ(0)) for i in range(nrows)}
    columns = [{i: L[i][j] for i in range(nrows) if L[i][j]} for j in range(ncols)]
    prio = data.draw(st.permutations(range(ncols)))
    S = solve_affine(SparseMatrix.from_columns(columns, nrows, QQ), [b])
    assert S.consistent
    direct = Ansatz.solve_canonical(columns, [b], nrows, QQ, list(prio)).particular[0]
    start = {j: v for j, v in enumerate(x0) if v}
    for shift in S.kernel[:2]:      # another solution reduces to the same member
        start = {j: start.get(j, QQ(0)) + shift.get(j, QQ(0)) for j in set(start) | set(shift)}
    reduced = Ansatz.canonical([start], S.kernel, list(prio), QQ)[0]
    clean = lambda v: {k: c for k, c in v.items() if c}  # noqa: E731
    assert clean(direct) == clean(reduced)
    assert all(sum((L[i][j] * direct.get(j, QQ(0)) for j in range(ncols)), QQ(0)) == b[i] for i in range(nrows))


def test_solve_canonical_maps_kernel_and_certificate_back():
    columns = [{0: QQ(1)}, {0: QQ(1)}, {1: QQ(1)}]
    S = Ansatz.solve_canonical(columns, [{0: QQ(1), 1: QQ(2)}], 2, QQ, [2, 0, 1])
    assert S.consistent and len(S.kernel) == 1 and set(S.kernel[0]) == {0, 1}
    bad = Ansatz.solve_canonical([{0: QQ(1)}], [{1: QQ(1)}], 2, QQ, [0])
    assert not bad.consistent and bad.certificate == {1: QQ(1)}
    with pytest.raises(NambuBCHError, match="priority"):
        Ansatz.solve_canonical(columns, [{0: QQ(1)}], 2, QQ, [0, 1])


def test_rows_intern_in_order_of_first_appearance():
    R = Rows()
    assert [R(k) for k in ("a", "b", "a", "c")] == [0, 1, 0, 2] and len(R) == 3 and R.keys() == ["a", "b", "c"]
    assert R.vector({"c": 5, "d": 1}, sign=-1) == {2: -5, 3: -1}
    assert R.vector([("a", 7)]) == {0: 7}
    from sympy.polys.rings import ring

    Rg, x, y, al = ring("x y alpha", QQ)
    rows = Rows()
    assert rows.field([x * al + 2 * y, y], 2) == {0: QQ(1), 1: QQ(2), 2: QQ(1)}
    assert rows.keys() == [(0, (1, 0)), (0, (0, 1)), (1, (0, 1))]


@pytest.mark.parametrize("kwargs", [dict(n=0, degree=1), dict(n=2, degree=-1), dict(n=2, degree=True),
                                    dict(n=2, degree=2, slots=0), dict(n=2, degree=1, lowest=2),
                                    dict(n=2, degree=2, order="grevlex"), dict(n=2.0, degree=2)])
def test_bad_ansatz_is_refused_with_one_line(kwargs):
    with pytest.raises(NambuBCHError) as info:
        Ansatz(**kwargs)
    assert "\n" not in str(info.value)


def test_huge_ansatz_is_refused_before_building():
    with pytest.raises(ResourceLimitError, match=str(MAX_COLUMNS)):
        Ansatz(12, 40, slots=2)


def test_priority_reads_ring_elements_like_exponent_tuples():
    """The Hamiltonians may be given as ring elements of an algebra with extra constants (alpha): only the first n
    exponents count.  ho3 (Eqs. H, G) in QQ(m, omega)[x1, x2, x3, alpha]."""
    from nambu_bch import model

    S = model("ho3")
    alg = S.algebra.with_constants(sympy.Symbol("alpha"))
    hams = [alg.convert(H) for H in S.hamiltonians]
    A = Ansatz(3, 3, slots=2)
    assert A.priorities(hams) == A.priorities([[(0, 0, 1), (0, 2, 0)], [(0, 0, 1), (2, 0, 0)]])
