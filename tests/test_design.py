"""Tests of nambu_bch.design: error constants, order conditions, designed compositions, comparisons.

Published error constants (LEM) are those of SplittingOrderConditions.jl (H. Hofstaetter),
``examples/CheckMethods.ipynb``, table "AB / ABC": the ABC column is the AB method with B
split Strang-like, i.e. the package's 3-part words built on 12321.  Each value is also
checked a second, independent way (hand computation or the formal BCH engine).
"""

from __future__ import annotations

import json
from fractions import Fraction
from math import factorial
from pathlib import Path

import numpy as np
import pytest
import sympy

import nambu_bch as nb
from nambu_bch.bch import formal_bch, lie_to_associative
from nambu_bch.cli import main
from nambu_bch.design import (
    Template,
    compare,
    composition_order,
    cost,
    error_analysis,
    error_constant,
    leading_error,
    optimize_composition,
    order_conditions,
    template,
)
from nambu_bch.design.catalog import CatalogComposition, lookup, methods
from nambu_bch.design.compare import slope
from nambu_bch.design.words import log_coefficients, lyndon_defect_words, lyndon_defects, word_coefficient, word_coefficients
from nambu_bch.errors import InvalidCompositionError, InvalidOrderError, InvalidRunError, NambuBCHError

F1 = Fraction(1)
F0 = Fraction(0)


def _inv(m):
    return Fraction(1, factorial(m))


# ------------------------------------------------------------------------------------------------
# 1. error constants


@pytest.mark.parametrize(
    "spec, parts, order, published",
    [
        ("lie-trotter", 2, 1, 1.00), ("lie-trotter", 3, 1, 1.73),          # CheckMethods: Lie-Trotter
        ("strang", 2, 2, 0.56), ("strang", 3, 2, 1.20),                      # Strang
        ("forest-ruth", 2, 4, 3.72), ("triple-jump:12321", 3, 4, 26.04),     # Y 4-4 (triple jump)
        ("yoshida6:121", 2, 6, 16.17), ("yoshida6:12321", 3, 6, 90.86),      # Y 8-6 (Yoshida 1990, sol. A)
        ("kahan-li:121", 2, 6, 1.84), ("kahan-li:12321", 3, 6, 10.70),       # KL 10-6 (Kahan & Li 1997)
    ],
)
def test_published_error_constants(spec, parts, order, published):
    E = error_analysis(spec, parts)
    assert E.order == order
    assert round(E.value, 2) == published
    assert abs(error_constant(spec, parts) - E.value) < 1e-12


def test_error_constants_by_hand():
    # Lie-Trotter e^A e^B: degree-2 part AB + (A^2 + B^2)/2 minus (A+B)^2/2 = (AB - BA)/2; 2! * 1/2 = 1 per Lyndon word
    assert error_analysis("12", 2).squared == 1
    assert error_analysis("123", 3).squared == 3                     # AB, AC, BC
    # Strang: log = A + B - [A,[A,B]]/24 + [[A,B],B]/12; Lyndon words AAB, ABB carry 3!(-1/24), 3!(1/12)
    assert error_analysis("121", 2).squared == sympy.Rational(5, 16)
    assert error_analysis("121", 2).defects == {(1, 1, 2): sympy.Rational(-1, 4), (1, 2, 2): sympy.Rational(1, 2)}


@pytest.mark.parametrize("spec, parts", [("12321", 3), ("32123", 3), ("forest-ruth", 2), ("triple-jump:12321", 3),
                                         ("suzuki:12321", 3), ("123", 3), ("1:1/3,2:1/2,1:2/3,2:1/2", 2)])
def test_error_constant_agrees_with_formal_bch(spec, parts):
    """Second route: the Lyndon-basis log of the formal BCH engine, expanded into words (P_w = w + larger)."""
    E = error_analysis(spec, parts)
    q = E.order + 1
    B = formal_bch(spec, q, n_pieces=parts)
    for d in range(2, q):
        assert B.terms(d) == []                                       # order p: nothing below degree p + 1
    assoc = lie_to_associative(B.terms(q))
    for w in lyndon_defect_words(parts, q):
        assert sympy.simplify(factorial(q) * assoc.get(w, 0) - E.defects[w]) == 0, w


