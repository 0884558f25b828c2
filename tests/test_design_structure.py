"""Structured splittings: the RKN quotient and near-integrable A + eps B (nambu_bch.design.structure).

Published values pinned here:
* Blanes & Moan, J. Comput. Appl. Math. 142 (2002) 313, Table 3: SRKN_6^b has order 4 and SRKN_11^b order 6 for
  RKN problems (``bm-srkn6``, ``bm-srkn11``);
* Omelyan, Mryglod & Folk, Comput. Phys. Commun. 146 (2002) 188, PEFRL: order 4;
* Laskar & Robutel, Celest. Mech. Dyn. Astr. 80 (2001) 39, Sect. 3: SABA_n and SBAB_n have generalised order (2n, 2);
* the numbers of independent order conditions per degree: Witt's 2, 1, 2, 3, 6, 9, 18, 30, 56 in general, and
  2, 1, 2, 2, 4, 5, 10, 15 for RKN problems (Blanes, Casas & Murua, Acta Numerica 33 (2024), Sect. 3; the 26 at
  degree 9 is this computation's).
"""

from __future__ import annotations

import pytest
import sympy

import nambu_bch as nb
from nambu_bch.design import error_analysis, error_constant, order_conditions
from nambu_bch.design.structure import condition_counts, generalized_order, rkn_annihilator, rkn_ideal
from nambu_bch.design.words import lyndon_defect_words
from nambu_bch.errors import InvalidCompositionError, InvalidOrderError, NambuBCHError


def test_the_rkn_relation_holds_for_quadratic_kinetic_energy():
    """The premise, as Poisson brackets: {V,{V,{V,T}}} = 0 for T = p^2/2 and any V(q), not for T = p^4/4."""
    q, p = sympy.symbols("q p")
    V = sympy.Function("V")(q)

    def pb(f, g):
        return sympy.diff(f, q) * sympy.diff(g, p) - sympy.diff(f, p) * sympy.diff(g, q)

    assert sympy.expand(pb(V, pb(V, pb(V, p**2 / 2)))) == 0
    assert sympy.expand(pb(V, pb(V, pb(V, p**4 / 4)))) != 0


def test_condition_counts_match_the_literature():
    assert condition_counts(9) == (2, 1, 2, 3, 6, 9, 18, 30, 56)
    assert condition_counts(9, "rkn") == (2, 1, 2, 2, 4, 5, 10, 15, 26)


def test_rkn_ideal_contains_the_relation_and_annihilator_is_its_complement():
    words = lyndon_defect_words(2, 4)
    assert words == [(1, 1, 1, 2), (1, 1, 2, 2), (1, 2, 2, 2)]
    # [2,[2,[2,1]]] = -[[[1,2],2],2]: its only Lyndon coordinate is on 1222
    assert rkn_ideal(4) == ((0, 0, 1),)
    assert [w for w, _ in rkn_annihilator(4)] == [(1, 1, 1, 2), (1, 1, 2, 2)]
    for q in (5, 6, 7):
        ideal, annihilator = rkn_ideal(q), rkn_annihilator(q)
        assert len(ideal) + len(annihilator) == len(lyndon_defect_words(2, q))
        assert all(sum(a * b for a, b in zip(row, v)) == 0 for _, row in annihilator for v in ideal)


@pytest.mark.parametrize("name, general, rkn", [
    ("bm-srkn6", 4, 4),     # Table 3, SRKN_6^b
    ("bm-srkn11", 4, 6),    # Table 3, SRKN_11^b: order 6 only for RKN problems
    ("bm-srkn14", 4, 6),    # Table 3, SRKN_14^a
    ("mclachlan-sb3a4", 4, 4),  # McLachlan (1995), SB3A with 4 stages
    ("pefrl", 4, 4),        # PEFRL
    ("blanes-moan", 4, 4),  # Table 2, S6 (a general method)
])
def test_published_rkn_orders(name, general, rkn):
    E, R = error_analysis(name), error_analysis(name, structure="rkn")
    assert (E.order, R.order) == (general, rkn) and R.structure == "rkn" and not E.structure
    assert R.value <= E.value   # a quotient can only shrink the error term
    assert R.to_dict()["structure"] == "rkn" and "structure" not in E.to_dict()


def test_rkn_method_on_three_parts_keeps_a_tight_bound():
    """CheckMethods' ABC rule on an RKN method: its RKN order says nothing about three general parts, so the stated
    bound covers the general conditions only (not the order-6 defects, which would pass for order 6)."""
    E = error_analysis("bm-srkn11", 3)
    assert E.order == 4 and 0 < E.tolerance < 1e-14
    assert nb.composition("bm-srkn11").structure == "rkn" and nb.composition("blanes-moan").structure == ""


