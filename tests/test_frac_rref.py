"""Exact solves over QQ(parameters) on python-flint's fraction pairs: the second canonical member by reduction, and the
conversion memo of one solve.

* :meth:`nambu_bch.algebra.ansatz.Ansatz.member` (normal forms modulo the kernel,
  :func:`nambu_bch.algebra.frac_rref.normal_forms` over ``QQ(a, b)``) gives the particular solutions of
  :meth:`~nambu_bch.algebra.ansatz.Ansatz.solve_canonical` for another priority: the identical field elements in the
  same order, with python-flint and on the pure path (``NAMBU_BCH_DISABLE_FLINT=1``), over ``QQ(a, b)`` and ``QQ``
  (hypothesis; the canonical member is unique, Horikoshi Eq. Xeff3 and the rule of ``algebra/ansatz.py``).
* :func:`nambu_bch.algebra.frac_rref.shared_conversions`: inside the scope an element crosses to flint once (the
  same pair object comes back), elements made by ``to_field`` are known, and nothing is kept after the scope.
* The direct route eliminates each order's system once (the ``alpha = 1`` member is reduced from the ``alpha = 0``
  one), on the rigid body with symbolic moments (Eqs. SH12321a-SH12321c generalised to ``QQ(I1, I2, I3)``).
"""

from __future__ import annotations

import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st
from sympy.polys.domains import QQ

from nambu_bch import model
from nambu_bch.algebra import ansatz as ansatz_module
from nambu_bch.algebra import _flint, frac_rref
from nambu_bch.algebra.ansatz import Ansatz
from nambu_bch.errors import NambuBCHError
from nambu_bch.shadow.direct_route import direct_route

pytest.importorskip("flint")

a, b = sympy.symbols("a b")
K = QQ.frac_field(a, b)
CTX = frac_rref.context(K)


@pytest.fixture(autouse=True)
def _flint_on(monkeypatch):
    """Each test starts with python-flint on and switches it off itself where it compares with the pure path."""
    monkeypatch.delenv("NAMBU_BCH_DISABLE_FLINT", raising=False)


def identical(u, v) -> bool:
    """The same field element in the same representation (numerator and denominator polynomials)."""
    return u.numer == v.numer and u.denom == v.denom


@st.composite
def entries(draw, field):
    """A small element of ``field`` (``QQ(a, b)``: a quotient of sparse polynomials; ``QQ``: a small rational)."""
    if field is QQ:
        return QQ(draw(st.integers(-3, 3)), draw(st.integers(1, 3)))
    ring = K.field.ring
    term = st.tuples(st.integers(0, 2), st.integers(0, 1), st.integers(-3, 3))
    num = ring.from_dict({(i, k): QQ(c) for i, k, c in draw(st.lists(term, max_size=2)) if c})
    den = ring.from_dict({(draw(st.integers(0, 1)), 0): QQ(draw(st.integers(1, 3)))}) + ring.gens[1] * draw(st.integers(0, 1))
    return K.field.new(num, den)


@st.composite
def systems(draw):
    """A consistent sparse ``L x = b_k`` (two right-hand sides, rank-deficient ``L``) and two column priorities."""
    field = draw(st.sampled_from([K, QQ]))
    nrows, ncols = draw(st.integers(1, 4)), draw(st.integers(2, 6))
    columns = []
    for _ in range(ncols):
        col = {i: v for i in range(nrows) if draw(st.integers(0, 2)) and (v := draw(entries(field)))}
        columns.append(col)
    if draw(st.booleans()):  # a dependent column: a kernel of more than the empty columns
        c = draw(entries(field)) or field.one
        columns[-1] = {i: c * v for i, v in columns[0].items() if c * v}
    rhs = []
    for _ in range(2):
        x = [draw(entries(field)) for _ in range(ncols)]
        bk = {}
        for j, col in enumerate(columns):
            for i, v in col.items():
                bk[i] = bk.get(i, field.zero) + v * x[j]
        rhs.append({i: v for i, v in bk.items() if v})
    prio0 = list(draw(st.permutations(range(ncols))))
    prio1 = list(draw(st.permutations(range(ncols))))
    return field, columns, rhs, nrows, prio0, prio1


def _same(ours, reference, field):
    assert [list(v) for v in ours] == [list(v) for v in reference]  # the same columns in the same order
    for u, w in zip(ours, reference):
        for c, v in u.items():
            assert identical(v, w[c]) if field is K else v == w[c]


@settings(max_examples=25, deadline=None, derandomize=True)
@given(systems(), st.booleans())
def test_member_is_solve_canonical_of_the_other_priority(case, flint):
    """``Ansatz.member`` from the ``prio0`` solution equals ``solve_canonical(.., prio1).particular``: identical
    elements, same entry order, with python-flint's pairs and on the pure path."""
    field, columns, rhs, nrows, prio0, prio1 = case
    with pytest.MonkeyPatch.context() as mp:
        if not flint:
            mp.setenv("NAMBU_BCH_DISABLE_FLINT", "1")
        first = Ansatz.solve_canonical(columns, rhs, nrows, field, prio0)
        assert first.consistent
        reference = Ansatz.solve_canonical(columns, rhs, nrows, field, prio1, certificate=False).particular
        _same(Ansatz.member(first, prio1, field), reference, field)


