"""The python-flint paths over QQ(parameters) against sympy's own field arithmetic: identical elements, not only equal.

* :mod:`nambu_bch.algebra.frac_rref`: the normal form of a rational function (sympy's ``PolyElement.cancel``:
  coprime integer numerator and denominator, positive leading coefficient of the denominator), products,
  differences and inverses (Knuth, TAOCP vol. 2, Sect. 4.5.1), and the reduced row echelon form against sympy's
  ``DomainMatrix.rref`` over ``QQ(a, b)`` (hypothesis; the reduced echelon form is unique).
* :class:`nambu_bch.algebra.flint_ring.FlintRing`: ``liouville_field`` (Eq. gLiouville) on flint polynomials
  against the same on sympy's ring, for N = 2 (canonical), N = 3 and N = 4.
* The effective field's brackets (integral Laurent backend) on flint against sympy's ring and against
  ``VectorField.bracket`` (Eq. CL1).
* The direct route's fraction-free fields (cross terms and operator columns, summed over their assignments) against
  ``liouville_field`` over the field, with and without python-flint (``NAMBU_BCH_DISABLE_FLINT=1``).
* Whole solves with flint, without flint and on the reference elimination (``FAST_PATHS = False``) give the same
  ``srepr`` of ``H_S, G_S``, of the members ``alpha = 0, 1`` (Eq. Xeff3) and of every order's corrections, on
  the rigid body with symbolic moments (Eqs. SH12321c, SG12321c generalised) and on a second N = 3 system whose
  parameters enter numerators and denominators (the rule is about ``QQ(params)``, not about one model).
* The per-order sympy forms converted on first access are those of ``PolynomialAlgebra.to_sympy``.
"""

from __future__ import annotations

import importlib

import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st
from sympy.polys.domains import QQ
from sympy.polys.matrices import DomainMatrix
from sympy.polys.matrices.sdm import SDM

from nambu_bch import System, liouville_field, model
from nambu_bch.algebra import PolynomialAlgebra, elimination, frac_rref
from nambu_bch.algebra.flint_ring import FlintRing
from nambu_bch.caches import clear_caches
from nambu_bch.shadow import shadow_hamiltonians

import shared_results as shared

pytest.importorskip("flint")


@pytest.fixture(autouse=True)
def _flint_on(monkeypatch):
    """Each test starts with python-flint on (even when the suite runs with NAMBU_BCH_DISABLE_FLINT=1) and switches
    it off itself where it compares with the pure path."""
    monkeypatch.delenv("NAMBU_BCH_DISABLE_FLINT", raising=False)

dr = importlib.import_module("nambu_bch.shadow.direct_route")
a, b = sympy.symbols("a b")
K = QQ.frac_field(a, b)
CTX = frac_rref.context(K)


def identical(u, v) -> bool:
    """The same field element in the same representation (numerator and denominator polynomials)."""
    return u.numer == v.numer and u.denom == v.denom


@st.composite
def rational_functions(draw, zero=True):
    """A random element of ``QQ(a, b)`` built by sympy's field (hence in its normal form)."""
    small = st.integers(-4, 4)

    def poly(terms):
        return sum((sympy.Rational(draw(small), draw(st.integers(1, 5))) * a ** draw(st.integers(0, 2))
                    * b ** draw(st.integers(0, 2)) for _ in range(terms)), sympy.Integer(0))

    num = poly(draw(st.integers(0 if zero else 1, 3)))
    den = poly(draw(st.integers(1, 2)))
    if den == 0:
        den = sympy.Integer(1)
    v = K.from_sympy(sympy.cancel(num / den))
    if not zero and not v:
        v = K.one
    return v


@settings(max_examples=60, deadline=None, derandomize=True)
@given(rational_functions(), rational_functions())
def test_fraction_arithmetic_is_sympys(u, v):
    """Round trip, product, difference and inverse on flint pairs are sympy's field elements, identically."""
    pu, pv = frac_rref.from_field(u, CTX), frac_rref.from_field(v, CTX)
    assert identical(frac_rref.to_field(pu, K), u)
    assert identical(frac_rref.to_field(frac_rref.mul(pu, pv), K), u * v)
    assert identical(frac_rref.to_field(frac_rref.sub(pu, pv), K), u - v)
    if u:
        assert identical(frac_rref.to_field(frac_rref.inverse(pu), K), 1 / u)