@pytest.mark.parametrize("word, parts", [("12", 2), ("121", 2), ("123", 3), ("1213121", 3)])
def test_log_coefficients_agree_with_formal_bch(word, parts):
    comp = nb.composition("1:1/2,2:1/3,1:1/2,2:2/3" if word == "1213121" else word)
    parts = max(comp.pieces)
    factors = [(k, Fraction(int(c.p), int(c.q))) for k, c in comp.factors()]
    B = formal_bch(comp, 6)
    for q in range(2, 7):
        ours = log_coefficients(factors, parts, q, F1, F0, Fraction)
        assoc = lie_to_associative(B.terms(q))
        assert all(ours[w] == assoc.get(w, 0) for w in ours), (word, q)


def test_word_coefficient_small_cases():
    # e^{aA} e^{bB}: [AB] = ab, [BA] = 0, [AAB] = a^2 b / 2; e^{A} e^{A}: [AA] = 4/2 = 2
    fac = [(1, Fraction(2)), (2, Fraction(3))]
    assert word_coefficient((1, 2), fac, F1, F0, _inv) == 6
    assert word_coefficient((2, 1), fac, F1, F0, _inv) == 0
    assert word_coefficient((1, 1, 2), fac, F1, F0, _inv) == 6
    assert word_coefficient((1, 1), [(1, F1), (1, F1)], F1, F0, _inv) == 2
    d = lyndon_defects([(1, F1), (2, F1)], 2, 2, F1, F0, _inv)
    assert d == {(1, 2): 1}


def test_word_coefficients_of_a_prefix_tree_equal_the_block_sums():
    """The shared-prefix walk (words.word_coefficients) against the definition (module docstring of design/words):
    [w] = sum over the splittings of w into consecutive blocks, block j empty or k_j^m, of prod c_j^m / m!."""
    from itertools import product

    fac = [(1, Fraction(1, 3)), (2, Fraction(-2, 5)), (3, Fraction(3, 7)), (2, Fraction(5, 4)), (1, Fraction(2, 3)),
           (1, Fraction(-1, 2))]

    def block_sum(w, j=0):
        if j == len(fac):
            return F1 if not w else F0
        k, c = fac[j]
        total, m = block_sum(w, j + 1), 1
        while m <= len(w) and w[m - 1] == k:
            total += c**m * _inv(m) * block_sum(w[m:], j + 1)
            m += 1
        return total

    words = [w for q in range(6) for w in product((1, 2, 3), repeat=q)]
    got = word_coefficients(words, fac, F1, F0, _inv)
    assert len(got) == len(words) and all(got[w] == block_sum(w) for w in words)
    assert all(word_coefficient(w, fac, F1, F0, _inv) == got[w] for w in words[:40])


def test_error_constant_bad_input():
    with pytest.raises(InvalidCompositionError, match="every piece 1..3"):
        error_constant("13", 3)                # pieces 1 and 2 on three parts: the ABC rule (test_design_methods)
    with pytest.raises(InvalidCompositionError, match="parts"):
        error_constant("12", 0)
    with pytest.raises(NambuBCHError):
        error_constant("not-a-method", 2)


# ------------------------------------------------------------------------------------------------
# 2. catalog


def test_catalog_methods_orders_and_bounds():
    from nambu_bch.integrators.tables import TABLES

    for name, (order, stages, citation) in methods().items():
        takes_word = TABLES[name].takes_word
        comp = nb.composition(f"{name}:121" if takes_word else name)
        assert comp.citation.startswith(citation.split(";")[0])
        structure = "rkn" if TABLES[name].structure == "rkn" else None   # RKN orders hold on the RKN quotient
        assert composition_order(comp, comp.n_pieces if structure is None else None, structure) == order == comp.order
        if isinstance(comp, CatalogComposition):
            assert 0 <= comp.error_bound < 1e-12                      # decimals: stated bound (0: met exactly)
    suzuki = nb.composition("suzuki:12321")
    assert not isinstance(suzuki, CatalogComposition) and suzuki.extension   # exact, in QQ(4^(1/3))
    # Suzuki (1990), the five-jump: a_1 = g/2 with g = 1/(4 - 4^(1/3)), i.e. a_1 (4 - 4^(1/3)) = 1/2, decided on the
    # expanded normal form over the basis 1, 2^(1/3), 2^(2/3) of QQ(2^(1/3))
    assert sympy.expand(suzuki.coefficients[0] * (4 - sympy.root(4, 3))) == sympy.Rational(1, 2)
    assert nb.composition("suzuki", 3) == suzuki


