"""Butcher tableaux as checked data: exact coefficients, row sums, and the order conditions up to order 6.

Order conditions ``Phi(t) = 1/gamma(t)`` for every rooted tree ``t`` with ``|t| <= p`` (Hairer, Lubich,
Wanner, *Geometric Numerical Integration*, Sect. III.1); the tree counts 1, 1, 2, 4, 9, 20 (OEIS A000081).
"""

from __future__ import annotations

import pytest
import sympy

from nambu_bch.bseries import rooted_trees as T
from nambu_bch.errors import InvalidCompositionError
from nambu_bch.integrators.runge_kutta import TABLEAUX, ButcherTableau, butcher_tableau


def _conditions_hold(tableau, p):
    return all(T.elementary_weight(t, tableau) == sympy.Rational(1, T.density(t))
               for n in range(1, p + 1) for t in T.trees(n))


def test_tree_counts_and_functions():
    assert [len(T.trees(n)) for n in range(1, 8)] == [1, 1, 2, 4, 9, 20, 48]   # OEIS A000081
    bushy, tall = ((), ()), (((),),)
    assert (T.symmetry(bushy), T.density(bushy)) == (2, 3)
    assert (T.symmetry(tall), T.density(tall)) == (1, 6)
    # F(t)' F(s) = sum over the vertices of t: grafting a leaf on [•] gives [•,•] (root) and [[•]] (leaf)
    assert sorted(T.graft(((),), ())) == sorted([bushy, tall])


@pytest.mark.parametrize("name", sorted(TABLEAUX))
def test_order_conditions(name):
    """Every condition of order <= p holds exactly, and some condition of order p + 1 fails (p the stated order)."""
    tableau = TABLEAUX[name]
    assert all(isinstance(x, sympy.Basic) and not x.has(sympy.Float) for row in tableau.A for x in row)
    assert _conditions_hold(tableau, tableau.order)
    assert not _conditions_hold(tableau, tableau.order + 1)
    for row, c in zip(tableau.A, tableau.c):
        assert sympy.simplify(sum(row) - c) == 0


def test_gauss_nodes_are_legendre_roots():
    """Gauss-Legendre nodes are the zeros of the shifted Legendre polynomial P_s(2c - 1) (Hairer-Wanner II, Sect. IV.5)."""
    c = sympy.Symbol("c")
    for name, s in (("gauss4", 2), ("gauss6", 3)):
        for node in TABLEAUX[name].c:
            assert sympy.simplify(sympy.legendre(s, 2 * c - 1).subs(c, node)) == 0


def test_explicitness_and_lookup():
    assert TABLEAUX["euler"].is_explicit and TABLEAUX["rk4"].is_explicit
    assert not TABLEAUX["midpoint"].is_explicit and not TABLEAUX["kahan"].is_explicit
    assert butcher_tableau(TABLEAUX["gauss4"]) is TABLEAUX["gauss4"]
    assert isinstance(butcher_tableau("gauss6"), ButcherTableau)
    with pytest.raises(InvalidCompositionError, match="unknown Runge-Kutta method 'gauss5'; accepted are"):
        butcher_tableau("gauss5")
