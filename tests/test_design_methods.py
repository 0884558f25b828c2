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
from nambu_bch.errors import InvalidCompositionError
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