def test_normal_form_of_a_non_canonical_fraction():
    """A fraction with rational coefficients and a negative leading denominator: normalised as sympy's cancel."""
    R = K.field.ring
    numer = R.from_dict({(1, 0): QQ(2, 3), (0, 0): QQ(-4, 9)})           # 2a/3 - 4/9
    denom = R.from_dict({(2, 0): QQ(-6), (0, 1): QQ(12)})                 # -6a^2 + 12b
    raw = K.field.raw_new(numer, denom)
    assert identical(frac_rref.to_field(frac_rref.from_field(raw, CTX), K), K.field.new(numer, denom))
    common = R.from_dict({(1, 1): QQ(3), (0, 0): QQ(-1)})                # an unreduced fraction with integer parts
    raw = K.field.raw_new(common * R.from_dict({(0, 2): QQ(2)}), common * R.from_dict({(1, 0): QQ(-4)}))
    assert identical(frac_rref.to_field(frac_rref.from_field(raw, CTX), K), K.field.new(raw.numer, raw.denom))


@st.composite
def matrices(draw):
    """A sparse matrix over QQ(a, b), rank-deficient rows and zero entries included."""
    nrows, ncols = draw(st.integers(1, 6)), draw(st.integers(1, 6))
    rows = {}
    for i in range(nrows):
        row = {}
        for j in range(ncols):
            if draw(st.integers(0, 2)):
                v = draw(rational_functions())
                if v:
                    row[j] = v
        rows[i] = row
    if nrows > 2 and draw(st.booleans()):  # a dependent row
        c = draw(rational_functions(zero=False))
        rows[nrows - 1] = {j: c * v + rows[1].get(j, K.zero) for j, v in rows[0].items()}
        rows[nrows - 1] = {j: v for j, v in rows[nrows - 1].items() if v}
    return rows, nrows, ncols


@settings(max_examples=50, deadline=None, derandomize=True)
@given(matrices())
def test_rref_equals_domain_matrix(case):
    """frac_rref.rref is DomainMatrix.rref over QQ(a, b): same pivots, identical entries (the RREF is unique)."""
    rows, nrows, ncols = case
    live = {i: r for i, r in rows.items() if r}
    ref, pivots = DomainMatrix.from_rep(SDM(live, (nrows, ncols), K)).rref()
    ref = ref.rep.to_sdm()
    pairs = {i: {j: frac_rref.from_field(v, CTX) for j, v in r.items()} for i, r in live.items()}
    ours, our_pivots = frac_rref.rref(pairs, ncols, CTX)
    assert our_pivots == tuple(pivots)
    assert sorted(ours) == sorted(k for k, r in ref.items() if r)
    for k, row in ours.items():
        assert set(row) == set(ref[k])
        assert all(identical(frac_rref.to_field(v, K), ref[k][j]) for j, v in row.items())


@pytest.mark.parametrize("n, hams", [
    (2, ["a*x1**2/2 + x1*x2**3/3 - x2"]),                                   # canonical, X_H (Sect. 2.2)
    (3, ["a*x1**2/2 + b*x2**2/3 + x1*x2*x3", "x1**2/2 + x2**2/2 + x3**2/2 - x1*x3"]),
    (4, ["x1*x2 + a*x3**2", "x2**2 - x4*x1", "b*x3*x4 + x1**3/5"]),
])
def test_flint_ring_liouville_field_equals_sympy_ring(n, hams):
    """X_{H_1..H_{N-1}} (Eq. gLiouville) on flint's fmpq_mpoly equals the same on sympy's ring over QQ."""
    xs = sympy.symbols(f"x1:{n + 1}")
    plain = PolynomialAlgebra(xs, (), (a, b))
    R = FlintRing([str(s) for s in xs + (a, b)], n)
    polys = [plain.convert(sympy.sympify(H, locals={"a": a, "b": b})) for H in hams]
    ref = liouville_field(plain, *polys).components
    ours = liouville_field(R, *[R.from_terms(dict(p.items())) for p in polys]).components
    assert [R.terms(c) for c in ours] == [dict(c.items()) for c in ref]
    assert any(ref)


