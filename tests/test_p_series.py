"""P-series of partitioned Runge-Kutta pairs: coloured trees, order conditions, the modified equation.

Sources: Hairer, Lubich, Wanner, *Geometric Numerical Integration* (HLW), Sect. III.2 (P-series over bi-coloured
trees; order conditions of partitioned methods), Sect. IX.10 (their modified equations); the number of bi-coloured
rooted trees with n vertices is OEIS A000151 (2, 4, 14, 52, 214, 916, 4116).  The modified fields are checked
against two independent routes: the Taylor expansion of the step (modified_equation_by_taylor) and the package's
BCH effective fields of the Stormer-Verlet compositions 212 and 121.
"""

from __future__ import annotations

import pytest
import sympy

from nambu_bch import model
from nambu_bch.bch.concrete import effective_field_by_cost
from nambu_bch.bseries import ColouredTrees, modified_coefficients, modified_equation, p_series_modified_equation
from nambu_bch.bseries.modified import modified_equation_by_taylor
from nambu_bch.bseries.p_series import MAX_P_ORDER, MAX_VERTICES, density, elementary_weight, leaf
from nambu_bch.errors import NambuBCHError
from nambu_bch.integrators.runge_kutta import PARTITIONED, TABLEAUX, PartitionedTableau


def test_bicoloured_tree_counts_are_oeis_a000151():
    family = ColouredTrees(2)
    assert [len(family.trees(n)) for n in range(1, 7)] == [2, 4, 14, 52, 214, 916]
    assert [len(ColouredTrees(1).trees(n)) for n in range(1, 7)] == [1, 1, 2, 4, 9, 20]


def test_exact_flow_has_the_field_itself_as_modified_field():
    """Phi(t) = 1/gamma(t) on every coloured tree is the exact flow: f~ = f_q + f_p, nothing else."""
    family = ColouredTrees(2)
    a = {t: sympy.Rational(1, density(t)) for n in range(1, 6) for t in family.trees(n)}
    assert modified_coefficients(a, 5, family) == {leaf(0): 1, leaf(1): 1}


def test_order_conditions_of_the_lobatto_pairs():
    """HLW Sect. III.2: order p iff Phi(t) = 1/gamma(t) for every bi-coloured tree with at most p vertices; the
    s = 3 pair has order 4 and not 5, the s = 2 pair order 2 and not 3."""
    family = ColouredTrees(2)
    for pair, p in ((PARTITIONED["lobatto-iiia-iiib-2"], 2), (PARTITIONED["lobatto-iiia-iiib-3"], 4)):
        def holds(t):
            return elementary_weight(t, (pair.q, pair.p)) == sympy.Rational(1, density(t))

        assert all(holds(t) for n in range(1, p + 1) for t in family.trees(n))
        assert not all(holds(t) for t in family.trees(p + 1))


@pytest.mark.parametrize("pair", sorted(PARTITIONED))
@pytest.mark.parametrize("system", ["ho", "henon-heiles"])
def test_p_series_equals_taylor_route(pair, system):
    M = p_series_modified_equation(system, pair, 4)
    Z = modified_equation_by_taylor(system, pair, 4)
    assert all(M[j] == Z[j] for j in range(5))
    assert M.method is PARTITIONED[pair] and M.tree_coefficients[leaf(0)] == 1


def test_stormer_verlet_pairs_are_212_and_121():
    """IIIA for q with IIIB for p is 212 (V/2, T, V/2); the swapped pair is 121 (T/2, V, T/2): equal to the BCH
    effective fields exactly through h^4 on Henon-Heiles."""
    S = model("henon-heiles")
    swapped = PartitionedTableau("lobatto-iiib-iiia-2", TABLEAUX["lobatto-iiib-2"], TABLEAUX["trapezoid"], 2, "")
    for pair, word in ((PARTITIONED["lobatto-iiia-iiib-2"], "212"), (swapped, "121")):
        M = p_series_modified_equation(S, pair, 4)
        E = effective_field_by_cost(S.splitting, word, 4)
        assert all(M[j] == E[j] for j in range(5))


def test_one_tableau_for_both_colours_is_the_b_series():
    """A pair of two equal tableaux is the plain method: the P-series gives the B-series modified field."""
    mid = TABLEAUX["midpoint"]
    M = p_series_modified_equation("henon-heiles", PartitionedTableau("mm", mid, mid, 2, ""), 3)
    B = modified_equation("henon-heiles", "midpoint", 3)
    assert all(M[j] == B[j] for j in range(4))


def test_refusals_are_one_line():
    with pytest.raises(NambuBCHError, match="partitioned method for canonical systems"):
        p_series_modified_equation("rigid-body", "lobatto-iiia-iiib-2", 2)
    with pytest.raises(NambuBCHError, match=str(MAX_P_ORDER)):
        p_series_modified_equation("ho", "lobatto-iiia-iiib-2", MAX_P_ORDER + 1)
    with pytest.raises(NambuBCHError, match="unknown partitioned"):
        p_series_modified_equation("ho", "gauss4", 2)
    with pytest.raises(NambuBCHError, match=f"n must be an integer from 1 to {MAX_VERTICES}"):
        ColouredTrees(2).trees(MAX_VERTICES + 1)  # refused before enumerating (18996 trees at 8 vertices)
