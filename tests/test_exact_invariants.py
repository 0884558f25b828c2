"""Exact conserved quantities of the discrete maps: Eqs. (CQPV), (CQ12321H), (CQ12321G), Table (table),
and Eqs. (XHc), (XHcGc): they are conserved but they are not the shadow Hamiltonians.

Horikoshi, *Shadow Hamiltonians of structure-preserving integrators for Nambu mechanics*.
"""

from __future__ import annotations

import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from nambu_bch import PAPER_WORDS, System, composed_map, liouville_field, model
from nambu_bch.bch import effective_field
from nambu_bch.errors import InvalidOrderError, NambuBCHError
from nambu_bch.exact import conserved_quantities, invariants, is_invariant

x1, x2, x3, m, omega, h = sympy.symbols("x1 x2 x3 m omega h")
H2 = x2**2 / (2 * m) + m * omega**2 * x1**2 / 2  # Eq. (HO1)
H = x2**2 / (2 * m) + m * omega**2 * x3 / 2  # Eq. (H)
G = x3 - x1**2  # Eq. (G)

# Table (table): (H_c, G_c) for the six second-order integrators of the N = 3 oscillator
TABLE = {
    "12321": (H, G + h**2 * x2**2 / (4 * m**2)),  # Eqs. (CQ12321H), (CQ12321G)
    "13231": (H, G + h**2 * x2**2 / (4 * m**2)),
    "31213": (H - omega**2 * h**2 * x2**2 / (4 * m), G - h**2 * x2**2 / (4 * m**2)),
    "21312": (H - m * omega**4 * h**2 * x1**2 / 8, G),
    "23132": (H - m * omega**4 * h**2 * x1**2 / 8, G),
    "32123": (H + m * omega**4 * h**2 * x1**2 / 8, G + omega**2 * h**2 * x1**2 / 2),
}


def _invariant_by_substitution(system, word, quantity) -> bool:
    phi = composed_map(system.splitting, word)
    image = quantity.subs(dict(zip(system.coordinates, phi)), simultaneous=True)
    return sympy.expand(image - quantity) == 0


def test_position_verlet_CQPV():
    """Eq. (CQPV): H_c = H - omega^2 h^2 x2^2 / (8m) for Phi^TVT on the oscillator."""
    ho = model("ho")
    cq = conserved_quantities(ho, "TVT")
    assert sympy.expand(cq.H_c - (H2 - omega**2 * h**2 * x2**2 / (8 * m))) == 0
    assert cq.G_c is None
    assert _invariant_by_substitution(ho, "121", cq.H_c)
    assert not _invariant_by_substitution(ho, "121", H2)


def test_velocity_verlet_on_ho():
    """VTV: the conserved quantity of Eq. (equiv2)'s 2-d map, H - m omega^4 h^2 x1^2 / 8 (Table (table), rows 21312)."""
    cq = conserved_quantities(model("ho"), "VTV")
    assert sympy.expand(cq.H_c - (H2 - m * omega**4 * h**2 * x1**2 / 8)) == 0
    assert _invariant_by_substitution(model("ho"), "212", cq.H_c)


@pytest.mark.parametrize("word", PAPER_WORDS)
def test_table_rows(word):
    """Every row of Table (table), checked as an exact invariant by substituting the composed map."""
    ho3 = model("ho3")
    cq = conserved_quantities(ho3, word)
    H_c, G_c = TABLE[word]
    assert sympy.expand(cq.H_c - H_c) == 0, cq.H_c
    assert sympy.expand(cq.G_c - G_c) == 0, cq.G_c
    assert _invariant_by_substitution(ho3, word, H_c)
    assert _invariant_by_substitution(ho3, word, G_c)
    assert is_invariant(ho3, word, cq.H_c) and is_invariant(ho3, word, cq.G_c)
    assert len(cq.quantities) == 2  # all invariants of degree <= 2 modulo constants
    assert cq.check()
    # the normalisation: H_c -> H, G_c -> G as h -> 0
    assert sympy.expand(cq.H_c.subs(h, 0) - H) == 0 and sympy.expand(cq.G_c.subs(h, 0) - G) == 0


def test_original_hamiltonians_are_not_conserved():
    ho3 = model("ho3")
    assert not _invariant_by_substitution(ho3, "32123", H)
    assert not _invariant_by_substitution(ho3, "32123", G)
    assert _invariant_by_substitution(ho3, "12321", H)  # Eq. (CQ12321H): H itself is conserved