@pytest.mark.parametrize("flint", [True, False])
def test_fraction_free_fields_equal_liouville_field(flint, monkeypatch):
    """The direct route's fraction-free sum of fields (cross terms of orders 2 + 2 and 2 + 4, rigid body with
    symbolic I) equals the sum of liouville_field over QQ(I1, I2, I3), with and without python-flint."""
    R = shared.direct("rigid-body", "12321", 4)  # the input (the route is the same with and without flint)
    if not flint:
        monkeypatch.setenv("NAMBU_BCH_DISABLE_FLINT", "1")
    solver = dr._Solver(model("rigid-body"), R.composition, 4, None)
    c = R.corrections
    assignments = [[c[(0, 2)], c[(1, 2)]], [c[(0, 4)], c[(1, 2)]], [solver.hams[0], c[(1, 4)]]]
    ours = solver._fields_cleared(assignments)
    plain = None
    for slots in assignments:
        X = liouville_field(solver.alg, *slots)
        plain = X if plain is None else plain + X
    assert ours.components == plain.components and any(ours.components)
    assert isinstance(solver._plain_ring(), FlintRing) == flint


def test_fraction_free_fields_clear_denominators_on_flint(monkeypatch):
    """With python-flint a correction ``P`` is cleared to ``Q / D`` in flint's ``ZZ[params]`` (``D`` the lcm of its
    coefficients' denominators): ``Q`` divided back by ``D`` is ``P`` coefficient by coefficient, and a sum of
    fields runs without sympy's polynomial lcm or exact division (rigid body with symbolic I, orders 2 and 4)."""
    from sympy.polys.rings import PolyElement

    R = shared.direct("rigid-body", "12321", 4)
    solver = dr._Solver(model("rigid-body"), R.composition, 4, None)
    c, ctx, plain = R.corrections, solver._flint_context(), solver._plain_ring()
    width = len(solver.alg.gens)
    for P in (c[(0, 2)], c[(1, 4)]):
        Q, D = solver._clear_flint(P, plain.from_terms, ctx)
        assert not D.is_constant()  # the parameters do occur in the denominators
        groups: dict = {}
        for m, q in plain.terms(Q).items():
            groups.setdefault(m[:width], {})[m[width:]] = q
        assert dr._divided(groups, D, solver.alg.domain, ctx) == dict(P.items())

    def refuse(*args):
        raise AssertionError("sympy polynomial arithmetic on the denominators")

    assignments = [[c[(0, 2)], c[(1, 2)]], [c[(0, 4)], c[(1, 2)]]]
    expected = [liouville_field(solver.alg, *slots) for slots in assignments]
    with monkeypatch.context() as m:
        m.setattr(PolyElement, "lcm", refuse)
        m.setattr(PolyElement, "exquo", refuse)
        ours = solver._fields_cleared(assignments)
    assert ours.components == (expected[0] + expected[1]).components


def test_right_hand_side_difference_on_flint_pairs(monkeypatch):
    """The right-hand side ``Z_j - (cross terms)`` of Eq. (*) subtracted on flint pairs is sympy's ``Z_j - cross``,
    the same elements with the terms in the same order (they intern the elimination's rows), without sympy's field
    subtraction (rigid body with symbolic I, h^4; and a difference in which a term cancels and one is new)."""
    from sympy.polys.fields import FracElement

    R = shared.direct("rigid-body", "12321", 4)
    solver = dr._Solver(model("rigid-body"), R.composition, 4, None)
    alg, ctx = solver.alg, solver._flint_context()
    Z = [dr._lift(alg, z) for z in solver.effective[4].components]
    expected = [z - x for z, x in zip(Z, solver._cross(4, R.corrections).components)]

    def refuse(*args):
        raise AssertionError("sympy's field subtraction")

    with monkeypatch.context() as m:
        m.setattr(FracElement, "__sub__", refuse)
        cross = solver._cross(4, R.corrections, as_pairs=True)
        ours = [solver._subtracted(z, x) for z, x in zip(Z, cross)]
    assert [list(p.items()) for p in ours] == [list(p.items()) for p in expected] and any(expected)
    c = next(z for z in Z if len(z) > 1)
    (m0, v0), (m1, _) = list(c.items())[:2]
    new = tuple(e + 1 for e in m0[:alg.n]) + m0[alg.n:]
    x = {m0: frac_rref.from_field(v0, ctx), new: frac_rref.from_field(v0 * 2, ctx)}
    other = alg.ring.from_dict({m0: v0, new: v0 * 2})
    assert list(solver._subtracted(c, x).items()) == list((c - other).items())
    assert m0 not in solver._subtracted(c, x) and m1 in solver._subtracted(c, x)