def test_coefficient_field_is_built_once_per_composition(monkeypatch):
    """The order analyses, error constants and backward error analysis of one composition asked sympy for the
    primitive element of its coefficients (QQ(2^(1/3)) for the triple jump, 10-100 ms) on every call; the field of
    a coefficient tuple is now memoised (nambu_bch.algebra.fields.number_field) and equal to sympy's."""
    import sympy.polys.numberfields as numberfields
    from sympy.polys.constructor import construct_domain

    from nambu_bch.algebra.fields import _number_field, number_field

    calls = []
    original = numberfields.primitive_element
    monkeypatch.setattr(numberfields, "primitive_element", lambda *a, **k: calls.append(1) or original(*a, **k))
    _number_field.cache_clear()  # this memo only: nb.clear_caches() would make the tests after this one recompute
    comp = nb.composition("triple-jump:12321")
    ho3 = nb.model("ho3").splitting
    first = (error_constant(comp, 3), composition_order(comp, 3), nb.effective_field(ho3, comp, order=2))
    made = len(calls)
    assert made >= 1
    assert (error_constant(comp, 3), composition_order(comp, 3), nb.effective_field(ho3, comp, order=2)) == first
    assert len(calls) == made
    K, elems = number_field(comp.coefficients)
    assert (K, elems) == construct_domain(list(comp.coefficients), extension=True)
    elems.append(None)  # a new list each call: the memo cannot be changed through it
    assert len(number_field(comp.coefficients)[1]) == len(comp.coefficients)


def test_catalog_names_and_errors():
    assert lookup("12321") is None and lookup("yoshida:121") is None
    assert nb.composition("kahan-li", 2).name == "kahan-li:121"
    with pytest.raises(InvalidCompositionError, match="takes no base word"):
        nb.composition("blanes-moan:121")
    with pytest.raises(InvalidCompositionError, match="needs the number of pieces"):
        nb.composition("kahan-li")
    with pytest.raises(InvalidCompositionError, match="symmetric base scheme"):
        nb.composition("suzuki:123")


def test_decimal_methods_within_their_bound():
    """Kahan-Li's 26 digits satisfy the order-6 conditions to ~1e-25 (exact rationals, defects computed exactly)."""
    comp = nb.composition("kahan-li:121")
    assert comp.error_bound < 1e-24
    E = error_analysis(comp, 2)
    assert E.tolerance == comp.error_bound and E.order == 6


# ------------------------------------------------------------------------------------------------
# 3. order conditions and design


def test_order_conditions_of_symmetric_compositions():
    # Hairer-Lubich-Wanner, Sect. V.3.2: symmetric composition of a symmetric step, order 4 iff
    # sum gamma = 1 and sum gamma^3 = 0
    C = order_conditions("strang", 4, parts=2, stages=3)
    g1, g2 = C.unknowns
    assert C.polynomials == [2 * g1 + g2 - 1, 2 * g1**3 + g2**3]
    assert all(len(w) % 2 == 1 for w, _ in C.equations)               # even degrees vanish identically
    C3 = order_conditions("strang", 4, parts=3, stages=5)
    a, b, c = C3.unknowns
    assert C3.polynomials == [2 * a + 2 * b + c - 1, 2 * a**3 + 2 * b**3 + c**3]
    # the triple jump solves them exactly
    root = sympy.root(2, 3)
    sol = {g1: 1 / (2 - root), g2: -root / (2 - root)}
    assert all(sympy.simplify(p.subs(sol)) == 0 for p in C.polynomials)


def test_order_conditions_of_a_general_word():
    C = order_conditions("word:121", 2)
    a1, a2 = C.unknowns
    assert C.polynomials == [2 * a1 - 1, a2 - 1]                     # position Verlet is the only solution
    C = order_conditions("word-general:12", 2)
    assert C.polynomials[-1] == C.unknowns[0] * C.unknowns[1]        # e^{aA} e^{bB}: [A,B] coefficient ab
    T = template("word:1213121")
    assert T.unknowns == sympy.symbols("a1:5") and T.coefficients[4] == T.coefficients[2]


