"""The fast paths of the direct route over QQ(parameters) and QQ<2^(1/3)>(parameters) against the plain ones.

* ``PolynomialAlgebra.expanded_terms`` (the shadow pair built term by term) against ``sympy.expand`` of
  ``to_sympy``: random ring elements over ``QQ``, ``QQ(a, b)``, ``QQ<2^(1/3)>`` and ``QQ<2^(1/3)>(a, b)``
  (hypothesis), compared structurally (``srepr``), not only as values.
* The rigid body with symbolic moments ``I1, I2, I3`` (Eqs. (SH12321c), (SG12321c) generalised; the family of
  Eq. (Xeff3)): the shadow pair of ``DirectResult.shadow`` against ``sympy.expand`` of the corrections' sum, and
  ``X_{H_S, G_S} = X_eff`` through the order (Eq. L2) by backward error analysis (an independent route).
"""

from __future__ import annotations

import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from nambu_bch import liouville_field, model
from nambu_bch.algebra import PolynomialAlgebra
from nambu_bch.algebra.elimination import signed_sums
from nambu_bch.bch.backward import effective_field as backward_field
from nambu_bch.shadow.direct_route import direct_route

x1, x2, a, b, h = sympy.symbols("x1 x2 a b h")
THETA = sympy.cbrt(2)

ALGEBRAS = {
    "QQ": PolynomialAlgebra([x1, x2]),
    "QQ(a,b)": PolynomialAlgebra([x1, x2], [a, b]),
    "QQ<2^(1/3)>": PolynomialAlgebra([x1, x2], extension=[THETA]),
    "QQ<2^(1/3)>(a,b)": PolynomialAlgebra([x1, x2], [a, b], extension=[THETA]),
}


@st.composite
def ring_elements(draw, name):
    """A random element of ``ALGEBRAS[name]``: a sum of monomials ``x^m`` times fractions ``p/q`` in the parameters."""
    alg = ALGEBRAS[name]
    params = list(alg.parameters)
    small = st.integers(-3, 3)

    def poly_in(symbols, terms):
        out = sympy.Integer(0)
        for _ in range(terms):
            c = sympy.Rational(draw(small), draw(st.integers(1, 6)))
            if alg.extension and draw(st.booleans()):
                c = c + sympy.Rational(draw(small), draw(st.integers(1, 4))) * THETA ** draw(st.integers(1, 2))
            out += c * sympy.Mul(*(s ** draw(st.integers(0, 2)) for s in symbols))
        return out

    expr = sympy.Integer(0)
    for _ in range(draw(st.integers(0, 4))):
        coeff = poly_in(params, draw(st.integers(1, 3)))
        if params and draw(st.booleans()):
            den = poly_in(params, draw(st.integers(1, 2)))
            if den != 0:
                coeff = coeff / den
        expr += coeff * x1 ** draw(st.integers(0, 3)) * x2 ** draw(st.integers(0, 2))
    return alg.convert(expr)


@settings(max_examples=40, deadline=None, derandomize=True)
@given(st.sampled_from(sorted(ALGEBRAS)).flatmap(lambda name: st.tuples(st.just(name), ring_elements(name))),
       st.integers(0, 3))
def test_expanded_terms_equal_sympy_expand(case, j):
    """``Add(*expanded_terms(p, (h^j,)))`` is the very expression ``sympy.expand(h^j to_sympy(p))`` (same srepr)."""
    name, p = case
    alg = ALGEBRAS[name]
    ours = alg.to_sympy_expanded(p, (h**j,))
    plain = sympy.expand(h**j * alg.to_sympy(p))
    assert sympy.srepr(ours) == sympy.srepr(plain)
    assert sympy.expand(ours - plain) == 0


def test_expanded_terms_rational_over_whole_denominator():
    """A rational coefficient over a non-monomial denominator: ``expand`` writes ``r/(s q)``, and so do we."""
    alg = ALGEBRAS["QQ<2^(1/3)>(a,b)"]
    p = alg.convert((sympy.Rational(5, 12) * THETA * a - sympy.Rational(1, 54)) * x1**2 / (a**2 * b - a * b**2))
    ours = alg.to_sympy_expanded(p)
    assert sympy.srepr(ours) == sympy.srepr(sympy.expand(alg.to_sympy(p)))
    assert any(isinstance(t, sympy.Pow) and t.exp == -1 and t.base.is_Add
               for term in sympy.Add.make_args(ours) for t in sympy.Mul.make_args(term))


