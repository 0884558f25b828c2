"""The extended exact ring of non-polynomial atoms, and the check of shadow Hamiltonians done in it."""

import pytest
import sympy

from nambu_bch import NambuBCHError, System, model
from nambu_bch.algebra.extended import ExtendedRing
from nambu_bch.errors import NoExactResultError
from nambu_bch.shadow.generic import (PoissonShadow, _check_in_expressions, _check_in_extended_ring, bch_shadow,
                                      check_against_backward)

x, y, m = sympy.symbols("x1 x2 m")
q1, q2 = sympy.symbols("q1 q2")


def ring(*exprs, coords=(x, y), params=()):
    return ExtendedRing(coords, params, exprs)


# -- the normal form -----------------------------------------------------------------------------------
@pytest.mark.parametrize("identity", [
    sympy.sin(x) ** 2 + sympy.cos(x) ** 2 - 1,
    sympy.sin(2 * x) - 2 * sympy.sin(x) * sympy.cos(x),
    sympy.cos(3 * x) - 4 * sympy.cos(x) ** 3 + 3 * sympy.cos(x),
    sympy.exp(2 * x) * sympy.exp(-x) - sympy.exp(x),
    (1 + x ** 2) / (1 + x ** 2) ** 2 - 1 / (1 + x ** 2),
    sympy.sqrt(x ** 2 + y ** 2) ** 3 - (x ** 2 + y ** 2) * sympy.sqrt(x ** 2 + y ** 2),
    1 / sympy.sqrt(x ** 2 + y ** 2) - sympy.sqrt(x ** 2 + y ** 2) / (x ** 2 + y ** 2),
])
def test_identities_reduce_to_zero(identity):
    R = ring(sympy.cos(x), sympy.exp(x), 1 / (1 + x ** 2), sympy.sqrt(x ** 2 + y ** 2), identity)
    assert not R.convert(identity)


@pytest.mark.parametrize("expr", [
    sympy.sin(x) ** 2 - sympy.cos(x) ** 2,
    sympy.exp(x) - 1 - x,
    sympy.sqrt(x ** 2 + y ** 2) - x - y,
    1 / (1 + x ** 2) - 1,
])
def test_non_zero_is_non_zero(expr):
    R = ring(sympy.cos(x), sympy.exp(x), 1 / (1 + x ** 2), sympy.sqrt(x ** 2 + y ** 2))
    assert R.convert(expr)


def test_normal_form_is_canonical_on_two_writings():
    # the same function written two ways has the same numerator and denominator exponents
    R = ring(sympy.sin(x), 1 / (1 + x ** 2))
    a = R.convert(sympy.sin(x) ** 3 / (1 + x ** 2))
    b = R.convert((sympy.sin(x) - sympy.sin(x) * sympy.cos(x) ** 2) / (1 + x ** 2))
    assert a.num == b.num and a.den == b.den


@pytest.mark.parametrize("f", [
    -1 / sympy.sqrt(q1 ** 2 + q2 ** 2),
    sympy.sin(sympy.sin(q1)) * sympy.exp(-q2) / (1 + q1 ** 2),
    sympy.cos(2 * q1) * sympy.sqrt(q1 ** 2 + q2 ** 2) ** 3,
])
def test_derivatives_agree_with_sympy(f):
    R = ring(f, coords=(q1, q2))
    for i, v in enumerate((q1, q2)):
        d = R.diff(R.convert(f), i) - R.convert(sympy.diff(f, v))
        assert not d


def test_parameters_in_denominators():
    R = ring(sympy.exp(x) / m, params=(m,))
    f = R.convert(sympy.exp(x) / m)
    assert not (R.diff(f, 0) - f)


@pytest.mark.parametrize("exprs, pattern", [
    ((sympy.tan(x),), "no rule"),
    ((sympy.exp(x + 1),), "constant part"),
    ((sympy.exp(x), sympy.exp(y), sympy.exp(x + y)), "linearly dependent"),
    ((sympy.sqrt(x), sympy.sqrt(y), sympy.sqrt(x * y)), "square"),
    ((sympy.cbrt(x),), "power"),
    ((sympy.Function("V")(x),), "no rule"),
    ((sympy.pi * x,), "constant"),
])
def test_refusals_are_one_line(exprs, pattern):
    with pytest.raises(NoExactResultError, match=pattern) as info:
        ring(*exprs)
    assert "\n" not in str(info.value) and isinstance(info.value, NambuBCHError)


# -- the check of H_S in the ring ---------------------------------------------------------------------
CENTRAL = ("q1 q2 p1 p2", ["(p1**2 + p2**2)/2 - 1/sqrt(q1**2 + q2**2)"])