def test_template_instantiation_and_errors():
    T = template("strang", parts=3, stages=5)
    assert isinstance(T, Template) and len(T.pieces) == 21          # 5 x 5 factors, 4 merges
    with pytest.raises(InvalidCompositionError):
        template("strang", parts=1, stages=3)
    with pytest.raises(InvalidCompositionError):
        template("1234", stages=3)
    with pytest.raises(InvalidCompositionError):
        template("word:12a", stages=3)
    with pytest.raises(InvalidOrderError):
        order_conditions("strang", 0, parts=2, stages=3)
    with pytest.raises(InvalidOrderError):
        order_conditions("strang", 40, parts=2, stages=3)


def test_optimize_reproduces_the_triple_jump():
    D = optimize_composition("strang", parts=2, order=4, stages=3)
    fr = nb.composition("forest-ruth")
    assert D.exact and D.order == 4 and D.pieces == fr.pieces
    assert all(sympy.simplify(a - b) == 0 for a, b in zip(D.coefficients, fr.coefficients))
    assert abs(D.lem - D.lem_optimum) < 1e-12 and round(D.lem, 2) == 3.72


@pytest.fixture(scope="module")
def designed():
    return optimize_composition("strang", parts=3, order=4, stages=5)


@pytest.fixture(scope="module")
def designed_rational():
    """The same template's 30-digit rational form (``exact=False``)."""
    return optimize_composition("strang", parts=3, order=4, stages=5, exact=False)


def test_designed_composition_beats_triple_jump_and_suzuki(designed):
    D = designed
    assert D.exact and D.error_bound == 0 and D.order == 4
    assert composition_order(D, 3) == 4                               # exact Lyndon defects vanish to degree 4
    lem = error_constant(D, 3)
    assert lem == D.lem
    assert lem < error_constant("suzuki:12321", 3) < error_constant("triple-jump:12321", 3)
    assert abs(D.lem - D.lem_optimum) < 1e-8                          # exact form next to the 30-digit optimum
    # its exact coefficients satisfy the symbolic order conditions (second route)
    values = dict(D.values)
    C = order_conditions("strang", 4, parts=3, stages=5)
    assert all(sympy.simplify(p.subs(values)) == 0 for p in C.polynomials)
    # and it is a constrained minimum (second route, floats): moving gamma3 by +-1e-3 along the order-4
    # variety (gamma1 + gamma2 = s, gamma1 gamma2 = P from 2a + 2b + c = 1, 2a^3 + 2b^3 + c^3 = 0) raises LEM
    T = template("strang", parts=3, stages=5)

    def lem_at(c):
        s_ = (1 - c) / 2
        P = (s_**3 + c**3 / 2) / (3 * s_)
        a_ = (s_ - np.sqrt(s_**2 - 4 * P)) / 2
        b_ = s_ - a_
        sub = dict(zip(T.unknowns, (a_, b_, c)))
        fac = [(k, float(co.subs(sub))) for k, co in zip(T.pieces, T.coefficients)]
        d = lyndon_defects(fac, 3, 5, 1.0, 0.0, lambda m: 1.0 / factorial(m))
        return float(np.sqrt(sum(v * v for v in d.values())))

    c0 = float(sympy.N(values[T.unknowns[2]]))
    assert abs(lem_at(c0) - D.lem) < 1e-9
    assert lem_at(c0 - 1e-3) > D.lem and lem_at(c0 + 1e-3) > D.lem


def test_designed_optimum_is_an_isolated_algebraic_number(designed):
    """The minimiser of this template is a root of an irreducible polynomial of degree 24 (no radicals sought): it is
    returned as ``CRootOf`` (certified isolating interval), and the composition, an exact order-4 solution next to
    it in real radicals, says that it is not the optimum itself."""
    D = designed
    assert not D.optimal and D.exact
    g3 = dict(D.optimum)[sympy.Symbol("gamma3")]
    roots = list(g3.atoms(sympy.CRootOf))
    assert len(roots) == 1 and sympy.Poly(roots[0].expr).degree() == 24 and sympy.Poly(roots[0].expr).is_irreducible
    assert abs(sympy.N(g3, 30) - sympy.Float("-0.78327532055276065131", 30)) < 1e-18   # the 30-digit Newton polish
    assert all(not v.is_Rational for _, v in D.optimum)