def _check_shadow(system, word, order, values=None, against_expand=True):
    """The shadow pair of the fast conversion: identical to sympy.expand of the sum (``against_expand``), the family
    through its members (alpha = 0, 1), and a solution of Eq. (L2) (at the parameter ``values`` when given)."""
    R = direct_route(system, word, order)
    assert R.exists
    fast = R.shadow()
    if against_expand:
        plain = []
        for a_, Ha in enumerate(R.hamiltonians):
            total = R.algebra.to_sympy(Ha)
            for j in range(1, order + 1):
                c = R.corrections.get((a_, j))
                if c:
                    total += h**j * R.algebra.to_sympy(c)
            plain.append(sympy.expand(total))
        assert [sympy.srepr(s) for s in fast] == [sympy.srepr(s) for s in plain]
    # the family m0 + alpha (m1 - m0) at alpha = 0, 1 is the two canonical members (Eq. Xeff3)
    alpha = sympy.Symbol("alpha")
    for o in R.orders:
        if o.status == "solved":
            for k in (0, 1):
                assert all(sympy.expand(sympy.together(c.subs(alpha, k) - m.subs(alpha, k))) == 0
                           for c, m in zip(o.corrections, o.members[k]))
    # X_{H_S, G_S} = X_eff through h^order (Eq. L2), X_eff by backward error analysis (an independent route)
    if values is not None:
        system = system.substitute(values)
        fast = [S.subs({sympy.Symbol(k): v for k, v in values.items()}) for S in fast]
    eff = backward_field(system.splitting, word, order)
    alg = eff[0].algebra.with_constants(h, alpha)
    X = liouville_field(alg, *(alg.convert(S) for S in fast))
    ih = alg.n + alg.constants.index(h)
    for j in range(order + 1):
        for comp, Z in zip(X.components, eff[j].components):
            part = {m[:ih] + (0,) + m[ih + 1:]: c for m, c in comp.items() if m[ih] == j}
            assert alg.ring.from_dict(part) == alg.convert(Z.as_expr())
    return R.shadow()


def test_rigid_body_symbolic_shadow_fast_conversion():
    """Rigid body, symbolic I1, I2, I3, word 12321 through h^2 (Eqs. (SH12321c), (SG12321c) generalised)."""
    H_S, G_S = _check_shadow(model("rigid-body"), "12321", 2)
    assert H_S.has(sympy.Symbol("alpha")) and H_S.has(sympy.Symbol("I1"))


def test_rigid_body_symbolic_yoshida_family_over_base_field():
    """Rigid body, symbolic I, yoshida:12321 (coefficients in QQ(2^(1/3))) through h^4: the family built over
    QQ(I1, I2, I3) (signed_sums) and the fast conversion; Eq. (L2) checked at I = 1, 2, 3."""
    # the conversion itself against sympy.expand: the 12321 case above and the hypothesis test over QQ<2^(1/3)>(a, b)
    H_S, _ = _check_shadow(model("rigid-body"), "yoshida:12321", 4, values={"I1": 1, "I2": 2, "I3": 3},
                           against_expand=False)
    assert H_S.has(THETA) and H_S.has(sympy.Symbol("I3"))


@st.composite
def split_values(draw):
    """Random small elements of QQ<2^(1/3)>(a, b) (monomial and linear-factor denominators, as in the rigid body)."""
    alg = ALGEBRAS["QQ<2^(1/3)>(a,b)"]
    num = sum((sympy.Rational(draw(st.integers(-4, 4)), draw(st.integers(1, 5))) * THETA ** draw(st.integers(0, 2))
               * a ** draw(st.integers(0, 2)) * b ** draw(st.integers(0, 2)) for _ in range(draw(st.integers(1, 3)))),
              sympy.Integer(0))
    den = draw(st.sampled_from([sympy.Integer(1), a, a * b**2, a - b, a * (a - b), 2 * a + b]))
    return alg.domain.from_sympy(num / den)