def test_rkn_constant_of_a_general_low_order_method_is_its_lem():
    """Below degree 4 the ideal is empty: the RKN constant of Strang (order 2, degree 3) is its LEM, exactly."""
    R = error_analysis("121", structure="rkn")
    assert R.order == 2 and R.squared == error_analysis("121", 2).squared == sympy.Rational(5, 16)


def test_rkn_residual_is_orthogonal_to_the_ideal():
    """The defects kept at degree p + 1 are v(E) minus its projection on v(I): orthogonal to the ideal."""
    R = error_analysis("pefrl", structure="rkn")
    d = [R.defects[w] for w in lyndon_defect_words(2, 5)]
    for v in rkn_ideal(5):
        assert abs(float(sum(a * b for a, b in zip(d, v)))) < 1e-25
    assert float(R.squared) == pytest.approx(R.value ** 2)


def test_rkn_order_conditions_are_fewer_and_met_by_the_rkn_method():
    general = order_conditions("word:1212121", 5)
    rkn = order_conditions("word:1212121", 5, structure="rkn")
    assert len(general.polynomials) == 2 + 2 + 6 and len(rkn.polynomials) == 2 + 2 + 4
    assert [w for w, _ in rkn.equations if len(w) == 5] == [w for w, _ in rkn_annihilator(5)]


def test_structure_is_validated():
    with pytest.raises(InvalidCompositionError, match="structure must be one of 'rkn'"):
        error_constant("121", structure="kepler")
    with pytest.raises(InvalidCompositionError, match="two pieces"):
        error_analysis("12321", structure="rkn")
    with pytest.raises(InvalidCompositionError, match="two parts"):
        error_analysis("121", 3, structure="rkn")
    with pytest.raises(NambuBCHError):
        order_conditions("strang", 3, parts=3, stages=1, structure="rkn")


# ------------------------------------------------------------------------------------------------
# near-integrable A + eps B


@pytest.mark.parametrize("name", ["saba2", "saba3", "saba4", "sbab2", "sbab3"])
def test_laskar_robutel_generalized_orders(name):
    from nambu_bch.integrators.tables import TABLES

    table = TABLES[name]
    G = generalized_order(name)
    assert G.orders == table.generalized and G.order == table.order == 2


def test_saba_coefficients_are_gauss_quadrature():
    """SABA_2's nodes are the Gauss points 1/2 -+ sqrt(3)/6 of [0, 1]; its eps error term is the quadrature error."""
    comp = nb.composition("saba2")
    assert comp.pieces == (1, 2, 1, 2, 1) and comp.symmetric
    assert comp.coefficients[0] == sympy.Rational(1, 2) - sympy.sqrt(3) / 6
    G = generalized_order("saba2", powers=3)
    assert G.orders == (4, 2, 4) and G.constants[0] == sympy.Rational(1, 1296)   # only the word 11112


def test_strang_is_second_order_in_every_power_of_eps():
    G = generalized_order("121", powers=2)
    assert G.orders == (2, 2) and G.constants == (sympy.Rational(1, 16), sympy.Rational(1, 4))
    assert G.to_dict()["generalized_order"] == [2, 2]


def test_generalized_order_refuses_bad_input():
    with pytest.raises(InvalidOrderError, match="max_degree"):
        generalized_order("121", max_degree=40)
    with pytest.raises(InvalidOrderError, match="powers"):
        generalized_order("121", powers=0)
    with pytest.raises(InvalidCompositionError, match="two pieces"):
        generalized_order("12321")


def test_srkn11_is_sixth_order_on_the_pendulum_numerically():
    """Independent of the algebra: on H = p^2/2 - cos q (T quadratic) the global error of SRKN_11^b falls as h^6, and
    that of a general fourth-order method (Blanes-Moan S6) as h^4."""
    import math

    def run(name, h, t_end=2.0, q=1.0, p=0.0):
        factors = [(k, float(c)) for k, c in nb.composition(name).factors()]
        for _ in range(round(t_end / h)):
            for k, c in factors:
                if k == 1:
                    q += c * h * p
                else:
                    p -= c * h * math.sin(q)
        return q, p

    reference = run("bm-srkn11", 0.01)
    for name, slope in (("bm-srkn11", 6), ("blanes-moan", 4)):
        errors = [math.hypot(*(a - b for a, b in zip(run(name, h), reference))) for h in (0.4, 0.2)]
        assert math.log2(errors[0] / errors[1]) == pytest.approx(slope, abs=0.4)