def test_designed_composition_usable_everywhere(designed):
    D = designed
    assert nb.composition(D) is D
    fam = nb.shadow_hamiltonians("ho3", D, order=4)
    assert fam.exists
    X = nb.effective_field(nb.model("ho3").splitting, D, order=4)
    assert X[1].is_zero() and X[2].is_zero() and X[3].is_zero() and not X[4].is_zero()
    x = nb.iterate("ho3", D, 0.05, 40, [1.0, 1.0, 1.0])
    assert x.shape == (41, 3) and np.all(np.isfinite(x))
    r = nb.check("ho3", D, 0.05, 40, [1.0, 1.0, 1.0], order=4, include=("H_S",))
    assert r.max_abs_error["H_S"] < 1e-6


@pytest.mark.parametrize("system, params", [("ho3", None), ("rigid-body", {"I1": 1, "I2": 2, "I3": 3})])
def test_designed_composition_has_order_four_numerically(designed, system, params):
    C = compare(system, [designed], t_end=2.0, steps=(8, 16, 32, 64), params=params, samples=50)
    row = C.rows[0]
    assert row["slope_points"] >= 3
    assert abs(row["slope"] + 4) < 0.25                               # error ~ evaluations^-4
    errs = [p["error"] for p in C.curves[C.rows[0]["integrator"]]]
    assert all(a > b for a, b in zip(errs, errs[1:]))


def test_rational_fallback_states_its_bound(designed, designed_rational):
    R = designed_rational
    assert not R.exact and 0 < R.error_bound < 1e-25
    assert all(c.is_Rational for c in R.coefficients)
    E = error_analysis(R, 3)
    assert E.order == 4 and E.tolerance == R.error_bound             # defects below the bound count as zero
    assert abs(E.value - designed.lem_optimum) < 1e-12               # the 30-digit optimum itself
    # exact=False keeps the optimum as 30-digit decimals; the exact form is that algebraic minimiser
    assert all(abs(sympy.Float(r, 30) - sympy.N(e, 30)) < 1e-25 for (_, r), (_, e) in zip(R.optimum, designed.optimum))
    # the exact symbolic route sees the rationals as they are: an h^2 term of the size of the bound
    Z2 = nb.effective_field(nb.model("ho3").splitting, R, order=2)[2].to_sympy()
    coeffs = [abs(c) for comp in Z2 for c in sympy.Poly(comp, *sympy.symbols("x1 x2 x3")).coeffs()]
    m_, omega_ = sympy.symbols("m omega")
    sizes = [float(c.subs({m_: 1, omega_: 1})) for c in coeffs]
    assert 0 < max(sizes) < 1e3 * R.error_bound


def test_optimize_finds_yoshidas_sixth_order_solution():
    """7 Strang steps, order 6: Yoshida's three real solutions (Phys. Lett. A 150 (1990) 262, Table 1); the
    smallest error constant is solution A (published LEM 16.17, CheckMethods 'Y 8-6')."""
    D = optimize_composition("strang", parts=2, order=6, stages=7)
    assert "among 3 critical points" in D.citation
    yoshida = nb.composition("yoshida6:121")
    w = [float(v) for _, v in D.optimum]
    assert np.allclose(w[:3], [float(c) for c in (sympy.Rational(s) for s in ("0.784513610477560", "0.235573213359357",
                                                                              "-1.17767998417887"))], atol=1e-13)
    assert not D.exact and D.error_bound < 1e-26                     # no radical form: 30-digit rationals
    assert round(error_constant(D, 2), 2) == 16.17
    assert abs(error_constant(D, 2) - error_constant(yoshida, 2)) < 1e-10


def test_rational_form_keeps_the_degree_one_conditions_exact(designed_rational):
    """Module docstring of design/optimize, step 6: the 30-digit rationals are re-solved on the degree-1 conditions
    (consistency, one per piece: the coefficients of each piece sum to 1), so those hold exactly, not to 1e-30."""
    R = designed_rational
    for k in (1, 2, 3):
        assert sum(c for p, c in zip(R.pieces, R.coefficients) if p == k) == 1
    assert R.error_bound > 0                                          # the higher conditions only to the bound


