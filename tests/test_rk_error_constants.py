"""Principal error norms A^(p+1) of tableaux and pairs (compare's error constant of a Runge-Kutta method).

Sources: Kennedy, Carpenter, Lewis, Appl. Numer. Math. 35 (2000) 177 (A^(p+1), the 2-norm of the coefficients
(Phi(t) - 1/gamma(t))/sigma(t) over the trees of order p+1); the classical RK4 value sqrt(1745)/2880 is the one
NodePy documents for its RK44 (`error_metrics`, citing the same paper).  Euler and implicit midpoint are worked
by hand in the test docstrings; the pairs' values are computed here (no published value found).
"""

from __future__ import annotations

import dataclasses

import pytest
import sympy

from nambu_bch.design import runge_kutta_error_constant
from nambu_bch.errors import NambuBCHError
from nambu_bch.integrators.runge_kutta import TABLEAUX


def test_rk4_principal_error_norm_is_kennedy_carpenter_lewis():
    assert runge_kutta_error_constant("rk4") == (4, sympy.sqrt(1745) / 2880)


def test_euler_and_midpoint_by_hand():
    """Euler: one tree [.] with Phi = 0, 1/gamma = 1/2: A^(2) = 1/2.  Midpoint: [., .] has Phi = 1/4, gamma = 3,
    sigma = 2 (tau = -1/24); [[.]] has Phi = 1/4, gamma = 6 (tau = 1/12): A^(3) = sqrt(5)/24."""
    assert runge_kutta_error_constant("euler") == (1, sympy.Rational(1, 2))
    assert runge_kutta_error_constant("midpoint") == (2, sympy.sqrt(5) / 24)


def test_a_stated_order_below_the_true_one_finds_the_first_non_vanishing_trees():
    understated = dataclasses.replace(TABLEAUX["gauss4"], name="g", order=2)
    assert runge_kutta_error_constant(understated) == runge_kutta_error_constant("gauss4")
    assert runge_kutta_error_constant("gauss4") == (4, sympy.sqrt(14) / 864)


def test_pairs_sum_over_bicoloured_trees():
    p2, a2 = runge_kutta_error_constant("lobatto-iiia-iiib-2")
    p3, a3 = runge_kutta_error_constant("lobatto-iiia-iiib-3")
    assert (p2, p3) == (2, 4) and a2 > a3 > 0 and a3.is_algebraic


def test_unknown_method_is_one_line():
    with pytest.raises(NambuBCHError, match="unknown Runge-Kutta method 'rk5'"):
        runge_kutta_error_constant("rk5")
