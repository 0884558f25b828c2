"""The factor F(x) of Eqs. (factor1), (factor2): exact form, series, double and arbitrary precision.

Horikoshi, *Shadow Hamiltonians of structure-preserving integrators for Nambu mechanics*.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from nambu_bch.errors import NambuBCHError, NumericalRangeError, UnstableStepError
from nambu_bch.exact import F, F_series

x = sympy.Symbol("x")
EPS = 2.0**-52


def _reference(value: float):
    """F at 50 digits from the closed form (mpmath), F(0) = 1."""
    with mpmath.workdps(50):
        v = mpmath.mpf(value)
        if v == 0:
            return mpmath.mpf(1)
        return 2 * mpmath.asin(v / 2) / (v * mpmath.sqrt(1 - v**2 / 4))


def test_exact_form_factor1():
    """Eq. (factor1): F(x) = 2 asin(x/2) / (x sqrt(1 - x^2/4))."""
    assert F(x) == 2 * sympy.asin(x / 2) / (x * sympy.sqrt(1 - x**2 / 4))
    omega, h = sympy.symbols("omega h")
    assert F(omega * h).has(sympy.asin(omega * h / 2))
    assert F(sympy.Integer(0)) == 1


def test_series_factor2():
    """Eq. (factor2): 1 + x^2/6 + x^4/30 + ..., general term (n!)^2/(2n+1)! x^(2n)."""
    assert F_series(x, 4) == 1 + x**2 / 6 + x**4 / 30
    series = sympy.series(F(x), x, 0, 14).removeO()
    assert sympy.expand(series - F_series(x, 13)) == 0
    poly = sympy.Poly(F_series(x, 20), x)
    for n in range(11):
        assert poly.coeff_monomial(x ** (2 * n)) == sympy.factorial(n) ** 2 / sympy.factorial(2 * n + 1)
    assert F_series(x, 5) == F_series(x, 4)


def test_series_numeric_and_mpmath():
    assert F_series(0.1, 20) == pytest.approx(F(0.1), rel=1e-15)
    with mpmath.workdps(40):
        v = F_series(mpmath.mpf("0.01"), 30)
        assert isinstance(v, mpmath.mpf)
        assert abs(v - F(mpmath.mpf("0.01"))) < mpmath.mpf(10) ** -38


def _grid():
    logs = np.logspace(-12, math.log10(2 - 1e-12), 400)
    near_two = 2 - 10.0 ** -np.arange(1, 13)
    special = np.array([1e-300, 5e-324, 1e-8, 0.1, 0.2499999999, 0.25, 0.2500000001, 1.0, 1.5, 1.9,
                        np.nextafter(2.0, 0.0)])
    return np.concatenate([logs, near_two, special])


def test_double_precision_within_a_few_ulps():
    """Relative error against mpmath at 50 digits over 1e-12 .. 2 - 1e-12, also 2 - 10^-k."""
    grid = _grid()
    values = F(grid)
    assert values.shape == grid.shape and values.dtype == np.float64
    worst = 0.0
    for g, v in zip(grid, values):
        ref = _reference(float(g))
        worst = max(worst, float(abs((mpmath.mpf(float(v)) - ref) / ref)))
        assert F(float(g)) == v  # scalar and vectorised paths agree bitwise
    assert worst <= 4 * EPS, worst / EPS


def test_even_and_zero():
    grid = _grid()
    assert np.array_equal(F(-grid), F(grid))
    assert F(0.0) == 1.0 and F(0) == 1.0 and F(-0.0) == 1.0
    assert np.array_equal(F(np.array([0.0, -0.0])), np.array([1.0, 1.0]))
    assert F(mpmath.mpf(0)) == 1


def test_blow_up_near_two():
    """F ~ pi / (2 sqrt(2 - x)) as x -> 2 (computed as sqrt((2-x)(2+x))/2, no cancellation)."""
    for k in range(4, 13):
        xk = 2 - 10.0**-k
        # asin(x/2) = pi/2 - sqrt(2 - x) + ..., so the relative correction is O(sqrt(2 - x))
        assert F(xk) == pytest.approx(math.pi / (2 * math.sqrt(2 - xk)), rel=2 * math.sqrt(2 - xk))


def test_kinds_in_kinds_out():
    assert isinstance(F(0.5), float)
    assert isinstance(F(np.float64(0.5)), np.float64)
    arr = F(np.array([[0.1, 0.2], [0.3, 0.4]]))
    assert isinstance(arr, np.ndarray) and arr.shape == (2, 2)
    assert isinstance(F(np.array(0.5)), np.float64)
    assert F(np.array([1, 0])).dtype == np.float64
    with mpmath.workdps(50):
        v = F(mpmath.mpf(1))
        assert isinstance(v, mpmath.mpf)
        assert abs(v - 2 * mpmath.pi / (3 * mpmath.sqrt(3))) < mpmath.mpf(10) ** -48
    assert isinstance(F(sympy.Rational(1, 2)), sympy.Expr)
    assert sympy.N(F(sympy.Rational(1, 2)), 30) == sympy.N(F(sympy.Rational(1, 2)), 30)
    assert float(F(sympy.Rational(1, 2))) == pytest.approx(F(0.5), rel=1e-15)


@pytest.mark.parametrize("bad", [2.0, -2.0, 2, 3.5, np.array([0.1, 2.0]), np.float64(-7.0),
                                 sympy.Integer(2), sympy.Rational(5, 2)])
def test_unstable_step(bad):
    with pytest.raises(UnstableStepError, match="x = "):
        F(bad)


def test_unstable_mpmath():
    with pytest.raises(UnstableStepError):
        F(mpmath.mpf(2))


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -np.inf, np.array([0.1, np.nan]), mpmath.inf,
                                 sympy.nan, sympy.oo])
def test_non_finite(bad):
    with pytest.raises(NumericalRangeError):
        F(bad)


@pytest.mark.parametrize("bad", [1j, "abc", np.array(["a"]), True])
def test_bad_types(bad):
    with pytest.raises(NambuBCHError):
        F(bad)


@settings(deadline=None, max_examples=200)
@given(st.floats(min_value=-1.999999, max_value=1.999999, allow_nan=False))
def test_property_even_at_least_one_and_monotone(v):
    f = F(v)
    assert f == F(-v)
    assert f >= 1.0
    w = abs(v) + (2 - abs(v)) / 2
    assert F(w) >= f


@settings(deadline=None, max_examples=100)
@given(st.floats(min_value=-0.3, max_value=0.3, allow_nan=False))
def test_property_series_near_zero(v):
    assert F(v) == pytest.approx(float(F_series(v, 30)), rel=4 * EPS)
