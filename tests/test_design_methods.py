"""Method families of the literature: a two-part method on three parts (CheckMethods' ABC rule) and exact optima.

Published values: SplittingOrderConditions.jl (Auzinger, Herfort, Hofstaetter, Koch),
``examples/CheckMethods.ipynb``, first table ("AB / ABC", columns ``ABC p`` and ``ABC LEM``), whose ABC column applies
each AB method to three parts with ``get_ABC_coeffs`` of ``src/SplittingOrderConditions.jl``.
"""

from __future__ import annotations

import sympy
import pytest

import nambu_bch as nb
from nambu_bch.design import error_analysis, error_constant, optimize_composition, order_conditions
from nambu_bch.errors import InvalidCompositionError, NambuBCHError
from nambu_bch.integrators.composition import three_parts


# ------------------------------------------------------------------------------------------------
# 1. a two-part method applied to three parts


def test_three_parts_rule_on_small_words():
    """The rule by hand: B's running time catches up with A's after each A factor and with C's after each C factor."""
    assert three_parts("12").pieces == (1, 2, 3) and three_parts("12").coefficients == (1, 1, 1)
    assert three_parts("121").pieces == (1, 2, 3, 2, 1)
    assert three_parts("121").coefficients == nb.composition("12321").coefficients
    a1, b1 = sympy.Rational(1, 3), sympy.Rational(1, 2)
    comp = nb.composition([(1, a1), (2, b1), (1, 1 - 2 * a1), (2, b1), (1, a1)])
    abc = three_parts(comp)
    # A(a1) B(a1) C(b1) B(b1 - a1) A(1 - 2 a1) ...: palindromic again
    assert abc.pieces == (1, 2, 3, 2, 1, 2, 3, 2, 1)
    assert abc.coefficients[:4] == (a1, a1, b1, b1 - a1) and abc.symmetric
    for k in (1, 2, 3):
        assert sum(c for p, c in zip(abc.pieces, abc.coefficients) if p == k) == 1


@pytest.mark.parametrize("spec, order, published", [
    ("lie-trotter", 1, 1.73),          # row "Lie-Trotter"
    ("121", 2, 1.20),                  # row "Strang"
    ("forest-ruth", 4, 26.04),         # row "Y 4-4"
    ("blanes-moan", 4, 0.11),          # row "Emb 4/3 BM PRK/A" (its 4th-order method, Blanes & Moan 2002, S6)
    ("blanes-moan-s10", 6, 0.45),      # row "BM 11-6 PRK" (Blanes & Moan 2002, Table 2, S10)
    ("yoshida6:121", 6, 90.86),        # row "Y 8-6"
    ("kahan-li:121", 6, 10.70),        # row "KL 10-6"
])
def test_abc_column_of_check_methods(spec, order, published):
    """CheckMethods.ipynb, first table, columns ``ABC p`` and ``ABC LEM`` (two decimals)."""
    E = error_analysis(spec, 3)
    assert E.order == order and round(E.value, 2) == published


def test_three_parts_of_decimal_method_states_its_bound():
    E = error_analysis("blanes-moan", 3)
    assert 0 < E.tolerance < 1e-14 and len(E.composition.pieces) == 25
    assert E.composition.name == "three-parts:blanes-moan"


def test_three_parts_refuses_other_pieces():
    with pytest.raises(InvalidCompositionError, match="pieces 1 and 2"):
        three_parts("12321")
    with pytest.raises(InvalidCompositionError, match="every piece 1..3"):
        error_constant("13", 3)


# ------------------------------------------------------------------------------------------------
# 2. exact optima


#: McLachlan, SIAM J. Sci. Comput. 16 (1995) 151, and Omelyan, Mryglod, Folk, Phys. Rev. E 65 (2002) 056706: the
#: minimum-norm two-stage second-order scheme, xi = 0.1931833275037836.
MCLACHLAN_XI = "0.1931833275037836"


@pytest.fixture(scope="module")
def twelve_one():
    return optimize_composition("word:12121", parts=2, order=2)