def _digest(family):
    """srepr of the shadow pair, of the members alpha = 0, 1, of every order's corrections, members and gauge
    (everything ``to_dict`` and the printers are computed from)."""
    orders = [(o.order, o.status, o.kernel_dim, o.psi_dim, [sympy.srepr(x) for x in o.corrections],
               [[sympy.srepr(x) for x in m] for m in o.members], [[sympy.srepr(x) for x in g] for g in o.gauge])
              for o in family.details.orders]
    return ([sympy.srepr(S) for S in family.shadows], [sympy.srepr(m) for m in family.member(alpha=0)],
            [sympy.srepr(m) for m in family.member(alpha=1)], orders, family.free_parameters, family.notes)


SYSTEMS = {
    "rigid-body": lambda: model("rigid-body"),
    # parameters in numerators and denominators, not only as reciprocals
    "n3-params": lambda: System("x1 x2 x3", ["a*x1**2/2 + x2**2/(2*b) + x3**2/2", "x1**2/2 + x2**2/2 + b*x3**2/2"],
                                "a b", name="n3-params"),
}


@pytest.mark.parametrize("name, word, order, reference", [("rigid-body", "12321", 4, False),
                                                          ("n3-params", "12321", 4, True), ("n3-params", "123", 2, True)])
def test_solves_identical_with_and_without_flint(name, word, order, reference, monkeypatch):
    """Flint paths, pure sympy (NAMBU_BCH_DISABLE_FLINT=1) and the reference elimination (FAST_PATHS = False)
    give the same objects: shadow pair, members alpha = 0, 1 (Eq. Xeff3), every order's corrections and gauge."""
    clear_caches()  # the effective field's backends are cached per splitting: built afresh for each path
    fast = _digest(shadow_hamiltonians(SYSTEMS[name](), word, order))
    monkeypatch.setenv("NAMBU_BCH_DISABLE_FLINT", "1")
    clear_caches()
    assert _digest(shadow_hamiltonians(SYSTEMS[name](), word, order)) == fast
    if reference:
        monkeypatch.setattr(elimination, "FAST_PATHS", False)
        clear_caches()
        assert _digest(shadow_hamiltonians(SYSTEMS[name](), word, order)) == fast
    clear_caches()
    assert sum(o[1] == "solved" for o in fast[3]) >= 2


@pytest.mark.parametrize("name", sorted(SYSTEMS))
def test_flint_brackets_equal_sympy_ring(name, monkeypatch):
    """The integral Laurent backend's brackets on flint (algebra/backend.py) equal those on sympy's ring and the
    vector fields' own Lie bracket (Eq. CL1, an independent route): all brackets of the pieces to depth 3,
    combined with integer and rational weights."""
    from nambu_bch.algebra.backend import PolynomialBackend

    splitting = SYSTEMS[name]().splitting
    alg = splitting.system.algebra
    fields = {p.number: p.field for p in splitting.pieces}

    def brackets(F):
        keys = sorted(F.fields)
        one = {k: F.fields[k] for k in keys}
        two = {(i, j): F.bracket(one[i], one[j]) for i in keys for j in keys if i < j}
        three = {(k, ij): F.bracket(one[k], X) for k in keys for ij, X in two.items()}
        out = [F.combine([(1, X)]) for X in list(two.values()) + list(three.values())]
        out.append(F.scaled_combine(6, [(n, X) for n, X in zip(range(-3, 9), list(three.values()))]))
        out.append(F.combine([(sympy.Rational(2, 7), X) for X in two.values()]))
        return out, two

    fast = PolynomialBackend.build(alg, fields)
    assert fast.laurent and fast.flint is not None
    ours, two = brackets(fast)
    monkeypatch.setenv("NAMBU_BCH_DISABLE_FLINT", "1")
    slow = PolynomialBackend.build(alg, fields)
    assert slow.flint is None
    assert [X.components for X in ours] == [X.components for X in brackets(slow)[0]]
    assert any(any(X.components) for X in ours)
    for (i, j), X in two.items():   # [X_i, X_j] as the vector fields compute it
        assert fast.combine([(1, X)]) == fields[i].bracket(fields[j])