def test_member_of_an_inconsistent_system_is_refused():
    bad = Ansatz.solve_canonical([{0: QQ(1)}], [{1: QQ(1)}], 2, QQ, [0])
    with pytest.raises(NambuBCHError, match="inconsistent"):
        Ansatz.member(bad, [0], QQ)


def test_shared_conversions_convert_each_element_once():
    """Inside the scope the same element gives the same pair object, an element made by ``to_field`` is known with
    its pair, nested scopes share one memo, and outside a scope every call converts afresh (an equal pair)."""
    u = K.from_sympy((a + 2 * b) / (3 * a * b - 1))
    outside = frac_rref.from_field(u, CTX)
    assert frac_rref.from_field(u, CTX) is not outside
    with frac_rref.shared_conversions():
        p = frac_rref.from_field(u, CTX)
        assert p == outside
        with frac_rref.shared_conversions():
            assert frac_rref.from_field(u, CTX) is p
        assert frac_rref.from_field(u, CTX) is p
        pair = frac_rref.mul(p, p)
        made = frac_rref.to_field(pair, K)
        assert identical(made, u * u)
        assert frac_rref.from_field(made, CTX) is pair
        seen = _flint._EXPONENTS.get()  # flint's exponent tuples, converted once each
        assert seen and all(type(e) is int for t in seen.values() for e in t)
        assert identical(frac_rref.to_field(pair, K), made)
    assert frac_rref._SHARED.get() is None and _flint._EXPONENTS.get() is None
    assert frac_rref.from_field(u, CTX) is not p


def test_exponents_with_a_memo_are_python_ints():
    """``_flint.exponents`` with a memo: the same tuples of Python ints as without, each distinct tuple converted once;
    inside ``shared_exponents`` the scope's memo is used."""
    n, _ = frac_rref.from_field(K.from_sympy(a**3 * b - 2 * a * b**2 + 5), CTX)
    memo: dict = {}
    assert _flint.exponents(n, memo) == _flint.exponents(n) == [(3, 1), (1, 2), (0, 0)]
    first = _flint.exponents(n, memo)
    assert all(x is y for x, y in zip(first, _flint.exponents(n, memo))) and len(memo) == 3
    assert all(type(e) is int for t in first for e in t)
    with _flint.shared_exponents():
        inner = _flint.exponents(n)
        assert _flint.exponents(n)[0] is inner[0] and len(_flint._EXPONENTS.get()) == 3


def test_direct_route_eliminates_each_order_once(monkeypatch):
    """The ``alpha = 1`` member comes from the ``alpha = 0`` solution: one ``solve_canonical`` per solved order (two
    before; that the members are those of two eliminations is tests/test_direct_route_flint.py's reference run)."""
    calls = []
    solve = Ansatz.solve_canonical

    def counted(*args, **kwargs):
        calls.append(args[4])
        return solve(*args, **kwargs)

    monkeypatch.setattr(ansatz_module.Ansatz, "solve_canonical", staticmethod(counted))
    R = direct_route(model("rigid-body"), "12321", order=4)
    solved = [o for o in R.orders if o.status == "solved"]
    assert len(solved) == 2 and len(calls) == len(solved)
    assert all(m[0] != m[1] for o in solved for m in [o.members])  # two distinct members all the same


X1, X2, H = sympy.symbols("x1 x2 h")


@st.composite
def sums(draw):
    """Parts ``(p_k, (h^j_k,))`` over ``QQ``, ``QQ(a, b)`` with monomial and non-monomial denominators, on a ring
    with ``h`` among its generators (so that a part's ``h^j`` may meet another part's monomials) or without."""
    from nambu_bch.algebra import PolynomialAlgebra

    params = draw(st.sampled_from([(), (a, b)]))
    alg = PolynomialAlgebra([X1, X2], list(params))
    if draw(st.booleans()):
        alg = alg.with_constants(H)
    gens = [X1, X2] + ([H] if len(alg.gens) > 2 else [])
    den = [sympy.Integer(1), 2 * a, a**2 * b, a - 2 * b][: 4 if params else 1]
    parts = []
    for j in draw(st.lists(st.integers(0, 3), min_size=1, max_size=3, unique=True)):
        expr = sympy.Integer(0)
        for _ in range(draw(st.integers(0, 4))):
            c = sympy.Rational(draw(st.integers(-5, 5)), draw(st.integers(1, 4)))
            mono = sympy.Mul(*[g ** draw(st.integers(0, 2)) for g in gens])
            coeff = c * (a ** draw(st.integers(0, 2)) + draw(st.integers(0, 1)) * b if params else 1)
            expr += coeff * mono / draw(st.sampled_from(den))
        parts.append((alg.convert(expr), (H**j,) if j else ()))
    return alg, parts


@settings(max_examples=40, deadline=None, derandomize=True)
@given(sums())
def test_expanded_sum_is_sympy_expand_of_the_sum(case):
    """``expanded_sum`` of several parts is the very expression ``sympy.expand`` of their sum (same srepr), whether
    the keyed construction applies or the terms go through ``canonical_add``."""
    alg, parts = case
    plain = sympy.expand(sympy.Add(*[alg.to_sympy(p) * sympy.Mul(*f) for p, f in parts]))
    assert sympy.srepr(alg.expanded_sum(parts)) == sympy.srepr(plain)