def test_XHc_is_not_X_eff():
    """Eq. (XHc): X_{H_c} = (1 - omega^2 h^2/4) x2/m d/dx1 - m omega^2 x1 d/dx2, which is not X_eff."""
    ho = model("ho")
    cq = conserved_quantities(ho, "121")
    X = liouville_field(ho.algebra, cq.H_c).to_sympy()
    assert sympy.expand(X[0] - (1 - omega**2 * h**2 / 4) * x2 / m) == 0
    assert sympy.expand(X[1] + m * omega**2 * x1) == 0
    Xeff = effective_field(ho.splitting, "121", 2).to_sympy()
    assert any(sympy.expand(a - b) != 0 for a, b in zip(X, Xeff))


def test_XHcGc_is_not_X_eff():
    """Eq. (XHcGc) for Phi^12321, and X_{H_c,G_c} != X_eff already at h^2."""
    ho3 = model("ho3")
    cq = conserved_quantities(ho3, "12321")
    X = liouville_field(ho3.algebra, cq.H_c, cq.G_c).to_sympy()
    expected = ((1 - omega**2 * h**2 / 4) * x2 / m, -m * omega**2 * x1, 2 * x1 * x2 / m)
    assert all(sympy.expand(a - b) == 0 for a, b in zip(X, expected))
    Z = effective_field(ho3.splitting, "12321", 2)
    diff = [sympy.expand(sympy.expand(a).coeff(h, 2) - b) for a, b in zip(X, Z[2].to_sympy())]
    assert any(d != 0 for d in diff)


def test_higher_degree_ansatz_contains_products():
    """With degree 4 the invariants include products of H_c and G_c; H_c, G_c stay the paper's."""
    ho3 = model("ho3")
    cq = conserved_quantities(ho3, "32123", degree=4)
    assert cq.degree == 4
    H_c, G_c = TABLE["32123"]
    assert sympy.expand(cq.H_c - H_c) == 0 and sympy.expand(cq.G_c - G_c) == 0
    assert len(cq.quantities) == 5  # H_c, G_c, H_c^2, H_c G_c, G_c^2
    for q in cq.quantities:
        assert _invariant_by_substitution(ho3, "32123", q)


def test_default_degree_and_output():
    cq = conserved_quantities(model("ho3"), "12321")
    assert cq.degree == 2
    d = cq.to_dict()
    names = model("ho3").symbols()
    assert sympy.expand(sympy.sympify(d["H_c"], locals=names) - TABLE["12321"][0]) == 0
    assert sympy.expand(sympy.sympify(d["G_c"], locals=names) - TABLE["12321"][1]) == 0
    # Table (table), row 12321, as the paper writes it: H_c = H, G_c = G + h^2 x2^2/(4 m^2)
    assert "H_{c} &= H," in cq.to_latex() and r"G_{c} &= G + \frac{h^{2} x_{2}^{2}}{4 m^{2}}" in cq.to_latex()
    assert cq._repr_latex_() == "$$" + cq.to_latex() + "$$"


def test_no_invariant_near_H_for_rigid_body():
    cq = conserved_quantities(model("rigid-body"), "12321")
    assert cq.H_c is None and cq.G_c is None
    data = cq.to_dict()
    assert {k: data[k] for k in ("H_c", "G_c", "series")} == {"H_c": None, "G_c": None, "series": {}}


@pytest.fixture(scope="module")
def rigid_body_setup():
    """The rigid body's 12321 prepared for a degree-2 search (the map composed once for the tests below)."""
    from nambu_bch import composition

    return invariants._Setup(model("rigid-body"), composition("12321", 3), 2)


def test_rigid_body_none_is_certified_at_a_point_without_the_exact_images(rigid_body_setup, monkeypatch):
    """"No invariant of degree <= 2" is decided by the rank at one rational point: the map is never converted to
    K[x] = QQ(I1, I2, I3, h)[x] and nothing is eliminated over K (that route took ~3.6 s of images)."""
    setup = rigid_body_setup
    monkeypatch.setattr(invariants, "nullspace", lambda matrix: pytest.fail("eliminated over K"))
    assert invariants._invariant_basis(setup, 2) == []
    assert "phi" not in setup.__dict__


def test_point_certificate_skips_points_where_a_denominator_vanishes(rigid_body_setup, monkeypatch):
    """The map divides by I1, I2, I3: a point with I1 = 0 is not used (the next one is), and with no usable point
    there is no certificate (the caller eliminates over K)."""
    setup, monos = rigid_body_setup, rigid_body_setup.monomials(2)
    monkeypatch.setattr(invariants, "_POINTS", ((0, 5, 7, 11), (3, 5, 7, 11)))
    assert invariants._no_invariant_at_a_point(setup, monos)
    monkeypatch.setattr(invariants, "_POINTS", ((3, 0, 7, 11),))
    assert not invariants._no_invariant_at_a_point(setup, monos)
    monkeypatch.setattr(invariants, "_POINTS", ((3, 5, 7),))  # fewer values than parameters and h
    assert not invariants._no_invariant_at_a_point(setup, monos)