def test_quotient_dimension_is_the_degree_of_the_shape_polynomial():
    """In shape position k[x]/I = k[x_n]/(q) (Cox, Little, O'Shea, Sect. 5.3): the number of standard monomials of a
    grevlex basis equals deg q of the lex basis (computed independently), and it is counted only up to limit + 1."""
    from nambu_bch.design.optimize import _quotient_dimension

    g1, g2 = sympy.symbols("gamma1 gamma2")
    system = [2 * g1 + g2 - 1, 2 * g1**3 + g2**3]                   # the triple jump (HLW, Sect. V.3.2)
    lex = sympy.groebner(system, g1, g2, order="lex")
    q = sympy.Poly(lex.exprs[-1], g2)
    assert _quotient_dimension(sympy.groebner(system, g1, g2, order="grevlex"), 10) == q.degree() == 3
    x, y = sympy.symbols("x y")
    G = sympy.groebner([x**3 - 1, y**2 - x], x, y, order="grevlex")  # 3 * 2 = 6 points
    assert _quotient_dimension(G, 10) == 6 and _quotient_dimension(G, 4) == 5


def test_optimize_bad_input():
    with pytest.raises(InvalidOrderError):
        optimize_composition("strang", parts=2, order=0, stages=3)
    with pytest.raises(InvalidOrderError, match="at most"):
        optimize_composition("word-general:121212121", order=2)
    with pytest.raises(InvalidCompositionError):
        optimize_composition("strang", parts=2, order=4)
    with pytest.raises(NambuBCHError, match="no real solution"):
        optimize_composition("strang", parts=2, order=4, stages=1)    # one Strang step is not of order 4


# ------------------------------------------------------------------------------------------------
# 4. the system's own error


def test_leading_error_position_verlet():
    E = leading_error("ho", "121")
    x1, x2, m, omega = sympy.symbols("x1 x2 m omega")
    # Eq. (SHPV1): X_eff - X_H = h^2 (-omega^2 x2/(12 m), -m omega^4 x1/6)
    assert E.power == 2 and E.formal_order == 2
    assert [sympy.simplify(a - b) for a, b in zip(E.field, (-omega**2 * x2 / (12 * m), -m * omega**4 * x1 / 6))] == [0, 0]
    # H_S - H at h^2 generates that field: (dH/dp, -dH/dq) = Z_2 (second route: the shadow Hamiltonian)
    dH = E.hamiltonian
    assert sympy.simplify(sympy.diff(dH, x2) - E.field[0]) == 0
    assert sympy.simplify(-sympy.diff(dH, x1) - E.field[1]) == 0
    # size on [-1, 1]^2 (m = omega = 1): |Z| <= sqrt(1/144 + 1/36), reached at the corners
    top = (1 / 144 + 1 / 36) ** 0.5
    assert 0.95 * top <= E.size <= top + 1e-15
    assert json.loads(json.dumps(E.to_dict()))["power"] == 2 and "h^{2}" in E.to_latex()


def test_leading_error_sees_the_system():
    # ho3 with the non-symmetric word 123: first order on this system as formally
    E = leading_error("ho3", "123", hamiltonian=False)
    assert E.power == 1 and E.hamiltonian is None
    # rigid body, 12321 with I1 = I2 = I3 (a sphere): every bracket vanishes -> size 0 at the default parameters
    assert leading_error("rigid-body", "12321", hamiltonian=False, samples=50).size == 0.0
    assert leading_error("rigid-body", "12321", hamiltonian=False, samples=50,
                         params={"I1": 1, "I2": 2, "I3": 3}).size > 0
    with pytest.raises(InvalidRunError):
        leading_error("ho", "121", box=[(0, 1)])
    with pytest.raises(InvalidRunError):
        leading_error("ho", "121", samples=0)


# ------------------------------------------------------------------------------------------------
# 5. work-precision


def test_cost_after_merging():
    assert cost(nb.composition("12321")) == (4, 1)                   # 1 merges across steps (FSAL)
    assert cost(nb.composition("123")) == (3, 0)
    assert cost(nb.composition("forest-ruth")) == (6, 1)             # 121 x 3: 7 sub-flows, ends merge
    assert cost(nb.composition("suzuki:12321")) == (20, 1)           # 5 x 5 - 4 merges = 21, FSAL 20
    assert slope([1, 10, 100], [1, 1e-2, 1e-4]) == pytest.approx(-2)