def test_lazy_sympy_forms():
    """The per-order sympy forms, converted on first access, are to_sympy of the family's and members' ring
    elements; the family's corrections mapping equals the dict of the solved orders' corrections."""
    S = SYSTEMS["n3-params"]()
    F = shadow_hamiltonians(S, "12321", 4)
    R = F.details
    solved = [o for o in R.orders if o.status == "solved"]
    assert solved and all(o.convert is not None for o in solved)         # nothing converted yet
    for o in solved:
        expected = tuple(R.algebra.to_sympy(R.corrections[(k, o.order)]) for k in range(2))
        assert o.corrections == expected and o.convert is None
        assert len(o.members) == 2
        # the members solve Eq. (*) as the family does: family = (1 - alpha) m0 + alpha m1 (Eq. Xeff3)
        alpha = sympy.Symbol("alpha")
        assert all(sympy.expand(f - ((1 - alpha) * m0 + alpha * m1)) == 0
                   for f, m0, m1 in zip(o.corrections, *o.members))
    assert dict(F.corrections) == {o.order: o.corrections for o in solved}
    assert F.corrections == {o.order: o.corrections for o in solved} and len(F.corrections) == len(solved)


def test_parameter_names_are_not_passed_to_flint():
    """flint's contexts use generated ASCII names: a parameter named ``ω`` (allowed in a PolynomialAlgebra) works,
    and the solution of L x = b over QQ(ω) is the reference elimination's."""
    w = sympy.Symbol("ω")
    Kw = QQ.frac_field(w)
    cols = [{0: Kw.from_sympy(w), 1: Kw.one}, {0: Kw.one, 1: Kw.from_sympy(1 / (w + 1))}]
    rhs = [{0: Kw.from_sympy(w**2), 1: Kw.from_sympy(sympy.Rational(1, 3))}]
    L = elimination.SparseMatrix.from_columns(cols, 2, Kw)
    ours = elimination.solve_affine(L, rhs)
    try:
        elimination.FAST_PATHS = False
        plain = elimination.solve_affine(L, rhs)
    finally:
        elimination.FAST_PATHS = True
    assert ours.particular == plain.particular and ours.consistent
    assert all(identical(ours.particular[0][c], plain.particular[0][c]) for c in plain.particular[0])


@pytest.mark.parametrize("numer, denom", [(0, 1), (3, 1), (-3, 4), (3, -6), (-2, -8)])
def test_rational_constants_convert_in_the_normal_form(numer, denom):
    """A constant of QQ(a, b), reduced or not (a negative denominator too), as the pair ``(p/q, 1)``-normal form and
    back: the element sympy's field gives, identically (constants take a shortcut past the polynomial conversion)."""
    R = K.field.ring
    raw = K.field.raw_new(R.from_dict({(0, 0): QQ(numer)}), R.from_dict({(0, 0): QQ(denom)}))
    n, d = frac_rref.from_field(raw, CTX)
    q = sympy.Rational(numer, denom)
    assert (n, d) == (CTX.constant(int(q.p)), CTX.constant(int(q.q)))
    assert identical(frac_rref.to_field((n, d), K), K.from_sympy(q))


def test_family_combination_on_flint_pairs_is_sympys():
    """``m0 + alpha (m1 - m0)`` with the differences on flint pairs: sympy's ring element, the same field elements and
    the same term order, with cancelling coefficients and a shifted term landing on one of ``m0``'s own."""
    from types import SimpleNamespace

    x, alpha = sympy.symbols("x alpha")
    alg = PolynomialAlgebra([x], [a, b], constants=[alpha])
    m0 = alg.convert(x**2 / a + (a - b) / (a + b) * x + alpha / (a * b) + 3)          # alpha^1 in m0 itself
    m1 = alg.convert(x**2 / a + (a + b) * x / (a - b) + 2 * alpha * x - 7)             # x^2 cancels in m1 - m0
    shift = (0, 1)  # alpha
    got = dr._Solver._family_flint(SimpleNamespace(alg=alg), m0, m1, shift, frac_rref.context(alg.domain))
    want = m0 + (m1 - m0).mul_monom(shift)
    assert got == want and list(got) == list(want)
    assert all(identical(got[m], want[m]) for m in want)
    same = dr._Solver._family_flint(SimpleNamespace(alg=alg), m0, m0, shift, frac_rref.context(alg.domain))
    assert same == m0 and list(same) == list(m0)