def test_map_at_a_point_is_exact_and_refuses_what_it_cannot_evaluate():
    """The specialised map is evaluated node by node over QQ: a zero denominator is a ZeroDivisionError (the point
    is skipped), and an algebraic number, exp(2) or a coordinate in a denominator is no certificate at all."""
    from sympy.polys.domains import QQ
    from sympy.polys.rings import PolyRing

    ring = PolyRing((x1, x2), QQ)
    values = {m: ring(3), omega: ring(0), h: ring(5), x1: ring.gens[0], x2: ring.gens[1]}
    at = invariants._at_point
    assert at(x1 + h**2 * x2 / (2 * m) - x1**2 * m**-2, values, ring) == ring.from_expr(x1 + 25 * x2 / 6 - x1**2 / 9)
    with pytest.raises(ZeroDivisionError):
        at(x1 + h * x2 / (m * omega), values, ring)
    for bad in (sympy.cbrt(2) * x1, sympy.exp(2) * x1, h / x1, sympy.Symbol("other") * x1):
        with pytest.raises(invariants._NotRational):
            at(bad, values, ring)


def test_point_certificate_never_claims_none_when_invariants_exist():
    """ho3's 12321 has H_c and G_c: the matrix is rank-deficient at every point, the certificate declines and the
    exact elimination finds both (Eqs. (CQ12321H), (CQ12321G))."""
    from nambu_bch import composition

    setup = invariants._Setup(model("ho3"), composition("12321", 3), 2)
    assert not invariants._no_invariant_at_a_point(setup, setup.monomials(2))
    assert len(invariants._invariant_basis(setup, 2)) == 2


def test_user_system_and_composition_object():
    from nambu_bch import composition

    ho3 = model("ho3")
    comp = composition("32123", 3)
    cq = conserved_quantities(ho3, comp)
    assert sympy.expand(cq.H_c - TABLE["32123"][0]) == 0
    S = System("x1 x2 x3", ["x2**2/2 + 2*x3", "x3 - x1**2"], (), name="ho3-numeric")  # m = 1, omega = 2
    cq = conserved_quantities(S, "12321")
    assert sympy.expand(cq.G_c - (x3 - x1**2 + h**2 * x2**2 / 4)) == 0


@pytest.mark.parametrize("degree", [0, -1, 2.5, "2", True, 99])
def test_bad_degree(degree):
    with pytest.raises(InvalidOrderError, match="degree"):
        conserved_quantities(model("ho3"), "12321", degree=degree)


def test_exponential_map_lotka_volterra(monkeypatch):
    """The Lotka-Volterra pieces X_{x_i, G} conserve G = x1 x2 x3 exactly; no polynomial invariant tends to H.

    Each component of the map is x_i exp(a_i): x^mu is invariant exactly when <mu, a> expands to zero, read off
    without expanding the images (_exp_images, ~3 s at degree 3, is not called)."""
    from nambu_bch import composition

    lv = model("lotka-volterra")
    with monkeypatch.context() as patch:
        patch.setattr(invariants, "_exp_images", lambda setup, monos: pytest.fail("images expanded"))
        setup = invariants._Setup(lv, composition("12321", 3), 3)
        assert invariants._invariant_basis(setup, 3) == [setup.R.from_expr(x1 * x2 * x3)]
    cq = conserved_quantities(lv, "12321")  # (a word over all three pieces; 121 would leave piece 3 out)
    assert cq.H_c is None
    assert sympy.expand(cq.G_c - x1 * x2 * x3) == 0
    assert cq.quantities == (cq.G_c,)
    assert is_invariant(lv, "12321", cq.G_c)


def test_exponents_only_of_monomial_times_exponential_maps():
    """The read-off applies to maps x_i -> x_i exp(a_i) only; a sum, a coefficient or another coordinate in front
    falls back to the images."""
    from types import SimpleNamespace

    a, b = h * x2, -h * x1 * sympy.exp(h * x2)
    setup = SimpleNamespace(coords=(x1, x2), phi_exprs=(x1 * sympy.exp(a) * sympy.exp(b), x2))
    assert invariants._exponents(setup) == [a + b, 0]
    for first in (x1 * sympy.exp(a) + x2, 2 * x1 * sympy.exp(a), x2 * sympy.exp(a), x1**2 * sympy.exp(a)):
        assert invariants._exponents(SimpleNamespace(coords=(x1, x2), phi_exprs=(first, x2))) is None


def test_bad_word():
    with pytest.raises(NambuBCHError):
        conserved_quantities(model("ho3"), "12x21")