def test_compare_slopes_are_the_orders(tmp_path):
    C = compare("ho", ["12", "121", "forest-ruth", "kahan-li:121"], t_end=2.0, steps=(10, 20, 40, 80))
    orders = [r["order"] for r in C.rows]
    assert orders == [1, 2, 4, 6]
    for r in C.rows:
        assert r["slope_points"] >= 2
        assert abs(r["slope"] + r["order"]) < 0.3, r
    data = json.loads(C.to_json())
    assert [r["integrator"] for r in data["integrators"]] == ["12", "121", "forest-ruth", "kahan-li:121"]
    assert data["reference_error"] < 1e-12
    out = C.figure(tmp_path / "wp.png")
    assert Path(out).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".tmp-")]   # atomic: no leftovers
    assert "forest-ruth" in C.table()
    with pytest.raises(InvalidRunError):
        C.figure(tmp_path / "wp.jpg")


def test_compare_bad_input():
    with pytest.raises(InvalidRunError):
        compare("ho", [], steps=(10, 20))
    with pytest.raises(InvalidRunError):
        compare("ho", ["121"], steps=(10,))
    with pytest.raises(InvalidRunError):
        compare("ho", ["121"], t_end=-1, steps=(10, 20))


# ------------------------------------------------------------------------------------------------
# 6. CLI


def test_cli_compare(tmp_path):
    fig = tmp_path / "wp.png"
    out = tmp_path / "wp.json"
    # in process (tests/test_cli.py runs compare once as a subprocess)
    code = main(["compare", "--model", "ho", "--integrator", "121", "--integrator", "forest-ruth", "--t-end", "2",
                 "--step-counts", "10,20,40", "--format", "json", "--output", str(out), "--figure", str(fig)])
    assert code == 0
    data = json.loads(out.read_text())
    assert [row["order"] for row in data["integrators"]] == [2, 4]
    assert fig.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("argv, needle", [
    (["--step-counts", "20"], "--step-counts"),
    (["--step-counts", "20,x"], "--step-counts"),
    (["--t-end", "-1"], "--t-end"),
    (["--integrator", "__import__('os')"], "accepted are letters, digits"),
    (["--figure", "a.jpg"], "--figure"),
    (["--model", "nope"], "nope"),
])
def test_cli_compare_bad_input(capsys, argv, needle):
    assert main(["compare", "--model", "ho", *argv] if "--model" not in argv else ["compare", *argv]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and needle in err[0] and "Traceback" not in err[0]


def test_catalog_names_match_the_alias_hook():
    from nambu_bch.design.catalog import NAMES
    from nambu_bch.integrators.composition import _CATALOG

    assert tuple(NAMES) == tuple(_CATALOG)


def test_exact_critical_point_helpers_agree_with_sympy_expressions():
    """The Lagrange minors as Poly determinants and the CRootOf values built term by term are the expressions the
    sympy-expression route gives (Matrix.det then expand; expand of the substituted polynomial)."""
    from nambu_bch.design.optimize import _algebraic_values, _poly_det

    a, b, c = sympy.symbols("a b c")
    rows = [[a**2 + b, a * c, 3], [b - c, 2 * a, b**2], [1, c, a * b - 1]]
    P = [[sympy.Poly(e, a, b, c) for e in row] for row in rows]
    assert _poly_det(P).as_expr() == sympy.expand(sympy.Matrix(rows).det())
    minor = sympy.Matrix(rows).extract([0, 1], [0, 1]).det()
    assert _poly_det([row[:2] for row in P[:2]]).as_expr() == sympy.expand(minor)
    t = sympy.Dummy("t")
    g = sympy.Poly(t**5 - 3 * t - 1, t)                                  # not solvable in radicals
    root = sympy.CRootOf(g.as_expr(), 0)
    rem = {a: sympy.Poly(sympy.Rational(2, 3) * t**4 - t + 5, t), b: sympy.Poly(0, t, domain="QQ")}
    values, radical = _algebraic_values(g, root, rem, [a, b], t)
    assert radical is False
    assert [v for _, v in values] == [sympy.expand(rem[v].as_expr().subs(t, root)) for v in (a, b)]