def test_optimum_of_12121_is_the_exact_minimiser(twelve_one):
    D = twelve_one
    a1 = dict(D.values)[sympy.Symbol("a1")]
    assert D.optimal and D.exact and a1 != sympy.Rational(17, 88)
    assert not a1.is_Rational and a1.has(sympy.sqrt(326))                      # real radicals (Cardano)
    assert abs(sympy.N(a1, 30) - sympy.Float(MCLACHLAN_XI, 30)) < 1e-16       # 16 published digits
    # a3 = 1 - 2 a1 is the real root of 6 t^3 + t - 2 (the critical-point equations over QQ)
    a3 = dict(D.values)[sympy.Symbol("a3")]
    t = sympy.Symbol("t")
    assert sympy.minimal_polynomial(a3, t) == 6 * t**3 + t - 2
    assert sympy.expand(D.coefficients[0] - a1) == 0 and abs(D.lem - D.lem_optimum) < 1e-15


def test_exact_optimum_satisfies_order_conditions(twelve_one):
    values = dict(twelve_one.values)
    assert all(sympy.simplify(p.subs(values)) == 0 for p in order_conditions("word:12121", 2).polynomials)
    assert nb.composition_order(twelve_one, 2) == 2



# ------------------------------------------------------------------------------------------------
# 3. complex coefficients


#: The complex triple jump of the Strang step ABA: gamma_1 = 1/(2 - 2^(1/3) e^(2 pi i/3)), gamma_2 = 1 - 2 gamma_1
#: (Castella, Chartier, Descombes, Vilmart, BIT 49 (2009) 487; Hansen & Ostermann, BIT 49 (2009) 527).  It is the
#: complex solution of the order-4 conditions of the palindromic ABABABA method (word:1212121), CheckMethods' row
#: "A 4-4 c".
_G = "1/(2-2^(1/3)*(-1/2+sqrt(3)*I/2))"
COMPLEX_TRIPLE_JUMP = f"1:{_G}/2,2:{_G},1:(1-{_G})/2,2:1-2*{_G},1:(1-{_G})/2,2:{_G},1:{_G}/2"
#: The complex third-order method B A B A B with coefficients 1/4 -+ sqrt(3) i/12, 1/2 -+ sqrt(3) i/6, 1/2: the
#: exact complex solution of the order-3 conditions of word-general:12121 (pieces swapped), CheckMethods' row "A 3-3 c".
COMPLEX_THIRD_ORDER = "2:1/4-sqrt(3)*I/12,1:1/2-sqrt(3)*I/6,2:1/2,1:1/2+sqrt(3)*I/6,2:1/4+sqrt(3)*I/12"


def test_complex_coefficients_are_parsed_exactly():
    comp = nb.composition("1:1/4+I/4,2:1/2+I/2,1:1/2,2:1/2-I/2,1:1/4-I/4")
    assert comp.coefficients[0] == sympy.Rational(1, 4) + sympy.I / 4 and comp.is_complex
    assert not nb.composition("12321").is_complex and not nb.composition("1:sqrt(2)/2,2:1,1:1-sqrt(2)/2").is_complex
    with pytest.raises(NambuBCHError, match="'J' is not declared"):
        nb.composition("1:1/2+J,2:1,1:1/2-J")                     # I is the one name of coefficient text
    with pytest.raises(InvalidCompositionError, match="must sum to 1"):
        nb.composition("1:1/2+I/2,2:1,1:1/2")


@pytest.mark.parametrize("spec, order, ab, abc", [
    (COMPLEX_TRIPLE_JUMP, 4, 0.42, 1.22),     # row "A 4-4 c": AB p 4, LEM 0.42; ABC p 4, LEM 1.22
    (COMPLEX_THIRD_ORDER, 3, 0.36, 1.49),     # row "A 3-3 c": AB p 3, LEM 0.36; ABC p 3, LEM 1.49
])
def test_complex_rows_of_check_methods(spec, order, ab, abc):
    """CheckMethods.ipynb, first table, complex rows: LEM = 2-norm of the complex Lyndon defects, exact over QQ(i, ...)."""
    E = error_analysis(spec, 2)
    assert E.order == order and round(E.value, 2) == ab
    assert E.squared.is_real and not E.squared.has(sympy.I)     # sum |d|^2, exact
    E3 = error_analysis(spec, 3)
    assert E3.order == order and round(E3.value, 2) == abc


def test_complex_third_order_method_solves_its_order_conditions():
    """Second route: the symbolic order-3 conditions of word-general:21212 vanish at the complex coefficients, and
    these are the only solutions (the method and its complex conjugate)."""
    comp = nb.composition(COMPLEX_THIRD_ORDER)
    C = order_conditions("word-general:21212", 3)
    assert all(sympy.expand(p.subs(dict(zip(C.unknowns, comp.coefficients)))) == 0 for p in C.polynomials)
    solutions = sympy.solve(C.polynomials, C.unknowns, dict=True)
    assert len(solutions) == 2 and {s[C.unknowns[0]] for s in solutions} == {
        comp.coefficients[0], sympy.conjugate(comp.coefficients[0])}