@pytest.mark.parametrize("name, word, order", [("pendulum", "121", 4), ("exp-well", "212", 4), ("rational", "121", 4),
                                               ("henon-heiles", "121", 4)])
def test_ring_check_agrees_with_the_expression_check(name, word, order):
    R = bch_shadow(model(name), word, order, verify=False)
    assert _check_in_extended_ring(R) is True
    _check_in_expressions(R)  # the old check passes on the same answer


def test_central_force_is_checked_in_the_ring():
    S = System(*CENTRAL, name="central")
    R = bch_shadow(S, "212", 2, verify=False)
    assert _check_in_extended_ring(R) is True


@pytest.mark.parametrize("name", ["pendulum", "rational"])
def test_a_wrong_shadow_is_detected(name):
    R = bch_shadow(model(name), "121", 2, verify=False)
    bad = dict(R.series)
    bad[2] = bad[2] * sympy.Rational(11, 10)
    wrong = PoissonShadow(R.system, R.composition, R.order, bad)
    with pytest.raises(NoExactResultError, match=r"differs from the backward-error X_eff at h\^2"):
        check_against_backward(wrong)


def test_undefined_functions_fall_back_to_expressions():
    from nambu_bch.shadow.generic import generic_system

    R = bch_shadow(generic_system(), "121", 2, verify=False)
    assert _check_in_extended_ring(R) is False
    check_against_backward(R)
    assert R.verified_orders == 2


@pytest.mark.parametrize("name, word", [("pendulum", "121"), ("exp-well", "212"), ("pendulum", "212")])
def test_ring_solve_equals_the_expression_solve(name, word, monkeypatch):
    import nambu_bch.shadow.generic as generic

    new = bch_shadow(model(name), word, 4)
    monkeypatch.setattr(generic, "_extended_ring", lambda system, hams: None)
    old = bch_shadow(model(name), word, 4)
    R = ExtendedRing(new.system.coordinates, (), [*new.series.values(), *old.series.values()])
    for j in range(5):
        assert not (R.convert(new.series[j]) - R.convert(old.series[j]))


def test_central_force_h4_is_solved_and_checked_in_the_ring():
    S = System(*CENTRAL, name="central")
    R = bch_shadow(S, "212", 4)
    assert R.verified_orders == 4
    r = sympy.sqrt(q1 ** 2 + q2 ** 2)
    # the h^2 term's potential part, -V'^2 / 24 for velocity Verlet: -(1/r^2)^2 / 24
    assert R.series[2].subs({sympy.Symbol("p1"): 0, sympy.Symbol("p2"): 0}) == -1 / (24 * r ** 4)


@pytest.mark.parametrize("f", [sympy.exp(-x), (1 - sympy.exp(-x)) ** 2, sympy.exp(2 * x) / (1 + x ** 2) - sympy.exp(-x),
                               sympy.sin(x) ** 3 / sympy.sqrt(x ** 2 + y ** 2) ** 3])
def test_to_sympy_round_trips(f):
    R = ring(f, sympy.exp(x), sympy.cos(x))
    back = R.to_sympy(R.convert(f))
    assert not (R.convert(back) - R.convert(f))
    assert sympy.simplify(back - f) == 0


# -- the new built-ins: the truncated H_S drifts like h^(k+2) -------------------------------------------
@pytest.mark.parametrize("name", ["kepler", "kepler-3d", "morse", "lennard-jones"])
def test_builtin_truncated_shadow_drifts_like_h_k_plus_2(name):
    """Over a fixed time the order-k truncation of H_S (k = 0, 2, 4) moves by O(h^(k+2)): log-log slopes 2, 4, 6."""
    import numpy as np

    import nambu_bch as nb
    from nambu_bch.systems.catalog import DEFAULT_X0

    S = nb.model(name)
    params = {p: 1 for p in S.parameters}
    R = bch_shadow(S, "212", 4)
    h = sympy.Symbol("h")
    hs = np.array([0.08, 0.04, 0.02])
    for k, expected in ((0, 2), (2, 4), (4, 6)):
        H_k = sympy.lambdify((*S.coordinates, h), sum(h**j * R.series[j] for j in range(k + 1)).subs(params), "numpy")
        errs = []
        for step in hs:
            xs = nb.iterate(S, "212", h=float(step), steps=int(round(4 / step)), x0=DEFAULT_X0[name],
                            params={str(p): 1.0 for p in S.parameters} or None)
            vals = H_k(*xs.T, step)
            errs.append(np.max(np.abs(vals - vals[0])))
        slope = np.polyfit(np.log(hs), np.log(errs), 1)[0]
        assert abs(slope - expected) < 0.4, (name, k, slope)