@settings(deadline=None, max_examples=25)
@given(
    word=st.sampled_from(PAPER_WORDS),
    state=st.tuples(*[st.fractions(min_value=-5, max_value=5, max_denominator=50)] * 3),
    params=st.tuples(st.fractions(min_value=sympy.Rational(1, 4), max_value=4, max_denominator=20),
                     st.fractions(min_value=sympy.Rational(1, 4), max_value=4, max_denominator=20),
                     st.fractions(min_value=sympy.Rational(1, 100), max_value=1, max_denominator=100)),
)
def test_property_invariant_along_exact_rational_orbits(word, state, params):
    """H_c, G_c are constant along orbits of the map computed in exact rational arithmetic (three steps)."""
    ho3 = model("ho3")
    cq = conserved_quantities(ho3, word)
    mv, wv, hv = (sympy.Rational(p.numerator, p.denominator) for p in params)
    num = {m: mv, omega: wv, h: hv}
    phi = [e.subs(num) for e in composed_map(ho3.splitting, word)]
    Hc, Gc = cq.H_c.subs(num), cq.G_c.subs(num)
    point = dict(zip((x1, x2, x3), (sympy.Rational(s.numerator, s.denominator) for s in state)))
    start = (Hc.xreplace(point), Gc.xreplace(point))
    assert all(v.is_Rational for v in start)
    for _ in range(3):
        point = dict(zip((x1, x2, x3), (e.xreplace(point) for e in phi)))
        assert (Hc.xreplace(point), Gc.xreplace(point)) == start


def _never(*args, **kwargs):
    raise AssertionError("the composed map was built")


def test_invariant_search_too_large_is_refused_up_front(monkeypatch):
    """Bounded work: the rigid body's 12321 at ansatz degree 4 (at most 153 723 image terms, 142 455 on the composed
    map, 200 s) is refused in one line from a bound on the sub-flows, before the composed map is built (that alone
    took 0.75 s); so is a long word, whose composed map would itself be the hang."""
    import nambu_bch.exact.invariants as inv
    from nambu_bch.errors import ResourceLimitError

    monkeypatch.setattr(inv, "composed_map", _never)
    with pytest.raises(ResourceLimitError, match=r"degree 4 on rigid-body with the word 12321 needs images of up to "
                                                 r"153723 terms.*\(at most 40000\); lower the degree"):
        conserved_quantities(model("rigid-body"), "12321", degree=4)
    with pytest.raises(ResourceLimitError, match="degree 1 on rigid-body with the word triple-jump:12321 .* 13 sub-flows"):
        conserved_quantities(model("rigid-body"), "yoshida", degree=1)


@pytest.mark.parametrize("name,word", [("ho3", "12321"), ("ho3", "32123"), ("ho3-pair", "31213"),
                                       ("henon-heiles", "VTV")])
def test_size_bound_is_never_below_the_composed_map(name, word):
    """The bound from the sub-flows is an upper bound: per component at least the composed map's terms and degree."""
    import nambu_bch.exact.invariants as inv
    from nambu_bch.integrators import composition_for
    from nambu_bch.integrators.flows import exact_flow

    system = model(name)
    comp = composition_for(word, system)
    flows = [exact_flow(system.splitting[k], system.coordinates) for k, _ in comp.factors()]
    counts, degrees = inv.composed_map_shape(flows, system.coordinates)
    for e, t, d in zip(composed_map(system.splitting, comp), counts, degrees):
        p = sympy.Poly(sympy.expand(e), *system.coordinates)
        assert len(p.terms()) <= t and p.total_degree() <= d


@pytest.mark.parametrize("name,degree,bound", [("ho3", 8, 35141), ("rigid-body", 3, 39616)])
def test_size_bound_admits_what_ran_before(name, degree, bound):
    """The largest requests that ran with the estimate on the composed map (ho3 at degree 8, 15 s; the rigid body's
    12321 at degree 3, 13 s) stay under the limit with the bound from the sub-flows (checked without running them)."""
    import nambu_bch.exact.invariants as inv
    from nambu_bch.integrators import composition_for
    from nambu_bch.integrators.flows import exact_flow

    system = model(name)
    comp = composition_for("12321", system)
    flows = [exact_flow(system.splitting[k], system.coordinates) for k, _ in comp.factors()]
    monos = inv.Ansatz(3, degree, lowest=1, order="graded").monomials
    assert inv.image_terms(*inv.composed_map_shape(flows, system.coordinates), monos) == bound <= inv.MAX_IMAGE_TERMS


def test_rotation_sub_flows_are_refused_before_the_map_is_composed(monkeypatch):
    """The Lie-Poisson rigid body splits into rotations (cos/sin sub-flows): no polynomial invariant search, and the
    refusal comes before the trigonometric composed map is built (it took 2-5 s of sympy expand to refuse)."""
    import nambu_bch.exact.invariants as inv
    from nambu_bch.errors import NoExactResultError

    monkeypatch.setattr(inv, "composed_map", _never)
    with pytest.raises(NoExactResultError, match="trigonometric sub-flows"):
        conserved_quantities(model("rigid-body-lp"), "12321")