def test_complex_formal_bch_agrees_with_the_defects():
    """formal BCH (Lyndon basis) against the Lyndon defects of error_analysis, on a method with complex defects."""
    from nambu_bch.bch import formal_bch

    spec = "1:1/2+I/2,2:1,1:1/2-I/2"
    E = error_analysis(spec, 2)
    # by hand: log(e^{aX} e^{Y} e^{bX}) = (a + b) X + Y + (a - b)/2 [X, Y] + ..., a - b = i
    assert E.order == 1 and E.defects == {(1, 2): sympy.I}          # 2! times the coefficient of [X1, X2]
    B = formal_bch(spec, 2)
    assert B.terms(2) == [(sympy.I / 2, (1, 2))]


def test_complex_coefficients_on_a_system():
    """X_eff over QQ(i): Z_1 = (i/2) [X_1, X_2] on ho (tests/test_complex_routes.py checks the routes)."""
    X = nb.effective_field(nb.model("ho").splitting, "1:1/2+I/2,2:1,1:1/2-I/2", order=2)
    omega, x1, x2 = sympy.symbols("omega x1 x2")
    assert X[1].to_sympy() == (sympy.I * omega**2 * x1 / 2, -sympy.I * omega**2 * x2 / 2)   # [X1, X2] = (w^2 x1, -w^2 x2)


def test_ab_column_of_blanes_moan_s10():
    """CheckMethods.ipynb, first table, row "BM 11-6 PRK", columns ``AB p`` and ``AB LEM``: 6 and 0.05."""
    E = error_analysis("blanes-moan-s10", 2)
    assert E.order == 6 and round(E.value, 2) == 0.05 and 0 < E.tolerance < 1e-14


@pytest.mark.parametrize("name, order, stages", [("mclachlan-s2", 2, 2), ("mclachlan-s4", 4, 4), ("mclachlan-s5", 4, 5)])
def test_mclachlan_1995_methods(name, order, stages):
    """McLachlan, SIAM J. Sci. Comput. 16 (1995) 151: S2, S4, S5 with their published orders and stages."""
    comp = nb.composition(name)
    assert error_analysis(comp, 2).order == order and comp.pieces.count(2) == stages and comp.symmetric


@pytest.mark.parametrize("conditions", [2, 0])
def test_float_evaluation_of_the_lagrange_system_is_bit_for_bit_per_polynomial(conditions, monkeypatch):
    """The float Newton of optimize_composition evaluates every polynomial of f, F, grad f, Hess f, J and its
    derivatives at each step; they are now evaluated as one array (numpy's per-call overhead was paid per
    polynomial), each value the np.sum of its own terms: bit for bit the per-polynomial value, so the critical
    points found do not change."""
    import numpy as np

    from nambu_bch.design.optimize import _PolyEval, _Problem

    a, b, c = sympy.symbols("a b c")
    objective = sympy.Poly(a**4 / 3 + a * b**3 - sympy.Rational(7, 5) * c**2 * a + b / 11 + 1, a, b, c)
    constraints = [2 * a + 2 * b + c - 1, 2 * a**3 + 2 * b**3 + c**3, a * b * c - sympy.Rational(1, 7)][:conditions]
    prob = _Problem(objective, constraints, [a, b, c])

    def one_by_one(obj, x):
        return [one_by_one(o, x) for o in obj] if isinstance(obj, list) else obj.float(x)

    rng = np.random.default_rng(5)
    for x in rng.normal(size=(50, 3)) * 3:
        for name in ("f", "F", "g", "H", "J", "C"):
            got, want = prob.values(name, list(x), "float"), one_by_one(getattr(prob, name), list(x))
            assert got == want and repr(got) == repr(want), name
    want = one_by_one(prob.C, [1.0, 2.0, 3.0])
    monkeypatch.setattr(_PolyEval, "float", lambda self, x: pytest.fail("evaluated one polynomial at a time"))
    assert prob.kkt(np.arange(3.0 + conditions), "float")[1] and prob.values("C", [1.0, 2.0, 3.0], "float") == want