@settings(max_examples=30, deadline=None, derandomize=True)
@given(st.lists(st.tuples(st.sampled_from([1, -1, 2]), split_values()), min_size=1, max_size=4))
def test_signed_sums_equal_plain_sums(pairs):
    """signed_sums over the basis 1, 2^(1/3), 2^(2/3) equals the sum in QQ<2^(1/3)>(a, b) (as values)."""
    K = ALGEBRAS["QQ<2^(1/3)>(a,b)"].domain
    out = signed_sums({"k": pairs}, K)
    plain = sum((s * v for s, v in pairs), K.zero)
    assert out.get("k", K.zero) - plain == K.zero
    assert signed_sums({"k": pairs}, ALGEBRAS["QQ(a,b)"].domain) is None  # other domains: the caller adds


@st.composite
def param_matrices(draw):
    """Random sparse matrices over QQ(a, b): entries ``p/q`` with small ``p`` and monomial or linear ``q``, and
    rows that are multiples of others (rank below the bound), as in the psi-direction ranks of the rigid body."""
    K = ALGEBRAS["QQ(a,b)"].domain
    nrows, ncols = draw(st.integers(1, 5)), draw(st.integers(1, 5))
    entry = st.tuples(st.integers(-3, 3), st.integers(0, 2), st.integers(0, 2),
                      st.sampled_from([sympy.Integer(1), a, a * b, a - b, 2 * a + b]))
    rows = []
    for _ in range(nrows):
        if rows and draw(st.booleans()):
            k = K.from_sympy(a ** draw(st.integers(0, 2)) - draw(st.integers(0, 2)))
            rows.append({c: k * v for c, v in draw(st.sampled_from(rows)).items()})
            continue
        row = {}
        for c in range(ncols):
            p, i, j, q = draw(entry)
            if p:
                row[c] = K.from_sympy(p * a**i * b**j / q)
        rows.append(row)
    return rows, ncols


@settings(max_examples=40, deadline=None, derandomize=True)
@given(param_matrices())
def test_rank_over_params_equals_plain_elimination(case):
    """rank over QQ(a, b) with the full-rank-at-a-point shortcut equals the plain Gauss-Jordan rank."""
    from nambu_bch.algebra import elimination

    rows, ncols = case
    K = ALGEBRAS["QQ(a,b)"].domain
    M = elimination.SparseMatrix.from_rows(rows, ncols, K)
    ours = elimination.rank(M)
    try:
        elimination.FAST_PATHS = False
        plain = elimination.rank(M)
    finally:
        elimination.FAST_PATHS = True
    assert ours == plain


def test_cross_terms_fraction_free_equal_liouville_field():
    """The cross terms X_{dH_j, dG_k} of the rigid body's family (symbolic I) computed fraction-free equal
    liouville_field over QQ(I1, I2, I3) (Eq. gLiouville; multilinearity of the Jacobian determinant)."""
    import importlib

    dr = importlib.import_module("nambu_bch.shadow.direct_route")
    R = direct_route(model("rigid-body"), "12321", 4)
    solver = dr._Solver(model("rigid-body"), R.composition, 4, None)
    slots = (R.corrections[(0, 2)], R.corrections[(1, 2)])
    ours = solver._field(slots)
    plain = liouville_field(solver.alg, *slots)
    assert ours.components == plain.components and any(ours.components)


def test_default_bound_admits_the_n4_single_split_at_h8():
    """``shadow_hamiltonians``' default ``max_unknowns`` is the direct route's own up-front limit: the N = 4 single
    split (H = sum x_i^2/2, G = x1^2/2 + x2^2 + 3 x3^2/2 + 2 x4^2, K = x1 + .. + x4; issue benchmark, row c) at h^8 has
    an ansatz of degree 10 in three slots, 3003 unknowns, and is solved exactly (elimination estimate 1.2e9, within
    ``SOLVE_COST``) instead of being handed to the generic route."""
    import inspect

    from nambu_bch.algebra.ansatz import Ansatz
    from nambu_bch.shadow import shadow_hamiltonians
    from nambu_bch.shadow.direct_route import MAX_UNKNOWNS

    default = inspect.signature(shadow_hamiltonians).parameters["max_unknowns"].default
    assert default == MAX_UNKNOWNS
    assert Ansatz.size(4, 10, 3) == 3003 <= default
